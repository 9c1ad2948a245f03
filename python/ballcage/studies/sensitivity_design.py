"""The cases of a sensitivity study (`ballcage.studies.sensitivity_run`): what each run of its sweep is.

- `oat_design`: the base run (case 0), then each parameter at its low and at
  its high value in turn, the others at the base; an end equal to the base
  value is the base run, not run again.
- `morris_design`: the base run, then SALib's Morris design
  (`SALib.sample.morris.sample`): `trajectories` paths of P + 1 runs on a
  grid of `levels` levels, seeded so that the same study designs the same runs.
- `add_check`: the verification case, last: the base run at ``ballcage run
  --verify``'s tighter setting (`ballcage.studies.refinement.tighter`).

SALib is the optional extra ``ballcage[sensitivity]``; `salib` says so when it is missing.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from ballcage import _native
from ballcage._native import InputError
from ballcage.studies.refinement import Tighter, tighter
from ballcage.studies.sensitivity_parameters import ParameterRange

__all__ = [
    "DEFAULT_LEVELS",
    "DEFAULT_SEED",
    "DEFAULT_TRAJECTORIES",
    "METHODS",
    "SALIB_EXTRA",
    "Design",
    "Role",
    "add_check",
    "check_morris",
    "morris_design",
    "oat_design",
    "problem",
    "salib",
]

#: The methods: one at a time, or Morris elementary effects (SALib).
METHODS: tuple[str, ...] = ("oat", "morris")
#: Morris defaults: trajectories, grid levels (even, as SALib asks) and the seed of the design (fixed, so that
#: running the same command again designs the same runs and resumes).
DEFAULT_TRAJECTORIES, DEFAULT_LEVELS, DEFAULT_SEED = 10, 4, 1
#: What a missing SALib is told.
SALIB_EXTRA = "pip install 'ballcage[sensitivity]' (or pip install SALib)"


@dataclass(frozen=True)
class Role:
    """What one case of the study is: the base run, a parameter at its low or high value, a Morris run, the check."""

    kind: str  # "base", "low", "high", "morris" or "verify"
    parameter: str | None = None


@dataclass
class Design:
    """The study's cases: each one's swept values and role; Morris's design matrix and settings."""

    method: str
    ranges: list[ParameterRange]
    values: list[dict[str, Any]]  # the listed cases of the sweep, in order
    roles: list[Role]
    check: Tighter | None  # the verification case's setting; None without one
    trajectories: int | None = None
    levels: int | None = None
    seed: int | None = None
    morris_x: list[list[float]] = field(default_factory=list)  # SALib's design, one row per Morris run
    ends: dict[str, tuple[int, int]] = field(default_factory=dict)  # OAT: key -> the cases at (low, high); 0 the base

    def indices(self, kind: str, parameter: str | None = None) -> list[int]:
        """The cases of one kind of role (of one parameter), in order."""
        return [i for i, r in enumerate(self.roles) if r.kind == kind and (parameter is None or r.parameter == parameter)]

    @property
    def delta(self) -> float | None:
        """Morris's grid jump Δ = L / (2(L − 1)), a fraction of each range; None for OAT."""
        return self.levels / (2.0 * (self.levels - 1)) if self.levels else None


def check_morris(trajectories: Any, levels: Any, seed: Any) -> None:
    """`InputError` naming the setting unless `trajectories` ≥ 2, `levels` even ≥ 2, `seed` ≥ 0 and SALib installed."""
    for name, value, least in (("trajectories", trajectories, 2), ("levels", levels, 2)):
        if isinstance(value, bool) or not isinstance(value, int) or value < least:
            raise InputError(f"{name} = {value!r}: must be a whole number, at least {least} "
                             + ("(Morris needs two elementary effects per parameter for sigma)" if name == "trajectories"
                                else "(the levels of Morris's grid)"))
    if levels % 2:
        raise InputError(f"levels = {levels}: must be even (SALib's Morris design jumps half the grid)")
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise InputError(f"seed = {seed!r}: must be a whole number, at least 0")
    salib()


def salib() -> Any:
    """SALib's Morris module pair (sample, analyze); `InputError` naming the extra when SALib is missing."""
    try:
        from SALib.analyze import morris as analyze
        from SALib.sample import morris as sample
    except ImportError as e:
        raise InputError(f"method = 'morris' needs SALib, which is not installed ({e}): {SALIB_EXTRA}") from None
    return sample, analyze


def oat_design(ranges: list[ParameterRange]) -> Design:
    """The base run, then each parameter at its low and at its high value (an end at the base value is the base run)."""
    design = Design("oat", ranges, [{}], [Role("base")], None)
    for r in ranges:
        ends = []
        for kind, value in (("low", r.low), ("high", r.high)):
            if value == r.base:
                ends.append(0)
                continue
            ends.append(len(design.values))
            design.values.append({r.key: r.scene_value(value)})
            design.roles.append(Role(kind, r.key))
        design.ends[r.key] = (ends[0], ends[1])
    return design


def morris_design(ranges: list[ParameterRange], trajectories: int, levels: int, seed: int) -> Design:
    """The base run, then SALib's Morris design: `trajectories` paths of P + 1 runs on a `levels`-level grid."""
    sample, _ = salib()
    x = sample.sample(problem(ranges), trajectories, num_levels=levels, seed=seed)
    rows = [[float(v) for v in row] for row in x]
    values: list[dict[str, Any]] = [{}] + [{r.key: v for r, v in zip(ranges, row, strict=True)} for row in rows]
    roles = [Role("base")] + [Role("morris")] * len(rows)
    return Design("morris", ranges, values, roles, None, trajectories, levels, seed, rows)


def problem(ranges: Sequence[ParameterRange]) -> dict[str, Any]:
    """SALib's problem definition of the ranges: names and bounds, in order."""
    return {"num_vars": len(ranges), "names": [r.key for r in ranges], "bounds": [[r.low, r.high] for r in ranges]}


def add_check(design: Design, base: _native.Scene) -> None:
    """Appends the verification case: the base run at ``ballcage run --verify``'s tighter setting."""
    setting = tighter(base)
    design.values.append(setting.values())
    design.roles.append(Role("verify"))
    design.check = setting
