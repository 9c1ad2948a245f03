"""``summary.parquet``: one row per case, built from the cases' records; units in every field's metadata."""

from __future__ import annotations

import json
import re
from collections.abc import Mapping, Sequence
from typing import Any

import pyarrow as pa

from ballcage import _native
from ballcage.studies.sweep_quantities import QUANTITIES, link_columns

__all__ = ["COST_COLUMNS", "WALL_TIME_COLUMNS", "parameter_units", "summary_table"]

#: Columns that measure wall time: the only ones two runs of the same sweep may differ in.
WALL_TIME_COLUMNS: tuple[str, ...] = ("wall_time_s", "case_wall_time_s")

_HEAD: tuple[tuple[str, pa.DataType, str, str], ...] = (
    ("case", pa.int32(), "", "case index in the sweep (the hive partition key case=NNNN of the table datasets)"),
    ("case_id", pa.string(), "", "index and the start of the hash of the case's base scene and overrides"),
    ("status", pa.string(), "", "ok: ran to the end; diverged: SimulationError (tables hold the frames up to then); "
     "error: any other failure"),
    ("error", pa.string(), "", "why the case did not finish (the error message); null when ok"),
)
COST_COLUMNS: tuple[tuple[str, pa.DataType, str, str], ...] = (
    ("steps", pa.int64(), "", "integrator steps taken (ballcage.steps)"),
    ("simulated_time_s", pa.float64(), "s", "simulated time reached: steps x dt"),
    ("wall_time_s", pa.float64(), "s", "wall time of the simulation alone (ballcage.wall_time_s)"),
    ("case_wall_time_s", pa.float64(), "s", "wall time of the whole case: scene, run, tables written, quantities"),
)


def parameter_units(scene_toml_with_units: str, keys: Sequence[str]) -> dict[str, str]:
    """The unit of each dotted key, read from a scene printed with ``to_toml(units=True)``; ``""`` if none."""
    section, units = "", {}
    lines: dict[str, str] = {}
    for raw in scene_toml_with_units.splitlines():
        line = raw.strip()
        header = re.fullmatch(r"\[+([^\]]+)\]+", line)
        if header:
            section = header.group(1).strip()
            continue
        m = re.match(r"([A-Za-z0-9_\-]+)\s*=.*#\s*(.+)$", line)
        if m:
            lines[f"{section}.{m.group(1)}" if section else m.group(1)] = m.group(2).strip()
    for key in keys:
        unit = lines.get(key, "")
        units[key] = "" if unit == "-" else unit
    return units


def summary_table(
    records: Sequence[Mapping[str, Any]],
    parameters: Sequence[str],
    units: Mapping[str, str],
    meta: Mapping[str, str],
) -> pa.Table:
    """One row per record (sorted by case): head, swept parameters, derived quantities, cost."""
    rows = sorted(records, key=lambda r: int(r["case"]))
    fields: list[pa.Field] = []
    arrays: list[pa.Array] = []

    def add(name: str, values: list[Any], kind: pa.DataType | None, unit: str, description: str) -> None:
        array = _array(values, kind)
        fields.append(pa.field(name, array.type, metadata={"unit": unit, "description": description}))
        arrays.append(array)

    for name, kind, unit, description in _HEAD:
        add(name, [r.get(name) for r in rows], kind, unit, description)
    for key in parameters:
        add(key, [r.get("parameters", {}).get(key) for r in rows], None, units.get(key, ""), f"scene key {key} (swept)")
    for name, (unit, description) in _quantity_columns(rows).items():
        add(name, [r.get("quantities", {}).get(name) for r in rows], pa.float64(), unit, description)
    for name, kind, unit, description in COST_COLUMNS:
        add(name, [r.get(name) for r in rows], kind, unit, description)
    schema = pa.schema(fields)
    file_meta = dict(meta)
    file_meta["ballcage.units"] = json.dumps({f.name: f.metadata[b"unit"].decode() for f in schema})
    file_meta["ballcage.descriptions"] = json.dumps({f.name: f.metadata[b"description"].decode() for f in schema})
    file_meta["ballcage.version"] = _native.__version__
    return pa.Table.from_arrays(arrays, schema=schema.with_metadata(file_meta))


def _quantity_columns(rows: Sequence[Mapping[str, Any]]) -> dict[str, tuple[str, str]]:
    """The fixed quantity columns, when any case is a drill pipe, then the per-link ones of the most links."""
    present = {k for r in rows for k in r.get("quantities", {})}
    if not present:
        return {}
    out = dict(QUANTITIES)
    links = sorted({int(m.group(1)) for k in present if (m := re.fullmatch(r"tube_normal_mean_link_(\d+)_n", k))})
    for link in links:
        out.update(link_columns(link))
    return out


def _array(values: list[Any], kind: pa.DataType | None) -> pa.Array:
    if kind is not None:
        return pa.array(values, type=kind)
    try:
        return pa.array(values)
    except (pa.ArrowInvalid, pa.ArrowTypeError):  # mixed kinds of value: as their TOML text
        return pa.array([None if v is None else json.dumps(v) for v in values], type=pa.string())
