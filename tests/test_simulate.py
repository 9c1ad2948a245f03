"""simulate(): free fall against the closed form, the schema's units, the run metadata, progress."""

from __future__ import annotations

import io

import numpy as np
import pyarrow as pa
import pytest

import ballcage
from ballcage.run import ProgressBar

G = 9.81
Z0 = 10.0


def test_free_fall_matches_z0_minus_half_g_t_squared_every_frame(free_fall):
    run = ballcage.simulate(free_fall)
    bodies = run.bodies

    t = bodies["t"].to_numpy()
    z = bodies["pos_z"].to_numpy()
    expected = Z0 - 0.5 * G * t**2
    assert len(t) == 101  # frames at 0, 0.01, ..., 1.0 s
    assert t[0] == 0.0
    assert t[-1] == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(z, expected, rtol=1e-9, atol=0.0)
    # RK4 integrates constant acceleration exactly: velocity too.
    np.testing.assert_allclose(bodies["vel_z"].to_numpy(), -G * t, rtol=0.0, atol=1e-9 * G)
    # Nothing moves sideways and nothing turns.
    for column in ("pos_x", "pos_y", "vel_x", "vel_y", "angvel_x", "angvel_y", "angvel_z"):
        assert np.all(bodies[column].to_numpy() == 0.0), column
    np.testing.assert_array_equal(bodies["quat_w"].to_numpy(), 1.0)


def test_frames_are_numbered_by_integrator_step(free_fall):
    bodies = ballcage.simulate(free_fall).bodies
    steps = bodies["step"].to_numpy()
    np.testing.assert_array_equal(steps, np.arange(0, 1001, 10, dtype=np.uint64))
    np.testing.assert_allclose(bodies["t"].to_numpy(), steps * 1e-3, rtol=1e-12, atol=1e-15)
    assert bodies["body"].to_pylist() == ["ball"] * 101
    assert set(bodies["body_id"].to_pylist()) == {0}


def test_bodies_schema_carries_units_and_matches_table_schema(free_fall):
    bodies = ballcage.simulate(free_fall).bodies
    schema = bodies.schema

    assert schema.field("pos_z").metadata[b"unit"] == b"m"
    assert schema.field("t").metadata[b"unit"] == b"s"
    assert schema.field("vel_x").metadata[b"unit"] == b"m/s"
    assert schema.field("angvel_x").metadata[b"unit"] == b"rad/s"
    for field in schema:
        assert b"unit" in field.metadata, field.name
        assert field.metadata.get(b"description"), field.name
    assert schema.field("step").type == pa.uint64()
    assert schema.field("t").type == pa.float64()
    assert schema.field("body_id").type == pa.uint32()
    assert schema.field("body").type == pa.dictionary(pa.uint32(), pa.utf8())

    published = ballcage.table_schema("bodies")
    assert schema.remove_metadata().equals(published.remove_metadata(), check_metadata=True)


@pytest.mark.parametrize(
    ("table", "column", "unit"),
    [("contacts", "normal_force", b"N"), ("contacts", "depth", b"m"), ("contacts", "normal_x", b"1"), ("energy", "total", b"J")],
)
def test_table_schema_units(table, column, unit):
    assert ballcage.table_schema(table).field(column).metadata[b"unit"] == unit


def test_metadata_names_version_integrator_and_a_complete_run(free_fall):
    run = ballcage.simulate(free_fall)
    meta = run.metadata

    assert meta["ballcage.version"] == ballcage.__version__
    assert meta["ballcage.integrator"] == "rk4"
    assert meta["ballcage.complete"] == "true"
    assert float(meta["ballcage.dt_s"]) == 1e-3
    assert float(meta["ballcage.wall_time_s"]) >= 0.0
    assert meta["ballcage.scene"] == run.scene_toml
    assert ballcage.load_scene(free_fall).to_toml() == run.scene_toml


def test_scene_properties_are_resolved_si_values(free_fall):
    scene = ballcage.load_scene(free_fall)
    assert scene.name == "free fall"
    assert (scene.duration, scene.dt, scene.output_interval) == (1.0, 1e-3, 1e-2)
    assert scene.integrator == "rk4"
    assert scene.table_names == ["bodies"]


def test_asking_for_an_unrecorded_table_says_how_to_record_it(free_fall):
    run = ballcage.simulate(free_fall)
    assert set(run.tables) == {"bodies"}
    with pytest.raises(KeyError, match=r"record\.tables") as info:
        run.contacts
    assert "contacts" in str(info.value)
    with pytest.raises(KeyError, match=r"record\.tables"):
        run.energy


