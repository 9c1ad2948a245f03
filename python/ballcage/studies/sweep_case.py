"""One sweep case where it runs (a local thread or a Dask worker): run, write its files, write its record.

`run_case` is the only function a worker executes. It writes straight into
the sweep's output folder (on Dask, a filesystem every worker and the client
share): ``DIR/<table>/case=NNNN/part.parquet`` for each recorded table, then
``DIR/cases/case=NNNN.scene.toml`` and, last, the case's record
``DIR/cases/case=NNNN.json`` (a JSON object: status, error, swept values,
engine cost, and the quantities of the task's plug-in,
`ballcage.studies.sweep_quantities.SweepQuantities`). Every file is written to a
temporary name and renamed, so a file under its final name is complete, and a
case with a record is finished. A run that diverges keeps what it recorded up
to then (status ``diverged``); so does a run stopped at the case's time limit
(``CaseTask.timeout``, ``--case-timeout``: status ``timed-out``); any other
failure is status ``error``; none is raised. A case whose scene has the
same engine digest as an earlier case's (`Scene.engine_digest`) is not run:
the worker of that case computes its quantities from that run with its own
scene (`derive_case`) and writes its scene and record (``run_of``: the case
whose tables it reads), no tables of its own.
"""

from __future__ import annotations

import json
import math
import time
import traceback
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ballcage import _native
from ballcage._files import write_parquet, write_text
from ballcage.run import Run, TimeLimitError, simulate
from ballcage.studies.sweep_quantities import GENERIC, SweepQuantities
from ballcage.studies.sweep_spec import partition_name, toml_value

__all__ = [
    "TIMED_OUT", "CaseTask", "derive_case", "read_case_run", "read_record", "record_path", "run_case", "scene_path",
    "write_record",
]

#: Name of every table file inside a case's partition directory.
PART = "part.parquet"
#: Folder of the per-case records and scenes.
CASES = "cases"
#: The status of a case stopped at its time limit (`CaseTask.timeout`); such a case is run again on resume.
TIMED_OUT = "timed-out"


@dataclass(frozen=True)
class CaseTask:
    """Everything a worker needs for one case (plain data: it is pickled to Dask workers)."""

    index: int
    case_id: str
    digest: str
    partition: str  # "case=0003"
    base_toml: str
    overrides: tuple[str, ...]
    values: dict[str, Any]  # swept key -> value as written
    parameters: tuple[str, ...]  # every swept key of the sweep, for the resolved values
    out: str  # the sweep's output folder
    quantities: SweepQuantities = GENERIC  # what the record's "quantities" hold (pickled with the task)
    timeout: float | None = None  # s of wall time the case's run may take (--case-timeout); None: no limit
    shares: tuple[CaseTask, ...] = ()  # cases with this one's engine digest, derived from its run (`derive_case`)


def record_path(out: Path, partition: str) -> Path:
    """Where the record of the case in `partition` lives: ``DIR/cases/case=NNNN.json``."""
    return out / CASES / f"{partition}.json"


def table_path(out: Path, table: str, partition: str) -> Path:
    return out / table / partition / PART


