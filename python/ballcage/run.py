"""Running a scene: `simulate` → `Run` (tables in memory) → `Run.write` (Parquet files).

The simulation itself runs in Rust without the GIL. `simulate` advances it in
about `CHUNKS` pieces so that Ctrl-C is honoured between pieces and a progress
bar can be drawn; the chunking does not change the result (the integrator
steps are the same).

``simulate(..., time_limit=SECONDS)`` stops a run whose wall time passes the
limit at the next of those pieces and raises `TimeLimitError` with the
frames recorded so far (the sweeps' ``--case-timeout``).

``simulate(..., verify=True)`` repeats the run ten times tighter and keeps the
difference of each headline quantity as the run's measured error
(`Verification`, ``verify.parquet``). The tighter run goes on in a thread of
its own beside the run (the engine releases the GIL: on two cores the pair
takes about the time of the tighter run alone). That work is
`ballcage.verify`, above this module (it takes a drill pipe's quantities
from `ballcage.measures`); this module calls it through `VERIFIER`, which
the package's facade (``ballcage/__init__.py``) sets, so it never imports it.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, TextIO, TypeVar

from ballcage import _native
from ballcage._files import parquet_writer, write_all_atomically
from ballcage.scene import BALL_KEY_HINGES, SceneSource, load_scene

if TYPE_CHECKING:
    import pyarrow as pa

__all__ = ["VERIFY_FILE", "Run", "TimeLimitError", "Verification", "VerificationError", "simulate", "simulate_then"]

#: What the work `simulate_then` does beside a verification run returns.
T = TypeVar("T")

#: Number of `advance` calls a run is split into.
CHUNKS = 200
#: Wall time [s] after which an automatic progress bar appears.
PROGRESS_DELAY_S = 1.5
#: The file `Run.write` writes a run's `Verification` table to.
VERIFY_FILE = "verify.parquet"


@dataclass(frozen=True)
class Verification:
    """A run's measured error: the same scene run ten times tighter (`ballcage.verify`).

    `table` holds one row per headline quantity (its value in both runs, their
    absolute and relative difference; ``ballcage schema``-style units in the
    field metadata, both runs' wall times in the schema metadata); `Run.write`
    writes it as ``verify.parquet``.
    """

    table: pa.Table
    #: The tighter setting, ``"dt/4"`` or ``"rtol/10"``.
    setting: str
    #: The overrides that made the verification run from the run's scene, e.g. ``("simulation.dt=2.5e-05",)``.
    overrides: tuple[str, ...]
    #: The largest relative difference over the quantities that have one; ``None`` when none has.
    largest: float | None
    #: The quantity of `largest`.
    quantity: str | None
    #: Wall time of the verification run (with ``verify=2`` both) over the run's (``ballcage.wall_time_s``); ``None``
    #: if not measured.
    time_ratio: float | None
    #: ``verify=2``: the second verification run's setting, ``"rtol/100"`` or ``"dt/16"``; ``None`` without one.
    confirm_setting: str | None = None
    #: ``verify=2``: the largest relative difference between the two verification runs: the first one's own error.
    confirm_largest: float | None = None
    #: The quantity of `confirm_largest`.
    confirm_quantity: str | None = None
    #: ``verify=2``: whether the second run confirms the first (`ballcage.verify.CONFIRM_RULE`); ``None`` without a
    #: second run or a difference to judge.
    confirmed: bool | None = None


class VerificationError(_native.SimulationError):
    """The verification run failed (it diverged, or its scene was refused, e.g. by ``simulation.max_steps``).

    ``e.run`` is the run that was being verified, complete but without a
    verification; ``e.check`` what the verification run recorded up to its
    failure (``None`` when it did not start).
    """

    run: Run
    check: Run | None


class Cancelled(Exception):
    """A run stopped by its `watch` (`_run`): the verification run of a run that failed or was interrupted."""


class TimeLimitError(_native.Error, TimeoutError):
    """A run stopped because its wall time passed ``simulate(..., time_limit=)``.

    Not a `ballcage.SimulationError`: the run did not diverge, it was stopped.
    ``run`` holds the frames recorded up to then (a `Run` whose
    ``Run.error`` is this message, ``Run.complete`` false); ``limit_s`` is the
    limit, ``elapsed_s`` the wall time when the run stopped and ``t_s`` the
    simulated time reached [s].
    """

    def __init__(
        self,
        message: str,
        *,
        run: Run | None = None,
        limit_s: float | None = None,
        elapsed_s: float | None = None,
        t_s: float | None = None,
    ) -> None:
        super().__init__(message)
        self.run, self.limit_s, self.elapsed_s, self.t_s = run, limit_s, elapsed_s, t_s


class Verifier(Protocol):
    """What ``simulate(..., verify=True)`` needs of `ballcage.verify` (`VERIFIER`)."""

    def start(self, scene: _native.Scene, progress: bool | None, runs: int) -> Any:
        """Starts the `runs` verification runs (1 or 2) of `scene` beside its run; returns a handle for `finish`."""

    def finish(self, run: Run, progress: bool | None, started: Any) -> Verification:
        """The `Verification` of the complete `run` from the verification run `started`."""

    def cancel(self, started: Any) -> None:
        """Stops the verification run `started` (its run failed or was interrupted)."""


#: Measures a run's error for ``simulate(..., verify=True)``: `ballcage.verify`, set by the package's facade.
VERIFIER: Verifier | None = None


class Run:
    """The recorded output of one simulation run.

    `tables` maps each recorded table name (``"bodies"``, ``"contacts"``,
    ``"energy"``) to a `pyarrow.Table`; units are in each field's metadata.
    """

    def __init__(
        self,
        tables: Mapping[str, pa.Table],
        scene_toml: str,
        *,
        error: str | None = None,
        scene: _native.Scene | None = None,
        verification: Verification | None = None,
    ) -> None:
        self.tables: dict[str, pa.Table] = dict(tables)
        self._scene_toml = scene_toml
        self._scene = scene
        #: Why the run stopped early (the `SimulationError` message); ``None`` for a complete run.
        self.error: str | None = error
        #: The run's measured error (``simulate(..., verify=True)``); ``None`` for a run not verified.
        self.verification: Verification | None = verification

    @property
    def bodies(self) -> pa.Table:
        """Body poses and velocities: one row per recorded body per frame."""
        return self._table("bodies")

    @property
    def contacts(self) -> pa.Table:
        """Contact points in contact: one row per point per frame."""
        return self._table("contacts")

    @property
    def energy(self) -> pa.Table:
        """Energy balance: one row per frame."""
        return self._table("energy")

    @property
    def metadata(self) -> dict[str, str]:
        """Run metadata (``ballcage.version``, ``ballcage.dt_s``, …), decoded from the table schemas."""
        for table in self.tables.values():
            raw = table.schema.metadata or {}
            return {k.decode(): v.decode() for k, v in raw.items()}
        return {}

    @property
    def fallback_note(self) -> str | None:
        """One sentence when the implicit integrator took part steps by its first-order fallback, else ``None``.

        SDIRK2 retries a step Newton cannot solve in halves, down to h/16, and takes a part step that still
        fails by the linearly implicit Euler step (``simulation.newton.fallback``): first order in the step,
        so the run is less accurate there than its step says. The count is ``ballcage.fallback_steps``,
        the smallest part step ``ballcage.smallest_step_s``.
        """
        meta = self.metadata
        count = int(meta.get("ballcage.fallback_steps", "0"))
        if count == 0:
            return None
        smallest = float(meta.get("ballcage.smallest_step_s", "nan"))
        return (
            f"{count} part step{'s' if count != 1 else ''} of {smallest:.3g} s were taken by the first-order "
            "fallback (linearly implicit Euler) where Newton did not converge: the run is less accurate there "
            "than its step says (docs/accuracy.md)"
        )

    @property
    def complete(self) -> bool:
        """Whether the run reached the scene's duration (``ballcage.complete`` in the metadata)."""
        if self.error is not None:
            return False
        return self.metadata.get("ballcage.complete", "true") == "true"

    @property
    def scene_toml(self) -> str:
        """The resolved scene as TOML, every default written out."""
        return self._scene_toml

    @property
    def scene(self) -> _native.Scene:
        """The run's scene, to ask for its values (``run.scene.value("drive.speed_rpm")``).

        The scene `simulate` ran; for a `Run` built from tables and TOML,
        `scene_toml` validated once on first use.
        """
        if self._scene is None:
            self._scene = _native.Scene.from_toml(self._scene_toml)
        return self._scene

    @property
    def has_ball_keys(self) -> bool:
        """Whether the run is of a drill pipe whose hinges have cages and ball keys (``pipe.hinge`` in
        `ballcage.scene.BALL_KEY_HINGES`), whose joint loads are contacts."""
        return self.scene.kind == "drill-pipe" and self.scene.value("pipe.hinge") in BALL_KEY_HINGES

    def write(self, directory: str | os.PathLike[str]) -> dict[str, Path]:
        """Writes ``<table>.parquet`` (zstd) for every table, ``scene.toml`` and ``verify.parquet`` into `directory`.

        The directory is created if needed. Each file is written atomically:
        a reader sees either the previous file or the complete new one, and a
        failed write leaves no file under the final name and no temporary file.
        All files are written to temporaries before any is renamed, so a
        write that fails (a full disk: `OSError` naming the file) changes none
        of the folder's files.
        Tables of an earlier run in the same directory that this run did not
        record (``<table>.parquet`` of any table ``ballcage schema`` lists) are
        removed afterwards, so the folder never mixes two runs, and so is an
        earlier ``verify.parquet`` when this run has no `verification`; other
        files are left alone. Returns the written paths, keyed by table
        name, ``"scene"`` and ``"verify"``.
        """
        out = Path(directory)
        out.mkdir(parents=True, exist_ok=True)
        written: dict[str, Path] = {}
        writers: dict[Path, Callable[[Path], object]] = {}
        for name, table in self.tables.items():
            path = out / f"{name}.parquet"
            writers[path] = parquet_writer(table)
            written[name] = path
        scene_path = out / "scene.toml"
        writers[scene_path] = lambda tmp: tmp.write_text(self._scene_toml, encoding="utf-8")
        written["scene"] = scene_path
        if self.verification is not None:
            written["verify"] = out / VERIFY_FILE
            writers[written["verify"]] = parquet_writer(self.verification.table)
        # Every temporary first, then the renames: a failed write (a full disk) leaves the folder as it was.
        write_all_atomically(writers)
        for name in _native.TABLE_NAMES:
            if name not in self.tables:
                (out / f"{name}.parquet").unlink(missing_ok=True)
        if self.verification is None:
            (out / VERIFY_FILE).unlink(missing_ok=True)
        return written

    def _table(self, name: str) -> pa.Table:
        try:
            return self.tables[name]
        except KeyError:
            recorded = ", ".join(self.tables) or "none"
            raise KeyError(
                f"the scene did not record the {name!r} table (recorded: {recorded}); "
                f"ask for it in the scene's `record.tables`, e.g. tables = [\"bodies\", \"contacts\", \"energy\"] "
                f"or overrides=['record.tables=[\"bodies\", \"contacts\", \"energy\"]']"
            ) from None

    def __repr__(self) -> str:
        shapes = ", ".join(f"{n}: {t.num_rows} rows" for n, t in self.tables.items())
        return f"<ballcage.Run {shapes}>"


def simulate(
    scene: SceneSource,
    *,
    overrides: Iterable[str] = (),
    progress: bool | None = None,
    verify: bool | int = False,
    time_limit: float | None = None,
) -> Run:
    """Runs a scene to its duration and returns the recorded tables.

    `scene` is anything `load_scene` accepts; `overrides` are ``dotted.key=value``
    strings. `progress`: ``None`` shows a bar on stderr once the run has taken
    more than 1.5 s, ``True`` shows it from the start, ``False`` never.

    `verify`: run the scene again ten times tighter (`ballcage.verify.tighter`:
    ``rtol/10`` for adaptive steps, else ``dt/d`` with d = ceil(10^(1/p)), p the
    integrator's order) and keep the difference of each headline quantity as
    the run's measured error in ``Run.verification`` (a `Verification`;
    ``Run.write`` writes ``verify.parquet``). The headline quantities are a
    drill pipe's comparison quantities and a generic scene's summary
    statistics, so a scene that does not record the ``summary`` table records
    it too. The verification run shows its own progress bar.
    ``verify=2`` adds a second verification run, a hundred times tighter
    (``rtol/100``, ``dt/16`` for SDIRK2), which checks the first: where the
    first is itself off by more than a third of the error it measures, the
    measured error is not confirmed (``Verification.confirmed``; the rule is
    `ballcage.verify.CONFIRM_RULE`).

    Raises `ballcage.SceneError` for an invalid scene and
    `ballcage.SimulationError` when the run diverges. The error then carries
    what was recorded up to the failure as ``e.run``, a `Run` whose metadata
    has ``ballcage.complete = "false"`` and ``ballcage.error`` (the message);
    ``e.run.write(dir)`` writes it like a complete run. An interrupt
    (Ctrl-C, `KeyboardInterrupt`) is re-raised the same way, carrying the
    frames recorded so far as ``e.run`` (``Run.error`` says when it stopped).
    When the verification run fails, `VerificationError` (a
    `SimulationError`) carries the complete run, unverified, as ``e.run``; an
    interrupt during the verification run carries it too.

    `time_limit`: wall time [s] the run may take (``None``: no limit). The
    run is checked between the `CHUNKS` pieces it is advanced in (the engine
    cannot be stopped inside one), so it stops at most one piece, 1/200 of
    its simulated time, after the limit, raising `TimeLimitError` with the
    frames recorded up to then as ``e.run``. The verification run has no limit.
    """
    if time_limit is not None and not (math.isfinite(time_limit) and time_limit > 0):
        raise _native.InputError(f"time_limit = {time_limit!r}: must be a positive number of seconds (None: no limit)")
    runs = verification_runs(verify)
    resolved = _resolved(scene, overrides, runs)
    if not runs:
        return _run(resolved, progress, time_limit)
    return _verified(resolved, progress, time_limit, _nothing, runs)[0]


def simulate_then(
    scene: SceneSource,
    work: Callable[[Run], T],
    *,
    overrides: Iterable[str] = (),
    progress: bool | None = None,
    verify: bool | int = False,
) -> tuple[Run, T]:
    """`simulate`, with `work(run)` done on the complete run while its verification run goes on beside it.

    Returns the run (with `verify`, its ``verification`` set once `work` is
    done and the verification run has ended) and what `work` returned: the
    paper report and ``ballcage run`` write their tables and figures while
    the tighter run goes on. Raises as `simulate`; a run that fails, or
    `work` that raises, stops the verification run. A verification run that
    fails raises its `VerificationError` after `work`, carrying the run as
    ``e.run`` and what `work` returned as ``e.done``.
    """
    runs = verification_runs(verify)
    resolved = _resolved(scene, overrides, runs)
    if not runs:
        run = _run(resolved, progress)
        return run, work(run)
    return _verified(resolved, progress, None, work, runs)


def verification_runs(verify: bool | int) -> int:
    """How many verification runs `simulate`'s `verify` asks for: 0, 1 (``True``) or 2."""
    if isinstance(verify, int) and verify in (0, 1, 2):  # a bool is an int
        return int(verify)
    raise _native.InputError(
        f"verify = {verify!r}: must be False, True (one verification run, ten times tighter) or 2 (a second, a "
        "hundred times tighter, checks the first)"
    )


def _resolved(scene: SceneSource, overrides: Iterable[str], runs: int) -> _native.Scene:
    """The validated scene of `simulate`: with `runs` verification runs, recording ``summary`` (the headline
    quantities need it)."""
    resolved = load_scene(scene, overrides)
    if runs and "summary" not in resolved.table_names:
        resolved = load_scene(resolved, ["record.tables=" + json.dumps([*resolved.table_names, "summary"])])
    return resolved


def _nothing(run: Run) -> None:
    """The work `simulate` does beside its verification run: none."""


def _verified(
    resolved: _native.Scene, progress: bool | None, time_limit: float | None, work: Callable[[Run], T], runs: int
) -> tuple[Run, T]:
    """The run of `resolved` and `work` on it, its `runs` verification runs going on beside both (`VERIFIER`)."""
    if VERIFIER is None:  # the facade sets it on `import ballcage`, which any import of ballcage.run runs first
        raise _native.InternalError("ballcage.run.VERIFIER is not set: import ballcage to verify a run")
    started = VERIFIER.start(resolved, progress, runs)
    try:
        run = _run(resolved, progress, time_limit)
        done = work(run)
    except BaseException:
        VERIFIER.cancel(started)
        raise
    try:
        run.verification = VERIFIER.finish(run, progress, started)
    except VerificationError as e:
        e.done = done  # type: ignore[attr-defined]
        raise
    return run, done


def _run(
    resolved: _native.Scene,
    progress: bool | None,
    time_limit: float | None = None,
    watch: Callable[[float], bool] | None = None,
) -> Run:
    """`simulate` of a validated scene, without verification; stopped past `time_limit` [s] of wall time.

    `watch`, if given, is called with the simulated time after each piece; when it returns true the run stops
    with `Cancelled` (the verification run of a run that failed).
    """
    start = time.monotonic()
    sim = _native.Simulation(resolved)
    duration = sim.duration
    bar = ProgressBar(progress, duration)
    try:
        for i in range(1, CHUNKS + 1):
            sim.advance(duration if i == CHUNKS else duration * i / CHUNKS)
            bar.update(sim.time)
            if watch is not None and watch(sim.time) and i < CHUNKS:
                raise Cancelled(f"cancelled at t = {sim.time:.6g} s of {duration:.6g} s")
            elapsed = time.monotonic() - start
            if time_limit is not None and elapsed > time_limit and i < CHUNKS:
                raise _past_limit(sim, resolved, time_limit, elapsed)
    except _native.SimulationError as e:
        # The native Simulation stays usable after an error: hand over what it
        # recorded (its metadata has ballcage.complete = "false" and ballcage.error).
        e.run = Run(sim.finish(), resolved.to_toml(), error=str(e), scene=resolved)  # type: ignore[attr-defined]
        raise
    except KeyboardInterrupt as e:
        reason = f"interrupted at t = {sim.time:.6g} s of {duration:.6g} s"
        e.run = Run(sim.finish(), resolved.to_toml(), error=reason, scene=resolved)  # type: ignore[attr-defined]
        raise
    finally:
        bar.close()
    return Run(sim.finish(), resolved.to_toml(), scene=resolved)


def run_watched(scene: SceneSource, overrides: Iterable[str], watch: Callable[[float], bool]) -> Run:
    """`simulate` of `scene` with `overrides`, without a progress bar, `watch` called with the simulated time after
    each of its pieces: when it returns true the run stops with `Cancelled` (the verification run, `ballcage.verify`)."""
    return _run(load_scene(scene, overrides), False, None, watch)


def _past_limit(sim: _native.Simulation, resolved: _native.Scene, limit: float, elapsed: float) -> TimeLimitError:
    """The `TimeLimitError` of a run stopped at `elapsed` s past its `limit`, with the frames recorded so far."""
    t, duration = sim.time, sim.duration
    message = (
        f"run stopped after {elapsed:.3g} s of wall time, past its time limit of {limit:.3g} s, "
        f"at t = {t:.6g} s of {duration:.6g} s"
    )
    run = Run(sim.finish(), resolved.to_toml(), error=message, scene=resolved)
    return TimeLimitError(message, run=run, limit_s=limit, elapsed_s=elapsed, t_s=t)


class ProgressBar:
    """A dependency-free progress bar on stderr.

    On a terminal it redraws one line with ``\\r``; otherwise (a log file, CI)
    it prints a line at every 10 %.
    """

    WIDTH = 30

    def __init__(
        self,
        mode: bool | None,
        duration: float,
        stream: TextIO | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self._mode = mode
        self._duration = duration
        self._stream = stream if stream is not None else sys.stderr
        self._clock = clock
        self._start = clock()
        self._shown = False
        self._tty = _isatty(self._stream)
        self._last_decile = 0  # the first line is at 10 %
        self._width = 0

    def update(self, t: float) -> None:
        if self._mode is False:
            return
        elapsed = self._clock() - self._start
        if not self._shown:
            if self._mode is not True and elapsed <= PROGRESS_DELAY_S:
                return
            self._shown = True
        fraction = min(max(t / self._duration, 0.0), 1.0) if self._duration > 0 else 1.0
        if self._tty:
            filled = round(fraction * self.WIDTH)
            bar = "#" * filled + "." * (self.WIDTH - filled)
            line = f"ballcage: [{bar}] {fraction:4.0%}  t = {t:.4g} / {self._duration:.4g} s  {elapsed:.1f} s"
            self._width = max(self._width, len(line))
            self._stream.write("\r" + line.ljust(self._width))  # pad over a longer previous line
            self._stream.flush()
        else:
            decile = int(fraction * 10 + 1e-9)
            if decile > self._last_decile:
                self._last_decile = decile
                self._stream.write(
                    f"ballcage: {decile * 10:3d}%  t = {t:.4g} / {self._duration:.4g} s  {elapsed:.1f} s\n"
                )
                self._stream.flush()

    def close(self) -> None:
        if self._shown and self._tty:
            self._stream.write("\n")
            self._stream.flush()


def _isatty(stream: TextIO) -> bool:
    try:
        return stream.isatty()
    except (AttributeError, ValueError):
        return False
