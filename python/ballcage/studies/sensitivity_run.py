"""A sensitivity study (``ballcage sensitivity``): how much each unstated parameter moves each quantity.

`sensitivity(scene, out)` varies the parameters of
`ballcage.studies.sensitivity_parameters` (by default every registry
parameter of the scene's kind) and measures the quantities of
`ballcage.studies.sensitivity_quantities` in each run:

- ``method="oat"``: the base run, then each parameter at its low and at its
  high value with the others at the base (at most 1 + 2·P runs);
- ``method="morris"``: Morris elementary effects over the ranges, the design
  and the analysis by SALib (`SALib.sample.morris.sample`,
  `SALib.analyze.morris.analyze`; the optional extra ``ballcage[sensitivity]``):
  the base run and `trajectories`·(P + 1) runs on a grid of `levels` levels.

The runs are one sweep of listed cases (`ballcage.studies.sweep_run.sweep`:
local threads or a Dask cluster, a diverging run recorded and the others going
on, resumed when run again into the same folder). Unless ``verify=False``, the
last case is the base run at the setting of ``ballcage run --verify``
(`ballcage.studies.refinement.tighter`: ``rtol/10`` or ``dt/d``): the
difference is the base run's measured numerical error on each quantity, the
bar a parameter's effect must exceed to be resolved. Without it, the
integrator's own estimate of the global position error
(``ballcage.error_estimate_position_m``, adaptive steps only) serves for the
quantities that are lengths, and the others have none.

Each run may take `case_timeout` seconds of wall time (``--case-timeout``):
by default (``"auto"``) `TIMEOUT_FACTOR` times the estimated time of the
study's longest run (the verification run's, d runs for ``dt/d``), never below
`TIMEOUT_FLOOR_S`, and no limit when there is no estimate (a scene of bodies
whose base run has not finished). A run past it is recorded ``timed-out``
and the others go on; running the study again runs it again. Written into ``out``::

    sensitivity.parquet           one row per quantity and parameter (`SENSITIVITY_SCHEMA`)
    sensitivity.md                the parameters ranked for each quantity (`sensitivity_report`)
    plots/tornado_<quantity>.png  one tornado chart per quantity (`sensitivity_plot`)
    runs/                         the sweep: summary.parquet, <table>/case=NNNN/, cases/ (docs/studies.md)

The cases are `ballcage.studies.sensitivity_design`'s, the table's rows
`ballcage.studies.sensitivity_effects`'s. Every value is in the scene's units
(SI; contact laws in theirs).
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import pyarrow as pa

from ballcage import _native
from ballcage._files import write_parquet, write_text
from ballcage._native import InputError
from ballcage.scene import SceneSource, override_list
from ballcage.studies.common import check_duration, resolve
from ballcage.studies.refinement import cost_factor
from ballcage.studies.schemas import SENSITIVITY_SCHEMA
from ballcage.studies.sensitivity_design import (
    DEFAULT_LEVELS,
    DEFAULT_SEED,
    DEFAULT_TRAJECTORIES,
    METHODS,
    Design,
    add_check,
    check_morris,
    morris_design,
    oat_design,
)
from ballcage.studies.sensitivity_effects import sensitivity_table
from ballcage.studies.sensitivity_parameters import ParameterChoice, parameter_ranges
from ballcage.studies.sensitivity_quantities import for_scene, tables_for
from ballcage.studies.sweep_case import PART, read_record, table_path
from ballcage.studies.sweep_quantities import LIVES_SECONDS_PER_SIMULATED_SECOND
from ballcage.studies.sweep_run import SweepResult, checked_case_timeout, pending_work, shared_runs, sweep
from ballcage.studies.sweep_spec import SweepError, SweepSpec, partition_name

__all__ = ["PLOTS", "REPORT_FILE", "RUNS", "TABLE_FILE", "Sensitivity", "describe", "sensitivity"]

#: The files and folders a study writes into its ``out``.
TABLE_FILE, REPORT_FILE, PLOTS, RUNS = "sensitivity.parquet", "sensitivity.md", "plots", "runs"
#: ``case_timeout="auto"`` (the default): each run may take this many times the estimated time of the longest run,
TIMEOUT_FACTOR = 10.0
#: and never less than this [s] (an estimate of a short study is dominated by start-up and other jobs' load).
TIMEOUT_FLOOR_S = 60.0


@dataclass
class Sensitivity:
    """What `sensitivity` did: the table, the folder, the files written, the sweep, the estimate and the time taken."""

    table: pa.Table
    out: Path
    paths: dict[str, Path]
    sweep: SweepResult
    estimate_s: float | None
    elapsed_s: float
    #: The wall time [s] each run was allowed (`case_timeout`); ``None``: no limit.
    case_timeout_s: float | None = None

    @property
    def failed(self) -> int:
        return self.sweep.failed


def sensitivity(
    scene: SceneSource | None,
    out: str | os.PathLike[str],
    *,
    parameters: ParameterChoice = None,
    method: str = "oat",
    trajectories: int = DEFAULT_TRAJECTORIES,
    levels: int = DEFAULT_LEVELS,
    seed: int = DEFAULT_SEED,
    overrides: Iterable[str] = (),
    duration: float | None = None,
    verify: bool = True,
    registry: pa.Table | None = None,
    workers: int | None = None,
    client: Any = None,
    plots: bool = True,
    progress: bool | None = None,
    command: str | None = None,
    case_timeout: float | str | None = "auto",
) -> Sensitivity:
    """Runs the sensitivity study of `scene` (``None``: the embedded paper scene) into the folder `out`.

    `parameters`: ``None`` (every registry parameter of the scene's kind), a
    list of registry keys, or a dict ``key -> (low, high)`` in the scene's
    units (``key -> None``: the registry's range); see
    `ballcage.studies.sensitivity_parameters`. `method`: ``"oat"`` or
    ``"morris"`` (`trajectories` ≥ 2, `levels` even ≥ 2, `seed` of SALib's
    design). `overrides` (``key=value``) and `duration` [s] change the base
    scene. `verify`: add the base run at ``ballcage run --verify``'s tighter
    setting for the numerical error. `registry`: the registry table (default
    ``ballcage.proposals()``). `workers`, `client`, `progress`: as for
    `ballcage.studies.sweep_run.sweep`; `plots`: draw the tornado charts;
    `command`: the command line for the report (default a description of
    this call). `case_timeout`: wall time [s] each run may take, ``None`` or 0
    for no limit, ``"auto"`` (the default) `TIMEOUT_FACTOR` times the
    estimated time of the longest run and at least `TIMEOUT_FLOOR_S`, or no
    limit when nothing gives an estimate; a run past it is recorded
    ``timed-out`` (`ballcage.studies.sweep_run.sweep`). Raises `InputError`,
    `ballcage.SceneError` or `SweepError` for bad input, before anything runs.
    """
    start = time.perf_counter()
    method = _checked_method(method)
    limit = None if case_timeout == "auto" else checked_case_timeout(case_timeout)
    check_duration(duration)
    if method == "morris":
        check_morris(trajectories, levels, seed)
    patches = override_list(overrides) + ([f"simulation.duration={float(duration)!r}"] if duration is not None else [])
    base = resolve(scene, patches)
    ranges = parameter_ranges(base, parameters, registry)
    design = oat_design(ranges) if method == "oat" else morris_design(ranges, trajectories, levels, seed)
    if verify:
        add_check(design, base)
    folder = Path(out)
    if folder.exists() and not folder.is_dir():
        raise SweepError(f"out = {str(folder)!r}: exists and is not a directory")
    spec = SweepSpec(name="sensitivity", base_toml=base.to_toml(), tables=tables_for(base), listed=design.values,
                     source="sensitivity")
    spec.check()
    runs = folder / RUNS
    per_run = _per_run(base, runs)
    run_of = shared_runs(spec, spec.cases())
    estimate = _estimate(per_run, design, runs, pending_work(spec, runs, run_of), workers, client,
                         _lives_rate(base) * base.duration)  # fmt: skip
    if case_timeout == "auto":
        limit = _default_case_timeout(per_run[0], design)
    say: Callable[[str], None] = _say if progress is not False else (lambda _: None)
    say(_plan(base, design, estimate, limit, case_timeout == "auto", sum(1 for k, v in run_of.items() if k != v)))
    quantities = for_scene(base)
    result = sweep(spec, runs, client=client, workers=workers, plots=False, progress=progress, quantities=quantities,
                   case_timeout=limit)  # fmt: skip
    table = sensitivity_table(result.summary, design, _base_metadata(runs), spec.parameters)
    call = command or _python_call(scene, folder, design, patches, verify, False if case_timeout == "auto" else limit)
    meta = _file_metadata(base, design, patches, call, limit)
    meta["ballcage.sensitivity.shared_runs"] = str(
        sum(1 for r in result.summary.to_pylist() if r["run_of"] != r["case"] and design.roles[r["case"]].kind != "verify")
    )
    table = table.replace_schema_metadata({**meta, **(SENSITIVITY_SCHEMA.metadata or {})} | _units_metadata())
    paths = _write(table, folder, plots)
    return Sensitivity(table, folder, paths, result, estimate[0], time.perf_counter() - start, limit)


# --------------------------------------------------------------------------- checks


def _checked_method(method: str) -> str:
    if method not in METHODS:
        raise InputError(f"method = {method!r}: not a method (methods: {', '.join(METHODS)})")
    return method


def _default_case_timeout(per_run: float | None, design: Design) -> float | None:
    """``case_timeout="auto"``: `TIMEOUT_FACTOR` x the longest run's estimate, at least `TIMEOUT_FLOOR_S`; None
    without an estimate."""
    if per_run is None:
        return None
    longest = per_run * max(1.0, cost_factor(design.check.label) if design.check is not None else 1.0)
    return max(TIMEOUT_FLOOR_S, TIMEOUT_FACTOR * longest)


# --------------------------------------------------------------------------- the estimate


def _per_run(base: _native.Scene, runs: Path) -> tuple[float | None, str]:
    """Seconds one run of the study should take, its quantities included, and what that rests on; None when nothing
    tells (a scene of bodies whose base run has not run yet)."""
    per_run, basis = _base_wall_time(runs), "at the base run's measured time"
    if per_run is None and base.kind == "drill-pipe":
        from ballcage.studies.design_chart import SECONDS_PER_SIMULATED_SECOND

        hinge = str(base.value("pipe.hinge"))
        rate = SECONDS_PER_SIMULATED_SECOND.get(hinge, 10.0) + _lives_rate(base)
        per_run = rate * base.duration
        basis = (f"{hinge}, {base.duration:g} s each at ~{rate:g} s per simulated s on one core of a 2-core AMD EPYC, "
                 "the lives included; a rough guide")
    return per_run, basis


def _lives_rate(base: _native.Scene) -> float:
    """Seconds per simulated second [–] a drill pipe's fatigue and wear lives take (`LIVES_SECONDS_PER_SIMULATED_SECOND`)."""
    return LIVES_SECONDS_PER_SIMULATED_SECOND.get(str(base.value("pipe.hinge")), 1.0) if base.kind == "drill-pipe" else 0.0


def _estimate(
    one_run: tuple[float | None, str],
    design: Design,
    runs: Path,
    pending: tuple[int, int],
    workers: int | None,
    client: Any,
    lives: float = 0.0,
) -> tuple[float | None, str]:
    """Seconds the pending runs (and the cases that share them, at `lives` seconds each) should take and what that
    rests on (`_per_run`); None when nothing tells."""
    per_run, basis = one_run
    pending, shared = pending
    if per_run is None:
        return None, ""
    if client is not None:
        info: dict[str, Any] = client.scheduler_info() if hasattr(client, "scheduler_info") else {}
        parallel = max(1, len(info.get("workers", {})))
    else:
        parallel = workers or os.cpu_count() or 1
    pending_check = design.check is not None and _pending(runs, len(design.roles) - 1)
    check = cost_factor(design.check.label) if pending_check and design.check is not None else 0.0
    work = pending - (1 if check else 0) + check
    seconds = per_run * max(math.ceil(work / parallel), check) if work > 0 else 0.0
    seconds += lives * shared  # in the worker of the run they share, one after another
    where = "on the Dask cluster" if client is not None else f"in {parallel} local threads"
    also = f" and {shared} cases from their runs" if shared else ""
    return seconds, f"{pending} runs to run{also} {where}, {basis}"


def _pending(runs: Path, index: int) -> bool:
    return read_record(runs, partition_name(index)) is None


def _base_wall_time(runs: Path) -> float | None:
    record = read_record(runs, partition_name(0))
    value = record.get("case_wall_time_s") if record is not None and record.get("status") == "ok" else None
    return float(value) if isinstance(value, (int, float)) else None


def _plan(
    base: _native.Scene, design: Design, estimate: tuple[float | None, str], limit: float | None, auto: bool,
    shared: int = 0,
) -> str:
    """The line printed before the study runs: what it runs, how long it should take and each run's time limit;
    `shared`: the cases that share another case's run (`shared_runs`)."""
    p = len(design.ranges)
    what = (
        "the base and each parameter at its low and its high value"
        if design.method == "oat"
        else f"the base and {design.trajectories} Morris trajectories of {p + 1} runs on {design.levels} levels"
    )
    if design.check is not None:
        what += f", and the base at {design.check.label} for the numerical error"
    head = f"sensitivity ({design.method}) to {p} parameters of the {base.kind} scene: {len(design.roles)} runs ({what})"
    if shared:
        head += (f"; {shared} of them not run but computed from another run's tables: their scene's engine digest is "
                 "that run's (the parameter enters only what is computed from the tables, or nothing this scene "
                 "builds)")
    seconds, basis = estimate
    if seconds is None:
        plan = f"{head}; no estimate before the base run of a scene of bodies has finished (the progress shows the time left)"
    else:
        plan = f"{head}; about {_duration(seconds)} ({basis})"
    if limit is None:
        return plan + ("; no time limit per run (no estimate; --case-timeout sets one)" if auto else "")
    why = f"{TIMEOUT_FACTOR:g}x the estimate of the longest run, at least {TIMEOUT_FLOOR_S:g} s" if auto else "given"
    return plan + f"; each run stopped after {_duration(limit)} (--case-timeout: {why})"


def _duration(seconds: float) -> str:
    return f"{seconds:.0f} s" if seconds < 120 else f"{int(seconds // 60)} min {seconds % 60:.0f} s"


def _base_metadata(runs: Path) -> dict[str, str]:
    """The base run's metadata (ballcage.*), from the schema of one of its table files; empty when it has none."""
    import pyarrow.parquet as pq

    partition = partition_name(0)
    record = read_record(runs, partition)
    for name in (record or {}).get("tables", []):
        path = table_path(runs, name, partition)
        if path.name == PART and path.is_file():
            meta = pq.read_schema(path).metadata or {}
            return {k.decode(): v.decode() for k, v in meta.items()}
    return {}


# --------------------------------------------------------------------------- files


def _file_metadata(
    base: _native.Scene, design: Design, patches: Sequence[str], command: str, limit: float | None
) -> dict[str, str]:
    ranges = [
        {"key": r.key, "low": r.low, "high": r.high, "base": r.base, "unit": r.unit, "source": r.source,
         "reference": r.reference, "meaning": r.meaning, "range_reason": r.range_reason}
        for r in design.ranges
    ]  # fmt: skip
    return {
        "ballcage.version": _native.__version__,
        "ballcage.table": "sensitivity",
        "ballcage.row": "one row per quantity and parameter",
        "ballcage.sensitivity.method": design.method,
        "ballcage.sensitivity.command": command,
        "ballcage.sensitivity.date": datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "ballcage.sensitivity.scene_kind": base.kind,
        "ballcage.sensitivity.scene_name": base.name,
        "ballcage.sensitivity.duration_s": repr(base.duration),
        "ballcage.sensitivity.overrides": json.dumps(list(patches)),
        "ballcage.sensitivity.parameters": json.dumps(ranges),
        "ballcage.sensitivity.runs": str(sum(1 for r in design.roles if r.kind != "verify")),
        "ballcage.sensitivity.verification": design.check.label if design.check is not None else "",
        "ballcage.sensitivity.case_timeout_s": "" if limit is None else repr(limit),
        "ballcage.sensitivity.trajectories": "" if design.trajectories is None else str(design.trajectories),
        "ballcage.sensitivity.levels": "" if design.levels is None else str(design.levels),
        "ballcage.sensitivity.seed": "" if design.seed is None else str(design.seed),
    }


def _units_metadata() -> dict[str, str]:
    return {
        "ballcage.units": json.dumps({f.name: f.metadata[b"unit"].decode() for f in SENSITIVITY_SCHEMA}),
        "ballcage.descriptions": json.dumps({f.name: f.metadata[b"description"].decode() for f in SENSITIVITY_SCHEMA}),
    }


def _write(table: pa.Table, out: Path, plots: bool) -> dict[str, Path]:
    from ballcage.studies.sensitivity_report import sensitivity_markdown

    out.mkdir(parents=True, exist_ok=True)
    charts: dict[str, Path] = {}
    if plots:
        from ballcage.studies.sensitivity_plot import write_tornados  # deferred: matplotlib

        charts = write_tornados(table, out / PLOTS)
    paths = {"table": write_parquet(table, out / TABLE_FILE)}
    paths["report"] = write_text(sensitivity_markdown(table, charts, out), out / REPORT_FILE)
    paths.update({f"tornado_{q}": p for q, p in charts.items()})
    return paths


def _python_call(
    scene: Any, out: Path, design: Design, patches: Sequence[str], verify: bool, limit: float | None | bool = False
) -> str:
    """This call as the equivalent ``ballcage sensitivity`` command line, where the scene is a file or the default."""
    import shlex

    if scene is not None and not isinstance(scene, (str, os.PathLike)):
        return f"ballcage.sensitivity(<{type(scene).__name__}>, {str(out)!r}, method={design.method!r}, ...) (Python)"
    args = ["ballcage", "sensitivity", *([os.fspath(scene)] if scene is not None else []), "--out", str(out)]
    args += ["--parameters", ",".join(
        f"{r.key}={r.low!r}:{r.high!r}" if r.source == "given" else r.key for r in design.ranges)]
    args += ["--method", design.method]
    if design.method == "morris":
        args += ["--trajectories", str(design.trajectories), "--levels", str(design.levels), "--seed", str(design.seed)]
    for patch in patches:
        args += ["--set", patch]
    if not verify:
        args.append("--no-verify")
    if limit is not False:  # given (None: no limit), not the default
        args += ["--case-timeout", f"{limit or 0:g}"]
    return shlex.join(args)


def _say(text: str) -> None:
    print(f"ballcage: {text}", file=sys.stderr, flush=True)


def describe(result: Sensitivity) -> Iterable[str]:
    """Lines the CLI prints after a study: the files, the runs, the time against the estimate."""
    rows = result.table.num_rows
    quantities = len(set(result.table.column("quantity").to_pylist()))
    yield f"wrote {result.paths['table']}  ({rows} rows: {quantities} quantities x parameters)"
    yield f"wrote {result.paths['report']}  (the parameters ranked for each quantity)"
    charts = [p for k, p in result.paths.items() if k.startswith("tornado_")]
    if charts:
        yield f"wrote {len(charts)} tornado charts in {charts[0].parent}"
    yield f"wrote {result.sweep.paths['summary']}  (the study's runs, one row each)"
    guess = f", estimated {_duration(result.estimate_s)}" if result.estimate_s is not None else ""
    shared = result.sweep.shared
    reused = f" ({shared} of them not simulated: from another run's tables, the same engine digest)" if shared else ""
    yield (
        f"ballcage: {result.sweep.ran} runs run{reused}, {result.sweep.skipped} skipped (already finished), "
        f"{result.failed} not ok; {_duration(result.elapsed_s)} in all{guess}"
    )
