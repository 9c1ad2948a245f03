"""The design chart's figure: heat maps over curvature radius × joint length, infeasible cells hatched.

`chart_figure(table)` draws a `ballcage.studies.design_chart.chart_table`
(or ``design_chart.parquet`` read back: everything it needs is in the table
and its metadata). Four panels share the grid, R [m] on x and L [m] on y,
both on log scales (the articulation limit is then a straight line), each
cell reaching halfway (geometrically) to its neighbours: (a) the peak race force
on one key over the whole run, (b) the largest per-link mean tube force,
(c) the sum over links of the mean tube forces, (d) the largest tube force of
any link, the tube forces over the summary window, all in kN and written in
each cell, under each value its numerical error relative to it (the cell
against its run at the tighter setting, when the chart measured it). Cells excluded before running are grey and hatched, labelled by
the constraint (``eq. 9``, ``art.``, ``both``); cells that ran but did not
finish are cross-hatched with their status. The boundaries are drawn as
curves: eq. (9)'s longest joint L(R) and the articulation limit's tightest
radius R(L).
"""

from __future__ import annotations

import json
import math
from typing import TYPE_CHECKING, Any

import numpy as np
import pyarrow as pa

from ballcage import sizing
from ballcage._plot import colormap, figure, no_data

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["PANELS", "chart_figure"]

#: Panels: column, title; every value is drawn in kN.
PANELS: tuple[tuple[str, str], ...] = (
    ("key_peak_n", "(a) peak race force on one key, whole run [kN]"),
    ("tube_normal_mean_max_n", "(b) largest per-link mean tube force [kN]"),
    ("tube_normal_mean_all_n", "(c) sum over links of the mean tube force [kN]"),
    ("tube_normal_peak_max_n", "(d) largest tube force of any link [kN]"),
)
_SHORT = {"eq. (9)": "eq. 9", "articulation limit": "art.", "eq. (9) and articulation limit": "both"}
_GREY = "0.85"


def chart_figure(table: pa.Table) -> Figure:
    """The chart of `table` (a chart table) as a matplotlib `Figure` (no pyplot)."""
    meta = {k.decode(): v.decode() for k, v in (table.schema.metadata or {}).items()}
    rows = table.to_pylist()
    radii = sorted({r["borehole.curvature_radius"] for r in rows})
    lengths = sorted({r["pipe.pitch"] for r in rows})
    fig = figure(figsize=(13, 10.5))
    axes = fig.subplots(2, 2).ravel()
    for ax, (name, title) in zip(axes, PANELS, strict=True):
        _panel(fig, ax, rows, radii, lengths, name)
        _boundaries(ax, meta, radii, lengths)
        ax.set_title(title, fontsize="medium")
        ax.set_xlabel("curvature radius R [m]")
        ax.set_ylabel("joint length L [m]")
        if name == "key_peak_n" and meta.get("ballcage.chart_hinge") == "ideal-cv":
            no_data(ax, "no keys in the ideal-CV model")
    handles, labels = axes[1].get_legend_handles_labels()
    unique = dict(zip(labels, handles, strict=True))  # one entry per kind of patch
    fig.legend(unique.values(), unique.keys(), loc="outside lower center", ncols=3, fontsize="small", markerscale=0.5)
    fig.suptitle(_title(meta), fontsize="medium")
    return fig


def _panel(fig: Figure, ax: Axes, rows: list[dict[str, Any]], radii: list[float], lengths: list[float], name: str) -> None:
    """One heat map: finished cells coloured and labelled, the others grey with why."""
    from matplotlib.colors import Normalize
    from matplotlib.patches import Rectangle

    xe, ye = _edges(radii), _edges(lengths)
    values = np.full((len(lengths), len(radii)), np.nan)
    for r in rows:
        v = r.get(name)
        if r["status"] == "ok" and isinstance(v, (int, float)) and math.isfinite(v):
            values[lengths.index(r["pipe.pitch"]), radii.index(r["borehole.curvature_radius"])] = v / 1e3
    finite = values[np.isfinite(values)]
    norm = Normalize(float(finite.min()), float(finite.max())) if finite.size else Normalize(0, 1)
    mesh = ax.pcolormesh(xe, ye, np.ma.masked_invalid(values), cmap=colormap("viridis"), norm=norm)
    if finite.size:
        fig.colorbar(mesh, ax=ax, shrink=0.9)
    for r in rows:
        i, j = lengths.index(r["pipe.pitch"]), radii.index(r["borehole.curvature_radius"])
        x, y = (xe[j] + xe[j + 1]) / 2, (ye[i] + ye[i + 1]) / 2
        box = (xe[j], ye[i]), xe[j + 1] - xe[j], ye[i + 1] - ye[i]
        if not r["feasible"]:
            ax.add_patch(Rectangle(*box, facecolor=_GREY, edgecolor="0.55", hatch="//", lw=0.5, label="excluded before running"))
            ax.text(x, y, _SHORT.get(r["reason"], "scene"), ha="center", va="center", fontsize="small",
                    bbox={"facecolor": "white", "edgecolor": "none", "pad": 1})
        elif r["status"] != "ok":
            ax.add_patch(Rectangle(*box, facecolor="white", edgecolor="tab:red", hatch="xx", lw=0.5, label="did not finish"))
            ax.text(x, y, str(r["status"] or "not run"), ha="center", va="center", fontsize="small", color="tab:red")
        elif math.isfinite(values[i, j]):
            color = "white" if norm(values[i, j]) < 0.6 else "black"
            ax.text(x, y, f"{values[i, j]:.3g}{_error_text(r, name)}", ha="center", va="center", fontsize="small",
                    color=color)
    ax.set(xscale="log", yscale="log", xlim=(xe[0], xe[-1]), ylim=(ye[0], ye[-1]))
    ax.set_xticks(radii, [f"{v:g}" for v in radii])
    ax.set_yticks(lengths, [f"{v:g}" for v in lengths])
    ax.minorticks_off()


