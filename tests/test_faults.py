"""Faults during a run (issue 14, item 3): SIGKILL at any moment, a full disk, a divergence in the middle of a sweep.

Everything here is a real ``python -m ballcage`` subprocess and a real signal
(``Popen.send_signal``); moments in the write phase are found by polling the
output folder (every 0.5 ms) for the k-th file to appear, not by timing, and
a hunt that comes too late (the process already finished) is retried. After
every fault, every file under a final name (``*.parquet``, ``*.toml``,
``*.json``, ``*.png``) must read completely (the Parquet footer, each row group
and the whole table) and every other file must be a hidden temporary
``.<final name>.<8 hex digits>.tmp``, which readers skip.

The run killed is the paper's drill pipe with ball keys cut to 2 joints and
0.1 s, a frame every 0.1 ms step: about 0.5 s of start-up, 0.4 s of simulation
and 0.3 s writing its 8 tables (~40 000 rows) and scene.toml.
"""

from __future__ import annotations

import json
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import time
import tomllib
from collections.abc import Callable
from pathlib import Path

import pyarrow.compute as pc
import pyarrow.dataset as ds
import pyarrow.parquet as pq
import pytest
from signalled import python_command

import ballcage

REPO = Path(__file__).resolve().parent.parent
BALL_DROP = REPO / "examples" / "scenes" / "ball_drop.toml"
SEED = 20261123
TIMEOUT_S = 120.0  # s: generous, for a loaded 2-core machine
POLL_S = 5e-4  # s between two looks at the output folder
#: The run killed: ball keys, 2 joints, 0.1 s, a frame every step.
KILLED_RUN = ("--set", "pipe.joints=2", "--set", "simulation.duration=0.1", "--set", "simulation.output_interval=1e-4")
#: What it writes: its 9 default tables and scene.toml, then the wear map and its figure derived from them.
TABLE_FILES, FILES_PER_RUN = 10, 12
TEMPORARY = re.compile(r"^\.(?P<final>.+)\.[0-9a-f]{8}\.tmp$")
#: A run that diverges in the middle: the ball drop on a 100x stiffer ground at 1 ms RK4 steps
#: diverges on landing, at t = 0.102 s of 0.2 s (step 102 of 200).
DIVERGING = ("--set", "simulation.dt=1e-3", "--set", "contacts.0.normal.stiffness=1e10")
#: A run for the small disk: pairs.parquet (16 KB) is written before keys.parquet (78 KB), so a
#: limit of 20 KiB per file, or a 64 KiB disk, fails the write with one table's temporary already written.
BIG_RUN = ("--set", "pipe.joints=2", "--set", "simulation.duration=0.04", "--set", 'record.tables=["pairs", "keys"]')


# --------------------------------------------------------------------------- helpers


def _start(args: list[str] | tuple[str, ...], log: Path, prefix: tuple[str, ...] = ()) -> subprocess.Popen[bytes]:
    """Starts ``python [prefix] -m ballcage ARGS`` with stderr into the file `log`.

    SIGINT and SIGTERM at their default disposition in the child (`signalled.python_command`),
    even when pytest was started with them ignored (``nohup``, cron, a background job).
    """
    with open(log, "wb") as err:
        command = python_command(*(prefix or ("-m", "ballcage")), *args)
        return subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=err)


def _files(root: Path) -> list[Path]:
    """Every file below `root` (hidden ones too); none when it does not exist."""
    return sorted(Path(d) / f for d, _, names in os.walk(root) for f in names)


def _wait_for(proc: subprocess.Popen[bytes], condition: Callable[[], bool]) -> bool:
    """Polls `condition` until it holds (True) or `proc` exits first (False); fails after `TIMEOUT_S`."""
    deadline = time.monotonic() + TIMEOUT_S
    while proc.poll() is None:
        if condition():
            return True
        assert time.monotonic() < deadline, "timed out waiting for the moment to strike"
        time.sleep(POLL_S)
    return False


