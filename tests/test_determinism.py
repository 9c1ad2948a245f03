"""Determinism (issue 14, item 4): the same scene gives bitwise the same tables, whoever runs it and how.

Compared: two runs in one process and two ``ballcage run`` processes; the
Python API (`ballcage.simulate` + `Run.write`) against the CLI;
``simulation.threads`` 1 against 2; and a sweep interrupted by a real SIGINT
after its first case and resumed (by another process, on two workers)
against the same sweep run straight in one go. Scenes: the paper's drill pipe
with ball keys cut to 2 joints and 0.01 s, and its ideal-CV chain for 0.05 s,
every table recorded.

"Bitwise" means, for each table: `pa.Table.equals` (exact values); the bit
patterns of every floating-point column (so -0.0 against 0.0 or two NaN
payloads would differ); the Parquet files' bytes before the footer (every
column chunk, compressed) and the footer's row-group and column-chunk
metadata (sizes, offsets, statistics); and the schema's key-value metadata
except `VARYING`, the keys that measure the machine rather than the run.
`test_the_comparison_sees_a_change_of_one_part_in_a_billion` shows the
comparison is sensitive.
"""

from __future__ import annotations

import json
import re
import shutil
import signal
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from signalled import python_command

import ballcage
from ballcage.scene import default_scene
from ballcage.studies.sweep_summary import WALL_TIME_COLUMNS

TIMEOUT_S = 120.0  # s: generous, for a loaded 2-core machine
ALL_TABLES = "record.tables=" + json.dumps(list(ballcage._native.TABLE_NAMES))
SCENES = {
    "ball-keys": ("pipe.joints=2", "simulation.duration=0.01", "simulation.output_interval=5e-4", ALL_TABLES),
    "ideal-cv": ("pipe.joints=2", 'pipe.hinge="ideal-cv"', "simulation.duration=0.05", ALL_TABLES),
}
#: Schema metadata that legitimately differs between two runs of one scene: both measure the machine.
VARYING = {
    b"ballcage.wall_time_s": "wall-clock time of the run [s]: depends on the machine's speed and load",
    b"ballcage.real_time_factor": "simulated time / wall time: the same measurement, inverted",
}
#: Case record fields that measure the machine: the engine's wall time and the whole case's, in s.
VARYING_RECORD = ("wall_time_s", "case_wall_time_s")


# --------------------------------------------------------------------------- the comparison


def _run_folder(run: ballcage.Run, folder: Path) -> Path:
    run.write(folder)
    return folder


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "ballcage", *args], capture_output=True, text=True, timeout=TIMEOUT_S)


def _cli_run(overrides: tuple[str, ...], out: Path) -> Path:
    sets = [a for o in overrides for a in ("--set", o)]
    proc = _cli("run", "--out", str(out), "--quiet", *sets)
    assert proc.returncode == 0, proc.stderr
    return out


#: Files `ballcage run` derives from the recorded tables, which `Run.write` does not write.
DERIVED = {"wear_map.parquet", "fatigue.parquet"}


def differences(a: Path, b: Path, *, same_scene: bool = True, derived: bool = True) -> list[str]:
    """What differs between the Parquet files of two folders (empty: bitwise the same, but for `VARYING`).

    With ``same_scene=False`` the ``ballcage.scene`` metadata may differ in ``simulation.threads`` only; with
    ``derived=False`` only the recorded tables are compared, not the files the CLI derives from them (`DERIVED`).
    """
    def parquet(folder: Path) -> list[str]:
        return sorted(p.name for p in folder.rglob("*.parquet") if derived or p.name not in DERIVED)

    names = parquet(a)
    found = [] if names == parquet(b) else [f"tables {names} against {b}"]
    for name in names if not found else []:
        pa_, pb = next(a.rglob(name)), next(b.rglob(name))
        found += [f"{name}: {d}" for d in _file_differences(pa_, pb, same_scene)]
    return found


