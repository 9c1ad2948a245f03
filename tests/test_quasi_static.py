"""The quasi-static ball-key hinge (issue 28, `pipe.hinge = "ball-keys-qs"`) through the Python API.

Its physics (the loaded hinge against the hand statics and the dynamic keys, its Jacobian against finite differences)
is checked in the engine's tests (crates/ballcage-core/tests/hinge_closed_forms.rs); here, that a drill-pipe run with
it records what the ball-key outputs read, and counts its solves.
"""

from __future__ import annotations

import pyarrow.compute as pc

import ballcage


def test_a_quasi_static_hinge_run_records_its_keys_and_counts_its_solves() -> None:
    run = ballcage.simulate(
        {"kind": "drill-pipe"},
        overrides=['pipe.hinge="ball-keys-qs"', "simulation.duration=0.01"],
        progress=False,
    )
    assert run.complete and run.has_ball_keys
    meta = run.metadata
    # 13 hinges, each solved at every force evaluation and once per step.
    assert int(meta["ballcage.static_solves"]) >= 13 * int(meta["ballcage.force_evaluations"])
    assert int(meta["ballcage.static_failures"]) == 0
    assert int(meta["ballcage.static_iterations"]) > 0
    keys = run.tables["keys"]
    assert keys.num_rows > 0
    # The drive's torque reaches the keys: their race forces are not all zero.
    assert pc.max(keys.column("inner_normal")).as_py() > 0.0
    ideal = ballcage.simulate(
        {"kind": "drill-pipe"}, overrides=['pipe.hinge="ideal-cv"', "simulation.duration=0.002"], progress=False
    )
    assert not ideal.has_ball_keys
    assert "ballcage.static_solves" not in ideal.metadata
