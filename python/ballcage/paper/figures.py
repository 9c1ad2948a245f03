"""The paper's figures (Figs. 9–13 and Table 3's chain shape) drawn from a run's tables."""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ballcage._files import write_png
from ballcage._plot import figure, no_data, series_styles
from ballcage.paper.definitions import TUBE_LINKS
from ballcage.measures.phases import SceneFacts, phases, scene_facts
from ballcage.measures.frames import frame_grid, frame_times
from ballcage.run import Run

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["FIGURES", "KEY_BODIES", "articulation_limit_deg", "write_figures"]

#: Figure files (without ``.png``), in the order they are written.
FIGURES: tuple[str, ...] = (
    "fig09_included_angles",
    "fig10_tube_normal",
    "fig11_tube_tangential",
    "fig12_key_normal",
    "fig13_key_tangential",
    "table3_shape",
)
#: Bodies whose ball-key forces the paper plots (Figs. 12–13): connectors and links.
KEY_BODIES: tuple[str | int, ...] = ("upper", 1, 3, 6, 9, 12, "lower")


def write_figures(run: Run, out_dir: str | os.PathLike[str]) -> dict[str, Path]:
    """Writes the paper's figures (`FIGURES`) as PNG into `out_dir`; returns their paths by name."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    facts = scene_facts(run)
    times = frame_times(run)
    makers: dict[str, Callable[[], Figure]] = {
        "fig09_included_angles": lambda: _fig_included_angles(run, facts, times),
        "fig10_tube_normal": lambda: _fig_tube(run, times, normal=True),
        "fig11_tube_tangential": lambda: _fig_tube(run, times, normal=False),
        "fig12_key_normal": lambda: _fig_keys(run, times, normal=True),
        "fig13_key_tangential": lambda: _fig_keys(run, times, normal=False),
        "table3_shape": lambda: _fig_shape(run, facts, times),
    }
    return {name: write_png(makers[name](), out / f"{name}.png") for name in FIGURES}


def articulation_limit_deg(run: Run) -> float | None:
    """The bend [deg] at which the run's hinges bind, ``None`` when nothing limits it.

    The one place the figures read the limit (`ballcage.Scene.articulation_limit_deg`:
    where the head's neck meets the seat's mouth).
    """
    return run.scene.articulation_limit_deg()


def _fig_included_angles(run: Run, facts: SceneFacts, times: np.ndarray) -> Figure:
    """Fig. 9: the included angle at hinge k between link k and link k+1 (links.included_angle_deg of link k).

    Hinges 1-11 join two links (the paper's adjacent joints); hinge 12 joins
    link 12 and the lower connector and is drawn apart (hollow markers; dotted over time).
    A dotted line marks 180 deg minus the articulation limit, where hinges
    that bind stay flat.
    """
    fig = figure(figsize=(12, 5))
    by_hinge, over_time = fig.subplots(1, 2)
    links = run.tables.get("links")
    found, skipped = phases(run, facts)
    if links is not None and links.num_rows:
        grid = frame_grid(links, times, ["link"], ["included_angle_deg"])["included_angle_deg"][:, 1:]
        hinges = np.arange(1, grid.shape[1] + 1)
        inner = hinges[:-1]  # between two links
        for p in found:
            (line,) = by_hinge.plot(inner, grid[p.frame, :-1], marker="o", label=f"{p.label} (t = {p.t:.3f} s)")
            by_hinge.plot(hinges[-1:], grid[p.frame, -1:], marker="o", mfc="none", ls="none", color=line.get_color())
        by_hinge.set_xticks(hinges)
        _included_angles_over_time(over_time, times, grid)
    else:
        no_data(over_time, "no links table")
    limit = articulation_limit_deg(run)
    if limit is not None:
        label = f"articulation limit {180.0 - limit:.2f} deg (180 - {limit:.2f})"
        for ax in (by_hinge, over_time):
            ax.axhline(180.0 - limit, color="k", ls=":", lw=1.2, zorder=0, label=label)
            ax.margins(y=0.08)
    if links is not None and links.num_rows:
        over_time.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5), title="hinge", title_fontsize=7)
    if found or limit is not None:
        low = by_hinge.get_ylim()[0]
        by_hinge.set_ylim(low, 180.0 + 0.4 * (180.0 - low))  # room above 180 deg (straight) for the legend
        by_hinge.set_yticks([t for t in by_hinge.get_yticks() if low <= t <= 180.0])
        by_hinge.legend(fontsize=7, title="phase of the upper connector", title_fontsize=7, loc="upper center", ncol=2)
    if skipped:
        by_hinge.text(
            0.01, 0.01, f"phases before t = 0 not shown: {', '.join(skipped)}", transform=by_hinge.transAxes, fontsize=7
        )
    by_hinge.set(
        xlabel="hinge k [-]\n(1-11: link k / link k+1; hollow 12: link 12 / lower connector)",
        ylabel="included angle at hinge k [deg]",
        title="At the four phases of the last revolution",
    )
    over_time.set(xlabel="time [s]", ylabel="included angle at hinge k [deg]", title="Over time")
    fig.suptitle(
        "Fig. 9: included angle at hinge k between link k and link k+1 "
        "(links.included_angle_deg of link k = 180 - hinges.bend_deg; 180 deg = straight)",
        fontsize=10,
    )
    return fig


def _included_angles_over_time(ax: Axes, times: np.ndarray, grid: np.ndarray) -> None:
    """One line per hinge, each with its own colour, line style and marker."""
    count = grid.shape[1]
    every = max(len(times) // 12, 1)
    for k, style in enumerate(series_styles(count)):
        last = k == count - 1
        label = f"hinge {k + 1}" + (" (lower conn.)" if last else "")
        if last:  # drawn apart, as in the left panel: dotted, hollow markers
            style = {**style, "ls": ":", "mfc": "none"}
        offset = (k * every) // max(count, 1)  # markers of neighbouring hinges do not sit on one time
        ax.plot(times, grid[:, k], lw=1, ms=4, markevery=(offset, every), label=label, **style)


def _fig_tube(run: Run, times: np.ndarray, *, normal: bool) -> Figure:
    fig = figure(figsize=(9, 4.8))
    ax = fig.subplots()
    kind = "normal" if normal else "tangential"
    column = f"tube_{kind}"
    links = run.tables.get("links")
    if links is not None and links.num_rows:
        forces = frame_grid(links, times, ["link"], [column])[column]
        for k in TUBE_LINKS:
            if k < forces.shape[1]:
                ax.plot(times, forces[:, k], lw=1, label=f"link {k}")
        ax.legend(title=f"links.{column}", fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))  # off the lines
    else:
        no_data(ax, "no links table")
    ax.set(xlabel="time [s]", ylabel=f"{kind} contact force link-tube [N]")
    detail = "sum over the contact points" if normal else "magnitude of the summed friction vector"
    number = 10 if normal else 11
    ax.set_title(f"Fig. {number}: {kind} force between links 2, 4, 6, 8, 10 and the guide tube\n(per frame: {detail})")
    return fig


def _key_races(joints: int) -> dict[str | int, list[tuple[int, str]]]:
    """For each plotted body, its races as (hinge, keys column prefix): head = inner race, seat = outer race."""
    races: dict[str | int, list[tuple[int, str]]] = {}
    for body in KEY_BODIES:
        if body == "upper":
            races[body] = [(0, "inner")]
        elif body == "lower":
            races[body] = [(joints, "outer")]
        else:
            assert isinstance(body, int)
            races[body] = [(body - 1, "outer"), (body, "inner")]
    return races


def _race_label(body: str | int, races: list[tuple[int, str]]) -> str:
    name = f"link {body}" if isinstance(body, int) else f"{body} connector"
    parts = [f"h{h:02d} {'seat (outer)' if side == 'outer' else 'head (inner)'} race" for h, side in races]
    return f"{name}: {parts[0]}" if len(parts) == 1 else f"{name}: max of {' and '.join(parts)}"


def _fig_keys(run: Run, times: np.ndarray, *, normal: bool) -> Figure:
    fig = figure(figsize=(10, 6.2))
    ax = fig.subplots()
    keys = run.tables.get("keys")
    kind = "normal" if normal else "tangential"
    if keys is not None and keys.num_rows:
        cols = [f"{side}_{kind}" for side in ("inner", "outer")]
        grids = frame_grid(keys, times, ["hinge", "key"], cols)
        joints = grids[cols[0]].shape[1] - 1
        for body, races in _key_races(joints).items():
            series = [grids[f"{side}_{kind}"][:, h, :] for h, side in races if 0 <= h <= joints]
            if not series:
                continue
            largest = np.nanmax(np.concatenate(series, axis=1), axis=1)
            ax.plot(times, largest, lw=1, label=_race_label(body, races))
        fig.legend(fontsize=7, loc="outside lower center", ncol=2)  # below the axes: off the lines
    else:
        no_data(ax, "no keys table")
    ax.set(xlabel="time [s]", ylabel=f"largest ball-key {kind} force [N]")
    number = 12 if normal else 13
    column = "inner/outer_" + kind
    ax.set_title(
        f"Fig. {number}: ball-key {kind} force on the races of the connectors and links 1, 3, 6, 9, 12\n"
        f"per frame, the largest keys.{column} of the 6 keys over the body's races "
        "(link k: seat race of hinge k-1, head race of hinge k)",
        fontsize=9,
    )
    return fig


def _fig_shape(run: Run, facts: SceneFacts, times: np.ndarray) -> Figure:
    fig = figure(figsize=(12, 8))
    grid_spec = fig.add_gridspec(2, 4, height_ratios=[1.1, 1])
    sections = [fig.add_subplot(grid_spec[0, i]) for i in range(4)]
    profile = fig.add_subplot(grid_spec[1, :])
    links = run.tables.get("links")
    found, _ = phases(run, facts)
    by_label = {p.label: p for p in found}
    clearance_mm = 1e3 * facts.clearance
    if links is not None and links.num_rows:
        g = frame_grid(links, times, ["link"], ["offset_outward", "offset_lateral", "radial_offset"])
        outward, lateral = g["offset_outward"][:, 1:], g["offset_lateral"][:, 1:]
        offsets = g["radial_offset"][:, 1:]
        numbers = np.arange(1, offsets.shape[1] + 1)
        for ax, (label, t) in zip(sections, facts.phase_times(), strict=True):
            p = by_label.get(label)
            _section_axes(ax, clearance_mm, first=ax is sections[0])
            if p is None:
                ax.set_title(f"{label}: t = {t:.3f} s\nnot in the run", fontsize=9)
                continue
            x_mm, y_mm = 1e3 * outward[p.frame], 1e3 * lateral[p.frame]
            sc = ax.scatter(x_mm, y_mm, c=numbers, cmap="viridis", s=22, zorder=3)
            for k, x, y in zip(numbers, x_mm, y_mm, strict=True):
                ax.annotate(str(k), (x, y), fontsize=6, xytext=(2, 2), textcoords="offset points")
            ax.set_title(f"{label}: t = {p.t:.3f} s\nfurthest out: link {p.furthest}", fontsize=9)
            profile.plot(numbers, 1e3 * offsets[p.frame], marker="o", label=f"{label} (t = {p.t:.3f} s)")
        if found:
            fig.colorbar(sc, ax=sections, label="link number [-]", shrink=0.8)
        profile.set_xticks(numbers)
    else:
        no_data(profile, "no links table")
    profile.axhline(clearance_mm, color="k", ls="--", lw=0.8, label=f"clearance {clearance_mm:.0f} mm")
    profile.set_ylim(bottom=0.0)  # offsets are distances from the centreline: 0 is on the axis
    profile.set(
        xlabel="link number k [-]",
        ylabel="centre offset from\ntube centreline [mm]",
        title="Radial offset of each link's centre of mass (links.radial_offset)",
    )
    # Below the figure, in one row: off the lines, and not in the right margin the colour bar takes.
    fig.legend(*profile.get_legend_handles_labels(), fontsize=8, loc="outside lower center", ncol=5)
    fig.suptitle(
        "Table 3: chain shape at the phases 0/90/180/270 deg of the upper connector's last revolution "
        f"({facts.rpm:g} rpm)\ncross-sections seen down the tube: x in the bend plane, + toward the outer wall; "
        f"dashed circle: tube clearance {clearance_mm:.0f} mm; numbers: link k",
        fontsize=10,
    )
    return fig


def _section_axes(ax: Axes, clearance_mm: float, *, first: bool) -> None:
    """A tube cross-section [mm]: the clearance circle, equal axes, + toward the outer wall of the bend.

    The four sections share their limits; only the `first` labels the y axis, so the
    labels of one panel never run into the next (the suptitle says what x and y are).
    """
    circle = np.linspace(0.0, 2.0 * math.pi, 181)
    ax.plot(clearance_mm * np.cos(circle), clearance_mm * np.sin(circle), "k--", lw=0.8)
    ax.set_aspect("equal")
    ax.set(
        xlabel="links.offset_outward [mm]",
        xlim=(-1.15 * clearance_mm, 1.15 * clearance_mm),
        ylim=(-1.15 * clearance_mm, 1.15 * clearance_mm),
    )
    if first:
        ax.set_ylabel("links.offset_lateral [mm]")
    else:
        ax.tick_params(labelleft=False)
