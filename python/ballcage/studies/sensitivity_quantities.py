"""The quantities a sensitivity study measures in each run, as sweep plug-ins (`SweepQuantities`).

- Drill pipes, `DRILL_PIPE_SENSITIVITY`: the comparison quantities of
  `ballcage.measures.DRILL_PIPE` (Table 3's motion, tube, cage and key
  forces, the drive efficiency, the per-link tube forces) and the smallest
  contact-pressure margin, ``pressure_margin_min`` (`ballcage.duty.smallest_margin`
  of the ``wear`` table: allowable over Hertz peak pressure, over the
  contact pairs); the shortest fatigue life and wear life,
  `ballcage.studies.sweep_quantities.LIVES` (``fatigue_life_min_h``,
  ``wear_hours_min_h``), from every frame's contacts, which each run records
  for them and the study does not keep (``memory_tables``).
- Scenes of bodies, `BODIES_SENSITIVITY`: each contact pair's summary
  statistics, ``<column>[<pair>]`` in N (`SUMMARY_STATISTICS`), and its
  largest penetration over the summary window, ``depth_peak[<pair>]`` in m
  (`depth_peaks`, from the ``contacts`` table).

`for_scene` picks one by the scene's kind; `tables_for` says what each run
must record for it.
"""

from __future__ import annotations

import re
from collections.abc import Collection
from typing import TYPE_CHECKING

from ballcage.duty import smallest_margin
from ballcage.measures.quantities import DRILL_PIPE
from ballcage.studies.sweep_quantities import (
    LIVES,
    SUMMARY_STATISTICS,
    DrillPipeLives,
    SweepQuantities,
)
from ballcage.studies.sweep_spec import DEFAULT_TABLES

if TYPE_CHECKING:
    from ballcage import _native
    from ballcage.run import Run

__all__ = [
    "BODIES_SENSITIVITY", "DRILL_PIPE_SENSITIVITY", "PRESSURE_MARGIN", "BodiesSensitivity", "DrillPipeSensitivity",
    "depth_peaks", "for_scene", "tables_for",
]

#: The smallest contact-pressure margin: name -> (unit, meaning).
PRESSURE_MARGIN: dict[str, tuple[str, str]] = {
    "pressure_margin_min": (
        "1",
        "smallest contact-pressure margin: allowable pressure / Hertz peak pressure of the contact pair where it is "
        "smallest (wear.pressure_margin, ballcage.duty.smallest_margin); below 1 beyond the static limit; null "
        "without contact",
    ),
}


class DrillPipeSensitivity(DrillPipeLives):
    """The drill pipe's sensitivity quantities: `DRILL_PIPE_LIVES`'s (`DRILL_PIPE`'s and `LIVES`) and
    `PRESSURE_MARGIN`."""

    def columns(self, recorded: Collection[str]) -> dict[str, tuple[str, str]]:
        return DRILL_PIPE.columns(recorded) | PRESSURE_MARGIN | LIVES

    def __call__(self, run: Run) -> dict[str, float | None]:
        out = super().__call__(run)
        if not out:  # not a drill pipe
            return out
        wear = run.tables.get("wear")
        row = smallest_margin(wear) if wear is not None else None
        out["pressure_margin_min"] = float(row["pressure_margin"]) if row is not None else None
        return out

    def __repr__(self) -> str:
        return "ballcage.studies.sensitivity_quantities.DRILL_PIPE_SENSITIVITY"


DRILL_PIPE_SENSITIVITY = DrillPipeSensitivity()


#: The name of a contact pair's largest penetration: ``depth_peak[<contact pair>]``.
_DEPTH = re.compile(r"depth_peak\[(?P<pair>.*)\]")
#: Slack [s] of the summary window's ends, as the engine's summary takes its frames.
_WINDOW_SLACK_S = 1e-12


def depth_peaks(run: Run) -> dict[str, float]:
    """``depth_peak[<pair>]`` -> the pair's largest penetration [m] over the summary window, 0 without contact.

    The largest ``depth`` of the ``contacts`` table over the pair's points and
    the frames the engine's ``summary`` counts (``window_start`` ≤ t ≤
    ``window_end``, `record.summary_window`); one entry per pair of the
    ``summary`` table, none without both tables.
    """
    import pyarrow.compute as pc  # deferred: only runs that measure depths pay for it

    contacts, summary = run.tables.get("contacts"), run.tables.get("summary")
    if contacts is None or summary is None:
        return {}
    out: dict[str, float] = {}
    t, names = contacts.column("t"), contacts.column("pair").cast("string")
    for row in summary.select(["pair", "window_start", "window_end"]).to_pylist():
        inside = pc.and_(pc.greater_equal(t, row["window_start"] - _WINDOW_SLACK_S),
                         pc.less_equal(t, row["window_end"] + _WINDOW_SLACK_S))  # fmt: skip
        pair = pc.equal(names, row["pair"])
        deepest = pc.max(contacts.column("depth").filter(pc.and_(inside, pair))).as_py()
        out[f"depth_peak[{row['pair']}]"] = max(0.0, deepest) if deepest is not None else 0.0
    return out


class BodiesSensitivity:
    """A scene of bodies' sensitivity quantities: `SUMMARY_STATISTICS`'s forces [N] and `depth_peaks` [m]."""

    def columns(self, recorded: Collection[str]) -> dict[str, tuple[str, str]]:
        depths = {m.string: m["pair"] for m in map(_DEPTH.fullmatch, sorted(recorded)) if m is not None}
        out = SUMMARY_STATISTICS.columns([name for name in recorded if name not in depths])
        for name, pair in depths.items():
            out[name] = ("m", f"largest penetration of contact pair {pair} over record.summary_window (contacts.depth); "
                              "0 without contact")  # fmt: skip
        return out

    def __call__(self, run: Run) -> dict[str, float | None]:
        return {**SUMMARY_STATISTICS(run), **depth_peaks(run)}

    def __repr__(self) -> str:
        return "ballcage.studies.sensitivity_quantities.BODIES_SENSITIVITY"


BODIES_SENSITIVITY = BodiesSensitivity()


def for_scene(scene: _native.Scene) -> SweepQuantities:
    """`DRILL_PIPE_SENSITIVITY` for a drill pipe, `BODIES_SENSITIVITY` for a scene of bodies."""
    return DRILL_PIPE_SENSITIVITY if scene.kind == "drill-pipe" else BODIES_SENSITIVITY


def tables_for(scene: _native.Scene) -> list[str]:
    """The tables each run records: a sweep's for a drill pipe plus ``wear``; ``summary`` and ``contacts`` (for the
    penetration depths) for a scene of bodies."""
    return [*DEFAULT_TABLES, "wear"] if scene.kind == "drill-pipe" else ["summary", "contacts"]
