"""`ballcage paper` on a short run: the files it writes, the comparison table, and physics sanity.

The full paper run (1.8 s simulated) takes minutes; everything here uses a
10 ms run of the same scene, which is long enough to exercise every table,
figure and comparison row but not to reach the paper's steady rotation.
"""

from __future__ import annotations

import math
import subprocess
import sys
import time
import tomllib
from importlib import resources
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq
import pytest

import ballcage
from ballcage import paper, studies
from ballcage._links import window_peak
from ballcage.measures import frames as paper_frames
from ballcage.measures import motion as paper_motion

REPO = Path(__file__).resolve().parent.parent
#: The reference file of the project's shared folder (beside the repository in CI, or /work/shared).
SHARED_REFERENCES = [
    REPO.parent / "shared" / "reference" / "paper-2023.toml",
    Path("/work/shared/reference/paper-2023.toml"),
]
SHORT = ["simulation.duration=0.01", "simulation.output_interval=0.001"]
TABLES = ["bodies", "contacts", "summary", "links", "hinges", "keys", "drive", "pairs", "wear"]
#: What the paper run derives from the tables: the wear map and its figure (the fatigue table needs the run past
#: its ramps, docs/model.md §8.6, so this short run has none).
DERIVED = ["wear_map.parquet", "wear_map.png"]
FIGURES = [
    "fig09_included_angles.png",
    "fig10_tube_normal.png",
    "fig11_tube_tangential.png",
    "fig12_key_normal.png",
    "fig13_key_tangential.png",
    "table3_shape.png",
    "losses.png",
]
EXPECTED_FILES = sorted(
    [f"{t}.parquet" for t in TABLES]
    + ["scene.toml", *FIGURES, *DERIVED, "chain.html", "comparison.parquet", "comparison.md", "verify.parquet"]
)
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
#: Radial play of a link centre in the guide tube (58 mm bore, 43 mm link radius) plus 1 mm of penetration.
MAX_RADIAL_OFFSET = 0.058 - 0.043 + 0.001


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "ballcage", *args], capture_output=True, text=True, timeout=300)


def _reference_quantities(path: Path | None = None) -> list[dict]:
    if path is None:
        text = resources.files("ballcage").joinpath("data", "paper-2023.toml").read_text(encoding="utf-8")
    else:
        text = path.read_text(encoding="utf-8")
    return tomllib.loads(text)["quantity"]


#: Rows the comparison adds to the reference file's: (key, the key it follows, unit, paper value).
EXTRA_ROWS = [
    ("included_angle_projected_min_deg", "included_angle_min_deg", "deg", 172.8),
    ("included_angle_projected_max_deg", "included_angle_max_deg", "deg", 176.0),
    ("range_of_motion_peak_to_peak_mm", "range_of_motion_mm", "mm", 25.3),
    ("tube_normal_mean_max_inclination_deg", "tube_normal_mean_joint12_n", "deg", None),
    ("head_cage_normal_peak_n", "seat_cage_normal_peak_n", "N", None),
]


def _expected_rows() -> list[tuple[str, float | None, str]]:
    """(key, paper, unit) of every comparison row: the reference quantities, each extra row after its key."""
    rows = []
    for q in _reference_quantities():
        rows.append((q["key"], float(q["value"]), q["unit"]))
        rows.extend((key, paper, unit) for key, after, unit, paper in EXTRA_ROWS if after == q["key"])
    return rows


@pytest.fixture(scope="module")
def paper_out(tmp_path_factory):
    out = tmp_path_factory.mktemp("paper") / "out"
    proc = _cli("paper", "--out", str(out), "--set", "simulation.duration=0.01")
    assert proc.returncode == 0, proc.stderr
    return out, proc


@pytest.fixture(scope="module")
def short_run():
    return ballcage.simulate(paper.paper_scene(SHORT), progress=False)


def test_paper_writes_every_table_figure_and_comparison(paper_out):
    out, proc = paper_out
    assert sorted(p.name for p in out.iterdir()) == EXPECTED_FILES
    lines = proc.stdout.splitlines()
    assert len(lines) == len(EXPECTED_FILES) + 1  # one "wrote ..." line per file, then the verification's
    assert lines[-1].startswith("ballcage: error ≤ ") and "(verified at rtol/10: " in lines[-1], lines[-1]
    for name in TABLES:
        assert pq.read_table(out / f"{name}.parquet").num_rows > 0, name
    assert tomllib.loads((out / "scene.toml").read_text(encoding="utf-8"))["simulation"]["duration"] == 0.01


