"""Studies that survive faults (issue 27, item 6), with real processes and a real Dask ``LocalCluster``:

- ``kill -9`` of a ``python -m ballcage sensitivity`` process mid-run, twice: running the command again
  resumes without running a finished case again (each finished record keeps its bytes and its mtime) and
  leaves no partial file (`test_faults.assert_no_partial_file`: every file under a final name reads
  completely, every other one is a hidden temporary), and the study's table equals a study never killed;
- ``--case-timeout`` (``case_timeout=``): a case past its limit is recorded ``timed-out`` with its frames
  up to then, the others go on, and running the sweep again runs it again;
- a Dask worker process killed (SIGKILL) in the middle of a case: Dask runs the case again on a worker,
  the sweep completes, and every value and table equals a local run's.

The runs are the ball drop (examples/scenes/ball_drop.toml) at 1 µs RK4 steps, about 0.45 s of wall time per
simulated second on one core of this machine, so that a case lasts long enough to be killed in.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pyarrow as pa
import pyarrow.dataset as ds
import pyarrow.parquet as pq
import pytest
from test_faults import TIMEOUT_S, _files, _kill, _start, _wait_for, assert_no_partial_file

import ballcage
from ballcage.scene import default_scene
from ballcage.studies.sensitivity_design import add_check, oat_design
from ballcage.studies.sensitivity_parameters import parameter_ranges
from ballcage.studies.sensitivity_run import TIMEOUT_FACTOR, TIMEOUT_FLOOR_S, _default_case_timeout, sensitivity
from ballcage.studies.sweep_summary import WALL_TIME_COLUMNS

REPO = Path(__file__).resolve().parent.parent
BALL_DROP = REPO / "examples" / "scenes" / "ball_drop.toml"
MASS, STIFFNESS = "bodies[1].mass", "contacts[0].normal.stiffness"
SLOW = ("--set", "simulation.dt=1e-6")  # 1 µs RK4 steps: ~0.45 s of wall time per simulated second


def _records(out: Path) -> list[Path]:
    return sorted((out / "cases").glob("case=*.json")) if (out / "cases").is_dir() else []


def _without_wall_time(table: pa.Table) -> pa.Table:
    return table.drop_columns([c for c in WALL_TIME_COLUMNS if c in table.column_names])


def _dataset(out: Path, table: str) -> pa.Table:
    data = ds.dataset(out / table, format="parquet", partitioning="hive").to_table()
    keys = ("case", "step", "body_id", "pair_id", "point_index")
    return data.sort_by([(c, "ascending") for c in keys if c in data.column_names])


# --------------------------------------------------------------------------- kill -9 of a sensitivity study


def test_sigkill_of_a_sensitivity_study_then_rerun_resumes_without_redoing_finished_runs(tmp_path: Path) -> None:
    """6 runs of 0.6 s simulated (the base, the mass and the stiffness at each end, the base at dt/2), one at a
    time: killed after the first run's record, killed again as the next file appears, then run to the end."""
    out = tmp_path / "study"
    args = ["sensitivity", str(BALL_DROP), "--out", str(out), "--parameters", f"{MASS}=0.5:2.0,{STIFFNESS}=5e7:2e8",
            *SLOW, "--duration", "0.6", "--workers", "1", "--no-plots"]  # fmt: skip
    runs = out / "runs"
    proc = _start(args, tmp_path / "first.log")
    assert _wait_for(proc, lambda: len(_records(runs)) >= 1), "the study finished before the kill"
    assert _kill(proc) == -signal.SIGKILL
    assert_no_partial_file(out)
    first = len(_records(runs))
    assert 1 <= first < 6 and not (out / "sensitivity.parquet").exists()
    before = set(_files(out))
    proc = _start(args, tmp_path / "second.log")
    assert _wait_for(proc, lambda: bool(set(_files(out)) - before)), "the study finished before the kill"
    assert _kill(proc) == -signal.SIGKILL
    assert_no_partial_file(out)  # only hidden temporaries beside complete files
    finished = {p: (p.stat().st_mtime_ns, p.read_bytes()) for p in _records(runs)}
    assert first <= len(finished) < 6, len(finished)

    last = subprocess.run([sys.executable, "-m", "ballcage", *args], capture_output=True, text=True, timeout=TIMEOUT_S)
    assert last.returncode == 0, last.stderr
    assert f"6 cases; {len(finished)} already finished" in last.stderr, last.stderr
    counts = re.search(r"(\d+) runs run, (\d+) skipped", last.stdout)
    assert counts and (int(counts[1]), int(counts[2])) == (6 - len(finished), len(finished)), last.stdout
    for path, (mtime, data) in finished.items():  # a finished run was not run again: its record is untouched
        assert (path.stat().st_mtime_ns, path.read_bytes()) == (mtime, data), path
    assert assert_no_partial_file(runs)["final"] == 1 + 6 * 4  # the summary; per run 2 tables, its scene, its record
    print(f"sensitivity: {first} of 6 runs finished at the first kill, {len(finished)} at the second")

    clean = sensitivity(BALL_DROP, tmp_path / "clean", parameters={MASS: (0.5, 2.0), STIFFNESS: (5e7, 2e8)},
                        overrides=[SLOW[1]], duration=0.6, workers=2, plots=False, progress=False)  # fmt: skip
    resumed = pq.read_table(out / "sensitivity.parquet")
    assert resumed.equals(clean.table)  # every value, to the bit
    depth = {(r["parameter"], r["quantity"]): r for r in resumed.to_pylist()}[(MASS, "depth_peak[ground/ball]")]
    assert depth["value_low"] < depth["base"] < depth["value_high"]  # a heavier ball lands deeper


