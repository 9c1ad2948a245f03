"""The stable-step search: probe runs at one step, bracketing the stability limit, then bisection in log dt."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

from ballcage import _native
from ballcage.run import simulate
from ballcage.scene import load_scene
from ballcage.studies.common import meta_int, stepping

__all__ = ["BRACKET_FACTOR", "DRILL_PIPE_FIRST_GUESS", "Search", "largest_stable_step"]

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
class Search:
    """The answer of one search: the bracket [s], the probes it took, their wall time [s] and why it ended."""

    max_stable: float
    min_unstable: float
    probes: int
    wall_s: float
    message: str


@dataclass(frozen=True)
class _Probe:
    """One probe run: whether it diverged, when, and its wall time [s]."""

    error: str | None  # the divergence message; None when the probe finished
    failed_at: float  # simulated time of the failure [s]; NaN when it finished
    wall_s: float


def _probe(scene: _native.Scene, integrator: str, dt: float) -> _Probe:
    """Runs `scene` at step `dt` [s], recording `PROBE_FRAMES` energy frames."""
    duration = scene.duration
    per_frame = max(1, round(duration / PROBE_FRAMES / dt))
    probe = load_scene(scene, stepping(integrator, dt, per_frame * dt, duration))
    start = time.perf_counter()
    try:
        simulate(probe, progress=False)
    except _native.SimulationError as e:
        run = getattr(e, "run", None)
        steps = meta_int(run.metadata, "ballcage.steps") if run is not None else None
        failed_at = steps * dt if steps is not None else math.nan
        return _Probe(str(e), failed_at, time.perf_counter() - start)
    return _Probe(None, math.nan, time.perf_counter() - start)


def largest_stable_step(scene: _native.Scene, integrator: str, guess: float, bisections: int) -> Search:
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
                return Search(
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
        return Search(stable, math.nan, probes, wall, f"stable at every step probed, up to {hi_limit:.3g} s (duration / {MIN_PROBE_STEPS})")
    if math.isnan(stable):
        return Search(math.nan, unstable, probes, wall, f"unstable at every step probed, down to {lo_limit:.3g} s: {message}")
    for _ in range(bisections):
        mid = math.sqrt(stable * unstable)
        result = _probe(scene, integrator, mid)
        probes += 1
        wall += result.wall_s
        if result.error is None:
            stable = mid
        else:
            unstable, message = mid, result.error
    return Search(stable, unstable, probes, wall, f"unstable at {unstable:.4g} s: {message}")
