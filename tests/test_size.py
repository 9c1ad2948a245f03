"""Link sizing, the paper's eq. (8)–(9) both ways: `ballcage.sizing` and ``ballcage size``.

Hand values: L = 2·√(2(D − d)(R + d/2)).
- the paper's pipe, R = 1500, D = 116, d = 86 mm: 2·√(2·30·1543) = 608.54 mm;
- R = 1000, D = 100, d = 50 mm: 2·√(2·50·1025) = √410000 = 640.31 mm, and back,
  (2R + D)² − L² = 2100² − 410000 = 2000², d = (D − 2R + 2000)/2 = 50 mm;
- L = 600, D = 116, d = 86 mm: R = 300²/(2·30) − 43 = 1457 mm.
"""

from __future__ import annotations

import math

import pytest

import ballcage
from ballcage import _native, sizing
from ballcage.cli import main
from ballcage.scene import default_scene


def _size(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(["size", *args])
    out, err = capsys.readouterr()
    return code, out, err


def test_the_issue_example_prints_608_54(capsys):
    code, out, err = _size(capsys, "--radius", "1500", "--tube-id", "116", "--joint-od", "86")
    assert (code, out, err) == (0, "608.54\n", "")
    assert ballcage.longest_link(1.5, 0.116, 0.086) == pytest.approx(2 * math.sqrt(2 * 0.030 * 1.543), rel=1e-14)


def test_a_second_hand_case_all_three_ways(capsys):
    assert ballcage.longest_link(1.0, 0.1, 0.05) == pytest.approx(math.sqrt(0.41), rel=1e-14)
    assert ballcage.largest_link_diameter(math.sqrt(0.41), 1.0, 0.1) == pytest.approx(0.05, rel=1e-12)
    assert ballcage.tightest_radius_for_link(0.6, 0.116, 0.086) == pytest.approx(1.457, rel=1e-14)
    assert _size(capsys, "--radius", "1000", "--tube-id", "100", "--joint-od", "50")[1] == "640.31\n"
    assert _size(capsys, "--length", "640.3124237", "--radius", "1000", "--tube-id", "100")[1] == "50.00\n"
    assert _size(capsys, "--length", "600", "--tube-id", "116", "--joint-od", "86")[1] == "1457.00\n"


@pytest.mark.parametrize(
    ("radius", "tube", "joint"),
    [(1.5, 0.116, 0.086), (1.0, 0.1, 0.05), (0.3, 0.116, 0.02), (25.0, 0.2, 0.19), (0.06, 0.116, 0.1)],
)
def test_round_trips(radius, tube, joint):
    length = sizing.longest_link(radius, tube, joint)
    assert sizing.tightest_radius_for_link(length, tube, joint) == pytest.approx(radius, rel=1e-9)
    assert sizing.largest_link_diameter(length, radius, tube) == pytest.approx(joint, rel=1e-9)


def test_a_short_link_fits_every_bend_and_a_long_one_none():
    # Eq. (9) would give 0.01²/(2·0.03) − 0.043 < 0: the tube's own tightest bend, D/2, is the answer.
    assert sizing.tightest_radius_for_link(0.01, 0.116, 0.086) == 0.058
    # 2·√(2RD) = 2·√(2·1.5·0.116) = 1.17983 m is the longest link of no diameter.
    with pytest.raises(ValueError, match=r"link_length = 1.2 m: .*at most 1.17983 m"):
        sizing.largest_link_diameter(1.2, 1.5, 0.116)
    with pytest.raises(ValueError, match="link_outer_diameter = 0.12 m: not narrower than the bore"):
        sizing.longest_link(1.5, 0.116, 0.12)


@pytest.mark.parametrize(
    ("old", "new", "args"),
    [
        ("longest_joint", "longest_link", (1.5, 0.116, 0.086)),
        ("smallest_curvature_radius", "tightest_radius_for_link", (0.6, 0.116, 0.086)),
        ("largest_joint_diameter", "largest_link_diameter", (0.6, 1.5, 0.116)),
        ("smallest_curvature_radius_for_bend", "tightest_radius_for_bend", (0.2, 14.92)),
    ],
)
def test_the_old_names_warn_and_give_the_new_ones_value(old, new, args):
    with pytest.warns(DeprecationWarning, match=f"ballcage.sizing.{old} is deprecated.*use {new}"):
        value = getattr(sizing, old)(*args)
    assert value == getattr(sizing, new)(*args)
    if hasattr(ballcage, new):  # the top-level aliases are the same functions
        assert getattr(ballcage, old) is getattr(sizing, old) and getattr(ballcage, new) is getattr(sizing, new)


def test_python_and_the_native_module_share_eq9s_names_and_arguments():
    # Same names, same argument meaning (diameters): the checked Python functions and the raw native ones agree.
    assert sizing.longest_link(1.5, 0.116, 0.086) == _native.longest_link(1.5, 0.116, 0.086)
    assert sizing.tightest_radius_for_link(0.6, 0.116, 0.086) == _native.tightest_radius_for_link(0.6, 0.116, 0.086)
    assert sizing.largest_link_diameter(0.6, 1.5, 0.116) == _native.largest_link_diameter(0.6, 1.5, 0.116)


def test_the_articulation_limit_has_its_own_radius():
    # The paper's hinge: β = 14.92°, p = 0.2 m → 0.2 / (2 sin 7.46°) = 0.770 m, as the scene says.
    scene = default_scene()
    beta = scene.articulation_limit_deg()
    assert sizing.tightest_radius_for_bend(0.2, beta) == pytest.approx(scene.tightest_radius(), rel=1e-12)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--radius", "-5", "--tube-id", "116", "--joint-od", "86"], "--radius -5: must be a positive length in mm"),
        (["--radius", "1500", "--tube-id", "116", "--joint-od", "120"], "--joint-od 120: not narrower than the bore"),
        (["--radius", "1500", "--joint-od", "86"], "--tube-id missing"),
        (["--radius", "1500", "--tube-id", "116"], "two of --radius, --joint-od and --length (got --radius)"),
        (["--length", "1200", "--radius", "1500", "--tube-id", "116"], "--length 1200: no joint that long fits"),
        (["--radius", "50", "--tube-id", "116", "--joint-od", "86"], "--radius 50: below half the bore (58 mm)"),
    ],
)
def test_bad_input_exits_2_naming_the_option(capsys, args, message):
    code, out, err = _size(capsys, *args)
    assert code == 2 and out == ""
    assert err.startswith("ballcage: error: ") and message in err and err.count("\n") == 1, err


