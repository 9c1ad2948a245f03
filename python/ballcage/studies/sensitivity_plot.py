"""Tornado charts of a sensitivity study: one per quantity, ``plots/tornado_<quantity>.png``.

Each parameter is a row, the largest effect at the top. One at a time (OAT):
two bars from the base value, the change with the parameter at its low
value and at its high value, in the quantity's unit (the top axis in per cent
of the base), or in decades, log10(value / base), for a quantity whose
values span more than two decades (a fatigue life: `spans_decades`).
Morris: a bar of mu_star with its 95 % confidence interval and a diamond at
sigma. The base run's numerical error is a row of its own (a
hatched red bar) and a shaded band across every row: a parameter whose effect
lies inside it is drawn grey and labelled "below the numerical error". A
quantity without an error estimate says so above the chart, with the reason.

Drawn: every quantity with a unit (not a part number such as
``most_deformed_joint``) that some run gives a nonzero value or some parameter
moves.
"""

from __future__ import annotations

import math
import re
import textwrap
from pathlib import Path
from typing import Any

import pyarrow as pa

from ballcage._files import write_png
from ballcage._plot import figure
from ballcage.studies.sensitivity_report import by_quantity, moves

__all__ = ["DECADES", "chart_name", "spans_decades", "tornado_figure", "write_tornados"]

_LOW, _HIGH, _GREY, _ERROR = "#1f77b4", "#ff7f0e", "#c0c0c0", "#d62728"
#: A quantity whose values span more decades than this is charted in decades (`spans_decades`).
DECADES = 2.0
#: Characters a chart's file name does not keep.
_UNSAFE = re.compile(r"[^A-Za-z0-9_.\-]")


def chart_name(quantity: str) -> str:
    """The chart's file name: ``tornado_<quantity>.png``, characters other than letters, digits, ``_.-`` as ``_``."""
    return "tornado_" + _UNSAFE.sub("_", quantity) + ".png"


def write_tornados(table: pa.Table, folder: Path) -> dict[str, Path]:
    """Writes one chart per drawn quantity into `folder`; returns the paths by quantity."""
    written: dict[str, Path] = {}
    for quantity, rows in by_quantity(table).items():
        if not rows[0]["unit"] or rows[0]["base"] is None or not moves(rows):
            continue
        folder.mkdir(parents=True, exist_ok=True)
        written[quantity] = write_png(tornado_figure(rows), folder / chart_name(quantity))
    return written


def tornado_figure(rows: list[dict[str, Any]]) -> Any:
    """The tornado chart of one quantity's rows of a sensitivity table."""
    first = rows[0]
    ordered = sorted(rows, key=lambda r: (r["effect"] is None, -(r["effect"] or 0.0)))
    fig = figure(figsize=(8.0, 1.9 + 0.55 * (len(ordered) + 1)))
    ax = fig.subplots()
    unit = _unit(first["unit"])
    morris = first["method"] == "morris"
    decades = not morris and spans_decades(rows)
    error = first["numerical_error"]
    if error is not None and decades:
        error = math.log10(1.0 + error / first["base"])
    if error is not None:
        lo = 0.0 if morris else -error
        ax.axvspan(lo, error, color=_ERROR, alpha=0.08, lw=0)
    n = len(ordered)
    seen: set[str] = set()  # the legend's labels so far: each once
    for k, row in enumerate(ordered):
        y = n - k  # the largest effect on top; the error row at 0
        grey = bool(row["below_error"])
        if morris:
            _morris_row(ax, y, row, grey, seen)
        else:
            _oat_row(ax, y, row, first["base"], grey, seen, decades)
    if error is not None:
        ax.barh(0, error - (0.0 if morris else -error), left=0.0 if morris else -error, height=0.6, color="white",
                edgecolor=_ERROR, hatch="///", label="numerical error of the base run")
    else:
        ax.text(0.5, 0, "numerical error: no estimate", transform=ax.get_yaxis_transform(), ha="center",
                va="center", color=_ERROR, fontsize="small")
    ax.axvline(0.0, color="black", lw=0.8)
    ax.set_yticks(range(n, -1, -1), [_row_label(r) for r in ordered] + [_error_label(first["numerical_error"], unit,
                  morris)], fontsize="small")  # fmt: skip
    for tick, row in zip(ax.get_yticklabels(), ordered, strict=False):
        if row["below_error"]:
            tick.set_color("grey")
    ax.set_ylim(-0.7, n + 0.7)
    if morris:
        ax.set_xlabel(f"elementary effect over the parameter's whole range [{unit}]")
    elif decades:
        ax.set_xlabel("change from the base run [decades: log10(value / base)]")
    else:
        ax.set_xlabel(f"change from the base run [{unit}]")
        base = first["base"]
        if base:
            scale = 100.0 / abs(base)

            def to_pct(x: Any) -> Any:
                return x * scale

            def from_pct(p: Any) -> Any:
                return p / scale

            ax.secondary_xaxis("top", functions=(to_pct, from_pct)).set_xlabel("change [% of the base]")
    handles, labels = ax.get_legend_handles_labels()
    if handles:
        fig.legend(handles, labels, loc="outside lower center", ncols=min(len(handles), 3), fontsize="small")
    source = textwrap.fill(f"numerical error: {first['numerical_error_source']}", 110)
    ax.set_title(source, fontsize="x-small", loc="left")
    what = "Morris mu_star" if morris else "one at a time"
    fig.suptitle(f"{first['quantity']}: base {_num(first['base'])} {_shown(unit)}".rstrip() + f" ({what})")
    return fig


