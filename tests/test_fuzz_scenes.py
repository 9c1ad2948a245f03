"""Property-based fuzzing of scene input (issue 14): Python scene dicts and ``--set`` overrides.

Scene dicts are the embedded drill-pipe scene and the example scenes with
fuzzed values (wrong types, negatives, zeros, NaN and infinities, huge and
tiny numbers, unknown keys, missing sections); overrides are ``key=value``
strings on the scenes' real keys or on any text. Each goes through
`ballcage.load_scene` (or `ballcage.Scene.from_toml`) and, when it loads, a
very short `ballcage.simulate`. The only allowed outcomes:

* a `ballcage.SceneError` whose message names the field (``.path``) it is about,
* a scene that loads, holds no NaN or infinity in any field, and runs to its
  (cut) end or stops with a `ballcage.SimulationError` (a diverged run); either
  way every float column of its tables, partial ones too, holds only finite
  numbers (a nullable column holds nulls, never NaN, where it does not apply).

Anything else (a pyo3 `PanicException`, ballcage's `InternalError`, another
exception, a non-finite number) fails. Runs are capped at a few steps of a
small scene, and hypothesis is derandomized, so the test is deterministic
and short. Longer runs are the cargo-fuzz targets in fuzz/ (docs/reliability.md).
"""

from __future__ import annotations

import copy
import math
import os
import tomllib
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pyarrow as pa
import pyarrow.compute as pc
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

import ballcage
from ballcage import _native

# On a failure, hypothesis's pytest plugin imports its patch writer, which
# imports libcst where installed, which warns (mypy_extensions.TypedDict is
# deprecated); under filterwarnings = error that hides the failure behind
# an INTERNALERROR. Importing it here, with the warning ignored, caches it.
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    try:
        import hypothesis.extra._patching  # noqa: F401
    except ImportError:  # pragma: no cover - libcst absent: nothing to pre-import
        pass

SCENES = Path(__file__).resolve().parent.parent / "examples" / "scenes"

#: Integrator steps a fuzzed scene runs at most.
MAX_STEPS = 4
#: A drill pipe with more joints, or a scene with more bodies, is loaded but not run.
MAX_JOINTS = 2
MAX_BODIES = 40

#: Examples per test: 300 in CI (a few seconds); ``BALLCAGE_FUZZ_EXAMPLES=20000`` for a longer
#: campaign, which also draws fresh random examples instead of the fixed derandomized ones.
EXAMPLES = int(os.environ.get("BALLCAGE_FUZZ_EXAMPLES", "300"))

SETTINGS = settings(
    max_examples=EXAMPLES,
    deadline=None,
    derandomize="BALLCAGE_FUZZ_EXAMPLES" not in os.environ,
    database=None,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much],
)


def _paper() -> dict[str, Any]:
    """The embedded paper scene with one joint (every default written out)."""
    doc = tomllib.loads(_native.default_scene_toml())
    doc["pipe"]["joints"] = 1
    return doc


def _examples() -> list[dict[str, Any]]:
    return [tomllib.loads(p.read_text(encoding="utf-8")) for p in sorted(SCENES.glob("*.toml"))]


BASES: list[dict[str, Any]] = [_paper(), *_examples()]


def _paths(value: Any, prefix: tuple[Any, ...] = ()) -> Iterator[tuple[Any, ...]]:
    """Every path (dict keys and list indices) into `value`, sections and leaves."""
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for key, child in items:
        yield (*prefix, key)
        yield from _paths(child, (*prefix, key))


PATHS: list[list[tuple[Any, ...]]] = [list(_paths(b)) for b in BASES]
WORDS = [
    "generic", "drill-pipe", "rk4", "sdirk2", "symplectic-euler", "linearly-implicit-euler", "sparse-lu",
    "fixed", "dynamic", "kinematic-spin", "spin", "ball", "cuboid", "half-space", "cylinder", "tube",
    "hertz", "linear", "impact", "hunt-crossley", "adams", "tanh", "torus-ball", "cv", "ideal-cv",
    "bodies", "contacts", "energy", "summary", "keys", "SI", "N-mm-s", "",
]  # fmt: skip

#: Numbers at the edges of what a field can hold.
EDGE_FLOATS = [0.0, -0.0, -1.0, 1e-320, 1e-200, 1e-12, 1e12, 1e200, 1.7e308, -1e308, math.nan, math.inf, -math.inf]

