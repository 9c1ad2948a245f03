"""``fatigue.parquet`` and ``fatigue.png`` of a drill-pipe run (`ballcage.measures.fatigue`), for ``ballcage run``
and ``ballcage paper``."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pyarrow as pa

from ballcage._files import write_with_figure
from ballcage._native import InputError
from ballcage._plot import figure, series_styles
from ballcage.measures.fatigue import fatigue_table, section_stresses
from ballcage.measures.sections import Section, SectionLoads, link_sections, section_loads
from ballcage.run import Run

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["FATIGUE_FIGURE", "FATIGUE_FILE", "fatigue_markdown", "write_fatigue", "write_fatigue_or_why"]

#: The table and the figure `write_fatigue` writes.
FATIGUE_FILE, FATIGUE_FIGURE = "fatigue.parquet", "fatigue.png"


def write_fatigue(run: Run, out: Path) -> tuple[pa.Table, dict[str, Path]]:
    """Writes ``fatigue.parquet`` and ``fatigue.png`` into `out`; the table and the paths (``"fatigue"``,
    ``"fatigue_figure"``). Raises `ballcage.InputError` when the run cannot give section loads."""
    sections = link_sections(run)
    loads = section_loads(run, sections)
    table = fatigue_table(run, sections, loads)
    fig = _figure(table, sections, loads)
    return table, write_with_figure("fatigue", table, fig, out, (FATIGUE_FILE, FATIGUE_FIGURE))


def write_fatigue_or_why(run: Run, out: Path, written: dict[str, Path]) -> pa.Table | str:
    """`write_fatigue`, its paths added to `written`; or, for a run that cannot give section loads (an ideal-CV
    hinge), the reason, no files, and an earlier run's ``fatigue.parquet`` and ``fatigue.png`` in `out` removed."""
    try:
        table, paths = write_fatigue(run, out)
    except InputError as e:
        for name in (FATIGUE_FILE, FATIGUE_FIGURE):
            (out / name).unlink(missing_ok=True)
        return str(e)
    written.update(paths)
    return table


def _figure(table: pa.Table, sections: list[Section], loads: SectionLoads) -> Figure:
    """Left: hours to failure per link and section; right: the shortest-lived section's stress history."""
    rows = table.to_pylist()
    fig = figure(figsize=(12.0, 4.6))
    left, right = fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2)
    width = 0.8 / max(len(sections), 1)
    for i, (sec, style) in enumerate(zip(sections, series_styles(len(sections)), strict=True)):
        mine = [r for r in rows if r["section"] == sec.name and r["hours_to_failure"] is not None]
        left.bar(
            [r["link"] + (i - (len(sections) - 1) / 2) * width for r in mine],
            [r["hours_to_failure"] for r in mine],
            width=width,
            color=style["color"],
            label=f"{sec.name} (K_t {sec.scf:g}, Ø{1e3 * sec.outer_diameter:g}/{1e3 * sec.inner_diameter:g} mm)",
        )
    left.set_yscale("log")
    left.set_xlabel("link [-]")
    left.set_ylabel("hours of this duty to failure [h] (Miner's sum 1)")
    left.set_title("Fatigue life at the critical sections (rigid-link nominal stress × K_t)")
    left.legend(loc="best", fontsize="small")
    lived = [r for r in rows if r["hours_to_failure"] is not None]
    if lived:
        worst = min(lived, key=lambda r: r["hours_to_failure"])
        sec = next(s for s in sections if s.name == worst["section"])
        sigma, tau = section_stresses(loads, sec)
        k = int(np.searchsorted(loads.links, worst["link"]))
        j = round(worst["fibre_deg"] / 360.0 * sigma.shape[2]) % sigma.shape[2]
        right.plot(
            loads.times, sec.scf * sigma[:, k, j] / 1e6, label=f"normal stress × K_t, fibre {worst['fibre_deg']:g}°"
        )
        right.plot(loads.times, tau[:, k] / 1e6, label="torsional shear (nominal)")
        right.axvspan(worst["window_start"], worst["window_end"], color="0.9", zorder=0, label="counted window")
        right.set_title(f"{worst['section']} of link {worst['link']}: {worst['hours_to_failure']:.3g} h")
        right.legend(loc="best", fontsize="small")
    right.set_xlabel("t [s]")
    right.set_ylabel("stress [MPa]")
    return fig


def fatigue_markdown(table: pa.Table | str) -> str:
    """The comparison's fatigue section: the shortest life, and the shortest per section over the links (or why
    there is no fatigue table, `write_fatigue_or_why`)."""
    from ballcage.measures.fatigue import fatigue_line

    title = ["", "## Fatigue at the critical sections (beyond the paper)", ""]
    if isinstance(table, str):
        return "\n".join([*title, f"- No fatigue table: {table}."]) + "\n"
    line = fatigue_line(table)
    if line is None:
        return ""
    out = [*title, f"- This run: {line}.", "",
           "| section | shortest life [h] | link | σ_a [MPa] | σ′_m [MPa] | τ_m [MPa] | cycles per revolution |",
           "| --- | ---: | ---: | ---: | ---: | ---: | ---: |"]  # fmt: skip
    rows = [r for r in table.to_pylist() if r["hours_to_failure"] is not None]
    for name in dict.fromkeys(r["section"] for r in rows):
        r = min((r for r in rows if r["section"] == name), key=lambda r: r["hours_to_failure"])
        # revolutions in the window = Miner's sum over it / its sum per revolution
        window_damage = r["damage_per_hour"] * (r["window_end"] - r["window_start"]) / 3600.0
        revs = window_damage / r["damage_per_revolution"] if r["damage_per_revolution"] else 0.0
        per_rev = f"{r['cycles'] / revs:.3g}" if revs > 0 else ""
        out.append(
            f"| {name} | {r['hours_to_failure']:.3g} | {r['link']} | {r['stress_amplitude'] / 1e6:.1f} | "
            f"{r['stress_mean'] / 1e6:.0f} | {r['shear_mean'] / 1e6:.0f} | {per_rev} |"
        )
    return "\n".join(out) + "\n"
