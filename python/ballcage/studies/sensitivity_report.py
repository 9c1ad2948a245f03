"""``sensitivity.md``, and a sensitivity table read back: each quantity's spread and dominant parameter.

`sensitivity_markdown` ranks the parameters for each quantity by effect
size, with the command and date at the top. `read_sensitivity` reads a
``sensitivity.parquet`` (checking its columns) and `spreads` gives, for each
quantity, the range over the study's runs and the parameter with the largest
effect, which ``ballcage paper`` adds to its comparison rows.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pyarrow as pa

from ballcage._native import InputError
from ballcage.studies.common import study_meta

__all__ = ["Spread", "by_quantity", "moves", "read_sensitivity", "sensitivity_markdown", "spreads"]

#: The columns `spreads` needs in a sensitivity table (`ballcage.studies.schemas.SENSITIVITY_SCHEMA`).
_NEEDED = ("parameter", "quantity", "unit", "base", "effect", "rank", "below_error", "range_min", "range_max", "runs")


@dataclass(frozen=True)
class Spread:
    """A quantity's spread over a sensitivity study: range over its runs [unit] and its dominant parameter."""

    quantity: str
    unit: str
    base: float | None
    low: float | None  # smallest value over the study's runs
    high: float | None  # largest
    runs: int
    dominant: str | None  # the parameter of rank 1; None when no parameter has an effect
    effect: float | None  # its effect [unit]
    below_error: bool | None  # its effect is below the base run's numerical error (None: no estimate)


def read_sensitivity(path: str | os.PathLike[str]) -> pa.Table:
    """A ``sensitivity.parquet``; `InputError` naming the file when it cannot be read or is not one."""
    import pyarrow.parquet as pq

    try:
        table = pq.read_table(path)
    except (OSError, pa.ArrowInvalid) as e:
        raise InputError(f"{os.fspath(path)}: cannot read the sensitivity table: {e}") from None
    missing = [c for c in _NEEDED if c not in table.column_names]
    if missing:
        raise InputError(f"{os.fspath(path)}: not a sensitivity table (ballcage sensitivity): no column "
                         f"{', '.join(missing)}")
    return table


def spreads(table: pa.Table) -> dict[str, Spread]:
    """Each quantity's `Spread`, from a sensitivity table's rows (the first row of each quantity for its range)."""
    out: dict[str, Spread] = {}
    ranked: dict[str, dict[str, Any]] = {}
    for row in table.select(list(_NEEDED)).to_pylist():
        q = row["quantity"]
        if q not in out:
            out[q] = Spread(q, row["unit"] or "", row["base"], row["range_min"], row["range_max"], row["runs"] or 0,
                            None, None, None)
        if row["rank"] == 1 and q not in ranked:
            ranked[q] = row
    for q, row in ranked.items():
        s = out[q]
        out[q] = Spread(s.quantity, s.unit, s.base, s.low, s.high, s.runs, row["parameter"], row["effect"],
                        row["below_error"])
    return out


