"""``ballcage run``: simulate a scene (`ballcage.run.simulate`) and write its Parquet tables (`Run.write`)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from collections.abc import Callable
from typing import TYPE_CHECKING

from ballcage import _native
from ballcage._files import write_parquet
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
from ballcage.run import VERIFY_FILE, Run, simulate_then
from ballcage.studies.common import implicit_steps, newton_per_stage
from ballcage.verify import VerificationError, disagreements, verdict

if TYPE_CHECKING:
    import pyarrow as pa


def add(commands: Commands) -> None:
    run = commands.add_parser(
        "run",
        help="simulate a scene and write Parquet tables",
        description=(
            "Simulate a scene; write <table>.parquet for each recorded table and the resolved scene.toml. "
            "The tables are the scene's record.tables; a drill-pipe scene records by default bodies, "
            "contacts and the engineering tables links, hinges, keys, drive, summary, pairs and wear, and from "
            "them fatigue.parquet and fatigue.png (life at the links' critical sections, docs/model.md §8.6). "
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
    run.add_argument(
        "--verify",
        nargs="?",
        type=int,
        choices=(1, 2),
        const=1,
        default=0,
        metavar="RUNS",
        help=(
            "repeat the run ten times tighter (dt/d with d = ceil(10^(1/order)), e.g. dt/4 for sdirk2, with a tenth "
            "of the Newton tolerance for sdirk2, trbdf2 and esdirk32; rtol/10 for adaptive steps), write the difference of "
            "each headline quantity (a drill pipe's comparison quantities, a generic scene's summary statistics) to "
            "verify.parquet and end with the largest: the run's measured "
            "error; a failed verification run exits 1, the run's own tables written. --verify 2 adds a second "
            "verification run, ten times tighter again (rtol/100, dt/16 for sdirk2), that checks the first: the "
            "error is confirmed when the first run's own error is at most a third of it, else reported as not "
            "measured"
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

    def write(run: Run) -> tuple[pa.Table | None, pa.Table | None]:
        # The tables and what is derived from them, while the verification run goes on beside.
        _write(run, out, args.quiet)
        return _fatigue(run, out, args.quiet), _wear_map(run, out, args.quiet)

    try:
        result, (fatigue, wear_map) = simulate_then(
            scene, write, progress=False if args.quiet else None, verify=args.verify
        )
    except VerificationError as e:  # the run's files are written; verify.parquet is not
        return _failed(e, e.run, out)
    except (_native.SimulationError, KeyboardInterrupt) as e:
        partial = getattr(e, "run", None)
        if partial is None:
            raise
        if not partial.complete:  # the run stopped: what it recorded (a complete run's files are written)
            _write(partial, out, args.quiet)
        return _failed(e, partial, out)
    if result.verification is not None:
        path = write_parquet(result.verification.table, out / VERIFY_FILE)
        if not args.quiet:
            print(_summary("verify", path, result.verification.table))
    if not args.quiet:
        _report(result, fatigue, wear_map)
    return 0


def _write(result: Run, out: Path, quiet: bool) -> None:
    """Writes `result` into `out` and, unless `quiet`, prints one line per file."""
    for derived in ("wear_map.parquet", "wear_map.png"):  # an earlier run's, never beside this run's tables
        (out / derived).unlink(missing_ok=True)
    paths = result.write(out)
    if not quiet:
        for name, path in paths.items():
            print(_summary(name, path, result.tables.get(name)))


def _fatigue(result: Run, out: Path, quiet: bool) -> pa.Table | None:
    """fatigue.parquet and fatigue.png (life at the links' critical sections) of a drill-pipe run that recorded
    bodies, contacts and pairs."""
    from ballcage.paper.fatigue import FATIGUE_FIGURE, FATIGUE_FILE, write_fatigue

    ready = all(t in result.tables for t in ("bodies", "contacts", "pairs"))
    return _derived(result, out, quiet, ("fatigue", "fatigue table"), write_fatigue, ready, (FATIGUE_FILE, FATIGUE_FIGURE))


def _wear_map(result: Run, out: Path, quiet: bool) -> pa.Table | None:
    """wear_map.parquet and wear_map.png (Archard depth per surface cell) of a drill-pipe run that recorded bodies,
    contacts and wear or pairs."""
    from ballcage.paper.wear_map import WEAR_FIGURE_FILE, WEAR_MAP_FILE, write_wear_map

    ids = "wear" in result.tables or "pairs" in result.tables
    ready = ids and all(t in result.tables for t in ("bodies", "contacts"))
    return _derived(result, out, quiet, ("wear_map", "wear map"), write_wear_map, ready, (WEAR_MAP_FILE, WEAR_FIGURE_FILE))


def _derived(
    result: Run,
    out: Path,
    quiet: bool,
    name: tuple[str, str],
    write: Callable[[Run, Path], tuple[pa.Table, dict[str, Path]]],
    ready: bool,
    files: tuple[str, ...],
) -> pa.Table | None:
    """A table computed from a drill-pipe run's tables, with its figure: `write(result, out)` gives the table and the
    paths ``<key>`` and ``<key>_figure``, `name` = (key, what to call it). Returns the table, or ``None`` with a note
    why not (unless `quiet`), an earlier run's `files` then removed so that none lies beside this run's tables."""
    key, called = name
    if result.scene.kind == "drill-pipe" and ready:
        try:
            table, paths = write(result, out)
        except _native.InputError as e:
            if not quiet:
                print(f"ballcage: no {called}: {e}")
        else:
            if not quiet:
                figure = paths[f"{key}_figure"]
                print(_summary(key, paths[key], table))
                print(f"wrote {figure}  (figure, {human_size(figure.stat().st_size)})")
            return table
    for file in files:
        (out / file).unlink(missing_ok=True)
    return None


def _failed(error: BaseException, written: Run, out: Path) -> int:
    """The exit code and message of a run that stopped (`written` is what was written) or whose verification failed."""
    code = 130 if isinstance(error, KeyboardInterrupt) else 1
    if isinstance(error, VerificationError) or (isinstance(error, KeyboardInterrupt) and written.complete):
        reason = error if isinstance(error, VerificationError) else "interrupted during the verification run"
        return fail(f"{reason}; the run's own tables in {out} are complete, {VERIFY_FILE} was not written", code)
    return fail(f"{written.error}; the output in {out} is incomplete (written up to then, ballcage.complete = false)", code)


def _report(result: Run, fatigue: pa.Table | None = None, wear_map: pa.Table | None = None) -> None:
    """The lines after the files: how close the run came to being stopped, its cost, wear, fatigue, fallback steps
    and, last, its verification."""
    margins = _margins(result.metadata)
    if margins is not None:
        print(margins)
    print(_cost(result.metadata))
    if "wear" in result.tables:
        from ballcage.duty import margin_line, wear_line

        for line in (margin_line(result.tables["wear"]), wear_line(result.tables["wear"])):
            if line is not None:
                print(f"ballcage: {line}")
    if wear_map is not None:
        from ballcage.measures.wear_map import hours_line

        line = hours_line(wear_map)
        if line is not None:
            print(f"ballcage: {line}")
    if fatigue is not None:
        from ballcage.measures.fatigue import fatigue_line

        line = fatigue_line(fatigue)
        if line is not None:
            print(f"ballcage: {line}")
    if result.fallback_note is not None:
        print(f"ballcage: warning: {result.fallback_note}")
    if result.verification is not None:
        for line in disagreements(result.verification):
            print(f"ballcage: warning: {line}")
        print(verdict(result.verification))


def _earlier_run(out: Path) -> list[str]:
    """Files of an earlier run in `out`: its ``<table>.parquet``, ``scene.toml`` and ``verify.parquet``."""
    files = [f"{t}.parquet" for t in _native.TABLE_NAMES] + ["scene.toml", VERIFY_FILE, "fatigue.parquet", "wear_map.parquet"]
    return [n for n in files if (out / n).exists()]


def _summary(name: str, path: Path, table: object) -> str:
    size = human_size(path.stat().st_size)
    if table is None:
        return f"wrote {path}  (resolved scene, {size})"
    return f"wrote {path}  ({table.num_rows} rows x {table.num_columns} columns, {size})"  # type: ignore[attr-defined]


def _margins(meta: dict[str, str]) -> str | None:
    """One line on how close the run came to the limits of its divergence checks (1 = stopped), or None from an
    engine that does not report it."""
    if "ballcage.penetration_of_limit" not in meta or "ballcage.energy_of_limit" not in meta:
        return None
    depth = float(meta["ballcage.penetration_of_limit"])
    where = ""
    if "ballcage.penetration_of_limit_pair" in meta:
        where = f" (pair {meta['ballcage.penetration_of_limit_pair']}, t = {float(meta['ballcage.penetration_of_limit_t_s']):.3g} s)"
    energy = float(meta["ballcage.energy_of_limit"])
    return (
        f"ballcage: divergence checks (simulation.divergence): deepest penetration {depth:.3g} of its pair's limit{where}; "
        f"energy created at most {energy:.3g} of what the check allows"
    )


def _cost(meta: dict[str, str]) -> str:
    """One line on what the run cost: wall time, real-time factor, solver work."""
    steps = int(meta["ballcage.steps"])
    simulated = steps * float(meta["ballcage.dt_s"])
    line = (
        f"ballcage: {simulated:.4g} s simulated in {float(meta['ballcage.wall_time_s']):.3g} s of wall time "
        f"(real-time factor {float(meta['ballcage.real_time_factor']):.3g}); "
    )
    if meta.get("ballcage.rtol") is not None:
        # Adaptive steps (an ESDIRK pair at simulation.rtol): the steps the integrator chose.
        line += (
            f"{meta['ballcage.integrator']} adaptive at rtol {float(meta['ballcage.rtol']):g}, "
            f"{meta['ballcage.accepted_steps']} steps ({meta['ballcage.rejected_steps']} rejected, "
            f"smallest {float(meta['ballcage.smallest_step_s']):.3g} s)"
        )
    else:
        line += f"{meta['ballcage.integrator']} at {float(meta['ballcage.dt_s']):g} s, {steps} steps"
    taken, per_stage = implicit_steps(meta), newton_per_stage(meta)
    if taken is not None and per_stage is not None:
        per_step = int(meta["ballcage.factorizations"]) / taken[0]
        line += f", {per_stage:.2f} Newton iterations per stage, {per_step:.2f} factorizations per step"
    return line
