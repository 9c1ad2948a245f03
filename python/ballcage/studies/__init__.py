"""Integrator studies: error against cost (`accuracy`) and the largest stable step (`stability`).

`accuracy(scene)` runs a scene with each integrator over a ladder of steps
and compares named scalar quantities with a reference: the same scene at a
much smaller step ``dt_ref`` with the most accurate integrator. The reference
is shown to be converged by running it again at ``2·dt_ref``: the relative
difference of the two is its own error estimate (``reference_error``; for a
method of order p it over-estimates the reference's error by 2^p − 1). One
row per run and quantity goes into a `pyarrow.Table` (`ACCURACY_SCHEMA`);
`write_accuracy` writes it as ``work_precision.parquet`` with a log-log
work-precision plot and a Markdown table (``ballcage accuracy``).

Quantities (`quantities`), each a scalar per run:

- drill-pipe scenes: ``key_seat_normal_peak`` (largest keys.outer_normal,
  seat race, both flanks of one key summed, over all keys and frames [N]),
  ``tube_mean_force_joint_NN`` (time mean of links.tube_normal of link NN
  over the summary window, from links.tube_normal_impulse [N]),
  ``final_bend_deg_link_NN`` (180° − links.included_angle_deg of link NN at
  the last frame [deg]);
- generic scenes: ``peak_normal_force_<pair>`` (summary.normal_peak [N]),
  ``final_position_<body>``, ``final_velocity_<body>`` and
  ``final_angular_velocity_<body>`` of every integrated body (the value is
  the vector's norm; the error the largest component difference);
- both: ``final_total_energy`` and ``final_kinetic_energy`` [J];
- ``max_over_quantities``: the largest error of the run.

Relative error: ``|q − q_ref| / max(|q_ref|, floor)``, the floor per kind of
quantity in `FLOORS` (1 N, 0.1°, 1 mm, 1 mm/s, 1e-3 rad/s, 1 mJ), so that a
quantity that is nearly zero in the reference is judged against a stated
absolute scale instead of a tiny denominator.

Every run of a study records at one output interval (the scene's, or a
multiple of it covering the largest step) and each step is snapped to a whole
fraction of it, so peaks are taken over the same frames; the duration is
snapped to a whole number of output intervals. The ``dt`` column holds the
step actually used.

`stability()` finds, for each integrator, the largest step at which a short
probe run finishes without a `ballcage.SimulationError` (bisection in log dt
between a stable and an unstable step), against one scene parameter at a time
(`Parameter`; for the drill pipe `drill_pipe_parameters`: contact stiffness,
drive speed, curvature radius down to the tightest the hinge allows, key mass,
contact damping) and optionally on a stiffness × speed grid; `write_stability`
writes ``stability.parquet`` and heat maps (``ballcage stability``).

Modules, one job each: `common` (integrators, scene overrides, progress),
`scalars` (the compared quantities), `ladders` (steps and the output grid),
`schemas` (the two table layouts), `accuracy_run` and `accuracy_report`
(running the work-precision study; its files), `stability_parameters` (what is
varied), `stability_search` (the stable-step search), `stability_run` and
`stability_report` (running the stability study; its files); the sweeps
(``ballcage sweep``, docs/studies.md): `sweep_spec` (the sweep file and its
cases), `sweep_case` (one case on a worker: run, files, record),
`sweep_quantities` (the plug-in a sweep computes each case's quantities with,
`sweep_quantities.SweepQuantities`; the drill pipe's is
`ballcage.measures.DRILL_PIPE`), `sweep_summary` (``summary.parquet``),
`sweep_plots` and `sweep_run` (`sweep`: local threads or Dask, resume,
progress); the design chart (``ballcage chart``): `design_chart_grid` (the
cells and their feasibility), `design_chart` (the sweep of the feasible ones,
``design_chart.parquet``) and `design_chart_plot` (its figure); the sensitivity
study (``ballcage sensitivity``): `sensitivity_parameters` (the ranges: the registry
of unstated parameters or given), `sensitivity_quantities` (what each run measures),
`sensitivity_run` (`sensitivity`: the runs as one sweep, the table),
`sensitivity_report` (``sensitivity.md``; a table read back as spreads) and
`sensitivity_plot` (the tornado charts); `refinement` (the tighter setting of a
verification run, shared with ``ballcage run --verify``).
"""

from ballcage.studies.accuracy_report import accuracy_markdown, write_accuracy
from ballcage.studies.accuracy_run import accuracy
from ballcage.studies.common import StudyError, available_integrators
from ballcage.studies.design_chart import DesignChart, design_chart
from ballcage.studies.ladders import default_steps
from ballcage.studies.scalars import FLOORS, MAX_QUANTITY, Quantity, quantities
from ballcage.studies.schemas import ACCURACY_SCHEMA, SENSITIVITY_SCHEMA, STABILITY_SCHEMA
from ballcage.studies.sensitivity_run import Sensitivity, sensitivity
from ballcage.studies.stability_parameters import (
    PARAMETER_NAMES,
    Parameter,
    drill_pipe_parameters,
    probe_scene,
    tightest_radius,
)
from ballcage.studies.stability_report import stability_markdown, write_stability
from ballcage.studies.stability_run import stability
from ballcage.studies.sweep_run import SweepResult, sweep
from ballcage.studies.sweep_spec import SweepError, SweepSpec, load_sweep

__all__ = [
    "ACCURACY_SCHEMA",
    "DesignChart",
    "FLOORS",
    "MAX_QUANTITY",
    "PARAMETER_NAMES",
    "SENSITIVITY_SCHEMA",
    "STABILITY_SCHEMA",
    "Parameter",
    "Quantity",
    "Sensitivity",
    "StudyError",
    "SweepError",
    "SweepResult",
    "SweepSpec",
    "accuracy",
    "accuracy_markdown",
    "available_integrators",
    "load_sweep",
    "default_steps",
    "design_chart",
    "drill_pipe_parameters",
    "probe_scene",
    "quantities",
    "sensitivity",
    "stability",
    "stability_markdown",
    "sweep",
    "tightest_radius",
    "write_accuracy",
    "write_stability",
]