def _kill(proc: subprocess.Popen[bytes], sig: int = signal.SIGKILL) -> int:
    """Sends `sig` unless `proc` has exited; reaps it; returns its exit status (-9 when SIGKILL ended it)."""
    proc.send_signal(sig)  # a no-op once the process has been reaped
    return proc.wait(timeout=TIMEOUT_S)


def assert_no_partial_file(root: Path) -> dict[str, int]:
    """Asserts each file below `root` under a final name is complete and each other one a hidden temporary.

    Returns how many of each there are: ``{"final": n, "temporary": m}``.
    """
    counts = {"final": 0, "temporary": 0}
    for path in _files(root):
        if TEMPORARY.match(path.name):
            counts["temporary"] += 1
        else:
            _assert_complete(path)
            counts["final"] += 1
    return counts


def _assert_complete(path: Path) -> None:
    """A Parquet file reads through (footer, every row group, the whole table); TOML, JSON and PNG parse."""
    assert not path.name.startswith("."), f"{path}: a hidden file that is not a ballcage temporary"
    if path.suffix == ".parquet":
        with pq.ParquetFile(path) as f:
            rows = sum(f.read_row_group(i).num_rows for i in range(f.num_row_groups))
            assert rows == f.metadata.num_rows, path
        assert pq.read_table(path).num_rows == rows, path
    elif path.suffix == ".toml":
        text = path.read_text(encoding="utf-8")
        assert tomllib.loads(text), path
        ballcage.load_scene(path)  # a complete, valid scene
    elif path.suffix == ".json":
        assert isinstance(json.loads(path.read_text(encoding="utf-8")), dict), path
    elif path.suffix == ".png":
        data = path.read_bytes()
        assert data.startswith(b"\x89PNG\r\n\x1a\n") and data[-8:-4] == b"IEND", path
    else:
        raise AssertionError(f"{path}: not a file ballcage writes")


def _two_phase(counts: dict[str, int]) -> bool:
    """Whether a killed run's folder fits writing every temporary before any rename, tables first, then the
    files derived from them: no final file yet, or (killed within the tables' renames) finals and temporaries
    together are the tables, or every table final and the derived files' temporaries and finals at most the
    rest of the run."""
    final, total = counts["final"], counts["final"] + counts["temporary"]
    return final == 0 or total == TABLE_FILES or (final >= TABLE_FILES and total <= FILES_PER_RUN)


def _error_lines(log: Path) -> list[str]:
    """The ``ballcage: error:`` lines of a stderr log; asserts there is no traceback."""
    text = log.read_text(encoding="utf-8", errors="replace")
    assert "Traceback" not in text, text
    return [line for line in text.splitlines() if line.startswith("ballcage: error:")]


# --------------------------------------------------------------------------- SIGKILL


def _calibrate(tmp_path: Path) -> tuple[float, float]:
    """One run left alone: (seconds until its first output file appears, seconds until it exits)."""
    out, start = tmp_path / "calibration", time.monotonic()
    proc = _start(["run", "--out", str(out), "--quiet", *KILLED_RUN], tmp_path / "calibration.log")
    assert _wait_for(proc, lambda: bool(_files(out))), "the run wrote nothing"
    first = time.monotonic() - start
    assert proc.wait(timeout=TIMEOUT_S) == 0, (tmp_path / "calibration.log").read_text()
    end = time.monotonic() - start
    assert assert_no_partial_file(out) == {"final": FILES_PER_RUN, "temporary": 0}
    return first, end


