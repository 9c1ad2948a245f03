"""Running a sweep: `sweep(spec, out)` locally in threads, or on a Dask cluster with ``client=``.

Output folder (docs/studies.md)::

    DIR/summary.parquet                      one row per case (`summary_table`)
    DIR/<table>/case=NNNN/part.parquet       one hive-partitioned dataset per table kind
    DIR/cases/case=NNNN.json                 the case's record: written last, it marks the case finished
    DIR/cases/case=NNNN.scene.toml           the case's resolved scene
    DIR/plots/<parameter>.png                each quantity against each swept parameter

A case whose scene has the same engine digest as an earlier case's
(`Scene.engine_digest`: bitwise the same run) is not run again: its
quantities come from that case's tables with its own scene (`shared_runs`,
`ballcage.studies.sweep_case.derive_case`; the summary's ``run_of``).

Each case's quantities (``summary.parquet``'s columns after the swept keys)
come from a plug-in, `ballcage.studies.sweep_quantities.SweepQuantities`:
by default the one of the base scene's kind (`for_scene`).

Running the same sweep into the same folder again resumes: a case with a
record whose hash matches and whose table files exist is skipped (with
``retry_failed``, only if it finished ``ok``); a case that timed out
(``case_timeout``, status ``timed-out``) is run again. A record of another
sweep's case (another hash) is refused, naming the case.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, TextIO

import pyarrow as pa
import pyarrow.compute as pc

from ballcage import _native
from ballcage._files import write_parquet
from ballcage.run import _isatty
from ballcage.studies.sweep_case import (
    TIMED_OUT,
    CaseTask,
    failed_record,
    read_record,
    run_case,
    table_path,
    write_record,
)
from ballcage.studies.sweep_plots import write_plots
from ballcage.studies.sweep_quantities import GENERIC, SweepQuantities, for_scene
from ballcage.studies.sweep_spec import Case, SweepError, SweepSource, SweepSpec, load_sweep
from ballcage.studies.sweep_summary import parameter_units, summary_table

__all__ = [
    "SweepResult", "checked_case_timeout", "connect", "largest_errors", "pending_cases", "pending_work",
    "scheduler_client", "shared_runs", "sweep",
]


@dataclass
class SweepResult:
    """What `sweep` did: the summary table, the folder, and how many cases ran, were skipped and failed."""

    summary: pa.Table
    out: Path
    ran: int
    skipped: int
    failed: int
    paths: dict[str, Path] = field(default_factory=dict)
    #: Of the cases `ran`, those that shared another case's run (`shared_runs`): their quantities were computed from
    #: its tables, no simulation of their own.
    shared: int = 0


def sweep(
    spec: SweepSource,
    out: str | os.PathLike[str],
    *,
    client: Any = None,
    workers: int | None = None,
    retry_failed: bool = False,
    plots: bool = True,
    progress: bool | None = None,
    quantities: SweepQuantities | None = None,
    case_timeout: float | None = None,
) -> SweepResult:
    """Runs every case of a sweep file (path, dict or `SweepSpec`) into the folder `out`.

    Locally, `workers` threads (default ``os.cpu_count()``) run the cases; the
    engine releases the GIL while it integrates. With a
    ``dask.distributed.Client`` as `client`, the cases run as tasks on its
    cluster; the workers write into `out` themselves, so it must be a path
    every worker and this process see (a shared filesystem). A case that
    diverges or fails is recorded (``status``, ``error``, its partial tables)
    and the others go on. `progress`: ``None`` a bar on a terminal and a line
    per case otherwise, ``False`` silent. `quantities`: what each case's
    record and the summary's quantity columns hold (a `SweepQuantities`
    plug-in; ``None``: `for_scene` of the base scene, so the drill pipe's
    quantities for a drill pipe and none for a scene of bodies).
    `case_timeout`: wall time [s] each case's run may take (``--case-timeout``;
    ``None`` or 0: no limit, the default, since a sweep has no estimate of
    its cases' time before they run): a case past it is stopped between two of
    its run's 200 pieces and recorded as ``timed-out`` with its frames up to
    then, and the others go on; resuming runs it again. Raises `SweepError`
    for a bad sweep file, a folder holding another sweep or a bad
    `case_timeout`, before anything runs.
    """
    timeout = checked_case_timeout(case_timeout)
    loaded = load_sweep(spec)
    cases = loaded.check()
    folder = Path(out)
    if folder.exists() and not folder.is_dir():
        raise SweepError(f"--out {folder}: exists and is not a directory")
    base = _native.Scene.from_toml(loaded.base_toml)
    plugin = quantities if quantities is not None else for_scene(base)
    pending, done = _pending_runs([_task(loaded, c, folder, plugin, timeout) for c in cases],
                                  shared_runs(loaded, cases), folder, retry_failed)  # fmt: skip
    say = _Say(progress is not False)
    where = _where(client, workers)
    limit = f", each stopped past {timeout:g} s of wall time (--case-timeout)" if timeout is not None else ""
    shared = sum(len(t.shares) for t in pending)
    reuse = f" (and {shared} cases from their runs: the same engine digest, Scene.engine_digest)" if shared else ""
    say(f"sweep {loaded.name}: {len(cases)} cases; {len(done)} already finished in {folder} (skipped), "
        f"running {len(pending)}{reuse} {where}{limit}")
    folder.mkdir(parents=True, exist_ok=True)
    bar = SweepProgress(len(pending), enabled=progress is not False)
    try:
        ran = _run_dask(client, pending, bar) if client is not None else _run_local(pending, workers, bar)
    finally:
        bar.close()
    records = done + [r for record in ran for r in (record, *record.pop("shared", []))]
    result = _finish(loaded, base, plugin, records, folder, (len(pending) + shared, len(done)), plots)
    result.shared = shared
    return result


def _pending_runs(
    tasks: list[CaseTask], run_of: dict[int, int], out: Path, retry_failed: bool
) -> tuple[list[CaseTask], list[dict[str, Any]]]:
    """The runs still to run, each with the cases that share it (`CaseTask.shares`), and the finished records.

    A run is run again, with all its cases, when any of them is unfinished (`_split_finished`): a shared case is
    computed from its run in memory, with tables its plug-in reads that the sweep does not keep.
    """
    unfinished, finished = _split_finished(tasks, out, retry_failed)
    again = {run_of[t.index] for t in unfinished}
    by_index = {t.index: t for t in tasks}
    pending = [
        replace(by_index[i], shares=tuple(t for t in tasks if run_of[t.index] == i and t.index != i))
        for i in sorted(again)
    ]
    done = [r for r in finished if run_of[int(r["case"])] not in again]
    return pending, done


def shared_runs(spec: SweepSpec, cases: Iterable[Case]) -> dict[int, int]:
    """Case index -> the first case whose scene has the same engine digest (`Scene.engine_digest`; itself if none).

    Two such scenes record bitwise the same tables, so only the first is run; the others differ only in what is
    computed from the tables afterwards (e.g. ``fatigue.*``) or in nothing the scene builds.
    """
    first: dict[str, int] = {}
    out: dict[int, int] = {}
    for case in cases:
        digest = _native.Scene.from_toml(spec.base_toml, list(case.overrides)).engine_digest()
        out[case.index] = first.setdefault(digest, case.index)
    return out


def pending_cases(spec: SweepSource, out: str | os.PathLike[str]) -> int:
    """How many runs the sweep `spec` has still to run in the folder `out` (`pending_work`)."""
    return pending_work(spec, out)[0]


def pending_work(
    spec: SweepSource, out: str | os.PathLike[str], run_of: dict[int, int] | None = None
) -> tuple[int, int]:
    """What the sweep `spec` has still to do in the folder `out`: the runs, and the cases computed from them that
    share their run (`run_of`, `shared_runs` when not given; no simulation, only their quantities)."""
    loaded = load_sweep(spec)
    folder = Path(out)
    cases = loaded.cases()
    run_of = shared_runs(loaded, cases) if run_of is None else run_of
    pending, _ = _pending_runs([_task(loaded, c, folder) for c in cases], run_of, folder, False)
    return len(pending), sum(len(t.shares) for t in pending)


def checked_case_timeout(value: float | str | None) -> float | None:
    """A case time limit [s] as `sweep` takes it: ``None`` (and 0) for none, else a positive finite number.

    Raises `SweepError` naming the value.
    """
    if value is None:
        return None
    try:
        seconds = float(value)
    except (TypeError, ValueError):
        raise SweepError(f"case_timeout = {value!r}: not a number of seconds (None or 0: no limit)") from None
    if seconds == 0.0:
        return None
    if not (math.isfinite(seconds) and seconds > 0):
        raise SweepError(f"case_timeout = {value!r}: must be a positive number of seconds (None or 0: no limit)")
    return seconds


def _task(
    spec: SweepSpec, case: Case, out: Path, quantities: SweepQuantities = GENERIC, timeout: float | None = None
) -> CaseTask:
    return CaseTask(
        index=case.index,
        case_id=case.case_id,
        digest=case.digest,
        partition=case.partition,
        base_toml=spec.base_toml,
        overrides=case.overrides,
        values=case.values,
        parameters=tuple(spec.parameters),
        out=str(out.resolve()),
        quantities=quantities,
        timeout=timeout,
    )


def _split_finished(tasks: list[CaseTask], out: Path, retry_failed: bool) -> tuple[list[CaseTask], list[dict[str, Any]]]:
    """The cases still to run, and the records of those finished (their files all present; not timed out)."""
    pending, done = [], []
    for task in tasks:
        record = read_record(out, task.partition)
        if record is None:
            pending.append(task)
            continue
        if record.get("digest") != task.digest:
            raise SweepError(
                f"--out {out}: holds case {task.index} of another sweep (case_id {record.get('case_id')}, "
                f"this sweep's is {task.case_id}): choose another --out folder or remove that one"
            )
        files = all(table_path(out, t, task.partition).is_file() for t in record.get("tables", []))
        status = record.get("status")
        if not files or status == TIMED_OUT or (retry_failed and status != "ok"):
            pending.append(task)
        else:
            done.append(record)
    return pending, done


def _where(client: Any, workers: int | None) -> str:
    if client is not None:
        return f"on the Dask cluster at {getattr(client.scheduler, 'address', client)}"
    return f"in {workers or os.cpu_count() or 1} local threads"


def _run_local(tasks: list[CaseTask], workers: int | None, bar: SweepProgress) -> list[dict[str, Any]]:
    if not tasks:
        return []
    count = max(1, min(workers or os.cpu_count() or 1, len(tasks)))
    executor = ThreadPoolExecutor(max_workers=count, thread_name_prefix="ballcage-sweep")
    try:
        futures = {executor.submit(run_case, t): t for t in tasks}
        records = []
        for future in as_completed(futures):
            records.append(_result(future.result, futures[future]))
            bar.update(records[-1])
        return records
    except KeyboardInterrupt:
        executor.shutdown(wait=False, cancel_futures=True)
        raise
    finally:
        executor.shutdown(wait=True)


def _run_dask(client: Any, tasks: list[CaseTask], bar: SweepProgress) -> list[dict[str, Any]]:
    from distributed import as_completed as dask_completed  # the optional extra: ballcage[dask]

    if not tasks:
        return []
    futures = {client.submit(run_case, t, pure=False): t for t in tasks}
    records = []
    try:
        for future in dask_completed(list(futures)):
            records.append(_result(future.result, futures[future]))
            bar.update(records[-1])
    except KeyboardInterrupt:
        client.cancel(list(futures))
        raise
    return records


def _result(get: Callable[[], dict[str, Any]], task: CaseTask) -> dict[str, Any]:
    """The case's record; when the worker itself failed (not the case), a record saying so, written here."""
    try:
        return get()
    except Exception as e:  # noqa: BLE001 - e.g. a worker lost; the sweep goes on
        records = [failed_record(t, e) for t in (task, *task.shares)]
        for record in records:
            write_record(Path(task.out), record)
        return records[0] | {"shared": records[1:]}


