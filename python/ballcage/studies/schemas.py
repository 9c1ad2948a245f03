"""The layouts of the study tables: `ACCURACY_SCHEMA` (one row per run and quantity),
`STABILITY_SCHEMA` (one row per integrator and parameter value) and `SENSITIVITY_SCHEMA` (one row per
quantity and parameter); every field carries ``unit`` and ``description`` metadata.
"""

from __future__ import annotations

import pyarrow as pa

__all__ = ["ACCURACY_SCHEMA", "SENSITIVITY_SCHEMA", "STABILITY_SCHEMA"]

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


def _sensitivity_field(name: str, kind: pa.DataType, unit: str, description: str) -> pa.Field:
    return pa.field(name, kind, metadata={"unit": unit, "description": description})


#: ``sensitivity.parquet`` (`ballcage.studies.sensitivity_run`): one row per quantity and parameter.
SENSITIVITY_SCHEMA = pa.schema(
    [
        _sensitivity_field("method", pa.string(), "", "oat: one parameter at a time at its low and its high value; "
                           "morris: Morris elementary effects (SALib) over every parameter's range"),
        _sensitivity_field("parameter", pa.string(), "", "the varied scene key, as --set takes it"),
        _sensitivity_field("parameter_unit", pa.string(), "", "unit of parameter_base, parameter_low, parameter_high"),
        _sensitivity_field("parameter_base", pa.float64(), "see parameter_unit", "the parameter's value in the base run"),
        _sensitivity_field("parameter_low", pa.float64(), "see parameter_unit", "low end of the parameter's range"),
        _sensitivity_field("parameter_high", pa.float64(), "see parameter_unit", "high end of the parameter's range"),
        _sensitivity_field("quantity", pa.string(), "", "the quantity: a drill pipe's comparison quantity (as in a "
                           "sweep's summary.parquet) or pressure_margin_min; a generic scene's "
                           "<column of the summary table>[<contact pair>]"),
        _sensitivity_field("unit", pa.string(), "", "unit of the quantity and of every column marked 'see unit'"),
        _sensitivity_field("base", pa.float64(), "see unit", "the quantity in the base run (every parameter at its base)"),
        _sensitivity_field("value_low", pa.float64(), "see unit", "oat: the quantity with the parameter at its low "
                           "value; null for morris or when that run has no value"),
        _sensitivity_field("value_high", pa.float64(), "see unit", "oat: the quantity with the parameter at its high "
                           "value; null for morris or when that run has no value"),
        _sensitivity_field("change_low_pct", pa.float64(), "%", "100 (value_low - base) / |base|; null when base is 0 "
                           "(and value_low is not) or the quantity has no unit (a part number)"),
        _sensitivity_field("change_high_pct", pa.float64(), "%", "100 (value_high - base) / |base|; null as "
                           "change_low_pct"),
        _sensitivity_field("mu_star", pa.float64(), "see unit", "morris: mean absolute elementary effect (SALib), the "
                           "change of the quantity per the parameter's whole range; null for oat"),
        _sensitivity_field("mu", pa.float64(), "see unit", "morris: mean signed elementary effect; null for oat"),
        _sensitivity_field("sigma", pa.float64(), "see unit", "morris: standard deviation of the elementary effects "
                           "(interactions, non-linearity); null for oat"),
        _sensitivity_field("mu_star_conf", pa.float64(), "see unit", "morris: half-width of the 95 % bootstrap "
                           "confidence interval of mu_star; null for oat"),
        _sensitivity_field("effect", pa.float64(), "see unit", "what the parameters are ranked by: oat max(|value_low - "
                           "base|, |value_high - base|); morris mu_star"),
        _sensitivity_field("rank", pa.int32(), "", "1 for the parameter with the largest effect on the quantity; "
                           "null for an effect of 0 or none"),
        _sensitivity_field("numerical_error", pa.float64(), "see unit", "the base run's numerical error on the scale "
                           "of effect (oat: the error of one run; morris: 2 error / delta, what the error alone can give "
                           "an elementary effect); null without a usable estimate"),
        _sensitivity_field("numerical_error_source", pa.string(), "", "where numerical_error comes from, or why "
                           "there is none"),
        _sensitivity_field("below_error", pa.bool_(), "", "effect <= numerical_error: the parameter's effect is not "
                           "resolved by the run; null without an estimate"),
        _sensitivity_field("range_min", pa.float64(), "see unit", "smallest value of the quantity over every run of "
                           "the study (base, oat or morris runs; not the verification run)"),
        _sensitivity_field("range_max", pa.float64(), "see unit", "largest value of the quantity over every run of "
                           "the study"),
        _sensitivity_field("runs", pa.int32(), "", "runs range_min and range_max are taken over (those with a value)"),
        _sensitivity_field("note", pa.string(), "", "runs that did not finish or gave no value; null when none"),
    ]
)  # fmt: skip
