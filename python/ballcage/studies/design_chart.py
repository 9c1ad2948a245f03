"""The design chart (issue 13): forces over curvature radius × joint length, and where the chain fits.

For one guide tube (inner diameter D) and one joint outer diameter d, every
cell of the grid curvature radius R × joint length L (``pipe.pitch``) is
checked before anything runs, by the scene validator of the Rust core (the
check ``ballcage run`` makes), which refuses a cell that breaks

- eq. (9) of Zhu et al. 2023: a rigid joint L long fits the tube bent to R
  only if L ≤ 2·√(2(D − d)(R + d/2)) (`ballcage.sizing.longest_link`), or
- the hinge's articulation limit β_max (`ballcage.Scene.articulation_limit_deg`):
  placed on the arc each hinge bends 2·asin(L / 2R), so R ≥ L / (2·sin(β_max / 2))
  (`ballcage.sizing.tightest_radius_for_bend`).

A refused cell is infeasible; its reason names the constraints it breaks
(both may; the validator reports eq. (9) first) or, for any other refusal,
the validator's message. The feasible cells run as one sweep
(`ballcage.studies.sweep_run.sweep`: local threads or Dask; running the same
chart into the same folder resumes) with the hinge model, D, d, the duration
and the summary window fixed. With ``verify`` (the default) each feasible
cell runs a second time at ``ballcage run --verify``'s tighter setting
(`ballcage.studies.refinement.tighter`: ``rtol/10`` for the adaptive
default), as a case of the same sweep, and each quantity's numerical error
in that cell is |value − the value at the tighter setting|, in the
quantity's unit (``<quantity>_error``). Written into ``out``::

    design_chart.parquet   one row per cell: R, L, feasible, reason, the link's mass, the quantities and their
                           numerical errors
    design_chart.png       heat maps over R × L (`ballcage.studies.design_chart_plot`)
    summary.parquet, <table>/case=NNNN/part.parquet, cases/   the sweep's own files (docs/studies.md)

**Link mass and inertia scale with L** (``scale_mass=True``, the default;
`ReferenceLink.scaled`), from the base scene's link (the paper's: L₀ = 0.2 m,
m₀ = 8.01 kg, I = [0.008306, 0.03085, 0.03085] kg·m², r₀ = 0.043 m): the
mass m = m₀·L/L₀ (a link of the same cross-section), the axial inertia
I_a = I_a0·m/m₀ (the same radial distribution), each transverse inertia as a
solid cylinder's, m(3r₀² + L²)/12, scaled so that L = L₀ gives I_t0 exactly:
I_t = I_t0·m(3r₀² + L²) / (m₀(3r₀² + L₀²)). The joint diameter d enters the
fit and the tube contact, not the mass. With ``scale_mass=False`` every cell
keeps the base scene's mass and inertia.

Everything here is SI: metres, seconds, kilograms, newtons.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pyarrow as pa

from ballcage import _native, sizing
from ballcage._files import write_parquet, write_png
from ballcage.measures.quantities import QUANTITIES
from ballcage.studies.design_chart_grid import (
    LENGTH,
    MASS,
    RADIUS,
    Cell,
    ChartError,
    ReferenceLink,
    Setup,
    chart_cells,
    chart_setup,
    chart_spec,
)
from ballcage.studies.refinement import cost_factor
from ballcage.studies.sweep_quantities import DRILL_PIPE_LIVES, LIVES, LIVES_SECONDS_PER_SIMULATED_SECOND
from ballcage.studies.sweep_run import SweepResult, largest_errors, pending_cases, sweep
from ballcage.studies.sweep_spec import with_verification
from ballcage.studies.sweep_summary import COST_COLUMNS

__all__ = [
    "DEFAULT_DURATION",
    "DEFAULT_LENGTHS",
    "DEFAULT_RADII",
    "ChartError",
    "DesignChart",
    "ReferenceLink",
    "chart_table",
    "describe",
    "design_chart",
]

#: Curvature radii [m] of the default chart.
DEFAULT_RADII: tuple[float, ...] = (1.0, 1.5, 2.0, 3.0, 4.0)
#: Joint lengths [m] of the default chart: for the paper's tube and joint the articulation limit cuts
#: below L = 0.935 m (R = 3.60 m), eq. (9) above (it alone excludes R = 4 m, L = 1 m).
DEFAULT_LENGTHS: tuple[float, ...] = (0.15, 0.2, 0.3, 0.4, 0.5, 1.0)
#: Simulated duration [s] of every cell (the paper's 1.8 s: three revolutions at 100 rpm).
DEFAULT_DURATION = 1.8
#: Wall seconds per simulated second of one case on one core of this project's 2-core AMD EPYC
#: (2026-11-26, the adaptive default at rtol 1e-4, two cases at a time: the default chart's 20 cells,
#: mean 3.6 s per 1.8 s cell, 38 s in all; ideal CV 11 s; docs/studies.md), for the estimate printed
#: before a chart or a study runs.
SECONDS_PER_SIMULATED_SECOND: dict[str, float] = {"ball-keys": 2.1, "ideal-cv": 0.6}
#: The quantities the chart table copies from the sweep's summary, in order.
QUANTITY_COLUMNS: tuple[str, ...] = (
    "key_peak_n",
    "tube_normal_mean_max_n",
    "tube_normal_mean_all_n",
    "tube_normal_peak_max_n",
    "efficiency",
    "fatigue_life_min_h",
    "wear_hours_min_h",
    "wall_time_s",
    "case_wall_time_s",
)
#: The quantities whose numerical error the chart measures (``<name>_error``); the run times have none.
CHECKED_COLUMNS: tuple[str, ...] = QUANTITY_COLUMNS[:-2]


@dataclass
class DesignChart:
    """What `design_chart` did: the chart table (one row per cell), the folder, the files, the sweep's result."""

    table: pa.Table
    out: Path
    paths: dict[str, Path]
    sweep: SweepResult | None
    estimate_s: float | None  # the run time estimated before the sweep started [s]; None when nothing ran
    elapsed_s: float  # wall time of the whole chart [s]
    verification: str = ""  # the verification runs' setting (``rtol/10``); empty without them

    @property
    def feasible(self) -> int:
        return sum(1 for v in self.table.column("feasible").to_pylist() if v)

    @property
    def failed(self) -> int:
        return self.sweep.failed if self.sweep is not None else 0


