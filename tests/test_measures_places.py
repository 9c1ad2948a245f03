"""The measures behind the well-conditioned comparison rows, on small tables built by hand with known answers.

- `ballcage.measures.shape`: the most deformed joint (the hinge with the largest mean bend over a window) and the
  included angle projected on the bend plane;
- `ballcage.measures.places`: the tube force along the chain and the key-force peak's hinge, time and drive stage;
- the sweep plug-in (`ballcage.measures.DRILL_PIPE`) and the comparison agree on the new quantities.
"""

from __future__ import annotations

import math

import numpy as np
import pyarrow as pa
import pytest

import ballcage
from ballcage import paper
from ballcage.measures import DRILL_PIPE, QUANTITIES
from ballcage.measures import places, shape
from ballcage.paper import places as paper_places

#: The paper scene at 100 rpm (drive.ramp 0.3 s), 0.6 s at 50 ms frames: its last revolution is the whole run.
SHORT = ["simulation.duration=0.6", "simulation.output_interval=0.05"]
TIMES = np.round(np.arange(0.0, 0.6 + 0.025, 0.05), 12)


def _axis(inclination_deg: float, azimuth_deg: float) -> np.ndarray:
    return shape.link_axes(np.array(inclination_deg), np.array(azimuth_deg))


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    return math.degrees(math.acos(float(np.clip(np.dot(a, b), -1.0, 1.0))))


# --------------------------------------------------------------------------- the included angle on the bend plane


def test_link_axes_follow_eq4_in_the_world_frame():
    # Straight down, then 90 deg toward +x (the bend direction) and toward +y (out of the bend plane).
    assert _axis(0.0, 0.0) == pytest.approx([0.0, 0.0, -1.0], abs=1e-15)
    assert _axis(90.0, 0.0) == pytest.approx([1.0, 0.0, 0.0], abs=1e-15)
    assert _axis(90.0, 90.0) == pytest.approx([0.0, 1.0, 0.0], abs=1e-15)


@pytest.mark.parametrize("fold_azimuth", [0.0, 30.0, 60.0, 90.0])
def test_an_out_of_plane_fold_shows_a_smaller_projected_bend(fold_azimuth):
    # Link k hangs straight down; link k+1 folds 10 deg in the direction `fold_azimuth` from the bend plane. On the
    # bend plane its axis leans atan(tan 10 deg cos(azimuth)) from the vertical: all of the fold in the plane (0 deg),
    # none of it out of the plane (90 deg).
    upper, lower = _axis(0.0, 0.0), _axis(10.0, fold_azimuth)
    assert _angle(upper, lower) == pytest.approx(10.0, abs=1e-12)
    expected = 180.0 - math.degrees(math.atan(math.tan(math.radians(10.0)) * math.cos(math.radians(fold_azimuth))))
    assert float(shape.projected_included_angle(upper, lower)) == pytest.approx(expected, abs=1e-9)
    assert float(shape.projected_included_angle(upper, lower)) >= 180.0 - 10.0 - 1e-9


def test_the_projected_angle_of_an_in_plane_chain_is_its_3d_angle_and_ignores_the_direction():
    # Two links in the bend plane, 40 and 52 deg from the vertical: 168 deg either way round.
    a, b = _axis(40.0, 0.0), _axis(52.0, 0.0)
    for upper, lower in ((a, b), (b, a)):
        assert float(shape.projected_included_angle(upper, lower)) == pytest.approx(168.0, abs=1e-9)
    # Across the vertical (azimuth 180: the axis leans toward -x): 5 + 3 deg of bend.
    assert float(shape.projected_included_angle(_axis(5.0, 0.0), _axis(3.0, 180.0))) == pytest.approx(172.0, abs=1e-9)


def _run(links: dict[str, list], extra: dict[str, pa.Table] | None = None, overrides: list[str] = SHORT) -> ballcage.Run:
    scene = paper.paper_scene(overrides)
    return ballcage.Run({"links": pa.table(links), **(extra or {})}, scene.to_toml())


def _lower_connector(times: np.ndarray, axis_about_y_deg: float) -> pa.Table:
    """A bodies table holding only the lower connector, its x axis turned by `axis_about_y_deg` about +y (toward -z)."""
    half = math.radians(axis_about_y_deg) / 2.0
    n = len(times)
    return pa.table(
        {
            "t": times,
            "part": ["lower"] * n,
            "quat_w": [math.cos(half)] * n,
            "quat_x": [0.0] * n,
            "quat_y": [math.sin(half)] * n,
            "quat_z": [0.0] * n,
        }
    )


