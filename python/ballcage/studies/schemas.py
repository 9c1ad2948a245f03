"""The layouts of the two study tables: `ACCURACY_SCHEMA` (one row per run and quantity) and
`STABILITY_SCHEMA` (one row per integrator and parameter value); every field carries ``unit`` and
``description`` metadata.
"""

from __future__ import annotations

import pyarrow as pa

__all__ = ["ACCURACY_SCHEMA", "STABILITY_SCHEMA"]

ACCURACY_SCHEMA = pa.schema(
    [
        pa.field("integrator", pa.string(), nullable=False, metadata={"unit": "", "description": "integrator name"}),
        pa.field(
            "dt",
            pa.float64(),
            nullable=False,
            metadata={"unit": "s", "description": "integrator step used (snapped to a whole fraction of the output interval)"},
        ),
        pa.field(
            "role",
            pa.string(),
            nullable=False,
            metadata={
                "unit": "",
                "description": "run: a ladder run; reference: the reference at dt_ref; reference-check: the reference integrator at 2 dt_ref; second-method: ESDIRK3(2) at rtol 1e-5, adaptive steps up to the output interval",
            },
        ),
        pa.field("quantity", pa.string(), nullable=False, metadata={"unit": "", "description": "quantity name"}),
        pa.field("unit", pa.string(), metadata={"unit": "", "description": "unit of value, reference and floor"}),
        pa.field("value", pa.float64(), metadata={"unit": "see unit", "description": "this run's value (vector norm for vector quantities); null when diverged"}),
        pa.field("reference", pa.float64(), metadata={"unit": "see unit", "description": "the reference's value"}),
        pa.field("floor", pa.float64(), metadata={"unit": "see unit", "description": "floor of the error's denominator"}),
        pa.field(
            "error",
            pa.float64(),
            metadata={
                "unit": "1",
                "description": "|value - reference| / max(|reference|, floor); largest component difference for vectors; inf when diverged",
            },
        ),
        pa.field(
            "reference_error",
            pa.float64(),
            metadata={
                "unit": "1",
                "description": "the reference's own error estimate: |q(dt_ref) - q(2 dt_ref)| / max(|q(dt_ref)|, floor)",
            },
        ),
        pa.field("wall_s", pa.float64(), metadata={"unit": "s", "description": "wall time of the run (ballcage.wall_time_s)"}),
        pa.field("steps", pa.int64(), metadata={"unit": "", "description": "integrator steps taken (ballcage.steps)"}),
        pa.field("force_evaluations", pa.int64(), metadata={"unit": "", "description": "ballcage.force_evaluations"}),
        pa.field("linear_solves", pa.int64(), metadata={"unit": "", "description": "ballcage.linear_solves; null if the engine does not report it"}),
        pa.field("factorizations", pa.int64(), metadata={"unit": "", "description": "ballcage.factorizations; null if the engine does not report it"}),
        pa.field("newton_iterations", pa.int64(), metadata={"unit": "", "description": "ballcage.newton_iterations; null if the engine does not report it"}),
        pa.field("diverged", pa.bool_(), nullable=False, metadata={"unit": "", "description": "the run raised SimulationError"}),
        pa.field("message", pa.string(), metadata={"unit": "", "description": "the divergence message, null otherwise"}),
    ]
)

STABILITY_SCHEMA = pa.schema(
    [
        pa.field("integrator", pa.string(), nullable=False, metadata={"unit": "", "description": "integrator name"}),
        pa.field("parameter", pa.string(), nullable=False, metadata={"unit": "", "description": "varied parameter"}),
        pa.field("value", pa.float64(), nullable=False, metadata={"unit": "see unit", "description": "parameter value"}),
        pa.field("unit", pa.string(), metadata={"unit": "", "description": "unit of value"}),
        pa.field("parameter2", pa.string(), metadata={"unit": "", "description": "second parameter of a grid row, else null"}),
        pa.field("value2", pa.float64(), metadata={"unit": "see unit2", "description": "second parameter's value, else null"}),
        pa.field("unit2", pa.string(), metadata={"unit": "", "description": "unit of value2"}),
        pa.field(
            "max_stable_dt_s",
            pa.float64(),
            metadata={"unit": "s", "description": "largest step probed that finished without a divergence error; NaN if none did"},
        ),
        pa.field(
            "min_unstable_dt_s",
            pa.float64(),
            metadata={"unit": "s", "description": "smallest step probed that diverged; NaN if none did (stable up to the largest step probed)"},
        ),
        pa.field("probes", pa.int64(), nullable=False, metadata={"unit": "", "description": "probe runs of the search"}),
        pa.field("wall_s", pa.float64(), metadata={"unit": "s", "description": "wall time of the probes"}),
        pa.field("message", pa.string(), metadata={"unit": "", "description": "the divergence at the bracket's unstable end, or why there is no bracket"}),
    ]
)