# --------------------------------------------------------------------------- --case-timeout


def _limit_sweep(tmp_path: Path) -> Path:
    """Two cases of the ball drop at 1 µs steps: 0.05 s simulated (~0.03 s of wall time) and 5 s (~2.3 s)."""
    spec = tmp_path / "limit.toml"
    spec.write_text(
        f'[sweep]\nname = "limit"\nbase = "{BALL_DROP}"\n\n[set]\n"simulation.dt" = 1e-6\n\n'
        '[grid]\n"simulation.duration" = [0.05, 5.0]\n',
        encoding="utf-8",
    )
    return spec


def test_a_case_past_its_time_limit_is_recorded_timed_out_and_the_others_go_on(tmp_path: Path) -> None:
    spec, out = _limit_sweep(tmp_path), tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "ballcage", "sweep", str(spec), "--out", str(out), "--workers", "2",
                           "--case-timeout", "0.5", "--no-plots"], capture_output=True, text=True, timeout=TIMEOUT_S)
    assert proc.returncode == 1, proc.stderr
    error = [line for line in proc.stderr.splitlines() if line.startswith("ballcage: error:")]
    assert len(error) == 1 and "1 of 2 cases did not finish (case 0001-" in error[0] and "timed-out" in error[0], error
    summary = pq.read_table(out / "summary.parquet").to_pylist()
    assert [r["status"] for r in summary] == ["ok", "timed-out"]
    stopped = summary[1]
    message = stopped["error"]
    for needle in (f"case {stopped['case_id']} (simulation.duration=5.0) timed out", "time limit of 0.5 s",
                   "--case-timeout SECONDS", "case_timeout=", "run the same command again"):  # fmt: skip
        assert needle in message, (needle, message)
    # stopped between two of its 200 pieces (25 ms of simulated time each) once past 0.5 s of wall time
    assert 0.0 < stopped["simulated_time_s"] < 5.0 and 0.5 <= stopped["case_wall_time_s"] < 0.5 + 5.0, stopped
    assert summary[0]["status"] == "ok" and summary[0]["simulated_time_s"] == pytest.approx(0.05)  # ran to its end
    bodies = pq.read_table(out / "bodies" / "case=0001" / "part.parquet")  # the frames up to the stop
    assert bodies.schema.metadata[b"ballcage.complete"] == b"false"
    assert max(bodies.column("t").to_pylist()) == pytest.approx(stopped["simulated_time_s"], abs=1.5e-3)
    assert_no_partial_file(out)

    again = ballcage.sweep(spec, out, workers=2, plots=False, progress=False)  # no limit: the timed-out case runs again
    assert (again.ran, again.skipped, again.failed) == (1, 1, 0)
    assert again.summary.column("status").to_pylist() == ["ok", "ok"]
    assert again.summary.column("simulated_time_s").to_pylist() == pytest.approx([0.05, 5.0])
    complete = pq.read_table(out / "bodies" / "case=0001" / "part.parquet")
    assert complete.schema.metadata[b"ballcage.complete"] == b"true" and complete.num_rows > bodies.num_rows
    assert complete.slice(0, bodies.num_rows).equals(bodies)  # the stopped run's frames are the full run's first ones


def test_a_sensitivity_run_past_its_time_limit_is_noted_in_the_table(tmp_path: Path) -> None:
    """The step as the parameter: the run at 1 µs (its low end) takes ~2.3 s, past a 0.5 s limit; the others ~0.1 s."""
    study = sensitivity(BALL_DROP, tmp_path / "study", parameters={"simulation.dt": (1e-6, 1e-4)}, duration=5.0,
                        case_timeout=0.5, workers=2, plots=False, progress=False)  # fmt: skip
    assert study.case_timeout_s == 0.5 and study.failed == 1
    assert study.sweep.summary.column("status").to_pylist() == ["ok", "timed-out", "ok", "ok"]  # base, low, high, check
    row = {r["quantity"]: r for r in study.table.to_pylist()}["normal_peak[ground/ball]"]
    assert row["value_low"] is None and row["value_high"] is not None and row["base"] is not None
    assert row["note"].startswith("the low run (case 1) timed-out: case 0001-") and "time limit of 0.5 s" in row["note"]
    meta = study.table.schema.metadata
    assert meta[b"ballcage.sensitivity.case_timeout_s"] == b"0.5"
    assert "--case-timeout 0.5" in meta[b"ballcage.sensitivity.command"].decode()


