"""`ballcage accuracy` and `ballcage stability` on tiny scenes, against orders and bounds derived by hand."""

from __future__ import annotations

import math

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import ballcage
from ballcage import cli, studies

G = 9.81

# --------------------------------------------------------------------------- scenes

SPIN_Z0 = 1.0  # m
SPIN_DURATION = 0.2  # s


def spinner() -> ballcage.SceneBuilder:
    """An asymmetric box falling and tumbling freely: smooth, no contact.

    Its angular velocity follows Euler's equations (non-linear, gyroscopic);
    its centre of mass falls freely, z = z0 − g t²/2.
    """
    return (
        ballcage.SceneBuilder("spinner")
        .simulation(duration=SPIN_DURATION, dt=1e-3, output_interval=0.02, integrator="rk4")
        .gravity([0.0, 0.0, -G])
        .body(
            "spinner",
            shape={"type": "cuboid", "half_extents": [0.05, 0.1, 0.2]},
            mass=1.0,
            position=[0.0, 0.0, SPIN_Z0],
            angular_velocity=[5.0, 20.0, 1.0],
        )
    )


def bounce() -> ballcage.SceneBuilder:
    """A ball hitting the ground at 1 m/s (Hunt–Crossley, with friction): 5 ms, contact ~2 ms."""
    return (
        ballcage.SceneBuilder("bounce")
        .simulation(duration=0.0048, dt=1e-5, output_interval=4e-4, integrator="rk4")
        .gravity([0.0, 0.0, -G])
        .body("ground", motion="fixed", shape={"type": "half-space", "normal": [0.0, 0.0, 1.0]})
        .body("ball", shape={"type": "ball", "radius": 0.05}, mass=1.0, position=[0.0, 0.0, 0.05], velocity=[0.2, 0.0, -1.0])
        .contact(
            "ground",
            "ball",
            normal={"law": "hunt-crossley", "stiffness": 1e8, "exponent": 1.5, "restitution": 0.5},
            friction={"law": "tanh", "mu": 0.3, "v_ref": 1e-3},
        )
    )


SLOT_M, SLOT_R, SLOT_PRELOAD = 1.0, 0.05, 1e-4  # kg, m, m


def slot(stiffness: float = 1e6, duration: float = 1.0) -> ballcage.SceneBuilder:
    """A ball pressed between two planes by linear springs k (preload 0.1 mm each side), no gravity.

    It stays in contact with both, so it is a linear oscillator of stiffness
    2k: ω = sqrt(2k/m). Symplectic Euler on x'' = −ω²x is stable exactly
    when h·ω < 2 (the amplification matrix has trace 2 − (hω)² and
    determinant 1), so its largest stable step is 2/ω = sqrt(2m/k).
    """
    spring = {"law": "linear", "stiffness": stiffness}
    return (
        ballcage.SceneBuilder("slot")
        .simulation(duration=duration, dt=1e-4, output_interval=1e-2, integrator="symplectic-euler")
        .body("ground", motion="fixed", shape={"type": "half-space", "normal": [0.0, 0.0, 1.0]})
        .body(
            "ceiling",
            motion="fixed",
            shape={"type": "half-space", "normal": [0.0, 0.0, -1.0]},
            position=[0.0, 0.0, 2 * SLOT_R - 2 * SLOT_PRELOAD],
        )
        .body(
            "ball",
            shape={"type": "ball", "radius": SLOT_R},
            mass=SLOT_M,
            position=[0.0, 0.0, SLOT_R - SLOT_PRELOAD],
            velocity=[0.0, 0.0, 1e-3],  # amplitude v/ω ≤ 7 µm, well inside the preload
        )
        .contact("ground", "ball", normal=spring)
        .contact("ceiling", "ball", normal=spring)
    )


def _rows(table: pa.Table, **where: object) -> list[dict]:
    return [r for r in table.to_pylist() if all(r[k] == v for k, v in where.items())]


def _errors(table: pa.Table, integrator: str, quantity: str) -> list[tuple[float, float]]:
    """(dt, error) of the ladder runs of one integrator, largest step first."""
    rows = _rows(table, integrator=integrator, quantity=quantity, role="run")
    return sorted(((r["dt"], r["error"]) for r in rows), reverse=True)


