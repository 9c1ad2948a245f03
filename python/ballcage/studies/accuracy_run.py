"""Running the work-precision study: `accuracy` plans the runs, runs them and tabulates their errors."""

from __future__ import annotations

import json
import math
import time
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import pyarrow as pa

from ballcage import _native
from ballcage._native import InputError
from ballcage.run import Run, simulate
from ballcage.scene import SceneSource, load_scene
from ballcage.studies.common import (
    REFERENCE_INTEGRATOR,
    Say,
    StudyError,
    available_integrators,
    check_duration,
    check_integrators,
    family,
    is_drill_pipe,
    meta_int,
    record,
    resolve,
    stepping,
)
from ballcage.studies.ladders import ladders, reference_step, snap_grid
from ballcage.studies.scalars import FLOORS, MAX_QUANTITY, Quantity, quantities, relative_error
from ballcage.studies.schemas import ACCURACY_SCHEMA

__all__ = ["DRILL_PIPE_TABLES", "GENERIC_TABLES", "accuracy", "default_integrators"]

#: The second method that checks the reference: ESDIRK3(2) with adaptive steps at this `simulation.rtol`,
#: its largest step the output interval (docs/accuracy.md: on the paper scene it agrees with SDIRK2 at 25 µs
#: within 0.0072 % over 1.8 s, 2026-11-26). A reference that two different integrators agree on is not one integrator's artefact.
SECOND_METHOD: tuple[str, float] = ("esdirk32", 1e-5)

#: Tables a study records, by scene kind.
DRILL_PIPE_TABLES: tuple[str, ...] = ("links", "keys", "energy")
GENERIC_TABLES: tuple[str, ...] = ("bodies", "summary", "energy")


def accuracy(
    scene: SceneSource | None = None,
    *,
    integrators: Sequence[str] | None = None,
    steps: Sequence[float] | Mapping[str, Sequence[float]] | None = None,
    reference_integrator: str | None = None,
    reference_dt: float | None = None,
    duration: float | None = None,
    overrides: Iterable[str] = (),
    floors: Mapping[str, float] | None = None,
    progress: bool = False,
) -> pa.Table:
    """Runs the work-precision study; one row per run and quantity (`ACCURACY_SCHEMA`).

    `scene`: anything `ballcage.load_scene` takes; ``None`` is the embedded
    paper scene (`overrides` then address its drill-pipe TOML).
    `integrators`: names (default every one, `available_integrators()`; on
    drill-pipe scenes the implicit ones only: the ball keys need explicit
    steps of 0.1–1 µs, hours for a paper run, so explicit ladders are asked
    for by name).
    `steps` [s]: one ladder for all, or a mapping integrator → ladder
    (default `default_steps`). `reference_integrator`: default ``"sdirk2"``.
    `reference_dt` [s]: default the reference integrator's smallest default
    step / 4. `duration` [s] replaces ``simulation.duration``. `floors`
    replaces entries of `FLOORS` (same units). `progress` prints one line per
    run on stderr.

    Runs that raise `ballcage.SimulationError` are rows with ``diverged``
    true, ``error`` inf and the message. Raises `ballcage.SceneError` for an
    invalid scene or override (before anything runs), `ValueError` for bad
    arguments and `StudyError` when the reference itself diverges.
    """
    ref_integrator = reference_integrator or REFERENCE_INTEGRATOR
    check_integrators([ref_integrator], "reference_integrator")
    floor_values = _floor_values(floors)
    check_duration(duration)
    base = resolve(scene, overrides)
    drill_pipe = is_drill_pipe(base)
    names = check_integrators(integrators if integrators is not None else default_integrators(base), "integrators")
    base = load_scene(base, [record(DRILL_PIPE_TABLES if drill_pipe else GENERIC_TABLES)])
    plan = _plan(base, names, ref_integrator, steps, reference_dt, duration)
    say = Say(progress)
    say(plan.headline())
    if progress:
        say(_estimate(plan))
    outcomes = _run_all(plan, floor_values, say)
    return _table(plan, outcomes, floor_values, base, drill_pipe)


