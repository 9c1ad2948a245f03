"""Scenes: load one from a file, a dict or a builder; validation happens in Rust.

There is one way in for each kind of source:

- a path (``str`` or ``os.PathLike``) to a TOML file,
- a dict with the structure of the TOML file,
- a `SceneBuilder` or a `DrillPipeBuilder`, which emit such a dict,
- an already validated `ballcage.Scene`.

`default_scene` is the embedded paper scene (Zhu et al. 2023's drill pipe):
its overrides are applied to the short drill-pipe TOML, so keys such as
``drive.speed_rpm`` or ``borehole.curvature_radius`` work there.

Every route ends in the same Rust validator, so a scene written as TOML and
the same scene built in Python produce bitwise identical runs.
"""

from __future__ import annotations

import copy
import errno
import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Self, TypeAlias

from ballcage import _native
from ballcage._native import InputError

if TYPE_CHECKING:
    import pyarrow as pa

__all__ = [
    "DrillPipeBuilder",
    "SceneBuilder",
    "SceneSource",
    "default_scene",
    "default_scene_toml",
    "load_scene",
    "override_list",
    "proposals",
]


class SceneBuilder:
    """A small fluent builder that emits a scene dict (see `to_dict`).

    Each method records one part of the scene and returns the builder::

        scene = (
            SceneBuilder("ball drop")
            .simulation(duration=0.2, dt=5e-5, output_interval=1e-3)
            .gravity([0.0, 0.0, -9.81])
            .body("ground", motion="fixed", shape={"type": "half-space", "normal": [0.0, 0.0, 1.0]})
            .body("ball", shape={"type": "ball", "radius": 0.05}, mass=1.0, position=[0.0, 0.0, 0.1])
            .contact("ground", "ball", normal={"law": "hertz", "stiffness": 1e8})
        )

    Field names and units are those of the TOML scene format (SI). Nothing is
    checked here: `load_scene` validates the dict in Rust.
    """

    def __init__(self, name: str = "") -> None:
        self._scene: dict[str, Any] = {"name": name, "simulation": {}, "bodies": []}

    def simulation(
        self,
        *,
        duration: float | None = None,
        dt: float | None = None,
        output_interval: float | None = None,
        integrator: str | None = None,
        threads: int | None = None,
        rtol: float | None = None,
        max_step: float | None = None,
    ) -> Self:
        """Time stepping: `duration`, `dt` and `output_interval` [s], `integrator` name, and
        `threads` evaluating the contact pairs (default 1; results are bitwise the same for any count).
        With ``integrator="esdirk32"`` or ``"trbdf2"``, `rtol` [–] sets the adaptive steps' relative tolerance
        (0: fixed steps of `dt`) and `max_step` [s] the longest step (default the output interval)."""
        given = {
            "duration": duration,
            "dt": dt,
            "output_interval": output_interval,
            "integrator": integrator,
            "threads": threads,
            "rtol": rtol,
            "max_step": max_step,
        }
        self._scene["simulation"].update({k: v for k, v in given.items() if v is not None})
        return self

    def gravity(self, gravity: Sequence[float]) -> Self:
        """Gravitational acceleration [m/s²], world frame."""
        self._scene.setdefault("world", {})["gravity"] = _plain(gravity)
        return self

    def body(self, name: str, *, shape: Mapping[str, Any], **fields: Any) -> Self:
        """A body: `shape` (a dict with ``type``) and any other body field (`mass`, `position`, …)."""
        self._scene["bodies"].append({"name": name, "shape": _plain(shape), **_plain(fields)})
        return self

    def contact(
        self,
        a: str,
        b: str,
        *,
        normal: Mapping[str, Any],
        friction: Mapping[str, Any] | None = None,
        **fields: Any,
    ) -> Self:
        """A contact pair between bodies `a` and `b` with a `normal` law (a dict with ``law``)."""
        spec: dict[str, Any] = {"bodies": [a, b], "normal": _plain(normal)}
        if friction is not None:
            spec["friction"] = _plain(friction)
        spec.update(_plain(fields))
        self._scene.setdefault("contacts", []).append(spec)
        return self

    def torque(self, body: str, axis: Sequence[float], magnitude: float, *, ramp: float = 0.0) -> Self:
        """A torque `magnitude`·`axis` [N·m] on `body`, ramped in over `ramp` [s]."""
        load = {"type": "torque", "body": body, "axis": _plain(axis), "magnitude": magnitude, "ramp": ramp}
        self._scene.setdefault("loads", []).append(load)
        return self

    def record(
        self,
        *,
        tables: Sequence[str] | None = None,
        bodies: Sequence[str] | None = None,
        contacts: Sequence[str] | None = None,
        max_bytes: int | None = None,
    ) -> Self:
        """What to record: table names, and optionally which bodies and contact
        pairs, and the memory budget of the recorded tables `max_bytes` [B]."""
        given = {"tables": tables, "bodies": bodies, "contacts": contacts, "max_bytes": max_bytes}
        self._scene.setdefault("record", {}).update({k: _plain(v) for k, v in given.items() if v is not None})
        return self

    def to_dict(self) -> dict[str, Any]:
        """The scene as a plain dict (a deep copy), ready for `load_scene`."""
        return copy.deepcopy(self._scene)

    def __repr__(self) -> str:
        return f"SceneBuilder({self._scene.get('name', '')!r}, bodies={len(self._scene['bodies'])})"


