"""The links table's impulse columns and the time means read from them (`ballcage._links.link_tube_forces`).

``links.tube_normal_impulse`` and ``tube_tangential_impulse`` [N*s] are the integrator's own integrals of the
link's tube force over its steps. The headline means (``tube_normal_mean_*``) are their differences over the
summary window's length, so recording more or fewer frames of one trajectory leaves them as they are, while a
mean over the frames moves. The engine's side (the impulse the integrator applied balances the momentum) is
checked in crates/ballcage-core/tests/impulses.rs.
"""

from __future__ import annotations

import numpy as np
import pytest

import ballcage
from ballcage._links import link_tube_forces, time_mean

# Ideal-CV hinges over 0.4 s: the chain is pushed into the bend and rings on the tube wall.
IDEAL_CV = ['pipe.hinge="ideal-cv"', "simulation.duration=0.4"]


def _run(output_interval: float, max_step: float) -> ballcage.Run:
    overrides = [*IDEAL_CV, f"simulation.output_interval={output_interval}", f"simulation.max_step={max_step}"]
    return ballcage.simulate({"kind": "drill-pipe"}, overrides=overrides, progress=False)


def _frame_means(run: ballcage.Run) -> dict[int, float]:
    links = run.tables["links"]
    link = links.column("link").to_numpy()
    normal = links.column("tube_normal").to_numpy()
    return {int(k): float(normal[link == k].mean()) for k in np.unique(link)}


def test_the_link_means_do_not_depend_on_the_frames_recorded():
    # The same trajectory (steps up to 4 ms whatever the frames) recorded every 1 ms and every 4 ms.
    fine, coarse = _run(1e-3, 4e-3), _run(4e-3, 4e-3)
    assert fine.metadata["ballcage.accepted_steps"] == coarse.metadata["ballcage.accepted_steps"]
    a, b = link_tube_forces(fine), link_tube_forces(coarse)
    assert a is not None and b is not None
    assert b.normal_mean == pytest.approx(a.normal_mean, rel=1e-12, abs=1e-9)
    assert b.tangential_mean == pytest.approx(a.tangential_mean, rel=1e-12, abs=1e-9)
    # A mean over the frames of the same runs moves by far more than that.
    fa, fb = _frame_means(fine), _frame_means(coarse)
    assert max(abs(fa[k] - fb[k]) / max(fa[k], 1.0) for k in fa) > 1e-3
    assert sum(a.normal_mean.values()) > 1000.0  # the chain does press on the tube


def test_the_impulse_columns_are_the_integrals_of_the_force_columns():
    # Frames every 0.25 ms, shorter than the steps: the trapezoid rule over them is close to the integral.
    run = _run(2.5e-4, 1e-3)
    links = run.tables["links"]
    t, link = links.column("t").to_numpy(), links.column("link").to_numpy()
    pressed = 0
    for force, impulse in (("tube_normal", "tube_normal_impulse"), ("tube_tangential", "tube_tangential_impulse")):
        f, integral = links.column(force).to_numpy(), links.column(impulse).to_numpy()
        for k in np.unique(link):
            rows = link == k
            assert integral[rows][0] == 0.0  # the frame at t = 0
            assert np.all(np.diff(integral[rows]) >= -1e-12)  # forces and their magnitudes are >= 0
            total = integral[rows][-1]
            if total < 1.0:  # N*s: a link that hardly touches
                continue
            pressed += 1
            assert np.trapezoid(f[rows], t[rows]) == pytest.approx(total, rel=1e-2)
    assert pressed >= 20


@pytest.mark.parametrize(
    "integrator", [{"integrator": "esdirk32"}, {"integrator": "esdirk32", "rtol": 0}, {"integrator": "sdirk2", "rtol": 0}]
)
def test_a_scene_of_prescribed_bodies_has_time_means_too(integrator):
    # Nothing is integrated, so no stage is solved: the step takes its start's force. A fixed ball 1 mm into a
    # linear floor (k = 1e5 N/m) pushes k * 1 mm = 100 N all along; the summary's time mean is that.
    builder = (
        ballcage.SceneBuilder("held")
        .simulation(duration=0.01, dt=1e-3, output_interval=1e-3, **integrator)
        .body("floor", shape={"type": "half-space", "normal": [0, 0, 1]}, motion="fixed")
        .body("ball", shape={"type": "ball", "radius": 0.05}, motion="fixed", position=[0, 0, 0.049])
        .contact("floor", "ball", normal={"law": "linear", "stiffness": 1e5, "damping": 0.0})
        .record(tables=["summary"])
    )
    row = ballcage.simulate(builder.to_dict(), progress=False).tables["summary"].to_pylist()[0]
    assert row["frames"] == 11
    assert row["normal_mean"] == pytest.approx(100.0, rel=1e-9)
    assert row["tangential_mean"] == 0.0


def test_a_links_table_without_the_impulse_columns_gives_the_trapezoid_mean():
    # An older file: the force sampled at frames 0.1 s apart. For f(t) = 100 t^2 N over [0.2, 0.8] the trapezoid
    # rule gives 0.05 * (13 + 25 + 41 + 61 + 85 + 113) / 0.6 = 169/6 N; the exact mean, 100 (0.8^3 - 0.2^3) / 3 / 0.6,
    # is 28 N. A window of one frame is that frame's value.
    t = np.round(np.arange(0.0, 1.0001, 0.1), 12)
    f = 100.0 * t**2
    inside = (t >= 0.2 - 1e-12) & (t <= 0.8 + 1e-12)
    trapezoid = float(np.sum(0.5 * (f[3:9] + f[2:8]) * 0.1)) / 0.6
    assert time_mean(t, f, None, inside) == pytest.approx(trapezoid, rel=1e-12)
    assert trapezoid == pytest.approx(169.0 / 6.0, rel=1e-12)
    # With the engine's integral the mean is its growth, whatever the frames show.
    assert time_mean(t, f, 100.0 * t**3 / 3.0, inside) == pytest.approx(28.0, rel=1e-12)
    one = t == 0.5
    assert time_mean(t, f, None, one) == pytest.approx(25.0)