def test_the_plot_is_a_png(capsys, tmp_path):
    path = tmp_path / "fig15.png"
    code, out, _ = _size(capsys, "--radius", "1500", "--tube-id", "116", "--joint-od", "86", "--plot", str(path))
    assert code == 0 and out.splitlines()[0] == "608.54" and "wrote" in out
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_scene_whose_pitch_does_not_fit_is_refused_by_how_much():
    # A 0.6 m link of Ø86 mm in the Ø116 mm tube: eq. (9) needs R ≥ 0.3²/0.06 − 0.043 = 1.457 m;
    # at R = 1.4 m the longest that fits is 2·√(2·0.03·1.443) = 0.58849 m, 0.0115 m short of the pitch.
    with pytest.raises(ballcage.SceneError) as e:
        ballcage.Scene.from_toml('kind = "drill-pipe"\n', ["pipe.pitch=0.6", "borehole.curvature_radius=1.4"])
    assert e.value.path == "borehole.curvature_radius"
    assert "eq. (9) needs R ≥ 1.4570 m, 0.0570 m more" in e.value.reason
    assert "pipe.pitch is 0.0115 m too long" in e.value.reason
    assert f"{sizing.longest_link(1.4, 0.116, 0.086):.4f} m" in e.value.reason


def test_a_scene_bent_past_the_articulation_limit_is_refused_by_how_much():
    # R = 0.7 m: 2·asin(0.1/0.7) = 16.43° against the 14.92° limit; R ≥ 0.7701 m, 0.0701 m more.
    with pytest.raises(ballcage.SceneError) as e:
        ballcage.Scene.from_toml('kind = "drill-pipe"\n', ["borehole.curvature_radius=0.7"])
    assert e.value.path == "borehole.curvature_radius"
    bend = 2 * math.degrees(math.asin(0.1 / 0.7))
    limit = default_scene().articulation_limit_deg()
    assert f"{bend - limit:.2f}° beyond" in e.value.reason
    assert "R ≥ 0.7701 m, 0.0701 m more" in e.value.reason