def test_sigkill_at_random_moments_never_leaves_a_partial_file(tmp_path: Path) -> None:
    """Six kills at seeded random moments, one in each sixth of a run's life: start-up, simulation, write."""
    first, end = _calibrate(tmp_path)
    rng = random.Random(SEED)
    moments = [end * (i + rng.random()) / 6 for i in range(6)]  # s after the start
    phases = []
    for i, moment in enumerate(moments):
        out = tmp_path / f"timed{i}"
        proc = _start(["run", "--out", str(out), "--quiet", *KILLED_RUN], tmp_path / f"timed{i}.log")
        _wait_for(proc, lambda moment=moment, t0=time.monotonic(): time.monotonic() - t0 >= moment)
        status = _kill(proc)
        counts = assert_no_partial_file(out)
        phases.append("exited" if status == 0 else "writing" if _files(out) else "before the write")
        if status == 0:
            assert counts == {"final": FILES_PER_RUN, "temporary": 0}
        else:
            assert status == -signal.SIGKILL and _two_phase(counts), counts
    print(f"calibration: first file at {first:.2f} s, exit at {end:.2f} s; kills at "
          + ", ".join(f"{m:.2f} s ({phase})" for m, phase in zip(moments, phases, strict=True)))
    assert "before the write" in phases, (first, end, moments, phases)


def test_sigkill_in_the_write_phase_leaves_only_hidden_temporaries(tmp_path: Path) -> None:
    """Kills as the k-th file of the write appears (k seeded), retried until each kill lands mid-write."""
    rng = random.Random(SEED)
    landed = []
    for k in sorted(rng.sample(range(1, FILES_PER_RUN + 1), 4)):
        # The last files are small and quick to write: a kill lands inside their write only now and then
        # (under load, 4 attempts once missed file 10), so up to 8; every attempt checks the invariants.
        for attempt in range(8):
            out = tmp_path / f"k{k}-{attempt}"
            proc = _start(["run", "--out", str(out), "--quiet", *KILLED_RUN], tmp_path / f"k{k}.log")
            _wait_for(proc, lambda out=out, k=k: len(_files(out)) >= k)
            status = _kill(proc)
            counts = assert_no_partial_file(out)
            assert _two_phase(counts), counts
            if status == -signal.SIGKILL and counts["temporary"]:
                landed.append((k, attempt))
                break
        else:
            pytest.fail(f"no kill landed in the write phase at file {k} in 8 attempts")
    print("kills landed mid-write (file k, attempt): " + ", ".join(f"({k}, {a})" for k, a in landed))
    # the folder of a killed run takes the next run (with --overwrite: a kill within the renames leaves some
    # of its tables under their final names); the leftover temporaries stay hidden beside it
    out = tmp_path / "k{}-{}".format(*landed[-1])
    leftovers = set(_files(out))
    again = subprocess.run([sys.executable, "-m", "ballcage", "run", "--out", str(out), "--quiet", "--overwrite",
                            *KILLED_RUN], capture_output=True, text=True, timeout=TIMEOUT_S)
    assert again.returncode == 0, again.stderr
    assert assert_no_partial_file(out)["final"] == FILES_PER_RUN
    assert {p for p in _files(out) if TEMPORARY.match(p.name)} <= leftovers


SWEEP_TOML = """
[sweep]
name = "killed"

[set]
"pipe.joints" = 2
"simulation.duration" = 0.01
"simulation.output_interval" = 5e-4

[grid]
"drive.speed_rpm" = [60.0, 80.0, 100.0, 120.0]
"""


def _records(out: Path) -> int:
    return len(list((out / "cases").glob("case=*.json"))) if (out / "cases").is_dir() else 0