def default_integrators(scene: _native.Scene) -> list[str]:
    """The integrators a study compares when none are named: all, or on a drill pipe the implicit ones only."""
    return [n for n in available_integrators() if not is_drill_pipe(scene) or family(n) == "implicit"]


def _floor_values(floors: Mapping[str, float] | None) -> dict[str, float]:
    """`FLOORS`' values with `floors` replacing some; `ValueError` for an unknown kind or a non-positive value."""
    out = {k: v for k, (v, _) in FLOORS.items()}
    for k, v in (floors or {}).items():
        if k not in FLOORS:
            raise InputError(f"floors: {k!r} is not a kind of quantity ({', '.join(FLOORS)})")
        if not (math.isfinite(v) and v > 0):
            raise InputError(f"floors[{k!r}] = {v!r}: must be positive")
        out[k] = float(v)
    return out


# --------------------------------------------------------------------------- plan


@dataclass(frozen=True)
class _Plan:
    """The runs of a study, each scene validated: the reference, its check at 2·dt_ref, the second method
    (`SECOND_METHOD`, adaptive, its largest step the output interval), then the ladders."""

    runs: list[tuple[str, float, str]]  # (integrator, dt [s], role)
    scenes: list[_native.Scene]
    interval: float  # common output interval [s]
    duration: float  # [s]
    notes: list[str]  # steps and duration the snapping changed

    def headline(self) -> str:
        """The progress line announcing the study."""
        (ref, dt_ref, _), (_, dt_check, _) = self.runs[0], self.runs[1]
        return (
            f"accuracy: {len(self.runs)} runs of {self.duration:g} s (output every {self.interval:g} s); reference {ref} "
            f"at {dt_ref:.4g} s, checked at {dt_check:.4g} s"
            + (f"; snapped to whole fractions / multiples of the output interval: {', '.join(self.notes)}" if self.notes else "")
        )


def _plan(
    base: _native.Scene,
    names: Sequence[str],
    ref_integrator: str,
    steps: Sequence[float] | Mapping[str, Sequence[float]] | None,
    reference_dt: float | None,
    duration: float | None,
) -> _Plan:
    ladder = ladders(base, names, steps)
    dt_ref = reference_step(base, ref_integrator, ladder, reference_dt)
    wanted = [*[dt for rungs in ladder.values() for dt in rungs], dt_ref, 2 * dt_ref]
    asked = duration or base.duration
    interval, total, snapped = snap_grid(base.output_interval, asked, wanted)
    # The interval holds 2·dt_ref, so the two reference steps stay distinct after snapping.
    runs = [(ref_integrator, snapped[dt_ref], "reference"), (ref_integrator, snapped[2 * dt_ref], "reference-check")]
    runs.append((SECOND_METHOD[0], interval, "second-method"))
    runs += [(name, snapped[dt], "run") for name in names for dt in ladder[name]]
    # Validate every scene before the first run.
    tolerance = {"second-method": [f"simulation.rtol={SECOND_METHOD[1]!r}"]}
    scenes = [load_scene(base, stepping(i, dt, interval, total) + tolerance.get(role, [])) for i, dt, role in runs]
    notes = [f"{dt:.4g} s → {snapped[dt]:.4g} s" for dt in dict.fromkeys(wanted) if snapped[dt] != dt]
    if total != asked:
        notes.append(f"duration {asked:.4g} s → {total:.4g} s")
    return _Plan(runs, scenes, interval, total, notes)


# --------------------------------------------------------------------------- runs

#: Share of each run's duration simulated as a pilot for the study's time estimate.
PILOT_SHARE = 0.01


def _estimate(plan: _Plan) -> str:
    """The study's expected wall time, from a pilot of each distinct run over `PILOT_SHARE` of the duration."""
    distinct: dict[tuple[str, float], _native.Scene] = {}
    for (integrator, dt, _), scene in zip(plan.runs, plan.scenes, strict=True):
        distinct.setdefault((integrator, dt), scene)
    total = 0.0
    for (_, dt), scene in distinct.items():
        sim = _native.Simulation(scene)
        start = time.perf_counter()
        try:
            sim.advance(max(PILOT_SHARE * plan.duration, 10 * dt))
        except _native.SimulationError:
            pass  # the run itself will report it
        elapsed = time.perf_counter() - start
        total += elapsed * plan.duration / max(sim.time, dt)
    return (
        f"accuracy: at least {_minutes(total)} for the {len(plan.runs)} runs, from pilots over the first "
        f"{PILOT_SHARE:.0%} of each (later, loaded phases cost more per step; each finished run updates the estimate)"
    )


