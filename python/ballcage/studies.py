"""Integrator studies: error against cost (`accuracy`) and the largest stable step (`stability`).

`accuracy(scene)` runs a scene with each integrator over a ladder of steps
and compares named scalar quantities with a reference: the same scene at a
much smaller step ``dt_ref`` with the most accurate integrator. The reference
is shown to be converged by running it again at ``2·dt_ref``: the relative
difference of the two is its own error estimate (``reference_error``; for a
method of order p it over-estimates the reference's error by 2^p − 1). One
row per run and quantity goes into a `pyarrow.Table` (`ACCURACY_SCHEMA`);
`write_accuracy` writes it as ``work_precision.parquet`` with a log-log
work-precision plot and a Markdown table (``ballcage accuracy``).

Quantities (`quantities`), each a scalar per run:

- drill-pipe scenes: ``key_seat_normal_peak`` (largest keys.outer_normal,
  seat race, both flanks of one key summed, over all keys and frames [N]),
  ``tube_mean_force_joint_NN`` (summary.normal_mean of pair linkNN/tube [N]),
  ``final_bend_deg_link_NN`` (180° − links.included_angle_deg of link NN at
  the last frame [deg]);
- generic scenes: ``peak_normal_force_<pair>`` (summary.normal_peak [N]),
  ``final_position_<body>``, ``final_velocity_<body>`` and
  ``final_angular_velocity_<body>`` of every integrated body (the value is
  the vector's norm; the error the largest component difference);
- both: ``final_total_energy`` and ``final_kinetic_energy`` [J];
- ``max_over_quantities``: the largest error of the run.

Relative error: ``|q − q_ref| / max(|q_ref|, floor)``, the floor per kind of
quantity in `FLOORS` (1 N, 0.1°, 1 mm, 1 mm/s, 1e-3 rad/s, 1 mJ), so that a
quantity that is nearly zero in the reference is judged against a stated
absolute scale instead of a tiny denominator.

Every run of a study records at one output interval (the scene's, or a
multiple of it covering the largest step) and each step is snapped to a whole
fraction of it, so peaks are taken over the same frames; the duration is
snapped to a whole number of output intervals. The ``dt`` column holds the
step actually used.

`stability()` finds, for each integrator, the largest step at which a short
probe run finishes without a `ballcage.SimulationError` (bisection in log dt
between a stable and an unstable step), against one scene parameter at a time
(`Parameter`; for the drill pipe `drill_pipe_parameters`: contact stiffness,
drive speed, curvature radius down to the tightest the hinge allows, key mass,
contact damping) and optionally on a stiffness × speed grid; `write_stability`
writes ``stability.parquet`` and heat maps (``ballcage stability``).
"""

from __future__ import annotations

import json
import math
import os
import re
import sys
import time
import tomllib
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import pyarrow as pa

from ballcage import _native
from ballcage.run import Run, _write_atomically, simulate
from ballcage.scene import SceneSource, default_scene, load_scene

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "ACCURACY_SCHEMA",
    "EXPLICIT_INTEGRATORS",
    "FLOORS",
    "PARAMETER_NAMES",
    "STABILITY_SCHEMA",
    "Parameter",
    "Quantity",
    "StudyError",
    "accuracy",
    "default_steps",
    "drill_pipe_parameters",
    "available_integrators",
    "probe_scene",
    "quantities",
    "stability",
    "tightest_radius",
    "write_accuracy",
    "write_stability",
]


class StudyError(RuntimeError):
    """A study that cannot go on, e.g. because its reference run diverged."""


# --------------------------------------------------------------------------- integrators

#: Integrators whose step must resolve the stiffest contact (no linear solve).
EXPLICIT_INTEGRATORS: frozenset[str] = frozenset({"symplectic-euler", "rk4"})


def available_integrators() -> tuple[str, ...]:
    """Every integrator the engine offers (``_native.INTEGRATORS``), in the docs' order."""
    return tuple(str(n) for n in _native.INTEGRATORS)


def _check_integrators(names: Iterable[str], what: str = "integrators") -> list[str]:
    known = available_integrators()
    out = []
    for name in names:
        if name not in known:
            raise ValueError(f"{what}: {name!r} is not an integrator (integrators: {', '.join(known)})")
        if name not in out:
            out.append(name)
    if not out:
        raise ValueError(f"{what}: name at least one integrator")
    return out


def _default_reference_integrator() -> str:
    return "sdirk2" if "sdirk2" in available_integrators() else "linearly-implicit-euler"


# --------------------------------------------------------------------------- scene helpers


def _scene_dict(scene: _native.Scene) -> dict[str, Any]:
    return tomllib.loads(scene.to_toml())


def _is_drill_pipe(scene: _native.Scene) -> bool:
    return _scene_dict(scene).get("kind") == "drill-pipe"


def _resolve(scene: SceneSource | None, overrides: Iterable[str]) -> _native.Scene:
    if isinstance(overrides, str):
        raise TypeError("overrides is a list of 'key=value' strings, not one string")
    return default_scene(list(overrides)) if scene is None else load_scene(scene, list(overrides))


def _toml(value: float | str | Sequence[str]) -> str:
    """A value as TOML for a ``key=value`` override."""
    if isinstance(value, str):
        return json.dumps(value)  # a TOML basic string for plain names
    if isinstance(value, Sequence):
        return "[" + ", ".join(json.dumps(v) for v in value) + "]"
    return repr(float(value))


def _stepping(integrator: str, dt: float, output_interval: float, duration: float) -> list[str]:
    return [
        f"simulation.integrator={_toml(integrator)}",
        f"simulation.dt={_toml(dt)}",
        f"simulation.output_interval={_toml(output_interval)}",
        f"simulation.duration={_toml(duration)}",
    ]


def _whole_ratio(a: float, b: float) -> int | None:
    """``a / b`` when it is a whole number ≥ 1 (to 1e-9 relative), else ``None``."""
    r = a / b
    n = round(r)
    return n if n >= 1 and abs(r - n) <= 1e-9 * r else None


def _snap_grid(output_interval: float, duration: float, steps: Iterable[float]) -> tuple[float, float, dict[float, float]]:
    """Common output interval [s], duration [s] and each step snapped to a whole fraction of the interval."""
    steps = list(steps)
    interval = output_interval
    largest = max(steps)
    if largest > interval * (1 + 1e-9):
        interval *= math.ceil(largest / interval - 1e-9)
    snapped = {}
    for dt in steps:
        snapped[dt] = dt if _whole_ratio(interval, dt) else interval / max(1, round(interval / dt))
    if not _whole_ratio(duration, interval):
        duration = interval * max(1, round(duration / interval))
    return interval, duration, snapped


def _meta_int(meta: Mapping[str, str], key: str) -> int | None:
    text = meta.get(key)
    if text is None or text == "":
        return None
    try:
        return int(float(text))
    except ValueError:
        return None


def _fmt(x: float | None, digits: int = 3) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return ""
    if math.isinf(x):
        return "inf"
    return f"{x:.{digits}g}"


# --------------------------------------------------------------------------- quantities

#: Floor of the relative error's denominator per kind of quantity: (value, unit).
FLOORS: dict[str, tuple[float, str]] = {
    "force": (1.0, "N"),
    "angle": (0.1, "deg"),
    "position": (1e-3, "m"),
    "velocity": (1e-3, "m/s"),
    "angular_velocity": (1e-3, "rad/s"),
    "energy": (1e-3, "J"),
}
#: The pseudo-quantity holding the largest error of a run.
MAX_QUANTITY = "max_over_quantities"
#: Tables a study records, by scene kind.
DRILL_PIPE_TABLES: tuple[str, ...] = ("summary", "links", "keys", "energy")
GENERIC_TABLES: tuple[str, ...] = ("bodies", "summary", "energy")

_TUBE_PAIR = re.compile(r"^link(?P<link>\d+)/tube$")