numbers = st.one_of(
    st.sampled_from(EDGE_FLOATS),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(2**70), max_value=2**70),
)
scalars = st.one_of(
    st.sampled_from(EDGE_FLOATS),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(2**70), max_value=2**70),
    st.sampled_from([0, -1, 1, 2**31, 2**32, 2**63 - 1, 2**64]),
    st.booleans(),
    st.sampled_from(WORDS),
    st.text(max_size=12),
    st.none(),
)
values = st.recursive(
    scalars,
    lambda inner: st.one_of(st.lists(inner, max_size=4), st.dictionaries(st.sampled_from(WORDS + ["x"]), inner, max_size=3)),
    max_leaves=6,
)


#: Powers of ten a base value is scaled by: near it (0 first: the value itself), and far enough to
#: overflow or underflow what is derived from it (r³, r⁵).
EXPONENTS = [0, *range(-12, 13), -100, -200, -300, 100, 200, 300]


def _scaled(old: Any, exponent: int) -> Any:
    """A number near the base value: scaled by 10**exponent, or negated for odd exponents."""
    if isinstance(old, bool) or not isinstance(old, int | float | list):
        return old
    if isinstance(old, list):
        return [_scaled(x, exponent) for x in old]
    return old * 10.0**exponent * (-1 if exponent % 2 else 1)


@st.composite
def mutated_scene(draw: st.DrawFn) -> dict[str, Any]:
    """A base scene dict with up to four fuzzed edits: a new value, a removed key or section, an unknown key."""
    b = draw(st.integers(0, len(BASES) - 1))
    scene = copy.deepcopy(BASES[b])
    for _ in range(draw(st.sampled_from([1, 1, 1, 2, 2, 3, 4]))):
        path = draw(st.sampled_from(PATHS[b]))
        action = draw(st.sampled_from(["near"] * 4 + ["number"] * 2 + ["set"] * 2 + ["delete", "unknown"]))
        _edit(scene, path, action, draw)
    return scene


def _edit(scene: dict[str, Any], path: tuple[Any, ...], action: str, draw: st.DrawFn) -> None:
    parent: Any = scene
    for key in path[:-1]:
        try:
            parent = parent[key]
        except (KeyError, IndexError, TypeError):
            return  # an earlier edit removed or replaced it
    last = path[-1]
    if isinstance(parent, list):
        if not isinstance(last, int) or last >= len(parent):
            return
    elif not isinstance(parent, dict) or not isinstance(last, str) or (last not in parent and action != "set"):
        return
    if action == "delete":
        del parent[last]
    elif action == "unknown" and isinstance(parent, dict):
        parent[draw(st.sampled_from(["colour", "mass_kg", "Kind", "x"]))] = draw(values)
    elif action == "near":
        parent[last] = _scaled(parent[last], draw(st.sampled_from(EXPONENTS)))
    elif action == "number":
        parent[last] = draw(numbers)
    else:
        parent[last] = draw(values)


def _at(value: Any, path: tuple[Any, ...]) -> Any:
    for key in path:
        value = value[key]
    return value


def _dotted(path: tuple[Any, ...], bracketed: bool) -> str:
    if not bracketed:
        return ".".join(str(k) for k in path)
    out = ""
    for k in path:
        out += f"[{k}]" if isinstance(k, int) else (f".{k}" if out else str(k))
    return out


