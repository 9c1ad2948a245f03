"""End-to-end contact checks against closed forms (the Rust tests own the detailed physics)."""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pytest

import ballcage

M, G, K, R = 1.0, 9.81, 1e8, 0.05  # examples/scenes/ball_drop.toml


def test_dropped_ball_settles_at_the_hertz_rest_depth(ball_drop_path):
    # The example's elastic Hertz law would bounce forever; Hunt–Crossley with
    # restitution 0.3 has the same spring (K δ^1.5) and damping that vanishes
    # at rest, so the ball settles where K δ^1.5 = m g.
    run = ballcage.simulate(
        ball_drop_path,
        overrides=[
            'contacts.0.normal={law = "hunt-crossley", stiffness = 1e8, exponent = 1.5, restitution = 0.3}',
            "simulation.duration=1.0",
        ],
    )
    rest_depth = (M * G / K) ** (1 / 1.5)

    contacts = run.contacts
    final = contacts.filter(pc.equal(contacts["step"], pc.max(contacts["step"])))
    assert final.num_rows == 1
    assert final["t"][0].as_py() == pytest.approx(1.0, abs=1e-9)
    assert final["depth"][0].as_py() == pytest.approx(rest_depth, rel=5e-3)
    assert final["normal_force"][0].as_py() == pytest.approx(M * G, rel=5e-3)
    assert final["normal_z"][0].as_py() == pytest.approx(1.0, abs=1e-9)

    bodies = run.bodies
    assert R - bodies["pos_z"][-1].as_py() == pytest.approx(rest_depth, rel=5e-3)
    assert abs(bodies["vel_z"][-1].as_py()) < 1e-4


def test_elastic_hertz_drop_lands_when_free_fall_says(ball_drop_path):
    # Free fall over the 5 cm gap: first contact at t = sqrt(2 h / g).
    run = ballcage.simulate(ball_drop_path)
    first_contact = run.contacts["t"].to_numpy().min()
    t_land = np.sqrt(2 * 0.05 / G)
    assert t_land <= first_contact <= t_land + 1e-3  # the next recorded frame


def test_head_on_collision_conserves_momentum_and_dissipates_energy(two_balls_path):
    run = ballcage.simulate(two_balls_path)
    bodies = run.bodies
    names = bodies["body"].cast(pa.utf8())
    left = bodies.filter(pc.equal(names, "left"))
    right = bodies.filter(pc.equal(names, "right"))
    assert left.num_rows == right.num_rows == 1001

    # Equal masses, opposite velocities: total momentum is zero at every frame.
    np.testing.assert_allclose(left["vel_x"].to_numpy() + right["vel_x"].to_numpy(), 0.0, atol=1e-12)
    assert run.contacts.num_rows > 0
    assert left["vel_x"][-1].as_py() < 0.0 < right["vel_x"][-1].as_py()  # they bounced apart

    energy = run.energy
    total = energy["total"].to_numpy()
    assert total[0] == pytest.approx(2 * 0.5 * M * 1.0**2, rel=1e-12)  # two balls at 1 m/s
    assert np.all(np.diff(total) <= 1e-9)  # a dissipative law never adds energy
    assert 0.0 < total[-1] < total[0]
    np.testing.assert_allclose(energy["potential_gravity"].to_numpy(), 0.0, atol=1e-12)