def design_chart(
    out: str | os.PathLike[str],
    *,
    radii: Sequence[float] = DEFAULT_RADII,
    lengths: Sequence[float] = DEFAULT_LENGTHS,
    tube_inner_diameter: float | None = None,
    joint_diameter: float | None = None,
    hinge: str = "ball-keys",
    duration: float = DEFAULT_DURATION,
    window: tuple[float, float] | None = None,
    scale_mass: bool = True,
    overrides: Sequence[str] = (),
    workers: int | None = None,
    client: Any = None,
    progress: bool | None = None,
    verify: bool = True,
) -> DesignChart:
    """Maps the forces of the paper's drill pipe over curvature radius × joint length into the folder `out`.

    `radii` and `lengths` [m] span the grid (R on x, L = ``pipe.pitch`` on y);
    `tube_inner_diameter` D and `joint_diameter` d [m] default to the base
    scene's (the paper's 0.116 and 0.086 m); `hinge` is ``"ball-keys"`` (the
    paper's model) or ``"ideal-cv"``; `duration` [s] is simulated per cell and
    the tube forces are averaged over `window` [s] (default the second half of
    the run); `overrides` (``"key=value"``) change the embedded paper scene
    except the keys the chart sets. `scale_mass`: see the module docstring.
    `workers`, `client`, `progress`: as for `ballcage.studies.sweep_run.sweep`.
    `verify`: run each feasible cell again at the tighter setting for its
    numerical error (see the module docstring). Writes ``design_chart.parquet`` and ``design_chart.png``; raises `ChartError`
    (a `SweepError`) for bad input, before anything runs.
    """
    start = time.perf_counter()
    setup = chart_setup(radii, lengths, tube_inner_diameter, joint_diameter, hinge, duration, window, scale_mass, overrides)
    folder = Path(out)
    if folder.exists() and not folder.is_dir():
        raise ChartError(f"out = {str(folder)!r}: exists and is not a directory")
    cells = chart_cells(setup, [float(r) for r in radii], [float(v) for v in lengths])
    feasible = [c for c in cells if c.feasible]
    say = (lambda text: print(f"ballcage: {text}", file=sys.stderr, flush=True)) if progress is not False else None
    result, estimate, verification = None, None, ""
    if feasible:
        plain = chart_spec(setup, [c.values for c in feasible])
        spec = with_verification(plain) if verify else plain
        verification = spec.verification
        pending = pending_cases(plain, folder)
        checks = pending_cases(spec, folder) - pending
        estimate = _estimate(pending + _check_cost(verification) * checks, setup, workers, client)
        if say:
            say(_plan(cells, (pending, checks), estimate, setup, verification))
        result = sweep(spec, folder, client=client, workers=workers, plots=False, progress=progress,
                       quantities=DRILL_PIPE_LIVES)  # fmt: skip
    elif say:
        say(_plan(cells, (0, 0), None, setup, ""))
    folder.mkdir(parents=True, exist_ok=True)
    table = chart_table(cells, result.summary if result is not None else None, setup, verification)
    paths = _write(table, folder)
    return DesignChart(table, folder, paths, result, estimate, time.perf_counter() - start, verification)