@pytest.mark.parametrize("figure", FIGURES)
def test_figures_are_real_pngs_of_nontrivial_size(paper_out, figure):
    out, _ = paper_out
    data = (out / figure).read_bytes()
    assert data[:8] == PNG_MAGIC
    assert len(data) > 15_000  # axes, labels and curves, not an empty canvas


def test_comparison_has_exactly_the_reference_keys_columns_and_types(paper_out):
    out, _ = paper_out
    table = pq.read_table(out / "comparison.parquet")
    assert table.column_names == [
        "key", "paper", "ours", "unit", "ratio", "note", "numerical_error", "numerical_error_rel",
        "numerical_error_confirmed",
    ]  # fmt: skip
    types = {f.name: f.type for f in table.schema}
    assert types == {
        "key": pa.string(),
        "paper": pa.float64(),
        "ours": pa.float64(),
        "unit": pa.string(),
        "ratio": pa.float64(),
        "note": pa.string(),
        "numerical_error": pa.float64(),
        "numerical_error_rel": pa.float64(),
        "numerical_error_confirmed": pa.bool_(),
    }
    assert table.column("numerical_error_confirmed").null_count == table.num_rows  # one verification run
    shipped = _reference_quantities()
    expected = _expected_rows()
    assert len(expected) == len(shipped) + len(EXTRA_ROWS)
    assert table.column("key").to_pylist() == [key for key, _, _ in expected]
    assert len(set(table.column("key").to_pylist())) == table.num_rows
    assert table.column("paper").to_pylist() == [paper for _, paper, _ in expected]
    assert table.column("unit").to_pylist() == [unit for _, _, unit in expected]
    for shared in SHARED_REFERENCES:
        if shared.exists():
            assert [q["key"] for q in _reference_quantities(shared)] == [q["key"] for q in shipped], shared


def test_comparison_notes_suspect_values_and_unrun_sweeps(paper_out):
    out, _ = paper_out
    rows = {r["key"]: r for r in pq.read_table(out / "comparison.parquet").to_pylist()}
    suspect = {q["key"] for q in _reference_quantities() if q.get("suspect", False)}
    assert suspect  # the reference marks some values
    for key, row in rows.items():
        assert ("suspect" in row["note"]) == (key in suspect), key
        if key.startswith("sweep_"):
            assert row["ours"] is None and row["ratio"] is None, key
            assert "not run: pass --sweeps" in row["note"], key
        else:
            assert row["ours"] is not None and math.isfinite(row["ours"]), key
        if key == "most_deformed_joint":
            assert row["ratio"] is None and "no ratio" in row["note"], key  # an index
        elif row["ours"] is not None and row["paper"] is not None and row["paper"] != 0:
            assert row["ratio"] == pytest.approx(row["ours"] / row["paper"]), key
        else:
            assert row["ratio"] is None, key
    # Definitions that differ from the paper's say so.
    for key in ("range_of_motion_mm", "tube_normal_mean_all_n", "tube_tangential_mean_all_n"):
        assert "differs" in rows[key]["note"], key
    assert "reading 2" in rows["tube_normal_mean_all_n"]["note"]
    assert "ratio undefined" in rows["tube_normal_mean_joint12_n"]["note"]  # the paper's value is 0


def test_comparison_markdown_has_title_command_and_one_row_per_key(paper_out):
    out, _ = paper_out
    text = (out / "comparison.md").read_text(encoding="utf-8")
    lines = text.splitlines()
    assert lines[0].startswith("# ")
    assert f"ballcage paper --out {out} --set simulation.duration=0.01" in text
    assert "| key | paper | ours | unit | ratio | numerical error | note |" in lines
    for key, _, _ in _expected_rows():
        assert sum(line.startswith(f"| {key} |") for line in lines) == 1, key
    # The paper gives no cage-head value: an empty paper cell and ratio, our value filled.
    head = next(line for line in lines if line.startswith("| head_cage_normal_peak_n |")).split(" | ")
    assert head[1] == "" and head[2] != "" and head[4] == "", head
    assert "range_of_motion_peak_to_peak_mm" in text.split("| key |")[0]  # the paragraph names the extra rows