def test_projected_angles_take_the_last_hinge_from_the_lower_connector():
    # Two links in the bend plane at 70 and 80 deg of inclination; the lower connector's x axis turned 10 deg about
    # +y, to (cos 10, 0, -sin 10): 80 deg from the downward vertical, in line with link 2.
    times = np.array([0.0, 0.05])
    links = {
        "t": [0.0, 0.0, 0.05, 0.05],
        "link": [1, 2, 1, 2],
        "inclination_deg": [70.0, 80.0, 70.0, 80.0],
        "azimuth_deg": [0.0, 0.0, 0.0, 0.0],
    }
    run = _run(links, {"bodies": _lower_connector(times, 10.0)})
    angles = shape.projected_angles(run, times)
    assert angles.shape == (2, 2)
    assert angles[:, 0] == pytest.approx([170.0, 170.0], abs=1e-9)  # hinge 1: link 1 / link 2
    assert angles[:, 1] == pytest.approx([180.0, 180.0], abs=1e-9)  # hinge 2: link 2 / connector, both at 80 deg
    # Without the bodies table the last hinge has no next axis.
    bare = shape.projected_angles(_run(links), times)
    assert bare[:, 0] == pytest.approx(angles[:, 0]) and np.isnan(bare[:, 1]).all()


# --------------------------------------------------------------------------- the most deformed joint


def test_rank_mean_bends_orders_the_hinges_by_their_mean_over_the_window():
    t = np.repeat([0.0, 0.1, 0.2, 0.3], 3)
    hinge = np.tile([1, 2, 3], 4)
    # Hinge 2 leads before 0.15 s (20 deg), hinge 3 after; hinge 1 has a NaN frame, skipped.
    bend = np.array([5.0, 20.0, 1.0, np.nan, 20.0, 1.0, 5.0, 2.0, 12.0, 5.0, 2.0, 12.0])
    late = shape.rank_mean_bends(t, hinge, bend, 0.15, 0.3)
    assert late is not None and (late.start, late.end, late.frames) == (0.2, 0.3, 2)
    assert late.order == [3, 1, 2] and late.winner == 3 and late.runner_up == 1
    assert late.margin == pytest.approx(7.0)
    whole = shape.rank_mean_bends(t, hinge, bend, 0.0, 0.3)
    assert whole is not None and whole.winner == 2 and whole.mean_bend[1] == pytest.approx(5.0)
    assert whole.margin == pytest.approx(11.0 - 6.5)
    assert shape.rank_mean_bends(t, hinge, bend, 0.5, 0.9) is None
    # A tie goes to the lower hinge; one hinge has no runner-up.
    tie = shape.rank_mean_bends(np.zeros(2), np.array([7, 4]), np.array([3.0, 3.0]), 0.0, 0.0)
    assert tie is not None and tie.winner == 4 and tie.margin == 0.0
    one = shape.rank_mean_bends(np.zeros(1), np.array([7]), np.array([3.0]), 0.0, 0.0)
    assert one is not None and one.winner == 7 and one.runner_up is None and math.isnan(one.margin)


def test_rank_bends_reads_the_bend_from_the_links_included_angle():
    links = pa.table({"t": [0.0, 0.0, 0.1, 0.1], "link": [1, 2, 1, 2], "included_angle_deg": [172.0, 171.0, 170.0, 175.0]})
    ranking = shape.rank_bends(links, 0.0, 0.1)
    assert ranking is not None and ranking.mean_bend == pytest.approx({1: 9.0, 2: 7.0}) and ranking.winner == 1


# --------------------------------------------------------------------------- where the forces are largest


def _profile_links() -> dict[str, list]:
    """Four links over 13 frames: mean tube forces 0, 900, 1000, 450 N at inclinations 10, 30, 50, 70 deg.

    The frames' forces swing +-100 N about the mean; the impulse columns (the engine's integral over its own
    steps) grow at the mean, so the time mean is the mean whatever the frames show.
    """
    means = {1: 0.0, 2: 900.0, 3: 1000.0, 4: 450.0}
    names = ("t", "link", "tube_normal", "tube_tangential", "inclination_deg", "tube_normal_impulse", "tube_tangential_impulse")
    cols: dict[str, list] = {c: [] for c in names}
    for f, t in enumerate(TIMES):
        for k, mean in means.items():
            swing = 100.0 if (f % 2 and mean) else (-100.0 if mean else 0.0)
            incl = 20.0 * k - 10.0 + (1.0 if f % 2 else -1.0)
            for name, v in zip(cols, (t, k, mean + swing, 0.1 * mean, incl, mean * t, 0.1 * mean * t)):
                cols[name].append(v)
    return cols