def test_sigkill_of_a_sweep_then_rerun_resumes_and_completes(tmp_path: Path) -> None:
    """Kill a sweep after its first case's record, again mid-write of a later case, then let it finish."""
    spec, out = tmp_path / "killed.toml", tmp_path / "out"
    spec.write_text(SWEEP_TOML, encoding="utf-8")
    args = ["sweep", str(spec), "--out", str(out), "--workers", "1", "--no-plots", "--quiet"]
    proc = _start(args, tmp_path / "sweep1.log")
    assert _wait_for(proc, lambda: _records(out) >= 1), "the sweep finished before the kill"
    assert _kill(proc) == -signal.SIGKILL
    assert_no_partial_file(out)
    finished = _records(out)
    assert 1 <= finished < 4 and not (out / "summary.parquet").exists()
    before = set(_files(out))
    proc = _start(args, tmp_path / "sweep2.log")
    assert _wait_for(proc, lambda: bool(set(_files(out)) - before)), "the sweep finished before the kill"
    assert _kill(proc) == -signal.SIGKILL
    assert_no_partial_file(out)
    ds.dataset(out / "links", format="parquet", partitioning="hive").to_table()  # temporaries are skipped
    last = subprocess.run([sys.executable, "-m", "ballcage", *args[:-1]], capture_output=True, text=True, timeout=TIMEOUT_S)
    assert last.returncode == 0, last.stderr
    skipped = int(re.search(r"(\d+) already finished", last.stderr).group(1))  # type: ignore[union-attr]
    assert finished <= skipped < 4, last.stderr
    print(f"sweep: {finished} of 4 cases finished at the first kill, {skipped} at the second")
    summary = pq.read_table(out / "summary.parquet")
    assert summary.column("case").to_pylist() == [0, 1, 2, 3]
    # Every case ran to the end: 0.01 s in the adaptive default's steps of one output interval (5e-4 s) each.
    assert summary.column("status").to_pylist() == ["ok"] * 4 and summary.column("steps").to_pylist() == [20] * 4
    links = ds.dataset(out / "links", format="parquet", partitioning="hive").to_table()
    assert sorted(set(links.column("case").to_pylist())) == [0, 1, 2, 3]
    assert assert_no_partial_file(out)["final"] == 1 + 4 * (2 + 5)  # summary; per case record, scene, 5 tables


def test_ctrl_c_in_the_write_phase_leaves_the_folder_as_it_was(tmp_path: Path) -> None:
    """SIGINT as the 5th file's temporary appears: exit 130, one error line, no final file and no temporary."""
    for attempt in range(4):
        out = tmp_path / f"int{attempt}"
        log = tmp_path / f"int{attempt}.log"
        proc = _start(["run", "--out", str(out), "--quiet", *KILLED_RUN], log)
        _wait_for(proc, lambda out=out: len(_files(out)) >= 5)
        status = _kill(proc, signal.SIGINT)
        counts = assert_no_partial_file(out)
        assert status in (0, 130) and counts["temporary"] == 0, (status, counts, log.read_text())
        if status == 130 and counts["final"] == 0:
            break
        assert counts["final"] == FILES_PER_RUN  # too late: the write had finished
    else:
        pytest.fail("no SIGINT landed in the write phase in 4 attempts")
    assert _error_lines(log) == ["ballcage: error: interrupted"]


def test_a_ctrl_c_just_after_a_temporary_is_created_leaves_no_temporary(tmp_path: Path, monkeypatch) -> None:
    """The Ctrl-C of the test above, landed at its narrowest moment: the temporary exists, the writer has not yet
    seen its name back. Found under load on 2026-11-27 (one temporary left, exit 130): the temporary was listed for
    clean-up only after its creation returned. It is listed before it is created now."""
    from ballcage import _files

    create = _files._create_temporary

    def interrupted(tmp: Path, final: Path) -> None:
        create(tmp, final)
        assert tmp.exists()
        raise KeyboardInterrupt

    monkeypatch.setattr(_files, "_create_temporary", interrupted)
    (tmp_path / "b.txt").write_text("earlier")
    with pytest.raises(KeyboardInterrupt):
        _files.write_all_atomically({tmp_path / "a.txt": lambda p: p.write_text("a"), tmp_path / "b.txt": lambda p: p.write_text("b")})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["b.txt"]
    assert (tmp_path / "b.txt").read_text() == "earlier"