def run_case(task: CaseTask) -> dict[str, Any]:
    """Runs one case, writes its tables, scene and record into ``task.out``; returns the record (a dict).

    The cases of ``task.shares`` (the same engine digest) are not run: `derive_case` gives their records from this
    run, under the record's ``"shared"``. Tables the quantities plug-in reads beyond the case's ``record.tables``
    (its ``memory_tables``) are recorded for the quantities and not written.
    """
    start = time.perf_counter()
    out = Path(task.out)
    scene = _native.Scene.from_toml(task.base_toml, list(task.overrides))
    run: Run | None = None
    status, error = "ok", None
    kept = [str(t) for t in scene.value("record.tables")] if scene.kind == "drill-pipe" else None
    try:
        run = simulate(_with_tables(task, scene, kept), progress=False, time_limit=task.timeout)
    except _native.SimulationError as e:
        run, status, error = getattr(e, "run", None), "diverged", str(e)
    except TimeLimitError as e:
        run, status, error = e.run, TIMED_OUT, _timed_out(task, e)
    except Exception as e:  # noqa: BLE001 - a failing case is recorded, never raised
        status, error = "error", _describe(e)
    record = _base_record(task, scene, status, error)
    try:
        if run is not None:
            record["tables"] = _write_tables(run, out, task.partition, kept)
            record.update(_cost(run))
            record["quantities"] = task.quantities(run)
    except Exception as e:  # noqa: BLE001
        record["status"], record["error"] = "error", _join(error, f"after the run: {_describe(e)}")
    _write_scene(out, task.partition, scene)
    record["case_wall_time_s"] = time.perf_counter() - start
    write_record(out, record)
    record["shared"] = [derive_case(t, record, run) for t in task.shares]
    return record


def _with_tables(task: CaseTask, scene: _native.Scene, kept: list[str] | None) -> _native.Scene:
    """`scene`, recording also the tables the quantities plug-in reads (``memory_tables``) that it does not; `scene`
    itself where they would not fit ``record.max_bytes`` (the quantities that need them are then null)."""
    extra = [t for t in getattr(task.quantities, "memory_tables", ()) if kept is not None and t not in kept]
    if not extra:
        return scene
    try:
        return _native.Scene.from_toml(task.base_toml, [*task.overrides, f"record.tables={toml_value([*kept, *extra])}"])
    except _native.SceneError:
        return scene


def derive_case(task: CaseTask, source: dict[str, Any], run: Run | None) -> dict[str, Any]:
    """The record of a case that shares the `run` of the case of record `source` (the same `Scene.engine_digest`):
    its quantities from that run's tables with its own scene, bitwise what running it would give (the engine is
    deterministic); its status and error are that run's. Writes its scene and record into ``task.out``; no tables
    (``run_of`` names the case whose tables it reads)."""
    start = time.perf_counter()
    out = Path(task.out)
    scene = _native.Scene.from_toml(task.base_toml, list(task.overrides))
    record = _base_record(task, scene, source["status"], source.get("error"))
    record["run_of"] = int(source["case"])
    try:
        if run is not None:
            own = Run(run.tables, _scene_text(scene), error=source.get("error"))
            record.update(_cost(own))
            record["wall_time_s"] = None  # no simulation of its own
            record["quantities"] = task.quantities(own)
    except Exception as e:  # noqa: BLE001 - recorded, never raised
        record["status"], record["error"] = "error", _join(source.get("error"), f"after the run: {_describe(e)}")
    _write_scene(out, task.partition, scene)
    record["case_wall_time_s"] = time.perf_counter() - start
    write_record(out, record)
    return record


def _scene_text(scene: _native.Scene) -> str:
    return scene.to_toml(units=True) if scene.kind == "drill-pipe" else scene.to_toml()


def _write_scene(out: Path, partition: str, scene: _native.Scene) -> None:
    path = scene_path(out, partition)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text(_scene_text(scene), path)


def read_case_run(out: Path, index: int) -> Run:
    """The run of finished case `index` of the sweep in `out`, read back from its record, tables and scene.

    A case that shares another case's run (its record's ``run_of``, `derive_case`) has that case's tables with its
    own scene. Raises `FileNotFoundError` when the case (or the case whose run it shares) has no record.
    """
    partition = partition_name(index)
    record = read_record(out, partition)
    if record is None:
        raise FileNotFoundError(f"{record_path(out, partition)}: no record of case {index} (not finished)")
    scene_toml = scene_path(out, partition).read_text(encoding="utf-8")
    return _tables_run(out, int(record.get("run_of", index)), scene_toml, record.get("error"))


