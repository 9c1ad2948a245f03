"""``ballcage run``: simulate a scene (`ballcage.run.simulate`) and write its Parquet tables (`Run.write`)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from ballcage import _native
from ballcage.cli._common import (
    TABLE_NAMES,
    Commands,
    UsageError,
    add_out_option,
    add_quiet_option,
    add_set_option,
    checked_out,
    checked_override,
    fail,
    human_size,
    load_cli_scene,
    names,
)
from ballcage.run import simulate


def add(commands: Commands) -> None:
    run = commands.add_parser(
        "run",
        help="simulate a scene and write Parquet tables",
        description=(
            "Simulate a scene; write <table>.parquet for each recorded table and the resolved scene.toml. "
            "The tables are the scene's record.tables; a drill-pipe scene records by default bodies, "
            "contacts and the engineering tables links, hinges, keys, drive, summary, pairs and wear. "
            "--tables chooses the tables instead."
        ),
    )
    run.add_argument(
        "scene",
        metavar="SCENE.toml",
        nargs="?",
        help="scene file (TOML); without it, the embedded paper scene (see `ballcage scene show`)",
    )
    add_out_option(run)
    run.add_argument(
        "--overwrite",
        action="store_true",
        help="replace an earlier run's tables in --out (without it, a folder holding them is refused)",
    )
    run.add_argument(
        "--tables",
        metavar="NAME,...",
        help=(
            f"tables to record, e.g. --tables links,drive (known: {', '.join(TABLE_NAMES)}; `ballcage schema` "
            "describes them); default: the scene's record.tables"
        ),
    )
    add_set_option(run)
    add_quiet_option(run, "no progress bar and no summary")
    run.set_defaults(command=command)


def command(args: argparse.Namespace) -> int:
    overrides = [checked_override(o) for o in args.overrides]
    out = checked_out(args.out)
    earlier = _earlier_run(out)
    if earlier and not args.overwrite:
        raise UsageError(
            f"--out {out} holds another run's output ({', '.join(earlier)}); "
            "pass --overwrite to replace it, or choose another folder"
        )
    chosen = names("--tables", args.tables, TABLE_NAMES, "table")
    scene = load_cli_scene(args.scene, overrides)
    tables = chosen
    if tables is not None:
        try:
            scene = load_cli_scene(args.scene, [*overrides, "record.tables=" + json.dumps(tables)])
        except UsageError as e:  # the scene loaded without the tables: they are what it refuses
            raise UsageError(f"--tables {','.join(tables)}: {e}") from e
    try:
        result = simulate(scene, progress=False if args.quiet else None)
    except (_native.SimulationError, KeyboardInterrupt) as e:
        partial = getattr(e, "run", None)
        if partial is None:
            raise
        paths = partial.write(out)
        if not args.quiet:
            for name, path in paths.items():
                print(_summary(name, path, partial.tables.get(name)))
        code = 130 if isinstance(e, KeyboardInterrupt) else 1
        return fail(f"{partial.error}; the output in {out} is incomplete (written up to then, ballcage.complete = false)", code)
    paths = result.write(out)
    if not args.quiet:
        for name, path in paths.items():
            print(_summary(name, path, result.tables.get(name)))
        print(_cost(result.metadata))
        if "wear" in result.tables:
            from ballcage.duty import margin_line, wear_line

            for line in (margin_line(result.tables["wear"]), wear_line(result.tables["wear"])):
                if line is not None:
                    print(f"ballcage: {line}")
        if result.fallback_note is not None:
            print(f"ballcage: warning: {result.fallback_note}")
    return 0


def _earlier_run(out: Path) -> list[str]:
    """Files of an earlier run in `out`: its ``<table>.parquet`` and ``scene.toml``."""
    files = [f"{t}.parquet" for t in _native.TABLE_NAMES] + ["scene.toml"]
    return [n for n in files if (out / n).exists()]


def _summary(name: str, path: Path, table: object) -> str:
    size = human_size(path.stat().st_size)
    if table is None:
        return f"wrote {path}  (resolved scene, {size})"
    return f"wrote {path}  ({table.num_rows} rows x {table.num_columns} columns, {size})"  # type: ignore[attr-defined]


def _cost(meta: dict[str, str]) -> str:
    """One line on what the run cost: wall time, real-time factor, solver work."""
    steps = int(meta["ballcage.steps"])
    simulated = steps * float(meta["ballcage.dt_s"])
    line = (
        f"ballcage: {simulated:.4g} s simulated in {float(meta['ballcage.wall_time_s']):.3g} s of wall time "
        f"(real-time factor {float(meta['ballcage.real_time_factor']):.3g}); "
        f"{meta['ballcage.integrator']} at {float(meta['ballcage.dt_s']):g} s, {steps} steps"
    )
    if meta["ballcage.integrator"] == "sdirk2" and steps > 0:
        per_stage = int(meta["ballcage.newton_iterations"]) / (2 * steps)
        per_step = int(meta["ballcage.factorizations"]) / steps
        line += f", {per_stage:.2f} Newton iterations per stage, {per_step:.2f} factorizations per step"
    return line