def test_simulation_advances_in_steps_and_finishes_once(free_fall):
    sim = ballcage.Simulation(ballcage.load_scene(free_fall))
    assert sim.duration == 1.0
    assert sim.time == 0.0
    sim.advance(0.25)
    assert 0.25 <= sim.time < 0.25 + 1e-3 + 1e-12
    sim.advance(5.0)  # clamped to the duration
    assert sim.time == pytest.approx(1.0, abs=1e-12)
    tables = sim.finish()
    assert tables["bodies"].num_rows == 101
    with pytest.raises(Exception):  # noqa: B017  (callable once; the type is not part of the contract)
        sim.finish()


def test_advance_between_steps_reaches_at_least_t_end(free_fall):
    sim = ballcage.Simulation(ballcage.load_scene(free_fall))  # dt = 1 ms
    sim.advance(0.2504)
    assert 0.2504 <= sim.time <= 0.2504 + 1e-3


def test_fast_run_prints_no_progress_bar(free_fall, capsys):
    ballcage.simulate(free_fall)
    assert capsys.readouterr().err == ""


def test_forced_progress_on_a_pipe_prints_a_line_every_ten_percent(free_fall, capsys):
    ballcage.simulate(free_fall, progress=True)
    lines = capsys.readouterr().err.splitlines()
    assert [line.split()[1] for line in lines] == [f"{p}%" for p in range(10, 101, 10)]


def test_progress_bar_appears_only_after_the_delay():
    now = [0.0]
    out = io.StringIO()
    bar = ProgressBar(None, duration=2.0, stream=out, clock=lambda: now[0])
    bar.update(0.5)
    assert out.getvalue() == ""
    now[0] = 1.6
    bar.update(0.8)
    bar.update(2.0)
    bar.close()
    assert out.getvalue().splitlines()[0].startswith("ballcage:  40%")
    assert out.getvalue().splitlines()[-1].startswith("ballcage: 100%")
    silent = io.StringIO()
    never = ProgressBar(False, duration=2.0, stream=silent, clock=lambda: 99.0)
    never.update(1.0)
    assert silent.getvalue() == ""


def test_progress_bar_on_a_terminal_redraws_one_line():
    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    out = Terminal()
    bar = ProgressBar(True, duration=0.2, stream=out, clock=lambda: 0.0)
    for t in (0.139, 0.14, 0.2):
        bar.update(t)
    bar.close()
    frames = out.getvalue().split("\r")[1:]
    assert len(frames) == 3 and out.getvalue().count("\n") == 1
    assert len({len(f.rstrip("\n")) for f in frames}) == 1  # a shorter line is padded over the longer one
    assert "100%" in frames[-1]


def test_debug_build_warns_on_import():
    with pytest.warns(RuntimeWarning, match="without optimizations"):
        ballcage._warn_if_debug_build("debug")
    ballcage._warn_if_debug_build("release")  # filterwarnings=error: any warning would fail here


def test_public_api_is_curated():
    assert set(ballcage.__all__) == {
        "DrillPipeBuilder", "Error", "InputError", "InternalError", "Run", "Scene", "SceneBuilder", "SceneError",
        "Simulation", "SimulationError", "__version__", "buckling", "largest_link_diameter", "load_scene",
        "longest_link", "proposals", "simulate", "table_schema", "tightest_radius_for_link",
    }
    # one base class for every error, each also the built-in exception code written before it catches
    assert issubclass(ballcage.SceneError, ballcage.Error) and issubclass(ballcage.SceneError, ValueError)
    assert issubclass(ballcage.SimulationError, ballcage.Error) and issubclass(ballcage.SimulationError, RuntimeError)
    assert issubclass(ballcage.InputError, ballcage.Error) and issubclass(ballcage.InputError, ValueError)
    assert issubclass(ballcage.InternalError, ballcage.Error) and issubclass(ballcage.InternalError, RuntimeError)
    assert not issubclass(ballcage.SceneError, ballcage.SimulationError)
    assert isinstance(ballcage.__version__, str) and ballcage.__version__


def test_run_scene_answers_for_the_scene_it_ran(free_fall):
    run = ballcage.simulate(free_fall, progress=False)
    assert run.scene.kind == "generic"
    assert run.scene.value("simulation.dt") == pytest.approx(1e-3)
    # A Run made from tables and TOML validates its scene once, on first use.
    rebuilt = ballcage.Run(run.tables, run.scene_toml)
    assert rebuilt.scene.to_toml() == run.scene_toml
    assert rebuilt.scene is rebuilt.scene


def test_the_package_namespace_holds_only_its_api_and_modules():
    import types

    public = {n for n in vars(ballcage) if not n.startswith("_")}
    modules = {n for n in public if isinstance(getattr(ballcage, n), types.ModuleType)}
    assert public - modules == {n for n in ballcage.__all__ if not n.startswith("_")}
