"""The sweep file: reading, checking and expanding ``SWEEP.toml`` into cases (`load_sweep`, `SweepSpec.cases`).

A sweep file (TOML; or a dict of the same structure in Python)::

    [sweep]
    name = "curvature-rpm"              # optional, default the file's stem
    base = "scene.toml"                 # optional, relative to this file; default the embedded paper scene
    tables = ["links", "drive"]         # optional, the tables each case records

    [set]                               # fixed overrides of every case
    "pipe.hinge" = "ideal-cv"

    [grid]                              # the Cartesian product of these lists, first key slowest
    "borehole.curvature_radius" = [1.0, 1.5, 2.5]
    "drive.speed_rpm" = [60, 100]

    [[case]]                            # and/or a list of cases, each a table of overrides
    "simulation.integrator" = "rk4"

Keys are the dotted scene keys of ``--set`` (quoted, or written as nested
tables). Everything is checked before anything runs: an unknown section or
key, a grid entry that is not a list, a key both fixed and swept, and every
case's scene (validated in Rust); each error is a `SweepError` naming the
file, the field, the value and the reason.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from itertools import product
from pathlib import Path
from typing import Any, TypeAlias

from ballcage import _native
from ballcage.scene import default_scene_toml

__all__ = [
    "DEFAULT_TABLES", "Case", "SweepError", "SweepSpec", "SweepSource", "load_sweep", "partition_name", "toml_value",
    "with_verification",
]

#: Tables a drill-pipe case records unless the sweep or its base scene says otherwise (no per-body tables).
DEFAULT_TABLES: tuple[str, ...] = ("links", "hinges", "keys", "drive", "summary")
_SECTIONS = ("sweep", "set", "grid", "case")
_SWEEP_KEYS = ("name", "base", "tables")


class SweepError(_native.Error, ValueError):
    """A sweep file or sweep output folder that cannot be used; the message names the field, value and reason."""


@dataclass(frozen=True)
class Case:
    """One case of a sweep: its index, its swept values and every override it runs with, in order."""

    index: int
    values: dict[str, Any]  # swept key -> value as written in the sweep file
    overrides: tuple[str, ...]  # "key=value" (TOML value), applied to the base scene in this order
    digest: str  # sha256 of the base scene text and the overrides, hex

    @property
    def case_id(self) -> str:
        """``0003-1a2b3c4d``: the index and the start of the digest; stable across runs of the same sweep."""
        return f"{self.index:04d}-{self.digest[:8]}"

    @property
    def partition(self) -> str:
        """The hive partition directory of the case, ``case=0003``."""
        return partition_name(self.index)

    def label(self) -> str:
        return " ".join(f"{k}={_short(v)}" for k, v in self.values.items())


@dataclass
class SweepSpec:
    """A checked sweep: the base scene, the fixed overrides, the grid and the listed cases."""

    name: str
    base_toml: str  # the base scene's TOML text (the embedded paper scene when `base` is None)
    base: Path | None = None
    tables: list[str] | None = None
    fixed: dict[str, Any] = field(default_factory=dict)
    grid: dict[str, list[Any]] = field(default_factory=dict)
    listed: list[dict[str, Any]] = field(default_factory=list)
    source: str = "sweep"  # the file's path (or "sweep" for a dict), the prefix of error messages
    #: `with_verification`: the last `verifies` cases are the first `verifies` again at the tighter setting of
    #: ``ballcage run --verify`` (case k + verifies verifies case k); 0: no verification runs.
    verifies: int = 0
    verification: str = ""  # that setting's label(s), ``rtol/10``; empty without verification runs

    @property
    def parameters(self) -> list[str]:
        """The swept keys: the grid's, then those of the listed cases, in order of appearance."""
        keys = list(self.grid)
        for case in self.listed:
            keys += [k for k in case if k not in keys]
        return keys

    def preamble(self) -> list[str]:
        """Overrides before the fixed ones: one thread per case, and the tables to record.

        The tables are `tables` when given; else a base file's ``record.tables`` when it sets them; else, for a
        drill pipe, `DEFAULT_TABLES` (the embedded scene writes every default out, so it counts as not setting them).
        """
        out = ["simulation.threads=1"]
        doc = tomllib.loads(self.base_toml)
        if self.tables is not None:
            out.append("record.tables=" + toml_value(self.tables))
        elif (self.base is None or "tables" not in doc.get("record", {})) and self._base_kind() == "drill-pipe":
            out.append("record.tables=" + toml_value(list(DEFAULT_TABLES)))
        return out

    def _base_kind(self) -> str | None:
        """The base scene's kind (`Scene.kind`); None when the base alone is not a valid scene (`check` names why)."""
        try:
            return _native.Scene.from_toml(self.base_toml).kind
        except _native.SceneError:
            return None

    def cases(self) -> list[Case]:
        """Every case, grid first (its first key slowest), then the listed ones."""
        keys = list(self.grid)
        chosen = [dict(zip(keys, combo, strict=True)) for combo in product(*self.grid.values())] if keys else []
        chosen += [dict(c) for c in self.listed]
        start = self.preamble() + [f"{k}={toml_value(v)}" for k, v in self.fixed.items()]
        out = []
        for i, values in enumerate(chosen):
            overrides = tuple(start + [f"{k}={toml_value(v)}" for k, v in values.items()])
            text = json.dumps({"base": self.base_toml, "overrides": overrides}, sort_keys=True)
            out.append(Case(i, values, overrides, hashlib.sha256(text.encode()).hexdigest()))
        return out

    def check(self) -> list[Case]:
        """Validates every key alone, then every case's scene; returns the cases. Raises `SweepError`."""
        cases = self.cases()
        if not cases:
            raise SweepError(f"{self.source}: nothing to sweep: give a [grid] of lists or [[case]] tables")
        base = self.preamble()
        for section, entries in (("set", self.fixed), ("grid", {k: v[0] for k, v in self.grid.items()})):
            for key, value in entries.items():
                self._check_scene(base + [f"{key}={toml_value(value)}"], f"[{section}] `{key}` = {_short(value)}")
        for case in cases:
            self._check_scene(list(case.overrides), f"case {case.index} ({case.label() or 'no swept values'})")
        return cases

    def _check_scene(self, overrides: list[str], what: str) -> None:
        try:
            _native.Scene.from_toml(self.base_toml, overrides)
        except _native.SceneError as e:
            raise SweepError(f"{self.source}: {what}: {e}") from None