def test_the_default_case_timeout_is_ten_times_the_longest_run_and_at_least_a_minute() -> None:
    scene = default_scene()  # the paper's scene: adaptive ESDIRK3(2), checked at rtol/10
    design = oat_design(parameter_ranges(scene, ["pipe.neck_radius"]))
    add_check(design, scene)
    weight = 10 ** (1 / 3)  # the verification run at rtol/10 costs about 10^(1/3) runs
    assert _default_case_timeout(20.0, design) == pytest.approx(TIMEOUT_FACTOR * 20.0 * weight)  # 431 s
    assert _default_case_timeout(0.5, design) == TIMEOUT_FLOOR_S == 60.0
    assert _default_case_timeout(None, design) is None  # no estimate: no limit


def test_bad_case_timeouts_are_refused_in_one_line(tmp_path: Path) -> None:
    spec = _limit_sweep(tmp_path)
    for value in ("-1", "nan", "soon"):
        proc = subprocess.run([sys.executable, "-m", "ballcage", "sweep", str(spec), "--out", str(tmp_path / "bad"),
                               "--case-timeout", value], capture_output=True, text=True, timeout=TIMEOUT_S)  # fmt: skip
        lines = proc.stderr.strip().splitlines()
        assert proc.returncode == 2 and len(lines) == 1, proc.stderr
        assert lines[0].startswith("ballcage: error: --case-timeout ") and value in lines[0], lines
    with pytest.raises(ballcage.studies.SweepError, match="case_timeout = -2.0: must be a positive number"):
        ballcage.sweep(spec, tmp_path / "bad", case_timeout=-2.0)
    assert not (tmp_path / "bad").exists()


# --------------------------------------------------------------------------- a lost Dask worker


@pytest.mark.filterwarnings("ignore::DeprecationWarning", "ignore::ResourceWarning", "ignore::UserWarning")
def test_a_dask_worker_killed_mid_case_has_its_case_rerun_with_the_same_result(tmp_path: Path) -> None:
    """Two cases of ~2.3 s on two worker processes; one worker is SIGKILLed 0.5 s into its case."""
    distributed = pytest.importorskip("distributed")
    spec = {"sweep": {"name": "lost-worker", "base": str(BALL_DROP)},
            "set": {"simulation.dt": 1e-6, "simulation.duration": 5.0}, "grid": {MASS: [1.0, 2.0]}}  # fmt: skip
    clean = ballcage.sweep(spec, tmp_path / "clean", workers=2, plots=False, progress=False)
    out, outcome = tmp_path / "dask", {}  # what the sweep's thread returned or raised
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        def run() -> None:
            try:
                outcome["result"] = ballcage.sweep(spec, out, client=client, plots=False, progress=False)
            except BaseException as e:  # noqa: BLE001 - reported by the test below
                outcome["error"] = e

        running = threading.Thread(target=run, daemon=True)
        running.start()
        deadline = time.monotonic() + TIMEOUT_S
        while True:  # until each worker is running a case
            executing = client.run(lambda dask_worker: len(dask_worker.state.executing))
            if len(executing) == 2 and all(n == 1 for n in executing.values()):
                break
            assert running.is_alive() and time.monotonic() < deadline, executing
            time.sleep(0.02)
        time.sleep(0.5)
        victim = sorted(executing)[0]
        pid = client.run(os.getpid, workers=[victim])[victim]
        assert not _records(out), "a case finished before the kill"  # both still running: the victim's is mid-case
        os.kill(pid, signal.SIGKILL)
        running.join(timeout=TIMEOUT_S)
        assert not running.is_alive()
        assert pid not in client.run(os.getpid).values()  # the worker is gone (its nanny started a new one)
    assert "error" not in outcome, outcome
    result = outcome["result"]
    assert (result.ran, result.failed) == (2, 0), result.summary.column("error").to_pylist()
    assert result.summary.column("status").to_pylist() == ["ok", "ok"]
    assert _without_wall_time(result.summary).equals(_without_wall_time(clean.summary))
    for table in ("bodies", "contacts"):
        assert _dataset(out, table).equals(_dataset(clean.out, table)), table
    assert_no_partial_file(out)
