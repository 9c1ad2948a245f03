"""The paper's §4.2–4.3 as one sweep (``ballcage paper --sweeps``), on the sweep machinery of `ballcage.sweep`.

Each case records the drill pipe's quantities (`ballcage.measures.DRILL_PIPE`);
none runs the paper's comparison. Unless ``--no-verify``, every case runs
again ten times tighter (`ballcage.studies.sweep_spec.with_verification`),
and the trends weigh each change against that numerical error.

The cases, on the paper scene with the user's overrides:

- §4.2: ``borehole.curvature_radius`` = `SECTION4_RADII` (1.0–2.5 m) at 100 rpm;
- §4.3: ``drive.speed_rpm`` = `SECTION4_SPEEDS` (60–120 rpm) at R = 1.5 m;
- the run-to-run spread: the baseline (1.5 m, 100 rpm) again with R moved by
  ± `SPREAD_OFFSET` (1 µm), which moves every placed body by at most 1 µm.

The baseline is one case, shared by both series. The sweep folder is
``DIR/sweeps`` (``summary.parquet``, the hive-partitioned tables, the
per-parameter plots); running the same command again resumes it, skipping
finished cases. The swept keys are applied after the user's ``--set``
overrides, so a ``--set`` of either key is overridden in the sweep.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pyarrow as pa
import pyarrow.compute as pc

from ballcage import _native
from ballcage._native import InputError
from ballcage._links import summary_window
from ballcage.measures.quantities import DRILL_PIPE
from ballcage.paper.definitions import BASELINE_RADIUS, BASELINE_RPM, SECTION4_RADII, SECTION4_SPEEDS, SWEEPS
from ballcage.run import Run
from ballcage.scene import default_scene
from ballcage.studies.sweep_case import read_case_run
from ballcage.studies.sweep_run import SweepResult, sweep
from ballcage.studies.sweep_spec import DEFAULT_TABLES, SweepSpec

__all__ = [
    "RADIUS_KEY",
    "RPM_KEY",
    "SPREAD_OFFSET",
    "Section4",
    "averaging_windows",
    "run_section4",
    "section4_spec",
    "series_rows",
    "spread_rows",
]

RADIUS_KEY = "borehole.curvature_radius"
RPM_KEY = "drive.speed_rpm"
#: The baseline's radius is moved by ± this much [m] for the run-to-run spread.
SPREAD_OFFSET = 1e-6
#: Two swept values closer than this are the same case value [m or rpm].
_SAME = 1e-9


@dataclass
class Section4:
    """The section-4 sweep's result and the runs of its finished cases, by (R [m], rpm)."""

    result: SweepResult
    runs: dict[tuple[float, float], Run]

    @property
    def summary(self) -> pa.Table:
        """The sweep's summary without its verification runs' rows (`with_verification`): one row per case, with
        each quantity's numerical error when the sweep verified its cases."""
        table = self.result.summary
        if "verifies" not in table.column_names:
            return table
        return table.filter(pc.is_null(table.column("verifies")))

    def variant_runs(self) -> dict[str, Run]:
        """The runs of the reference file's sweep variants (`SWEEPS` ids) that finished."""
        return {vid: run for vid, v in SWEEPS.items() if (run := _find(self.runs, v.radius, v.rpm)) is not None}

    def curvature_runs(self) -> dict[float, Run]:
        """§4.2: R [m] → run at the baseline speed, for the radii that finished."""
        return {r: run for r in SECTION4_RADII if (run := _find(self.runs, r, BASELINE_RPM)) is not None}

    def speed_runs(self) -> dict[float, Run]:
        """§4.3: rpm → run at the baseline radius, for the speeds that finished."""
        return {s: run for s in SECTION4_SPEEDS if (run := _find(self.runs, BASELINE_RADIUS, s)) is not None}

    def window_rows(self, window: tuple[float, float]) -> list[dict[str, Any]]:
        """Summary-like rows of the finished cases with their quantities averaged over `window` [s] instead.

        Recomputed from the recorded tables (`ballcage.measures.DRILL_PIPE` on each run with
        ``record.summary_window`` replaced): nothing is run again.
        """
        rows = []
        for (radius, rpm), run in self.runs.items():
            scene = _native.Scene.from_toml(run.scene_toml, [f"record.summary_window=[{window[0]!r}, {window[1]!r}]"])
            moved = Run(run.tables, scene.to_toml(), error=run.error, scene=scene)
            rows.append({"status": "ok", RADIUS_KEY: radius, RPM_KEY: rpm, **DRILL_PIPE(moved)})
        return rows

    def other_windows(self) -> dict[str, list[dict[str, Any]]]:
        """`window_rows` for each of `averaging_windows` that differs from the scene's own window, by label."""
        if not self.runs:
            return {}
        scene = next(iter(self.runs.values())).scene
        own = summary_window(scene)
        return {
            f"{a:g}-{b:g} s": self.window_rows((a, b))
            for a, b in averaging_windows(scene)
            if not (math.isclose(a, own[0]) and (math.isclose(b, own[1]) or math.isinf(own[1])))
        }