def _check_cost(verification: str) -> float:
    """How many cells a verification run costs (`cost_factor`); 0 without verification runs."""
    return cost_factor(verification) if verification else 0.0


def _estimate(pending: float, setup: Setup, workers: int | None, client: Any) -> float:
    """Seconds the pending cases should take: rounds of `workers` cases at the measured cost per simulated second;
    `pending` counts a verification run as the cases it costs (`cost_factor`)."""
    if client is not None:
        info: dict[str, Any] = client.scheduler_info() if hasattr(client, "scheduler_info") else {}
        parallel = max(1, len(info.get("workers", {})))
    else:
        parallel = workers or os.cpu_count() or 1
    per_case = _rate(setup) * setup.fixed["simulation.duration"]
    return math.ceil(pending / max(1, min(parallel, pending or 1))) * per_case


def _rate(setup: Setup) -> float:
    """Seconds of one core per simulated second of a cell: its run and its lives."""
    hinge = str(setup.fixed["pipe.hinge"])
    return SECONDS_PER_SIMULATED_SECOND.get(hinge, 10.0) + LIVES_SECONDS_PER_SIMULATED_SECOND.get(hinge, 1.0)


def _plan(cells: list[Cell], pending: tuple[int, int], estimate: float | None, setup: Setup, verification: str) -> str:
    """The line printed before the chart runs: cells, why some are excluded, the estimate; `pending`: the cells and
    the verification runs still to run."""
    excluded: dict[str, int] = {}
    for c in cells:
        if not c.feasible:
            excluded[c.reason or ""] = excluded.get(c.reason or "", 0) + 1
    why = "; ".join(f"{n} by {r}" for r, n in excluded.items()) or "none"
    feasible = sum(c.feasible for c in cells)
    line = f"design chart: {len(cells)} cells, {feasible} feasible, {len(cells) - feasible} excluded ({why})"
    if estimate is None:
        return line + "; nothing to run"
    cells_left, checks_left = pending
    verified = (
        f", each also at {verification} for its numerical error ({checks_left} of those to run, each costing "
        f"~{_check_cost(verification):.2g} cells)"
        if verification
        else ", not verified (no numerical error)"
    )
    return (
        f"{line}; {cells_left} to run, {feasible - cells_left} already finished{verified}: about {_duration(estimate)} "
        f"({setup.fixed['pipe.hinge']}, {setup.fixed['simulation.duration']:g} s each at ~{_rate(setup):g} s per "
        "simulated s on one core of a 2-core AMD EPYC, the lives included; a rough guide, cells differ by up to 5x)"
    )


def _duration(seconds: float) -> str:
    return f"{seconds:.0f} s" if seconds < 120 else f"{int(seconds // 60)} min {seconds % 60:.0f} s"