def sensitivity_markdown(table: pa.Table, charts: Mapping[str, Path], out: Path) -> str:
    """``sensitivity.md``: the command and date, the method, the parameters, the dominant parameter of each
    quantity, then each quantity's parameters ranked by effect with its tornado chart (`charts`, under `out`)."""
    meta = study_meta(table)
    method = meta.get("ballcage.sensitivity.method", "")
    lines = [
        f"# Sensitivity of the {meta.get('ballcage.sensitivity.scene_kind', '')} scene "
        f"\"{meta.get('ballcage.sensitivity.scene_name') or 'unnamed'}\" to {len(_ranges(meta))} parameters",
        "",
        "```",
        meta.get("ballcage.sensitivity.command", ""),
        "```",
        "",
        f"Written {meta.get('ballcage.sensitivity.date', '')} by ballcage {meta.get('ballcage.version', '')}. "
        + _method_text(meta) + " " + _scene_text(meta),
        "",
        _error_text(table, meta),
        "",
        *_parameter_lines(meta),
        "",
        "## The dominant parameter of each quantity",
        "",
        "| quantity | unit | base | range over the runs | dominant parameter | its effect | numerical error |",
        "| --- | --- | ---: | --- | --- | ---: | ---: |",
    ]
    grouped = by_quantity(table)
    for q, rows in grouped.items():
        s = spreads_row(rows)
        lines.append(f"| {q} | {rows[0]['unit']} | {_num(rows[0]['base'])} | {s} |")
    lines += ["", f"Effect: {_effect_text(method)}. A parameter flagged **below the numerical error** moves the "
              "quantity less than the base run's own error: this run cannot tell its effect.", ""]
    quiet = []
    for q, rows in grouped.items():
        if q not in charts and not moves(rows):
            quiet.append(q)
            continue
        lines += _quantity_section(q, rows, charts.get(q), out, method)
    if quiet:
        lines += ["", "## Quantities without a chart", "",
                  "Null or zero in every run (a part the model lacks, a link that never touches the tube in this run), "
                  "or no parameter moved them: " + ", ".join(f"`{q}`" for q in quiet) + "."]
    return "\n".join(lines) + "\n"


def spreads_row(rows: list[dict[str, Any]]) -> str:
    """The summary table's cells after the base: range, dominant parameter, its effect, numerical error."""
    first = rows[0]
    span = "—" if first["range_min"] is None else f"{_num(first['range_min'])} – {_num(first['range_max'])}"
    top = next((r for r in rows if r["rank"] == 1), None)
    error = _num(first["numerical_error"]) if first["numerical_error"] is not None else "no estimate"
    if top is None:
        return f"{span} | — | — | {error}"
    flag = " (below the numerical error)" if top["below_error"] else ""
    return f"{span} | `{top['parameter']}`{flag} | {_num(top['effect'])} | {error}"


def _quantity_section(
    q: str, rows: list[dict[str, Any]], chart: Path | None, out: Path, method: str
) -> list[str]:
    unit = _shown(rows[0]["unit"])
    head = f"## {q}" + (f" [{unit or '-'}]" if rows[0]["unit"] else "")
    lines = ["", head, "", f"Base {_num(rows[0]['base'])} {unit}".rstrip() + "; numerical error: "
             + (f"{_num(rows[0]['numerical_error'])} {unit}".rstrip() if rows[0]["numerical_error"] is not None
                else "none") + f" ({rows[0]['numerical_error_source']}).", ""]
    if chart is not None:
        lines += [f"![tornado chart of {q}]({chart.relative_to(out).as_posix()})", ""]
    if method == "morris":
        lines += ["| rank | parameter | range | mu_star | mu | sigma | mu_star 95 % conf. | vs numerical error | note |",
                  "| ---: | --- | --- | ---: | ---: | ---: | ---: | --- | --- |"]
    else:
        lines += ["| rank | parameter | range | value at low | value at high | change at low | change at high | "
                  "vs numerical error | note |",
                  "| ---: | --- | --- | ---: | ---: | ---: | ---: | --- | --- |"]
    for r in sorted(rows, key=lambda r: (r["rank"] is None, r["rank"] or 0)):
        span = f"{_num(r['parameter_low'])} – {_num(r['parameter_high'])} {r['parameter_unit']}".rstrip()
        verdict = {True: "**below the numerical error**", False: "above", None: "—"}[r["below_error"]]
        note = (r["note"] or "").replace("|", "\\|")
        if method == "morris":
            cells = [_num(r[c]) for c in ("mu_star", "mu", "sigma", "mu_star_conf")]
        else:
            cells = [_num(r["value_low"]), _num(r["value_high"]), _pct(r["change_low_pct"]), _pct(r["change_high_pct"])]
        rank = "" if r["rank"] is None else str(r["rank"])
        lines.append(f"| {rank} | `{r['parameter']}` | {span} | {' | '.join(cells)} | {verdict} | {note} |")
    return lines