# --------------------------------------------------------------------------- accuracy

LADDER = [4e-3, 2e-3, 1e-3]  # s, halving


@pytest.fixture(scope="module")
def spin_study() -> pa.Table:
    return studies.accuracy(
        spinner(),
        integrators=["symplectic-euler", "rk4"],
        steps=LADDER,
        reference_integrator="rk4",
        reference_dt=5e-5,
    )


def test_accuracy_schema_units_and_roles(spin_study):
    table = spin_study
    for column in ("integrator", "dt", "quantity", "value", "reference", "error", "reference_error", "wall_s", "steps",
                   "force_evaluations", "linear_solves", "newton_iterations", "diverged", "message"):
        assert column in table.column_names, column
    assert table.schema.equals(studies.ACCURACY_SCHEMA)  # field metadata compared too: units
    assert table.schema.field("dt").metadata[b"unit"] == b"s"
    assert table.schema.field("wall_s").metadata[b"unit"] == b"s"
    assert table.schema.field("error").metadata[b"unit"] == b"1"

    runs = {(r["integrator"], r["dt"], r["role"]) for r in table.to_pylist()}
    interval = float(table.schema.metadata[b"ballcage.output_interval_s"])
    assert runs == {("rk4", 5e-5, "reference"), ("rk4", 1e-4, "reference-check"), ("esdirk32", interval, "second-method")} | {
        (i, dt, "run") for i in ("symplectic-euler", "rk4") for dt in LADDER
    }
    quantities = set(table.column("quantity").to_pylist())
    assert {
        "final_position_spinner",
        "final_velocity_spinner",
        "final_angular_velocity_spinner",
        "final_total_energy",
        "final_kinetic_energy",
        studies.MAX_QUANTITY,
    } == quantities
    assert table.num_rows == len(runs) * len(quantities)
    assert not any(table.column("diverged").to_pylist())
    assert table.column("message").null_count == table.num_rows
    assert all(r["steps"] == round(SPIN_DURATION / r["dt"]) for r in table.to_pylist())
    se = _rows(table, integrator="symplectic-euler", quantity="final_total_energy", role="run")
    assert all(r["force_evaluations"] == r["steps"] for r in se)  # one evaluation per step
    rk = _rows(table, integrator="rk4", quantity="final_total_energy", role="run")
    assert all(r["force_evaluations"] == 4 * r["steps"] for r in rk)
    meta = table.schema.metadata
    assert meta[b"ballcage.study"] == b"accuracy"
    assert meta[b"ballcage.reference_integrator"] == b"rk4"
    assert float(meta[b"ballcage.reference_dt_s"]) == 5e-5


def test_symplectic_euler_position_error_is_the_closed_form(spin_study):
    # Free fall under symplectic Euler: z_n = z0 − g h² n(n+1)/2, so at t = nh the error is g h t / 2
    # (first order). RK4 integrates constant acceleration exactly, so the reference is exact.
    z_ref = SPIN_Z0 - 0.5 * G * SPIN_DURATION**2
    for dt, error in _errors(spin_study, "symplectic-euler", "final_position_spinner"):
        assert error == pytest.approx(G * dt * SPIN_DURATION / 2 / z_ref, rel=1e-6)


def test_error_falls_with_the_order_of_each_integrator(spin_study):
    # Global error e(h) ≈ C h^p, so halving the step divides it by 2^p: 2 for symplectic Euler
    # (p = 1) and 16 for RK4 (p = 4) on the smooth rotation.
    quantity = "final_angular_velocity_spinner"
    se = _errors(spin_study, "symplectic-euler", quantity)
    rk = _errors(spin_study, "rk4", quantity)
    for (_, coarse), (_, fine) in zip(se, se[1:]):
        assert coarse / fine == pytest.approx(2.0, rel=0.15)
    for (_, coarse), (_, fine) in zip(rk, rk[1:]):
        assert 8.0 < coarse / fine < 24.0  # clearly faster than second order; 16 expected
    assert rk[-1][1] < 1e-3 * se[-1][1]


