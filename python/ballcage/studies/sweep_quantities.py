"""A sweep's per-case quantities as a plug-in (`SweepQuantities`), as the engine takes ``record::Observer``\\ s.

`sweep` calls its plug-in on each case's run (complete or partial) and
writes the values into the case's record; ``summary.parquet`` holds one
column per name the plug-in's `SweepQuantities.columns` lists, with its unit
and meaning in the field's metadata. Nothing here knows a scene kind's
quantities:

- `GENERIC` (scenes of bodies): no quantity columns;
- `SUMMARY_STATISTICS` (scenes of bodies): the summary statistics of each
  contact pair (`summary_statistics`), the headline quantities of a generic
  scene for ``ballcage run --verify`` and ``ballcage sensitivity``;
- `ballcage.measures.DRILL_PIPE` (drill pipes): included angles, ranges of
  motion, tube, cage and key forces, drive efficiency, per-link tube forces;
  ``ballcage sweep`` and ``ballcage paper --sweeps`` pass it;
- `DRILL_PIPE_LIVES` (drill pipes): those and the shortest fatigue and wear
  lives (`LIVES`, `lives`), from every frame's contacts, which each run
  records for them and the sweep does not keep (``memory_tables``);
  ``ballcage chart`` passes it, and the sensitivity study's plug-in extends it.

`for_scene` picks one of these by the scene's kind when a caller passes none.
"""

from __future__ import annotations

import re
from collections.abc import Collection
from typing import TYPE_CHECKING, Protocol, runtime_checkable

from ballcage._native import InputError
from ballcage.measures.quantities import DRILL_PIPE

if TYPE_CHECKING:
    from ballcage import _native
    from ballcage.run import Run

__all__ = [
    "DRILL_PIPE_LIVES",
    "GENERIC",
    "LIVES",
    "LIVES_SECONDS_PER_SIMULATED_SECOND",
    "SUMMARY_STATISTICS",
    "DrillPipeLives",
    "GenericQuantities",
    "SummaryStatistics",
    "SweepQuantities",
    "for_scene",
    "lives",
    "summary_statistics",
]


@runtime_checkable
class SweepQuantities(Protocol):
    """What a sweep computes for each case; picklable, since it travels to Dask workers with each case."""

    def columns(self, recorded: Collection[str]) -> dict[str, tuple[str, str]]:
        """The summary's quantity columns, in order: name -> (unit, meaning).

        `recorded` holds every name any case's record holds (not empty), for
        columns that depend on the scene (one per link).
        """
        ...

    def __call__(self, run: Run) -> dict[str, float | None]:
        """The quantities of one case's run, complete or partial; ``None`` where a value is not computed."""
        ...

    # A plug-in may also name tables it reads beyond the sweep's, ``memory_tables: tuple[str, ...]``: each drill-pipe
    # run records them for the plug-in and the sweep does not keep them (`ballcage.studies.sweep_case.run_case`).


class GenericQuantities:
    """The plug-in of scenes of bodies: no quantities (the summary holds the swept values and the cost)."""

    def columns(self, recorded: Collection[str]) -> dict[str, tuple[str, str]]:
        return {}

    def __call__(self, run: Run) -> dict[str, float | None]:
        return {}

    def __repr__(self) -> str:
        return "ballcage.studies.sweep_quantities.GENERIC"


GENERIC = GenericQuantities()

#: The name of a generic scene's summary statistic: ``<column of the summary table>[<contact pair>]``.
_STATISTIC = re.compile(r"(?P<column>[A-Za-z0-9_]+)\[(?P<pair>.*)\]")


def summary_statistics(run: Run) -> dict[str, tuple[str, float | None]]:
    """``<statistic>[<pair>]`` -> (unit, value) for each contact pair and each force column of ``summary``.

    The force columns are those in N (peak, mean, RMS of the normal and
    tangential force over ``record.summary_window``); empty without a
    ``summary`` table.
    """
    summary = run.tables.get("summary")
    if summary is None:
        return {}
    units = {f.name: (f.metadata or {}).get(b"unit", b"").decode() for f in summary.schema}
    stats = [name for name, unit in units.items() if unit == "N"]
    out: dict[str, tuple[str, float | None]] = {}
    for row in summary.select(["pair", *stats]).to_pylist():
        for stat in stats:
            out[f"{stat}[{row['pair']}]"] = ("N", row[stat])
    return out


