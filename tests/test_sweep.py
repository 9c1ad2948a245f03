"""`ballcage sweep`: the sweep file, local parallel runs, failure isolation, resume, and the same sweep on Dask.

Every case is the paper's drill pipe reduced to 2 ideal-CV joints for 0.05 s at
1 ms steps (a few hundredths of a second each). One listed case runs RK4 at
that step, which diverges at its first step on this chain: the case that must
fail without stopping the others. The Dask tests start a real
``dask.distributed.LocalCluster`` with two worker processes (no mocks).
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.dataset as ds
import pyarrow.parquet as pq
import pytest

import ballcage
from ballcage.studies.sweep_spec import SweepError, load_sweep, toml_value, with_verification
from ballcage.studies.sweep_summary import WALL_TIME_COLUMNS, parameter_units

REPO = Path(__file__).resolve().parent.parent
TINY_SET = {
    "pipe.hinge": "ideal-cv",
    "pipe.joints": 2,
    "simulation.duration": 0.05,
    "simulation.rtol": 0,
    "simulation.dt": 1e-3,
    "simulation.output_interval": 2e-3,
}
GRID = {"borehole.curvature_radius": [1.5, 2.5], "drive.speed_rpm": [60.0, 100.0]}
DIVERGING = {"simulation.integrator": "rk4"}  # explicit RK4 at 1 ms: diverges at the first step
SPEC = {"sweep": {"name": "tiny"}, "set": TINY_SET, "grid": GRID, "case": [DIVERGING]}
TINY_TOML = """
[sweep]
name = "tiny"

[set]
"pipe.hinge" = "ideal-cv"
"pipe.joints" = 2
"simulation.duration" = 0.05
"simulation.rtol" = 0
"simulation.dt" = 1e-3
"simulation.output_interval" = 2e-3

[grid]
"borehole.curvature_radius" = [1.5, 2.5]
"drive.speed_rpm" = [60.0, 100.0]