def test_python_api_comparison_matches_the_cli(paper_out, short_run):
    out, _ = paper_out
    api = paper.comparison(short_run)
    cli = pq.read_table(out / "comparison.parquet")
    assert api.select(["key", "paper", "ours", "unit", "ratio"]).equals(
        cli.select(["key", "paper", "ours", "unit", "ratio"])
    )


def test_each_row_s_numerical_error_is_its_difference_to_the_run_ten_times_tighter(tmp_path):
    # Long enough for the links to reach the tube and the keys to load, so that the errors are not all zero.
    out, duration = tmp_path / "p", ["simulation.duration=0.05"]
    proc = _cli("paper", "--out", str(out), "--set", duration[0])
    assert proc.returncode == 0, proc.stderr
    rows = pq.read_table(out / "comparison.parquet").to_pylist()
    # By hand: the same scene at rtol 1e-4 (the default) and at 1e-5, each compared with the paper on its own.
    run = paper.comparison(ballcage.simulate(paper.paper_scene(duration), progress=False))
    tight = paper.comparison(ballcage.simulate(paper.paper_scene([*duration, "simulation.rtol=1e-05"]), progress=False))
    floors = {"N": 1.0, "deg": 0.1, "mm": 1.0}
    moved = 0
    for row, a, b in zip(rows, run.to_pylist(), tight.to_pylist(), strict=True):
        key = row["key"]
        assert row["ours"] == a["ours"], key
        if key.startswith("sweep_"):  # the section-4 cases are not rerun
            assert row["numerical_error"] is None and row["numerical_error_rel"] is None, key
            continue
        assert row["numerical_error"] == abs(a["ours"] - b["ours"]), key
        if key == "most_deformed_joint":  # an index: no relative difference
            assert row["numerical_error_rel"] is None
        else:
            rel = abs(a["ours"] - b["ours"]) / max(abs(b["ours"]), floors[row["unit"]])
            assert row["numerical_error_rel"] == pytest.approx(rel, rel=1e-12, abs=0.0), key
        moved += row["numerical_error"] > 0.0
    assert moved >= 10  # the tighter run differs: the column measures something
    text = (out / "comparison.md").read_text(encoding="utf-8")
    largest = max((r["numerical_error_rel"], r["key"]) for r in rows if r["numerical_error_rel"] is not None)
    assert f"on `{largest[1]}`" in text and "Numerical error: each row's |ours − ours of the same run" in text


def test_paper_verify_2_confirms_each_row_s_error_by_a_run_a_hundred_times_tighter(tmp_path):
    out, duration = tmp_path / "p", ["simulation.duration=0.05"]
    proc = _cli("paper", "--out", str(out), "--set", duration[0], "--verify", "2")
    assert proc.returncode == 0, proc.stderr
    rows = pq.read_table(out / "comparison.parquet").to_pylist()
    # By hand: the rtol/10 and rtol/100 runs, each compared with the paper on its own; the rule of CONFIRM_RULE.
    tight = paper.comparison(ballcage.simulate(paper.paper_scene([*duration, "simulation.rtol=1e-05"]), progress=False))
    tighter = paper.comparison(ballcage.simulate(paper.paper_scene([*duration, "simulation.rtol=1e-06"]), progress=False))
    floors = {"N": 1.0, "deg": 0.1, "mm": 1.0}
    judged = {True: 0, False: 0}
    for row, b, c in zip(rows, tight.to_pylist(), tighter.to_pylist(), strict=True):
        if row["numerical_error_rel"] is None:
            assert row["numerical_error_confirmed"] is None, row["key"]
            continue
        own = abs(b["ours"] - c["ours"]) / max(abs(c["ours"]), floors[row["unit"]])
        assert row["numerical_error_confirmed"] == (own <= max(row["numerical_error_rel"] / 3, 1e-9)), row["key"]
        judged[row["numerical_error_confirmed"]] += 1
    assert judged[True] >= 10  # most rows are confirmed at this short, smooth start
    text = (out / "comparison.md").read_text(encoding="utf-8")
    assert "A second run at rtol/100" in text and "--verify 2" in text.split("```")[1]
    assert "confirmed at rtol/100" in proc.stdout or "error NOT MEASURED" in proc.stdout
    both = _cli("paper", "--out", str(tmp_path / "q"), "--verify", "2", "--no-verify")
    assert both.returncode == 2 and "--verify 2 and --no-verify: choose one" in both.stderr