def _finish(
    spec: SweepSpec,
    base: _native.Scene,
    quantities: SweepQuantities,
    records: list[dict[str, Any]],
    out: Path,
    counts: tuple[int, int],
    plots: bool,
) -> SweepResult:
    """Writes ``summary.parquet`` (and the plots) of the `records`; `counts`: cases (ran, skipped)."""
    units = parameter_units(base, spec.parameters)
    meta = {
        "ballcage.sweep": spec.name,
        "ballcage.sweep_parameters": json.dumps(spec.parameters),
        "ballcage.sweep_fixed": json.dumps(spec.fixed),
        "ballcage.sweep_base": str(spec.base) if spec.base is not None else "embedded paper scene",
        "ballcage.sweep_verification": spec.verification,
    }
    table = summary_table(records, spec.parameters, units, meta, quantities, spec.verifies)
    paths = {"summary": write_parquet(table, out / "summary.parquet")}
    if plots:
        # The sweep's own cases against the swept keys, not the verification runs or their tighter setting.
        own, swept = table, spec.parameters
        if spec.verifies:
            own = table.filter(pc.is_null(table.column("verifies")))
            swept = list(dict.fromkeys(k for values in spec.listed[: spec.verifies] for k in values))
        paths.update({f"plot_{k}": v for k, v in write_plots(own, swept, out).items()})
    failed = sum(1 for r in records if r.get("status") != "ok")
    return SweepResult(table, out, *counts, failed, paths)


