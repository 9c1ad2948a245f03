"""`ballcage chart` (`ballcage.studies.design_chart`): feasibility by the closed forms, the mass scaling, the files, the CLI.

The cells that run are the paper's pipe reduced to 3 ideal-CV joints for 0.06 s
at 1 ms steps (a few tenths of a second each). A joint OD of 110 mm in the
paper's 116 mm bore makes eq. (9) bind at lengths the articulation limit
allows (with the paper's 86 mm joint it binds only beyond L = 0.935 m).
"""

from __future__ import annotations

import math
from pathlib import Path

import pyarrow.parquet as pq
import pytest

import ballcage
from ballcage.cli import main
from ballcage.scene import default_scene_toml
from ballcage.studies.design_chart import ChartError, DesignChart, ReferenceLink, design_chart

TUBE, JOINT = 0.116, 0.110  # m
TINY = ("pipe.joints=3", "simulation.dt=1e-3", "simulation.output_interval=2e-3")
DURATION = 0.06  # s; the window is its second half
R_WIDE, R_TIGHT = 1.5, 0.5  # m


def eq9(radius: float) -> float:
    """The paper's eq. (9) by hand: L = 2·sqrt(2(D − 2r)(R + r)), r = d/2 [m]."""
    r = JOINT / 2
    return 2 * math.sqrt(2 * (TUBE - 2 * r) * (radius + r))


L_SHORT = 0.15  # m: fits R_TIGHT by eq. (9) (0.1632 m) but bends its hinges 17.25 degrees there
L_IN, L_OUT = eq9(R_WIDE) - 0.005, eq9(R_WIDE) + 0.005  # just inside and just outside eq. (9) at R_WIDE (0.2732 m)


@pytest.fixture(scope="module")
def chart(tmp_path_factory: pytest.TempPathFactory) -> DesignChart:
    out = tmp_path_factory.mktemp("chart")
    return design_chart(
        out, radii=[R_TIGHT, R_WIDE], lengths=[L_SHORT, L_IN, L_OUT], tube_inner_diameter=TUBE,
        joint_diameter=JOINT, hinge="ideal-cv", duration=DURATION, overrides=TINY, workers=2, progress=False,
    )


def _cell(chart: DesignChart, radius: float, length: float) -> dict:
    rows = [r for r in chart.table.to_pylist() if r["borehole.curvature_radius"] == radius and r["pipe.pitch"] == length]
    assert len(rows) == 1
    return rows[0]


def _limit_deg() -> float:
    scene = ballcage.Scene.from_toml(default_scene_toml(), ['pipe.hinge="ideal-cv"'])
    limit = scene.articulation_limit_deg()
    assert limit is not None and 14 < limit < 16  # the neck meets the mouth at 14.92 degrees
    return limit


def test_eq9_just_inside_runs_and_just_outside_is_excluded_by_eq9(chart: DesignChart) -> None:
    inside, outside = _cell(chart, R_WIDE, L_IN), _cell(chart, R_WIDE, L_OUT)
    assert inside["feasible"] and inside["reason"] is None and inside["status"] == "ok"
    assert inside["tube_normal_mean_max_n"] is not None  # it ran, and its quantities came back
    assert not outside["feasible"] and outside["status"] is None and outside["case"] is None
    assert outside["reason"] == "eq. (9)"
    assert "eq. (9)" in outside["refusal"]  # the scene validator's own message
    assert outside["longest_joint_m"] == pytest.approx(eq9(R_WIDE), rel=1e-12)


def test_a_cell_bent_past_the_articulation_limit_is_excluded_by_it(chart: DesignChart) -> None:
    limit = _limit_deg()
    bend = math.degrees(2 * math.asin(L_SHORT / (2 * R_TIGHT)))
    assert L_SHORT < eq9(R_TIGHT) and bend > limit  # eq. (9) holds; the articulation limit does not
    tight = _cell(chart, R_TIGHT, L_SHORT)
    assert not tight["feasible"] and tight["reason"] == "articulation limit"
    assert "articulation limit" in tight["refusal"]
    assert tight["hinge_bend_deg"] == pytest.approx(bend)
    wide = _cell(chart, R_WIDE, L_SHORT)
    assert math.degrees(2 * math.asin(L_SHORT / (2 * R_WIDE))) < limit
    assert wide["feasible"] and wide["status"] == "ok"


