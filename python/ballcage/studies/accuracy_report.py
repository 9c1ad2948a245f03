"""The accuracy study's files: ``work_precision.parquet``, the work-precision plot and the Markdown table."""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pyarrow as pa

from ballcage._files import write_parquet, write_png, write_text
from ballcage.studies.common import fmt, study_meta
from ballcage.studies.scalars import MAX_QUANTITY

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["accuracy_markdown", "write_accuracy"]


def _headline(table: pa.Table) -> list[str]:
    """Up to three headline quantities of a study table (non-zero in the reference), then `MAX_QUANTITY`.

    In order of preference: the peak key-seat force, joint 10's mean tube
    force (else the largest), the largest peak pair force, the first body's
    final position, the largest final link bend, the final total energy.
    """
    import pyarrow.compute as pc

    ref_rows = table.filter(pc.equal(table.column("role"), "reference"))
    refs = {
        q: abs(v)
        for q, v in zip(ref_rows.column("quantity").to_pylist(), ref_rows.column("reference").to_pylist(), strict=True)
        if q != MAX_QUANTITY and v is not None and math.isfinite(v) and v != 0.0
    }

    def largest(prefix: str) -> str | None:
        cands = [q for q in refs if q.startswith(prefix)]
        return max(cands, key=lambda q: refs[q]) if cands else None

    picked: list[str] = []
    for choice in (
        "key_seat_normal_peak",
        "tube_mean_force_joint_10" if "tube_mean_force_joint_10" in refs else largest("tube_mean_force_joint_"),
        largest("peak_normal_force_"),
        next((q for q in refs if q.startswith("final_position_")), None),
        largest("final_bend_deg_link_"),
        "final_total_energy",
    ):
        if choice is not None and choice in refs and choice not in picked and len(picked) < 3:
            picked.append(choice)
    return [*picked, MAX_QUANTITY]


