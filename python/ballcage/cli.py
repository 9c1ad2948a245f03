"""Command line: ``ballcage run`` and ``ballcage schema``.

Exit codes: 0 success; 1 the run failed (`SimulationError`) or its output could
not be written; 2 bad input (an invalid scene, a missing file, a malformed
``--set``, a usage error). Errors are one line on stderr,
``ballcage: error: <message>``, never a traceback.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import NoReturn

from ballcage import _native
from ballcage.run import simulate
from ballcage.scene import SceneSource, load_scene

__all__ = ["main"]

PROG = "ballcage"
#: Output tables, in the order `ballcage schema` prints them.
TABLE_NAMES = ("bodies", "contacts", "energy")


class UsageError(Exception):
    """Bad command-line input; reported as one line, exit code 2."""


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (usage stays available through --help)."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{PROG}: error: {message} (see `{self.prog} --help`)\n")


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``ballcage`` script; returns the exit code."""
    args = _build_parser().parse_args(argv)
    try:
        return int(args.command(args))
    except (UsageError, _native.SceneError) as e:
        return _fail(str(e), 2)
    except _native.SimulationError as e:
        return _fail(str(e), 1)
    except OSError as e:
        return _fail(f"cannot write output: {e}", 1)
    except KeyboardInterrupt:
        return _fail("interrupted", 130)


def _build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog=PROG, description="Rigid-body contact dynamics with Arrow/Parquet output.")
    parser.add_argument("--version", action="version", version=f"{PROG} {_native.__version__}")
    commands = parser.add_subparsers(title="commands", required=True, metavar="COMMAND", parser_class=_Parser)

    run = commands.add_parser(
        "run",
        help="simulate a scene and write Parquet tables",
        description="Simulate a scene; write <table>.parquet for each recorded table and the resolved scene.toml.",
    )
    # To make SCENE optional later: nargs="?", and let _scene_source() supply the default scene.
    run.add_argument("scene", metavar="SCENE.toml", help="scene file (TOML)")
    run.add_argument("--out", "-o", metavar="DIR", required=True, type=Path, help="output directory (created)")
    run.add_argument(
        "--set",
        metavar="KEY=VALUE",
        action="append",
        default=[],
        dest="overrides",
        help="override a scene field, e.g. --set simulation.duration=0.1 --set bodies.1.mass=2 (value is TOML)",
    )
    run.add_argument("--quiet", "-q", action="store_true", help="no progress bar and no summary")
    run.set_defaults(command=_run)

    schema = commands.add_parser(
        "schema",
        help="print the columns of the output tables",
        description="Print each output column with its type, unit and description.",
    )
    schema.add_argument("table", nargs="?", choices=TABLE_NAMES, metavar="TABLE", help=f"one of {', '.join(TABLE_NAMES)}")
    schema.set_defaults(command=_schema)
    return parser


def _run(args: argparse.Namespace) -> int:
    overrides = [_checked_override(o) for o in args.overrides]
    out: Path = args.out
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {out} exists and is not a directory")
    source = _scene_source(args.scene)
    try:
        scene = load_scene(source, overrides)
    except _native.SceneError as e:
        raise UsageError(f"{source}: {e}") from e
    except OSError as e:  # missing, a directory, unreadable
        raise UsageError(f"{e.strerror or e}: {e.filename or source}") from e
    except UnicodeDecodeError as e:
        raise UsageError(f"{source}: not UTF-8 text ({e.reason} at byte {e.start})") from e
    result = simulate(scene, progress=False if args.quiet else None)
    paths = result.write(out)
    if not args.quiet:
        for name, path in paths.items():
            print(_summary(name, path, result.tables.get(name)))
    return 0


def _scene_source(arg: str | None) -> SceneSource:
    """The scene named on the command line (a default scene can be supplied here)."""
    if arg is None:
        raise UsageError("no scene given")
    return arg


def _checked_override(text: str) -> str:
    key, sep, _ = text.partition("=")
    if not sep or not key.strip():
        raise UsageError(f"malformed --set {text!r}: write KEY=VALUE, e.g. --set simulation.duration=0.1")
    return text


def _summary(name: str, path: Path, table: object) -> str:
    size = _human_size(path.stat().st_size)
    if table is None:
        return f"wrote {path}  (resolved scene, {size})"
    return f"wrote {path}  ({table.num_rows} rows x {table.num_columns} columns, {size})"  # type: ignore[attr-defined]


def _human_size(n: int) -> str:
    size = float(n)
    for unit in ("B", "KiB", "MiB", "GiB"):
        if size < 1024 or unit == "GiB":
            return f"{size:.0f} {unit}" if unit == "B" else f"{size:.1f} {unit}"
        size /= 1024
    raise AssertionError("unreachable")


def _schema(args: argparse.Namespace) -> int:
    names = [args.table] if args.table else list(TABLE_NAMES)
    blocks = []
    for name in names:
        schema = _native.table_schema(name)
        rows = []
        for field in schema:
            meta = field.metadata or {}
            unit = meta.get(b"unit", b"").decode()
            description = meta.get(b"description", b"").decode()
            rows.append((field.name, str(field.type), f"[{unit}]" if unit else "", description))
        widths = [max(len(r[i]) for r in rows) for i in range(3)] if rows else [0, 0, 0]
        lines = [name]
        lines += [
            f"  {n:<{widths[0]}}  {t:<{widths[1]}}  {u:<{widths[2]}}  {d}".rstrip() for n, t, u, d in rows
        ]
        blocks.append("\n".join(lines))
    print("\n\n".join(blocks))
    return 0


def _fail(message: str, code: int) -> int:
    first_line = " ".join(message.split()) if message else "failed"
    print(f"{PROG}: error: {first_line}", file=sys.stderr)
    return code


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main(sys.argv[1:]))