def test_a_cell_breaking_both_says_both(chart: DesignChart) -> None:
    row = _cell(chart, R_TIGHT, L_OUT)
    assert row["excluded_by_eq9"] and row["excluded_by_articulation"]
    assert row["reason"] == "eq. (9) and articulation limit"


def test_only_the_feasible_cells_ran_and_rerunning_resumes(chart: DesignChart) -> None:
    # Each feasible cell and its verification run: 2 x 2 cases.
    assert chart.table.num_rows == 6 and chart.feasible == 2
    assert chart.sweep is not None and chart.sweep.summary.num_rows == 4 and chart.sweep.ran == 4
    again = design_chart(
        chart.out, radii=[R_TIGHT, R_WIDE], lengths=[L_SHORT, L_IN, L_OUT], tube_inner_diameter=TUBE,
        joint_diameter=JOINT, hinge="ideal-cv", duration=DURATION, overrides=TINY, workers=2, progress=False,
    )
    assert again.sweep is not None and (again.sweep.ran, again.sweep.skipped) == (0, 4)


def test_each_cell_s_numerical_error_is_its_difference_to_its_run_ten_times_tighter(chart: DesignChart) -> None:
    # The verification cases are the feasible cells again at rtol/10 (the scene's 1e-4 over 10), after them.
    assert chart.verification == "rtol/10"
    summary = pq.read_table(chart.out / "summary.parquet").to_pylist()
    cells, checks = summary[:2], summary[2:]
    assert [c["verifies"] for c in summary] == [None, None, 0, 1]
    assert [c["simulation.rtol"] for c in checks] == [1e-5, 1e-5]
    assert [c["simulation.rtol"] for c in cells] == [1e-4, 1e-4]  # the scene's own
    table = pq.read_table(chart.paths["table"])
    assert table.schema.metadata[b"ballcage.chart_verification"] == b"rtol/10"
    assert table.schema.field("tube_normal_mean_all_n_error").metadata[b"unit"] == b"N"
    moved = 0
    for cell, check in zip(cells, checks, strict=True):
        assert (check["borehole.curvature_radius"], check["pipe.pitch"]) == (
            cell["borehole.curvature_radius"], cell["pipe.pitch"])  # fmt: skip
        row = _cell(chart, cell["borehole.curvature_radius"], cell["pipe.pitch"])
        for name in ("tube_normal_mean_all_n", "tube_normal_mean_max_n", "wear_hours_min_h"):
            assert row[name + "_error"] == abs(cell[name] - check[name]), name
            moved += row[name + "_error"] > 0.0
        # Ten times tighter moves the summed mean tube force by far less than the force itself: the chart's
        # tolerance holds it to within a per cent even on these short runs.
        assert row["tube_normal_mean_all_n_error"] < 0.01 * row["tube_normal_mean_all_n"]
        assert row["key_peak_n_error"] is None  # no keys in the ideal-CV model
    assert moved > 0  # the two runs differ: the error is measured, not zero by construction


def test_the_mass_scaling_reproduces_the_paper_at_0_2_m_and_follows_the_formula() -> None:
    link = ReferenceLink.of(ballcage.Scene.from_toml(default_scene_toml()))
    assert link.scaled(0.2) == (8.01, [0.008306, 0.03085, 0.03085])  # exactly the paper's
    mass, inertia = link.scaled(0.5)
    r = 0.043  # the paper's link radius [m]
    assert mass == pytest.approx(8.01 * 2.5, rel=1e-12)
    assert inertia[0] == pytest.approx(0.008306 * 2.5, rel=1e-12)
    transverse = 0.03085 * (20.025 * (3 * r**2 + 0.5**2)) / (8.01 * (3 * r**2 + 0.2**2))  # = 0.43272 kg m^2
    assert inertia[1] == inertia[2] == pytest.approx(transverse, rel=1e-12)
    assert transverse == pytest.approx(0.43272, rel=1e-4)


def test_the_scaled_mass_is_what_the_cell_ran_with(chart: DesignChart) -> None:
    row = _cell(chart, R_WIDE, L_IN)
    assert row["pipe.link_mass"] == pytest.approx(8.01 * L_IN / 0.2, rel=1e-12)
    scene = ballcage.Scene.from_toml((chart.out / "cases" / f"case={row['case']:04d}.scene.toml").read_text())
    assert scene.value("pipe.link_mass") == pytest.approx(row["pipe.link_mass"], rel=1e-12)
    assert scene.value("pipe.link_inertia")[1] == pytest.approx(row["link_inertia_transverse"], rel=1e-12)


