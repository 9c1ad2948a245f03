"""`ballcage run` writes Parquet + scene.toml identical to simulate(); writes are atomic."""

from __future__ import annotations

import subprocess
import sys
import tomllib
from pathlib import Path

import pyarrow.parquet as pq
import pytest
from signalled import python_command

import ballcage

BALL_DROP = Path(__file__).resolve().parent.parent / "examples" / "scenes" / "ball_drop.toml"
WALL_TIME = b"ballcage.wall_time_s"
# Metadata that depends on the machine's speed.
TIMING = {WALL_TIME, b"ballcage.real_time_factor"}
METADATA_KEYS = {
    b"ballcage.scene",
    b"ballcage.version",
    b"ballcage.integrator",
    b"ballcage.dt_s",
    b"ballcage.wall_time_s",
    b"ballcage.complete",
}


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "ballcage", *args], capture_output=True, text=True, timeout=120)


def _without_wall_time(table):
    meta = {k: v for k, v in (table.schema.metadata or {}).items() if k not in TIMING}
    return table.replace_schema_metadata(meta)


@pytest.fixture(scope="module")
def cli_out(tmp_path_factory):
    out = tmp_path_factory.mktemp("run") / "out"
    proc = _cli("run", str(BALL_DROP), "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    return out, proc


def test_cli_run_writes_tables_and_scene_and_summarises_each(cli_out):
    out, proc = cli_out
    assert sorted(p.name for p in out.iterdir()) == ["bodies.parquet", "contacts.parquet", "scene.toml"]
    lines = proc.stdout.splitlines()
    assert len(lines) == 5
    for name, line in zip(["bodies.parquet", "contacts.parquet", "scene.toml"], lines[:3], strict=True):
        assert name in line
    assert "rows" in lines[0]
    # Then how close it came to being stopped: the metadata's shares of the divergence limits.
    meta = pq.read_table(out / "bodies.parquet").schema.metadata
    depth = float(meta[b"ballcage.penetration_of_limit"])
    pair = meta[b"ballcage.penetration_of_limit_pair"].decode()
    assert 0.0 < depth < 1.0
    assert lines[3].startswith("ballcage: divergence checks (simulation.divergence): deepest penetration ")
    assert f"{depth:.3g} of its pair's limit (pair {pair}, t = " in lines[3]
    assert "energy created at most " in lines[3]
    # Last, what the run cost: 0.2 s simulated with rk4 at 50 µs is 4000 steps.
    assert "0.2 s simulated" in lines[4] and "real-time factor" in lines[4] and "4000 steps" in lines[4]
    assert proc.stderr == ""  # a 0.2 s scene is too quick for a progress bar


@pytest.mark.parametrize(("integrator", "rtol", "stages"), [("esdirk32", 0.0, 3), ("trbdf2", 0.0, 2), ("trbdf2", 1e-4, 2)])
def test_cli_run_states_the_cost_of_an_esdirk_pair_at_fixed_and_adaptive_steps(tmp_path, integrator, rtol, stages):
    # Fixed steps (rtol 0) state the step and their count, adaptive ones the tolerance and the steps chosen; the
    # Newton iterations per stage count the pair's own implicit stages (ESDIRK3(2) three a step, TR-BDF2 two).
    out = tmp_path / "out"
    integrate = ("--set", f'simulation.integrator="{integrator}"', "--set", f"simulation.rtol={rtol}")
    proc = _cli("run", str(BALL_DROP), "--out", str(out), *integrate)
    assert proc.returncode == 0, proc.stderr
    last = proc.stdout.splitlines()[-1]
    meta = pq.read_table(out / "bodies.parquet").schema.metadata
    accepted, rejected = int(meta[b"ballcage.accepted_steps"]), int(meta[b"ballcage.rejected_steps"])
    if rtol:
        assert f"{integrator} adaptive at rtol 0.0001, {accepted} steps ({rejected} rejected" in last
    else:
        assert f"{integrator} at 5e-05 s, 4000 steps" in last
        assert (accepted, rejected) == (4000, 0)
    per_stage = int(meta[b"ballcage.newton_iterations"]) / (stages * (accepted + rejected))
    assert f", {per_stage:.2f} Newton iterations per stage" in last


def test_parquet_files_equal_the_in_memory_tables(cli_out, ball_drop_path):
    out, _ = cli_out
    run = ballcage.simulate(ball_drop_path)
    assert run.contacts.num_rows > 0
    for name, table in run.tables.items():
        read = pq.read_table(out / f"{name}.parquet")
        assert read.equals(table), name
        # Field metadata (units) and run metadata survive, except the wall time.
        assert _without_wall_time(read).schema.equals(_without_wall_time(table).schema, check_metadata=True), name
        assert METADATA_KEYS <= set(read.schema.metadata), name
        assert float(read.schema.metadata[WALL_TIME]) >= 0.0
        assert read.schema.metadata[b"ballcage.complete"] == b"true"
    assert pq.read_table(out / "bodies.parquet").schema.field("pos_z").metadata[b"unit"] == b"m"
    assert pq.read_table(out / "contacts.parquet").schema.field("normal_force").metadata[b"unit"] == b"N"


def test_written_scene_toml_loads_and_is_the_resolved_scene(cli_out, ball_drop_path):
    out, _ = cli_out
    text = (out / "scene.toml").read_text(encoding="utf-8")
    assert text == ballcage.load_scene(ball_drop_path).to_toml()
    assert ballcage.load_scene(out / "scene.toml").to_toml() == text
    assert pq.read_table(out / "bodies.parquet").schema.metadata[b"ballcage.scene"].decode() == text


def test_cli_set_overrides_the_scene(tmp_path, ball_drop_path):
    out = tmp_path / "short"
    proc = _cli("run", str(ball_drop_path), "--out", str(out), "--set", "simulation.duration=0.05", "--quiet")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == "" and proc.stderr == ""
    assert pq.read_table(out / "bodies.parquet").num_rows == round(0.05 / 1e-3) + 1
    assert tomllib.loads((out / "scene.toml").read_text(encoding="utf-8"))["simulation"]["duration"] == 0.05


def test_cli_schema_prints_units_and_descriptions():
    proc = _cli("schema", "bodies")
    assert proc.returncode == 0, proc.stderr
    schema = ballcage.table_schema("bodies")
    lines = proc.stdout.splitlines()
    assert lines[0] == "bodies"
    assert len(lines) == 1 + len(schema)
    pos_z = next(line for line in lines if line.split()[0] == "pos_z")
    assert "[m]" in pos_z
    assert schema.field("pos_z").metadata[b"description"].decode() in pos_z
    every = _cli("schema")
    assert every.returncode == 0
    assert [line for line in every.stdout.splitlines() if line and not line.startswith(" ")] == list(
        ballcage._native.TABLE_NAMES
    )


def _run_small(ball_drop_path):
    return ballcage.simulate(ball_drop_path, overrides=["simulation.duration=0.01"])


def _leftovers(directory):
    return sorted(p.name for p in directory.iterdir() if p.name.startswith(".") or p.name.endswith(".tmp"))


def test_failed_parquet_write_leaves_no_file_and_no_temporary(tmp_path, ball_drop_path, monkeypatch):
    run = _run_small(ball_drop_path)
    real_write_table = pq.write_table

    def write_half_then_fail(table, where, **kwargs):
        real_write_table(table.slice(0, 1), where, **kwargs)  # something is on disk...
        raise OSError("disk full")  # ...then the write fails midway

    monkeypatch.setattr(pq, "write_table", write_half_then_fail)
    out = tmp_path / "out"
    with pytest.raises(OSError, match="disk full"):
        run.write(out)
    assert not (out / "bodies.parquet").exists()
    assert _leftovers(out) == []


def test_failed_write_keeps_the_previous_file_intact(tmp_path, ball_drop_path, monkeypatch):
    run = _run_small(ball_drop_path)
    out = tmp_path / "out"
    run.write(out)
    before = (out / "bodies.parquet").read_bytes()

    def fail(table, where, **kwargs):
        with open(where, "wb") as f:
            f.write(b"PAR1 truncated")
        raise KeyboardInterrupt

    monkeypatch.setattr(pq, "write_table", fail)
    with pytest.raises(KeyboardInterrupt):
        ballcage.simulate(ball_drop_path, overrides=["simulation.duration=0.02"]).write(out)
    assert (out / "bodies.parquet").read_bytes() == before
    assert _leftovers(out) == []


def test_write_returns_the_paths_and_creates_the_directory(tmp_path, ball_drop_path):
    run = _run_small(ball_drop_path)
    out = tmp_path / "a" / "b"
    paths = run.write(out)
    assert paths == {
        "bodies": out / "bodies.parquet",
        "contacts": out / "contacts.parquet",
        "scene": out / "scene.toml",
    }
    assert all(p.is_file() for p in paths.values())
    assert _leftovers(out) == []
    assert pq.read_table(paths["bodies"]).equals(run.bodies)


def test_reusing_an_output_folder_removes_the_earlier_runs_tables(tmp_path):
    out = tmp_path / "out"
    three = 'record.tables=["bodies", "contacts", "energy"]'
    assert _cli("run", str(BALL_DROP), "--out", str(out), "--quiet", "--set", three).returncode == 0
    assert (out / "energy.parquet").exists()
    (out / "notes.txt").write_text("mine")
    # Without --overwrite the folder of another run is refused, naming what it holds.
    refused = _cli("run", str(BALL_DROP), "--out", str(out), "--quiet")
    assert refused.returncode == 2
    assert "--overwrite" in refused.stderr and "energy.parquet" in refused.stderr
    assert (out / "energy.parquet").exists()
    proc = _cli(
        "run", str(BALL_DROP), "--out", str(out), "--quiet", "--overwrite", "--set", 'record.tables=["bodies"]'
    )
    assert proc.returncode == 0, proc.stderr
    # Only this run's tables remain beside its scene.toml; files ballcage did not write stay.
    assert sorted(p.name for p in out.glob("*.parquet")) == ["bodies.parquet"]
    assert (out / "notes.txt").read_text() == "mine"


def test_ctrl_c_writes_what_was_computed_marked_incomplete(tmp_path, monkeypatch, capsys):
    # An interrupt arrives between two chunks of the run (as Ctrl-C does, once
    # the native step returns): the tables so far are written, marked incomplete.
    import ballcage.cli
    import ballcage.run

    calls = {"n": 0}
    real_update = ballcage.run.ProgressBar.update

    def interrupt_on_the_tenth(self, t):
        calls["n"] += 1
        if calls["n"] == 10:
            raise KeyboardInterrupt
        real_update(self, t)

    monkeypatch.setattr(ballcage.run.ProgressBar, "update", interrupt_on_the_tenth)
    out = tmp_path / "out"
    code = ballcage.cli.main(["run", str(BALL_DROP), "--out", str(out), "--quiet"])
    assert code == 130
    assert "interrupted at t =" in capsys.readouterr().err
    bodies = pq.read_table(out / "bodies.parquet")
    assert bodies.schema.metadata[b"ballcage.complete"] == b"false"
    full = ballcage.simulate(BALL_DROP).bodies
    assert 0 < bodies.num_rows < full.num_rows


def test_every_parquet_file_carries_units_and_descriptions_as_key_value_metadata(cli_out):
    # What DuckDB's parquet_kv_metadata() and polars see: the file's raw
    # key-value pairs, read here without decoding the Arrow schema.
    import json

    out, _ = cli_out
    raw = pq.read_metadata(out / "bodies.parquet").metadata
    units = json.loads(raw[b"ballcage.units"])
    descriptions = json.loads(raw[b"ballcage.descriptions"])
    assert units["pos_z"] == "m" and units["vel_x"] == "m/s" and units["t"] == "s"
    assert "world frame" in descriptions["pos_x"]
    assert set(units) == set(pq.read_table(out / "bodies.parquet").column_names)


def test_a_real_sigint_leaves_readable_tables_marked_incomplete(tmp_path):
    # Four joints over 6 s at SDIRK2's fixed 100 µs run for tens of seconds (the adaptive default
    # finishes 1.8 s of four joints within a few); the progress lines on stderr (one per 10 %) say
    # the run is under way; SIGINT then arrives mid-run.
    import signal

    out = tmp_path / "out"
    slow = ["--set", "pipe.joints=4", "--set", "simulation.duration=6", "--set", 'simulation.integrator="sdirk2"']
    proc = subprocess.Popen(
        python_command("-m", "ballcage", "run", "--out", str(out), *slow, "--set", "simulation.rtol=0"),
        stderr=subprocess.PIPE,
        stdout=subprocess.DEVNULL,
        text=True,
    )
    try:
        assert proc.stderr is not None
        for line in proc.stderr:
            if "%" in line:
                break
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
    assert proc.returncode == 130, err
    assert "interrupted at t =" in err
    table = pq.read_table(out / "bodies.parquet")
    assert table.schema.metadata[b"ballcage.complete"] == b"false"
    assert 0 < table.column("t").to_numpy().max() < 6.0