class DrillPipeBuilder:
    """Builds a drill-pipe scene dict (``kind = "drill-pipe"``) section by section.

    Every section and field left out takes the paper's value, so only what
    differs is written::

        scene = (
            DrillPipeBuilder()
            .borehole(curvature_radius=2.5)          # m
            .pipe(joints=12, hinge="ideal-cv")
            .drive(speed_rpm=60)                      # rpm
            .load(resisting_moment=1800.0)            # N·m
            .simulation(duration=0.5)                 # s
        )
        run = ballcage.simulate(scene)

    Each method takes the fields of its TOML section (`ballcage scene show`
    prints them all with units); nested tables such as ``pipe.ball_keys`` are
    dicts. Nothing is checked here: `load_scene` validates in Rust.
    """

    def __init__(self, name: str | None = None) -> None:
        self._scene: dict[str, Any] = {"kind": "drill-pipe"}
        if name is not None:
            self._scene["name"] = name

    def _section(self, section: str, fields: dict[str, Any]) -> Self:
        self._scene.setdefault(section, {}).update(copy.deepcopy(fields))
        return self

    def simulation(self, **fields: Any) -> Self:
        """`duration`, `dt`, `output_interval` [s], `integrator`, `threads`."""
        return self._section("simulation", fields)

    def world(self, **fields: Any) -> Self:
        """`gravity` [m/s², along −z]."""
        return self._section("world", fields)

    def borehole(self, **fields: Any) -> Self:
        """`curvature_radius` [m], `build_angle_deg` [deg], `inner_diameter` [m]."""
        return self._section("borehole", fields)

    def pipe(self, **fields: Any) -> Self:
        """`joints`, `hinge` ("ball-keys" or "ideal-cv"), `pitch` [m], sizes, masses, `ball_keys`, `ideal_cv`."""
        return self._section("pipe", fields)

    def drive(self, **fields: Any) -> Self:
        """`speed_rpm` [rpm], `ramp` [s]."""
        return self._section("drive", fields)

    def load(self, **fields: Any) -> Self:
        """`resisting_moment` [N·m], `ramp` [s]."""
        return self._section("load", fields)

    def materials(self, **fields: Any) -> Self:
        """`tube` and `internal`, each ``{"normal": {...}, "friction": {...}}``."""
        return self._section("materials", fields)

    def record(self, **fields: Any) -> Self:
        """`tables`, `bodies`, `contacts`, `summary_window` [s], `max_bytes` [B]."""
        return self._section("record", fields)

    def to_dict(self) -> dict[str, Any]:
        """The scene dict (a deep copy)."""
        return copy.deepcopy(self._scene)

    def __repr__(self) -> str:
        return f"DrillPipeBuilder({self._scene!r})"


SceneSource: TypeAlias = "str | os.PathLike[str] | Mapping[str, Any] | SceneBuilder | DrillPipeBuilder | _native.Scene"


def load_scene(source: SceneSource, overrides: Iterable[str] = ()) -> _native.Scene:
    """Reads and validates a scene.

    `source` is a path to a TOML file, a dict of the same structure, a
    `SceneBuilder` or a `ballcage.Scene`. `overrides` are ``dotted.key=value``
    strings applied before validation (``"bodies.1.mass=2"``; the value is
    parsed as TOML).

    Raises `ballcage.SceneError` (naming the field) for an invalid scene and
    `FileNotFoundError` (naming the path) for a missing file. The message of
    an error in a file starts with the file's path: ``bad.toml: TOML syntax
    error at line 2, column 7: …`` or ``bad.toml: scene field `…` = …: …``.
    """
    patches = override_list(overrides)
    if isinstance(source, _native.Scene):
        return _native.Scene.from_toml(source.to_toml(), patches) if patches else source
    if isinstance(source, (SceneBuilder, DrillPipeBuilder)):
        return _native.Scene.from_dict(source.to_dict(), patches)
    if isinstance(source, Mapping):
        return _native.Scene.from_dict(_plain(source), patches)
    if isinstance(source, (str, os.PathLike)):
        text = _read_scene_file(source)
        try:
            return _native.Scene.from_toml(text, patches)
        except _native.SceneError as e:
            raise _in_file(e, source) from None
    raise InputError(
        f"cannot load a scene from {type(source).__name__}: give a path to a TOML file, "
        "a dict, a SceneBuilder or a ballcage.Scene"
    )


