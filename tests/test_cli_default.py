"""The embedded default scene: `ballcage scene show`, `ballcage run` without a scene, `ballcage schema`."""

from __future__ import annotations

import subprocess
import sys
import tomllib

import pyarrow.parquet as pq

import ballcage
from ballcage import _native
from ballcage.scene import default_scene


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "ballcage", *args], capture_output=True, text=True, timeout=120)


def test_scene_show_prints_the_default_scene_which_loads_back(tmp_path):
    proc = _cli("scene", "show")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == default_scene().to_toml(units=True)  # the same values, each with its unit
    parsed = tomllib.loads(proc.stdout)
    assert parsed == tomllib.loads(_native.default_scene_toml())
    assert parsed["kind"] == "drill-pipe"
    assert parsed["pipe"]["joints"] == 12 and parsed["drive"]["speed_rpm"] == 100.0
    path = tmp_path / "paper.toml"
    path.write_text(proc.stdout, encoding="utf-8")
    default = _native.Scene.from_toml(_native.default_scene_toml())
    assert ballcage.load_scene(path).to_toml() == default.to_toml()
    assert default_scene().to_toml() == default.to_toml()


def test_run_without_a_scene_runs_the_paper_scene(tmp_path):
    out = tmp_path / "out"
    proc = _cli("run", "--out", str(out), "--set", "simulation.duration=0.002", "--quiet")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == "" and proc.stderr == ""
    # A drill pipe that does not choose its tables records the engineering ones besides its own.
    tables = ["bodies", "contacts", "links", "hinges", "keys", "drive", "summary", "pairs", "wear"]
    # and the wear map derived from them (the fatigue table needs the run past its ramps, docs/model.md §8.6)
    derived = ["wear_map.parquet", "wear_map.png"]
    assert sorted(p.name for p in out.iterdir()) == sorted([f"{t}.parquet" for t in tables] + ["scene.toml", *derived])
    bodies = pq.read_table(out / "bodies.parquet")
    names = set(bodies.column("body").cast("string").to_pylist())
    assert names == {"upper", "lower", *(f"link{k:02d}" for k in range(1, 13))}  # the chain, by default
    assert max(bodies.column("t").to_pylist()) == 0.002
    assert pq.read_table(out / "contacts.parquet").num_rows > 0
    assert tomllib.loads((out / "scene.toml").read_text(encoding="utf-8"))["simulation"]["duration"] == 0.002


def test_run_without_a_scene_rejects_a_bad_override_in_one_line(tmp_path):
    proc = _cli("run", "--out", str(tmp_path / "out"), "--set", "drive.speed_rmp=60")
    assert proc.returncode == 2
    assert proc.stderr.startswith("ballcage: error: default scene: ") and proc.stderr.count("\n") == 1
    assert "drive.speed_rmp" in proc.stderr
    assert not (tmp_path / "out").exists()


def test_default_scene_overrides_address_the_drill_pipe_toml():
    scene = default_scene(["drive.speed_rpm=60", "simulation.duration=0.5"])
    assert scene.duration == 0.5
    resolved = tomllib.loads(scene.to_toml())
    assert resolved["kind"] == "drill-pipe"
    assert resolved["drive"]["speed_rpm"] == 60


def test_schema_lists_every_table():
    proc = _cli("schema")
    assert proc.returncode == 0, proc.stderr
    headers = [line for line in proc.stdout.splitlines() if line and not line.startswith(" ")]
    assert headers == list(_native.TABLE_NAMES)
    assert set(headers) >= {"bodies", "contacts", "energy", "summary", "links", "hinges", "keys", "drive"}
    links = _cli("schema", "links")
    assert links.returncode == 0 and "radial_offset" in links.stdout and "[m]" in links.stdout


def test_drill_pipe_builder_equals_the_toml_section_and_the_dotted_keys():
    built = (
        ballcage.DrillPipeBuilder()
        .borehole(curvature_radius=2.5)
        .pipe(joints=4, hinge="ideal-cv")
        .drive(speed_rpm=60)
        .load(resisting_moment=900.0)
        .simulation(duration=0.01)
    )
    toml_text = (
        'kind = "drill-pipe"\n[borehole]\ncurvature_radius = 2.5\n[pipe]\njoints = 4\nhinge = "ideal-cv"\n'
        "[drive]\nspeed_rpm = 60\n[load]\nresisting_moment = 900.0\n[simulation]\nduration = 0.01\n"
    )
    dotted = [
        "borehole.curvature_radius=2.5",
        'pipe.hinge="ideal-cv"',
        "pipe.joints=4",
        "drive.speed_rpm=60",
        "load.resisting_moment=900.0",
        "simulation.duration=0.01",
    ]
    a = ballcage.load_scene(built).to_toml()
    assert a == _native.Scene.from_toml(toml_text).to_toml()
    assert a == default_scene(dotted).to_toml()
    resolved = tomllib.loads(a)
    assert resolved["pipe"]["joints"] == 4 and resolved["drive"]["speed_rpm"] == 60
    run = ballcage.simulate(built, progress=False)
    # Four links and the two connectors are recorded; no keys or cages exist in the ideal-CV model.
    names = set(run.bodies["body"].cast("string").to_pylist())
    assert names == {"upper", "lower", "link01", "link02", "link03", "link04"}
