"""``summary.parquet``: one row per case, built from the cases' records; units in every field's metadata.

A sweep with verification runs (`ballcage.studies.sweep_spec.with_verification`) also has, after the
quantities, each quantity's numerical error in each case, ``<quantity>_error`` = |value − the value of its
verification run| in the quantity's unit (null on the verification runs' own rows, and where either run did not
finish or has no value), and before ``run_of`` the column ``verifies``: the case a verification run verifies.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from typing import Any

import pyarrow as pa

from ballcage import _native
from ballcage.studies.sweep_quantities import GENERIC, SweepQuantities

__all__ = ["COST_COLUMNS", "RUN_OF_COLUMN", "VERIFIES_COLUMN", "WALL_TIME_COLUMNS", "parameter_units", "summary_table"]

#: Columns that measure wall time: the only ones two runs of the same sweep may differ in.
WALL_TIME_COLUMNS: tuple[str, ...] = ("wall_time_s", "case_wall_time_s")

_HEAD: tuple[tuple[str, pa.DataType, str, str], ...] = (
    ("case", pa.int32(), "", "case index in the sweep (the hive partition key case=NNNN of the table datasets)"),
    ("case_id", pa.string(), "", "index and the start of the hash of the case's base scene and overrides"),
    ("status", pa.string(), "", "ok: ran to the end; diverged: SimulationError (tables hold the frames up to then); "
     "timed-out: stopped at the case time limit, --case-timeout (tables hold the frames up to then; run again on "
     "resume); error: any other failure"),
    ("error", pa.string(), "", "why the case did not finish (the error message); null when ok"),
)
COST_COLUMNS: tuple[tuple[str, pa.DataType, str, str], ...] = (
    ("steps", pa.int64(), "", "integrator steps taken (ballcage.steps)"),
    ("simulated_time_s", pa.float64(), "s", "simulated time reached: steps x dt"),
    ("wall_time_s", pa.float64(), "s", "wall time of the simulation alone (ballcage.wall_time_s); null for a case that "
     "shares another case's run (run_of)"),
    ("case_wall_time_s", pa.float64(), "s", "wall time of the whole case: scene, run, tables written, quantities"),
)
#: With verification runs, before ``run_of``: the case a row's run verifies (`with_verification`).
VERIFIES_COLUMN: tuple[str, pa.DataType, str, str] = (
    "verifies", pa.int32(), "", "the case this row verifies: it is that case again at the tighter setting of ballcage "
    "run --verify (ballcage.sweep_verification); null for the sweep's own cases",
)
#: The last column: which case's run gave a case its tables (`ballcage.studies.sweep_run.shared_runs`).
RUN_OF_COLUMN: tuple[str, pa.DataType, str, str] = (
    "run_of", pa.int32(), "", "the case whose run gave this case's tables: its own index, or an earlier case's whose "
    "scene has the same engine digest (Scene.engine_digest: bitwise the same run), so only what is computed from the "
    "tables afterwards differs",
)


def parameter_units(scene: _native.Scene, keys: Sequence[str]) -> dict[str, str]:
    """The unit of each dotted key of `scene`, from the engine's table of field units (`Scene.unit`).

    ``""`` for a pure number, text, or a key `scene` does not have (a sweep may set
    one its base scene leaves out).
    """
    units: dict[str, str] = {}
    for key in keys:
        try:
            unit = scene.unit(key)
        except _native.InputError:
            unit = ""
        units[key] = "" if unit == "-" else unit
    return units


def summary_table(
    records: Sequence[Mapping[str, Any]],
    parameters: Sequence[str],
    units: Mapping[str, str],
    meta: Mapping[str, str],
    quantities: SweepQuantities = GENERIC,
    verifies: int = 0,
) -> pa.Table:
    """One row per record (sorted by case): head, swept parameters, the `quantities` plug-in's columns, their
    numerical errors when the last `verifies` cases verify the first ones (the module docstring), cost."""
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
    columns = _quantity_columns(rows, quantities)
    for name, (unit, description) in columns.items():
        add(name, [r.get("quantities", {}).get(name) for r in rows], pa.float64(), unit, description)
    if verifies:
        checked = {int(r["case"]) - verifies: r for r in rows if int(r["case"]) >= verifies}
        for name, (unit, _) in columns.items():
            errors = [_error(r, checked.get(int(r["case"])), name) for r in rows]
            add(f"{name}_error", errors, pa.float64(), unit,
                f"numerical error of {name}: |value - the value of the case's verification run| (verifies)")
    for name, kind, unit, description in COST_COLUMNS:
        add(name, [r.get(name) for r in rows], kind, unit, description)
    if verifies:
        name, kind, unit, description = VERIFIES_COLUMN
        add(name, [int(r["case"]) - verifies if int(r["case"]) >= verifies else None for r in rows], kind, unit,
            description)
    name, kind, unit, description = RUN_OF_COLUMN
    add(name, [r.get(name) for r in rows], kind, unit, description)
    schema = pa.schema(fields)
    file_meta = dict(meta)
    file_meta["ballcage.units"] = json.dumps({f.name: f.metadata[b"unit"].decode() for f in schema})
    file_meta["ballcage.descriptions"] = json.dumps({f.name: f.metadata[b"description"].decode() for f in schema})
    file_meta["ballcage.version"] = _native.__version__
    return pa.Table.from_arrays(arrays, schema=schema.with_metadata(file_meta))


def _error(row: Mapping[str, Any], check: Mapping[str, Any] | None, name: str) -> float | None:
    """|value − value of the verification run| of quantity `name` in `row`; None where there is none."""
    if check is None or row.get("status") != "ok" or check.get("status") != "ok":
        return None
    a, b = row.get("quantities", {}).get(name), check.get("quantities", {}).get(name)
    numbers = all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in (a, b))
    return abs(a - b) if numbers else None


def _quantity_columns(rows: Sequence[Mapping[str, Any]], quantities: SweepQuantities) -> dict[str, tuple[str, str]]:
    """The plug-in's columns when any case recorded a quantity (none otherwise)."""
    present = {k for r in rows for k in r.get("quantities", {})}
    return quantities.columns(present) if present else {}


def _array(values: list[Any], kind: pa.DataType | None) -> pa.Array:
    if kind is not None:
        return pa.array(values, type=kind)
    try:
        return pa.array(values)
    except (pa.ArrowInvalid, pa.ArrowTypeError):  # mixed kinds of value: as their TOML text
        return pa.array([None if v is None else json.dumps(v) for v in values], type=pa.string())
