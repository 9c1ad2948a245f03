"""``sensitivity.parquet``'s rows from a sensitivity study's runs: effects, Morris indices, the numerical error.

`sensitivity_table` takes the sweep's ``summary.parquet`` (one row per run,
one column per quantity) and the study's `Design`, and gives one row per
quantity and parameter (`SENSITIVITY_SCHEMA`): OAT's values at each end and
their change, or SALib's Morris indices (`morris_indices`), the effect the
parameters are ranked by, and the base run's `numerical_error` with its
source. Only runs that finished (status ``ok``) count.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import pyarrow as pa

from ballcage.studies.schemas import SENSITIVITY_SCHEMA
from ballcage.studies.sensitivity_design import Design, problem, salib
from ballcage.studies.sensitivity_parameters import ParameterRange
from ballcage.studies.sweep_summary import COST_COLUMNS, RUN_OF_COLUMN

__all__ = ["morris_indices", "numerical_error", "sensitivity_table"]

#: The summary's columns before the swept keys (`ballcage.studies.sweep_summary`): not quantities.
_HEAD_COLUMNS = ("case", "case_id", "status", "error")


def sensitivity_table(
    summary: pa.Table, design: Design, base_meta: Mapping[str, str], parameters: Sequence[str] = ()
) -> pa.Table:
    """``sensitivity.parquet``'s rows (`SENSITIVITY_SCHEMA`): one per quantity of the sweep's `summary` and parameter.

    `base_meta` is the base run's metadata (for the integrator's error estimate); `parameters` the sweep's swept keys.
    """
    rows = {int(r["case"]): r for r in summary.to_pylist()}
    skip = {*_HEAD_COLUMNS, *parameters, *(c[0] for c in (*COST_COLUMNS, RUN_OF_COLUMN))}
    units = {f.name: (f.metadata or {}).get(b"unit", b"").decode() for f in summary.schema}
    out: list[dict[str, Any]] = []
    for quantity in (c for c in summary.column_names if c not in skip):
        out += _quantity_rows(quantity, units.get(quantity, ""), rows, design, base_meta)
    return pa.Table.from_pylist(out, schema=SENSITIVITY_SCHEMA)


def _value(rows: Mapping[int, Mapping[str, Any]], index: int, quantity: str) -> float | None:
    row = rows.get(index)
    if row is None or row.get("status") != "ok":
        return None
    value = row.get(quantity)
    return float(value) if isinstance(value, (int, float)) and math.isfinite(value) else None


def _quantity_rows(
    quantity: str, unit: str, rows: Mapping[int, Mapping[str, Any]], design: Design, base_meta: Mapping[str, str]
) -> list[dict[str, Any]]:
    base = _value(rows, 0, quantity)
    study = [i for i, r in enumerate(design.roles) if r.kind != "verify"]
    seen = [v for v in (_value(rows, i, quantity) for i in study) if v is not None]
    error, source = numerical_error(quantity, unit, base, rows, design, base_meta)
    if design.method == "morris" and error is not None:
        assert design.delta is not None
        error, source = 2.0 * error / design.delta, f"{source}; x 2/delta = {2.0 / design.delta:.3g} for an elementary effect"
    effects = _oat_effects(quantity, unit, base, rows, design) if design.method == "oat" else _morris_effects(
        quantity, rows, design)
    order = sorted((k for k, e in enumerate(effects) if e["effect"]), key=lambda k: -effects[k]["effect"])
    rank = {k: n for n, k in enumerate(order, start=1)}
    out = []
    for k, (r, effect) in enumerate(zip(design.ranges, effects, strict=True)):
        out.append({
            "method": design.method, "parameter": r.key, "parameter_unit": r.unit, "parameter_base": r.base,
            "parameter_low": r.low, "parameter_high": r.high, "quantity": quantity, "unit": unit, "base": base,
            **effect, "rank": rank.get(k), "numerical_error": error, "numerical_error_source": source,
            "below_error": None if error is None or effect["effect"] is None else effect["effect"] <= error,
            "range_min": min(seen) if seen else None, "range_max": max(seen) if seen else None, "runs": len(seen),
        })  # fmt: skip
    return out


def _oat_effects(
    quantity: str, unit: str, base: float | None, rows: Mapping[int, Mapping[str, Any]], design: Design
) -> list[dict[str, Any]]:
    out = []
    for r in design.ranges:
        low, high = design.ends[r.key]
        v_low, v_high = _value(rows, low, quantity), _value(rows, high, quantity)
        changes = [abs(v - base) for v in (v_low, v_high) if v is not None and base is not None]
        out.append({
            "value_low": v_low, "value_high": v_high,
            "change_low_pct": _pct(v_low, base, unit), "change_high_pct": _pct(v_high, base, unit),
            "effect": max(changes) if changes else None,
            "note": _missing(rows, {"base": 0, "low": low, "high": high}, quantity),
        })  # fmt: skip
    return out


def _pct(value: float | None, base: float | None, unit: str) -> float | None:
    """100 (value − base) / |base|; None for a part number (no unit), a missing value, or base 0 with value not 0."""
    if value is None or base is None or not unit:
        return None
    if base == 0.0:
        return 0.0 if value == 0.0 else None
    return 100.0 * (value - base) / abs(base)


def _missing(rows: Mapping[int, Mapping[str, Any]], cases: Mapping[str, int], quantity: str) -> str | None:
    """Which of the named runs did not finish or have no value of `quantity`; None when all have one."""
    parts = []
    for label, index in cases.items():
        row = rows.get(index)
        if row is None:
            parts.append(f"the {label} run (case {index}) has no record")
        elif row.get("status") != "ok":
            parts.append(f"the {label} run (case {index}) {row.get('status')}: {' '.join(str(row.get('error')).split())}")
        elif _value(rows, index, quantity) is None:
            parts.append(f"not computed in the {label} run (case {index})")
    return "; ".join(parts) or None


def _morris_effects(quantity: str, rows: Mapping[int, Mapping[str, Any]], design: Design) -> list[dict[str, Any]]:
    indices = design.indices("morris")
    ys = [_value(rows, i, quantity) for i in indices]
    empty = {"value_low": None, "value_high": None, "change_low_pct": None, "change_high_pct": None}
    missing = [i for i, y in zip(indices, ys, strict=True) if y is None]
    if missing:
        note = (f"no Morris indices: {len(missing)} of {len(indices)} Morris runs have no value (first case "
                f"{missing[0]}: {_missing(rows, {'Morris': missing[0]}, quantity)})")
        return [{**empty, "mu_star": None, "mu": None, "sigma": None, "mu_star_conf": None, "effect": None,
                 "note": note} for _ in design.ranges]  # fmt: skip
    assert design.levels is not None and design.seed is not None
    indices_by_name = morris_indices(design.ranges, design.morris_x, [y for y in ys if y is not None], design.levels,
                                     design.seed)
    out = []
    for r in design.ranges:
        mu_star, mu, sigma, conf = indices_by_name[r.key]
        out.append({**empty, "mu_star": mu_star, "mu": mu, "sigma": sigma, "mu_star_conf": conf, "effect": mu_star,
                    "note": None})
    return out


def morris_indices(
    ranges: Sequence[ParameterRange], x: Sequence[Sequence[float]], y: Sequence[float], levels: int, seed: int
) -> dict[str, tuple[float | None, float | None, float | None, float | None]]:
    """SALib's Morris analysis of the outputs `y` of the design `x`: key -> (mu_star, mu, sigma, mu_star_conf).

    Each in the output's unit per the parameter's whole range (SALib's
    unscaled elementary effects); the confidence interval at 95 % from 100
    bootstrap resamples seeded with `seed`. A value SALib leaves undefined
    (NaN, masked) is None.
    """
    import numpy as np

    _, analyze = salib()
    result = analyze.analyze(problem(ranges), np.asarray(x, dtype=float), np.asarray(y, dtype=float),
                             num_levels=levels, conf_level=0.95, num_resamples=100, seed=seed, print_to_console=False)

    def number(name: str, k: int) -> float | None:
        value = np.ma.filled(np.ma.asarray(result[name], dtype=float), np.nan)[k]
        return float(value) if math.isfinite(value) else None

    return {r.key: (number("mu_star", k), number("mu", k), number("sigma", k), number("mu_star_conf", k))
            for k, r in enumerate(ranges)}  # fmt: skip


def numerical_error(
    quantity: str,
    unit: str,
    base: float | None,
    rows: Mapping[int, Mapping[str, Any]],
    design: Design,
    base_meta: Mapping[str, str],
) -> tuple[float | None, str]:
    """The base run's numerical error on `quantity` [unit] and where it comes from (or why there is none).

    Measured, when the study has its verification case: |base − the base at
    the tighter setting|. Else, for a length (m, mm), the integrator's
    estimate of the global position error; else none.
    """
    why = ""
    if design.check is not None:
        index = len(design.roles) - 1
        check = _value(rows, index, quantity)
        if base is not None and check is not None:
            return abs(base - check), f"measured: |base run - the base run at {design.check.label}| (ballcage run --verify's rule)"
        why = f"no measured error ({_missing(rows, {'base': 0, 'verification': index}, quantity)}); "
    estimate = base_meta.get("ballcage.error_estimate_position_m")
    scale = {"m": 1.0, "mm": 1e3}.get(unit)
    if estimate and scale is not None:
        try:
            value = float(estimate) * scale
        except ValueError:
            value = math.nan
        if math.isfinite(value):
            return value, (f"{why}the integrator's estimate of the global position error "
                           f"(ballcage.error_estimate_position_m = {float(estimate):.3g} m), taken as a length's error")
    if estimate:
        reason = f"the integrator's estimate is of positions [m] and velocities [m/s], not of a quantity in {unit or 'no unit'}"
    else:
        reason = "the integrator gives no error estimate (fixed steps)"
    hint = "" if design.check is not None else "; verify=True (the default) measures one"
    return None, f"{why}no estimate: {reason}{hint}"
