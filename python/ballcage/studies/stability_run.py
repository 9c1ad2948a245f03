"""Running the stability study: `stability` probes each integrator against each parameter value."""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Mapping, Sequence
from typing import Any, TypeAlias

import pyarrow as pa

from ballcage import _native
from ballcage._native import InputError
from ballcage.scene import SceneSource, load_scene
from ballcage.studies.common import (
    Say,
    available_integrators,
    check_duration,
    check_integrators,
    family,
    is_drill_pipe,
    resolve,
    toml_value,
)
from ballcage.studies.schemas import STABILITY_SCHEMA
from ballcage.studies.stability_parameters import (
    PARAMETER_NAMES,
    Parameter,
    assign,
    drill_pipe_parameters,
    probe_scene,
    tightest_radius,
)
from ballcage.studies.stability_search import BRACKET_FACTOR, DRILL_PIPE_FIRST_GUESS, Search, largest_stable_step

__all__ = ["stability"]

#: One probed variant: a parameter and its value, and for a grid row a second parameter and value.
Case: TypeAlias = tuple[Parameter, float, Parameter | None, float | None]


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
    names = check_integrators(integrators if integrators is not None else available_integrators(), "integrators")
    if values_per_parameter < 2:
        raise InputError(f"values_per_parameter = {values_per_parameter}: must be at least 2")
    if bisections < 0:
        raise InputError(f"bisections = {bisections}: must be zero or more")
    check_duration(duration)
    base = _base_scene(scene, overrides, duration)
    drill_pipe = is_drill_pipe(base)
    base = load_scene(base, ['record.tables=["energy"]'])
    builtin = drill_pipe_parameters(base, values_per_parameter) if drill_pipe else {}
    chosen = _chosen(parameters, builtin, drill_pipe, grid)
    cases = _cases(chosen, builtin if grid else None)
    # Validate every variant before the first probe.
    scenes = [load_scene(base, _overrides(case)) for case in cases]

    say = Say(progress)
    say(
        f"stability: {len(names)} integrators x {len(cases)} cases, probes of {base.duration:g} s "
        f"(bracket x{BRACKET_FACTOR:g}, {bisections} bisections)"
    )
    rows = []
    for integrator in names:
        start = _first_guess(first_guess, integrator, base, drill_pipe)
        rows += _search_cases(integrator, cases, scenes, start, bisections, say)
    table = pa.Table.from_pylist(rows, schema=STABILITY_SCHEMA)
    return table.replace_schema_metadata(_metadata(base, chosen, bisections, drill_pipe))


def _base_scene(scene: SceneSource | None, overrides: Iterable[str], duration: float | None) -> _native.Scene:
    """The scene to probe: `probe_scene` for ``None``, else `scene` with `overrides`, then `duration` [s]."""
    if scene is None:
        return probe_scene(overrides, duration)
    return resolve(scene, [*overrides, *([f"simulation.duration={toml_value(duration)}"] if duration is not None else [])])


def _chosen(
    parameters: Sequence[str | Parameter] | None, builtin: Mapping[str, Parameter], drill_pipe: bool, grid: bool
) -> list[Parameter]:
    """The parameters to vary one at a time; `ValueError` naming an unknown one or for an empty study."""
    chosen: list[Parameter] = []
    for p in parameters if parameters is not None else (PARAMETER_NAMES if drill_pipe else ()):
        if isinstance(p, Parameter):
            chosen.append(p)
        elif p in builtin:
            chosen.append(builtin[p])
        elif drill_pipe or p in PARAMETER_NAMES:
            where = ", ".join(PARAMETER_NAMES) if drill_pipe else "a drill-pipe scene; give Parameter objects for a generic scene"
            raise InputError(f"parameters: {p!r} is not a built-in parameter ({where})")
        else:
            raise InputError(f"parameters: {p!r} is not a built-in parameter (they need a drill-pipe scene; give Parameter objects)")
    if not chosen and not grid:
        raise InputError("parameters: name at least one (a generic scene needs Parameter objects)")
    if grid and not drill_pipe:
        raise InputError("grid: the stiffness × speed map needs a drill-pipe scene")
    return chosen


def _cases(chosen: Sequence[Parameter], builtin: Mapping[str, Parameter] | None) -> list[Case]:
    """Each value of each chosen parameter, then (given the built-in parameters) every stiffness × speed pair."""
    cases: list[Case] = [(p, v, None, None) for p in chosen for v in p.values]
    if builtin is not None:
        k, s = builtin["stiffness"], builtin["speed"]
        cases += [(k, kv, s, sv) for kv in k.values for sv in s.values]
    return cases


def _overrides(case: Case) -> list[str]:
    """The overrides that set a case's parameter values."""
    p, v, p2, v2 = case
    return assign(p, v) + (assign(p2, v2) if p2 is not None and v2 is not None else [])


def _first_guess(first_guess: float | Mapping[str, float] | None, integrator: str, base: _native.Scene, drill_pipe: bool) -> float:
    """The first step [s] of each series of `integrator`'s searches."""
    if isinstance(first_guess, Mapping):
        return float(first_guess.get(integrator, base.dt))
    if first_guess is not None:
        return float(first_guess)
    return DRILL_PIPE_FIRST_GUESS[family(integrator)] if drill_pipe else base.dt


def _search_cases(
    integrator: str, cases: Sequence[Case], scenes: Sequence[_native.Scene], start: float, bisections: int, say: Say
) -> list[dict[str, Any]]:
    """One row per case; within a series (same parameters) each search starts from the previous answer."""
    rows = []
    guess = start
    previous: tuple[str, str | None] | None = None
    for (p, v, p2, v2), variant in zip(cases, scenes, strict=True):
        series = (p.name, p2.name if p2 else None)
        if series != previous:
            guess, previous = start, series
        found = largest_stable_step(variant, integrator, guess, bisections)
        if not math.isnan(found.max_stable):
            guess = found.max_stable
        rows.append(_row(integrator, (p, v, p2, v2), found))
        where = f"{p.name} = {v:.4g} {p.unit}" + (f", {p2.name} = {v2:.4g} {p2.unit}" if p2 else "")
        answer = (
            f"max stable dt {found.max_stable:.3g} s"
            if math.isfinite(found.max_stable)
            else f"no stable step ({found.message.split(':')[0]})"
        )
        say(f"stability: {integrator}, {where}: {answer} ({found.probes} probes, {found.wall_s:.1f} s)")
    return rows


def _row(integrator: str, case: Case, found: Search) -> dict[str, Any]:
    p, v, p2, v2 = case
    return {
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


def _metadata(base: _native.Scene, chosen: Sequence[Parameter], bisections: int, drill_pipe: bool) -> dict[str, str]:
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
    return meta
