"""What a sensitivity study varies: each parameter's range, from the registry of unstated parameters or given.

The registry (``ballcage.proposals()``, `ballcage.scene.proposals`, issue 27)
is one table of the PROPOSAL values the scenes' defaults hold where the paper
states none, one row per parameter: ``key`` (the dotted scene key ``--set``
takes), ``scene_kind`` (``"drill-pipe"``, or ``"generic"`` for the engine's
own, which every scene kind has), ``default``, ``low``, ``high`` (in
``unit``), ``source`` (``invented``, ``paper-reading``, ``handbook``),
``reference``, ``meaning`` and ``range_reason``. A scene's parameters are the
rows of its kind and the generic ones.

`parameter_ranges` turns a choice of parameters into checked `ParameterRange`\\ s:

- ``None``: every registry parameter of the scene (its kind's and the generic ones);
- a list of keys: those registry parameters;
- a dict ``key -> (low, high)`` (a range in the scene's units, for any
  numeric scene field) or ``key -> None`` (the registry's range).

Every error is an `InputError` naming the field, the value and the reason.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypeAlias

from ballcage import _native
from ballcage._native import InputError

if TYPE_CHECKING:
    import pyarrow as pa

__all__ = ["REGISTRY_COLUMNS", "ParameterChoice", "ParameterRange", "parameter_ranges", "proposal_registry"]

#: The columns the registry table must have (`proposal_registry`).
REGISTRY_COLUMNS: tuple[str, ...] = (
    "key", "scene_kind", "default", "low", "high", "unit", "source", "reference", "meaning", "range_reason",
)  # fmt: skip
#: The registry's scene kind of the engine's own parameters, which every scene kind has.
GENERIC_KIND = "generic"
#: What the messages call the registry.
_REGISTRY = "the registry of unstated parameters (ballcage.proposals())"

#: A choice of parameters: None (the registry's, all), keys of the registry, or key -> (low, high) or None.
ParameterChoice: TypeAlias = "Sequence[str] | Mapping[str, tuple[float, float] | Sequence[float] | None] | None"


@dataclass(frozen=True)
class ParameterRange:
    """One varied parameter: its scene key, its range and base value (in `unit`, the scene's), and where they come from."""

    key: str
    low: float
    high: float
    base: float  # the base scene's value
    unit: str  # the scene's unit of the key ("" for a pure number)
    source: str  # the registry's source (invented, paper-reading, handbook), or "given" for an explicit range
    reference: str = ""
    meaning: str = ""
    range_reason: str = ""
    integer: bool = False  # the scene field holds a whole number

    def scene_value(self, value: float) -> float | int:
        """`value` as the scene field takes it: a whole number for an integer field (OAT's low and high)."""
        return int(value) if self.integer and float(value).is_integer() else float(value)


def proposal_registry() -> pa.Table:
    """The registry table, ``ballcage.proposals()`` (every scene kind's rows)."""
    from ballcage.scene import proposals

    return proposals()


def parameter_ranges(
    scene: _native.Scene,
    parameters: ParameterChoice = None,
    registry: pa.Table | None = None,
    *,
    what: str = "parameters",
) -> list[ParameterRange]:
    """The checked ranges of `parameters` on `scene` (see the module docstring); `what` names the option in errors.

    `registry` is the registry table (default `proposal_registry`, read only
    where a parameter's range is not given).
    """
    if isinstance(parameters, str):
        raise InputError(f"{what} = {parameters!r}: give a list of scene keys or a dict key -> (low, high), not a string")
    if parameters is not None and not isinstance(parameters, (Mapping, Sequence)):
        raise InputError(f"{what} = {parameters!r}: give a list of scene keys or a dict key -> (low, high)")
    given: Mapping[str, Any] = (
        parameters if isinstance(parameters, Mapping) else dict.fromkeys(parameters) if parameters is not None else {}
    )
    rows = _Registry(registry, scene.kind, what) if parameters is None or any(v is None for v in given.values()) else None
    if parameters is None:
        assert rows is not None
        keys = rows.keys_of_kind()
        if not keys:
            raise InputError(
                f"{what}: {_REGISTRY} lists no unstated parameter of a {scene.kind} scene; name the parameters with "
                "their ranges, e.g. {'key': (low, high)} (--parameters KEY=LOW:HIGH)"
            )
        given = dict.fromkeys(keys)
    if not given:
        raise InputError(f"{what}: empty: name at least one parameter")
    out = []
    for key, span in given.items():
        if not isinstance(key, str) or not key:
            raise InputError(f"{what}: key {key!r}: must be a dotted scene key such as 'pipe.neck_radius'")
        out.append(_range(scene, key, span, rows, what))
    return out


def _range(scene: _native.Scene, key: str, span: Any, rows: _Registry | None, what: str) -> ParameterRange:
    """One parameter's range, checked against the scene: it must be a numeric field, low < high, both finite."""
    entry = rows.entry(key) if span is None and rows is not None else None
    base, unit = _scene_number(scene, key, what)
    if entry is not None:
        low, high = float(entry["low"]), float(entry["high"])
        source = str(entry["source"])
        extra = {k: str(entry[k] or "") for k in ("reference", "meaning", "range_reason")}
    else:
        low, high = _given_span(key, span, what)
        source, extra = "given", {"meaning": _meaning(scene, key)}
    if not (math.isfinite(low) and math.isfinite(high)):
        raise InputError(f"{what}: `{key}` range ({low!r}, {high!r}): low and high must be finite numbers")
    if not low < high:
        raise InputError(f"{what}: `{key}` range ({low!r}, {high!r}): low must be below high")
    integer = isinstance(base, int)
    return ParameterRange(key, low, high, float(base), unit, source, integer=integer, **extra)


def _given_span(key: str, span: Any, what: str) -> tuple[float, float]:
    if isinstance(span, (str, bytes)) or not isinstance(span, Sequence) or len(span) != 2:
        raise InputError(f"{what}: `{key}` range {span!r}: give (low, high), two numbers in the scene's units")
    try:
        return float(span[0]), float(span[1])
    except (TypeError, ValueError):
        raise InputError(f"{what}: `{key}` range {span!r}: low and high must be numbers") from None


def _scene_number(scene: _native.Scene, key: str, what: str) -> tuple[int | float, str]:
    """The base value of `key` in `scene` (a number) and its unit ("" for a pure number)."""
    try:
        value = scene.value(key)
    except (_native.SceneError, _native.InputError) as e:
        raise InputError(f"{what}: `{key}`: not a field of this {scene.kind} scene ({e})") from None
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"{what}: `{key}` = {value!r}: not a number; a sensitivity study varies numeric fields")
    try:
        unit = scene.unit(key)
    except _native.InputError:
        unit = ""
    return value, "" if unit == "-" else unit


