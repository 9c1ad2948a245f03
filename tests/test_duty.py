"""Contact pressure, wear and where the power goes (`ballcage.duty`, the wear, hinges and drive tables).

The Hertz formulas themselves are checked against textbook cases in Rust
(crates/ballcage-core/src/force/hertz.rs) and the energy balance in
crates/ballcage-core/tests/energy_balance.rs; here: the tables a user reads.
"""

from __future__ import annotations

import math

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pytest

import ballcage
from ballcage.scene import default_scene
from ballcage.duty import loss_breakdown, margin_line, pressure_at, smallest_margin, wear_line, write_loss_figure

#: 0.32 s of the paper's pipe with 3 joints: past the 0.3 s ramps, so the drive runs at constant speed.
SHORT = ["pipe.joints=3", "simulation.duration=0.32", "record.summary_window=[0.2, 0.32]"]


@pytest.fixture(scope="module")
def run() -> ballcage.Run:
    return ballcage.simulate(default_scene(SHORT), progress=False)


def _wear_rows(**columns: list) -> pa.Table:
    n = len(columns["feature"])
    base = {
        "pair": [f"p{i}" for i in range(n)],
        "link": [None] * n,
        "hinge": [1] * n,
        "key": [None] * n,
        "window_start": [0.0] * n,
        "window_end": [1.0] * n,
        "pressure_peak_t": [0.5] * n,
        "hours_per_100um": [None] * n,
        "allowable_pressure": [1.0e9] * n,
    }
    base.update(columns)
    return pa.table(base)


def test_the_smallest_margin_and_the_loss_groups_by_hand():
    wear = _wear_rows(
        feature=["tube", "inner-race", "outer-race", "window", "cage-head"],
        friction_power=[10.0, 3.0, 2.0, 1.0, 4.0],
        pressure_peak=[2e9, 4e9, None, 1e9, 5e7],
        pressure_peak_force=[1e3, 8e3, None, 1e3, 1e3],
        pressure_margin=[0.5, 0.25, None, 1.0, 20.0],
    )
    assert smallest_margin(wear)["feature"] == "inner-race"
    assert loss_breakdown(wear) == {"tube": 10.0, "key–race": 5.0, "key–window": 1.0, "cage": 4.0, "neck": 0.0}
    # p0 goes as F^(1/3): 8 kN → 4 GPa, so 1 kN → 2 GPa and 27 kN → 6 GPa
    assert pressure_at(wear, "inner-race", 1e3) == pytest.approx(2e9, rel=1e-12)
    assert pressure_at(wear, "inner-race", 27e3) == pytest.approx(6e9, rel=1e-12)
    assert pressure_at(wear, "outer-race", 1e3) is None
    line = margin_line(wear)
    assert line is not None and "0.25 (beyond the static limit)" in line and "4000 MPa" in line
    assert "friction loss 20 W (tube 50 %, key–race 25 %" in (wear_line(wear) or "")


def test_a_wear_table_is_required():
    with pytest.raises(ballcage.InputError, match="not a wear table"):
        loss_breakdown(pa.table({"x": [1.0]}))


def test_the_first_hinge_takes_the_drive_torque(run):
    # After the ramp the upper connector turns at constant speed: the drive's torque is exactly what
    # hinge 0's contacts take from it (the connector touches nothing else), with the opposite sign.
    drive, hinges = run.tables["drive"], run.tables["hinges"]
    t = drive.column("t").to_numpy()
    steady = t > 0.3 + 1e-9
    h0 = hinges.filter(pc.equal(hinges.column("hinge"), 0))
    assert h0.column("t").to_numpy()[steady] == pytest.approx(t[steady])
    torque_in = h0.column("torque_in").to_numpy()[steady]
    assert torque_in == pytest.approx(drive.column("input_torque").to_numpy()[steady], rel=1e-9)
    assert torque_in.mean() > 1000.0  # the 1.8 kN·m load is through the chain
    power_in = h0.column("power_in").to_numpy()[steady]
    assert power_in == pytest.approx(drive.column("input_power").to_numpy()[steady], rel=1e-9)