def test_reference_self_error_is_recorded_and_small(spin_study):
    table = spin_study
    ref = _rows(table, role="reference")
    check = _rows(table, role="reference-check")
    assert ref and check
    for r in ref:
        assert r["error"] == 0.0 or r["quantity"] == studies.MAX_QUANTITY
        assert r["reference_error"] is not None and r["reference_error"] < 1e-8, r["quantity"]
    # The check run's error is the reference's self-error, repeated on every row of that quantity.
    for r in check:
        if r["quantity"] != studies.MAX_QUANTITY:
            assert r["error"] == pytest.approx(r["reference_error"], rel=1e-12, abs=1e-300)
    smallest = min(e for _, e in _errors(table, "rk4", "final_angular_velocity_spinner"))
    self_error = _rows(table, role="run", quantity="final_angular_velocity_spinner")[0]["reference_error"]
    assert self_error < 1e-2 * smallest
    assert float(table.schema.metadata[b"ballcage.reference_self_error_max"]) < 1e-8


def test_a_second_method_confirms_the_reference(spin_study):
    # ESDIRK3(2) at rtol 1e-5 against RK4 at 50 µs: two integrators of different families agree on every
    # quantity far below the ladder's errors. Its rows carry its error against the reference.
    table = spin_study
    second = _rows(table, role="second-method")
    assert second and not any(r["diverged"] for r in second)
    worst = float(table.schema.metadata[b"ballcage.second_method_error_max"])
    assert worst == max(r["error"] for r in second)
    assert 0.0 < worst < 1e-4
    # The ladder's best RK4 run resolves less than the second method's agreement allows:
    # the confirmation is of the reference, not of a run.
    largest_ladder_error = max(e for _, e in _errors(table, "symplectic-euler", "final_angular_velocity_spinner"))
    assert worst < 1e-2 * largest_ladder_error
    assert table.schema.metadata[b"ballcage.second_method"] == b"esdirk32 rtol 1e-05"


def test_a_study_where_every_run_diverged_still_writes_its_files(tmp_path):
    table = studies.accuracy(
        slot(1e8, duration=0.02),
        integrators=["symplectic-euler"],
        steps=[1e-3],
        reference_integrator="rk4",
        reference_dt=1e-6,
    )
    assert all(r["diverged"] for r in _rows(table, role="run"))
    paths = studies.write_accuracy(table, tmp_path)
    assert all(p.stat().st_size > 0 for p in paths.values())


def test_diverged_runs_are_rows_not_errors():
    # h·ω = 1e-3 · sqrt(2e8) ≈ 14 ≫ 2: symplectic Euler diverges; 1e-5 s is stable (h·ω ≈ 0.14).
    table = studies.accuracy(
        slot(1e8, duration=0.02),
        integrators=["symplectic-euler"],
        steps=[1e-3, 1e-5],
        reference_integrator="rk4",
        reference_dt=1e-6,
    )
    bad = _rows(table, dt=1e-3, role="run")
    good = _rows(table, dt=1e-5, role="run")
    assert bad and good
    assert all(r["diverged"] and math.isinf(r["error"]) and r["value"] is None for r in bad)
    assert all(r["message"] and "diverged" in r["message"] for r in bad)
    assert all(r["steps"] is not None and r["steps"] < 20 for r in bad)  # the partial run's own count
    assert not any(r["diverged"] for r in good)
    assert all(math.isfinite(r["error"]) for r in good)