def test_paper_without_verification_leaves_the_column_empty_and_says_so(tmp_path):
    out = tmp_path / "p"
    (out).mkdir()
    (out / "verify.parquet").write_bytes(b"an earlier run's")
    proc = _cli("paper", "--out", str(out), "--set", "simulation.duration=0.01", "--no-verify")
    assert proc.returncode == 0, proc.stderr
    assert not (out / "verify.parquet").exists()  # the earlier run's would be taken for this run's
    table = pq.read_table(out / "comparison.parquet")
    assert table.column("numerical_error").null_count == table.num_rows
    text = (out / "comparison.md").read_text(encoding="utf-8")
    assert "**Numerical error: not measured (--no-verify).**" in text and " --no-verify" in text.split("```")[1]
    assert "error ≤" not in proc.stdout


def test_a_failed_verification_leaves_a_complete_report_without_the_column_and_exits_1(tmp_path):
    # SDIRK2's 100 steps fit simulation.max_steps = 200, the verification run's 400 (dt/4) do not.
    out = tmp_path / "p"
    fixed = ['simulation.integrator="sdirk2"', "simulation.rtol=0", "simulation.max_steps=200"]
    proc = _cli("paper", "--out", str(out), "--set", "simulation.duration=0.01", *[a for o in fixed for a in ("--set", o)])
    assert proc.returncode == 1
    last = proc.stderr.strip().splitlines()[-1]
    assert last.startswith("ballcage: error: the verification run at dt/4 failed: "), last
    assert "simulation.max_steps" in last and "complete without the numerical error column" in last
    assert sorted(p.name for p in out.iterdir()) == [f for f in EXPECTED_FILES if f != "verify.parquet"]
    table = pq.read_table(out / "comparison.parquet")
    assert table.column("numerical_error").null_count == table.num_rows
    assert "**Numerical error: the verification run at dt/4 failed: " in (out / "comparison.md").read_text()


def test_a_paper_run_that_fails_stops_its_verification_run(tmp_path, monkeypatch):
    import threading

    import ballcage.run

    real_run = ballcage.run._run

    def diverging(resolved, progress, time_limit=None, watch=None):
        if watch is not None:  # the verification run (ballcage.run.run_watched) goes on
            return real_run(resolved, progress, time_limit, watch)
        time.sleep(0.2)  # the verification run has started beside it
        raise ballcage.SimulationError("diverged (made up by the test)")

    monkeypatch.setattr(ballcage.run, "_run", diverging)
    with pytest.raises(ballcage.SimulationError, match="made up by the test"):
        paper.run_paper(tmp_path / "p", ["simulation.duration=0.5"], progress=False)
    assert not [t for t in threading.enumerate() if t.name == "ballcage-verify" and t.is_alive()]


def test_comparison_fills_sweep_rows_from_given_runs(short_run):
    # The short baseline run stands in for the R = 1.0 m variant: the rows are filled, the rest are not.
    rows = {r["key"]: r for r in paper.comparison(short_run, {"R1000": short_run}).to_pylist()}
    for key in ("sweep_R1000_tube_mean_max_n", "sweep_R1000_key_peak_n"):
        assert rows[key]["ours"] is not None and rows[key]["ours"] >= 0.0, key
        assert "not run" not in rows[key]["note"], key
    assert rows["sweep_R1000_key_peak_n"]["ours"] >= rows["seat_key_normal_peak_n"]["ours"]
    assert rows["sweep_R2500_tube_mean_max_n"]["ours"] is None


def test_bad_set_exits_2_with_one_line(tmp_path):
    for bad in ("simulation.durration=0.01", "nonsense", "pipe.hinge=\"cardan\""):
        proc = _cli("paper", "--out", str(tmp_path / "bad"), "--set", bad)
        assert proc.returncode == 2, bad
        assert proc.stderr.startswith("ballcage: error: ") and proc.stderr.count("\n") == 1, proc.stderr
        assert not (tmp_path / "bad").exists()


def test_paper_refuses_a_record_list_without_its_tables(tmp_path):
    proc = _cli("paper", "--out", str(tmp_path / "x"), "--set", 'record.tables=["bodies"]')
    assert proc.returncode == 2
    assert "record.tables" in proc.stderr and proc.stderr.count("\n") == 1