def test_a_temporary_name_another_writer_holds_is_left_to_it(tmp_path: Path, monkeypatch) -> None:
    """The clean-up removes only the temporaries this writer created: when the hidden name it drew is already
    taken (O_EXCL), the writer fails with FileExistsError naming the final file, and the other file stays."""
    from ballcage import _files

    monkeypatch.setattr(_files.secrets, "token_hex", lambda n: "0" * (2 * n))
    theirs = tmp_path / ".a.txt.00000000.tmp"
    theirs.write_text("another writer's")
    with pytest.raises(FileExistsError) as caught:
        _files.write_all_atomically({tmp_path / "a.txt": lambda p: p.write_text("a")})
    assert caught.value.filename == str(tmp_path / "a.txt")
    assert theirs.read_text() == "another writer's"
    assert sorted(p.name for p in tmp_path.iterdir()) == [theirs.name]


# --------------------------------------------------------------------------- full disk


#: Runs ``python -m ballcage ...`` with files limited to 20 KiB: a write past that fails with EFBIG.
#: BIG_RUN's pairs table (16.4 KB with its run metadata on 2026-11-27) fits, its keys table (78 KB) does not;
#: the diverging ball drop's bodies table (22 KB) does not either (SIGXFSZ ignored, as CPython does at
#: start-up, so the write returns the error instead of killing).
FSIZE_SHIM = (
    "-c",
    "import os, resource, signal, sys; signal.signal(signal.SIGXFSZ, signal.SIG_IGN); "
    "resource.setrlimit(resource.RLIMIT_FSIZE, (20480, 20480)); "
    "os.execv(sys.executable, [sys.executable, '-m', 'ballcage', *sys.argv[1:]])",
)


@pytest.fixture(params=["file-size-limit", "tmpfs"])
def small_disk(request: pytest.FixtureRequest, tmp_path: Path):
    """(a folder, the interpreter arguments that run ballcage there with too little space, the expected errno text).

    Either every file limited to 20 KiB (RLIMIT_FSIZE, any POSIX system) or the folder a 64 KiB tmpfs (root only).
    """
    folder = tmp_path / "disk"
    folder.mkdir()
    if request.param == "file-size-limit":
        yield folder, FSIZE_SHIM, "File too large (errno 27)"
        return
    try:
        mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(folder)], capture_output=True, text=True)
    except FileNotFoundError as e:  # no mount command (macOS, Windows)
        pytest.skip(f"cannot mount a tmpfs here: {e}")
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a 64 KiB tmpfs here (needs root or CAP_SYS_ADMIN): {mounted.stderr.strip()}")
    try:
        yield folder, (), "No space left on device (errno 28)"
    finally:
        subprocess.run(["umount", str(folder)], check=True, timeout=60)


def _run_limited(shim: tuple[str, ...], args: list[str], log: Path) -> int:
    proc = _start(args, log, prefix=shim)
    return proc.wait(timeout=TIMEOUT_S)


def test_a_full_disk_is_exit_3_with_one_line_and_no_file(small_disk, tmp_path: Path) -> None:
    """A fresh folder: nothing under a final name, no temporary left, the error names the file and errno."""
    folder, shim, reason = small_disk
    out, log = folder / "fresh", tmp_path / "fresh.log"
    assert _run_limited(shim, ["run", "--out", str(out), *BIG_RUN], log) == 3
    lines = _error_lines(log)
    assert len(lines) == 1, lines
    match = re.fullmatch(r"ballcage: error: cannot write (\S+): (.+)", lines[0])
    assert match and match.group(2) == reason, lines
    assert Path(match.group(1)) == out / "keys.parquet", lines
    # pairs.parquet's temporary was complete when keys.parquet's failed: it is removed, and never renamed
    assert assert_no_partial_file(folder) == {"final": 0, "temporary": 0}


