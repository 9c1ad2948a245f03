"""A diverging run keeps what it recorded: `e.run` in Python, incomplete Parquet files from the CLI (exit 1)."""

from __future__ import annotations

import math
import re

import numpy as np
import pyarrow.parquet as pq
import pytest

import ballcage
from ballcage import cli
from ballcage.scene import default_scene

M, R, K = 1.0, 0.05, 1e8  # kg, m, N/m
DT = 1e-3  # s: h·ω = DT·sqrt(2K/M) ≈ 14, far beyond symplectic Euler's bound of 2
DURATION = 1.0  # s
OUTPUT_INTERVAL = DT  # s: a frame every step, so the few steps before the failure are recorded
FULL_FRAMES = round(DURATION / OUTPUT_INTERVAL) + 1


def stiff_slot() -> ballcage.SceneBuilder:
    """A ball pressed between two planes by stiff linear springs (0.1 mm preload each side).

    It cannot escape, so at h·ω ≈ 14 the symplectic Euler amplitude grows by
    about (h·ω)² ≈ 200 per step: within a few steps the penetration exceeds
    the pair's limit, and within a few hundred the state is non-finite,
    either way long before the 1 s duration.
    """
    spring = {"law": "linear", "stiffness": K}
    return (
        ballcage.SceneBuilder("stiff slot")
        .simulation(duration=DURATION, dt=DT, output_interval=OUTPUT_INTERVAL, integrator="symplectic-euler")
        .body("ground", motion="fixed", shape={"type": "half-space", "normal": [0.0, 0.0, 1.0]})
        .body(
            "ceiling",
            motion="fixed",
            shape={"type": "half-space", "normal": [0.0, 0.0, -1.0]},
            position=[0.0, 0.0, 2 * R - 2e-4],
        )
        .body("ball", shape={"type": "ball", "radius": R}, mass=M, position=[0.0, 0.0, R - 1e-4], velocity=[0.0, 0.0, 1e-3])
        .contact("ground", "ball", normal=spring)
        .contact("ceiling", "ball", normal=spring)
        .record(tables=["bodies", "contacts", "energy", "summary"])
    )


def _failure_time(message: str) -> float | None:
    """The time the engine's message names (``... at t = 1.56e-1 s ...``), if it names one."""
    match = re.search(r"t = ([-+0-9.eE]+) s", message)
    return float(match.group(1)) if match else None


def test_diverging_run_raises_with_the_partial_run_attached():
    with pytest.raises(ballcage.SimulationError) as info:
        ballcage.simulate(stiff_slot())
    e = info.value
    run = e.run
    assert isinstance(run, ballcage.Run)
    assert not run.complete
    assert run.error == str(e)
    assert set(run.tables) == {"bodies", "contacts", "energy", "summary"}

    meta = run.metadata
    assert meta["ballcage.complete"] == "false"
    assert meta["ballcage.error"]  # the engine's or ours: one message either way
    assert meta["ballcage.integrator"] == "symplectic-euler"
    assert int(meta["ballcage.steps"]) < round(DURATION / DT)

    t = run.bodies["t"].to_numpy()
    assert 2 <= len(t) < FULL_FRAMES
    assert t[0] == 0.0
    assert t.max() < DURATION
    t_fail = _failure_time(str(e))
    if t_fail is not None:
        assert t.max() <= t_fail + 1e-12
    np.testing.assert_array_less(run.energy["t"].to_numpy(), DURATION)
    # Recorded frames are the ones before the failure: all finite.
    assert np.all(np.isfinite(run.bodies["pos_z"].to_numpy()))
    # The field metadata (units) survives the added schema metadata.
    assert run.bodies.schema.field("pos_z").metadata[b"unit"] == b"m"
    for table in run.tables.values():
        assert table.schema.metadata[b"ballcage.complete"] == b"false"


def test_error_metadata_is_the_message_once_whoever_writes_it():
    # The engine writes ballcage.error itself; simulate() adds it only when missing.
    with pytest.raises(ballcage.SimulationError) as info:
        ballcage.simulate(stiff_slot())
    for table in info.value.run.tables.values():
        meta = table.schema.metadata
        assert [k for k in meta if k == b"ballcage.error"] == [b"ballcage.error"]
        assert meta[b"ballcage.error"].decode() == str(info.value)


def test_a_complete_run_has_no_error():
    run = ballcage.simulate(stiff_slot().simulation(dt=1e-5, output_interval=1e-3, duration=0.01))  # h·ω ≈ 0.14
    assert run.complete
    assert run.error is None
    assert "ballcage.error" not in run.metadata