def test_tube_profile_finds_the_largest_link_its_neighbours_and_link_shares():
    profile = places.tube_profile(_run(_profile_links()))
    assert profile is not None
    assert profile.normal_mean == pytest.approx({1: 0.0, 2: 900.0, 3: 1000.0, 4: 450.0})
    assert profile.largest == 3
    assert profile.inclination[3] == pytest.approx(50.0, abs=0.1)
    assert profile.near() == [2, 3]  # 900 N is 90 % of 1000 N
    assert profile.near(0.95) == [3] and profile.near(0.4) == [2, 3, 4]
    low, high = profile.span(0.4)
    assert (low, high) == pytest.approx((30.0, 70.0), abs=0.1)
    assert profile.share(4) == pytest.approx(0.45) and profile.share(1) == 0.0


def test_the_inclination_row_and_the_summary_column_agree():
    cols = _profile_links()
    n = len(cols["t"])
    cols |= {"azimuth_deg": [0.0] * n, "included_angle_deg": [178.0] * n, "radial_offset": [0.0] * n}
    cols |= {"offset_outward": [0.0] * n, "offset_lateral": [0.0] * n}
    run = _run(cols)
    row = {r["key"]: r for r in paper.comparison(run).to_pylist()}["tube_normal_mean_max_inclination_deg"]
    assert row["ours"] == pytest.approx(50.0, abs=0.1) and row["paper"] is None
    assert "largest at link 3 (1000 N mean" in row["note"] and "0 N at joint 12" in row["note"]
    assert DRILL_PIPE(run)["tube_normal_mean_max_inclination_deg"] == row["ours"]
    assert QUANTITIES["tube_normal_mean_max_inclination_deg"][0] == "deg"


def _keys_and_drive() -> dict[str, pa.Table]:
    """Two hinges of two keys; the largest outer force 9 kN at hinge 1 key 1, t = 0.5 s (after the 0.3 s ramp), the
    largest during the ramp 7 kN at hinge 0 key 1, t = 0.1 s; a drive turning at 100 rpm from t = 0."""
    cols: dict[str, list] = {c: [] for c in ("t", "hinge", "key", "outer_normal")}
    for t in TIMES:
        for h in (0, 1):
            for j in (0, 1):
                force = 1000.0 * (1 + h + j)
                if (h, j, t) == (1, 1, 0.5):
                    force = 9000.0
                if (h, j, t) == (0, 1, 0.1):
                    force = 7000.0
                for name, v in zip(cols, (t, h, j, force)):
                    cols[name].append(v)
    speed = 100.0 * 2.0 * math.pi / 60.0
    drive = pa.table({"t": TIMES, "input_speed": np.full(len(TIMES), speed)})
    return {"keys": pa.table(cols), "drive": drive}


def test_peak_place_gives_the_hinge_key_time_stage_and_connector_angle():
    run = _run({"t": [0.0], "link": [1]}, _keys_and_drive())
    place = places.peak_place(run, "outer_normal")
    assert place is not None
    assert (place.value, place.ids, place.t) == (9000.0, (1, 1), 0.5)
    assert place.stage == "steady rotation" and place.ramp == 0.3
    assert place.angle_deg == pytest.approx(300.0, abs=1e-9)  # 100 rpm for 0.5 s: 5/6 of a turn
    value, ids, t = place.during_ramp
    assert (value, ids, t) == (7000.0, (0, 1), 0.1)
    assert place.by_hinge == {0: 7000.0, 1: 9000.0}
    # The note locates it and says where the paper's is.
    text = paper_places.key_place_text(place)
    assert "at hinge 01 key 1, t = 0.5 s, during the steady rotation" in text
    assert "the largest during the acceleration: 7000 N at hinge 00 key 1, t = 0.1 s" in text
    assert "joint 1# during the acceleration" in text
    assert places.peak_place(_run({"t": [0.0], "link": [1]}), "outer_normal") is None


def test_a_peak_during_the_ramp_is_in_the_acceleration():
    tables = _keys_and_drive()
    keys = tables["keys"]
    force = keys.column("outer_normal").to_numpy().copy()
    force[force == 9000.0] = 1.0
    tables["keys"] = keys.set_column(keys.schema.get_field_index("outer_normal"), "outer_normal", pa.array(force))
    place = places.peak_place(_run({"t": [0.0], "link": [1]}, tables), "outer_normal")
    assert place is not None and place.t == 0.1 and place.stage == "acceleration"
    assert place.angle_deg == pytest.approx(60.0, abs=1e-9)
