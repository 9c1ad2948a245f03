"""The setting of a verification run: a scene's error bound ten times tighter (`tighter`).

``ballcage run --verify`` (`ballcage.verify.verify`) reruns a scene at this
setting and takes the difference of its headline quantities as the run's
measured error; ``ballcage sensitivity`` (`ballcage.studies.sensitivity_run`)
runs its base case at this setting as one case of its sweep, for the
numerical-error bar of its tornado charts. One rule, here, for both.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from typing import Any

from ballcage import _native

__all__ = ["TIGHTER", "Tighter", "cost_factor", "tighter"]

#: A run's error bound falls by this factor in the verification run.
TIGHTER = 10


@dataclass(frozen=True)
class Tighter:
    """The verification run's setting: its `label` (``"dt/4"``, ``"rtol/10"``) and the `overrides` that make it."""

    label: str
    overrides: tuple[str, ...]

    def values(self) -> dict[str, Any]:
        """The `overrides` as a sweep case's values: dotted key -> value (parsed from its TOML text)."""
        out = {}
        for override in self.overrides:
            key, _, text = override.partition("=")
            out[key] = tomllib.loads(f"v = {text}")["v"]
        return out


#: The integrators whose stages are solved by Newton iterations to ``simulation.newton.tolerance``.
NEWTON_INTEGRATORS = tuple(name for name, facts in _native.integrator_facts().items() if facts["newton_stages"])
#: The absolute tolerances of ``[simulation]``: ``atol`` and one per quantity.
ATOL_KEYS = ("atol", "atol_position", "atol_rotation", "atol_velocity", "atol_angular_velocity")


def tighter(scene: _native.Scene, times: int = 1) -> Tighter:
    """The verification run's setting: the scene's error bound ten times tighter, `times` over (1 or 2).

    - Adaptive steps (a positive ``simulation.rtol``; ESDIRK3(2)): ``rtol/10``,
      and each absolute tolerance the scene sets (``simulation.atol`` and the
      per-quantity ``atol_*``) over 10 (unset, they follow rtol). ``max_step``, the largest step, is kept.
    - Fixed steps: ``dt/d`` with d = ceil(10^(1/p)), p the integrator's order
      (symplectic-euler and linearly-implicit-euler 1 → dt/10, sdirk2 2 →
      dt/4, trbdf2 2 → dt/4, esdirk32 3 → dt/3, rk4 4 → dt/2), so the error bound C·dt^p falls
      by d^p ≥ 10. ``simulation.output_interval``, k·dt, is k·d of the new
      step, so the frames are the same. The Newton iterations of sdirk2,
      trbdf2 and esdirk32 stop at ``simulation.newton.tolerance`` whatever the step, an
      error of their own: it is divided by 10 as well. (With adaptive steps
      they stop at min(tolerance, rtol/10), which follows rtol.)

    ``times=2`` applies the rule twice (``rtol/100``, ``dt/16`` for sdirk2): the
    second verification run of ``verify=2``, which checks the first.

    Every other field (``max_steps`` among them) is kept: a ``max_steps`` the
    d times more steps exceed makes the verification fail.
    """
    if times not in (1, 2):
        raise _native.InputError(f"tighter: times = {times!r} is not 1 or 2 (the verification runs of verify=1 or 2)")
    simulation = scene.value("simulation")
    rtol = simulation.get("rtol")
    if rtol:
        factor = TIGHTER**times
        overrides = [f"simulation.rtol={rtol / factor!r}"]
        for key in ATOL_KEYS:
            if simulation.get(key) is not None:
                overrides.append(f"simulation.{key}={simulation[key] / factor!r}")
        return Tighter(f"rtol/{factor}", tuple(overrides))
    name = simulation["integrator"]
    order = _native.integrator_facts()[name]["order"]
    d = math.ceil(TIGHTER ** (1.0 / order)) ** times
    overrides = [f"simulation.dt={simulation['dt'] / d!r}"]
    if name in NEWTON_INTEGRATORS:
        newton = scene.value("simulation.newton.tolerance")
        overrides.append(f"simulation.newton.tolerance={newton / TIGHTER**times:.6g}")
    return Tighter(f"dt/{d}", tuple(overrides))


def cost_factor(label: str) -> float:
    """How many runs a verification run at the setting `label` (`Tighter.label`) costs: d for ``dt/d``; for
    ``rtol/f``, f^(1/3), since ESDIRK3(2)'s steps grow as the tolerance^(-1/3); the largest of several labels
    (``"rtol/10, dt/4"``, a sweep whose cases differ)."""
    factors = [float(x.removeprefix("dt/")) if x.startswith("dt/") else float(x.removeprefix("rtol/")) ** (1.0 / 3.0)
               for x in label.split(", ")]  # fmt: skip
    return max(factors)