class SummaryStatistics:
    """A plug-in of scenes of bodies: each contact pair's summary statistics (`summary_statistics`), in N."""

    def columns(self, recorded: Collection[str]) -> dict[str, tuple[str, str]]:
        out: dict[str, tuple[str, str]] = {}
        for name in sorted(recorded):
            m = _STATISTIC.fullmatch(name)
            if m is not None:
                out[name] = ("N", f"summary.{m['column']} of contact pair {m['pair']} (over record.summary_window)")
        return out

    def __call__(self, run: Run) -> dict[str, float | None]:
        return {name: value for name, (_, value) in summary_statistics(run).items()}

    def __repr__(self) -> str:
        return "ballcage.studies.sweep_quantities.SUMMARY_STATISTICS"


SUMMARY_STATISTICS = SummaryStatistics()


#: The shortest fatigue life and wear life: name -> (unit, meaning).
LIVES: dict[str, tuple[str, str]] = {
    "fatigue_life_min_h": (
        "h",
        "shortest fatigue life of any link section (neck, body, seat) in hours of this duty: Basquin-Goodman and "
        "Miner over the steady window (ballcage.measures.fatigue, fatigue.*); null for an ideal-CV hinge, a run too "
        "short for a steady window, or no damage",
    ),
    "wear_hours_min_h": (
        "h",
        "hours of this duty until the wear map's deepest cell reaches wear.map_depth (Archard k/H over the frames, "
        "ballcage.measures.wear_map, wear.*); null where nothing wears",
    ),
}

#: Seconds of one core per simulated second the lives take (fatigue 0.73 s and wear map 0.79 s for the paper's 1.8 s;
#: the ideal-CV hinge has the wear map only, 0.50 s; this project's machine, 2026-11-26), for the estimates.
LIVES_SECONDS_PER_SIMULATED_SECOND: dict[str, float] = {"ball-keys": 0.85, "ideal-cv": 0.3}


def lives(run: Run) -> dict[str, float | None]:
    """`LIVES` of a drill-pipe run: ``None`` where the run cannot give one (`InputError`: an ideal-CV hinge, a
    table not recorded, a run too short for its steady window)."""
    from ballcage.measures.fatigue import fatigue_table  # deferred: only plug-ins that measure lives pay for them
    from ballcage.measures.wear_map import deepest, wear_map

    out: dict[str, float | None] = dict.fromkeys(LIVES)
    try:
        hours = [h for h in fatigue_table(run).column("hours_to_failure").to_pylist() if h is not None]
        out["fatigue_life_min_h"] = min(hours) if hours else None
    except InputError:
        pass
    try:
        row = deepest(wear_map(run))
        out["wear_hours_min_h"] = float(row["hours_to_depth"]) if row is not None else None
    except InputError:
        pass
    return out


class DrillPipeLives:
    """A drill pipe's `DRILL_PIPE` quantities and its `LIVES`.

    The lives need every frame's contacts: each run records ``memory_tables`` for them, which a sweep does not keep.
    """

    #: Tables each run records for the lives and the sweep does not keep (`ballcage.studies.sweep_case.run_case`).
    memory_tables: tuple[str, ...] = ("bodies", "contacts", "pairs")

    def columns(self, recorded: Collection[str]) -> dict[str, tuple[str, str]]:
        return DRILL_PIPE.columns(recorded) | LIVES

    def __call__(self, run: Run) -> dict[str, float | None]:
        out = DRILL_PIPE(run)
        return out | lives(run) if out else out

    def __repr__(self) -> str:
        return "ballcage.studies.sweep_quantities.DRILL_PIPE_LIVES"


DRILL_PIPE_LIVES = DrillPipeLives()


def for_scene(scene: _native.Scene) -> SweepQuantities:
    """The plug-in of `scene`'s kind: `ballcage.measures.DRILL_PIPE` for a drill pipe, else `GENERIC`."""
    return DRILL_PIPE if scene.kind == "drill-pipe" else GENERIC