def test_a_full_disk_leaves_an_earlier_run_as_it_was(small_disk, tmp_path: Path) -> None:
    """``--overwrite`` onto an earlier run, then a diverging run's partial write: both fail, the earlier files stay."""
    folder, shim, reason = small_disk
    out = folder / "earlier"
    small = ["--set", "pipe.joints=2", "--set", "simulation.duration=0.005", "--set", 'record.tables=["energy"]']
    assert _run_limited((), ["run", "--out", str(out), "--quiet", *small], tmp_path / "small.log") == 0
    before = {p.name: p.read_bytes() for p in _files(out)}
    assert sorted(before) == ["energy.parquet", "scene.toml"]
    bigger = ["run", "--out", str(out), "--overwrite", "--quiet", *BIG_RUN]
    assert _run_limited(shim, bigger, tmp_path / "bigger.log") == 3  # pairs.parquet was written, not renamed
    assert _error_lines(tmp_path / "bigger.log")[0].endswith(reason)
    assert {p.name: p.read_bytes() for p in _files(out)} == before
    tables = 'record.tables=["bodies", "contacts", "energy", "summary"]'  # 20 KiB or more than the tmpfs holds
    diverging = ["run", str(BALL_DROP), "--out", str(out), "--overwrite", "--quiet", *DIVERGING, "--set", tables]
    assert _run_limited(shim, diverging, tmp_path / "diverging.log") == 3  # not 1: its output could not be written
    assert _error_lines(tmp_path / "diverging.log")[0].endswith(reason)
    assert {p.name: p.read_bytes() for p in _files(out)} == before


# --------------------------------------------------------------------------- divergence mid-sweep


def test_a_case_diverging_mid_run_keeps_its_frames_and_the_sweep_goes_on(tmp_path: Path) -> None:
    """The ball drop at 1e8, 1e10 and 2e8 N/m^1.5: the middle case diverges on landing; the third still runs."""
    scene = tmp_path / "ball_drop.toml"
    shutil.copy(BALL_DROP, scene)
    spec = tmp_path / "drop.toml"
    spec.write_text(
        '[sweep]\nname = "drop"\nbase = "ball_drop.toml"\n\n[set]\n"simulation.dt" = 1e-3\n\n'
        '[grid]\n"contacts.0.normal.stiffness" = [1e8, 1e10, 2e8]\n',
        encoding="utf-8",
    )
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "ballcage", "sweep", str(spec), "--out", str(out), "--workers", "1",
                           "--no-plots"], capture_output=True, text=True, timeout=TIMEOUT_S)
    assert proc.returncode == 1, proc.stderr
    assert "1 of 3 cases did not finish (case 0001-" in proc.stderr and "diverged at t = 1.02" in proc.stderr
    summary = pq.read_table(out / "summary.parquet")
    assert summary.column("status").to_pylist() == ["ok", "diverged", "ok"]
    assert summary.column("steps").to_pylist() == [200, 102, 200]
    assert_no_partial_file(out)
    bodies = [pq.read_table(out / "bodies" / f"case={i:04d}" / "part.parquet") for i in range(3)]
    assert [b.schema.metadata[b"ballcage.complete"] for b in bodies] == [b"true", b"false", b"true"]
    balls = [b.filter(pc.equal(b.column("body"), "ball")) for b in bodies]  # the fixed ground has rows too
    assert [len(b) for b in balls] == [201, 102, 201]
    t = balls[1].column("t").to_pylist()
    assert t == pytest.approx([i * 1e-3 for i in range(102)], abs=1e-12), "every frame up to the divergence, none after"
    # before landing (t ≈ 0.1 s) the stiffness does not act: the diverged case's frames are the first case's
    airborne = [b.filter(pc.less(b.column("t"), 0.0945)) for b in balls[:2]]
    assert airborne[1].num_rows == 95 and airborne[1].equals(airborne[0])
    with pytest.raises(ballcage.SimulationError) as straight:  # the same case run on its own: the same frames
        ballcage.simulate(BALL_DROP, overrides=["simulation.threads=1", "simulation.dt=1e-3",
                                                "contacts.0.normal.stiffness=1e10"])
    assert straight.value.run.bodies.equals(bodies[1])