def _meaning(scene: _native.Scene, key: str) -> str:
    try:
        return scene.meaning(key)
    except _native.InputError:
        return ""


class _Registry:
    """The registry's rows of one scene kind (its own and the generic ones), checked once: every column present."""

    def __init__(self, table: pa.Table | None, kind: str, what: str) -> None:
        table = table if table is not None else proposal_registry()
        missing = [c for c in REGISTRY_COLUMNS if c not in table.column_names]
        if missing:
            raise InputError(f"{what}: the registry table lacks the columns {', '.join(missing)} (it has: "
                             f"{', '.join(table.column_names)})")
        self.rows = table.select(list(REGISTRY_COLUMNS)).to_pylist()
        self.kind, self.what = kind, what

    def _mine(self) -> dict[str, dict[str, Any]]:
        """The rows of this kind and the generic ones (the engine's, which every kind has), by key, in order."""
        return {r["key"]: r for r in self.rows if r["scene_kind"] in (self.kind, GENERIC_KIND)}

    def keys_of_kind(self) -> list[str]:
        return list(self._mine())

    def entry(self, key: str) -> dict[str, Any]:
        mine = self._mine()
        if key in mine:
            return mine[key]
        other = [r["scene_kind"] for r in self.rows if r["key"] == key]
        if other:
            reason = f"the registry lists it for {other[0]} scenes, not {self.kind} ones"
        else:
            close = difflib.get_close_matches(key, list(mine), n=1)
            hint = f"; did you mean `{close[0]}`?" if close else ""
            reason = f"not an unstated parameter of a {self.kind} scene in {_REGISTRY}{hint}"
        raise InputError(
            f"{self.what}: `{key}`: {reason} (give a range to vary any other numeric field: "
            f"{{'{key}': (low, high)}}, --parameters {key}=LOW:HIGH)"
        )