def _time_left(plan: _Plan, outcomes: Sequence[_Outcome]) -> float:
    """Wall time [s] the runs after `outcomes` should take, at the cost per step of the finished
    run nearest in step with the same integrator (else of the reference)."""
    left = 0.0
    for integrator, dt, _ in plan.runs[len(outcomes) :]:
        same = [o for o in outcomes if o.integrator == integrator and not o.diverged] or [outcomes[0]]
        nearest = min(same, key=lambda o: abs(math.log(o.dt / dt)))
        left += nearest.wall_s * nearest.dt / dt
    return left


def _minutes(seconds: float) -> str:
    return f"{seconds:.0f} s" if seconds < 120 else f"{seconds / 60:.0f} min"


@dataclass
class _Outcome:
    """One finished (or diverged) run of the study."""

    integrator: str
    dt: float
    role: str
    quantities: dict[str, Quantity]
    wall_s: float
    meta: dict[str, str]
    diverged: bool
    message: str | None


def _run_all(plan: _Plan, floors: Mapping[str, float], say: Say) -> list[_Outcome]:
    """Every run of `plan` in order (a repeated integrator and step runs once); the reference first."""
    done: dict[tuple[str, float], _Outcome] = {}
    outcomes: list[_Outcome] = []
    for n, ((integrator, dt, role), scene) in enumerate(zip(plan.runs, plan.scenes, strict=True), start=1):
        prev = done.get((integrator, dt))
        outcome = replace(prev, role=role) if prev is not None else _one_run(scene, integrator, dt, role)
        done.setdefault((integrator, dt), outcome)
        if role == "reference" and outcome.diverged:
            raise StudyError(
                f"the reference run ({integrator} at dt = {dt:.4g} s) diverged: {outcome.message}; "
                "choose a smaller reference step or another reference integrator"
            )
        outcomes.append(outcome)
        line = _progress_line(n, len(plan.runs), outcome, outcomes[0], floors)
        if n < len(plan.runs):
            line += f"; about {_minutes(_time_left(plan, outcomes))} left"
        say(line)
    return outcomes


def _one_run(scene: _native.Scene, integrator: str, dt: float, role: str) -> _Outcome:
    start = time.perf_counter()
    run: Run | None
    try:
        run = simulate(scene, progress=False)
        diverged, message = False, None
    except _native.SimulationError as e:
        run = getattr(e, "run", None)
        diverged, message = True, str(e)
    elapsed = time.perf_counter() - start
    meta = run.metadata if run is not None else {}
    wall = float(meta.get("ballcage.wall_time_s", elapsed))
    found = {} if diverged or run is None else quantities(run)
    return _Outcome(integrator, dt, role, found, wall, meta, diverged, message)


def _progress_line(n: int, total: int, outcome: _Outcome, reference: _Outcome, floors: Mapping[str, float]) -> str:
    head = f"accuracy {n}/{total}: {outcome.integrator} dt = {outcome.dt:.4g} s ({outcome.role}), {outcome.wall_s:.3g} s wall"
    if outcome.diverged:
        return f"{head}, diverged: {outcome.message}"
    if outcome is reference:
        return head
    errors = [
        relative_error(q, reference.quantities[name], floors[q.kind])
        for name, q in outcome.quantities.items()
        if name in reference.quantities
    ]
    errors = [e for e in errors if not math.isnan(e)]
    return f"{head}, max error {max(errors):.3g}" if errors else head


# --------------------------------------------------------------------------- table


