"""Writing a drill-pipe run's wear map (`ballcage.measures.wear_map`): ``wear_map.parquet``, the tube wall's figure
``wear_map.png`` (`ballcage.view.wear`), and its lines for the report and ``comparison.md``."""

from __future__ import annotations

from pathlib import Path

import pyarrow as pa

from ballcage._files import write_with_figure
from ballcage.measures.wear_map import deepest, hours_line, wear_map
from ballcage.run import Run
from ballcage.view.wear import WEAR_FIGURE_FILE, WEAR_MAP_FILE, wear_figure

__all__ = ["WEAR_FIGURE_FILE", "WEAR_MAP_FILE", "wear_map_markdown", "write_wear_map"]


def write_wear_map(run: Run, out: Path) -> tuple[pa.Table, dict[str, Path]]:
    """Writes ``wear_map.parquet`` and ``wear_map.png`` of `run` into `out`; returns the map and the paths
    (``"wear_map"``, ``"wear_map_figure"``). Raises `InputError` when the run lacks a table the map needs."""
    table = wear_map(run)
    figure = wear_figure(table)
    return table, write_with_figure("wear_map", table, figure, out, (WEAR_MAP_FILE, WEAR_FIGURE_FILE))


def wear_map_markdown(table: pa.Table, spot_hours: float | None) -> str:
    """A ``comparison.md`` section: the deepest cell of each surface and its hours, beside the `wear` table's
    spot-under bound `spot_hours` [h]."""
    lines = ["", "## Wear map", "", hours_line(table) or "No surface wore in the window.", ""]
    lines += ["| surface | deepest cell | depth [µm] | hours to the map's depth |", "|---|---|---:|---:|"]
    for surface in ("tube", "link", "inner-race", "outer-race", "window"):
        row = deepest(table, surface)
        if row is None:
            continue
        where = f"{1e3 * row['axial_start']:.1f}–{1e3 * row['axial_end']:.1f} mm"
        if row["angle_start"] is not None:
            where += f" × {row['angle_start']:.0f}–{row['angle_end']:.0f}°"
        who = next((str(row[n]) for n in ("link", "pair") if row[n] is not None), "")
        lines.append(f"| {surface} {who} | {where} | {1e6 * row['depth']:.4g} | {row['hours_to_depth']:.3g} |")
    if spot_hours is not None:
        lines += ["", f"The `wear` table's spot-under bound (a wall spot that stays under the contact): {spot_hours:.3g} h."]
    return "\n".join(lines) + "\n"
