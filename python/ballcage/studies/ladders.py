"""The accuracy study's steps: default ladders, checked user ladders, and snapping to one output grid.

Every run of a study records at one output interval (the scene's, or a
multiple of it covering the largest step) and each step is snapped to a whole
fraction of it, so peaks are taken over the same frames; the duration is
snapped to a whole number of output intervals.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence

from ballcage import _native
from ballcage._native import InputError, whole_multiple
from ballcage.studies.common import family, is_drill_pipe

__all__ = ["DRILL_PIPE_STEPS", "GENERIC_STEP_FACTORS", "REFERENCE_DIVISOR", "default_steps"]

#: Default ladders [s] on drill-pipe scenes: the ball keys' contact needs ~1 µs explicit steps
#: (docs/accuracy.md); implicit steps are bounded by accuracy, not by stability. The implicit
#: ladders keep a default study of the paper scene within minutes (reference at 12.5 µs).
DRILL_PIPE_STEPS: dict[str, tuple[float, ...]] = {
    "symplectic-euler": (1e-6, 5e-7, 2e-7, 1e-7),
    "rk4": (2e-6, 1e-6, 5e-7, 2e-7),
    "linearly-implicit-euler": (1e-4, 5e-5, 2e-5),
    "sdirk2": (2e-4, 1e-4, 5e-5),
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
    if is_drill_pipe(scene):
        steps = DRILL_PIPE_STEPS.get(integrator)
        if steps is None:
            steps = DRILL_PIPE_STEPS["symplectic-euler" if family(integrator) == "explicit" else "sdirk2"]
        return steps
    return tuple(scene.dt * f for f in GENERIC_STEP_FACTORS[family(integrator)])


def ladders(
    scene: _native.Scene,
    names: Sequence[str],
    steps: Sequence[float] | Mapping[str, Sequence[float]] | None,
) -> dict[str, tuple[float, ...]]:
    """The ladder [s] of each studied integrator: `steps` for all, per name, or the defaults."""
    out: dict[str, tuple[float, ...]] = {}
    if isinstance(steps, Mapping):
        unknown = [k for k in steps if k not in names]
        if unknown:
            raise InputError(f"steps: {unknown[0]!r} is not one of the studied integrators ({', '.join(names)})")
    for name in names:
        if steps is None:
            out[name] = default_steps(scene, name)
        elif isinstance(steps, Mapping):
            out[name] = check_steps(steps[name], f"steps[{name!r}]") if name in steps else default_steps(scene, name)
        else:
            out[name] = check_steps(steps, "steps")
    return out


def reference_step(
    scene: _native.Scene, integrator: str, ladders: Mapping[str, Sequence[float]], reference_dt: float | None
) -> float:
    """`reference_dt` [s] checked, or the reference integrator's smallest ladder step / `REFERENCE_DIVISOR`."""
    if reference_dt is None:
        ladder = ladders.get(integrator) or default_steps(scene, integrator)
        return min(ladder) / REFERENCE_DIVISOR
    if not (math.isfinite(reference_dt) and reference_dt > 0):
        raise InputError(f"reference_dt = {reference_dt!r}: must be a positive step in seconds")
    return reference_dt


def check_steps(steps: Iterable[float], what: str) -> tuple[float, ...]:
    """`steps` [s] as floats, largest first without repeats; `ValueError` naming `what` for a bad one."""
    out = []
    for dt in steps:
        dt = float(dt)
        if not (math.isfinite(dt) and dt > 0):
            raise InputError(f"{what}: {dt!r} is not a positive step in seconds")
        out.append(dt)
    if not out:
        raise InputError(f"{what}: give at least one step")
    return tuple(sorted(set(out), reverse=True))


def snap_grid(output_interval: float, duration: float, steps: Iterable[float]) -> tuple[float, float, dict[float, float]]:
    """Common output interval [s], duration [s] and each step [s] snapped to a whole fraction of the interval.

    The interval is the scene's `output_interval`, or its smallest multiple
    that holds the largest step; the duration a whole number of intervals.
    A value that already fits (`ballcage._native.whole_multiple`, the
    engine's own test) is kept as given.
    """
    steps = list(steps)
    interval = output_interval
    largest = max(steps)
    if largest > interval and whole_multiple(interval, largest) is None:
        interval *= whole_multiple(largest, interval) or math.ceil(largest / interval)
    snapped = {dt: dt if whole_multiple(interval, dt) else interval / max(1, round(interval / dt)) for dt in steps}
    if not whole_multiple(duration, interval):
        duration = interval * max(1, round(duration / interval))
    return interval, duration, snapped