def _table(plan: _Plan, outcomes: Sequence[_Outcome], floors: Mapping[str, float], base: _native.Scene, drill_pipe: bool) -> pa.Table:
    """The study table: per outcome, one row per reference quantity and one `MAX_QUANTITY` row."""
    reference, check, second = outcomes[0], outcomes[1], outcomes[2]
    ref_q = reference.quantities
    self_error = _errors_against(check, ref_q, floors)
    rows = [row for outcome in outcomes for row in _outcome_rows(outcome, ref_q, self_error, floors)]
    table = pa.Table.from_pylist(rows, schema=ACCURACY_SCHEMA)
    worst_ref = _largest(self_error)
    worst_second = _largest(_errors_against(second, ref_q, floors))
    meta = {
        "ballcage.study": "accuracy",
        "ballcage.version": _native.__version__,
        "ballcage.scene": base.to_toml(),
        "ballcage.kind": "drill-pipe" if drill_pipe else "generic",
        "ballcage.duration_s": repr(plan.duration),
        "ballcage.output_interval_s": repr(plan.interval),
        "ballcage.reference_integrator": reference.integrator,
        "ballcage.reference_dt_s": repr(reference.dt),
        "ballcage.reference_check_dt_s": repr(check.dt),
        "ballcage.reference_self_error_max": repr(worst_ref[1]),
        "ballcage.reference_self_error_max_quantity": worst_ref[0],
        "ballcage.second_method": f"{second.integrator} rtol {SECOND_METHOD[1]:g}",
        "ballcage.second_method_error_max": repr(worst_second[1]),
        "ballcage.second_method_error_max_quantity": worst_second[0],
        "ballcage.floors": json.dumps({k: [v, FLOORS[k][1]] for k, v in floors.items()}),
        "ballcage.quantities": json.dumps({name: q.description for name, q in ref_q.items()}),
    }
    return table.replace_schema_metadata(meta)


def _errors_against(outcome: _Outcome, ref_q: Mapping[str, Quantity], floors: Mapping[str, float]) -> dict[str, float]:
    """Per reference quantity, `outcome`'s relative error (inf where it diverged or lacks the quantity)."""
    return {
        name: (relative_error(outcome.quantities[name], q, floors[q.kind]) if name in outcome.quantities else math.inf)
        for name, q in ref_q.items()
    }


def _largest(errors: Mapping[str, float]) -> tuple[str, float]:
    """The quantity with the largest error (NaN ignored) and that error; ``("", nan)`` when there is none."""
    return max(errors.items(), key=lambda kv: kv[1] if not math.isnan(kv[1]) else -1.0, default=("", math.nan))


def _outcome_rows(
    outcome: _Outcome, ref_q: Mapping[str, Quantity], self_error: Mapping[str, float], floors: Mapping[str, float]
) -> list[dict[str, Any]]:
    rows, errors = [], []
    for name, q_ref in ref_q.items():
        floor = floors[q_ref.kind]
        q = outcome.quantities.get(name)
        if outcome.diverged:
            value, error = None, math.inf
        elif q is None:
            value, error = None, math.nan
        else:
            value, error = q.value, relative_error(q, q_ref, floor)
        errors.append(error)
        rows.append(_row(outcome, name, q_ref.unit, value, q_ref.value, floor, error, self_error[name]))
    finite = [e for e in errors if not math.isnan(e)]
    worst = max(finite) if finite else math.nan
    ref_worst = max((e for e in self_error.values() if not math.isnan(e)), default=math.nan)
    rows.append(_row(outcome, MAX_QUANTITY, "1", None, None, None, worst, ref_worst))
    return rows


def _row(
    outcome: _Outcome,
    quantity: str,
    unit: str,
    value: float | None,
    reference: float | None,
    floor: float | None,
    error: float,
    reference_error: float,
) -> dict[str, Any]:
    meta = outcome.meta
    return {
        "integrator": outcome.integrator,
        "dt": outcome.dt,
        "role": outcome.role,
        "quantity": quantity,
        "unit": unit,
        "value": value,
        "reference": reference,
        "floor": floor,
        "error": error,
        "reference_error": reference_error,
        "wall_s": outcome.wall_s,
        "steps": meta_int(meta, "ballcage.steps"),
        "force_evaluations": meta_int(meta, "ballcage.force_evaluations"),
        "linear_solves": meta_int(meta, "ballcage.linear_solves"),
        "factorizations": meta_int(meta, "ballcage.factorizations"),
        "newton_iterations": meta_int(meta, "ballcage.newton_iterations"),
        "diverged": outcome.diverged,
        "message": outcome.message,
    }