def partition_name(index: int) -> str:
    """The hive partition directory of case `index`: ``case=0003``."""
    return f"case={index:04d}"


SweepSource: TypeAlias = "str | os.PathLike[str] | Mapping[str, Any] | SweepSpec"


def with_verification(source: SweepSource) -> SweepSpec:
    """The sweep `source` with, after all its cases, each case again at the tighter setting of ``ballcage run
    --verify`` (`ballcage.studies.refinement.tighter` of that case's scene: ``rtol/10`` for adaptive steps, ``dt/d``
    for fixed ones): the summary then gives each quantity's numerical error in each case, |value − value at the
    tighter setting| (`ballcage.studies.sweep_summary`). The cases keep their indices and hashes, so a sweep run
    without verification resumes with it. Validates every case first (`SweepSpec.check`). Raises `SweepError`.
    """
    from ballcage.studies.refinement import tighter  # deferred: refinement is a study module

    loaded = load_sweep(source)
    if loaded.verifies:
        return loaded
    cases = loaded.check()
    checks, labels = [], []
    for case in cases:
        setting = tighter(_native.Scene.from_toml(loaded.base_toml, list(case.overrides)))
        checks.append({**case.values, **setting.values()})
        labels += [setting.label] if setting.label not in labels else []
    return replace(loaded, grid={}, listed=[dict(c.values) for c in cases] + checks, verifies=len(cases),
                   verification=", ".join(labels))  # fmt: skip


def load_sweep(source: SweepSource) -> SweepSpec:
    """Reads a sweep file (path), a dict of the same structure or a `SweepSpec`; checks its structure.

    The cases' scenes are validated by `SweepSpec.check`. Raises `SweepError`.
    """
    if isinstance(source, SweepSpec):
        return source
    if isinstance(source, Mapping):
        return _parse(dict(source), "sweep", Path.cwd(), "sweep")
    path = Path(source)
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise SweepError(f"{path}: sweep file not found") from None
    except (OSError, UnicodeDecodeError) as e:
        raise SweepError(f"{path}: cannot read the sweep file: {e}") from None
    except tomllib.TOMLDecodeError as e:
        raise SweepError(f"{path}: TOML syntax error: {e}") from None
    return _parse(doc, str(path), path.resolve().parent, path.stem)