def test_contact_scene_with_every_integrator_and_the_default_reference(tmp_path):
    table = studies.accuracy(bounce())
    names = {r["integrator"] for r in _rows(table, role="run")}
    assert names == set(ballcage._native.INTEGRATORS)
    assert {r["integrator"] for r in _rows(table, role="second-method")} == {"esdirk32"}
    assert "peak_normal_force_ground/ball" in set(table.column("quantity").to_pylist())
    meta = table.schema.metadata
    assert meta[b"ballcage.reference_integrator"] == b"sdirk2"
    # Default ladders: explicit 0.25-2x the scene's step, implicit 1-8x; the reference at the smallest / 4.
    rk4_steps = sorted({r["dt"] for r in _rows(table, integrator="rk4", role="run")})
    assert rk4_steps == pytest.approx([2.5e-6, 5e-6, 1e-5, 2e-5])
    assert float(meta[b"ballcage.reference_dt_s"]) == pytest.approx(2.5e-6)
    ok = [r for r in _rows(table, role="run", quantity="peak_normal_force_ground/ball") if not r["diverged"]]
    assert ok and all(0 <= r["error"] < 0.2 for r in ok)
    assert all(r["reference"] > 100.0 for r in ok)  # the impact force [N]

    paths = studies.write_accuracy(table, tmp_path, command="ballcage accuracy bounce.toml")
    assert {p.name for p in paths.values()} == {"work_precision.parquet", "work_precision.png", "work_precision.md"}
    read = pq.read_table(tmp_path / "work_precision.parquet")
    assert read.equals(table)
    assert read.schema.field("dt").metadata[b"unit"] == b"s"
    md = (tmp_path / "work_precision.md").read_text(encoding="utf-8")
    assert "self-error" in md and "ballcage accuracy bounce.toml" in md
    assert (tmp_path / "work_precision.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_drill_pipe_quantities_are_named_by_joint_and_link():
    table = studies.accuracy(
        None,
        overrides=["pipe.joints=1"],
        duration=0.002,
        integrators=["linearly-implicit-euler"],
        steps=[2e-5],
        reference_integrator="linearly-implicit-euler",
        reference_dt=5e-6,
    )
    quantities = set(table.column("quantity").to_pylist())
    assert {"key_seat_normal_peak", "tube_mean_force_joint_01", "final_bend_deg_link_01", "final_total_energy"} <= quantities
    bend = _rows(table, role="reference", quantity="final_bend_deg_link_01")[0]
    assert bend["unit"] == "deg" and 0.0 < bend["reference"] < 15.0
    assert table.schema.metadata[b"ballcage.kind"] == b"drill-pipe"


def test_a_diverging_reference_stops_the_study(tmp_path, capsys):
    # The reference itself at h·ω ≈ 14: nothing can be measured against it.
    with pytest.raises(studies.StudyError, match="reference run"):
        studies.accuracy(slot(1e8, duration=0.02), integrators=["rk4"], steps=[1e-5],
                         reference_integrator="symplectic-euler", reference_dt=1e-3)
    scene = tmp_path / "slot.toml"
    scene.write_text(ballcage.load_scene(slot(1e8, duration=0.02)).to_toml(), encoding="utf-8")
    code = cli.main(["accuracy", str(scene), "--out", str(tmp_path / "o"), "--integrators", "rk4", "--steps", "1e-5",
                     "--reference-integrator", "symplectic-euler", "--reference-dt", "1e-3", "--quiet"])
    err = capsys.readouterr().err
    assert code == 1
    assert err.startswith("ballcage: error: the reference run") and len(err.strip().splitlines()) == 1


def test_bad_arguments_name_the_argument():
    with pytest.raises(ValueError, match="integrators: 'rk5'"):
        studies.accuracy(spinner(), integrators=["rk5"])
    with pytest.raises(ValueError, match="steps: -1e-05"):
        studies.accuracy(spinner(), integrators=["rk4"], steps=[-1e-5])
    with pytest.raises(ValueError, match="reference_dt"):
        studies.accuracy(spinner(), integrators=["rk4"], reference_dt=0.0)


# --------------------------------------------------------------------------- stability

STIFFNESSES = (1e6, 1e7, 1e8)  # N/m


@pytest.fixture(scope="module")
def slot_stability() -> pa.Table:
    parameter = studies.Parameter(
        "stiffness", ("contacts.0.normal.stiffness", "contacts.1.normal.stiffness"), STIFFNESSES, "N/m"
    )
    return studies.stability(slot(), parameters=[parameter], integrators=["symplectic-euler", "rk4"])


def test_stability_schema(slot_stability):
    table = slot_stability
    assert table.schema.equals(studies.STABILITY_SCHEMA)
    assert table.schema.field("max_stable_dt_s").metadata[b"unit"] == b"s"
    assert table.num_rows == 2 * len(STIFFNESSES)
    for r in table.to_pylist():
        assert r["parameter"] == "stiffness" and r["unit"] == "N/m"
        assert 1 <= r["probes"] <= 12
        assert r["max_stable_dt_s"] < r["min_unstable_dt_s"] <= r["max_stable_dt_s"] * 4 ** (1 / 2**5) * (1 + 1e-9)
        assert "unstable at" in r["message"]


def test_symplectic_euler_stable_step_falls_as_two_over_omega(slot_stability):
    rows = sorted(_rows(slot_stability, integrator="symplectic-euler"), key=lambda r: r["value"])
    steps = [r["max_stable_dt_s"] for r in rows]
    assert all(a > b for a, b in zip(steps, steps[1:]))  # stiffer: smaller step
    for r in rows:
        bound = 2.0 / math.sqrt(2 * r["value"] / SLOT_M)  # 2/ω, ω = sqrt(2k/m)
        assert bound / 3 < r["max_stable_dt_s"] < 3 * bound
    # Ten times stiffer: sqrt(10) times smaller.
    for a, b in zip(steps, steps[1:]):
        assert a / b == pytest.approx(math.sqrt(10), rel=0.25)


def test_rk4_is_stable_to_a_larger_step_than_symplectic_euler(slot_stability):
    # RK4's stability interval on the imaginary axis is 2√2 against symplectic Euler's 2.
    se = {r["value"]: r["max_stable_dt_s"] for r in _rows(slot_stability, integrator="symplectic-euler")}
    rk = {r["value"]: r["max_stable_dt_s"] for r in _rows(slot_stability, integrator="rk4")}
    for k in STIFFNESSES:
        assert rk[k] / se[k] == pytest.approx(math.sqrt(2), rel=0.25)


def test_stability_heat_maps_are_written(slot_stability, tmp_path):
    paths = studies.write_stability(slot_stability, tmp_path)
    assert (tmp_path / "stability.parquet").is_file()
    assert (tmp_path / "stability_stiffness.png").read_bytes()[:4] == b"\x89PNG"
    assert (tmp_path / "stability.md").is_file()
    assert set(paths) == {"parquet", "stability_stiffness", "md"}


def test_tightest_radius_is_the_articulation_limit_over_the_pitch():
    # The neck (r = 19 mm) meets the seat's mouth (the seat sphere, R_s = 32.01 mm, cut 20 mm
    # from the hinge centre) at β = acos(19/32.01) − asin(20/32.01) = 14.92°; on an arc
    # R = p / (2 sin(β/2)).
    beta = math.acos(19 / 32.01) - math.asin(20 / 32.01)
    assert studies.tightest_radius() == pytest.approx(0.2 / (2 * math.sin(beta / 2)), rel=1e-12)
    assert studies.tightest_radius() == pytest.approx(0.770, abs=1e-3)


def test_tightest_radius_is_eq9_without_an_articulation_limit():
    # Without a neck contact nothing limits the bend; the 86 mm link in the
    # 116 mm tube fits only down to R = 0.1² / (2·0.030) − 0.043 = 0.1237 m (eq. (9)).
    scene = ballcage.load_scene({"kind": "drill-pipe", "pipe": {"neck_radius": 0.0}})
    assert studies.tightest_radius(scene) == pytest.approx(0.01 / 0.06 - 0.043, rel=1e-12)
    params = studies.drill_pipe_parameters(values_per_parameter=5)
    assert tuple(params) == studies.PARAMETER_NAMES
    assert params["stiffness"].values == pytest.approx((1e3, 1e4, 1e5, 1e6, 1e7))
    assert params["stiffness"].unit == "N/mm^2.2"
    assert params["damping"].values[0] == 0.0
    assert params["curvature_radius"].values[0] == pytest.approx(studies.tightest_radius())
    assert params["speed"].values[0] == pytest.approx(30.0) and params["speed"].values[-1] == pytest.approx(600.0)


# --------------------------------------------------------------------------- CLI


def test_cli_accuracy_writes_the_files_and_prints_a_line_per_run(tmp_path, capsys):
    scene = tmp_path / "spinner.toml"
    scene.write_text(ballcage.load_scene(spinner()).to_toml(), encoding="utf-8")
    out = tmp_path / "acc"
    code = cli.main(
        ["accuracy", str(scene), "--out", str(out), "--integrators", "symplectic-euler,rk4",
         "--steps", "4e-3,2e-3", "--steps", "rk4=4e-3", "--reference-integrator", "rk4", "--reference-dt", "1e-4"]
    )
    captured = capsys.readouterr()
    assert code == 0, captured.err
    for name in ("work_precision.parquet", "work_precision.png", "work_precision.md"):
        assert (out / name).is_file(), name
        assert name in captured.out
    progress = [line for line in captured.err.splitlines() if line.startswith("ballcage: accuracy ")]
    assert len(progress) == 3 + 2 + 1  # reference, check, second method, then the ladder runs
    table = pq.read_table(out / "work_precision.parquet")
    assert sorted({(r["integrator"], r["dt"]) for r in _rows(table, role="run")}) == [
        ("rk4", 4e-3), ("symplectic-euler", 2e-3), ("symplectic-euler", 4e-3)
    ]
    assert "ballcage accuracy" in (out / "work_precision.md").read_text(encoding="utf-8")


def test_cli_stability_writes_the_files_and_exits_0(tmp_path, capsys):
    out = tmp_path / "stab"
    code = cli.main(
        ["stability", "--out", str(out), "--integrators", "symplectic-euler", "--parameters", "key_mass",
         "--values-per-parameter", "2", "--duration", "0.004", "--bisections", "1", "--quiet"]
    )
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert captured.out == "" and captured.err == ""
    table = pq.read_table(out / "stability.parquet")
    assert table.num_rows == 2
    assert set(table.column("parameter").to_pylist()) == {"key_mass"}
    assert np.all(np.isfinite(table.column("max_stable_dt_s").to_numpy()))
    assert (out / "stability_key_mass.png").is_file()
    assert (out / "stability.md").is_file()
    assert float(table.schema.metadata[b"ballcage.tightest_radius_m"]) == pytest.approx(0.770, abs=1e-3)


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["accuracy", "--integrators", "rk5"], "--integrators rk5"),
        (["accuracy", "--steps", "-1e-5"], "--steps -1e-5"),
        (["accuracy", "--steps", "sdirk2=0"], "--steps 0"),
        (["accuracy", "--reference-dt", "-2e-6"], "--reference-dt -2e-6"),
        (["accuracy", "--reference-integrator", "euler"], "--reference-integrator euler"),
        (["accuracy", "--duration", "0"], "--duration 0"),
        (["stability", "--integrators", "rk4,magic"], "--integrators magic"),
        (["stability", "--parameters", "colour"], "--parameters colour"),
        (["stability", "--values-per-parameter", "1"], "--values-per-parameter 1"),
        (["stability", "--duration", "-0.01"], "--duration -0.01"),
    ],
)
def test_cli_bad_options_exit_2_naming_option_and_value(tmp_path, capsys, argv, needle):
    out = tmp_path / "never"
    code = cli.main([argv[0], "--out", str(out), *argv[1:]])
    err = capsys.readouterr().err
    assert code == 2
    assert err.startswith("ballcage: error: ") and needle in err
    assert len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_time_left_scales_the_cost_per_step_of_the_nearest_finished_run():
    from ballcage.studies.accuracy_run import _Outcome, _Plan, _time_left

    runs = [
        ("sdirk2", 1e-5, "reference"),
        ("sdirk2", 2e-5, "reference-check"),
        ("sdirk2", 1e-4, "run"),
        ("rk4", 1e-6, "run"),
    ]
    plan = _Plan(runs, [], 1e-3, 1.0, [])
    done = [_Outcome("sdirk2", 1e-5, "reference", {}, 10.0, {}, False, None)]
    # The sdirk2 runs take 10 s × 1e-5 / dt (half and a tenth of the steps); rk4 has no finished
    # run, so the reference's cost per step applies to its 10× more steps.
    assert _time_left(plan, done) == pytest.approx(5.0 + 1.0 + 100.0)
    done.append(_Outcome("sdirk2", 2e-5, "reference-check", {}, 4.0, {}, False, None))
    # Now the 1e-4 run scales the nearer 2e-5 run: 4 s × 0.2.
    assert _time_left(plan, done) == pytest.approx(0.8 + 100.0)
