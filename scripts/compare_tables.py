#!/usr/bin/env python3
"""Checks that a change leaves the engine's output bitwise identical.

Runs a fixed set of scenes with every table recorded, using whichever
`ballcage` the Python running this script imports, and writes the tables as
Parquet; then compares two such folders column by column, bit for bit.

    python3 scripts/compare_tables.py run DIR [--duration S] [--set KEY=VALUE ...]
    python3 scripts/compare_tables.py compare BEFORE AFTER

To compare two commits, install each into its own virtual environment
(`python3 -m venv V && V/bin/pip install .` in a checkout of the commit), run
`V/bin/python scripts/compare_tables.py run DIR` with each, then `compare`.

Columns present in both runs must be identical: floats by their bit
patterns (so 0.0 and -0.0 differ, and NaN equals only the same NaN), the
rest by value. Columns or tables present in only one run are listed, not
failed: a change may add columns. Run metadata (wall time, version) is not
compared. Exit code 1 when a common column differs.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

ALL_TABLES = ["bodies", "contacts", "energy", "summary", "links", "hinges", "keys", "drive", "pairs", "wear"]
ENGINE_TABLES = ["bodies", "contacts", "energy", "summary"]

#: name -> (scene source: "paper" or a TOML file, overrides)
CASES: dict[str, tuple[str, list[str]]] = {
    "paper-ball-keys": ("paper", []),
    "paper-ideal-cv": ("paper", ['pipe.hinge="ideal-cv"']),
    "two-balls": ("examples/scenes/two_balls.toml", []),
}


def _run_case(source: str, overrides: list[str], duration: float, root: Path) -> dict[str, pa.Table]:
    from ballcage import _native

    if source == "paper":
        text = _native.default_scene_toml()
        tables = ALL_TABLES
        overrides = [*overrides, f"simulation.duration={duration!r}"]
    else:
        text = (root / source).read_text()
        tables = ENGINE_TABLES
    listed = ", ".join(f'"{t}"' for t in tables)
    scene = _native.Scene.from_toml(text, [*overrides, f"record.tables=[{listed}]"])
    sim = _native.Simulation(scene)
    sim.advance(scene.duration)
    return sim.finish()


def run(out: Path, duration: float, paper_overrides: list[str]) -> int:
    root = Path(__file__).resolve().parent.parent
    for name, (source, overrides) in CASES.items():
        extra = paper_overrides if source == "paper" else []
        tables = _run_case(source, [*overrides, *extra], duration, root)
        folder = out / name
        folder.mkdir(parents=True, exist_ok=True)
        for table_name, table in tables.items():
            pq.write_table(table, folder / f"{table_name}.parquet")
        print(f"{name}: {', '.join(f'{k} ({v.num_rows} rows)' for k, v in sorted(tables.items()))}")
    return 0


def _same(a: pa.ChunkedArray, b: pa.ChunkedArray) -> bool:
    if len(a) != len(b):
        return False
    if pa.types.is_floating(a.type) and pa.types.is_floating(b.type):
        x = a.to_numpy().astype(np.float64)
        y = b.to_numpy().astype(np.float64)
        return bool(np.array_equal(x.view(np.uint64), y.view(np.uint64)))
    return a.cast(pa.string()).to_pylist() == b.cast(pa.string()).to_pylist()


def compare(before: Path, after: Path) -> int:
    failures = 0
    for case in sorted(p.name for p in before.iterdir() if p.is_dir()):
        if not (after / case).is_dir():
            print(f"{case}: missing after")
            failures += 1
            continue
        names_b = {p.stem for p in (before / case).glob("*.parquet")}
        names_a = {p.stem for p in (after / case).glob("*.parquet")}
        for only, where in ((names_b - names_a, "before"), (names_a - names_b, "after")):
            for t in sorted(only):
                print(f"{case}/{t}: only {where}")
        for t in sorted(names_b & names_a):
            tb = pq.read_table(before / case / f"{t}.parquet")
            ta = pq.read_table(after / case / f"{t}.parquet")
            common = [c for c in tb.column_names if c in ta.column_names]
            extra = [c for c in ta.column_names if c not in tb.column_names]
            gone = [c for c in tb.column_names if c not in ta.column_names]
            bad = [c for c in common if not _same(tb.column(c), ta.column(c))]
            status = "identical" if not bad else f"DIFFERENT in {', '.join(bad)}"
            notes = (f"; new columns: {', '.join(extra)}" if extra else "") + (
                f"; removed columns: {', '.join(gone)}" if gone else ""
            )
            print(f"{case}/{t}: {tb.num_rows} rows, {len(common)} common columns {status}{notes}")
            failures += bool(bad) or bool(gone)
    print("all common columns bitwise identical" if not failures else f"{failures} table(s) differ")
    return 1 if failures else 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run", help="run the cases and write DIR/<case>/<table>.parquet")
    r.add_argument("out", type=Path)
    r.add_argument("--duration", type=float, default=0.4, help="simulated time of the paper cases [s] (default 0.4)")
    r.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="an override for the paper cases (repeatable), e.g. to keep a law a later change made optional",
    )
    c = sub.add_parser("compare", help="compare two folders written by `run`")
    c.add_argument("before", type=Path)
    c.add_argument("after", type=Path)
    args = parser.parse_args(argv)
    if args.command == "run":
        return run(args.out, args.duration, args.set)
    return compare(args.before, args.after)


if __name__ == "__main__":
    sys.exit(main())
