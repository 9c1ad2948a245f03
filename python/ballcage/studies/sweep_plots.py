"""The sweep's summary plots: each headline quantity against each swept parameter, one line per value of the others.

One PNG per swept parameter, ``DIR/plots/<parameter>.png``, with one panel per
quantity of `PLOTTED` that some finished case has; each line joins the cases
that share the values of every other swept parameter (its legend names
them). Only cases with status ``ok`` are drawn. A parameter whose values are
not all numbers (a hinge model, an integrator) is drawn on an axis of its
values in sweep order.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import pyarrow as pa

from ballcage._files import write_png
from ballcage._plot import figure, no_data, series_styles

__all__ = ["PLOTTED", "write_plots"]

#: Summary columns drawn, in panel order.
PLOTTED: tuple[str, ...] = (
    "tube_normal_mean_max_n",
    "tube_normal_peak_max_n",
    "key_peak_n",
    "seat_cage_normal_peak_n",
    "included_angle_min_deg",
    "range_of_motion_peak_to_peak_mm",
    "efficiency",
    "wall_time_s",
)


def write_plots(summary: pa.Table, parameters: list[str], out: Path) -> dict[str, Path]:
    """Writes ``out/plots/<parameter>.png`` for each swept parameter; returns the paths by parameter."""
    ok = [r for r in summary.to_pylist() if r["status"] == "ok"]
    names = [q for q in PLOTTED if q in summary.column_names and any(_number(r[q]) for r in ok)]
    units = {f.name: (f.metadata or {}).get(b"unit", b"").decode() for f in summary.schema}
    written: dict[str, Path] = {}
    if not names:
        return written
    (out / "plots").mkdir(parents=True, exist_ok=True)
    for parameter in parameters:
        fig = _figure(ok, parameter, [p for p in parameters if p != parameter], names, units)
        written[parameter] = write_png(fig, out / "plots" / f"{_file_name(parameter)}.png")
    return written


def _figure(rows: list[dict[str, Any]], parameter: str, others: list[str], names: list[str], units: dict[str, str]) -> Any:
    columns = min(len(names), 4)
    nrows = math.ceil(len(names) / columns)
    fig = figure(figsize=(3.6 * columns, 2.9 * nrows + 0.6))
    axes = fig.subplots(nrows, columns, squeeze=False).ravel()
    xs = [r[parameter] for r in rows]
    numeric = all(_number(x) for x in xs)
    order = list(dict.fromkeys(_key(x) for x in xs))
    groups: dict[tuple[str, ...], list[dict[str, Any]]] = {}
    for r in rows:
        groups.setdefault(tuple(_key(r[o]) for o in others), []).append(r)
    styles = series_styles(len(groups))
    for ax, name in zip(axes, names, strict=False):
        for style, (label, members) in zip(styles, groups.items(), strict=True):
            points = sorted(
                ((float(r[parameter]) if numeric else order.index(_key(r[parameter])), r[name]) for r in members if _number(r[name])),
            )
            if points:
                text = ", ".join(_setting(o, v, units) for o, v in zip(others, label, strict=True)) or None
                ax.plot([p[0] for p in points], [p[1] for p in points], label=text, **style)
        if not numeric:
            ax.set_xticks(range(len(order)), order, rotation=20)
        ax.set_xlabel(_label(parameter, units))
        ax.set_ylabel(_label(name, units))
        if not ax.lines:
            no_data(ax, "no finished case")
    for ax in axes[len(names):]:
        ax.set_visible(False)
    if others and len(groups) > 1:
        handles, labels = axes[0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="outside lower center", ncols=min(len(groups), 4), fontsize="small")
    fig.suptitle(f"sweep summary against {parameter}")
    return fig


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _key(value: Any) -> str:
    return f"{value:g}" if _number(value) else str(value)


def _label(name: str, units: dict[str, str]) -> str:
    """An axis label with its unit: ``[-]`` for a pure number (unit ``1`` or ``-``), none for a text column."""
    unit = units.get(name, "")
    if unit in ("1", "-"):
        unit = "-"
    return f"{name} [{unit}]" if unit else name


def _setting(parameter: str, value: str, units: dict[str, str]) -> str:
    """A legend entry's ``parameter=value unit`` (no unit for a pure number or a text value)."""
    unit = units.get(parameter, "")
    return f"{parameter}={value} {unit}" if unit not in ("", "1", "-") else f"{parameter}={value}"


def _file_name(parameter: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.\-]", "_", parameter)
