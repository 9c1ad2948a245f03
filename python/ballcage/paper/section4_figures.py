"""Figures 16–17 of the paper from the section-4 sweep: tube and key forces along the chain, one line per case.

Each figure has two panels over the summary window of every case:

- left: each link's mean tube normal force (``links.tube_normal``) against
  the link's mean inclination (``links.inclination_deg``, the paper's "well
  slope angle");
- right: the largest race normal force on any key of each hinge
  (max of ``keys.inner_normal`` and ``keys.outer_normal``) against the hinge
  number (0: upper connector / link 1), as the paper's peak ball-key force.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ballcage._files import write_png
from ballcage._links import in_summary_window, link_tube_forces
from ballcage._plot import figure, no_data, series_styles
from ballcage.run import Run

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["FRICTION_COLUMNS", "SECTION4_FIGURES", "friction_split", "hinge_key_peaks", "link_inclinations",
           "write_section4_figures"]

#: Figure files (without ``.png``).
SECTION4_FIGURES: tuple[str, ...] = ("fig16_curvature", "fig17_speed", "losses_curvature")
#: The drive table's friction power per frame [W] by contact group (the groups of `ballcage.duty.loss_breakdown`).
FRICTION_COLUMNS: dict[str, str] = {
    "tube": "friction_tube",
    "key–race": "friction_key_race",
    "key–window": "friction_key_window",
    "cage": "friction_cage",
    "neck": "friction_neck",
}


def write_section4_figures(
    curvature: Mapping[float, Run], speed: Mapping[float, Run], out_dir: str | os.PathLike[str]
) -> dict[str, Path]:
    """Writes ``fig16_curvature.png`` (runs by R [m]), ``fig17_speed.png`` (runs by rpm) and, beyond the
    paper, ``losses_curvature.png`` (efficiency and friction loss by contact against R); returns the paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    fig16 = _figure({f"R = {r:g} m": run for r, run in sorted(curvature.items())},
                    "Fig. 16: contact forces along the chain for different borehole curvature radii (100 rpm)")
    fig17 = _figure({f"{s:g} rpm": run for s, run in sorted(speed.items())},
                    "Fig. 17: contact forces along the chain for different drive speeds (R = 1.5 m)")
    return {
        "fig16_curvature": write_png(fig16, out / "fig16_curvature.png"),
        "fig17_speed": write_png(fig17, out / "fig17_speed.png"),
        "losses_curvature": write_png(_losses_figure(curvature), out / "losses_curvature.png"),
    }


def friction_split(run: Run) -> dict[str, float] | None:
    """Mean friction power [W] by contact group (`FRICTION_COLUMNS`) over the summary window, from the drive table.

    The sweep's cases record ``drive`` but not ``wear``; the drive table samples per frame the
    friction power that the wear table integrates per step (`ballcage.duty.loss_breakdown`).
    ``None`` without a drive table or without a frame in the window.
    """
    drive = run.tables.get("drive")
    if drive is None or drive.num_rows == 0:
        return None
    inside = in_summary_window(run.scene, drive.column("t").to_numpy())
    if not inside.any():
        return None
    return {group: float(drive.column(c).to_numpy()[inside].mean()) for group, c in FRICTION_COLUMNS.items()}