# --------------------------------------------------------------------------- physics


def _float_columns(table: pa.Table):
    """Each float column's non-null values; only nullable columns may hold nulls."""
    for field in table.schema:
        if pa.types.is_floating(field.type):
            column = table.column(field.name)
            assert field.nullable or column.null_count == 0, field.name
            yield field.name, column.drop_null().to_numpy()


def test_no_table_holds_nan_or_inf(short_run):
    for name, table in short_run.tables.items():
        for column, values in _float_columns(table):
            assert np.isfinite(values).all(), f"{name}.{column}"
    # A key not touching its race has no contact angle: null, never NaN.
    keys = short_run.tables["keys"]
    assert keys.schema.field("outer_contact_angle_deg").nullable


def test_links_stay_inside_the_tube(short_run):
    offsets = short_run.tables["links"].column("radial_offset").to_numpy()
    assert offsets.max() < MAX_RADIAL_OFFSET
    assert (offsets >= 0.0).all()


def test_initial_chain_lies_on_the_centreline_chords(short_run):
    # docs/model.md §7.5: a 200 mm pitch on R = 1.5 m gives included angles of 180 - 7.645 = 172.355 deg, and
    # each link's centre (a chord midpoint) sits one sagitta R - sqrt(R^2 - 0.1^2) inside the centreline.
    links = short_run.tables["links"]
    first = links.filter(pc.equal(links.column("step"), 0))
    angle = first.column("included_angle_deg").to_numpy()
    offset = first.column("radial_offset").to_numpy()
    sagitta = 1.5 - math.sqrt(1.5**2 - 0.1**2)
    assert angle[:10] == pytest.approx(180.0 - 2.0 * math.degrees(math.asin(0.1 / 1.5)), abs=1e-3)
    assert offset[:11] == pytest.approx(sagitta, rel=1e-3)
    # Inside the bend (toward the inner wall: negative outward) and in the bend plane.
    assert first.column("offset_outward").to_numpy()[:11] == pytest.approx(-sagitta, rel=1e-3)
    assert first.column("offset_lateral").to_numpy() == pytest.approx(0.0, abs=1e-9)


def test_contact_forces_are_non_negative(short_run):
    for name in ("keys", "hinges", "summary"):
        for column, values in _float_columns(short_run.tables[name]):
            # the hinges' torque and power are signed: a hinge can run backward for a moment
            signed = column.startswith(("torque_", "power_"))
            if column not in ("t", "window_start", "window_end") and not signed:
                assert (values >= 0.0).all(), f"{name}.{column}"
    keys = short_run.tables["keys"]
    assert keys.num_rows == 13 * 6 * 11  # 13 hinges x 6 keys x 11 frames
    # The drive has started: the keys of the driven hinge carry load by the end of the 10 ms.
    loaded = sum(keys.column(c).to_numpy().max() for c in ("inner_normal", "outer_normal"))
    assert loaded > 0.0


def test_shape_offsets_agree_with_the_native_radial_offset(short_run):
    # links.offset_outward (in the bend plane) and links.offset_lateral (out of it) resolve links.radial_offset.
    links = short_run.tables["links"]
    outward = links.column("offset_outward").to_numpy()
    lateral = links.column("offset_lateral").to_numpy()
    assert np.hypot(outward, lateral) == pytest.approx(links.column("radial_offset").to_numpy(), abs=1e-9)


