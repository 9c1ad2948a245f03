"""`simulation.threads`: the contact pairs of a force evaluation on several threads give
bitwise the same tables as one thread (the Rust test `tests/threads.rs` covers the paper scene)."""

from __future__ import annotations

import ballcage


def _run(threads: int) -> ballcage.Run:
    # Eight balls dropped onto a plane, each its own contact pair, with friction and
    # sideways velocities so that every pair carries normal and tangential force.
    b = ballcage.SceneBuilder("eight balls").simulation(
        duration=0.05, dt=1e-5, output_interval=1e-3, integrator="sdirk2", threads=threads
    )
    b.gravity([0.0, 0.0, -9.81])
    b.record(tables=["bodies", "contacts"])
    b.body("ground", shape={"type": "half-space", "normal": [0.0, 0.0, 1.0]}, motion="fixed")
    for i in range(8):
        b.body(
            f"ball{i}",
            shape={"type": "ball", "radius": 0.01},
            density=7850.0,
            position=[0.03 * i, 0.0, 0.0099 - 1e-5 * i],
            velocity=[0.1 * i, 0.05, -0.01 * i],
        )
        b.contact(
            "ground",
            f"ball{i}",
            normal={"law": "impact", "stiffness": 1e9, "exponent": 1.5, "damping": 10.0, "depth_max": 1e-4},
            friction={"law": "tanh", "mu": 0.3, "v_ref": 1e-3},
        )
    return ballcage.simulate(b)


def test_two_threads_write_the_single_threaded_tables_bit_for_bit():
    one, two = _run(1), _run(2)
    assert one.metadata["ballcage.scene"] != two.metadata["ballcage.scene"]  # threads differ
    for name in ("bodies", "contacts"):
        a, b = one.tables[name], two.tables[name]
        assert a.num_rows > 0
        # Table.equals compares the values exactly (no tolerance).
        assert a.equals(b), name
    # The run did something: the balls slid and carried load.
    contacts = one.contacts
    assert max(abs(f) for f in contacts["normal_force"].to_pylist()) > 1.0