def _error_text(row: dict[str, Any], name: str) -> str:
    """The cell's numerical error of `name` as a second line, ``±0.06 %`` (relative to its value); empty when the
    chart did not measure it."""
    value, error = row.get(name), row.get(name + "_error")
    if not value or error is None:
        return ""
    percent = 100 * error / abs(value)
    return "\n±<0.01 %" if percent < 0.01 else f"\n±{percent:.2g} %"


def _edges(values: list[float]) -> np.ndarray:
    """Cell edges around sorted positive centres: geometric midpoints, half a spacing (in log) beyond the ends."""
    v = np.log(np.asarray(values, dtype=float))
    if v.size == 1:
        return np.exp(np.array([v[0] - 0.1, v[0] + 0.1]))
    mid = (v[1:] + v[:-1]) / 2
    return np.exp(np.concatenate([[v[0] - (mid[0] - v[0])], mid, [v[-1] + (v[-1] - mid[-1])]]))


def _boundaries(ax: Axes, meta: dict[str, str], radii: list[float], lengths: list[float]) -> None:
    """Eq. (9)'s longest joint L(R) and the articulation limit's tightest radius R(L), over the panel."""
    xe, ye = _edges(radii), _edges(lengths)
    tube = float(meta["ballcage.chart_tube_inner_diameter_m"])
    joint = float(meta["ballcage.chart_joint_diameter_m"])
    r = np.linspace(max(xe[0], tube / 2), xe[-1], 300)
    ax.plot(r, [sizing.longest_link(float(x), tube, joint) for x in r], color="tab:red", lw=2,
            label=f"eq. (9): longest joint that fits, D = {1e3 * tube:g} mm, d = {1e3 * joint:g} mm")
    limit = json.loads(meta.get("ballcage.chart_articulation_limit_deg", "null"))
    if limit is not None and int(meta.get("ballcage.chart_joints", "2")) >= 2:
        length = np.linspace(max(ye[0], 1e-6), ye[-1], 300)
        ax.plot([sizing.tightest_radius_for_bend(float(v), limit) for v in length], length, color="black",
                ls="--", lw=2, label=f"articulation limit {limit:.2f}°: R = L / (2 sin(β/2))")
    if math.isclose(tube, sizing.PAPER_TUBE_INNER_DIAMETER) and math.isclose(joint, sizing.PAPER_JOINT_OUTER_DIAMETER):
        ax.plot([1.5], [0.2], marker="o", mfc="none", mec="tab:orange", mew=2.5, ms=30, ls="none",
                label="the paper's pipe (R 1.5 m, L 0.2 m)")


def _title(meta: dict[str, str]) -> str:
    hinge = meta.get("ballcage.chart_hinge", "?")
    model = {"ball-keys": "ball-key hinges (the paper's model)", "ideal-cv": "ideal-CV hinges (the reduced model)"}
    window = json.loads(meta.get("ballcage.chart_summary_window_s", "[]"))
    scaling = json.loads(meta.get("ballcage.chart_mass_scaling", "{}"))
    mass = (f"link mass ∝ L ({scaling['reference_mass_kg']:g} kg at {scaling['reference_length_m']:g} m)"
            if scaling.get("on") else "link mass fixed")
    return (
        f"Design chart, {model.get(hinge, hinge + ' hinges')}: tube ID {1e3 * float(meta['ballcage.chart_tube_inner_diameter_m']):g} mm, "
        f"joint OD {1e3 * float(meta['ballcage.chart_joint_diameter_m']):g} mm, "
        f"{meta.get('ballcage.chart_joints', '?')} joints\n"
        f"{float(meta['ballcage.chart_duration_s']):g} s simulated per cell; tube forces averaged over "
        f"{window[0]:g}–{window[1]:g} s; {mass}; hatched: excluded before running{_verified(meta)}"
    )


def _verified(meta: dict[str, str]) -> str:
    label = meta.get("ballcage.chart_verification", "")
    return f"; ± each cell's numerical error (against it at {label})" if label else "; numerical error not measured"