[[case]]
"simulation.integrator" = "rk4"
"""
PARAMETERS = ["borehole.curvature_radius", "drive.speed_rpm", "simulation.integrator"]


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "ballcage", *args], capture_output=True, text=True, timeout=300)


def _without_wall_time(table: pa.Table) -> pa.Table:
    return table.drop_columns([c for c in WALL_TIME_COLUMNS if c in table.column_names])


@pytest.fixture(scope="module")
def local(tmp_path_factory: pytest.TempPathFactory) -> ballcage.studies.SweepResult:
    """The tiny sweep run locally on two threads."""
    out = tmp_path_factory.mktemp("local")
    return ballcage.sweep(SPEC, out, workers=2, progress=False)


# --------------------------------------------------------------------------- the sweep file


def test_cases_are_the_grid_then_the_listed_ones() -> None:
    cases = load_sweep(SPEC).check()
    assert [c.values for c in cases] == [
        {"borehole.curvature_radius": 1.5, "drive.speed_rpm": 60.0},
        {"borehole.curvature_radius": 1.5, "drive.speed_rpm": 100.0},
        {"borehole.curvature_radius": 2.5, "drive.speed_rpm": 60.0},
        {"borehole.curvature_radius": 2.5, "drive.speed_rpm": 100.0},
        {"simulation.integrator": "rk4"},
    ]
    assert cases[0].overrides[0] == "simulation.threads=1"
    assert [c.case_id for c in cases] == [c.case_id for c in load_sweep(SPEC).check()], "ids are stable"
    assert len({c.digest for c in cases}) == 5
    # nested tables mean the same as dotted keys
    nested = {"set": {"pipe": {"hinge": "ideal-cv", "joints": 2}}, "grid": {"drive": {"speed_rpm": [60.0]}}}
    assert load_sweep(nested).check()[0].overrides[-3:] == ('pipe.hinge="ideal-cv"', "pipe.joints=2", "drive.speed_rpm=60.0")


@pytest.mark.parametrize(
    ("spec", "needle"),
    [
        ({"grid": {"borehole.curvature_radiu": [1.0]}}, "`borehole.curvature_radiu`"),
        ({"grid": {"drive.speed_rpm": 60}}, "[grid] `drive.speed_rpm` = 60: must be a non-empty list"),
        ({"grid": {"borehole.curvature_radius": [1.5, -1.0]}}, "case 1 (borehole.curvature_radius=-1.0): scene field"),
        ({"grid": {"drive.speed_rpm": [60]}, "set": {"drive.speed_rpm": 50}}, "both fixed"),
        ({"grids": {}}, "unknown section [grids]"),
        ({"sweep": {"nam": "x"}, "grid": {"drive.speed_rpm": [60]}}, "[sweep] unknown key `nam`"),
        ({"sweep": {"tables": ["linkz"]}, "grid": {"drive.speed_rpm": [60]}}, "unknown table 'linkz'"),
        ({"set": {"drive.speed_rpm": 60}}, "nothing to sweep"),
        ({"case": [{}]}, "[[case]] 0 is empty"),
    ],
)
def test_bad_sweep_files_are_refused_naming_the_field(spec: dict, needle: str) -> None:
    with pytest.raises(SweepError) as info:
        load_sweep(spec).check()
    assert needle in str(info.value)


def test_bad_sweep_file_exits_2_before_running(tmp_path: Path) -> None:
    path = tmp_path / "bad.toml"
    path.write_text('[grid]\n"borehole.curvature_radius" = [1.5, -1.0]\n')
    result = _cli("sweep", str(path), "--out", str(tmp_path / "out"))
    assert result.returncode == 2, result.stderr
    assert result.stderr.startswith(f"ballcage: error: {path}: case 1 (borehole.curvature_radius=-1.0): scene field")
    assert "must be positive" in result.stderr and len(result.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()
    path.write_text("[grid\n")
    assert "TOML syntax error" in _cli("sweep", str(path), "--out", str(tmp_path / "out")).stderr


def test_toml_values_and_parameter_units() -> None:
    assert [toml_value(v) for v in (True, 3, 0.5, "a", [1, "b"], {"x": 1.0})] == [
        "true", "3", "0.5", '"a"', '[1, "b"]', '{"x" = 1.0}'
    ]
    scene = ballcage.scene.default_scene()
    keys = ["borehole.curvature_radius", "drive.speed_rpm", "pipe.joints", "pipe.hinge", "materials.tube.normal.damping"]
    assert parameter_units(scene, [*keys, "simulation.divergence.max_penetration"]) == {
        "borehole.curvature_radius": "m", "drive.speed_rpm": "rpm", "pipe.joints": "", "pipe.hinge": "",
        "materials.tube.normal.damping": "N·s/mm", "simulation.divergence.max_penetration": "",
    }


# --------------------------------------------------------------------------- local runs


def test_summary_has_one_row_per_case_with_units(local: ballcage.studies.SweepResult) -> None:
    summary = pq.read_table(local.out / "summary.parquet")
    assert summary.equals(local.summary)
    assert summary.column("case").to_pylist() == [0, 1, 2, 3, 4]
    assert summary.column("status").to_pylist() == ["ok"] * 4 + ["diverged"]
    assert summary.column_names[4:7] == PARAMETERS
    assert summary.column("borehole.curvature_radius").to_pylist() == [1.5, 1.5, 2.5, 2.5, 1.5]  # resolved values
    assert summary.column("simulation.integrator").to_pylist() == ["esdirk32"] * 4 + ["rk4"]
    for name in ("tube_normal_mean_link_01_n", "tube_normal_peak_link_02_n", "tube_normal_mean_max_n", "efficiency"):
        assert all(v is not None for v in summary.column(name).to_pylist()[:4]), name
    # the ideal-CV hinge has no cages or keys: null, not 0
    assert summary.column("key_peak_n").null_count == 5
    assert summary.column("seat_cage_normal_peak_n").null_count == 5
    assert summary.column("steps").to_pylist()[:4] == [50] * 4
    units = json.loads(summary.schema.metadata[b"ballcage.units"])
    assert units["borehole.curvature_radius"] == "m" and units["drive.speed_rpm"] == "rpm"
    assert units["tube_normal_mean_link_01_n"] == "N" and units["wall_time_s"] == "s"
    assert units["included_angle_min_deg"] == "deg" and units["range_of_motion_mm"] == "mm"
    for field in summary.schema:
        assert b"unit" in field.metadata and field.metadata[b"description"], field.name


def test_diverging_case_is_recorded_with_partial_data(local: ballcage.studies.SweepResult) -> None:
    row = local.summary.to_pylist()[4]
    assert row["status"] == "diverged" and "diverged" in row["error"] and row["steps"] <= 2
    assert local.failed == 1 and local.ran == 5 and local.skipped == 0
    links = pq.read_table(local.out / "links" / "case=0004" / "part.parquet")
    assert 0 < links.num_rows < 10
    assert links.schema.metadata[b"ballcage.complete"] == b"false"
    record = json.loads((local.out / "cases" / "case=0004.json").read_text())
    assert record["status"] == "diverged" and record["case_id"] == row["case_id"]
    assert (local.out / "cases" / "case=0004.scene.toml").is_file()


def test_tables_open_as_one_hive_dataset_with_a_case_column(local: ballcage.studies.SweepResult) -> None:
    for table in ("links", "hinges", "drive", "summary"):
        data = ds.dataset(local.out / table, format="parquet", partitioning="hive").to_table()
        assert sorted(set(data.column("case").to_pylist())) == [0, 1, 2, 3, 4], table
    links = ds.dataset(local.out / "links", partitioning="hive").to_table()
    assert links.schema.field("tube_normal").metadata[b"unit"] == b"N"
    assert not (local.out / "bodies").exists(), "per-body tables are not recorded by default"
    assert {p.stem for p in (local.out / "plots").glob("*.png")} == set(PARAMETERS)
    assert not list(local.out.rglob("*.tmp")), "no temporary file left behind"


def test_other_readers_open_the_datasets(local: ballcage.studies.SweepResult) -> None:
    """polars (in the test extra, so this runs) does what README.md and docs/studies.md show it doing.

    README: ``json.loads(pl.read_parquet_metadata(FILE)["ballcage.units"])``; docs/studies.md: the
    links as one hive dataset, each case's peak tube force joined with the summary on ``case``.
    """
    import polars as pl

    part = local.out / "links" / "case=0000" / "part.parquet"
    units = json.loads(pl.read_parquet_metadata(str(part))["ballcage.units"])
    assert units == json.loads(pq.read_metadata(part).metadata[b"ballcage.units"])
    assert units["tube_normal"] == "N" and units["t"] == "s"
    links = pl.scan_parquet(str(local.out / "links" / "**" / "*.parquet"), hive_partitioning=True)
    summary = pl.read_parquet(local.out / "summary.parquet")
    peaks = links.group_by("case").agg(pl.col("tube_normal").max()).collect().join(summary, on="case").sort("case")
    assert peaks["case"].to_list() == [0, 1, 2, 3, 4]
    assert peaks["case_id"].to_list() == local.summary.column("case_id").to_pylist()
    arrow = ds.dataset(local.out / "links", format="parquet", partitioning="hive").to_table()
    for case, peak in zip(peaks["case"], peaks["tube_normal"], strict=True):
        assert peak == max(arrow.filter(pc.equal(arrow["case"], case)).column("tube_normal").to_pylist()), case


def test_resume_skips_finished_cases_and_reruns_missing_ones(
    local: ballcage.studies.SweepResult, tmp_path: Path
) -> None:
    out = tmp_path / "copy"
    shutil.copytree(local.out, out)
    again = ballcage.sweep(SPEC, out, workers=2, progress=False)
    assert (again.ran, again.skipped) == (0, 5)
    assert _without_wall_time(again.summary).equals(_without_wall_time(local.summary))
    assert again.summary.column("wall_time_s").equals(local.summary.column("wall_time_s")), "nothing ran again"
    (out / "cases" / "case=0002.json").unlink()  # as if interrupted before its record was written
    (out / "links" / "case=0003" / "part.parquet").unlink()  # a record whose files are gone
    third = ballcage.sweep(SPEC, out, workers=2, progress=False)
    assert (third.ran, third.skipped) == (2, 3)
    assert _without_wall_time(third.summary).equals(_without_wall_time(local.summary))
    retried = ballcage.sweep(SPEC, out, workers=1, retry_failed=True, progress=False)
    assert (retried.ran, retried.skipped) == (1, 4)


def test_verification_runs_follow_the_cases_and_give_each_quantity_s_numerical_error(
    local: ballcage.studies.SweepResult, tmp_path: Path
) -> None:
    # The tiny sweep again with verification, into a copy of its folder: its 5 cases keep their hashes and are
    # skipped, and each runs again at `ballcage run --verify`'s setting for its fixed steps: dt/3 for ESDIRK3(2)
    # (order 3), dt/2 for RK4 (order 4).
    out = tmp_path / "verified"
    shutil.copytree(local.out, out)
    spec = with_verification(SPEC)
    assert (spec.verifies, spec.verification) == (5, "dt/3, dt/2")
    result = ballcage.sweep(spec, out, workers=2, progress=False)
    assert (result.ran, result.skipped) == (5, 5)
    rows = result.summary.to_pylist()
    assert [r["verifies"] for r in rows] == [None] * 5 + [0, 1, 2, 3, 4]
    assert [r["simulation.dt"] for r in rows[5:]] == [1e-3 / 3] * 4 + [1e-3 / 2]
    assert result.summary.schema.metadata[b"ballcage.sweep_verification"] == b"dt/3, dt/2"
    # Every quantity's error is |value - its verification run's value| on the sweep's own rows; null on the
    # verification rows and for the diverged RK4 case.
    errors = [n for n in result.summary.column_names if n.endswith("_error")]
    assert "tube_normal_mean_all_n_error" in errors
    measured = 0
    for name in errors:
        quantity = name.removesuffix("_error")
        assert result.summary.schema.field(name).metadata[b"unit"] == result.summary.schema.field(quantity).metadata[b"unit"]
        for k in range(4):
            a, b = rows[k][quantity], rows[k + 5][quantity]
            assert rows[k][name] == (abs(a - b) if a is not None and b is not None else None), (name, k)
            measured += bool(rows[k][name])
        assert rows[4][name] is None and all(r[name] is None for r in rows[5:])
    assert measured > 0  # the runs differ: the errors are measured, not zero by construction
    # The plots stay those of the sweep's own cases against its own keys.
    assert {p.stem for p in (out / "plots").glob("*.png")} == set(PARAMETERS)
    assert "largest numerical errors (each case against its run at dt/3, dt/2)" in "\n".join(
        ballcage.studies.sweep_run.describe(result))  # fmt: skip


def test_a_folder_of_another_sweep_is_refused(local: ballcage.studies.SweepResult, tmp_path: Path) -> None:
    out = tmp_path / "copy"
    shutil.copytree(local.out, out)
    other = {**SPEC, "set": {**TINY_SET, "simulation.duration": 0.04}}
    with pytest.raises(SweepError, match="holds case 0 of another sweep"):
        ballcage.sweep(other, out, progress=False)


def test_cli_runs_resumes_and_says_how_many_it_skipped(tmp_path: Path) -> None:
    path = tmp_path / "tiny.toml"
    path.write_text(TINY_TOML)
    out = tmp_path / "out"
    first = _cli("sweep", str(path), "--out", str(out), "--workers", "2", "--no-plots")
    assert first.returncode == 1, first.stderr  # one case diverged; the others ran
    assert "1 of 5 cases did not finish (case 0004-" in first.stderr
    assert "5/5 cases, 1 failed" in first.stderr and "left" in first.stderr
    assert "wrote" in first.stdout and (out / "summary.parquet").is_file() and not (out / "plots").exists()
    second = _cli("sweep", str(path), "--out", str(out), "--quiet")
    assert second.returncode == 1, second.stderr
    third = _cli("sweep", str(path), "--out", str(out))
    assert "5 already finished" in third.stderr and "(skipped), running 0" in third.stderr
    assert "0 cases run, 5 skipped" in third.stdout
    zero = _cli("sweep", str(path), "--out", str(out), "--workers", "0")
    assert zero.returncode == 2 and "--workers: 0: must be at least 1" in zero.stderr, (zero.returncode, zero.stderr)


def test_cli_verify_adds_the_verification_runs_and_names_the_largest_error(tmp_path: Path) -> None:
    path = tmp_path / "tiny.toml"
    path.write_text(TINY_TOML.split("[[case]]")[0])  # the grid's 4 cases, none diverging
    out = tmp_path / "out"
    done = _cli("sweep", str(path), "--out", str(out), "--workers", "2", "--no-plots", "--verify")
    assert done.returncode == 0, done.stderr
    assert "sweep tiny: 8 cases" in done.stderr
    assert "largest numerical errors (each case against its run at dt/3): " in done.stdout
    summary = pq.read_table(out / "summary.parquet")
    assert summary.column("verifies").to_pylist() == [None] * 4 + [0, 1, 2, 3]


def test_example_sweep_file_is_valid() -> None:
    spec = load_sweep(REPO / "examples" / "sweeps" / "curvature_rpm.toml")
    assert len(spec.check()) == 9 and spec.parameters == ["borehole.curvature_radius", "drive.speed_rpm"]


# --------------------------------------------------------------------------- Dask


@pytest.fixture(scope="module")
def dask_client():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        yield client


@pytest.mark.filterwarnings("ignore::DeprecationWarning", "ignore::ResourceWarning", "ignore::UserWarning")
def test_dask_sweep_matches_the_local_one_and_resumes(
    dask_client, local: ballcage.studies.SweepResult, tmp_path: Path
) -> None:
    out = tmp_path / "dask"
    result = ballcage.sweep(SPEC, out, client=dask_client, progress=False)
    assert (result.ran, result.skipped, result.failed) == (5, 0, 1)
    assert _without_wall_time(result.summary).equals(_without_wall_time(local.summary))
    assert result.summary.column("status").to_pylist()[4] == "diverged"
    links = ds.dataset(out / "links", partitioning="hive").to_table()
    local_links = ds.dataset(local.out / "links", partitioning="hive").to_table()
    assert links.sort_by([("case", "ascending"), ("step", "ascending"), ("link", "ascending")]).equals(
        local_links.sort_by([("case", "ascending"), ("step", "ascending"), ("link", "ascending")])
    )
    (out / "cases" / "case=0001.json").unlink()
    again = ballcage.sweep(SPEC, out, client=dask_client, progress=False)
    assert (again.ran, again.skipped) == (1, 4)
    assert _without_wall_time(again.summary).equals(_without_wall_time(local.summary))


@pytest.mark.filterwarnings("ignore::DeprecationWarning", "ignore::ResourceWarning", "ignore::UserWarning")
def test_cli_scheduler_option_runs_on_the_cluster(dask_client, tmp_path: Path) -> None:
    path = tmp_path / "tiny.toml"
    path.write_text(TINY_TOML)
    address = dask_client.scheduler.address
    result = _cli("sweep", str(path), "--out", str(tmp_path / "out"), "--scheduler", address, "--no-plots")
    assert result.returncode == 1, result.stderr
    assert f"on the Dask cluster at {address}" in result.stderr
    assert pq.read_table(tmp_path / "out" / "summary.parquet").column("status").to_pylist() == ["ok"] * 4 + ["diverged"]