class SweepProgress:
    """Counts finished cases on stderr with an estimate of the time left.

    On a terminal it redraws one line (a bar); otherwise it prints one line per case.
    """

    WIDTH = 24

    def __init__(self, total: int, *, enabled: bool, stream: TextIO | None = None,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.total, self.enabled = total, enabled and total > 0
        self.stream = stream if stream is not None else sys.stderr
        self.clock, self.start = clock, clock()
        self.done = self.failed = 0
        self.tty = _isatty(self.stream)

    def update(self, record: dict[str, Any]) -> None:
        self.done += 1
        self.failed += record.get("status") != "ok"
        if not self.enabled:
            return
        elapsed = self.clock() - self.start
        left = elapsed / self.done * (self.total - self.done)
        counts = f"{self.done}/{self.total} cases" + (f", {self.failed} failed" if self.failed else "")
        timing = f"{elapsed:.1f} s, ~{left:.0f} s left" if self.done < self.total else f"{elapsed:.1f} s"
        case = f"case {record.get('case_id')} {record.get('status')}"
        if self.tty:
            if record.get("status") != "ok":
                self.stream.write("\r\x1b[K" + f"ballcage: {case}: {record.get('error')}\n")
            filled = round(self.WIDTH * self.done / self.total)
            self.stream.write("\r\x1b[K" + f"ballcage: [{'#' * filled}{'.' * (self.WIDTH - filled)}] {counts}  {timing}")
        else:
            error = f": {record.get('error')}" if record.get("error") else ""
            self.stream.write(f"ballcage: {counts} ({case}{error})  {timing}\n")
        self.stream.flush()

    def close(self) -> None:
        if self.enabled and self.tty and self.done:
            self.stream.write("\n")
            self.stream.flush()


class _Say:
    def __init__(self, enabled: bool) -> None:
        self.enabled = enabled

    def __call__(self, text: str) -> None:
        if self.enabled:
            print(f"ballcage: {text}", file=sys.stderr, flush=True)


def describe(result: SweepResult) -> Iterable[str]:
    """Lines the CLI prints after a sweep."""
    yield f"wrote {result.paths['summary']}  ({result.summary.num_rows} cases)"
    for name, path in result.paths.items():
        if name.startswith("plot_"):
            yield f"wrote {path}  (plot)"
    shared = f" ({result.shared} of them from another case's run: the same engine digest)" if result.shared else ""
    yield (
        f"ballcage: {result.ran} cases run{shared}, {result.skipped} skipped (already finished), "
        f"{result.failed} of {result.summary.num_rows} not ok"
    )
    verification = (result.summary.schema.metadata or {}).get(b"ballcage.sweep_verification", b"").decode()
    if verification:
        worst = largest_errors(result.summary)[:3]
        text = "; ".join(f"{name} {100 * rel:.2g} % (case {row['case']})" for name, rel, row in worst) or "none measured"
        yield f"ballcage: largest numerical errors (each case against its run at {verification}): {text}"


def largest_errors(table: pa.Table, quantities: Iterable[str] | None = None) -> list[tuple[str, float, dict[str, Any]]]:
    """Per quantity with a numerical error column (``<quantity>_error``; of `quantities`, by default every one),
    its largest error relative to the value and that row, largest first; rows whose value is 0 are left out."""
    rows, out = table.to_pylist(), []
    names = table.column_names if quantities is None else [q + "_error" for q in quantities]
    for name in names:
        quantity = name.removesuffix("_error")
        if not name.endswith("_error") or quantity not in table.column_names or name not in table.column_names:
            continue
        relative = [(r[name] / abs(r[quantity]), i) for i, r in enumerate(rows) if r[name] is not None and r[quantity]]
        if relative:
            rel, i = max(relative)
            out.append((quantity, rel, rows[i]))
    return sorted(out, key=lambda x: -x[1])


def connect(scheduler: str) -> Any:
    """A ``dask.distributed.Client`` of the scheduler at `scheduler` (``--scheduler``); raises `SweepError`."""
    try:
        from distributed import Client
    except ImportError:
        raise SweepError("--scheduler needs dask.distributed: pip install 'ballcage[dask]'") from None
    try:
        return Client(scheduler, timeout="20s")
    except (OSError, TimeoutError) as e:
        raise SweepError(f"--scheduler {scheduler}: cannot connect: {e}") from None


@contextmanager
def scheduler_client(scheduler: str | None) -> Iterator[Any]:
    """The ``--scheduler`` option as a context: a connected client (`connect`), or ``None`` without one; closed after."""
    client = connect(scheduler) if scheduler else None
    try:
        yield client
    finally:
        if client is not None:
            client.close()

