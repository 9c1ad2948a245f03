"""The stability study's files: ``stability.parquet``, heat maps of the largest stable step and ``stability.md``."""

from __future__ import annotations

import math
import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import pyarrow as pa

from ballcage._files import write_parquet, write_png, write_text
from ballcage.studies.common import study_meta

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["stability_markdown", "write_stability"]


def write_stability(table: pa.Table, out_dir: str | os.PathLike[str], *, command: str | None = None) -> dict[str, Path]:
    """Writes ``stability.parquet``, one heat map ``stability_<parameter>.png`` per parameter
    (``stability_grid.png`` for the stiffness × speed map) and ``stability.md`` into `out_dir`.

    Each file is written atomically. Returns the paths by name (``"parquet"``, the figure's file stem, ``"md"``).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = {"parquet": write_parquet(table, out / "stability.parquet")}
    rows = table.to_pylist()
    single = [r for r in rows if r["parameter2"] is None]
    figures = {
        f"stability_{name}": _heat_map([r for r in single if r["parameter"] == name])
        for name in dict.fromkeys(r["parameter"] for r in single)
    }
    pairs = [r for r in rows if r["parameter2"] is not None]
    if pairs:
        figures["stability_grid"] = _grid_map(pairs)
    for name, fig in figures.items():
        written[name] = write_png(fig, out / f"{name}.png")
    written["md"] = write_text(stability_markdown(table, command=command), out / "stability.md")
    return written


def _log10(x: float) -> float:
    return math.log10(x) if x is not None and math.isfinite(x) and x > 0 else math.nan


def _cell_text(r: Mapping[str, Any]) -> str:
    dt = r["max_stable_dt_s"]
    if dt is None or not math.isfinite(dt):
        return "none"
    return ("≥" if r["min_unstable_dt_s"] is None or math.isnan(r["min_unstable_dt_s"]) else "") + f"{dt:.2g}"


def _value_label(v: float) -> str:
    return f"{v:.3g}"


def _draw_map(
    ax: Axes,
    matrix: np.ndarray,
    texts: list[list[str]],
    vmin: float,
    vmax: float,
    origin: Literal["upper", "lower"] = "upper",
) -> Any:
    from ballcage._plot import colormap  # deferred: matplotlib

    cmap = colormap("viridis").with_extremes(bad="0.85")  # no stable step: grey
    image = ax.imshow(np.ma.masked_invalid(matrix), cmap=cmap, vmin=vmin, vmax=vmax, aspect="auto", origin=origin)
    span = vmax - vmin if vmax > vmin else 1.0
    for i, row in enumerate(texts):
        for j, text in enumerate(row):
            dark = np.isfinite(matrix[i, j]) and (matrix[i, j] - vmin) / span < 0.6  # viridis is dark below ~0.6
            ax.text(j, i, text, ha="center", va="center", fontsize=7, color="w" if dark else "k")
    return image


def _limits(values: Iterable[float]) -> tuple[float, float]:
    finite = [v for v in values if math.isfinite(v)]
    if not finite:
        return -7.0, -3.0
    lo, hi = min(finite), max(finite)
    return (lo - 0.5, hi + 0.5) if hi - lo < 1e-9 else (lo, hi)


def _heat_map(rows: Sequence[Mapping[str, Any]]) -> Figure:
    from ballcage._plot import figure  # deferred: matplotlib

    integrators_ = list(dict.fromkeys(r["integrator"] for r in rows))
    values = sorted({r["value"] for r in rows})
    by = {(r["integrator"], r["value"]): r for r in rows}
    matrix = np.full((len(integrators_), len(values)), np.nan)
    texts = [["" for _ in values] for _ in integrators_]
    for i, integ in enumerate(integrators_):
        for j, v in enumerate(values):
            r = by.get((integ, v))
            if r is not None:
                matrix[i, j] = _log10(r["max_stable_dt_s"])
                texts[i][j] = _cell_text(r)
    fig = figure(figsize=(1.3 * len(values) + 3.0, 0.7 * len(integrators_) + 2.0))
    ax = fig.subplots()
    image = _draw_map(ax, matrix, texts, *_limits(matrix.ravel()))
    ax.set_xticks(range(len(values)), [_value_label(v) for v in values])
    ax.set_yticks(range(len(integrators_)), integrators_)
    ax.set_xlabel(f"{rows[0]['parameter']} [{rows[0]['unit']}]")
    ax.set_title(f"Largest stable step vs {rows[0]['parameter']} (cells: dt [s]; ≥: stable at the largest probe)", fontsize=9)
    fig.colorbar(image, ax=ax, label="log10 max stable dt [s]")
    return fig


def _grid_map(rows: Sequence[Mapping[str, Any]]) -> Figure:
    from ballcage._plot import figure  # deferred: matplotlib

    integrators_ = list(dict.fromkeys(r["integrator"] for r in rows))
    xs = sorted({r["value"] for r in rows})
    ys = sorted({r["value2"] for r in rows})
    fig = figure(figsize=(4.6 * len(integrators_) + 1.0, 4.2))
    axes = np.atleast_1d(fig.subplots(1, len(integrators_)))
    vmin, vmax = _limits(_log10(r["max_stable_dt_s"]) for r in rows)
    image = None
    for ax, integ in zip(axes, integrators_, strict=True):
        by = {(r["value"], r["value2"]): r for r in rows if r["integrator"] == integ}
        matrix = np.full((len(ys), len(xs)), np.nan)
        texts = [["" for _ in xs] for _ in ys]
        for i, y in enumerate(ys):
            for j, x in enumerate(xs):
                r = by.get((x, y))
                if r is not None:
                    matrix[i, j] = _log10(r["max_stable_dt_s"])
                    texts[i][j] = _cell_text(r)
        image = _draw_map(ax, matrix, texts, vmin, vmax, origin="lower")
        ax.set_xticks(range(len(xs)), [_value_label(v) for v in xs], fontsize=7)
        ax.set_yticks(range(len(ys)), [_value_label(v) for v in ys], fontsize=7)
        ax.set(xlabel=f"{rows[0]['parameter']} [{rows[0]['unit']}]", ylabel=f"{rows[0]['parameter2']} [{rows[0]['unit2']}]", title=integ)
    if image is not None:
        fig.colorbar(image, ax=list(axes), label="log10 max stable dt [s]")
    return fig


def stability_markdown(table: pa.Table, *, command: str | None = None) -> str:
    """``stability.md``: per parameter, integrators × values of the largest stable step [s]."""
    meta = study_meta(table)
    rows = table.to_pylist()
    lines = ["# Largest stable step", ""]
    if command:
        lines += ["```", command, "```", ""]
    radius = meta.get("ballcage.tightest_radius_m")
    lines.append(
        f"Probe runs of {float(meta.get('ballcage.duration_s', 'nan')):g} s; a probe is stable when it finishes without a "
        f"divergence error. Bracketing by x{float(meta.get('ballcage.bracket_factor', 'nan')):g}, then "
        f"{meta.get('ballcage.bisections', '?')} bisections in log dt. '≥' marks a step stable at the largest probe; "
        "'none' no stable step found (why: below)."
        + (f" Tightest curvature radius the hinge allows: {float(radius):.3f} m." if radius else "")
    )
    single = [r for r in rows if r["parameter2"] is None]
    for name in dict.fromkeys(r["parameter"] for r in single):
        mine = [r for r in single if r["parameter"] == name]
        values = sorted({r["value"] for r in mine})
        by = {(r["integrator"], r["value"]): r for r in mine}
        lines += [
            "",
            f"## {name} [{mine[0]['unit']}]",
            "",
            "| integrator | " + " | ".join(_value_label(v) for v in values) + " |",
            "| --- | " + " | ".join("---:" for _ in values) + " |",
        ]
        for integ in dict.fromkeys(r["integrator"] for r in mine):
            lines.append("| " + integ + " | " + " | ".join(_cell_text(by[(integ, v)]) if (integ, v) in by else "" for v in values) + " |")
    pairs = [r for r in rows if r["parameter2"] is not None]
    if pairs:
        lines += ["", f"## {pairs[0]['parameter']} x {pairs[0]['parameter2']}: see stability_grid.png and stability.parquet"]
    failed = [r for r in rows if not math.isfinite(r["max_stable_dt_s"])]
    if failed:
        lines += ["", "## No stable step", ""]
        for r in failed:
            where = f"{r['parameter']} = {r['value']:.4g} {r['unit']}"
            if r["parameter2"] is not None:
                where += f", {r['parameter2']} = {r['value2']:.4g} {r['unit2']}"
            lines.append(f"- {r['integrator']}, {where}: {r['message']}")
    return "\n".join(lines) + "\n"