def _once(label: str, seen: set[str]) -> str | None:
    """`label` the first time it is asked for, then None (one legend entry per kind of bar)."""
    if label in seen:
        return None
    seen.add(label)
    return label


def spans_decades(rows: list[dict[str, Any]]) -> bool:
    """Whether a quantity's values over the study are all positive and span more than `DECADES` decades (a fatigue
    life): its OAT chart then shows log10(value / base), where a linear axis would hide all but the largest bar."""
    values = [r[k] for r in rows for k in ("value_low", "value_high")] + [rows[0]["base"]]
    values = [v for v in values if v is not None]
    return bool(values) and min(values) > 0.0 and math.log10(max(values) / min(values)) > DECADES


def _oat_row(
    ax: Any, y: float, row: dict[str, Any], base: float | None, grey: bool, seen: set[str], decades: bool = False
) -> None:
    for value, offset, color, label in ((row["value_low"], 0.17, _LOW, "parameter at its low value"),
                                        (row["value_high"], -0.17, _HIGH, "parameter at its high value")):
        if value is None or base is None:
            ax.text(0.0, y + offset, "  no value", va="center", fontsize="x-small")
            continue
        label = "below the numerical error" if grey else label
        width = math.log10(value / base) if decades else value - base
        ax.barh(y + offset, width, height=0.32, color=_GREY if grey else color, label=_once(label, seen))


def _morris_row(ax: Any, y: float, row: dict[str, Any], grey: bool, seen: set[str]) -> None:
    if row["mu_star"] is None:
        ax.text(0.0, y, "  no Morris indices", va="center", fontsize="x-small")
        return
    label = "below the numerical error" if grey else "mu_star (95 % conf.)"
    ax.barh(y, row["mu_star"], height=0.5, color=_GREY if grey else _LOW, xerr=row["mu_star_conf"], capsize=3,
            label=_once(label, seen))
    if row["sigma"] is not None:
        ax.plot([row["sigma"]], [y], "D", color="black", ms=5, label=_once("sigma", seen))


def _row_label(row: dict[str, Any]) -> str:
    span = f"{_num(row['parameter_low'])} – {_num(row['parameter_high'])} {row['parameter_unit']}".rstrip()
    flag = "\n(below the numerical error)" if row["below_error"] else ""
    return f"{row['parameter']}\n{span}{flag}"


def _error_label(error: float | None, unit: str, morris: bool) -> str:
    if error is None:
        return "numerical error\n(no estimate)"
    return f"numerical error\n{'2 err / delta =' if morris else '±'} {_num(error)} {_shown(unit)}".rstrip()


def _unit(unit: str) -> str:
    """An axis label's unit: ``-`` for a pure number."""
    return "-" if unit in ("1", "-", "") else unit


def _shown(unit: str) -> str:
    """A value's unit beside the number: none for a pure number."""
    return "" if unit == "-" else unit


def _num(x: float | None) -> str:
    return "—" if x is None else f"{x:.4g}"