def test_link_tube_forces_agree_with_the_summary_of_the_tube_pairs():
    # A 3-joint pipe comes to rest on the tube from about 0.13 s. links.tube_normal / tube_tangential are the
    # per-frame totals of each link's contact with the tube, links.tube_*_impulse their integrals and
    # links.tube_*_max their largest values at the integrator's stages since the frame before, so over the summary
    # window their peak and time mean are the summary's for that pair (the pair name is formatted here only to find
    # its summary row).
    start, end = 0.1, 0.2
    scene = paper.paper_scene(
        ["pipe.joints=3", f"simulation.duration={end}", "simulation.output_interval=0.005",
         f"record.summary_window=[{start}, {end}]"]
    )
    run = ballcage.simulate(scene, progress=False)
    summary = {r["pair"]: r for r in run.tables["summary"].to_pylist()}
    links = run.tables["links"]
    t = links.column("t").to_numpy()
    inside = (t >= start - 1e-12) & (t <= end + 1e-12)
    link = links.column("link").to_numpy()
    normal = links.column("tube_normal").to_numpy()
    tangential = links.column("tube_tangential").to_numpy()
    impulse = {kind: links.column(f"tube_{kind}_impulse").to_numpy() for kind in ("normal", "tangential")}
    assert normal[inside].max() > 100.0  # the chain rests on the tube [N]
    assert (normal[~inside] == 0.0).any()  # and did not at the start
    found = studies.quantities(run)
    for k in (1, 2, 3):
        row = summary[f"link{k:02d}/tube"]
        mask = inside & (link == k)
        assert mask.sum() == row["frames"], k
        span = t[mask].max() - t[mask].min()
        for kind in ("normal", "tangential"):
            growth = impulse[kind][mask].max() - impulse[kind][mask].min()  # the integrals do not decrease
            assert growth / span == pytest.approx(row[f"{kind}_mean"], rel=1e-9), (k, kind)
        for kind, value in (("normal", normal), ("tangential", tangential)):
            since = links.column(f"tube_{kind}_max").to_numpy()
            peak = window_peak(value[link == k], since[link == k], inside[link == k])
            assert peak == pytest.approx(row[f"{kind}_peak"], rel=1e-9), (k, kind)
            assert peak >= 0.99 * value[mask].max(), (k, kind)  # the frames are samples of what the stages saw
        assert found[f"tube_mean_force_joint_{k:02d}"].value == pytest.approx(row["normal_mean"], rel=1e-9), k
    rows = {r["key"]: r for r in paper.comparison(run).to_pylist()}
    for kind in ("normal", "tangential"):
        total = sum(summary[f"link{k:02d}/tube"][f"{kind}_mean"] for k in (1, 2, 3))
        assert rows[f"tube_{kind}_mean_all_n"]["ours"] == pytest.approx(total, rel=1e-9), kind
    assert "not computed: the pipe has no link 10" in rows["tube_normal_mean_joint10_n"]["note"]


def test_phases_are_the_quarter_turns_of_the_last_revolution(short_run):
    # At 100 rpm a quarter turn takes 0.15 s: the phases fall at 0.01 - 0.45, - 0.3, - 0.15 and 0.01 s,
    # so a 10 ms run holds only the last one (270°).
    note = {r["key"]: r for r in paper.comparison(short_run).to_pylist()}["included_angle_min_deg"]["note"]
    assert "270° t=0.010 s: link " in note
    assert "1 of 4 phases in the run (0°, 90°, 180° fall before t = 0)" in note


# --------------------------------------------------------------------------- Table 3 as the paper defines it


def _brute_peak_to_peak(x: np.ndarray, y: np.ndarray) -> float:
    """Largest distance between any two points, by comparing every pair."""
    d = np.hypot(x[:, None] - x[None, :], y[:, None] - y[None, :])
    return float(d.max())


def test_peak_to_peak_of_a_circle_is_its_diameter_and_the_offset_its_radius():
    # A centre going once round a circle of radius 10 mm: 20 mm peak to peak, 10 mm largest offset.
    theta = np.linspace(0.0, 2.0 * math.pi, 601)
    x, y = 0.010 * np.cos(theta), 0.010 * np.sin(theta)
    assert paper_motion.peak_to_peak(x, y) == pytest.approx(0.020, rel=1e-12)
    assert paper_motion.largest_offset(x, y) == pytest.approx(0.010, rel=1e-12)
    # Off-centre: a circle of radius 5 mm about (8, 0) mm has 10 mm excursion but a 13 mm largest offset.
    assert paper_motion.peak_to_peak(0.008 + x / 2, y / 2) == pytest.approx(0.010, rel=1e-12)
    assert paper_motion.largest_offset(0.008 + x / 2, y / 2) == pytest.approx(0.013, rel=1e-12)


def test_peak_to_peak_matches_every_pair_on_random_paths():
    rng = np.random.default_rng(7)
    for n in (1, 2, 3, 17, 400):
        x, y = rng.normal(0.0, 0.005, n), rng.normal(0.0, 0.002, n)
        assert paper_motion.peak_to_peak(x, y) == pytest.approx(_brute_peak_to_peak(x, y), rel=1e-12), n
    # Collinear points, repeats and NaN (a frame without the link) are handled.
    x = np.array([0.0, 0.001, 0.003, 0.003, np.nan, -0.002])
    assert paper_motion.peak_to_peak(x, 2.0 * x) == pytest.approx(0.005 * math.sqrt(5.0), rel=1e-12)
    assert math.isnan(paper_motion.peak_to_peak(np.array([np.nan]), np.array([0.0])))