def averaging_windows(scene: _native.Scene) -> list[tuple[float, float]]:
    """Windows [s] the trends are also checked over: after the drive and load ramps, and the run's second half."""
    duration = float(scene.value("simulation.duration"))
    ramps = max(float(scene.value("drive.ramp")), float(scene.value("load.ramp")))
    return [(w, duration) for w in (ramps, duration / 2.0) if w < duration]


def section4_spec(overrides: Iterable[str] = ()) -> SweepSpec:
    """The section-4 sweep on the paper scene with `overrides` (``key=value``); raises `ballcage.SceneError`."""
    base = default_scene(list(overrides))
    cases: list[tuple[float, float]] = [(r, BASELINE_RPM) for r in SECTION4_RADII]
    cases += [(BASELINE_RADIUS, s) for s in SECTION4_SPEEDS if not _same(s, BASELINE_RPM)]
    cases += [(BASELINE_RADIUS + SPREAD_OFFSET, BASELINE_RPM), (BASELINE_RADIUS - SPREAD_OFFSET, BASELINE_RPM)]
    return SweepSpec(
        name="paper-section-4",
        base_toml=base.to_toml(),
        tables=list(DEFAULT_TABLES),
        listed=[{RADIUS_KEY: r, RPM_KEY: s} for r, s in cases],
        source="ballcage paper --sweeps",
    )


def run_section4(
    out: str | os.PathLike[str],
    spec: SweepSpec,
    *,
    client: Any = None,
    workers: int | None = None,
    progress: bool | None = None,
) -> Section4:
    """Runs (or resumes) the section-4 sweep `spec` into `out` and reads back its finished cases' runs.

    Each case's quantities are the drill pipe's (`ballcage.measures.DRILL_PIPE`), the summary columns
    the trends are checked on; the comparison's own rows are built once, from the variants' runs.
    """
    result = sweep(spec, out, client=client, workers=workers, progress=progress, quantities=DRILL_PIPE)
    runs: dict[tuple[float, float], Run] = {}
    for row in result.summary.to_pylist():
        if row["status"] == "ok" and row.get("verifies") is None:
            runs[(float(row[RADIUS_KEY]), float(row[RPM_KEY]))] = read_case_run(Path(out), int(row["case"]))
    return Section4(result, runs)


def spread_rows(rows: Iterable[Mapping[str, Any]]) -> list[Mapping[str, Any]]:
    """The summary rows of the baseline and its two ± `SPREAD_OFFSET` copies (status ok)."""
    return [
        r
        for r in rows
        if r["status"] == "ok"
        and _same(float(r[RPM_KEY]), BASELINE_RPM)
        and abs(float(r[RADIUS_KEY]) - BASELINE_RADIUS) <= SPREAD_OFFSET * 1.5
    ]


def series_rows(rows: Iterable[Mapping[str, Any]], parameter: str) -> list[Mapping[str, Any]]:
    """The rows of one series (ok), sorted by `parameter`: §4.2 for the radius, §4.3 for the speed."""
    if parameter == RADIUS_KEY:
        chosen = [r for r in rows if _same(float(r[RPM_KEY]), BASELINE_RPM)
                  and any(_same(float(r[RADIUS_KEY]), x) for x in SECTION4_RADII)]
    elif parameter == RPM_KEY:
        chosen = [r for r in rows if _same(float(r[RADIUS_KEY]), BASELINE_RADIUS)
                  and any(_same(float(r[RPM_KEY]), x) for x in SECTION4_SPEEDS)]
    else:
        raise InputError(f"parameter = {parameter!r}: the section-4 sweep varies {RADIUS_KEY} and {RPM_KEY}")
    return sorted((r for r in chosen if r["status"] == "ok"), key=lambda r: float(r[parameter]))


def _find(runs: Mapping[tuple[float, float], Run], radius: float, rpm: float) -> Run | None:
    for (r, s), run in runs.items():
        if _same(r, radius) and _same(s, rpm):
            return run
    return None


def _same(a: float, b: float) -> bool:
    return math.isclose(a, b, rel_tol=0.0, abs_tol=_SAME)