def test_cli_writes_the_incomplete_output_and_exits_1(tmp_path, capsys):
    scene = tmp_path / "slot.toml"
    scene.write_text(ballcage.load_scene(stiff_slot()).to_toml(), encoding="utf-8")
    out = tmp_path / "out"

    code = cli.main(["run", str(scene), "--out", str(out)])

    captured = capsys.readouterr()
    assert code == 1
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1
    assert lines[0].startswith("ballcage: error: ")
    assert "diverged" in lines[0] and "incomplete" in lines[0]
    assert "Traceback" not in captured.err
    assert "wrote" in captured.out

    for name in ("bodies", "contacts", "energy", "summary"):
        path = out / f"{name}.parquet"
        assert path.is_file(), name
        meta = pq.read_schema(path).metadata
        assert meta[b"ballcage.complete"] == b"false"
        assert meta[b"ballcage.error"]
    assert (out / "scene.toml").is_file()
    assert not list(out.glob(".*.tmp"))  # atomic writes leave no temporaries
    bodies = pq.read_table(out / "bodies.parquet")
    assert 0 < bodies.num_rows < FULL_FRAMES
    assert bodies["t"].to_numpy().max() < DURATION
    assert math.isfinite(float(bodies["pos_z"].to_numpy()[-1]))


def test_cli_quiet_still_writes_and_reports_one_line(tmp_path, capsys):
    scene = tmp_path / "slot.toml"
    scene.write_text(ballcage.load_scene(stiff_slot()).to_toml(), encoding="utf-8")
    code = cli.main(["run", str(scene), "--out", str(tmp_path / "q"), "--quiet"])
    captured = capsys.readouterr()
    assert code == 1
    assert captured.out == ""
    assert len(captured.err.strip().splitlines()) == 1
    assert (tmp_path / "q" / "bodies.parquet").is_file()


# --------------------------------------------------------------------------- the advice in the message


def overlapping_ball(integrator: str, dt: float) -> ballcage.SceneBuilder:
    """A ball of radius 50 mm placed 20 mm deep in the ground: beyond its pair's limit (25 % of the
    radius, 12.5 mm) from the start, whatever the step."""
    return (
        ballcage.SceneBuilder("overlap")
        .simulation(duration=0.05, dt=dt, output_interval=1e-3, integrator=integrator)
        .gravity([0.0, 0.0, -9.81])
        .body("ground", motion="fixed", shape={"type": "half-space", "normal": [0.0, 0.0, 1.0]})
        .body("ball", shape={"type": "ball", "radius": R}, mass=M, position=[0.0, 0.0, R - 0.02])
        .contact("ground", "ball", normal={"law": "hertz", "stiffness": 1e8})
    )


def _advised_step(message: str) -> float | None:
    match = re.search(r"simulation\.dt ≤ ([-+0-9.eE]+) s", message)
    return float(match.group(1)) if match else None


@pytest.mark.parametrize(("integrator", "dt"), [("symplectic-euler", 1e-3), ("rk4", 1e-5), ("sdirk2", 1e-4)])
def test_an_initial_overlap_is_not_blamed_on_the_step(integrator, dt):
    with pytest.raises(ballcage.SimulationError) as info:
        ballcage.simulate(overlapping_ball(integrator, dt))
    text = str(info.value)
    assert "already penetrates 20.0000 mm at t = 0" in text and "initial overlap" in text, text
    assert "is probably not the cause" in text, text
    assert "geometry" in text and "too soft" in text and "load" in text, text
    assert _advised_step(text) is None, text
    # Following the old advice (a smaller step) would fail at once again: same advice.
    with pytest.raises(ballcage.SimulationError) as again:
        ballcage.simulate(overlapping_ball(integrator, dt / 4))
    assert "is probably not the cause" in str(again.value)


def test_a_step_too_large_still_gets_the_step_advice_which_holds():
    with pytest.raises(ballcage.SimulationError) as info:
        ballcage.simulate(stiff_slot())
    text = str(info.value)
    advised = _advised_step(text)
    assert advised is not None and advised < DT, text
    assert "probably not the cause" not in text
    # The advice holds: at half the advised step (a step that divides the output interval) the run completes.
    steps = math.ceil(OUTPUT_INTERVAL / (0.5 * advised))
    assert ballcage.simulate(stiff_slot().simulation(dt=OUTPUT_INTERVAL / steps)).complete


