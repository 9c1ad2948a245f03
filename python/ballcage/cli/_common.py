"""What the command modules of `ballcage.cli` share: the parser class, the usage error, option adders and checks.

Every check raises `UsageError` naming the option, the value and the reason;
`ballcage.cli.main` reports it as one line with exit code 2.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import NoReturn, TypeAlias

from ballcage import _native
from ballcage.scene import default_scene, load_scene

PROG = "ballcage"
#: Output tables, in the order `ballcage schema` prints them.
TABLE_NAMES: tuple[str, ...] = tuple(_native.TABLE_NAMES)
#: What the commands name the embedded scene in messages.
DEFAULT_SCENE_NAME = "default scene"


class UsageError(Exception):
    """Bad command-line input; reported as one line, exit code 2."""


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors (usage stays available through --help)."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{PROG}: error: {message} (see `{self.prog} --help`)\n")


#: What `commands.add_parser` returns for each subcommand: each command module's `add(commands)` takes it.
Commands: TypeAlias = "argparse._SubParsersAction[Parser]"


def add_out_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", "-o", metavar="DIR", required=True, type=Path, help="output directory (created)")


def add_quiet_option(parser: argparse.ArgumentParser, what: str) -> None:
    parser.add_argument("--quiet", "-q", action="store_true", help=what)


def add_set_option(parser: argparse.ArgumentParser, example: str | None = None) -> None:
    example = example or "--set simulation.duration=0.1 --set bodies.1.mass=2"
    parser.add_argument(
        "--set",
        metavar="KEY=VALUE",
        action="append",
        default=[],
        dest="overrides",
        help=f"override a scene field, e.g. {example} (value is TOML)",
    )


def add_integrators_option(parser: argparse.ArgumentParser, default: str | None = None) -> None:
    parser.add_argument(
        "--integrators",
        metavar="NAME,...",
        help=f"integrators to study (default {default or 'all: ' + ','.join(_native.INTEGRATORS)})",
    )


def workers(text: str) -> int:
    """``--workers N`` (an argparse ``type``): a whole number, at least 1."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: not a whole number") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text}: must be at least 1")
    return value


def positive(option: str, text: str | None, what: str = "a positive time in seconds") -> float | None:
    """`text` as a positive, finite number; ``None`` when the option was not given."""
    if text is None:
        return None
    try:
        value = float(text)
    except ValueError:
        raise UsageError(f"{option} {text!r}: not a number; give {what}") from None
    if not (math.isfinite(value) and value > 0):
        raise UsageError(f"{option} {text}: must be {what}")
    return value


def add_case_timeout_option(parser: argparse.ArgumentParser, default: str) -> None:
    parser.add_argument(
        "--case-timeout", metavar="SECONDS",
        help="wall time each case's run may take: a case past it is stopped, recorded as timed-out with its frames "
        f"up to then, and run again when the command is run again; 0: no limit ({default})",
    )  # fmt: skip


def case_timeout(text: str | None) -> float | None:
    """``--case-timeout``: seconds, 0 for no limit (returned as 0.0); ``None`` when the option was not given."""
    if text is None:
        return None
    what = "a positive number of seconds, or 0 for no limit"
    try:
        value = float(text)
    except ValueError:
        raise UsageError(f"--case-timeout {text!r}: not a number; give {what}") from None
    if not (math.isfinite(value) and value >= 0):
        raise UsageError(f"--case-timeout {text}: must be {what}")
    return value


def count(option: str, text: str, least: int) -> int:
    """`text` as a whole number, at least `least`."""
    try:
        value = int(text)
    except ValueError:
        raise UsageError(f"{option} {text!r}: not a whole number") from None
    if value < least:
        raise UsageError(f"{option} {text}: must be at least {least}")
    return value


def names(option: str, text: str | None, known: Sequence[str], what: str) -> list[str] | None:
    """A comma-separated list of `known` names; ``None`` when the option was not given."""
    if text is None:
        return None
    listed = [n.strip() for n in text.split(",") if n.strip()]
    if not listed:
        raise UsageError(f"{option} {text!r}: name at least one {what}")
    for name in listed:
        if name not in known:
            raise UsageError(f"{option} {name}: unknown {what} (known: {', '.join(known)})")
    return listed


def checked_out(out: Path) -> Path:
    """``--out DIR``: refused when it exists and is not a directory."""
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {out} exists and is not a directory")
    return out


def checked_override(text: str) -> str:
    """One ``--set KEY=VALUE``: refused without ``=`` or a key (the scene loader checks the rest)."""
    key, sep, _ = text.partition("=")
    if not sep or not key.strip():
        raise UsageError(f"malformed --set {text!r}: write KEY=VALUE, e.g. --set simulation.duration=0.1")
    return text


def load_cli_scene(arg: str | None, overrides: Sequence[str]) -> _native.Scene:
    """The scene named on the command line (or the embedded one) with `overrides`; bad input is a `UsageError`."""
    try:
        if arg is None:
            return default_scene(overrides)
        return load_scene(arg, overrides)
    except _native.SceneError as e:  # `load_scene` names the file itself
        raise UsageError(str(e) if arg is not None else f"{DEFAULT_SCENE_NAME}: {e}") from e
    except OSError as e:  # missing, a directory, unreadable
        raise UsageError(f"{e.strerror or e}: {e.filename or arg}") from e
    except UnicodeDecodeError as e:
        raise UsageError(f"{arg}: not UTF-8 text ({e.reason} at byte {e.start})") from e


def human_size(n: int) -> str:
    """A file size for the ``wrote ...`` lines: ``512 B``, ``1.5 KiB``, ``3.2 MiB``."""
    size = float(n)
    for unit in ("B", "KiB", "MiB", "GiB"):
        if size < 1024 or unit == "GiB":
            return f"{size:.0f} {unit}" if unit == "B" else f"{size:.1f} {unit}"
        size /= 1024
    raise AssertionError("unreachable")


def fail(message: str, code: int) -> int:
    """Prints ``ballcage: error: <message>`` (one line) on stderr; returns `code`."""
    first_line = " ".join(message.split()) if message else "failed"
    print(f"{PROG}: error: {first_line}", file=sys.stderr)
    return code
