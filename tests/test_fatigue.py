"""Fatigue at the links' critical sections (docs/model.md §8.6), against hand calculations.

- the free-body cut (`ballcage.measures.sections`) of a link held still under known contact forces gives the
  hand statics of the piece beyond each section, its weight included; a link accelerating with no contact
  carries its piece's d'Alembert force;
- rainflow through `count_cycles` (the ``rainflow`` package) gives ASTM E1049's counts of its example;
- Miner's sum of a constant-amplitude history is N/N_f with Basquin's N_f; Goodman's equivalent amplitude of a
  cycle with a mean, and with a steady shear, is the closed form;
- ``ballcage run`` writes fatigue.parquet with units and no NaN and ends with the shortest life.
"""

from __future__ import annotations

import math
from collections import defaultdict

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq
import pytest

from ballcage.measures.fatigue import FATIGUE_COLUMNS, SnCurve, count_cycles, miner_sum
from ballcage.measures.sections import link_sections, section_loads
from ballcage.run import Run
from ballcage.scene import default_scene

MASS, PITCH, G = 8.010, 0.2, 9.8  # the default link mass [kg], pitch [m], gravity [m/s²]
NECK_X = PITCH / 2 - 0.030  # the default neck section, 30 mm behind the head's hinge centre [m]
SEAT_X = -PITCH / 2 + 0.032  # the default seat section [m]


def _bodies(times: list[float], vel_y: list[float]) -> pa.Table:
    """Link 1 (body ``link01``) at the origin, its axis along world x (identity pose), moving along y at `vel_y`."""
    n = len(times)
    cols = {
        "t": times, "body": ["link01"] * n, "link": pa.array([1] * n, pa.uint32()),
        "pos_x": [0.0] * n, "pos_y": [0.0] * n, "pos_z": [0.0] * n,
        "quat_w": [1.0] * n, "quat_x": [0.0] * n, "quat_y": [0.0] * n, "quat_z": [0.0] * n,
        "vel_x": [0.0] * n, "vel_y": vel_y, "vel_z": [0.0] * n,
        "angvel_x": [0.0] * n, "angvel_y": [0.0] * n, "angvel_z": [0.0] * n,
    }  # fmt: skip
    return pa.table(cols)


#: (pair id, feature, hinge, the link is body a?, point, normal, normal force, tangential force on b)
CONTACTS = [
    (0, "inner-race", 1, True, (0.1, 0.0315, 0.0), (0.0, 0.0, 1.0), 1000.0, (0.0, 0.0, 0.0)),
    (1, "cage-head", 1, False, (0.1, 0.0, -0.0315), (0.0, 1.0, 0.0), 500.0, (200.0, 0.0, 0.0)),
    (2, "outer-race", 0, True, (-0.1, 0.0, 0.0315), (0.0, 1.0, 0.0), 300.0, (0.0, 0.0, 0.0)),
    (3, "tube", None, False, (0.09, 0.0, -0.043), (0.0, 0.0, 1.0), 700.0, (0.0, 0.0, 0.0)),
    (4, "tube", None, False, (-0.095, 0.0, 0.043), (0.0, 0.0, -1.0), 400.0, (0.0, 0.0, 0.0)),
]


def _contacts(times: list[float]) -> tuple[pa.Table, pa.Table]:
    rows: dict[str, list] = defaultdict(list)
    for t in times:
        for pid, _, _, a_is_link, p, n, fn, ft in CONTACTS:
            rows["t"].append(t)
            rows["pair_id"].append(pid)
            rows["body_a"].append("link01" if a_is_link else "other")
            rows["body_b"].append("other" if a_is_link else "link01")
            rows["normal_force"].append(fn)
            for i, axis in enumerate("xyz"):
                rows[f"point_{axis}"].append(p[i])
                rows[f"normal_{axis}"].append(n[i])
                rows[f"tangential_force_{axis}"].append(ft[i])
    contacts = pa.table(dict(rows))
    contacts = contacts.set_column(
        contacts.schema.get_field_index("body_a"), "body_a", contacts.column("body_a").dictionary_encode()
    )
    pairs = pa.table({
        "pair_id": [c[0] for c in CONTACTS], "feature": [c[1] for c in CONTACTS],
        "hinge": pa.array([c[2] for c in CONTACTS], pa.uint32()),
    })  # fmt: skip
    return contacts, pairs