def _losses_figure(curvature: Mapping[float, Run]) -> Figure:
    """Beyond the paper: drive efficiency against R, and the friction loss by contact (`friction_split`) per R."""
    from ballcage.measures.quantities import efficiency

    fig = figure(figsize=(12, 4.8))
    eff_ax, loss_ax = fig.subplots(1, 2)
    radii = sorted(curvature)
    eff = {r: e for r in radii if (e := efficiency(curvature[r])) is not None}
    if eff:
        eff_ax.plot(list(eff), [100 * e for e in eff.values()], marker="o")
    else:
        no_data(eff_ax, "no finished case")
    eff_ax.set(xlabel="borehole curvature radius R [m]", ylabel="drive efficiency [%]",
               title="Load-transfer efficiency\n(mean output / mean input power, summary window)")
    losses = {r: split for r in radii if (split := friction_split(curvature[r])) is not None}
    if losses:
        groups = list(next(iter(losses.values())))
        bottom = np.zeros(len(losses))
        width = 0.8 * min(np.diff(list(losses)), default=0.5)
        for group, style in zip(groups, series_styles(len(groups)), strict=True):
            heights = np.array([losses[r][group] for r in losses])
            loss_ax.bar(list(losses), heights, bottom=bottom, width=width, color=style["color"], label=group)
            bottom += heights
        loss_ax.set_xticks(list(losses))
        loss_ax.legend(fontsize=8, title="contact", title_fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    else:
        no_data(loss_ax, "no drive table in the cases")
    loss_ax.set(xlabel="borehole curvature radius R [m]", ylabel="mean friction power [W]",
                title="Friction loss by contact\n(drive.friction_*, summary window)")
    fig.suptitle("Where the power goes against the borehole curvature (100 rpm)", fontsize=10)
    return fig


def link_inclinations(run: Run) -> dict[int, float]:
    """Each link's mean inclination [deg] over the summary window (``links.inclination_deg``)."""
    links = run.tables.get("links")
    if links is None or links.num_rows == 0:
        return {}
    inside = in_summary_window(run.scene, links.column("t").to_numpy())
    link = links.column("link").to_numpy()
    incl = links.column("inclination_deg").to_numpy()
    return {int(k): float(incl[inside & (link == k)].mean()) for k in np.unique(link) if (inside & (link == k)).any()}


def hinge_key_peaks(run: Run) -> dict[int, float]:
    """Each hinge's largest race normal force on one key [N] over the summary window; empty without keys."""
    keys = run.tables.get("keys")
    if keys is None or keys.num_rows == 0:
        return {}
    inside = in_summary_window(run.scene, keys.column("t").to_numpy())
    hinge = keys.column("hinge").to_numpy()
    force = np.maximum(keys.column("inner_normal").to_numpy(), keys.column("outer_normal").to_numpy())
    return {int(h): float(force[inside & (hinge == h)].max()) for h in np.unique(hinge) if (inside & (hinge == h)).any()}


def _figure(runs: Mapping[str, Run], title: str) -> Figure:
    fig = figure(figsize=(12, 4.8))
    tube, keys = fig.subplots(1, 2)
    styles = series_styles(len(runs))
    for style, (label, run) in zip(styles, runs.items(), strict=True):
        _tube_line(tube, run, label, style)
        peaks = hinge_key_peaks(run)
        if peaks:
            keys.plot(list(peaks), [v / 1e3 for v in peaks.values()], label=label, **style)
    for ax, what in ((tube, "no links table"), (keys, "no ball keys (pipe.hinge is not ball-keys)")):
        if not ax.lines:
            no_data(ax, what if runs else "no finished case")
    # One legend for both panels (the same cases), beside them rather than over the lines.
    handles, labels = max((ax.get_legend_handles_labels() for ax in (tube, keys)), key=lambda hl: len(hl[1]))
    if handles:
        fig.legend(handles, labels, loc="outside right upper", fontsize=8)
    tube.set(xlabel="link's mean inclination [deg]", ylabel="mean tube normal force per link [N]",
             title="Link–tube contact (summary window)")
    keys.set(xlabel="hinge [-] (0: upper connector / link 1)", ylabel="peak race normal force on one key [kN]",
             title="Ball keys (summary window)")
    fig.suptitle(title, fontsize=10)
    return fig


def _tube_line(ax: Axes, run: Run, label: str, style: dict[str, object]) -> None:
    tube = link_tube_forces(run)
    angles = link_inclinations(run)
    if tube is None or not angles:
        return
    links = sorted(k for k in tube.normal_mean if k in angles)
    ax.plot([angles[k] for k in links], [tube.normal_mean[k] for k in links], label=label, **style)  # type: ignore[arg-type]