def _parse(doc: dict[str, Any], source: str, here: Path, default_name: str) -> SweepSpec:
    for section in doc:
        if section not in _SECTIONS:
            raise SweepError(f"{source}: unknown section [{section}] (sections: {', '.join(_SECTIONS)})")
    head = _table(doc.get("sweep", {}), "[sweep]", source)
    for key in head:
        if key not in _SWEEP_KEYS:
            raise SweepError(f"{source}: [sweep] unknown key `{key}` (keys: {', '.join(_SWEEP_KEYS)})")
    name = head.get("name", default_name)
    if not isinstance(name, str) or not name:
        raise SweepError(f"{source}: [sweep] `name` = {_short(name)}: must be a non-empty string")
    spec = SweepSpec(name=name, base_toml=default_scene_toml(), source=source)
    if "base" in head:
        spec.base, spec.base_toml = _base(head["base"], here, source)
    if "tables" in head:
        spec.tables = _tables(head["tables"], source)
    spec.fixed = _flatten(_table(doc.get("set", {}), "[set]", source))
    spec.grid = _grid(_flatten(_table(doc.get("grid", {}), "[grid]", source)), source)
    spec.listed = _listed(doc.get("case", []), source)
    both = [k for k in spec.fixed if k in spec.parameters]
    if both:
        raise SweepError(f"{source}: `{both[0]}` is both fixed ([set]) and swept ([grid] or [[case]]): keep one")
    return spec


def _base(value: Any, here: Path, source: str) -> tuple[Path, str]:
    if not isinstance(value, (str, os.PathLike)) or not str(value):
        raise SweepError(f"{source}: [sweep] `base` = {_short(value)}: must be the path of a scene file")
    path = Path(value) if Path(value).is_absolute() else here / value
    try:
        return path, path.read_text(encoding="utf-8")
    except OSError as e:
        raise SweepError(f"{source}: [sweep] `base` = {_short(str(value))}: cannot read {path}: {e.strerror or e}") from None


def _tables(value: Any, source: str) -> list[str]:
    known = list(_native.TABLE_NAMES)
    if not isinstance(value, list) or not value:
        raise SweepError(f"{source}: [sweep] `tables` = {_short(value)}: must be a non-empty list of table names")
    for name in value:
        if name not in known:
            raise SweepError(f"{source}: [sweep] `tables` = {_short(value)}: unknown table {name!r} (known: {', '.join(known)})")
    return list(value)


def _grid(flat: dict[str, Any], source: str) -> dict[str, list[Any]]:
    for key, values in flat.items():
        if not isinstance(values, list) or not values:
            raise SweepError(f"{source}: [grid] `{key}` = {_short(values)}: must be a non-empty list of values")
    return flat


def _listed(value: Any, source: str) -> list[dict[str, Any]]:
    if not isinstance(value, list):
        raise SweepError(f"{source}: `case` = {_short(value)}: write each case as a [[case]] table")
    out = []
    for i, case in enumerate(value):
        flat = _flatten(_table(case, f"[[case]] {i}", source))
        if not flat:
            raise SweepError(f"{source}: [[case]] {i} is empty: give it at least one key = value")
        out.append(flat)
    return out


def _table(value: Any, what: str, source: str) -> dict[str, Any]:
    if not isinstance(value, Mapping):
        raise SweepError(f"{source}: {what} = {_short(value)}: must be a table")
    return dict(value)


def _flatten(table: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """Nested tables to dotted keys: ``{"drive": {"speed_rpm": 60}}`` → ``{"drive.speed_rpm": 60}``."""
    out: dict[str, Any] = {}
    for key, value in table.items():
        dotted = f"{prefix}{key}"
        if isinstance(value, Mapping):
            out.update(_flatten(value, dotted + "."))
        else:
            out[dotted] = value
    return out


def toml_value(value: Any) -> str:
    """`value` as a TOML value for a ``key=value`` override (bool, int, float, str, list, table)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        return repr(value) if math.isfinite(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, Mapping):
        return "{" + ", ".join(f"{json.dumps(str(k))} = {toml_value(v)}" for k, v in value.items()) + "}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    raise SweepError(f"value {value!r}: cannot be written as TOML (give a number, string, boolean, list or table)")


def _short(value: Any) -> str:
    """`value` as it would be written in TOML, cut to 60 characters."""
    try:
        text = toml_value(value)
    except SweepError:
        text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
