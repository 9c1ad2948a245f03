"""A Rust panic reaches Python as `ballcage.InternalError`, never as an abort of the interpreter.

The panic is injected by the extension built with the test-only cargo feature
``test-panic`` (crates/ballcage-py/Cargo.toml): `Simulation.advance` panics,
inside the GIL-free stepping loop, for a scene named ``ballcage-test-panic``.
That build never ships; scripts/test-all.sh installs it into a side directory
and names it in ``BALLCAGE_TEST_PANIC_PATH``. Each check runs in a subprocess,
so an abort would show as a signal exit code, not take pytest down.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
PANIC_PATH = os.environ.get("BALLCAGE_TEST_PANIC_PATH")
SCENE = REPO / "examples" / "scenes" / "ball_drop.toml"
PANIC_NAME = "ballcage-test-panic"

pytestmark = pytest.mark.skipif(
    not PANIC_PATH, reason="needs the test-panic build in BALLCAGE_TEST_PANIC_PATH (scripts/test-all.sh makes it)"
)


def _python(code: str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(PANIC_PATH)}
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, env=env, cwd=REPO)


def test_the_side_build_is_the_one_imported() -> None:
    result = _python("import ballcage; print(ballcage.__file__)")
    assert result.returncode == 0, result.stderr
    assert Path(result.stdout.strip()).resolve().is_relative_to(Path(PANIC_PATH).resolve())


def test_a_panic_in_advance_is_an_internal_error_and_the_interpreter_goes_on() -> None:
    code = f"""
import ballcage
text = open({str(SCENE)!r}).read()
sim = ballcage.Simulation(ballcage.Scene.from_toml(text, ['name="{PANIC_NAME}"']))
try:
    sim.advance(0.01)
except ballcage.InternalError as e:
    assert isinstance(e, ballcage.Error) and isinstance(e, RuntimeError)
    print("caught:", e)
try:
    sim.advance(0.02)
except ballcage.InputError as e:
    print("after:", e)
# the interpreter and the extension still work: an ordinary scene runs
other = ballcage.Simulation(ballcage.Scene.from_toml(text))
other.advance(0.01)
print("still running:", other.steps > 0)
"""
    result = _python(code)
    assert result.returncode == 0, result.stderr
    out = result.stdout
    assert "caught: internal error in Simulation.advance: injected panic" in out
    assert "the simulation was dropped" in out
    assert "after: the simulation was finished (or dropped after an internal error)" in out
    assert "still running: True" in out


def test_an_ordinary_scene_does_not_panic_in_the_side_build() -> None:
    code = f"""
import ballcage
run = ballcage.simulate({str(SCENE)!r}, progress=False)
print(run.complete)
"""
    result = _python(code)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "True"


def test_the_cli_reports_a_panic_in_one_line_with_exit_code_70(tmp_path: Path) -> None:
    env = {**os.environ, "PYTHONPATH": str(PANIC_PATH)}
    result = subprocess.run(
        [sys.executable, "-m", "ballcage", "run", str(SCENE), "--out", str(tmp_path / "out"), "--set", f'name="{PANIC_NAME}"'],
        capture_output=True, text=True, timeout=120, env=env,
    )
    assert result.returncode == 70, (result.returncode, result.stderr)
    assert result.stderr.count("\n") == 1 and "Traceback" not in result.stderr
    assert "internal error in Simulation.advance" in result.stderr
    assert not any((tmp_path / "out").glob("*.parquet")) if (tmp_path / "out").exists() else True