def _synthetic_run(duration: float = 0.6, interval: float = 0.05) -> ballcage.Run:
    """A links table built by hand on the paper scene's TOML (100 rpm: phases at 0.15, 0.3, 0.45, 0.6 s).

    Every hinge bends 5 deg + frame / 100 deg, hinge 4 3 deg more (the most deformed joint: mean bend over the last
    revolution, here the whole run, 3 deg above every other). The chain lies in the bend plane (azimuth 0, each
    inclination the sum of the bends above), so projected and 3-D included angles agree. Link 4 circles the
    centreline at 10 mm once over the run; link 6 sits 12 mm out at the 90° phase and link 5 11 mm out at the 180°
    phase; every other centre stays 1 mm out: the links furthest out at the phases are 4, 6, 5, 4, which no longer
    decide the most deformed joint.
    """
    scene = paper.paper_scene([f"simulation.duration={duration}", f"simulation.output_interval={interval}"])
    times = np.round(np.arange(0.0, duration + interval / 2, interval), 12)
    names = ("t", "link", "offset_outward", "offset_lateral", "included_angle_deg", "inclination_deg", "azimuth_deg")
    cols: dict[str, list] = {c: [] for c in names}
    for f, t in enumerate(times):
        inclination = 1.0
        for k in range(1, 13):
            out, lat = 0.001, 0.0
            if k == 4:
                theta = 2.0 * math.pi * t / duration
                out, lat = 0.010 * math.cos(theta), 0.010 * math.sin(theta)
            elif k == 6 and f == 6:
                out = 0.012
            elif k == 5 and f == 9:
                out = 0.011
            bend = _synthetic_bend(k, f)
            for name, v in zip(names, (t, k, out, lat, 180.0 - bend, inclination, 0.0), strict=True):
                cols[name].append(v)
            inclination += bend
    table = pa.table(cols)
    table = table.append_column("radial_offset", pa.array(np.hypot(cols["offset_outward"], cols["offset_lateral"])))
    zeros = pa.array(np.zeros(table.num_rows))
    table = table.append_column("tube_normal", zeros).append_column("tube_tangential", zeros)
    return ballcage.Run({"links": table}, scene.to_toml())


def _synthetic_bend(hinge: int, frame: int) -> float:
    """Hinge `hinge`'s bend at `frame` in `_synthetic_run` [deg]."""
    return 5.0 + (3.0 if hinge == 4 else 0.0) + frame / 100.0


def test_table3_rows_on_a_hand_built_run():
    rows = {r["key"]: r for r in paper.comparison(_synthetic_run()).to_pylist()}
    # Hinge 4 bends 3 deg more than any other on average: it is the most deformed joint, whatever the offsets say.
    assert rows["most_deformed_joint"]["ours"] == 4.0
    # A joint number is an index: no ratio against the paper's joint number.
    assert rows["most_deformed_joint"]["ratio"] is None
    note = rows["most_deformed_joint"]["note"]
    mean = 8.0 + np.arange(13).mean() / 100.0
    assert f"hinge 4 {mean:.2f} deg, hinge 1 {mean - 3.0:.2f} deg" in note
    assert "margin over the runner-up 3.000 deg" in note
    assert "the link centres furthest out at the phases: links 4, 6, 5, 4" in note
    # Included angle at hinge 4 between link 4 and link 5 at frames 3, 6, 9, 12; in the bend plane, projected alike.
    angles = [180.0 - _synthetic_bend(4, f) for f in (3, 6, 9, 12)]
    for kind in ("", "projected_"):
        assert rows[f"included_angle_{kind}min_deg"]["ours"] == pytest.approx(min(angles), abs=1e-9), kind
        assert rows[f"included_angle_{kind}max_deg"]["ours"] == pytest.approx(max(angles), abs=1e-9), kind
    assert "hinge k between link k and link k+1" in rows["included_angle_min_deg"]["note"]
    assert "hinge 4 at every phase" in rows["included_angle_min_deg"]["note"]
    assert rows["included_angle_projected_min_deg"]["paper"] == 172.8
    # The two ranges of motion of link 4: its largest centre offset at the phases (10 mm on its circle) and its
    # excursion over the last revolution (0-0.6 s, the whole circle: 20 mm).
    assert rows["range_of_motion_mm"]["ours"] == pytest.approx(10.0)
    p2p = rows["range_of_motion_peak_to_peak_mm"]
    assert p2p["ours"] == pytest.approx(20.0)
    assert p2p["paper"] == 25.3 and p2p["ratio"] == pytest.approx(20.0 / 25.3)
    assert "excursion 20.00 mm, largest centre offset 10.00 mm" in p2p["note"]
    assert "radial clearance 15.0 mm" in rows["range_of_motion_mm"]["note"]
    assert "can only be an excursion" in rows["range_of_motion_mm"]["note"]
    # No hinges table: both cage rows say why.
    for key in ("seat_cage_normal_peak_n", "head_cage_normal_peak_n"):
        assert rows[key]["ours"] is None and "hinges table" in rows[key]["note"], key