def test_the_last_hinge_hands_the_load_its_resisting_moment(run):
    # The lower connector turns against the resisting moment (ramping to 1.8 kN·m until 0.3 s) and touches
    # only the last hinge: averaged over the window its spin barely changes (I·Δω/T < 1 N·m), so the torque
    # the last hinge hands it is the resisting moment's mean.
    hinges, drive = run.tables["hinges"], run.tables["drive"]
    t = hinges.column("t").to_numpy()
    hinge = hinges.column("hinge").to_numpy()
    last = (t >= 0.2 - 1e-12) & (hinge == hinge.max())
    td = drive.column("t").to_numpy()
    applied = drive.column("output_torque").to_numpy()[td >= 0.2 - 1e-12].mean()
    assert applied > 1500.0
    assert hinges.column("torque_out").to_numpy()[last].mean() == pytest.approx(applied, rel=0.01)
    # and the first hinge's torque is larger by what the links rub off on the tube
    first = (t >= 0.2 - 1e-12) & (hinge == 0)
    assert hinges.column("torque_in").to_numpy()[first].mean() > 1.01 * applied


def test_the_wear_table_integrates_the_frames_friction(run):
    # The wear table integrates every step; the drive table samples the same friction power per frame.
    drive, wear = run.tables["drive"], run.tables["wear"]
    t = drive.column("t").to_numpy()
    window = (t > 0.2 + 1e-9) & (t <= 0.32 + 1e-9)
    groups = {"tube": "friction_tube", "key–race": "friction_key_race", "cage": "friction_cage"}
    losses = loss_breakdown(wear)
    for group, column in groups.items():
        sampled = drive.column(column).to_numpy()[window].mean()
        assert losses[group] == pytest.approx(sampled, rel=0.05), group
    assert losses["tube"] > 100.0 and losses["key–race"] > 10.0


def test_the_drive_tables_friction_split_matches_the_wear_table(run):
    # losses_curvature.png splits each sweep case's loss from its drive table: the cases record no wear table.
    from ballcage.paper.section4_figures import friction_split

    split, losses = friction_split(run), loss_breakdown(run.tables["wear"])
    assert split is not None and list(split) == list(losses)
    for group in ("tube", "key–race", "cage"):
        assert split[group] == pytest.approx(losses[group], rel=0.05), group


def test_window_pressure_is_hertz_ball_on_a_flat(run):
    # Ball (r = 7.5 mm) on a flat: p0 = (6 F E*² / (π³ R²))^(1/3), E* of bearing steel on 35CrMo.
    s = run.scene
    e = [float(s.value(f"materials.{m}.youngs_modulus")) for m in ("key_steel", "pipe_steel")]
    nu = [float(s.value(f"materials.{m}.poisson_ratio")) for m in ("key_steel", "pipe_steel")]
    e_star = 1.0 / sum((1 - n * n) / y for y, n in zip(e, nu, strict=True))
    r = float(s.value("pipe.ball_keys.ball_radius"))
    keys = run.tables["keys"]
    force = keys.column("window_normal").to_numpy()
    p0 = keys.column("window_pressure").to_numpy()
    touching = force > 1.0
    assert touching.sum() > 20
    hertz = (6 * force * e_star**2 / (math.pi**3 * r**2)) ** (1 / 3)
    # The most loaded face carries between half and all of the key's window force.
    assert np.all(p0[touching] <= hertz[touching] * (1 + 1e-9))
    assert np.all(p0[touching] >= hertz[touching] * 0.5 ** (1 / 3) * (1 - 1e-9))
    assert np.mean(np.isclose(p0[touching], hertz[touching], rtol=1e-9)) > 0.9


def test_archard_volume_and_margin_follow_the_scene(run):
    wear = run.tables["wear"].to_pylist()
    s = run.scene
    k = {"tube": float(s.value("wear.tube_coefficient")), "internal": float(s.value("wear.internal_coefficient"))}
    h_pipe = float(s.value("materials.pipe_steel.hardness"))
    for r in wear:
        coefficient = k["tube"] if r["feature"] == "tube" else k["internal"]
        assert r["wear_volume"] == pytest.approx(coefficient * r["normal_sliding"] / h_pipe, rel=1e-12, abs=1e-30)
        if r["pressure_peak"] is not None:
            assert r["pressure_margin"] == pytest.approx(r["allowable_pressure"] / r["pressure_peak"], rel=1e-12)
    assert any(r["normal_sliding"] > 0 for r in wear)


def test_run_reports_the_margin_and_the_loss_and_draws_the_breakdown(run, tmp_path):
    line = margin_line(run.tables["wear"])
    assert line is not None and line.startswith("smallest contact-pressure margin")
    path = write_loss_figure(run.tables["wear"], tmp_path / "losses.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
