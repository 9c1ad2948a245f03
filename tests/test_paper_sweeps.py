"""`ballcage paper --sweeps`: the paper's section 4 as a sweep, its trend checks and Figures 16–17.

The verdicts are checked on hand-made summary rows whose answers follow from
the definitions in `ballcage.paper.trends`; the paper's own verdicts from the
reference file's numbers, read here by hand. The end-to-end run uses the
paper's scene (ball keys) for 10 ms: too short for physics, long enough for
every file, the comparison rows and the resume.
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import ballcage
from ballcage.paper import run_paper
from ballcage.paper.section4 import (
    RADIUS_KEY,
    RPM_KEY,
    SPREAD_OFFSET,
    averaging_windows,
    run_section4,
    section4_spec,
)
from ballcage.paper.section4_figures import hinge_key_peaks, link_inclinations
from ballcage.paper.trends import trend_table, verdict
from ballcage.scene import default_scene, default_scene_toml

SHORT = ["simulation.duration=0.01", "simulation.output_interval=0.001"]
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "ballcage", *args], capture_output=True, text=True, timeout=300)


# --------------------------------------------------------------------------- the verdict rule


@pytest.mark.parametrize(
    ("ys", "direction", "spread", "expected"),
    [
        ([2000.0, 1300.0, 1000.0, 800.0], -1, 5.0, "holds"),
        ([2000.0, 1300.0, 1400.0, 800.0], -1, 5.0, "holds end to end, not monotone"),  # a step up of 100 > 5
        ([2000.0, 1300.0, 1303.0, 800.0], -1, 5.0, "holds"),  # the step up of 3 is within the spread
        ([1000.0, 1010.0, 995.0, 1004.0], -1, 5.0, "flat"),  # end to end +4, within 5
        ([1000.0, 1010.0, 995.0, 1006.0], -1, 5.0, "reversed"),  # end to end +6, beyond 5, against the claim
        ([790.0, 876.8, 920.0], +1, 0.0, "holds"),
        ([36700.0, 33500.0, 39700.0], +1, 0.0, "holds end to end, not monotone"),
    ],
)
def test_verdict(ys: list[float], direction: int, spread: float, expected: str) -> None:
    assert verdict(list(range(len(ys))), ys, direction, spread) == expected


def _row(case: int, radius: float, rpm: float, tube: float, key: float | None, **extra: float) -> dict:
    row = {"case": case, "status": "ok", RADIUS_KEY: radius, RPM_KEY: rpm,
           "tube_normal_mean_max_n": tube, "key_peak_n": key,
           "tube_normal_mean_all_n": 10_000.0, "tube_tangential_mean_all_n": 2_000.0,
           "seat_key_normal_peak_n": 30_000.0, "seat_key_tangential_peak_n": 1_000.0}
    row.update(extra)
    return row


def _summary(rows: list[dict]) -> pa.Table:
    table = pa.Table.from_pylist(rows)
    fields = [f.with_metadata({"unit": "N" if f.name.endswith("_n") else ""}) for f in table.schema]
    return table.cast(pa.schema(fields))


SWEEP_ROWS = [
    _row(0, 1.0, 100.0, 2000.0, 30_000.0),
    _row(1, 1.5, 100.0, 1300.0, 32_000.0),
    _row(2, 2.0, 100.0, 1000.0, 31_000.0),
    _row(3, 2.5, 100.0, 800.0, 30_500.0),
    _row(4, 1.5, 60.0, 1400.0, 36_000.0),
    _row(5, 1.5, 80.0, 1350.0, 33_000.0),
    _row(6, 1.5, 120.0, 1250.0, 32_100.0),
    _row(7, 1.5 + SPREAD_OFFSET, 100.0, 1302.0, 32_050.0),
    _row(8, 1.5 - SPREAD_OFFSET, 100.0, 1299.0, 31_990.0),
]


def test_trend_table_checks_each_claim_against_the_spread() -> None:
    rows = {r["key"]: r for r in trend_table(_summary(SWEEP_ROWS)).to_pylist()}
    tube_r = rows["tube_mean_max_falls_with_R"]
    assert tube_r["verdict"] == "holds"
    assert tube_r["change"] == pytest.approx(800.0 - 2000.0)
    assert tube_r["change_percent"] == pytest.approx(100.0 * -1200.0 / 1300.0)
    assert tube_r["spread"] == pytest.approx(1302.0 - 1299.0)  # over the baseline and its two copies
    assert tube_r["spread_percent"] == pytest.approx(100.0 * 3.0 / 1300.0)
    # key peak over R: 30 000 -> 30 500 (+500 against the claim) beyond the spread of 60 N
    assert rows["key_peak_falls_with_R"]["verdict"] == "reversed"
    assert rows["key_peak_falls_with_R"]["spread"] == pytest.approx(32_050.0 - 31_990.0)
    assert rows["tube_mean_max_rises_with_rpm"]["verdict"] == "reversed"  # 1400 -> 1250
    assert rows["key_peak_rises_with_rpm"]["verdict"] == "reversed"  # 36 000 -> 32 100
    assert rows["normal_exceeds_tangential"]["verdict"].startswith("holds")  # smallest ratio 5


def test_trend_within_the_spread_is_flat_and_small_ratios_do_not_hold() -> None:
    rows = [dict(r) for r in SWEEP_ROWS]
    rows[3]["tube_normal_mean_max_n"] = 2000.0 - 2.5  # end to end -2.5 against a spread of 3
    rows[5]["tube_tangential_mean_all_n"] = 5_000.0  # ratio 2 in one case
    table = {r["key"]: r for r in trend_table(_summary(rows)).to_pylist()}
    assert table["tube_mean_max_falls_with_R"]["verdict"] == "flat"
    assert table["normal_exceeds_tangential"]["verdict"].startswith("does not hold")
    assert "smallest 2" in table["normal_exceeds_tangential"]["verdict"]


def test_a_change_within_twice_the_numerical_error_is_flat() -> None:
    # The tube force over R falls 1200 N end to end against a spread of 3 N: it holds. With the cases verified, a
    # numerical error of 700 N in one of them makes the tolerance 2 x 700 = 1400 N, and the same change is flat;
    # 500 N (tolerance 1000 N) leaves it standing. Unverified rows (no _error column) weigh the spread alone.
    for error, expected in ((700.0, "flat"), (500.0, "holds")):
        rows = [dict(r, tube_normal_mean_max_n_error=1.0) for r in SWEEP_ROWS]
        rows[2]["tube_normal_mean_max_n_error"] = error  # R 2.0 m, in the series
        tube_r = {r["key"]: r for r in trend_table(_summary(rows)).to_pylist()}["tube_mean_max_falls_with_R"]
        assert tube_r["numerical_error"] == error
        assert tube_r["numerical_error_percent"] == pytest.approx(100.0 * error / 1300.0)
        assert tube_r["verdict"] == expected, error
    # An error in the spread's copies counts too (they are the baseline's cases).
    rows = [dict(r, tube_normal_mean_max_n_error=1.0) for r in SWEEP_ROWS]
    rows[7]["tube_normal_mean_max_n_error"] = 650.0
    assert {r["key"]: r for r in trend_table(_summary(rows)).to_pylist()}["tube_mean_max_falls_with_R"]["verdict"] == "flat"
    plain = {r["key"]: r for r in trend_table(_summary(SWEEP_ROWS)).to_pylist()}["tube_mean_max_falls_with_R"]
    assert plain["numerical_error"] is None and plain["verdict"] == "holds"


def test_missing_key_forces_are_not_checked_and_say_where() -> None:
    rows = [dict(r, key_peak_n=None) for r in SWEEP_ROWS]  # the ideal-CV model has no keys
    table = {r["key"]: r for r in trend_table(_summary(rows)).to_pylist()}
    assert table["key_peak_falls_with_R"]["verdict"].startswith("not checked: key_peak_n is missing")
    assert table["tube_mean_max_falls_with_R"]["verdict"] == "holds"


def test_the_papers_own_numbers_contradict_its_key_peak_trends() -> None:
    """Reference file: key peak 42.4 / 33.5 / 36.8 kN at R 1.0 / 1.5 / 2.5 m, 36.7 / 33.5 / 39.7 kN at 60 / 100 / 120 rpm."""
    table = {r["key"]: r for r in trend_table(_summary(SWEEP_ROWS)).to_pylist()}
    assert table["key_peak_falls_with_R"]["paper_verdict"] == "holds end to end, not monotone"
    assert table["key_peak_rises_with_rpm"]["paper_verdict"] == "holds end to end, not monotone"
    # tube means 970 / 876.8 / 250 N over R and 790 / 876.8 / 920 N over rpm follow the claims
    assert table["tube_mean_max_falls_with_R"]["paper_verdict"] == "holds"
    assert table["tube_mean_max_rises_with_rpm"]["paper_verdict"] == "holds"
    assert "1 m: 970 N" in table["tube_mean_max_falls_with_R"]["paper"]


def test_section4_cases_are_the_papers_and_the_spread() -> None:
    cases = section4_spec().check()
    pairs = [(c.values[RADIUS_KEY], c.values[RPM_KEY]) for c in cases]
    assert pairs[:4] == [(1.0, 100.0), (1.5, 100.0), (2.0, 100.0), (2.5, 100.0)]  # §4.2
    assert sorted(p for p in pairs if p[0] == 1.5) == [(1.5, 60.0), (1.5, 80.0), (1.5, 100.0), (1.5, 120.0)]  # §4.3
    assert (1.5 + 1e-6, 100.0) in pairs and (1.5 - 1e-6, 100.0) in pairs
    assert len(pairs) == len(set(pairs)) == 9  # the baseline once


# --------------------------------------------------------------------------- Figures 16-17: the per-hinge and per-link values


def _hand_run(tables: dict[str, pa.Table], window: tuple[float, float]) -> ballcage.Run:
    scene = ballcage.Scene.from_toml(default_scene_toml(), [f"record.summary_window=[{window[0]}, {window[1]}]"])
    return ballcage.Run(tables, scene.to_toml(), scene=scene)


def test_hinge_key_peaks_and_link_inclinations_keep_to_the_summary_window() -> None:
    keys = pa.table({
        "t": [0.05, 0.15, 0.15, 0.25, 0.15],
        "hinge": np.array([0, 0, 0, 0, 3], dtype=np.int32),
        "inner_normal": [900.0, 4.0, 7.0, 800.0, 1.0],
        "outer_normal": [0.0, 5.0, 2.0, 0.0, 3.0],
    })
    links = pa.table({
        "t": [0.05, 0.12, 0.18, 0.12],
        "link": np.array([1, 1, 1, 2], dtype=np.int32),
        "inclination_deg": [50.0, 10.0, 20.0, 30.0],
    })
    run = _hand_run({"keys": keys, "links": links}, (0.1, 0.2))
    assert hinge_key_peaks(run) == {0: 7.0, 3: 3.0}  # max of both races, frames at 0.05 and 0.25 s left out
    assert link_inclinations(run) == {1: 15.0, 2: 30.0}


# --------------------------------------------------------------------------- end to end


@pytest.fixture(scope="module")
def swept(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Path]]:
    out = tmp_path_factory.mktemp("paper_sweeps")
    return out, run_paper(out, SHORT, sweeps=True, progress=False, workers=2)


def test_run_paper_with_sweeps_writes_the_sweep_figures_and_trends(swept: tuple[Path, dict[str, Path]]) -> None:
    out, paths = swept
    summary = pq.read_table(out / "sweeps" / "summary.parquet")
    # The 9 cases, then each again ten times tighter (run_paper verifies by default).
    assert summary.num_rows == 18 and set(summary.column("status").to_pylist()) == {"ok"}
    assert summary.column("verifies").to_pylist() == [None] * 9 + list(range(9))
    for name in ("fig16_curvature", "fig17_speed", "losses_curvature"):
        assert paths[name].read_bytes()[:8] == PNG_MAGIC
    trends = pq.read_table(paths["trends"])
    assert trends.column("key").to_pylist() == [
        "tube_mean_max_falls_with_R", "key_peak_falls_with_R", "tube_mean_max_rises_with_rpm",
        "key_peak_rises_with_rpm", "normal_exceeds_tangential",
    ]
    assert "## The paper's trends" in paths["comparison_md"].read_text(encoding="utf-8")
    # Each trend over a series weighs its change against the cases' numerical error.
    errors = trends.column("numerical_error").to_pylist()
    assert all(e is not None and e >= 0.0 for e in errors[:4]) and errors[4] is None


def test_sweep_rows_of_the_comparison_come_from_the_right_cases(swept: tuple[Path, dict[str, Path]]) -> None:
    out, paths = swept
    rows = {r["key"]: r for r in pq.read_table(paths["comparison"]).to_pylist()}
    sweep_rows = [r for key, r in rows.items() if key.startswith("sweep_")]
    assert len(sweep_rows) == 8
    for r in sweep_rows:
        assert r["ours"] is not None and math.isfinite(r["ours"]) and r["ratio"] is not None, r["key"]
        assert "not run" not in r["note"], r["key"]
    for vid in ("R1000", "R2500", "rpm60", "rpm120"):
        assert rows[f"sweep_{vid}_key_peak_n"]["ours"] > 0, vid
    assert "of the R = 1.0 m variant" in rows["sweep_R1000_key_peak_n"]["note"]
    # the R = 1.0 m case's key peak is the summary's, not the baseline's
    summary = {(r[RADIUS_KEY], r[RPM_KEY]): r for r in pq.read_table(out / "sweeps" / "summary.parquet").to_pylist()
               if r["verifies"] is None}  # not the verification runs' rows, which repeat each case ten times tighter
    assert rows["sweep_R1000_key_peak_n"]["ours"] == pytest.approx(summary[(1.0, 100.0)]["key_peak_n"])
    assert rows["sweep_rpm120_key_peak_n"]["ours"] == pytest.approx(summary[(1.5, 120.0)]["key_peak_n"])
    assert summary[(1.0, 100.0)]["key_peak_n"] != pytest.approx(summary[(1.5, 100.0)]["key_peak_n"], rel=1e-3)


def test_running_the_section4_sweep_again_resumes(swept: tuple[Path, dict[str, Path]]) -> None:
    out, _ = swept
    again = run_section4(out / "sweeps", section4_spec(SHORT), workers=1, progress=False)
    assert (again.result.ran, again.result.skipped) == (0, 9)
    assert set(again.variant_runs()) == {"R1000", "R2500", "rpm60", "rpm120"}
    assert again.variant_runs()["R2500"].scene.value(RADIUS_KEY) == 2.5


def test_trends_are_also_checked_over_the_windows_after_the_ramps_and_the_second_half() -> None:
    # the paper scene: drive and load ramps 0.3 s, 1.8 s simulated
    assert averaging_windows(default_scene()) == [(0.3, 1.8), (0.9, 1.8)]
    windows = {"w": [dict(r) for r in SWEEP_ROWS]}
    windows["w"][0]["tube_normal_mean_max_n"] = 700.0  # now rises with R: 700 -> 800
    rows = {r["key"]: r for r in trend_table(_summary(SWEEP_ROWS), windows).to_pylist()}
    assert rows["tube_mean_max_falls_with_R"]["verdict"] == "holds"
    assert rows["tube_mean_max_falls_with_R"]["other_windows"] == "w: reversed"


def test_window_rows_recompute_the_quantities_over_another_window(swept: tuple[Path, dict[str, Path]]) -> None:
    out, _ = swept
    section4 = run_section4(out / "sweeps", section4_spec(SHORT), workers=1, progress=False)
    rows = {(r[RADIUS_KEY], r[RPM_KEY]): r for r in section4.window_rows((0.005, 0.01))}
    drive = section4.runs[(1.0, 100.0)].tables["drive"]
    t = drive.column("t").to_numpy()
    p_in, p_out = drive.column("input_power").to_numpy(), drive.column("output_power").to_numpy()
    inside = t >= 0.005 - 1e-12
    # the drive efficiency: mean output over mean input power in the window (10 ms: the chain still spinning up)
    assert rows[(1.0, 100.0)]["efficiency"] == pytest.approx(p_out[inside].mean() / p_in[inside].mean(), rel=1e-12)
    assert p_out[inside].mean() / p_in[inside].mean() != pytest.approx(p_out.mean() / p_in.mean(), rel=0.01)


def test_cli_workers_without_sweeps_is_refused(tmp_path: Path) -> None:
    result = _cli("paper", "--out", str(tmp_path / "p"), "--workers", "2")
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and "--workers" in result.stderr and "--sweeps" in result.stderr
    assert not (tmp_path / "p").exists()