def test_most_deformed_joint_follows_the_mean_bend_of_the_last_revolution():
    # Hinge 9 bends 4 deg more than the rest, but only before the last revolution (t < 0.3 s of a 0.9 s run,
    # whose last revolution is 0.3-0.9 s): hinge 4, the most bent over the last revolution, stays the joint, and the
    # note names hinge 9 as the winner of the revolution before.
    run = _synthetic_run(duration=0.9)
    links = run.tables["links"]
    early = (links.column("link").to_numpy() == 9) & (links.column("t").to_numpy() < 0.3 - 1e-9)
    angles = links.column("included_angle_deg").to_numpy().copy()
    angles[early] -= 4.0
    links = links.set_column(links.schema.get_field_index("included_angle_deg"), "included_angle_deg", pa.array(angles))
    row = {r["key"]: r for r in paper.comparison(ballcage.Run({"links": links}, run.scene_toml)).to_pylist()}
    assert row["most_deformed_joint"]["ours"] == 4.0
    assert "over the revolution before 0.000-0.250 s (6 frames): hinge 9 " in row["most_deformed_joint"]["note"]


def test_included_angle_at_hinge_k_is_180_minus_the_bend_of_hinge_k(short_run):
    # links.included_angle_deg of link k is the angle between link k and body k+1: hinge k's (link 12: the lower
    # connector, hinge 12). The Fig. 9 and Table 3 rows rely on it.
    links, hinges = short_run.tables["links"], short_run.tables["hinges"]
    times = np.unique(links.column("t").to_numpy())
    angle = paper_frames.frame_grid(links, times, ["link"], ["included_angle_deg"])["included_angle_deg"][:, 1:]
    bend = paper_frames.frame_grid(hinges, times, ["hinge"], ["bend_deg"])["bend_deg"]
    assert angle.shape[1] == 12 and bend.shape[1] == 13
    assert angle == pytest.approx(180.0 - bend[:, 1:], abs=1e-9)


def test_new_rows_on_a_short_run(short_run):
    rows = {r["key"]: r for r in paper.comparison(short_run).to_pylist()}
    hinges = short_run.tables["hinges"]
    head = rows["head_cage_normal_peak_n"]
    assert head["ours"] == pytest.approx(float(hinges.column("cage_head_normal").to_numpy().max()))
    assert head["paper"] is None and head["ratio"] is None
    assert "the paper reports no value" in head["note"]
    assert "head_cage_normal_peak_n" in rows["seat_cage_normal_peak_n"]["note"]
    # The excursion of the most deformed link over the (partly recorded) last revolution, by every pair.
    link = int(rows["most_deformed_joint"]["ours"])
    links = short_run.tables["links"]
    mine = links.filter(pc.equal(links.column("link"), link))
    x, y = mine.column("offset_outward").to_numpy(), mine.column("offset_lateral").to_numpy()
    p2p = rows["range_of_motion_peak_to_peak_mm"]
    assert p2p["ours"] == pytest.approx(1e3 * _brute_peak_to_peak(x, y), rel=1e-9)
    assert "the run holds only 0.010 s of it" in p2p["note"]
    assert rows["range_of_motion_mm"]["ours"] <= 1e3 * MAX_RADIAL_OFFSET