def write_accuracy(table: pa.Table, out_dir: str | os.PathLike[str], *, command: str | None = None) -> dict[str, Path]:
    """Writes ``work_precision.parquet``, ``work_precision.png`` and ``work_precision.md`` into `out_dir`.

    Each file is written atomically. Returns the paths by name (``"parquet"``, ``"png"``, ``"md"``).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    return {
        "parquet": write_parquet(table, out / "work_precision.parquet"),
        "png": write_png(_accuracy_figure(table), out / "work_precision.png"),
        "md": write_text(accuracy_markdown(table, command=command), out / "work_precision.md"),
    }


#: Columns of a study row that belong to one quantity, not to the run.
_PER_QUANTITY = ("quantity", "unit", "value", "reference", "floor", "error", "reference_error")


def _runs(table: pa.Table) -> list[dict[str, Any]]:
    """One dict per run (integrator, dt, role) with its work columns and ``errors`` by quantity."""
    runs: dict[tuple[str, float, str], dict[str, Any]] = {}
    for r in table.to_pylist():
        key = (r["integrator"], r["dt"], r["role"])
        fresh = {**{k: v for k, v in r.items() if k not in _PER_QUANTITY}, "errors": {}, "reference_errors": {}}
        run = runs.setdefault(key, fresh)
        run["errors"][r["quantity"]] = r["error"]
        run["reference_errors"][r["quantity"]] = r["reference_error"]
    return list(runs.values())


def _accuracy_figure(table: pa.Table) -> Figure:
    """One log-log panel per headline quantity: relative error against wall time [s], a line per integrator."""
    from ballcage._plot import figure  # deferred: matplotlib

    panels = _headline(table)
    runs = _runs(table)
    cols = min(len(panels), 2)
    rows = math.ceil(len(panels) / cols)
    fig = figure(figsize=(5.5 * cols, 4.2 * rows))
    axes = np.atleast_1d(fig.subplots(rows, cols)).ravel()
    meta = study_meta(table)
    for ax, quantity in zip(axes, panels, strict=False):
        _panel(ax, runs, quantity)
    for ax in axes[len(panels) :]:
        ax.set_visible(False)
    fig.suptitle(
        f"Work-precision: reference {meta.get('ballcage.reference_integrator', '?')} at "
        f"{float(meta.get('ballcage.reference_dt_s', 'nan')):.3g} s, {float(meta.get('ballcage.duration_s', 'nan')):g} s simulated "
        "(errors below 1e-16 drawn at 1e-16; labels: dt [s])",
        fontsize=9,
    )
    return fig


def _panel(ax: Axes, runs: list[dict[str, Any]], quantity: str) -> None:
    """Error of `quantity` against wall time for each integrator's ladder, and the reference's self-error."""
    ladder = [r for r in runs if r["role"] == "run"]
    drawn = False
    for integrator in dict.fromkeys(r["integrator"] for r in ladder):
        mine = sorted((r for r in ladder if r["integrator"] == integrator), key=lambda r: -r["dt"])
        points = [(r["wall_s"], r["errors"].get(quantity), r["dt"]) for r in mine]
        ok = [(w, max(e, 1e-16), dt) for w, e, dt in points if e is not None and math.isfinite(e) and w and w > 0]
        diverged = sum(1 for r in mine if r["diverged"])
        label = integrator + (f" ({diverged} diverged)" if diverged else "")
        if ok:
            drawn = True
            (line,) = ax.loglog([p[0] for p in ok], [p[1] for p in ok], marker="o", label=label)
            for w, e, dt in ok:
                ax.annotate(f"{dt:.2g}", (w, e), textcoords="offset points", xytext=(4, 3), fontsize=6, color=line.get_color())
        else:
            ax.plot([], [], marker="x", label=label)
    ref_err = next((r["reference_errors"].get(quantity) for r in runs if r["role"] == "reference"), None)
    if ref_err is not None and math.isfinite(ref_err) and ref_err > 0:
        ax.axhline(ref_err, color="0.5", ls="--", lw=1, label="reference self-error")
    ax.set(xlabel="wall time [s]", ylabel="relative error", title=quantity.replace("_", " "))
    if drawn:
        ax.set_xscale("log")
        ax.set_yscale("log")
    else:
        ax.text(0.5, 0.5, "no finite error: every run diverged", transform=ax.transAxes, ha="center", fontsize=8)
    ax.grid(True, which="both", lw=0.3, alpha=0.5)
    ax.legend(fontsize=7)


def accuracy_markdown(table: pa.Table, *, command: str | None = None) -> str:
    """``work_precision.md``: the reference and its self-error, then one table row per run."""
    meta = study_meta(table)
    runs = _runs(table)
    headline = _headline(table)
    ref = next((r for r in runs if r["role"] == "reference"), None)
    floors = json.loads(meta.get("ballcage.floors", "{}"))
    lines = ["# Work-precision study", ""]
    if command:
        lines += ["```", command, "```", ""]
    lines.append(
        f"{float(meta.get('ballcage.duration_s', 'nan')):g} s simulated, output every "
        f"{float(meta.get('ballcage.output_interval_s', 'nan')):g} s. Reference: "
        f"{meta.get('ballcage.reference_integrator', '?')} at dt_ref = {float(meta.get('ballcage.reference_dt_s', 'nan')):.4g} s; "
        f"its self-error |q(dt_ref) − q(2·dt_ref)| / max(|q_ref|, floor) is at most "
        f"{fmt(float(meta.get('ballcage.reference_self_error_max', 'nan')))} "
        f"({meta.get('ballcage.reference_self_error_max_quantity', '')})"
        + (
            "; " + ", ".join(f"{q}: {fmt(ref['reference_errors'].get(q))}" for q in headline if q != MAX_QUANTITY)
            if ref
            else ""
        )
        + ". Errors at or below it are not resolved. A second method, "
        f"{meta.get('ballcage.second_method', '?')} (adaptive steps up to the output interval), agrees with the "
        f"reference within {fmt(float(meta.get('ballcage.second_method_error_max', 'nan')))} "
        f"({meta.get('ballcage.second_method_error_max_quantity', '')})."
    )
    lines += [
        "",
        "Error = |q − q_ref| / max(|q_ref|, floor); floors: "
        + ", ".join(f"{k} {v[0]:g} {v[1]}" for k, v in floors.items())
        + ". `max` is the largest error over all quantities of the run; inf = diverged.",
        "",
        "| integrator | dt [s] | role | wall [s] | steps | force evals | Newton its | "
        + " | ".join(("max" if q == MAX_QUANTITY else q) for q in headline)
        + " | note |",
        "| --- | ---: | --- | ---: | ---: | ---: | ---: | " + " | ".join("---:" for _ in headline) + " | --- |",
    ]
    for r in runs:
        note = ("diverged: " + str(r["message"]).replace("|", "\\|")) if r["diverged"] else ""
        cells = [
            r["integrator"],
            f"{r['dt']:.4g}",
            r["role"],
            f"{r['wall_s']:.3g}",
            "" if r["steps"] is None else str(r["steps"]),
            "" if r["force_evaluations"] is None else str(r["force_evaluations"]),
            "" if r["newton_iterations"] is None else str(r["newton_iterations"]),
            *[fmt(r["errors"].get(q)) for q in headline],
            note,
        ]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