def chart_table(cells: Sequence[Cell], summary: pa.Table | None, setup: Setup, verification: str = "") -> pa.Table:
    """One row per cell (L slowest, then R): geometry, feasibility, the link, the case, its quantities and, when the
    sweep verified its cases (`with_verification`, at the setting `verification`), their numerical errors.

    Units and descriptions in each field's metadata (and as JSON in the file's), like ``summary.parquet``.
    """
    rows = {r["case"]: r for r in summary.to_pylist()} if summary is not None else {}
    feasible = sum(c.feasible for c in cells)
    records, index = [], 0
    for cell in cells:
        row = None
        if cell.feasible:  # the sweep's cases are the feasible cells, in order, then their verification runs
            row, index = rows.get(index), index + 1
        records.append(_row(cell, row, setup))
    if rows and len(rows) != feasible * (2 if verification else 1):
        raise AssertionError("the sweep's cases are not the chart's feasible cells (and their verification runs)")
    columns = _columns()
    fields = [pa.field(n, t, metadata={"unit": u, "description": d}) for n, (t, u, d) in columns.items()]
    arrays = [pa.array([r[n] for r in records], type=t) for n, (t, _, _) in columns.items()]
    schema = pa.schema(fields).with_metadata(_file_metadata(fields, setup, verification))
    return pa.Table.from_arrays(arrays, schema=schema)


def _row(cell: Cell, case: Mapping[str, Any] | None, setup: Setup) -> dict[str, Any]:
    mass, inertia = setup.link.scaled(cell.length) if setup.scale_mass else (setup.link.mass, list(setup.link.inertia))
    ratio = cell.length / (2 * cell.radius)
    fits = cell.radius >= setup.tube / 2
    row: dict[str, Any] = {
        RADIUS: cell.radius,
        LENGTH: cell.length,
        "feasible": cell.feasible,
        "reason": cell.reason,
        "refusal": cell.refusal,
        "excluded_by_eq9": "eq9" in cell.broken,
        "excluded_by_articulation": "articulation" in cell.broken,
        "hinge_bend_deg": math.degrees(2 * math.asin(ratio)) if ratio <= 1 else None,
        "longest_joint_m": sizing.longest_link(cell.radius, setup.tube, setup.joint) if fits else None,
        "tightest_radius_for_bend_m": (
            sizing.tightest_radius_for_bend(cell.length, setup.limit_deg) if setup.limit_deg else None
        ),
        MASS: mass,
        "link_inertia_axial": inertia[0],
        "link_inertia_transverse": inertia[1],
        "case": None if case is None else case["case"],
        "case_id": None if case is None else case["case_id"],
        "status": None if case is None else case["status"],
    }
    for name in QUANTITY_COLUMNS:
        row[name] = None if case is None else case.get(name)
    for name in CHECKED_COLUMNS:  # the summary's, when the sweep verified its cases
        row[name + "_error"] = None if case is None else case.get(name + "_error")
    return row


def _columns() -> dict[str, tuple[pa.DataType, str, str]]:
    f64, text, flag = pa.float64(), pa.string(), pa.bool_()
    columns: dict[str, tuple[pa.DataType, str, str]] = {
        RADIUS: (f64, "m", "curvature radius R of the tube's centreline (x of the chart)"),
        LENGTH: (f64, "m", "joint length L, the hinge pitch (y of the chart)"),
        "feasible": (flag, "", "the scene validator accepts the cell (eq. (9) and the articulation limit hold)"),
        "reason": (text, "", "why not: eq. (9), articulation limit, both, or the validator's message; null when feasible"),
        "refusal": (text, "", "the scene validator's message for an infeasible cell; null when feasible"),
        "excluded_by_eq9": (flag, "", "L > eq. (9)'s longest joint 2*sqrt(2(D - d)(R + d/2)), or R < D/2"),
        "excluded_by_articulation": (flag, "", "R < L / (2 sin(beta_max / 2)): a placed hinge bends past its limit"),
        "hinge_bend_deg": (f64, "deg", "bend of a hinge placed on the arc, 2 asin(L / 2R); null when L > 2R"),
        "longest_joint_m": (f64, "m", "eq. (9): the longest joint that fits the tube at this R; null when R < D/2"),
        "tightest_radius_for_bend_m": (f64, "m", "the tightest R the articulation limit allows at this L; null without one"),
        MASS: (f64, "kg", "mass of each link (scaled with L unless scale_mass is off)"),
        "link_inertia_axial": (f64, "kg m^2", "axial moment of inertia of each link"),
        "link_inertia_transverse": (f64, "kg m^2", "transverse moment of inertia of each link"),
        "case": (pa.int32(), "", "the sweep case of the cell (partition case=NNNN); null when infeasible"),
        "case_id": (text, "", "the sweep case's id; null when infeasible"),
        "status": (text, "", "ok, diverged or error (summary.parquet); null when infeasible"),
    }
    units = {name: (unit, description) for name, _, unit, description in COST_COLUMNS}
    units.update(QUANTITIES)
    units.update(LIVES)
    for name in QUANTITY_COLUMNS:
        unit, description = units[name]
        columns[name] = (f64, unit, description + " (null when infeasible or not computed)")
    for name in CHECKED_COLUMNS:
        columns[name + "_error"] = (
            f64, units[name][0],
            f"numerical error of {name}: |value - the cell's value at the tighter setting of ballcage run --verify| "
            "(ballcage.chart_verification; null when not verified, or either run did not finish)",
        )
    return columns