def _toml_text(value: Any) -> str:
    """A Python value as the value text of an override (TOML, loosely)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf") if math.isinf(value) else repr(value)
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, list):
        return "[" + ", ".join(_toml_text(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {_toml_text(v)}" for k, v in value.items()) + " }"
    return str(value)  # int, None


@st.composite
def overrides(draw: st.DrawFn) -> tuple[int, list[str]]:
    """A base scene and up to four ``key=value`` strings, on its real keys or on any text."""
    b = draw(st.integers(0, len(BASES) - 1))
    out = []
    for _ in range(draw(st.sampled_from([1, 1, 1, 2, 2, 3, 4]))):
        kind = draw(st.sampled_from(["near", "near", "near", "number", "value", "text", "raw"]))
        if kind == "raw":
            out.append(draw(st.text(max_size=30)))
            continue
        path = draw(st.sampled_from(PATHS[b]))
        key = _dotted(path, draw(st.booleans()))
        key += draw(st.sampled_from(["", "", "", "", "", ".0", ".x", "[9]", ".", "..", "=", " "]))
        if kind == "near":
            value = _toml_text(_scaled(_at(BASES[b], path), draw(st.sampled_from(EXPONENTS))))
        elif kind == "number":
            value = _toml_text(draw(numbers))
        elif kind == "value":
            value = _toml_text(draw(values))
        else:
            value = draw(st.text(max_size=12))
        out.append(f"{key}={value}")
    return b, out


def _nonfinite_columns(table: pa.Table) -> list[str]:
    """Float columns holding NaN or ±inf among their non-null values."""
    bad = []
    for name, column in zip(table.column_names, table.columns, strict=True):
        if pa.types.is_floating(column.type) and pc.any(pc.invert(pc.is_finite(column))).as_py():
            bad.append(name)
    return bad


def _check_scene_error(e: ballcage.SceneError) -> None:
    message = str(e)
    assert message.strip(), "a SceneError without a message"
    path = getattr(e, "path", "")
    if path:
        assert path in message, f"the message {message!r} does not name the field {path!r}"


def _non_finite_at(value: Any, path: str = "") -> str | None:
    """The dotted path of the first NaN or infinity in a resolved scene (every field is validated: none may hold one)."""
    if isinstance(value, float) and not math.isfinite(value):
        return path
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for key, child in items:
        found = _non_finite_at(child, f"{path}.{key}" if path else str(key))
        if found is not None:
            return found
    return None


def _too_big(scene: ballcage.Scene) -> bool:
    if scene.kind == "drill-pipe":
        return int(scene.value("pipe.joints")) > MAX_JOINTS
    return len(scene.value("bodies")) > MAX_BODIES


def check(source: Any, patches: list[str]) -> str:
    """Loads and briefly runs a fuzzed scene; fails on any outcome but the allowed ones."""
    try:
        scene = ballcage.load_scene(source, patches) if isinstance(source, dict) else _native.Scene.from_toml(source, patches)
    except ballcage.SceneError as e:
        _check_scene_error(e)
        return "rejected"
    where = _non_finite_at(scene.value(""))
    assert where is None, f"the loaded scene holds a non-finite number at `{where}`:\n{scene.to_toml()}"
    if _too_big(scene) or scene.value("simulation.threads") > 2 or scene.value("simulation.newton.max_iterations") > 50:
        return "not run"
    # A few steps: the duration cut to MAX_STEPS steps (when it is longer).
    cut = [f"simulation.duration={MAX_STEPS * scene.dt!r}"] if scene.duration > MAX_STEPS * scene.dt else []
    try:
        run = ballcage.simulate(scene, overrides=cut, progress=False)
        outcome = "ran"
    except ballcage.SimulationError as e:
        run, outcome = e.run, "diverged"  # type: ignore[attr-defined]
    except ballcage.SceneError as e:  # the cut duration can be rejected (a step longer than it)
        _check_scene_error(e)
        return "rejected"
    for name, table in run.tables.items():
        bad = _nonfinite_columns(table)
        assert not bad, f"non-finite values in table {name!r}, columns {bad}, scene:\n{scene.to_toml()}"
    return outcome


@SETTINGS
@given(mutated_scene())
def test_fuzzed_scene_dicts_load_or_fail_with_a_scene_error(scene: dict[str, Any]) -> None:
    event(check(scene, []))


@SETTINGS
@given(overrides())
def test_fuzzed_overrides_load_or_fail_with_a_scene_error(case: tuple[int, list[str]]) -> None:
    b, patches = case
    base = _native.default_scene_toml() if b == 0 else None
    if base is not None:
        event(check(base, ["pipe.joints=1", *patches]))
    else:
        event(check(BASES[b], patches))


def test_the_unfuzzed_bases_run() -> None:
    """The fuzz bases themselves load and run (the fuzzing starts from valid scenes)."""
    for base in BASES:
        assert check(base, []) == "ran"



#: Inputs the fuzzing found a bug with (docs/reliability.md, "Fuzzing"); each is also a regression
#: input of the cargo-fuzz targets, fuzz/regressions/<name>.toml.
REGRESSIONS = {
    # r³ underflows to 0: the inertia derived from the mass was m·I₁/m₁ = 0/0 = NaN (energy.kinetic NaN at t = 0).
    "ball-radius-underflow-nan-inertia": ("two balls", ["bodies.1.shape.radius=5e-302"]),
    # spin_speed / spin_ramp of a dynamic body were not validated: NaN kept in the scene.
    "dynamic-body-nan-spin-speed": ("two balls", ["bodies[1].spin_speed=nan"]),
    # ½·m·v² overflows: energy.kinetic inf at t = 0.
    "huge-velocity-infinite-kinetic-energy": ("two balls", ["bodies.0.velocity.0=1e+200"]),
    # forces ~2e220 N, finite, but the summary's sqrt(ΣF²/n) overflows: summary.normal_rms inf.
    "summary-rms-overflow": ("paper", ["pipe.ball_keys.pitch_radius=3.15e+98"]),
}


@pytest.mark.parametrize("name", sorted(REGRESSIONS))
def test_inputs_the_fuzzing_found_a_bug_with_are_refused_or_run_finite(name: str) -> None:
    base_name, patches = REGRESSIONS[name]
    base = next(b for b in BASES if b.get("name", "paper") == base_name)
    assert check(base, patches) in ("rejected", "diverged", "ran")