def _run(vel_y: list[float], with_contacts: bool = True) -> Run:
    times = [0.0, 0.001, 0.002][: len(vel_y)]
    contacts, pairs = _contacts(times)
    if not with_contacts:
        contacts = contacts.slice(0, 0)
    tables = {"bodies": _bodies(times, vel_y), "contacts": contacts, "pairs": pairs}
    return Run(tables, default_scene().to_toml())


def _force_on_link(c: tuple) -> np.ndarray:
    _, _, _, a_is_link, _, n, fn, ft = c
    f = fn * np.array(n) + np.array(ft)
    return -f if a_is_link else f


def _hand_statics(section_x: float, side: int, chosen: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """What the +x material exerts on the −x material at `section_x`, from the contacts `chosen` and the
    weight of the free body (the uniform link's piece beyond the cut on `side`), by hand."""
    lo, hi = (section_x, PITCH / 2) if side > 0 else (-PITCH / 2, section_x)
    weight = np.array([0.0, 0.0, -MASS * (hi - lo) / PITCH * G])
    centre = np.array([(lo + hi) / 2, 0.0, 0.0])
    s = np.array([section_x, 0.0, 0.0])
    force, moment = weight.copy(), np.cross(centre - s, weight)
    for i in chosen:
        f = _force_on_link(CONTACTS[i])
        force += f
        moment += np.cross(np.array(CONTACTS[i][4]) - s, f)
    return (force, moment) if side > 0 else (-force, -moment)


@pytest.mark.parametrize(
    ("name", "x", "side", "chosen"),
    [
        ("neck", NECK_X, 1, [0, 1]),  # the head's joint contacts only: the tube touches the seat's tube, not the head
        ("body", 0.0, 1, [0, 1, 3]),  # the downhole half: the head's contacts and the tube contact at x = 0.09
        ("seat", SEAT_X, -1, [2, 4]),  # the seat's joint contact and the tube contact behind the cut
    ],
)
def test_the_cut_of_a_link_held_still_gives_the_hand_statics_of_the_piece_beyond_it(name, x, side, chosen):
    run = _run([0.0, 0.0, 0.0])
    loads = section_loads(run)
    sec = next(s for s in link_sections(run) if s.name == name)
    assert (sec.x, sec.side) == pytest.approx((x, side))
    force, moment = _hand_statics(x, side, chosen)
    assert loads.force[name][1, 0] == pytest.approx(force, abs=1e-9)
    assert loads.moment[name][1, 0] == pytest.approx(moment, abs=1e-9)
    # the neck by hand in full: N = 200 N, T = −1000·0.0315 + 500·0.0315 N·m, bending from the key and the cage
    if name == "neck":
        w = MASS * 0.03 / PITCH * G
        assert loads.force[name][1, 0] == pytest.approx([200.0, 500.0, -1000.0 - w], abs=1e-9)
        assert loads.moment[name][1, 0] == pytest.approx([-15.75, 30.0 - 6.3 + 0.015 * w, 15.0], abs=1e-9)


def test_a_link_accelerating_without_contact_carries_its_pieces_dalembert_force():
    a = 50.0  # m/s² along world y, constant: vel = a·t
    run = _run([0.0, a * 0.001, a * 0.002], with_contacts=False)
    loads = section_loads(run)
    m_neck = MASS * 0.03 / PITCH
    # the head's piece is pulled along by the rest: the −x material exerts m·a on it, so it exerts −m·a back
    assert loads.force["neck"][1, 0] == pytest.approx([0.0, -m_neck * a, -m_neck * G], abs=1e-9)
    # the moment of that force about the section centre: the piece's centre 15 mm beyond it
    assert loads.moment["neck"][1, 0, 2] == pytest.approx(-0.015 * m_neck * a, abs=1e-9)


def test_rainflow_gives_the_astm_e1049_counts_of_its_example():
    # ASTM E1049-85 (2017), §5.4.4 and X1: the sequence −2, 1, −3, 5, −1, 3, −4, 4, −2
    cycles = count_cycles([-2, 1, -3, 5, -1, 3, -4, 4, -2])
    by_range: dict[float, float] = defaultdict(float)
    for rng, _, count in cycles:
        by_range[float(rng)] += count
    assert dict(by_range) == {3.0: 0.5, 4.0: 1.5, 6.0: 0.5, 8.0: 1.0, 9.0: 0.5}


CURVE = SnCurve(ultimate=980e6, coefficient=1.47e9, exponent=-0.087)


@pytest.mark.parametrize("mean", [0.0, 245e6])
def test_miners_sum_of_a_constant_amplitude_history_is_n_over_n_f(mean):
    amplitude, n = 200e6, 1000
    history = [mean - amplitude, mean + amplitude] * n + [mean - amplitude]
    cycles = count_cycles(history)
    assert cycles[:, 2].sum() == pytest.approx(n)
    reversed_amplitude = amplitude / (1 - mean / 980e6)  # Goodman by hand
    n_f = 0.5 * (reversed_amplitude / 1.47e9) ** (1 / -0.087)  # Basquin by hand
    assert miner_sum(cycles, CURVE) == pytest.approx(n / n_f, rel=1e-12)
    assert miner_sum(cycles, CURVE, scf=2.0) == pytest.approx(
        n / (0.5 * (2 * reversed_amplitude / 1.47e9) ** (1 / -0.087)), rel=1e-12
    )


def test_goodman_gives_the_closed_form_equivalent_amplitude():
    assert CURVE.reversed_amplitude(200e6, 245e6) == pytest.approx(200e6 / 0.75, rel=1e-15)
    assert CURVE.reversed_amplitude(200e6, -300e6) == pytest.approx(200e6)  # no credit for a compressive mean
    assert math.isinf(CURVE.reversed_amplitude(200e6, 980e6))
    # a steady shear τ raises the mean to √(σ_m² + 3τ²): here √3·τ = 490 MPa, half of σ_u
    tau = 490e6 / math.sqrt(3)
    one_cycle = np.array([[400e6, 0.0, 1.0]])
    n_f = 0.5 * ((200e6 / 0.5) / 1.47e9) ** (1 / -0.087)
    assert miner_sum(one_cycle, CURVE, shear_mean=tau) == pytest.approx(1 / n_f, rel=1e-12)


def test_ballcage_run_writes_the_fatigue_table_and_ends_with_the_shortest_life(tmp_path, capsys):
    from ballcage.cli import main

    out = tmp_path / "run"
    assert main(["run", "--out", str(out), "--set", "simulation.duration=0.33"]) == 0  # counted over 0.3–0.33 s
    printed = capsys.readouterr().out
    table = pq.read_table(out / "fatigue.parquet")
    assert table.column_names == [c[0] for c in FATIGUE_COLUMNS]
    assert table.schema.field("hours_to_failure").metadata[b"unit"] == b"h"
    assert table.num_rows == 3 * 12
    for name in table.column_names[3:]:
        assert not pc.any(pc.is_nan(table.column(name))).as_py(), name
        assert table.column(name).null_count == 0 or name in ("damage_per_revolution", "hours_to_failure"), name
    assert (out / "fatigue.png").stat().st_size > 0
    last = [line for line in printed.splitlines() if line.startswith("ballcage: ")]
    margin = next(i for i, line in enumerate(last) if "smallest contact-pressure margin" in line)
    fatigue = next(i for i, line in enumerate(last) if "shortest fatigue life" in line)
    assert margin < fatigue and "at the neck of link" in last[fatigue]


@pytest.mark.parametrize(
    ("override", "reason"),
    [
        ("fatigue.neck_scf=0.5", "at least 1"),
        ("fatigue.strength_exponent=0.1", "must lie in (-1, 0)"),
        ("fatigue.head_bore_diameter=0.04", "smaller than the neck's diameter"),
        ("fatigue.neck_offset=0.3", "shorter than the link"),
    ],
)
def test_a_section_or_curve_that_cannot_be_is_refused_naming_the_field(override, reason):
    import ballcage

    with pytest.raises(ballcage.SceneError) as caught:
        default_scene([override])
    key, value = override.split("=")
    assert (caught.value.path, float(caught.value.value)) == (key, float(value))
    assert reason in caught.value.reason


def test_an_ideal_cv_run_writes_no_fatigue_table_and_says_why(tmp_path, capsys):
    from ballcage.cli import main

    out = tmp_path / "run"
    out.mkdir()
    (out / "fatigue.parquet").write_bytes(b"an earlier run's")
    args = ["run", "--out", str(out), "--overwrite", "--set", 'pipe.hinge="ideal-cv"', "--set", "simulation.duration=0.02"]
    assert main(args) == 0
    assert "no fatigue table: pipe.hinge = 'ideal-cv'" in capsys.readouterr().out
    assert not (out / "fatigue.parquet").exists()