def _tables_run(out: Path, index: int, scene_toml: str, error: str | None) -> Run:
    """The tables case `index` recorded, read back, as a run of the scene `scene_toml`."""
    import pyarrow.parquet as pq  # deferred: only readers pay for it

    partition = partition_name(index)
    record = read_record(out, partition)
    if record is None:
        raise FileNotFoundError(f"{record_path(out, partition)}: no record of case {index} (not finished)")
    tables = {name: pq.read_table(table_path(out, name, partition)) for name in record.get("tables", [])}
    return Run(tables, scene_toml, error=error)


def failed_record(task: CaseTask, error: BaseException) -> dict[str, Any]:
    """The record of a case whose worker failed before writing one (e.g. a lost Dask worker)."""
    scene = _native.Scene.from_toml(task.base_toml, list(task.overrides))
    return _base_record(task, scene, "error", f"worker: {_describe(error)}")


def _base_record(task: CaseTask, scene: _native.Scene, status: str, error: str | None) -> dict[str, Any]:
    return {
        "case": task.index,
        "case_id": task.case_id,
        "digest": task.digest,
        "partition": task.partition,
        "overrides": list(task.overrides),
        "values": task.values,
        "parameters": {k: scene.value(k) for k in task.parameters},
        "status": status,
        "error": error,
        "tables": [],
        "quantities": {},
        "run_of": task.index,
    }


def _write_tables(run: Run, out: Path, partition: str, kept: list[str] | None = None) -> list[str]:
    """Writes the run's tables (those of `kept` when given) into the case's partitions; their names."""
    names = []
    for name, table in run.tables.items():
        if kept is not None and name not in kept:
            continue
        path = table_path(out, name, partition)
        path.parent.mkdir(parents=True, exist_ok=True)
        write_parquet(table, path)
        names.append(name)
    return names


def _cost(run: Run) -> dict[str, Any]:
    meta = run.metadata

    def number(key: str) -> float | None:
        try:
            return float(meta[key])
        except (KeyError, ValueError):
            return None

    steps, dt = number("ballcage.steps"), number("ballcage.dt_s")
    return {
        "wall_time_s": number("ballcage.wall_time_s"),
        "steps": int(steps) if steps is not None else None,
        "simulated_time_s": steps * dt if steps is not None and dt is not None else None,
    }


def scene_path(out: Path, partition: str) -> Path:
    """Where the resolved scene of the case in `partition` lives: ``DIR/cases/case=NNNN.scene.toml``."""
    return out / CASES / f"{partition}.scene.toml"


def write_record(out: Path, record: dict[str, Any]) -> Path:
    """Writes a case record (JSON, NaN and infinities as null) atomically; it marks the case finished."""
    path = record_path(out, record["partition"])
    path.parent.mkdir(parents=True, exist_ok=True)
    return write_text(json.dumps(_clean(record), indent=1, sort_keys=True, allow_nan=False) + "\n", path)


def read_record(out: Path, partition: str) -> dict[str, Any] | None:
    """The record of a finished case; ``None`` when there is none (or it cannot be read)."""
    try:
        data = json.loads(record_path(out, partition).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def _clean(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    return value


def _timed_out(task: CaseTask, error: TimeLimitError) -> str:
    """The message of a case stopped at its time limit: the case, the limit, where it stopped, how to raise it."""
    values = " ".join(f"{k}={toml_value(v)}" for k, v in task.values.items()) or "no swept values"
    return (
        f"case {task.case_id} ({values}) timed out: {error}; raise the limit with --case-timeout SECONDS "
        "(case_timeout= in Python; 0 for none) and run the same command again, which runs timed-out cases again"
    )


def _describe(error: BaseException) -> str:
    text = str(error) or type(error).__name__
    frames = traceback.extract_tb(error.__traceback__)
    where = f" (at {Path(frames[-1].filename).name}:{frames[-1].lineno})" if frames else ""
    return f"{type(error).__name__}: {text}{where}"


def _join(first: str | None, second: str) -> str:
    return f"{first}; {second}" if first else second
