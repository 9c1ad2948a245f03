"""The grid of a design chart and where the chain fits (`ballcage.studies.design_chart`, whose docstring has the rules).

`chart_setup` checks a chart's arguments and its base scene once; `chart_cells`
lays out the cells R × L (L slowest) and has the scene validator of the Rust
core judge each, as its sweep case would run; `Cell.broken` names the closed-form
constraints a cell breaks (eq. (9) and the articulation limit). `chart_spec`
makes the sweep of a list of cells. Everything here is SI: metres, seconds,
kilograms.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from ballcage import _native, sizing
from ballcage.scene import default_scene_toml
from ballcage.studies.sweep_spec import DEFAULT_TABLES, SweepError, SweepSpec, toml_value

__all__ = [
    "CONSTRAINTS",
    "INERTIA",
    "LENGTH",
    "MASS",
    "RADIUS",
    "Cell",
    "ChartError",
    "ReferenceLink",
    "Setup",
    "chart_cells",
    "chart_setup",
    "chart_spec",
]

#: Constraint keys of `Cell.broken` and their labels.
CONSTRAINTS: dict[str, str] = {"eq9": "eq. (9)", "articulation": "articulation limit"}

RADIUS, LENGTH, MASS, INERTIA = "borehole.curvature_radius", "pipe.pitch", "pipe.link_mass", "pipe.link_inertia"
#: Scene keys the chart sets itself, and the argument that sets each; an override of one is refused.
_CHART_KEYS: dict[str, str] = {
    RADIUS: "`radii`, --radius-mm",
    LENGTH: "`lengths`, --length-mm",
    "borehole.inner_diameter": "`tube_inner_diameter`, --tube-id",
    "pipe.link_diameter": "`joint_diameter`, --joint-od",
    "pipe.hinge": "`hinge`, --hinge",
    "simulation.duration": "`duration`, --duration",
    "record.summary_window": "`window`, --window",
}
#: Where the base scene is checked: a bend so wide that every joint of the grid fits it [m].
_WIDE_RADIUS = 1e3


class ChartError(SweepError):
    """Bad input to a design chart; the message names the argument, the value and the reason."""


@dataclass(frozen=True)
class ReferenceLink:
    """The link masses scale from: length [m], mass [kg], inertia (axial, transverse, transverse) [kg·m²], radius [m]."""

    length: float
    mass: float
    inertia: tuple[float, ...]
    radius: float

    @classmethod
    def of(cls, scene: _native.Scene) -> ReferenceLink:
        """The link of a drill-pipe scene: ``pipe.pitch``, ``pipe.link_mass``, ``pipe.link_inertia``, ``pipe.link_diameter`` / 2."""
        inertia = tuple(float(v) for v in scene.value(INERTIA))
        return cls(float(scene.value(LENGTH)), float(scene.value(MASS)), inertia, float(scene.value("pipe.link_diameter")) / 2)

    def scaled(self, length: float) -> tuple[float, list[float]]:
        """Mass [kg] and inertia [kg·m²] of a link `length` [m] long (`ballcage.studies.design_chart`'s docstring gives the rule).

        m = m₀·L/L₀; axial I_a = I_a0·m/m₀; transverse I_t = I_t0·m(3r₀² + L²) / (m₀(3r₀² + L₀²)).
        At L = L₀ it returns the reference's own values exactly.
        """
        ratio = length / self.length
        shape = (3 * self.radius**2 + length**2) / (3 * self.radius**2 + self.length**2)
        axial, *transverse = self.inertia
        return self.mass * ratio, [axial * ratio, *(t * ratio * shape for t in transverse)]


@dataclass(frozen=True)
class Cell:
    """One cell of the chart: R [m], L [m], its scene overrides, the constraints it breaks, the validator's refusal."""

    radius: float
    length: float
    values: dict[str, Any]
    broken: tuple[str, ...]  # keys of CONSTRAINTS
    refusal: str | None  # the SceneError message; None when the scene is valid

    @property
    def feasible(self) -> bool:
        return self.refusal is None

    @property
    def reason(self) -> str | None:
        """Why the cell is infeasible: ``"eq. (9)"``, ``"articulation limit"``, both, or the validator's message."""
        if self.refusal is None:
            return None
        return " and ".join(CONSTRAINTS[b] for b in self.broken) or f"scene refused: {self.refusal}"


@dataclass(frozen=True)
class Setup:
    """What every cell shares: the base scene text, the chart's fixed keys, the link and the limits."""

    base_toml: str
    fixed: dict[str, Any]
    link: ReferenceLink
    scale_mass: bool
    limit_deg: float | None  # the hinge's articulation limit; None when nothing limits the bend
    joints: int
    overrides: tuple[str, ...]

    @property
    def tube(self) -> float:
        return float(self.fixed["borehole.inner_diameter"])

    @property
    def joint(self) -> float:
        return float(self.fixed["pipe.link_diameter"])


def chart_setup(
    radii: Sequence[float],
    lengths: Sequence[float],
    tube: float | None,
    joint: float | None,
    hinge: str,
    duration: float,
    window: tuple[float, float] | None,
    scale_mass: bool,
    overrides: Sequence[str],
) -> Setup:
    """Checks the arguments and the base scene; raises `ChartError` naming the argument."""
    for name, values in (("radii", radii), ("lengths", lengths)):
        if len(values) == 0:
            raise ChartError(f"{name}: empty; give at least one length in metres")
        for v in values:
            _positive(name, v, "m")
    duration = _positive("duration", duration, "s")
    start, end = (duration / 2, duration) if window is None else (float(window[0]), float(window[1]))
    if not (0 <= start < end <= duration):
        raise ChartError(f"window (--window) = ({start:g}, {end:g}) s: must satisfy 0 <= start < end <= duration = {duration:g} s")
    for text in overrides:
        key = text.partition("=")[0].strip()
        if key in _CHART_KEYS:
            raise ChartError(f"override {text!r}: the chart sets `{key}` itself (use {_CHART_KEYS[key]})")
    base = _scene(default_scene_toml(), [*overrides, f"{RADIUS}={_WIDE_RADIUS!r}"], "overrides (--set)")
    tube = _positive("tube_inner_diameter", tube, "m") if tube is not None else float(base.value("borehole.inner_diameter"))
    joint = _positive("joint_diameter", joint, "m") if joint is not None else float(base.value("pipe.link_diameter"))
    if joint >= tube:
        raise ChartError(f"joint_diameter = {joint:g} m: not narrower than the tube, tube_inner_diameter = {tube:g} m")
    fixed = {
        "borehole.inner_diameter": tube,
        "pipe.link_diameter": joint,
        "pipe.hinge": hinge,
        "simulation.duration": duration,
        "record.summary_window": [start, end],
    }
    shared = _scene(base.to_toml(), [f"{k}={toml_value(v)}" for k, v in fixed.items()], "hinge, diameters or duration")
    return Setup(
        base.to_toml(), fixed, ReferenceLink.of(base), scale_mass, shared.articulation_limit_deg(),
        int(shared.value("pipe.joints")), tuple(overrides),
    )


def _positive(name: str, value: Any, unit: str) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ChartError(f"{name} = {value!r}: not a number in {unit}") from None
    if not (math.isfinite(number) and number > 0):
        raise ChartError(f"{name} = {value!r} {unit}: must be positive and finite")
    return number


def _scene(text: str, overrides: list[str], what: str) -> _native.Scene:
    try:
        scene = _native.Scene.from_toml(text, overrides)
    except _native.SceneError as e:
        raise ChartError(f"{what}: {e}") from None
    if scene.kind != "drill-pipe":
        raise ChartError(f"{what}: the chart needs a drill-pipe scene, not a {scene.kind} one")
    return scene


def chart_cells(setup: Setup, radii: list[float], lengths: list[float]) -> list[Cell]:
    """Every cell, L slowest then R, each validated by the scene validator exactly as its sweep case would run."""
    spec = chart_spec(setup, [_values(setup, r, length) for length in lengths for r in radii])
    cells = []
    for case in spec.cases():
        radius, length = case.values[RADIUS], case.values[LENGTH]
        try:
            _native.Scene.from_toml(spec.base_toml, list(case.overrides))
            refusal = None
        except _native.SceneError as e:
            refusal = str(e)
        cells.append(Cell(radius, length, case.values, _broken(setup, radius, length), refusal))
    return cells


def _values(setup: Setup, radius: float, length: float) -> dict[str, Any]:
    values: dict[str, Any] = {RADIUS: radius, LENGTH: length}
    if setup.scale_mass:
        values[MASS], values[INERTIA] = setup.link.scaled(length)
    return values


def _broken(setup: Setup, radius: float, length: float) -> tuple[str, ...]:
    """The constraints a cell breaks, by the closed forms (eq. (9); the articulation limit on chains of 2+ links)."""
    out = []
    if radius < setup.tube / 2 or length > sizing.longest_link(radius, setup.tube, setup.joint):
        out.append("eq9")
    if setup.limit_deg is not None and setup.joints >= 2:
        if radius < sizing.tightest_radius_for_bend(length, setup.limit_deg):
            out.append("articulation")
    return tuple(out)


def chart_spec(setup: Setup, cases: list[dict[str, Any]]) -> SweepSpec:
    return SweepSpec(
        name="design-chart",
        base_toml=setup.base_toml,
        tables=list(DEFAULT_TABLES),
        fixed=dict(setup.fixed),
        listed=cases,
        source="design chart",
    )
