"""No silent first-order steps (issue 26): a run whose implicit steps fell back to the linearly implicit Euler
step says so in its last line and in ``comparison.md``, with the count and the smallest part step in its metadata.

Newton limited to two iterations per stage cannot converge once the chain touches the tube, so SDIRK2 at fixed
steps of 100 µs halves those steps to h/16 and takes the rest by the fallback; with the default settings (adaptive
ESDIRK3(2)) the same short run takes none.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pyarrow.parquet as pq
import pytest

SHORT = ("--set", "simulation.duration=0.2")
STARVED = (
    "--set",
    'simulation.integrator="sdirk2"',
    "--set",
    "simulation.rtol=0",
    "--set",
    "simulation.newton.max_iterations=2",
)


def _ballcage(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "ballcage", *args], capture_output=True, text=True, check=False)


def test_a_run_with_fallback_steps_says_so_in_its_last_line(tmp_path: Path) -> None:
    out = tmp_path / "starved"
    done = _ballcage("run", "--out", str(out), "--tables", "drive", *SHORT, *STARVED)
    assert done.returncode == 0, done.stderr
    meta = pq.read_metadata(out / "drive.parquet").metadata
    count = int(meta[b"ballcage.fallback_steps"])
    assert count > 0
    # SDIRK2 halves a step four times before it falls back: h/16.
    assert float(meta[b"ballcage.smallest_step_s"]) == pytest.approx(1e-4 / 16, rel=1e-12)
    last = done.stdout.strip().splitlines()[-1]
    assert last.startswith("ballcage: warning: "), last
    assert f"{count} part steps of 6.25e-06 s were taken by the first-order fallback" in last


def test_a_run_without_fallback_steps_prints_no_warning(tmp_path: Path) -> None:
    out = tmp_path / "default"
    done = _ballcage("run", "--out", str(out), "--tables", "drive", *SHORT)
    assert done.returncode == 0, done.stderr
    meta = pq.read_metadata(out / "drive.parquet").metadata
    assert int(meta[b"ballcage.fallback_steps"]) == 0
    assert "ballcage: warning" not in done.stdout
    assert done.stdout.strip().splitlines()[-1].startswith("ballcage: 0.2 s simulated")


def test_the_paper_comparison_flags_a_run_with_fallback_steps(tmp_path: Path) -> None:
    out = tmp_path / "paper"
    done = _ballcage("paper", "--out", str(out), *SHORT, *STARVED)
    assert done.returncode == 0, done.stderr
    assert "first-order fallback" in done.stdout.strip().splitlines()[-1]
    text = (out / "comparison.md").read_text()
    assert "**Warning: " in text and "first-order fallback" in text