def test_without_scaling_every_cell_keeps_the_paper_link(tmp_path: Path) -> None:
    # every cell excluded: nothing runs, the chart is still drawn
    fixed = design_chart(tmp_path, radii=[0.5], lengths=[0.3, 0.6], scale_mass=False, progress=False)
    assert fixed.sweep is None and fixed.feasible == 0
    assert fixed.table.column("pipe.link_mass").to_pylist() == [8.01, 8.01]
    assert (tmp_path / "design_chart.png").is_file()


def test_the_chart_files(chart: DesignChart) -> None:
    assert chart.paths["figure"].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    table = pq.read_table(chart.paths["table"])
    assert table.num_rows == 6
    assert table.schema.field("borehole.curvature_radius").metadata[b"unit"] == b"m"
    assert table.schema.field("tube_normal_mean_max_n").metadata[b"unit"] == b"N"
    assert table.schema.metadata[b"ballcage.chart_hinge"] == b"ideal-cv"
    assert table.column("key_peak_n").null_count == 6  # the ideal-CV model has no keys
    # The lives: the ideal-CV hinge's joint loads are no contacts, so no fatigue life; the links wear on the tube.
    assert table.schema.field("fatigue_life_min_h").metadata[b"unit"] == b"h"
    assert table.column("fatigue_life_min_h").null_count == 6
    ran = [r for r in table.to_pylist() if r["status"] == "ok"]
    assert ran and all(r["wear_hours_min_h"] is not None and r["wear_hours_min_h"] > 0.0 for r in ran)


def test_a_setting_the_chart_owns_is_refused() -> None:
    with pytest.raises(ChartError, match="pipe.pitch"):
        design_chart("unused", overrides=["pipe.pitch=0.3"], progress=False)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--radius-mm", "1000", "-1500"], "--radius-mm -1500: must be a positive length in mm"),
        (["--joint-od", "120"], "--joint-od 120: not narrower than the tube, --tube-id 116"),
        (["--length-mm", "200", "x"], "--length-mm 'x': not a number; give a positive length in mm"),
    ],
)
def test_bad_cli_input_exits_2_with_one_line(capsys: pytest.CaptureFixture[str], tmp_path: Path, args, message) -> None:
    code = main(["chart", "--out", str(tmp_path / "c"), *args])
    out, err = capsys.readouterr()
    assert code == 2 and out == ""
    assert err == f"ballcage: error: {message}\n"
    assert not (tmp_path / "c").exists()


def test_the_cli_estimates_runs_and_names_its_files(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    args = ["chart", "--out", str(tmp_path), "--hinge", "ideal-cv", "--radius-mm", "500", "1500", "--length-mm", "200",
            "--duration", "0.04", "--workers", "1", *[a for o in TINY for a in ("--set", o)]]
    code = main(args)
    out, err = capsys.readouterr()
    assert code == 0
    assert "design chart: 2 cells, 1 feasible, 1 excluded (1 by articulation limit); 1 to run" in err
    assert "each also at rtol/10 for its numerical error (1 of those to run" in err
    assert f"wrote {tmp_path / 'design_chart.png'}" in out and f"wrote {tmp_path / 'design_chart.parquet'}" in out
    assert "largest numerical error (each cell against its run at rtol/10): tube_normal_mean_max_n 0 N (every value 0)" in out


def test_no_verify_runs_each_cell_once_and_leaves_the_errors_null(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    args = ["chart", "--out", str(tmp_path), "--hinge", "ideal-cv", "--radius-mm", "1500", "--length-mm", "200",
            "--duration", "0.02", "--workers", "1", "--no-verify", *[a for o in TINY for a in ("--set", o)]]
    assert main(args) == 0
    out, err = capsys.readouterr()
    assert "not verified (no numerical error)" in err and "numerical error not measured (--no-verify)" in out
    assert pq.read_table(tmp_path / "summary.parquet").num_rows == 1
    table = pq.read_table(tmp_path / "design_chart.parquet")
    assert table.column("tube_normal_mean_all_n_error").null_count == 1
    assert table.column("tube_normal_mean_all_n").null_count == 0