def test_a_step_that_halving_did_not_cure_is_not_blamed_on_the_step():
    # One Newton iteration per stage cannot converge, however small the step: SDIRK2 halves the
    # step four times and, without its fallback to linearly implicit Euler, gives up; the message
    # says the step is not the cause.
    scene = default_scene(
        [
            "pipe.joints=2",
            "simulation.duration=0.01",
            'simulation.integrator="sdirk2"',
            "simulation.rtol=0",
            "simulation.dt=1e-3",
            "simulation.newton.max_iterations=1",
            "simulation.newton.fallback=false",
        ]
    )
    with pytest.raises(ballcage.SimulationError) as info:
        ballcage.simulate(scene)
    text = str(info.value)
    assert "retried in halves" in text and "is probably not the cause" in text, text
    assert "simulation.newton.max_iterations" in text
    assert _advised_step(text) is None, text
    # The adaptive default shrinks its own step to 1/16384 of the largest before it gives up (here Newton cannot
    # converge at any step: one iteration against a tolerance no increment meets): the message says so, and does
    # not advise a step either.
    adaptive = default_scene(
        [
            "pipe.joints=2", "simulation.duration=0.01", "simulation.newton.max_iterations=1",
            "simulation.newton.tolerance=1e-300", "simulation.newton.fallback=false",
        ]
    )  # fmt: skip
    with pytest.raises(ballcage.SimulationError) as info:
        ballcage.simulate(adaptive)
    text = str(info.value)
    assert "the adaptive steps went down to" in text and "is probably not the cause" in text, text
    assert "simulation.newton.max_iterations" in text
    assert _advised_step(text) is None, text



def sinking_ball(rtol: float) -> ballcage.SceneBuilder:
    """A ball of 1 kg on a linear spring floor of 400 N/m under gravity: it settles 24.5 mm deep
    (mg/k), beyond its pair's limit (25 % of the 50 mm radius, 12.5 mm), however accurately the
    motion is integrated. Adaptive steps (ESDIRK3(2) at `rtol`)."""
    return (
        ballcage.SceneBuilder("sinking ball")
        .simulation(duration=0.5, dt=1e-3, output_interval=1e-3, integrator="esdirk32", rtol=rtol)
        .gravity([0.0, 0.0, -9.81])
        .body("ground", motion="fixed", shape={"type": "half-space", "normal": [0.0, 0.0, 1.0]})
        .body("ball", shape={"type": "ball", "radius": R}, mass=M, position=[0.0, 0.0, R])
        .contact("ground", "ball", normal={"law": "linear", "stiffness": 400.0})
    )


def test_an_adaptive_run_that_sinks_says_its_steps_met_their_tolerance():
    # The adaptive integrator shortened no step for this failure: the message must not claim it
    # did, and says the depth is the model's, naming the tolerance the steps met.
    with pytest.raises(ballcage.SimulationError) as info:
        ballcage.simulate(sinking_ball(1e-4))
    text = str(info.value)
    assert "penetrates" in text and "every step met its error estimate's tolerance" in text, text
    assert "simulation.rtol = 0.0001" in text and "the depth is the model's" in text, text
    assert "went down to" not in text and _advised_step(text) is None, text
    # It holds: a hundred times tighter, the run fails at the same frame (the depth crosses the
    # limit at t ≈ 0.13 s; the 1 ms frames would show a step's worth of difference).
    with pytest.raises(ballcage.SimulationError) as tighter:
        ballcage.simulate(sinking_ball(1e-6))
    assert _failure_time(str(tighter.value)) == _failure_time(text)


def test_an_interpolated_frame_s_energy_does_not_stop_an_adaptive_run():
    # Three ideal-CV links at rtol 1e-3 with steps of up to 5 ms and frames every 1 ms: the frame
    # at 1 ms is interpolated within the first step, and the interpolant's velocities hold about
    # ten times the kinetic energy the links have then (4.3e-5 J with 1 ms steps). That frame
    # fails the energy balance; the integrator's own state at the step's end holds it, and the
    # run goes on from there.
    overrides = [
        'pipe.hinge="ideal-cv"', "pipe.joints=3", "simulation.rtol=1e-3", "simulation.max_step=5e-3",
        "simulation.duration=0.02", 'record.tables=["energy", "summary"]',
    ]  # fmt: skip
    run = ballcage.simulate(default_scene(overrides), progress=False)
    assert run.complete
    e = run.energy.to_pandas()
    work = e["drive_work"] + e["load_work"]
    created = e["total"] - e["total"].iloc[0] - work
    free = e["kinetic"].iloc[0] + e["potential_contact"].iloc[0]
    swing = (e["potential_gravity"] - e["potential_gravity"].iloc[0]).abs().cummax()
    scale = free + swing + e["drive_work"].abs() + e["load_work"].abs()
    at_1ms = e.index[np.isclose(e["t"], 1e-3)][0]
    # The frame at 1 ms would have failed the check (energy_growth = 1): the test covers that path.
    assert created[at_1ms] > 2.0 * scale[at_1ms], (created[at_1ms], scale[at_1ms])