def _file_differences(a: Path, b: Path, same_scene: bool) -> list[str]:
    ta, tb = pq.read_table(a), pq.read_table(b)
    found = [] if ta.equals(tb) else ["values (Table.equals)"]
    found += [f"bits of {c}" for c in ta.column_names if c in tb.column_names and not _same_bits(ta[c], tb[c])]
    if _data_pages(a) != _data_pages(b):
        found.append("Parquet bytes before the footer")
    if _chunk_metadata(a) != _chunk_metadata(b):
        found.append("Parquet row-group metadata")
    ma, mb = _run_metadata(ta, same_scene), _run_metadata(tb, same_scene)
    found += [f"metadata {k.decode()}" for k in sorted(ma.keys() | mb.keys()) if ma.get(k) != mb.get(k)]
    return found


def _same_bits(a: pa.ChunkedArray, b: pa.ChunkedArray) -> bool:
    """Floating-point columns compared by bit pattern (nulls by position); other columns by `equals`."""
    if not pa.types.is_floating(a.type) or a.type != b.type:
        return a.equals(b)
    if not a.is_null().equals(b.is_null()):
        return False
    bits = {16: np.uint16, 32: np.uint32, 64: np.uint64}[a.type.bit_width]
    va, vb = (np.asarray(x.fill_null(0).to_numpy()).view(bits) for x in (a, b))
    return bool(np.array_equal(va, vb))


def _data_pages(path: Path) -> bytes:
    """The file's bytes before its footer: magic number and every column chunk, as compressed on disk."""
    raw = path.read_bytes()
    assert raw[-4:] == b"PAR1", path
    footer = int.from_bytes(raw[-8:-4], "little")
    return raw[: len(raw) - 8 - footer]


def _chunk_metadata(path: Path) -> list[dict]:
    meta = pq.read_metadata(path)
    return [meta.row_group(i).to_dict() for i in range(meta.num_row_groups)]


def _run_metadata(table: pa.Table, same_scene: bool) -> dict[bytes, bytes]:
    meta = {k: v for k, v in (table.schema.metadata or {}).items() if k not in VARYING}
    if not same_scene:  # the scene as data without its thread count, which is what was varied
        scene = tomllib.loads(meta.pop(b"ballcage.scene").decode())
        scene["simulation"].pop("threads")
        meta[b"ballcage.scene"] = json.dumps(scene, sort_keys=True).encode()
    return meta


# --------------------------------------------------------------------------- runs


@pytest.mark.parametrize("scene", sorted(SCENES))
def test_repeated_runs_in_python_and_the_cli_write_bitwise_the_same_tables(scene: str, tmp_path: Path) -> None:
    overrides = SCENES[scene]
    first = _run_folder(ballcage.simulate(default_scene(overrides)), tmp_path / "python1")
    second = _run_folder(ballcage.simulate(default_scene(overrides)), tmp_path / "python2")
    cli = [_cli_run(overrides, tmp_path / f"cli{i}") for i in (1, 2)]
    assert len(list(first.glob("*.parquet"))) == len(ballcage._native.TABLE_NAMES)
    assert differences(first, second) == []  # repeated, one process
    assert differences(cli[0], cli[1]) == []  # repeated, two processes, the derived files included
    assert differences(first, cli[0], derived=False) == []  # Python against the CLI
    assert (first / "scene.toml").read_bytes() == (cli[0] / "scene.toml").read_bytes()


@pytest.mark.parametrize("scene", sorted(SCENES))
def test_one_and_two_threads_write_bitwise_the_same_tables(scene: str, tmp_path: Path) -> None:
    overrides = SCENES[scene]
    one = _run_folder(ballcage.simulate(default_scene([*overrides, "simulation.threads=1"])), tmp_path / "one")
    two = _run_folder(ballcage.simulate(default_scene([*overrides, "simulation.threads=2"])), tmp_path / "two")
    assert differences(one, two, same_scene=False) == []
    assert differences(one, two) == ["{}.parquet: metadata ballcage.scene".format(t) for t in sorted(ballcage._native.TABLE_NAMES)]
    assert pq.read_table(one / "pairs.parquet").num_rows > 1, "several contact pairs for the threads to share"


