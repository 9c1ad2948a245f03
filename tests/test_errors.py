"""Invalid scenes raise SceneError naming the field, in Python and as one CLI line (exit 2)."""

from __future__ import annotations

import math
import re
import subprocess
import sys
import tomllib

import pytest

import ballcage
from ballcage import cli


def _drop_dt(text: str) -> str:
    out, n = re.subn(r"(?m)^dt = .*\n", "", text)
    assert n == 1
    return out


def _replace(old: str, new: str):
    def edit(text: str) -> str:
        assert text.count(old) == 1, old
        return text.replace(old, new)

    return edit


# (id, edit of ball_drop.toml, accepted .path values)
CASES = [
    ("missing-dt", _drop_dt, {"simulation.dt"}),
    ("negative-mass", _replace("mass = 1.0", "mass = -2.0"), {"bodies[1].mass"}),
    ("unknown-law", _replace('law = "hertz"', 'law = "magic"'), {"contacts[0].normal.law"}),
    ("nan-radius", _replace("radius = 0.05", "radius = nan"), {"bodies[1].shape.radius"}),
]
IDS = [c[0] for c in CASES]


@pytest.fixture
def base_text(ball_drop_path) -> str:
    return ball_drop_path.read_text(encoding="utf-8")


@pytest.mark.parametrize(("case", "edit", "paths"), CASES, ids=IDS)
def test_bad_toml_file_raises_scene_error_naming_the_field(tmp_path, base_text, case, edit, paths):
    path = tmp_path / f"{case}.toml"
    path.write_text(edit(base_text), encoding="utf-8")
    with pytest.raises(ballcage.SceneError) as info:
        ballcage.load_scene(path)
    assert info.value.path in paths
    assert info.value.path in str(info.value)
    assert isinstance(info.value, ValueError)


@pytest.mark.parametrize(("case", "edit", "paths"), CASES, ids=IDS)
def test_bad_dict_raises_scene_error_naming_the_field(base_text, case, edit, paths):
    scene = tomllib.loads(edit(base_text))
    if case == "nan-radius":
        scene["bodies"][1]["shape"]["radius"] = float("nan")
    with pytest.raises(ballcage.SceneError) as info:
        ballcage.load_scene(scene)
    assert info.value.path in paths


def test_scene_error_fields_and_message(base_text):
    scene = tomllib.loads(base_text)
    scene["bodies"][1]["mass"] = -2.0
    with pytest.raises(ballcage.SceneError) as info:
        ballcage.load_scene(scene)
    e = info.value
    assert (e.path, e.value, e.reason) == ("bodies[1].mass", "-2", "must be positive")
    assert str(e) == "scene field `bodies[1].mass` = -2: must be positive"


def test_nan_is_rejected_as_not_finite(base_text):
    scene = tomllib.loads(base_text)
    scene["bodies"][1]["shape"]["radius"] = math.nan
    with pytest.raises(ballcage.SceneError, match="finite"):
        ballcage.load_scene(scene)


def test_bad_override_names_the_field(ball_drop_path):
    with pytest.raises(ballcage.SceneError) as info:
        ballcage.load_scene(ball_drop_path, ["bodies.1.mass=-2"])
    assert info.value.path == "bodies[1].mass"


def _cli(*args: str, cwd=None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "ballcage", *args], capture_output=True, text=True, timeout=120, cwd=cwd
    )


def _one_error_line(proc: subprocess.CompletedProcess[str]) -> str:
    lines = proc.stderr.splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("ballcage: error: "), lines[0]
    assert "Traceback" not in proc.stderr
    return lines[0]


@pytest.mark.parametrize(("case", "edit", "paths"), CASES, ids=IDS)
def test_cli_reports_a_bad_scene_in_one_line_with_exit_code_2(tmp_path, base_text, case, edit, paths):
    path = tmp_path / f"{case}.toml"
    path.write_text(edit(base_text), encoding="utf-8")
    proc = _cli("run", str(path), "--out", str(tmp_path / "out"))
    assert proc.returncode == 2, proc.stderr
    line = _one_error_line(proc)
    assert any(p in line for p in paths), line
    assert str(path) in line
    assert not (tmp_path / "out").exists()
    assert proc.stdout == ""


def test_cli_missing_scene_file_exits_2_naming_it(tmp_path):
    proc = _cli("run", str(tmp_path / "absent.toml"), "--out", str(tmp_path / "out"))
    assert proc.returncode == 2
    assert "absent.toml" in _one_error_line(proc)


@pytest.mark.parametrize("assignment", ["simulation.duration", "=0.1"])
def test_cli_malformed_set_exits_2(tmp_path, ball_drop_path, assignment):
    proc = _cli("run", str(ball_drop_path), "--out", str(tmp_path / "out"), "--set", assignment)
    assert proc.returncode == 2
    assert "--set" in _one_error_line(proc)


def test_cli_invalid_set_value_names_the_field(tmp_path, ball_drop_path):
    proc = _cli("run", str(ball_drop_path), "--out", str(tmp_path / "out"), "--set", "bodies.1.mass=-2")
    assert proc.returncode == 2
    assert "bodies[1].mass" in _one_error_line(proc)


def test_cli_usage_error_is_one_line(capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(["run", "scene.toml"])  # no --out
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("ballcage: error: ") and "--out" in err


def test_cli_simulation_error_exits_1_with_its_message(tmp_path, ball_drop_path, monkeypatch, capsys):
    def diverge(*args, **kwargs):
        raise ballcage.SimulationError("simulation diverged at t = 1.0e-01 s (step 2000): ball left the world")

    monkeypatch.setattr(cli.run, "simulate_then", diverge)
    assert cli.main(["run", str(ball_drop_path), "--out", str(tmp_path / "out")]) == 1
    err = capsys.readouterr().err
    assert err == "ballcage: error: simulation diverged at t = 1.0e-01 s (step 2000): ball left the world\n"
