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
  ``ballcage sweep``, ``ballcage chart`` and ``ballcage paper --sweeps`` pass it.

`for_scene` picks one of these by the scene's kind when a caller passes none.
"""

from __future__ import annotations

import re
from collections.abc import Collection
from typing import TYPE_CHECKING, Protocol, runtime_checkable

from ballcage.measures.quantities import DRILL_PIPE

if TYPE_CHECKING:
    from ballcage import _native
    from ballcage.run import Run

__all__ = [
    "GENERIC",
    "SUMMARY_STATISTICS",
    "GenericQuantities",
    "SummaryStatistics",
    "SweepQuantities",
    "for_scene",
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


def for_scene(scene: _native.Scene) -> SweepQuantities:
    """The plug-in of `scene`'s kind: `ballcage.measures.DRILL_PIPE` for a drill pipe, else `GENERIC`."""
    return DRILL_PIPE if scene.kind == "drill-pipe" else GENERIC