@dataclass(frozen=True)
class Quantity:
    """One named scalar of a run: `value` in `unit`; `components` are compared for the error."""

    kind: str  # a key of FLOORS
    unit: str
    value: float
    components: tuple[float, ...]
    description: str


def _scalar(kind: str, value: float, description: str) -> Quantity:
    return Quantity(kind, FLOORS[kind][1], float(value), (float(value),), description)


def _vector(kind: str, vec: Sequence[float], description: str) -> Quantity:
    comps = tuple(float(v) for v in vec)
    return Quantity(kind, FLOORS[kind][1], math.sqrt(sum(c * c for c in comps)), comps, description)


def quantities(run: Run) -> dict[str, Quantity]:
    """The named scalars of a run the accuracy study compares (see the module docstring).

    Drill-pipe quantities come from the ``keys``, ``summary`` and ``links``
    tables; generic ones from ``summary`` and ``bodies``; both from ``energy``.
    A quantity whose table was not recorded (or is empty) is left out.
    """
    out: dict[str, Quantity] = {}
    keys = run.tables.get("keys")
    if keys is not None and keys.num_rows:
        peak = float(np.nanmax(keys.column("outer_normal").to_numpy()))
        out["key_seat_normal_peak"] = _scalar(
            "force", peak, "largest keys.outer_normal (seat race, both flanks of one key) over all keys and frames"
        )
    summary = run.tables.get("summary")
    if summary is not None and summary.num_rows:
        pairs = summary.column("pair").cast(pa.string()).to_pylist()
        means = summary.column("normal_mean").to_numpy()
        peaks = summary.column("normal_peak").to_numpy()
        tube = {int(m["link"]): i for i, p in enumerate(pairs) if (m := _TUBE_PAIR.match(p))}
        if tube:
            for link in sorted(tube):
                out[f"tube_mean_force_joint_{link:02d}"] = _scalar(
                    "force", means[tube[link]], f"summary.normal_mean of pair link{link:02d}/tube"
                )
        elif keys is None:
            for i, pair in enumerate(pairs):
                out[f"peak_normal_force_{pair}"] = _scalar("force", peaks[i], f"summary.normal_peak of pair {pair}")
    links = run.tables.get("links")
    if links is not None and links.num_rows:
        last = _last_frame(links)
        for link, angle in zip(last.column("link").to_pylist(), last.column("included_angle_deg").to_numpy(), strict=True):
            out[f"final_bend_deg_link_{int(link):02d}"] = _scalar(
                "angle", 180.0 - float(angle), f"180 deg - links.included_angle_deg of link {int(link):02d} at the last frame"
            )
    bodies = run.tables.get("bodies")
    if bodies is not None and bodies.num_rows:
        integrated = _integrated_bodies(run.scene_toml)
        last = _last_frame(bodies)
        names = last.column("body").cast(pa.string()).to_pylist()
        cols = {c: last.column(c).to_numpy() for c in last.column_names if c.startswith(("pos_", "vel_", "angvel_"))}
        for i, name in enumerate(names):
            if integrated is not None and name not in integrated:
                continue
            for prefix, kind, label in (
                ("pos", "position", "final_position"),
                ("vel", "velocity", "final_velocity"),
                ("angvel", "angular_velocity", "final_angular_velocity"),
            ):
                vec = [cols[f"{prefix}_{a}"][i] for a in "xyz"]
                out[f"{label}_{name}"] = _vector(kind, vec, f"bodies.{prefix}_x/y/z of {name} at the last frame")
    energy = run.tables.get("energy")
    if energy is not None and energy.num_rows:
        last = _last_frame(energy)
        out["final_total_energy"] = _scalar("energy", last.column("total")[0].as_py(), "energy.total at the last frame")
        out["final_kinetic_energy"] = _scalar("energy", last.column("kinetic")[0].as_py(), "energy.kinetic at the last frame")
    return out


def _last_frame(table: pa.Table) -> pa.Table:
    import pyarrow.compute as pc

    return table.filter(pc.equal(table.column("step"), pc.max(table.column("step"))))


def _integrated_bodies(scene_toml: str) -> set[str] | None:
    """Names of the bodies the integrator moves (``dynamic`` and ``spin``); ``None`` if the scene does not say."""
    bodies = tomllib.loads(scene_toml).get("bodies")
    if not isinstance(bodies, list):
        return None
    return {b["name"] for b in bodies if b.get("motion", "dynamic") in ("dynamic", "spin")}


def _relative_error(q: Quantity, ref: Quantity, floor: float) -> float:
    if len(q.components) != len(ref.components):
        return math.nan
    diff = max(abs(a - b) for a, b in zip(q.components, ref.components, strict=True))
    return diff / max(abs(ref.value), floor)


# --------------------------------------------------------------------------- accuracy: steps

#: Default ladders [s] on drill-pipe scenes: the ball keys' contact needs ~1 µs explicit steps
#: (docs/accuracy.md); implicit steps are bounded by accuracy, not by stability.
DRILL_PIPE_STEPS: dict[str, tuple[float, ...]] = {
    "symplectic-euler": (1e-6, 5e-7, 2e-7, 1e-7),
    "rk4": (2e-6, 1e-6, 5e-7, 2e-7),
    "linearly-implicit-euler": (1e-4, 5e-5, 2e-5, 1e-5, 5e-6),
    "sdirk2": (2e-4, 1e-4, 5e-5, 2e-5, 1e-5),
}
#: Default ladders on generic scenes, as multiples of the scene's own step.
GENERIC_STEP_FACTORS: dict[str, tuple[float, ...]] = {
    "explicit": (2.0, 1.0, 0.5, 0.25),
    "implicit": (8.0, 4.0, 2.0, 1.0),
}
#: The default reference step is the reference integrator's smallest ladder step over this.
REFERENCE_DIVISOR = 4.0


def default_steps(scene: _native.Scene, integrator: str) -> tuple[float, ...]:
    """The default ladder of steps [s] for `integrator` on `scene`, largest first.

    Drill-pipe scenes: `DRILL_PIPE_STEPS`. Generic scenes: the scene's
    ``simulation.dt`` times `GENERIC_STEP_FACTORS` (explicit integrators
    around the scene's step, implicit ones up to 8× larger).
    """
    if _is_drill_pipe(scene):
        steps = DRILL_PIPE_STEPS.get(integrator)
        if steps is None:
            steps = DRILL_PIPE_STEPS["symplectic-euler" if integrator in EXPLICIT_INTEGRATORS else "sdirk2"]
        return steps
    family = "explicit" if integrator in EXPLICIT_INTEGRATORS else "implicit"
    return tuple(scene.dt * f for f in GENERIC_STEP_FACTORS[family])


def _check_steps(steps: Iterable[float], what: str) -> tuple[float, ...]:
    out = []
    for dt in steps:
        dt = float(dt)
        if not (math.isfinite(dt) and dt > 0):
            raise ValueError(f"{what}: {dt!r} is not a positive step in seconds")
        out.append(dt)
    if not out:
        raise ValueError(f"{what}: give at least one step")
    return tuple(sorted(set(out), reverse=True))


# --------------------------------------------------------------------------- accuracy: runs


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