def _file_metadata(fields: list[pa.Field], setup: Setup, verification: str) -> dict[str, str]:
    window = setup.fixed["record.summary_window"]
    return {
        "ballcage.chart_verification": verification,
        "ballcage.version": _native.__version__,
        "ballcage.chart_hinge": str(setup.fixed["pipe.hinge"]),
        "ballcage.chart_tube_inner_diameter_m": repr(setup.tube),
        "ballcage.chart_joint_diameter_m": repr(setup.joint),
        "ballcage.chart_duration_s": repr(setup.fixed["simulation.duration"]),
        "ballcage.chart_summary_window_s": json.dumps(window),
        "ballcage.chart_articulation_limit_deg": json.dumps(setup.limit_deg),
        "ballcage.chart_joints": str(setup.joints),
        "ballcage.chart_mass_scaling": json.dumps(
            {"on": setup.scale_mass, "reference_length_m": setup.link.length, "reference_mass_kg": setup.link.mass,
             "reference_inertia_kg_m2": list(setup.link.inertia), "reference_radius_m": setup.link.radius}
        ),
        "ballcage.chart_overrides": json.dumps(list(setup.overrides)),
        "ballcage.units": json.dumps({f.name: f.metadata[b"unit"].decode() for f in fields}),
        "ballcage.descriptions": json.dumps({f.name: f.metadata[b"description"].decode() for f in fields}),
    }


def _write(table: pa.Table, out: Path) -> dict[str, Path]:
    from ballcage.studies.design_chart_plot import chart_figure  # deferred: matplotlib

    return {
        "table": write_parquet(table, out / "design_chart.parquet"),
        "figure": write_png(chart_figure(table), out / "design_chart.png"),
    }


def describe(chart: DesignChart) -> Iterable[str]:
    """Lines the CLI prints after a chart: the files, the cells, the run time against the estimate."""
    cells = chart.table.num_rows
    yield f"wrote {chart.paths['figure']}  (design chart)"
    yield f"wrote {chart.paths['table']}  ({cells} cells, {chart.feasible} feasible)"
    if chart.sweep is not None:
        yield f"wrote {chart.sweep.paths['summary']}  (the sweep of the feasible cells, {chart.sweep.summary.num_rows} cases)"
        guess = f", estimated {_duration(chart.estimate_s)}" if chart.estimate_s is not None else ""
        yield (
            f"ballcage: {chart.sweep.ran} cases run, {chart.sweep.skipped} skipped (already finished), "
            f"{chart.failed} not ok; {_duration(chart.elapsed_s)} in all{guess}"
        )
        yield _error_line(chart)


def _error_line(chart: DesignChart) -> str:
    """The largest numerical error of each force panel's quantity over the cells, relative to the cell's value (or
    absolute [N] where every value is 0), or why there is none."""
    if not chart.verification:
        return "ballcage: numerical error not measured (--no-verify)"
    from ballcage.studies.design_chart_plot import PANELS

    rows, parts = chart.table.to_pylist(), []
    worst = {name: (rel, row) for name, rel, row in largest_errors(chart.table, [n for n, _ in PANELS])}
    for name, _ in PANELS:
        if name in worst:
            rel, row = worst[name]
            parts.append(f"{name} {100 * rel:.2g} % (R {row[RADIUS]:g} m, L {row[LENGTH]:g} m)")
        elif known := [r[name + "_error"] for r in rows if r[name + "_error"] is not None]:
            parts.append(f"{name} {max(known):.3g} N (every value 0)")
    head = f"ballcage: largest numerical error (each cell against its run at {chart.verification})"
    return f"{head}: " + "; ".join(parts) if parts else f"{head}: no cell finished both runs"