def default_scene_toml() -> str:
    """The embedded default scene (the paper's drill pipe) as TOML, every default written out."""
    return _native.default_scene_toml()


def default_scene(overrides: Iterable[str] = ()) -> _native.Scene:
    """The embedded paper scene, validated, with ``dotted.key=value`` `overrides` applied.

    The overrides address the drill-pipe TOML of `default_scene_toml`
    (``"drive.speed_rpm=60"``, ``"simulation.duration=0.02"``), not the
    expanded scene that ``Scene.to_toml()`` returns. Raises `ballcage.SceneError`.
    """
    return _native.Scene.from_toml(_native.default_scene_toml(), override_list(overrides))


#: The columns of `proposals`, in order: (name, Arrow type, meaning).
PROPOSAL_COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("key", "string", "dotted scene key, as --set key=value takes it"),
    ("scene_kind", "string", "the scene kind whose default it is: drill-pipe, or generic (the engine's, every kind)"),
    ("default", "float64", "the default scene's value, in unit"),
    ("low", "float64", "lowest plausible value, in unit"),
    ("high", "float64", "highest plausible value, in unit"),
    ("unit", "string", "the field's unit in the default scene (a contact law's in its N-mm-s field units); - pure"),
    ("source", "string", "invented, paper-reading (our reading of the paper) or handbook"),
    ("reference", "string", "where the default comes from: the argument or the citation"),
    ("meaning", "string", "what the field is"),
    ("range_reason", "string", "why the range is plausible"),
)


def proposals(kind: str | None = None) -> pa.Table:
    """The registry of unstated parameters: every default ballcage chose because the paper gives none.

    One row per PROPOSAL value, with the columns of `PROPOSAL_COLUMNS`: ``key`` (dotted, as ``--set`` takes
    it), ``scene_kind`` (``"drill-pipe"``, or ``"generic"`` for the engine's own, which every scene kind
    has), ``default``, ``low`` and ``high`` (float64, in ``unit``, the field's unit in the default scene:
    a contact law's in its N-mm-s field units), ``source`` (``"invented"``, ``"paper-reading"`` or
    ``"handbook"``), ``reference``, ``meaning`` and ``range_reason``. `kind` (``"drill-pipe"`` or
    ``"generic"``) keeps one kind's rows. The registry is defined once in Rust beside the spec fields; the
    default, unit and meaning come from the default scene and the table of field units (docs/proposals.md).
    Raises `ballcage.InputError` for an unknown `kind`.
    """
    import pyarrow as pa  # deferred: `import ballcage` stays light

    if kind is not None and not isinstance(kind, str):
        raise InputError(f"kind = {kind!r}: give a scene kind name, e.g. 'drill-pipe', or None for every kind")
    schema = pa.schema(
        [pa.field(name, pa.type_for_alias(type_), nullable=False, metadata={"description": meaning})
         for name, type_, meaning in PROPOSAL_COLUMNS]
    )  # fmt: skip
    return pa.Table.from_pylist(_native.proposals(kind), schema=schema)


#: The hinge models with a cage and ball keys (their joint loads are contacts): ``pipe.hinge`` values.
BALL_KEY_HINGES = ("ball-keys", "ball-keys-qs")


def override_list(overrides: Iterable[str]) -> list[str]:
    """`overrides` (``dotted.key=value`` strings) as a list; `ballcage.InputError` for a single string.

    A single string is a common slip (``overrides="a=1"``) that would
    otherwise be read one character at a time; every function that takes
    overrides passes them through here.
    """
    if isinstance(overrides, str):
        raise InputError("overrides is a list of 'key=value' strings, not one string")
    return list(overrides)


def _read_scene_file(source: str | os.PathLike[str]) -> str:
    if isinstance(source, str) and "\n" in source:
        raise InputError("load_scene takes a path, not TOML text: use ballcage.Scene.from_toml(text)")
    path = Path(source)
    try:
        return path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise FileNotFoundError(errno.ENOENT, "scene file not found", str(path)) from None


def _in_file(error: _native.SceneError, source: str | os.PathLike[str]) -> _native.SceneError:
    """`error` with the scene file's path in front of its message; ``path``, ``value``, ``reason`` and ``errors`` kept."""
    named = _native.SceneError(f"{os.fspath(source)}: {error}")
    for attribute in ("path", "value", "reason"):
        setattr(named, attribute, getattr(error, attribute, ""))
    named.errors = list(getattr(error, "errors", []))
    return named


def _plain(value: Any) -> Any:
    """Deep-copies mappings to dicts and other sequences (tuples, arrays) to lists."""
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (str, bytes)):
        return value
    if isinstance(value, Sequence):
        return [_plain(v) for v in value]
    if hasattr(value, "tolist"):  # numpy arrays and scalars
        return _plain(value.tolist())
    return value