def by_quantity(table: pa.Table) -> dict[str, list[dict[str, Any]]]:
    out: dict[str, list[dict[str, Any]]] = {}
    for row in table.to_pylist():
        out.setdefault(row["quantity"], []).append(row)
    return out


def moves(rows: list[dict[str, Any]]) -> bool:
    """Whether any run gives the quantity a nonzero value or any parameter an effect."""
    return any((r["effect"] or 0.0) > 0.0 for r in rows) or any(
        v not in (None, 0.0) for v in (rows[0]["range_min"], rows[0]["range_max"])
    )


def _method_text(meta: Mapping[str, str]) -> str:
    runs = meta.get("ballcage.sensitivity.runs", "")
    shared = int(meta.get("ballcage.sensitivity.shared_runs", "0") or 0)
    tail = (f"; {shared} of them not simulated: their scene's engine digest is another run's, so their quantities "
            "come from that run's tables") if shared else ""
    if meta.get("ballcage.sensitivity.method") == "morris":
        return (
            f"Method: Morris elementary effects (SALib's design and analysis), "
            f"{meta.get('ballcage.sensitivity.trajectories')} trajectories on {meta.get('ballcage.sensitivity.levels')} "
            f"levels, seed {meta.get('ballcage.sensitivity.seed')}, and the base run: {runs} runs{tail}."
        )
    return f"Method: one at a time (OAT), the base run and each parameter at its low and at its high value: {runs} runs{tail}."


def _effect_text(method: str) -> str:
    if method == "morris":
        return ("mu_star, the mean absolute elementary effect: the change of the quantity per the parameter's whole "
                "range (SALib's unscaled effects); sigma their spread (interactions, non-linearity); in the quantity's "
                "unit")
    return "the larger of |value at low − base| and |value at high − base|, in the quantity's unit"


def _scene_text(meta: Mapping[str, str]) -> str:
    overrides = meta.get("ballcage.sensitivity.overrides", "[]")
    duration = meta.get("ballcage.sensitivity.duration_s", "")
    return f"Base scene: {meta.get('ballcage.sensitivity.scene_name') or 'unnamed'}, {duration} s simulated, overrides {overrides}."


def _error_text(table: pa.Table, meta: Mapping[str, str]) -> str:
    label = meta.get("ballcage.sensitivity.verification", "")
    if label:
        return (f"Numerical error: measured on each quantity as |base run − the base run at {label}| (the rule of "
                "`ballcage run --verify`), drawn in each chart as a bar of its own.")
    return ("Numerical error: no verification run (--no-verify); a length takes the integrator's estimate of the global "
            "position error where the run has one, every other quantity has none (said in its chart).")


def _ranges(meta: Mapping[str, str]) -> list[dict[str, Any]]:
    """The study's parameters and their ranges, from the table's metadata."""
    return list(json.loads(meta.get("ballcage.sensitivity.parameters", "[]")))


def _parameter_lines(meta: Mapping[str, str]) -> list[str]:
    ranges = _ranges(meta)
    lines = ["## Parameters", "", "| parameter | base | low | high | unit | source | reference | why this range |",
             "| --- | ---: | ---: | ---: | --- | --- | --- | --- |"]
    for r in ranges:
        cells = [f"`{r['key']}`", _num(r["base"]), _num(r["low"]), _num(r["high"]), r["unit"], r["source"],
                 r["reference"], r["range_reason"]]
        lines.append("| " + " | ".join(str(c).replace("|", "\\|") for c in cells) + " |")
    return lines


def _num(x: float | None, digits: int = 5) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "—"
    return f"{x:.{digits}g}"


def _shown(unit: str) -> str:
    """A unit beside a number: none for a pure number (``1``, ``-``)."""
    return "" if unit in ("1", "-") else unit


def _pct(x: float | None) -> str:
    return "—" if x is None else f"{x:+.2f} %"