ACCURACY_SCHEMA = pa.schema(
    [
        pa.field("integrator", pa.string(), nullable=False, metadata={"unit": "", "description": "integrator name"}),
        pa.field(
            "dt",
            pa.float64(),
            nullable=False,
            metadata={"unit": "s", "description": "integrator step used (snapped to a whole fraction of the output interval)"},
        ),
        pa.field(
            "role",
            pa.string(),
            nullable=False,
            metadata={
                "unit": "",
                "description": "run: a ladder run; reference: the reference at dt_ref; reference-check: the reference integrator at 2 dt_ref",
            },
        ),
        pa.field("quantity", pa.string(), nullable=False, metadata={"unit": "", "description": "quantity name"}),
        pa.field("unit", pa.string(), metadata={"unit": "", "description": "unit of value, reference and floor"}),
        pa.field("value", pa.float64(), metadata={"unit": "see unit", "description": "this run's value (vector norm for vector quantities); null when diverged"}),
        pa.field("reference", pa.float64(), metadata={"unit": "see unit", "description": "the reference's value"}),
        pa.field("floor", pa.float64(), metadata={"unit": "see unit", "description": "floor of the error's denominator"}),
        pa.field(
            "error",
            pa.float64(),
            metadata={
                "unit": "1",
                "description": "|value - reference| / max(|reference|, floor); largest component difference for vectors; inf when diverged",
            },
        ),
        pa.field(
            "reference_error",
            pa.float64(),
            metadata={
                "unit": "1",
                "description": "the reference's own error estimate: |q(dt_ref) - q(2 dt_ref)| / max(|q(dt_ref)|, floor)",
            },
        ),
        pa.field("wall_s", pa.float64(), metadata={"unit": "s", "description": "wall time of the run (ballcage.wall_time_s)"}),
        pa.field("steps", pa.int64(), metadata={"unit": "", "description": "integrator steps taken (ballcage.steps)"}),
        pa.field("force_evaluations", pa.int64(), metadata={"unit": "", "description": "ballcage.force_evaluations"}),
        pa.field("linear_solves", pa.int64(), metadata={"unit": "", "description": "ballcage.linear_solves; null if the engine does not report it"}),
        pa.field("factorizations", pa.int64(), metadata={"unit": "", "description": "ballcage.factorizations; null if the engine does not report it"}),
        pa.field("newton_iterations", pa.int64(), metadata={"unit": "", "description": "ballcage.newton_iterations; null if the engine does not report it"}),
        pa.field("diverged", pa.bool_(), nullable=False, metadata={"unit": "", "description": "the run raised SimulationError"}),
        pa.field("message", pa.string(), metadata={"unit": "", "description": "the divergence message, null otherwise"}),
    ]
)


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
    `integrators`: names (default every one, `available_integrators()`).
    `steps` [s]: one ladder for all, or a mapping integrator → ladder
    (default `default_steps`). `reference_integrator`: default ``"sdirk2"``
    when the engine has it, else ``"linearly-implicit-euler"``.
    `reference_dt` [s]: default the reference integrator's smallest default
    step / 4. `duration` [s] replaces ``simulation.duration``. `floors`
    replaces entries of `FLOORS` (same units). `progress` prints one line per
    run on stderr.

    Runs that raise `ballcage.SimulationError` are rows with ``diverged``
    true, ``error`` inf and the message. Raises `ballcage.SceneError` for an
    invalid scene or override (before anything runs), `ValueError` for bad
    arguments and `StudyError` when the reference itself diverges.
    """
    names = _check_integrators(integrators if integrators is not None else available_integrators(), "integrators")
    ref_integrator = reference_integrator or _default_reference_integrator()
    _check_integrators([ref_integrator], "reference_integrator")
    floor_values = {k: v for k, (v, _) in FLOORS.items()}
    for k, v in (floors or {}).items():
        if k not in FLOORS:
            raise ValueError(f"floors: {k!r} is not a kind of quantity ({', '.join(FLOORS)})")
        if not (math.isfinite(v) and v > 0):
            raise ValueError(f"floors[{k!r}] = {v!r}: must be positive")
        floor_values[k] = float(v)
    if duration is not None and not (math.isfinite(duration) and duration > 0):
        raise ValueError(f"duration = {duration!r}: must be a positive time in seconds")

    base = _resolve(scene, overrides)
    drill_pipe = _is_drill_pipe(base)
    tables = DRILL_PIPE_TABLES if drill_pipe else GENERIC_TABLES
    record = f"record.tables={_toml(list(tables))}"
    base = load_scene(base, [record])

    ladders: dict[str, tuple[float, ...]] = {}
    for name in names:
        if steps is None:
            ladders[name] = default_steps(base, name)
        elif isinstance(steps, Mapping):
            unknown = [k for k in steps if k not in names]
            if unknown:
                raise ValueError(f"steps: {unknown[0]!r} is not one of the studied integrators ({', '.join(names)})")
            ladders[name] = _check_steps(steps[name], f"steps[{name!r}]") if name in steps else default_steps(base, name)
        else:
            ladders[name] = _check_steps(steps, "steps")
    if reference_dt is None:
        ref_ladder = ladders.get(ref_integrator) or default_steps(base, ref_integrator)
        reference_dt = min(ref_ladder) / REFERENCE_DIVISOR
    elif not (math.isfinite(reference_dt) and reference_dt > 0):
        raise ValueError(f"reference_dt = {reference_dt!r}: must be a positive step in seconds")

    wanted = [*[dt for ladder in ladders.values() for dt in ladder], reference_dt, 2 * reference_dt]
    interval, total, snapped = _snap_grid(base.output_interval, duration or base.duration, wanted)
    # The interval holds 2·dt_ref, so the two reference steps stay distinct after snapping.
    dt_ref, dt_check = snapped[reference_dt], snapped[2 * reference_dt]

    plan: list[tuple[str, float, str]] = [(ref_integrator, dt_ref, "reference"), (ref_integrator, dt_check, "reference-check")]
    for name in names:
        for dt in ladders[name]:
            plan.append((name, snapped[dt], "run"))
    # Validate every scene before the first run.
    scenes = [load_scene(base, _stepping(i, dt, interval, total)) for i, dt, _ in plan]

    say = _Say(progress)
    notes = [f"{dt:.4g} s → {snapped[dt]:.4g} s" for dt in dict.fromkeys(wanted) if abs(snapped[dt] - dt) > 1e-9 * dt]
    asked = duration or base.duration
    if abs(total - asked) > 1e-9 * asked:
        notes.append(f"duration {asked:.4g} s → {total:.4g} s")
    say(
        f"accuracy: {len(plan)} runs of {total:g} s (output every {interval:g} s); reference {ref_integrator} "
        f"at {dt_ref:.4g} s, checked at {dt_check:.4g} s"
        + (f"; snapped to whole fractions / multiples of the output interval: {', '.join(notes)}" if notes else "")
    )
    done: dict[tuple[str, float], _Outcome] = {}
    outcomes: list[_Outcome] = []
    reference: _Outcome | None = None
    check: _Outcome | None = None
    for n, ((integrator, dt, role), run_scene) in enumerate(zip(plan, scenes, strict=True), start=1):
        key = (integrator, dt)
        if key in done:
            prev = done[key]
            outcome = _Outcome(integrator, dt, role, prev.quantities, prev.wall_s, prev.meta, prev.diverged, prev.message)
        else:
            outcome = _one_run(run_scene, integrator, dt, role)
            done[key] = outcome
        if role == "reference":
            if outcome.diverged:
                raise StudyError(
                    f"the reference run ({integrator} at dt = {dt:.4g} s) diverged: {outcome.message}; "
                    "choose a smaller reference step or another reference integrator"
                )
            reference = outcome
        elif role == "reference-check":
            check = outcome
        outcomes.append(outcome)
        say(_progress_line(n, len(plan), outcome, reference, floor_values))
    assert reference is not None and check is not None

    ref_q = reference.quantities
    self_error = {
        name: (_relative_error(check.quantities[name], q, floor_values[q.kind]) if name in check.quantities else math.inf)
        for name, q in ref_q.items()
    }
    rows = []
    for outcome in outcomes:
        errors = []
        for name, q_ref in ref_q.items():
            floor = floor_values[q_ref.kind]
            q = outcome.quantities.get(name)
            if outcome.diverged:
                value, error = None, math.inf
            elif q is None:
                value, error = None, math.nan
            else:
                value, error = q.value, _relative_error(q, q_ref, floor)
            errors.append(error)
            rows.append(_row(outcome, name, q_ref.unit, value, q_ref.value, floor, error, self_error[name]))
        finite = [e for e in errors if not math.isnan(e)]
        worst = max(finite) if finite else math.nan
        ref_worst = max((e for e in self_error.values() if not math.isnan(e)), default=math.nan)
        rows.append(_row(outcome, MAX_QUANTITY, "1", None, None, None, worst, ref_worst))
    table = pa.Table.from_pylist(rows, schema=ACCURACY_SCHEMA)
    worst_ref = max(self_error.items(), key=lambda kv: kv[1] if not math.isnan(kv[1]) else -1.0, default=("", math.nan))
    meta = {
        "ballcage.study": "accuracy",
        "ballcage.version": _native.__version__,
        "ballcage.scene": base.to_toml(),
        "ballcage.kind": "drill-pipe" if drill_pipe else "generic",
        "ballcage.duration_s": repr(total),
        "ballcage.output_interval_s": repr(interval),
        "ballcage.reference_integrator": ref_integrator,
        "ballcage.reference_dt_s": repr(dt_ref),
        "ballcage.reference_check_dt_s": repr(dt_check),
        "ballcage.reference_self_error_max": repr(worst_ref[1]),
        "ballcage.reference_self_error_max_quantity": worst_ref[0],
        "ballcage.floors": json.dumps({k: [v, FLOORS[k][1]] for k, v in floor_values.items()}),
        "ballcage.quantities": json.dumps({name: q.description for name, q in ref_q.items()}),
    }
    return table.replace_schema_metadata(meta)


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
        "steps": _meta_int(meta, "ballcage.steps"),
        "force_evaluations": _meta_int(meta, "ballcage.force_evaluations"),
        "linear_solves": _meta_int(meta, "ballcage.linear_solves"),
        "factorizations": _meta_int(meta, "ballcage.factorizations"),
        "newton_iterations": _meta_int(meta, "ballcage.newton_iterations"),
        "diverged": outcome.diverged,
        "message": outcome.message,
    }


def _progress_line(n: int, total: int, outcome: _Outcome, reference: _Outcome | None, floors: Mapping[str, float]) -> str:
    head = f"accuracy {n}/{total}: {outcome.integrator} dt = {outcome.dt:.4g} s ({outcome.role}), {outcome.wall_s:.3g} s wall"
    if outcome.diverged:
        return f"{head}, diverged: {outcome.message}"
    if reference is None or outcome is reference:
        return head
    errors = [
        _relative_error(q, reference.quantities[name], floors[q.kind])
        for name, q in outcome.quantities.items()
        if name in reference.quantities
    ]
    errors = [e for e in errors if not math.isnan(e)]
    return f"{head}, max error {max(errors):.3g}" if errors else head


class _Say:
    """Progress lines on stderr, ``ballcage: ...``; silent unless enabled."""

    def __init__(self, enabled: bool) -> None:
        self.enabled = enabled

    def __call__(self, text: str) -> None:
        if self.enabled:
            print(f"ballcage: {text}", file=sys.stderr, flush=True)


# --------------------------------------------------------------------------- accuracy: output


def _headline(table: pa.Table) -> list[str]:
    """Up to three headline quantities of a study table (non-zero in the reference), then `MAX_QUANTITY`.

    In order of preference: the peak key-seat force, joint 10's mean tube
    force (else the largest), the largest peak pair force, the first body's
    final position, the largest final link bend, the final total energy.
    """
    import pyarrow.compute as pc

    ref_rows = table.filter(pc.equal(table.column("role"), "reference"))
    refs = {
        q: abs(v)
        for q, v in zip(ref_rows.column("quantity").to_pylist(), ref_rows.column("reference").to_pylist(), strict=True)
        if q != MAX_QUANTITY and v is not None and math.isfinite(v) and v != 0.0
    }

    def largest(prefix: str) -> str | None:
        cands = [q for q in refs if q.startswith(prefix)]
        return max(cands, key=lambda q: refs[q]) if cands else None

    picked: list[str] = []
    for choice in (
        "key_seat_normal_peak",
        "tube_mean_force_joint_10" if "tube_mean_force_joint_10" in refs else largest("tube_mean_force_joint_"),
        largest("peak_normal_force_"),
        next((q for q in refs if q.startswith("final_position_")), None),
        largest("final_bend_deg_link_"),
        "final_total_energy",
    ):
        if choice is not None and choice in refs and choice not in picked and len(picked) < 3:
            picked.append(choice)
    return [*picked, MAX_QUANTITY]


def write_accuracy(table: pa.Table, out_dir: str | os.PathLike[str], *, command: str | None = None) -> dict[str, Path]:
    """Writes ``work_precision.parquet``, ``work_precision.png`` and ``work_precision.md`` into `out_dir`.

    Each file is written atomically. Returns the paths by name (``"parquet"``, ``"png"``, ``"md"``).
    """
    import pyarrow.parquet as pq

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = {}
    path = out / "work_precision.parquet"
    _write_atomically(path, lambda tmp: pq.write_table(table, str(tmp), compression="zstd"))
    written["parquet"] = path
    fig = _accuracy_figure(table)
    path = out / "work_precision.png"
    _write_atomically(path, lambda tmp: fig.savefig(tmp, format="png", dpi=120))
    written["png"] = path
    path = out / "work_precision.md"
    text = accuracy_markdown(table, command=command)
    _write_atomically(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    written["md"] = path
    return written


def _study_meta(table: pa.Table) -> dict[str, str]:
    return {k.decode(): v.decode() for k, v in (table.schema.metadata or {}).items()}


def _runs(table: pa.Table) -> list[dict[str, Any]]:
    """One dict per run (integrator, dt, role) with its work columns and ``errors`` by quantity."""
    runs: dict[tuple[str, float, str], dict[str, Any]] = {}
    for r in table.to_pylist():
        key = (r["integrator"], r["dt"], r["role"])
        run = runs.setdefault(key, {**{k: r[k] for k in r if k not in ("quantity", "unit", "value", "reference", "floor", "error", "reference_error")}, "errors": {}, "reference_errors": {}})
        run["errors"][r["quantity"]] = r["error"]
        run["reference_errors"][r["quantity"]] = r["reference_error"]
    return list(runs.values())


def _accuracy_figure(table: pa.Table) -> Figure:
    from ballcage.paper import _figure  # deferred: matplotlib

    panels = _headline(table)
    runs = _runs(table)
    cols = min(len(panels), 2)
    rows = math.ceil(len(panels) / cols)
    fig = _figure(figsize=(5.5 * cols, 4.2 * rows))
    axes = np.atleast_1d(fig.subplots(rows, cols)).ravel()
    meta = _study_meta(table)
    ladder = [r for r in runs if r["role"] == "run"]
    order = list(dict.fromkeys(r["integrator"] for r in ladder))
    for ax, quantity in zip(axes, panels, strict=False):
        drawn = False
        for integrator in order:
            mine = sorted((r for r in ladder if r["integrator"] == integrator), key=lambda r: -r["dt"])
            points = [(r["wall_s"], r["errors"].get(quantity), r["dt"]) for r in mine]
            ok = [(w, max(e, 1e-16), dt) for w, e, dt in points if e is not None and math.isfinite(e) and w and w > 0]
            diverged = sum(1 for r in mine if r["diverged"])
            label = integrator + (f" ({diverged} diverged)" if diverged else "")
            if ok:
                drawn = True
                (line,) = ax.loglog([p[0] for p in ok], [p[1] for p in ok], marker="o", label=label)
                for w, e, dt in ok:
                    ax.annotate(f"{dt:.2g}", (w, e), textcoords="offset points", xytext=(4, 3), fontsize=6, color=line.get_color())
            else:
                ax.plot([], [], marker="x", label=label)
        ref_err = next((r["reference_errors"].get(quantity) for r in runs if r["role"] == "reference"), None)
        if ref_err is not None and math.isfinite(ref_err) and ref_err > 0:
            ax.axhline(ref_err, color="0.5", ls="--", lw=1, label="reference self-error")
        ax.set(xlabel="wall time [s]", ylabel="relative error", title=quantity.replace("_", " "))
        if drawn:
            ax.set_xscale("log")
            ax.set_yscale("log")
        else:
            ax.text(0.5, 0.5, "no finite error: every run diverged", transform=ax.transAxes, ha="center", fontsize=8)
        ax.grid(True, which="both", lw=0.3, alpha=0.5)
        ax.legend(fontsize=7)
    for ax in axes[len(panels) :]:
        ax.set_visible(False)
    fig.suptitle(
        f"Work-precision: reference {meta.get('ballcage.reference_integrator', '?')} at "
        f"{float(meta.get('ballcage.reference_dt_s', 'nan')):.3g} s, {float(meta.get('ballcage.duration_s', 'nan')):g} s simulated "
        "(errors below 1e-16 drawn at 1e-16; labels: dt [s])",
        fontsize=9,
    )
    return fig


def accuracy_markdown(table: pa.Table, *, command: str | None = None) -> str:
    """``work_precision.md``: the reference and its self-error, then one table row per run."""
    meta = _study_meta(table)
    runs = _runs(table)
    headline = _headline(table)
    ref = next((r for r in runs if r["role"] == "reference"), None)
    floors = json.loads(meta.get("ballcage.floors", "{}"))
    lines = ["# Work-precision study", ""]
    if command:
        lines += ["```", command, "```", ""]
    lines.append(
        f"{float(meta.get('ballcage.duration_s', 'nan')):g} s simulated, output every "
        f"{float(meta.get('ballcage.output_interval_s', 'nan')):g} s. Reference: "
        f"{meta.get('ballcage.reference_integrator', '?')} at dt_ref = {float(meta.get('ballcage.reference_dt_s', 'nan')):.4g} s; "
        f"its self-error |q(dt_ref) − q(2·dt_ref)| / max(|q_ref|, floor) is at most "
        f"{_fmt(float(meta.get('ballcage.reference_self_error_max', 'nan')))} "
        f"({meta.get('ballcage.reference_self_error_max_quantity', '')})"
        + (
            "; " + ", ".join(f"{q}: {_fmt(ref['reference_errors'].get(q))}" for q in headline if q != MAX_QUANTITY)
            if ref
            else ""
        )
        + ". Errors at or below it are not resolved."
    )
    lines += [
        "",
        "Error = |q − q_ref| / max(|q_ref|, floor); floors: "
        + ", ".join(f"{k} {v[0]:g} {v[1]}" for k, v in floors.items())
        + ". `max` is the largest error over all quantities of the run; inf = diverged.",
        "",
        "| integrator | dt [s] | role | wall [s] | steps | force evals | Newton its | "
        + " | ".join(("max" if q == MAX_QUANTITY else q) for q in headline)
        + " | note |",
        "| --- | ---: | --- | ---: | ---: | ---: | ---: | " + " | ".join("---:" for _ in headline) + " | --- |",
    ]
    for r in runs:
        note = ("diverged: " + str(r["message"]).replace("|", "\\|")) if r["diverged"] else ""
        cells = [
            r["integrator"],
            f"{r['dt']:.4g}",
            r["role"],
            f"{r['wall_s']:.3g}",
            "" if r["steps"] is None else str(r["steps"]),
            "" if r["force_evaluations"] is None else str(r["force_evaluations"]),
            "" if r["newton_iterations"] is None else str(r["newton_iterations"]),
            *[_fmt(r["errors"].get(q)) for q in headline],
            note,
        ]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------- stability: parameters


@dataclass(frozen=True)
class Parameter:
    """A scene parameter a stability study varies: every override key in `keys` is set to each of `values`."""

    name: str
    keys: tuple[str, ...]
    values: tuple[float, ...]
    unit: str
    description: str = ""


#: Built-in drill-pipe parameters, in the order they are studied.
PARAMETER_NAMES: tuple[str, ...] = ("stiffness", "speed", "curvature_radius", "key_mass", "damping")
#: Range of the built-in parameters (paper units where the scene's law uses them).
STIFFNESS_RANGE = (1e3, 1e7)  # N/mm^n
SPEED_RANGE = (30.0, 600.0)  # rpm
LARGEST_RADIUS = 5.0  # m
KEY_MASS_FACTORS = (0.25, 4.0)  # × the scene's key mass
DAMPING_RANGE = (0.1, 100.0)  # N·s/mm, plus zero


def tightest_radius(scene: SceneSource | None = None) -> float:
    """The tightest tube curvature radius [m] the hinge allows, whichever binds first of:

    * the articulation stop: on an arc of radius R, links of pitch p bend by
      2·asin(p / 2R) at each joint, which ``bend_limit_deg`` (ball keys or ideal
      CV) bounds: R = p / (2 sin(limit / 2)) — 0.766 m for the paper's 200 mm
      pitch and 15° stop;
    * the paper's eq. (9), the longest rigid link of radius r that fits the
      tube (diameter D): L = 2·√(2(D − 2r)(R + r)), so R = (p/2)² / (2(D − 2r)) − r
      — 0.124 m for the paper's 86 mm links in the 116 mm tube.

    The stop binds first for the paper's pipe.
    """
    spec = _scene_dict(_resolve(scene, ()))
    if spec.get("kind") != "drill-pipe":
        raise ValueError("tightest_radius needs a drill-pipe scene (kind = \"drill-pipe\")")
    pipe = spec["pipe"]
    hinge = "ideal_cv" if pipe.get("hinge") == "ideal-cv" else "ball_keys"
    limit = math.radians(float(pipe[hinge]["bend_limit_deg"]))
    pitch = float(pipe["pitch"])
    stop = pitch / (2.0 * math.sin(limit / 2.0))
    r = float(pipe["link_diameter"]) / 2.0
    gap = float(spec["borehole"]["inner_diameter"]) - 2.0 * r
    eq9 = (pitch / 2.0) ** 2 / (2.0 * gap) - r if gap > 0 else math.inf
    return max(stop, eq9)


def drill_pipe_parameters(scene: SceneSource | None = None, values_per_parameter: int = 5) -> dict[str, Parameter]:
    """The built-in parameters (`PARAMETER_NAMES`) for a drill-pipe scene, `values_per_parameter` values each.

    - ``stiffness``: K of the internal contacts (keys on head and seat races,
      cage windows, cage on head and seat: ``materials.internal.normal.stiffness``),
      1e3–1e7 N/mm^n, log-spaced;
    - ``speed``: ``drive.speed_rpm``, 30–600 rpm, log-spaced;
    - ``curvature_radius``: ``borehole.curvature_radius`` from `tightest_radius` to 5 m, log-spaced;
    - ``key_mass``: ``pipe.ball_keys.ball_mass``, 1/4 to 4 × the scene's, log-spaced;
    - ``damping``: ``materials.internal.normal.damping``, zero and 0.1–100 N·s/mm log-spaced.
    """
    if values_per_parameter < 2:
        raise ValueError(f"values_per_parameter = {values_per_parameter}: must be at least 2")
    resolved = _resolve(scene, ())
    spec = _scene_dict(resolved)
    if spec.get("kind") != "drill-pipe":
        raise ValueError("the built-in stability parameters need a drill-pipe scene (kind = \"drill-pipe\")")
    n = values_per_parameter
    law = spec.get("materials", {}).get("internal", {}).get("normal", {})
    exponent = float(law.get("exponent", 1.0))
    paper_units = law.get("units") == "N-mm-s"
    k_scale = 1.0 if paper_units else 1000.0**exponent
    c_scale = 1.0 if paper_units else 1000.0
    k_unit = f"N/mm^{exponent:g}" if paper_units else f"N/m^{exponent:g}"
    c_unit = "N·s/mm" if paper_units else "N·s/m"
    mass = float(spec["pipe"]["ball_keys"]["ball_mass"])

    def geom(lo: float, hi: float, count: int) -> tuple[float, ...]:
        return tuple(float(v) for v in np.geomspace(lo, hi, count))

    return {
        "stiffness": Parameter(
            "stiffness",
            ("materials.internal.normal.stiffness",),
            tuple(v * k_scale for v in geom(*STIFFNESS_RANGE, n)),
            k_unit,
            "K of the internal (key, cage) contacts",
        ),
        "speed": Parameter("speed", ("drive.speed_rpm",), geom(*SPEED_RANGE, n), "rpm", "drive speed"),
        "curvature_radius": Parameter(
            "curvature_radius",
            ("borehole.curvature_radius",),
            geom(tightest_radius(resolved), LARGEST_RADIUS, n),
            "m",
            "guide tube curvature radius, from the tightest the hinge allows",
        ),
        "key_mass": Parameter(
            "key_mass",
            ("pipe.ball_keys.ball_mass",),
            geom(mass * KEY_MASS_FACTORS[0], mass * KEY_MASS_FACTORS[1], n),
            "kg",
            "ball key mass",
        ),
        "damping": Parameter(
            "damping",
            ("materials.internal.normal.damping",),
            (0.0, *(v * c_scale for v in geom(*DAMPING_RANGE, n - 1))),
            c_unit,
            "damping of the internal contacts (IMPACT c_max)",
        ),
    }


#: The default probe scene: the paper's drill pipe, shortened (see `probe_scene`).
PROBE_JOINTS = 2
PROBE_DURATION = 0.03  # s
PROBE_RAMP = 0.01  # s


def probe_scene(overrides: Iterable[str] = (), duration: float | None = None) -> _native.Scene:
    """The cheap drill-pipe scene `stability` probes by default.

    The paper's scene with ``pipe.joints = 2``, ``simulation.duration = 0.03``
    s and the drive and load ramped in over 0.01 s (instead of 0.3 s) so the
    keys carry the full 1.8 kN·m during the probe; then `overrides`, then
    `duration` [s] if given.
    """
    patches = [
        f"pipe.joints={PROBE_JOINTS}",
        f"simulation.duration={_toml(PROBE_DURATION)}",
        f"drive.ramp={_toml(PROBE_RAMP)}",
        f"load.ramp={_toml(PROBE_RAMP)}",
        *overrides,
    ]
    if duration is not None:
        patches.append(f"simulation.duration={_toml(duration)}")
    return default_scene(patches)


# --------------------------------------------------------------------------- stability: search

#: Bracketing factor of the stable-step search.
BRACKET_FACTOR = 4.0
#: A probe takes at most this many steps (the smallest step probed is duration / this).
MAX_PROBE_STEPS = 1_000_000
#: A probe takes at least this many steps (the largest step probed is duration / this).
MIN_PROBE_STEPS = 20
#: Frames a probe records (energy only; the engine checks divergence at every step and frame).
PROBE_FRAMES = 20
#: Default first guesses [s] on drill-pipe scenes (later values start from the previous value's answer).
DRILL_PIPE_FIRST_GUESS: dict[str, float] = {"explicit": 1e-6, "implicit": 1e-5}


#: Two unstable probes a factor `BRACKET_FACTOR` apart that fail within this fraction of the same
#: simulated time fail for a reason the step does not change (e.g. a penetration the physics makes).
SAME_FAILURE_TIME = 0.1


@dataclass(frozen=True)
class _Search:
    max_stable: float
    min_unstable: float
    probes: int
    wall_s: float
    message: str


@dataclass(frozen=True)
class _Probe:
    error: str | None  # the divergence message; None when the probe finished
    failed_at: float  # simulated time of the failure [s]; NaN when it finished
    wall_s: float


def _probe(scene: _native.Scene, integrator: str, dt: float) -> _Probe:
    """Runs `scene` at step `dt` [s], recording `PROBE_FRAMES` energy frames."""
    duration = scene.duration
    per_frame = max(1, round(duration / PROBE_FRAMES / dt))
    probe = load_scene(scene, _stepping(integrator, dt, per_frame * dt, duration))
    start = time.perf_counter()
    try:
        simulate(probe, progress=False)
    except _native.SimulationError as e:
        run = getattr(e, "run", None)
        steps = _meta_int(run.metadata, "ballcage.steps") if run is not None else None
        failed_at = steps * dt if steps is not None else math.nan
        return _Probe(str(e), failed_at, time.perf_counter() - start)
    return _Probe(None, math.nan, time.perf_counter() - start)


def _largest_stable_step(scene: _native.Scene, integrator: str, guess: float, bisections: int) -> _Search:
    """Brackets the stability limit by factors of `BRACKET_FACTOR`, then bisects `bisections` times in log dt.

    The search stops without a bracket when the step reaches duration /
    `MIN_PROBE_STEPS` still stable, or duration / `MAX_PROBE_STEPS` still
    unstable, or when two unstable probes fail at the same simulated time
    (`SAME_FAILURE_TIME`): a smaller step would not help.
    """
    lo_limit = scene.duration / MAX_PROBE_STEPS
    hi_limit = scene.duration / MIN_PROBE_STEPS
    dt = min(max(guess, lo_limit), hi_limit)
    stable = unstable = math.nan
    message = ""
    probes = 0
    wall = 0.0
    previous_failure = math.nan
    while True:
        result = _probe(scene, integrator, dt)
        probes += 1
        wall += result.wall_s
        if result.error is None:
            stable = dt
            if not math.isnan(unstable) or dt >= hi_limit:
                break
            dt = min(dt * BRACKET_FACTOR, hi_limit)
        else:
            unstable, message = dt, result.error
            if not math.isnan(stable) or dt <= lo_limit:
                break
            if abs(result.failed_at - previous_failure) <= SAME_FAILURE_TIME * result.failed_at:
                return _Search(
                    math.nan,
                    unstable,
                    probes,
                    wall,
                    f"fails at t = {result.failed_at:.4g} s whatever the step (down to {dt:.3g} s), so not for "
                    f"stability: {message}",
                )
            previous_failure = result.failed_at
            dt = max(dt / BRACKET_FACTOR, lo_limit)
    if math.isnan(unstable):
        return _Search(stable, math.nan, probes, wall, f"stable at every step probed, up to {hi_limit:.3g} s (duration / {MIN_PROBE_STEPS})")
    if math.isnan(stable):
        return _Search(math.nan, unstable, probes, wall, f"unstable at every step probed, down to {lo_limit:.3g} s: {message}")
    for _ in range(bisections):
        mid = math.sqrt(stable * unstable)
        result = _probe(scene, integrator, mid)
        probes += 1
        wall += result.wall_s
        if result.error is None:
            stable = mid
        else:
            unstable, message = mid, result.error
    return _Search(stable, unstable, probes, wall, f"unstable at {unstable:.4g} s: {message}")


STABILITY_SCHEMA = pa.schema(
    [
        pa.field("integrator", pa.string(), nullable=False, metadata={"unit": "", "description": "integrator name"}),
        pa.field("parameter", pa.string(), nullable=False, metadata={"unit": "", "description": "varied parameter"}),
        pa.field("value", pa.float64(), nullable=False, metadata={"unit": "see unit", "description": "parameter value"}),
        pa.field("unit", pa.string(), metadata={"unit": "", "description": "unit of value"}),
        pa.field("parameter2", pa.string(), metadata={"unit": "", "description": "second parameter of a grid row, else null"}),
        pa.field("value2", pa.float64(), metadata={"unit": "see unit2", "description": "second parameter's value, else null"}),
        pa.field("unit2", pa.string(), metadata={"unit": "", "description": "unit of value2"}),
        pa.field(
            "max_stable_dt_s",
            pa.float64(),
            metadata={"unit": "s", "description": "largest step probed that finished without a divergence error; NaN if none did"},
        ),
        pa.field(
            "min_unstable_dt_s",
            pa.float64(),
            metadata={"unit": "s", "description": "smallest step probed that diverged; NaN if none did (stable up to the largest step probed)"},
        ),
        pa.field("probes", pa.int64(), nullable=False, metadata={"unit": "", "description": "probe runs of the search"}),
        pa.field("wall_s", pa.float64(), metadata={"unit": "s", "description": "wall time of the probes"}),
        pa.field("message", pa.string(), metadata={"unit": "", "description": "the divergence at the bracket's unstable end, or why there is no bracket"}),
    ]
)


def stability(
    scene: SceneSource | None = None,
    *,
    parameters: Sequence[str | Parameter] | None = None,
    integrators: Sequence[str] | None = None,
    values_per_parameter: int = 5,
    duration: float | None = None,
    overrides: Iterable[str] = (),
    grid: bool = False,
    bisections: int = 5,
    first_guess: float | Mapping[str, float] | None = None,
    progress: bool = False,
) -> pa.Table:
    """The largest stable step of each integrator against each parameter, one at a time (`STABILITY_SCHEMA`).

    `scene`: ``None`` is `probe_scene` (the cheap drill pipe; `overrides` and
    `duration` apply to it); anything else `ballcage.load_scene` takes, with
    `overrides` and then `duration` [s] applied. `parameters`: names of
    `drill_pipe_parameters` (default all, drill-pipe scenes only) or
    `Parameter` objects (any scene). Each value is probed with the others at
    the scene's values. With `grid`, also every stiffness × speed pair
    (drill pipe). A probe is stable when the run finishes without
    `ballcage.SimulationError`; the search brackets the limit by factors of 4
    and then bisects `bisections` times in log dt (4^(1/2^b): 4.4 % for b = 5).
    `first_guess` [s]: the first step tried (default: the scene's dt on
    generic scenes; 1 µs explicit, 10 µs implicit on drill pipes); later
    values start from the previous value's answer.

    Raises `ballcage.SceneError` (before anything runs) for an override or a
    parameter value the scene rejects and `ValueError` for bad arguments.
    """
    names = _check_integrators(integrators if integrators is not None else available_integrators(), "integrators")
    if values_per_parameter < 2:
        raise ValueError(f"values_per_parameter = {values_per_parameter}: must be at least 2")
    if bisections < 0:
        raise ValueError(f"bisections = {bisections}: must be zero or more")
    if duration is not None and not (math.isfinite(duration) and duration > 0):
        raise ValueError(f"duration = {duration!r}: must be a positive time in seconds")
    if scene is None:
        base = probe_scene(overrides, duration)
    else:
        base = _resolve(scene, [*overrides, *([f"simulation.duration={_toml(duration)}"] if duration is not None else [])])
    drill_pipe = _is_drill_pipe(base)
    base = load_scene(base, ['record.tables=["energy"]'])
    builtin = drill_pipe_parameters(base, values_per_parameter) if drill_pipe else {}
    chosen: list[Parameter] = []
    for p in parameters if parameters is not None else (PARAMETER_NAMES if drill_pipe else ()):
        if isinstance(p, Parameter):
            chosen.append(p)
        elif p in builtin:
            chosen.append(builtin[p])
        elif drill_pipe or p in PARAMETER_NAMES:
            where = ", ".join(PARAMETER_NAMES) if drill_pipe else "a drill-pipe scene; give Parameter objects for a generic scene"
            raise ValueError(f"parameters: {p!r} is not a built-in parameter ({where})")
        else:
            raise ValueError(f"parameters: {p!r} is not a built-in parameter (they need a drill-pipe scene; give Parameter objects)")
    if not chosen and not grid:
        raise ValueError("parameters: name at least one (a generic scene needs Parameter objects)")
    if grid and not drill_pipe:
        raise ValueError("grid: the stiffness × speed map needs a drill-pipe scene")

    cases: list[tuple[Parameter, float, Parameter | None, float | None]] = []
    for p in chosen:
        for v in p.values:
            cases.append((p, v, None, None))
    if grid:
        k, s = builtin["stiffness"], builtin["speed"]
        for kv in k.values:
            for sv in s.values:
                cases.append((k, kv, s, sv))
    # Validate every variant before the first probe.
    scenes = [load_scene(base, _assign(p, v) + (_assign(p2, v2) if p2 is not None and v2 is not None else [])) for p, v, p2, v2 in cases]

    say = _Say(progress)
    say(
        f"stability: {len(names)} integrators x {len(cases)} cases, probes of {base.duration:g} s "
        f"(bracket x{BRACKET_FACTOR:g}, {bisections} bisections)"
    )
    rows = []
    for integrator in names:
        family = "explicit" if integrator in EXPLICIT_INTEGRATORS else "implicit"
        if isinstance(first_guess, Mapping):
            start_guess = float(first_guess.get(integrator, base.dt))
        elif first_guess is not None:
            start_guess = float(first_guess)
        else:
            start_guess = DRILL_PIPE_FIRST_GUESS[family] if drill_pipe else base.dt
        guess = start_guess
        previous: tuple[str, str | None] | None = None
        for (p, v, p2, v2), variant in zip(cases, scenes, strict=True):
            series = (p.name, p2.name if p2 else None)
            if series != previous:
                guess, previous = start_guess, series
            found = _largest_stable_step(variant, integrator, guess, bisections)
            if not math.isnan(found.max_stable):
                guess = found.max_stable
            rows.append(
                {
                    "integrator": integrator,
                    "parameter": p.name,
                    "value": float(v),
                    "unit": p.unit,
                    "parameter2": p2.name if p2 else None,
                    "value2": float(v2) if v2 is not None else None,
                    "unit2": p2.unit if p2 else None,
                    "max_stable_dt_s": found.max_stable,
                    "min_unstable_dt_s": found.min_unstable,
                    "probes": found.probes,
                    "wall_s": found.wall_s,
                    "message": found.message,
                }
            )
            where = f"{p.name} = {v:.4g} {p.unit}" + (f", {p2.name} = {v2:.4g} {p2.unit}" if p2 else "")
            answer = (
                f"max stable dt {found.max_stable:.3g} s"
                if math.isfinite(found.max_stable)
                else f"no stable step ({found.message.split(':')[0]})"
            )
            say(f"stability: {integrator}, {where}: {answer} ({found.probes} probes, {found.wall_s:.1f} s)")
    table = pa.Table.from_pylist(rows, schema=STABILITY_SCHEMA)
    meta = {
        "ballcage.study": "stability",
        "ballcage.version": _native.__version__,
        "ballcage.scene": base.to_toml(),
        "ballcage.duration_s": repr(base.duration),
        "ballcage.bracket_factor": repr(BRACKET_FACTOR),
        "ballcage.bisections": str(bisections),
        "ballcage.parameters": json.dumps(
            {p.name: {"keys": list(p.keys), "values": list(p.values), "unit": p.unit, "description": p.description} for p in chosen}
        ),
    }
    if drill_pipe:
        meta["ballcage.tightest_radius_m"] = repr(tightest_radius(base))
    return table.replace_schema_metadata(meta)


def _assign(p: Parameter, value: float) -> list[str]:
    return [f"{key}={_toml(value)}" for key in p.keys]


# --------------------------------------------------------------------------- stability: output


def write_stability(table: pa.Table, out_dir: str | os.PathLike[str], *, command: str | None = None) -> dict[str, Path]:
    """Writes ``stability.parquet``, one heat map ``stability_<parameter>.png`` per parameter
    (``stability_grid.png`` for the stiffness × speed map) and ``stability.md`` into `out_dir`.
    """
    import pyarrow.parquet as pq

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = {}
    path = out / "stability.parquet"
    _write_atomically(path, lambda tmp: pq.write_table(table, str(tmp), compression="zstd"))
    written["parquet"] = path
    rows = table.to_pylist()
    single = [r for r in rows if r["parameter2"] is None]
    figures = {
        f"stability_{name}": _heat_map([r for r in single if r["parameter"] == name])
        for name in dict.fromkeys(r["parameter"] for r in single)
    }
    pairs = [r for r in rows if r["parameter2"] is not None]
    if pairs:
        figures["stability_grid"] = _grid_map(pairs)
    for name, fig in figures.items():
        path = out / f"{name}.png"

        def save(tmp: Path, fig: Figure = fig) -> None:
            fig.savefig(tmp, format="png", dpi=120)

        _write_atomically(path, save)
        written[name] = path
    path = out / "stability.md"
    text = stability_markdown(table, command=command)
    _write_atomically(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    written["md"] = path
    return written


def _log10(x: float) -> float:
    return math.log10(x) if x is not None and math.isfinite(x) and x > 0 else math.nan


def _cell_text(r: Mapping[str, Any]) -> str:
    dt = r["max_stable_dt_s"]
    if dt is None or not math.isfinite(dt):
        return "none"
    return ("≥" if r["min_unstable_dt_s"] is None or math.isnan(r["min_unstable_dt_s"]) else "") + f"{dt:.2g}"


def _value_label(v: float) -> str:
    return f"{v:.3g}"


def _draw_map(
    ax: Axes,
    matrix: np.ndarray,
    texts: list[list[str]],
    vmin: float,
    vmax: float,
    origin: Literal["upper", "lower"] = "upper",
) -> Any:
    import matplotlib

    cmap = matplotlib.colormaps["viridis"].with_extremes(bad="0.85")  # no stable step: grey
    image = ax.imshow(np.ma.masked_invalid(matrix), cmap=cmap, vmin=vmin, vmax=vmax, aspect="auto", origin=origin)
    span = vmax - vmin if vmax > vmin else 1.0
    for i, row in enumerate(texts):
        for j, text in enumerate(row):
            dark = np.isfinite(matrix[i, j]) and (matrix[i, j] - vmin) / span < 0.6  # viridis is dark below ~0.6
            ax.text(j, i, text, ha="center", va="center", fontsize=7, color="w" if dark else "k")
    return image


def _limits(values: Iterable[float]) -> tuple[float, float]:
    finite = [v for v in values if math.isfinite(v)]
    if not finite:
        return -7.0, -3.0
    lo, hi = min(finite), max(finite)
    return (lo - 0.5, hi + 0.5) if hi - lo < 1e-9 else (lo, hi)


def _heat_map(rows: Sequence[Mapping[str, Any]]) -> Figure:
    from ballcage.paper import _figure  # deferred: matplotlib

    integrators_ = list(dict.fromkeys(r["integrator"] for r in rows))
    values = sorted({r["value"] for r in rows})
    by = {(r["integrator"], r["value"]): r for r in rows}
    matrix = np.full((len(integrators_), len(values)), np.nan)
    texts = [["" for _ in values] for _ in integrators_]
    for i, integ in enumerate(integrators_):
        for j, v in enumerate(values):
            r = by.get((integ, v))
            if r is not None:
                matrix[i, j] = _log10(r["max_stable_dt_s"])
                texts[i][j] = _cell_text(r)
    fig = _figure(figsize=(1.3 * len(values) + 3.0, 0.7 * len(integrators_) + 2.0))
    ax = fig.subplots()
    image = _draw_map(ax, matrix, texts, *_limits(matrix.ravel()))
    ax.set_xticks(range(len(values)), [_value_label(v) for v in values])
    ax.set_yticks(range(len(integrators_)), integrators_)
    ax.set_xlabel(f"{rows[0]['parameter']} [{rows[0]['unit']}]")
    ax.set_title(f"Largest stable step vs {rows[0]['parameter']} (cells: dt [s]; ≥: stable at the largest probe)", fontsize=9)
    fig.colorbar(image, ax=ax, label="log10 max stable dt [s]")
    return fig


def _grid_map(rows: Sequence[Mapping[str, Any]]) -> Figure:
    from ballcage.paper import _figure  # deferred: matplotlib

    integrators_ = list(dict.fromkeys(r["integrator"] for r in rows))
    xs = sorted({r["value"] for r in rows})
    ys = sorted({r["value2"] for r in rows})
    fig = _figure(figsize=(4.6 * len(integrators_) + 1.0, 4.2))
    axes = np.atleast_1d(fig.subplots(1, len(integrators_)))
    vmin, vmax = _limits(_log10(r["max_stable_dt_s"]) for r in rows)
    image = None
    for ax, integ in zip(axes, integrators_, strict=True):
        by = {(r["value"], r["value2"]): r for r in rows if r["integrator"] == integ}
        matrix = np.full((len(ys), len(xs)), np.nan)
        texts = [["" for _ in xs] for _ in ys]
        for i, y in enumerate(ys):
            for j, x in enumerate(xs):
                r = by.get((x, y))
                if r is not None:
                    matrix[i, j] = _log10(r["max_stable_dt_s"])
                    texts[i][j] = _cell_text(r)
        image = _draw_map(ax, matrix, texts, vmin, vmax, origin="lower")
        ax.set_xticks(range(len(xs)), [_value_label(v) for v in xs], fontsize=7)
        ax.set_yticks(range(len(ys)), [_value_label(v) for v in ys], fontsize=7)
        ax.set(xlabel=f"{rows[0]['parameter']} [{rows[0]['unit']}]", ylabel=f"{rows[0]['parameter2']} [{rows[0]['unit2']}]", title=integ)
    if image is not None:
        fig.colorbar(image, ax=list(axes), label="log10 max stable dt [s]")
    return fig


def stability_markdown(table: pa.Table, *, command: str | None = None) -> str:
    """``stability.md``: per parameter, integrators × values of the largest stable step [s]."""
    meta = _study_meta(table)
    rows = table.to_pylist()
    lines = ["# Largest stable step", ""]
    if command:
        lines += ["```", command, "```", ""]
    radius = meta.get("ballcage.tightest_radius_m")
    lines.append(
        f"Probe runs of {float(meta.get('ballcage.duration_s', 'nan')):g} s; a probe is stable when it finishes without a "
        f"divergence error. Bracketing by x{float(meta.get('ballcage.bracket_factor', 'nan')):g}, then "
        f"{meta.get('ballcage.bisections', '?')} bisections in log dt. '≥' marks a step stable at the largest probe; "
        "'none' no stable step found (why: below)."
        + (f" Tightest curvature radius the hinge allows: {float(radius):.3f} m." if radius else "")
    )
    single = [r for r in rows if r["parameter2"] is None]
    for name in dict.fromkeys(r["parameter"] for r in single):
        mine = [r for r in single if r["parameter"] == name]
        values = sorted({r["value"] for r in mine})
        by = {(r["integrator"], r["value"]): r for r in mine}
        lines += [
            "",
            f"## {name} [{mine[0]['unit']}]",
            "",
            "| integrator | " + " | ".join(_value_label(v) for v in values) + " |",
            "| --- | " + " | ".join("---:" for _ in values) + " |",
        ]
        for integ in dict.fromkeys(r["integrator"] for r in mine):
            lines.append("| " + integ + " | " + " | ".join(_cell_text(by[(integ, v)]) if (integ, v) in by else "" for v in values) + " |")
    pairs = [r for r in rows if r["parameter2"] is not None]
    if pairs:
        lines += ["", f"## {pairs[0]['parameter']} x {pairs[0]['parameter2']}: see stability_grid.png and stability.parquet"]
    failed = [r for r in rows if not math.isfinite(r["max_stable_dt_s"])]
    if failed:
        lines += ["", "## No stable step", ""]
        for r in failed:
            where = f"{r['parameter']} = {r['value']:.4g} {r['unit']}"
            if r["parameter2"] is not None:
                where += f", {r['parameter2']} = {r['value2']:.4g} {r['unit2']}"
            lines.append(f"- {r['integrator']}, {where}: {r['message']}")
    return "\n".join(lines) + "\n"