@pytest.mark.parametrize("scene", sorted(SCENES))
def test_the_comparison_sees_a_change_of_one_part_in_a_billion(scene: str, tmp_path: Path) -> None:
    """The curvature radius 1.5 m against 1.5 m + 1.5 nm: some tables differ, in values and bytes."""
    overrides = SCENES[scene]
    base = _run_folder(ballcage.simulate(default_scene(overrides)), tmp_path / "base")
    assert default_scene(overrides).value("borehole.curvature_radius") == 1.5
    nudged = default_scene([*overrides, "borehole.curvature_radius=1.5000000015"])
    found = differences(base, _run_folder(ballcage.simulate(nudged), tmp_path / "nudged"))
    assert any("values (Table.equals)" in d for d in found), found
    assert any("bits of" in d for d in found) and any("Parquet bytes" in d for d in found), found
    assert "bodies.parquet: metadata ballcage.scene" in found


# --------------------------------------------------------------------------- sweeps


SWEEP = {
    "sweep": {"name": "determinism"},
    "set": {"pipe.joints": 2, "simulation.duration": 0.01, "simulation.output_interval": 5e-4},
    "grid": {"drive.speed_rpm": [60.0, 80.0, 100.0]},
    "case": [{"pipe.hinge": "ideal-cv"}],
}
SWEEP_TOML = """
[sweep]
name = "determinism"

[set]
"pipe.joints" = 2
"simulation.duration" = 0.01
"simulation.output_interval" = 5e-4

[grid]
"drive.speed_rpm" = [60.0, 80.0, 100.0]

[[case]]
"pipe.hinge" = "ideal-cv"
"""


def _interrupted_then_resumed(tmp_path: Path) -> tuple[Path, int]:
    """The sweep by the CLI on one worker, SIGINT once its first case has a record, then resumed on two workers.

    Returns the folder and how many cases the resumed run skipped (finished before the interrupt).
    """
    spec, out = tmp_path / "sweep.toml", tmp_path / "resumed"
    spec.write_text(SWEEP_TOML, encoding="utf-8")
    for attempt in range(3):
        shutil.rmtree(out, ignore_errors=True)
        command = python_command("-m", "ballcage", "sweep", str(spec), "--out", str(out), "--workers", "1", "--no-plots")
        proc = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        deadline = time.monotonic() + TIMEOUT_S
        while proc.poll() is None and not list(out.glob("cases/*.json")):
            assert time.monotonic() < deadline, "the sweep wrote no record"
            time.sleep(5e-4)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=TIMEOUT_S)
        if proc.returncode == 130:
            assert "run the same command again to resume" in err, err
            break
    else:
        pytest.fail("the sweep finished before SIGINT in 3 attempts")
    resumed = _cli("sweep", str(spec), "--out", str(out), "--workers", "2", "--no-plots")
    assert resumed.returncode == 0, resumed.stderr
    skipped = int(re.search(r"(\d+) already finished", resumed.stderr).group(1))  # type: ignore[union-attr]
    return out, skipped


def test_a_resumed_sweep_writes_bitwise_the_cases_of_a_straight_one(tmp_path: Path) -> None:
    straight = ballcage.sweep(SWEEP, tmp_path / "straight", workers=1, plots=False, progress=False)
    assert straight.failed == 0 and straight.summary.num_rows == 4
    resumed, skipped = _interrupted_then_resumed(tmp_path)
    assert 1 <= skipped < 4, "some cases before the interrupt, some after"
    for case in range(4):
        part = f"case={case:04d}"
        a, b = tmp_path / "straight", resumed
        tables = json.loads((a / "cases" / f"{part}.json").read_text())["tables"]
        for table in tables:
            assert differences(a / table / part, b / table / part) == [], (case, table)
        assert _record(a, part) == _record(b, part), case
        assert (a / "cases" / f"{part}.scene.toml").read_bytes() == (b / "cases" / f"{part}.scene.toml").read_bytes()
    summary = [pq.read_table(p / "summary.parquet") for p in (tmp_path / "straight", resumed)]
    assert summary[0].drop_columns(list(WALL_TIME_COLUMNS)).equals(summary[1].drop_columns(list(WALL_TIME_COLUMNS)))
    print(f"sweep: {skipped} of 4 cases finished before SIGINT, {4 - skipped} after the resume")


def _record(out: Path, partition: str) -> dict:
    record = json.loads((out / "cases" / f"{partition}.json").read_text(encoding="utf-8"))
    return {k: v for k, v in record.items() if k not in VARYING_RECORD}
