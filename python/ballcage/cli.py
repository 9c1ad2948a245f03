"""Command line: ``ballcage run``, ``ballcage paper``, ``ballcage scene show`` and ``ballcage schema``.

``ballcage run`` without a scene runs the embedded paper scene (Zhu et al.
2023's drill pipe); ``ballcage scene show`` prints it as TOML to copy and edit.
``ballcage paper`` runs it with every table recorded and writes the paper's
figures and a comparison with its numbers (`ballcage.paper.run_paper`).

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
from ballcage.scene import SceneSource, default_scene, load_scene

__all__ = ["main"]

PROG = "ballcage"
#: Output tables, in the order `ballcage schema` prints them.
TABLE_NAMES: tuple[str, ...] = tuple(_native.TABLE_NAMES)
#: What `ballcage run` names the embedded scene in messages.
DEFAULT_SCENE_NAME = "default scene"


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
    run.add_argument(
        "scene",
        metavar="SCENE.toml",
        nargs="?",
        help="scene file (TOML); without it, the embedded paper scene (see `ballcage scene show`)",
    )
    run.add_argument("--out", "-o", metavar="DIR", required=True, type=Path, help="output directory (created)")
    _add_set_option(run)
    run.add_argument("--quiet", "-q", action="store_true", help="no progress bar and no summary")
    run.set_defaults(command=_run)

    paper = commands.add_parser(
        "paper",
        help="run the paper's scene; write tables, the paper's figures and a comparison",
        description=(
            "Run the embedded paper scene (Zhu et al., Machines 2023) recording every table; write "
            "<table>.parquet, scene.toml, the figures fig09-fig13 and table3_shape as PNG, and "
            "comparison.parquet / comparison.md against the paper's numbers. The full run takes minutes."
        ),
    )
    paper.add_argument("--out", "-o", metavar="DIR", required=True, type=Path, help="output directory (created)")
    _add_set_option(paper, example="--set simulation.duration=0.2 --set drive.speed_rpm=60")
    paper.add_argument(
        "--sweeps",
        action="store_true",
        help="also run the R = 1.0 / 2.5 m and 60 / 120 rpm variants (4 more runs) and fill the sweep rows",
    )
    paper.add_argument("--quiet", "-q", action="store_true", help="no progress bar and no summary")
    paper.set_defaults(command=_paper)

    scene = commands.add_parser(
        "scene",
        help="the embedded default scene",
        description="Work with the embedded default scene (the paper's drill pipe).",
    )
    scene_commands = scene.add_subparsers(title="commands", required=True, metavar="COMMAND", parser_class=_Parser)
    show = scene_commands.add_parser(
        "show",
        help="print the default scene as TOML",
        description="Print the default scene as TOML, every default written out: copy it, edit it, run it.",
    )
    show.set_defaults(command=_scene_show)

    schema = commands.add_parser(
        "schema",
        help="print the columns of the output tables",
        description="Print each output column with its type, unit and description.",
    )
    schema.add_argument("table", nargs="?", choices=TABLE_NAMES, metavar="TABLE", help=f"one of {', '.join(TABLE_NAMES)}")
    schema.set_defaults(command=_schema)
    return parser


def _add_set_option(parser: argparse.ArgumentParser, example: str | None = None) -> None:
    example = example or "--set simulation.duration=0.1 --set bodies.1.mass=2"
    parser.add_argument(
        "--set",
        metavar="KEY=VALUE",
        action="append",
        default=[],
        dest="overrides",
        help=f"override a scene field, e.g. {example} (value is TOML)",
    )


def _checked_out(out: Path) -> Path:
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {out} exists and is not a directory")
    return out


def _run(args: argparse.Namespace) -> int:
    overrides = [_checked_override(o) for o in args.overrides]
    out = _checked_out(args.out)
    source = _scene_source(args.scene)
    try:
        if source is None:
            scene = default_scene(overrides)
        else:
            scene = load_scene(source, overrides)
    except _native.SceneError as e:
        raise UsageError(f"{source or DEFAULT_SCENE_NAME}: {e}") from e
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


def _scene_source(arg: str | None) -> SceneSource | None:
    """The scene named on the command line; ``None`` for the embedded default scene."""
    return arg


def _paper(args: argparse.Namespace) -> int:
    from ballcage.paper import run_paper  # deferred: imports matplotlib

    overrides = [_checked_override(o) for o in args.overrides]
    out = _checked_out(args.out)
    try:
        paths = run_paper(out, overrides, sweeps=args.sweeps, progress=False if args.quiet else None)
    except _native.SceneError as e:
        raise UsageError(f"{DEFAULT_SCENE_NAME}: {e}") from e
    if not args.quiet:
        for name, path in paths.items():
            print(_paper_summary(name, path))
    return 0


def _paper_summary(name: str, path: Path) -> str:
    if path.is_dir():
        return f"wrote {path}/  (sweep variant {name.removeprefix('sweep_')})"
    if path.suffix == ".parquet":
        import pyarrow.parquet as pq

        meta = pq.ParquetFile(path).metadata
        return f"wrote {path}  ({meta.num_rows} rows x {meta.num_columns} columns, {_human_size(path.stat().st_size)})"
    what = {"scene": "resolved scene", "comparison_md": "comparison"}.get(name, "figure" if path.suffix == ".png" else name)
    return f"wrote {path}  ({what}, {_human_size(path.stat().st_size)})"


def _scene_show(args: argparse.Namespace) -> int:
    text = _native.default_scene_toml()
    sys.stdout.write(text if text.endswith("\n") else text + "\n")
    return 0


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
