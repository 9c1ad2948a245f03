"""What both studies share: integrator names, scene overrides, progress lines and table metadata."""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Iterable, Mapping, Sequence

import pyarrow as pa

from ballcage import _native
from ballcage._native import InputError
from ballcage.scene import SceneSource, default_scene, load_scene, override_list

__all__ = ["StudyError", "available_integrators"]


class StudyError(_native.Error, RuntimeError):
    """A study that cannot go on, e.g. because its reference run diverged."""


#: The default reference integrator of the accuracy study.
REFERENCE_INTEGRATOR = "sdirk2"


def available_integrators() -> tuple[str, ...]:
    """Every integrator the engine offers (``_native.INTEGRATORS``), in the docs' order."""
    return tuple(str(n) for n in _native.INTEGRATORS)


def family(integrator: str) -> str:
    """``"implicit"`` (a linear solve per step) or ``"explicit"`` (the step must resolve the stiffest contact).

    Raises `ValueError` naming `integrator` when the engine does not know it.
    """
    facts = _native.integrator_facts()
    if integrator not in facts:
        raise InputError(f"integrator {integrator!r}: not an integrator (integrators: {', '.join(facts)})")
    return "implicit" if facts[integrator]["implicit"] else "explicit"


def check_integrators(names: Iterable[str], what: str = "integrators") -> list[str]:
    """`names` without repeats, in order; `ValueError` naming `what` for an unknown name or none at all."""
    known = available_integrators()
    out: list[str] = []
    for name in names:
        if name not in known:
            raise InputError(f"{what}: {name!r} is not an integrator (integrators: {', '.join(known)})")
        if name not in out:
            out.append(name)
    if not out:
        raise InputError(f"{what}: name at least one integrator")
    return out


def check_duration(duration: float | None) -> None:
    """`ValueError` unless `duration` is ``None`` or a positive finite time [s]."""
    if duration is not None and not (math.isfinite(duration) and duration > 0):
        raise InputError(f"duration = {duration!r}: must be a positive time in seconds")


# --------------------------------------------------------------------------- scenes


def is_drill_pipe(scene: _native.Scene) -> bool:
    """Whether `scene` is a drill pipe (``kind = "drill-pipe"``)."""
    return scene.kind == "drill-pipe"


def resolve(scene: SceneSource | None, overrides: Iterable[str]) -> _native.Scene:
    """`scene` (``None``: the embedded paper scene) validated with `overrides`."""
    patches = override_list(overrides)
    return default_scene(patches) if scene is None else load_scene(scene, patches)


def toml_value(value: float | str | Sequence[str]) -> str:
    """A value as TOML for a ``key=value`` override."""
    if isinstance(value, str):
        return json.dumps(value)  # a TOML basic string for plain names
    if isinstance(value, Sequence):
        return "[" + ", ".join(json.dumps(v) for v in value) + "]"
    return repr(float(value))


def record(tables: Sequence[str]) -> str:
    """The override that records exactly `tables`."""
    return f"record.tables={toml_value(list(tables))}"


def stepping(integrator: str, dt: float, output_interval: float, duration: float) -> list[str]:
    """Overrides for the integrator, its fixed step `dt`, the `output_interval` and the `duration` [s].

    The steps are fixed (``simulation.rtol = 0``), whatever the scene's own tolerance.
    """
    return [
        f"simulation.integrator={toml_value(integrator)}",
        "simulation.rtol=0",
        f"simulation.dt={toml_value(dt)}",
        f"simulation.output_interval={toml_value(output_interval)}",
        f"simulation.duration={toml_value(duration)}",
    ]


# --------------------------------------------------------------------------- metadata and text


def meta_int(meta: Mapping[str, str], key: str) -> int | None:
    """The run metadata entry `key` as an integer; ``None`` when absent, empty or not a number."""
    text = meta.get(key)
    if text is None or text == "":
        return None
    try:
        return int(float(text))
    except ValueError:
        return None


def implicit_steps(meta: Mapping[str, str]) -> tuple[int, int] | None:
    """Steps an implicit run's integrator took and the implicit stages they solved, from its metadata.

    Each step solves the integrator's ``newton_stages`` (`_native.integrator_facts`: ESDIRK3(2) three, TR-BDF2
    and SDIRK2 two). The ESDIRK pairs count their steps in ``ballcage.accepted_steps`` and
    ``ballcage.rejected_steps`` (at fixed steps every step and part step is an accepted one); SDIRK2 in
    ``ballcage.steps`` and the part steps its halvings added. ``None`` for the integrators without Newton
    iterations.
    """
    facts = _native.integrator_facts().get(meta.get("ballcage.integrator", ""), {})
    stages = facts.get("newton_stages")
    if stages is None:
        return None
    accepted, rejected = meta_int(meta, "ballcage.accepted_steps"), meta_int(meta, "ballcage.rejected_steps")
    if accepted is not None and rejected is not None:
        return accepted + rejected, stages * (accepted + rejected)
    steps, halvings = meta_int(meta, "ballcage.steps"), meta_int(meta, "ballcage.step_halvings") or 0
    return (steps + halvings, stages * (steps + halvings)) if steps else None


def newton_per_stage(meta: Mapping[str, str]) -> float | None:
    """Newton iterations per implicit stage of a run, from its metadata; ``None`` where `implicit_steps` is."""
    taken, iterations = implicit_steps(meta), meta_int(meta, "ballcage.newton_iterations")
    return iterations / taken[1] if taken and taken[1] and iterations is not None else None


def study_meta(table: pa.Table) -> dict[str, str]:
    """A study table's schema metadata, decoded."""
    return {k.decode(): v.decode() for k, v in (table.schema.metadata or {}).items()}


def fmt(x: float | None, digits: int = 3) -> str:
    """`x` to `digits` significant digits; empty for ``None`` and NaN, ``inf`` for infinities."""
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return ""
    if math.isinf(x):
        return "inf"
    return f"{x:.{digits}g}"


class Say:
    """Progress lines on stderr, ``ballcage: ...``; silent unless enabled."""

    def __init__(self, enabled: bool) -> None:
        self.enabled = enabled

    def __call__(self, text: str) -> None:
        if self.enabled:
            print(f"ballcage: {text}", file=sys.stderr, flush=True)
