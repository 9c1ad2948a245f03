"""Command line: the ``ballcage`` script and ``python -m ballcage``.

Commands, one module of this package each (in the order ``ballcage --help``
lists them); each parses its options and calls the library:

    run          simulate a scene (default: the embedded paper scene), write Parquet tables (`run`)
    paper        the paper's scene with every table, its figures and a comparison (`paper`)
    accuracy     error against run time of each integrator over a ladder of steps (`accuracy`)
    stability    largest stable step of each integrator against five parameters (`stability`)
    scene show   print a scene as TOML with every default and unit, to copy and edit (`scene`)
    schema       the columns of the output tables, with units (`schema`)
    buckling     torque above which a drill-pipe chain leaves the arc (`buckling`)
    size         joint sizing by the paper's eq. (9), in mm (`size`)
    sweep        a grid or list of scene variants, in parallel, one summary row per case (`sweep`)
    chart        the design chart over curvature radius x joint length (`chart`)
    sensitivity  how much each unstated parameter moves each quantity: table, ranking, tornado charts (`sensitivity`)
    view         the chain turning in 3D: an HTML page, a GIF or an MP4 of a run (`view`)

`_common` holds what they share: `UsageError`, the parser class, the option
adders and checks, and the loading of the command line's scene.

Exit codes: 0 success; 1 the run diverged (`SimulationError`; ``ballcage run``
then still writes what was recorded, marked incomplete), the verification run
of ``ballcage run --verify`` failed (the run's own tables written), a study
failed, or a sweep case, chart cell or sensitivity run did not finish; 2 bad input (an invalid scene, a TOML
syntax error, a missing file, a malformed ``--set``, an unknown ``--tables``
name, an ``--out`` folder holding another run, an option value the library
refused, a usage error); 3 the output could not be written; 70 internal error
(a bug in ballcage, e.g. a panic in the engine: sysexits' EX_SOFTWARE); 130
interrupted (Ctrl-C, after writing what was recorded). Errors are one line on
stderr, ``ballcage: error: <message>``, never a traceback.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence

from ballcage import _native
from ballcage.cli import (
    accuracy,
    buckling,
    chart,
    paper,
    run,
    scene,
    schema,
    sensitivity,
    size,
    stability,
    sweep,
    view,
)
from ballcage.cli._common import PROG, Parser, UsageError, fail

__all__ = ["build_parser", "main"]

#: The command modules, in the order ``ballcage --help`` lists them.
COMMANDS = (run, paper, accuracy, stability, scene, schema, buckling, size, sweep, chart, sensitivity, view)
#: Exit code of an internal error (a bug in ballcage): sysexits' EX_SOFTWARE.
EXIT_INTERNAL = 70
#: Options whose value may be a (wrong) negative number, which argparse would take for an option.
_NUMBER_OPTIONS = frozenset(option for command in COMMANDS for option in getattr(command, "NUMBER_OPTIONS", ()))


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``ballcage`` script; returns the exit code."""
    given = list(sys.argv[1:] if argv is None else argv)
    args = build_parser().parse_args(_attach_negative_numbers(given))
    args.argv = given
    try:
        return int(args.command(args))
    except (UsageError, _native.SceneError) as e:
        return fail(str(e), 2)
    except _native.SimulationError as e:
        return fail(str(e), 1)
    except _native.InputError as e:  # an option value the API refused (e.g. a sizing length)
        return fail(str(e), 2)
    except _native.InternalError as e:  # a bug: a Rust panic, caught in the glue
        return fail(str(e), EXIT_INTERNAL)
    except _study_error() as e:
        return fail(str(e), 1)
    except OSError as e:
        return fail(_write_error(e), 3)
    except KeyboardInterrupt:
        return fail("interrupted", 130)


def build_parser() -> argparse.ArgumentParser:
    """The ``ballcage`` parser: each command module's `add` registers its subcommand and handler."""
    parser = Parser(prog=PROG, description="Rigid-body contact dynamics with Arrow/Parquet output.")
    parser.add_argument("--version", action="version", version=f"{PROG} {_native.__version__}")
    commands = parser.add_subparsers(title="commands", required=True, metavar="COMMAND", parser_class=Parser)
    for command in COMMANDS:
        command.add(commands)
    return parser


def _attach_negative_numbers(argv: Sequence[str]) -> list[str]:
    """``--steps -1e-5`` → ``--steps=-1e-5``, so the option's own check reports the value."""
    out: list[str] = []
    i = 0
    while i < len(argv):
        arg = argv[i]
        nxt = argv[i + 1] if i + 1 < len(argv) else ""
        if arg in _NUMBER_OPTIONS and nxt[:1] == "-" and (nxt[1:2].isdigit() or nxt[1:2] == "."):
            out.append(f"{arg}={nxt}")
            i += 2
            continue
        out.append(arg)
        i += 1
    return out


def _study_error() -> type[Exception]:
    from ballcage.studies import StudyError  # deferred: numpy, pyarrow

    return StudyError


def _write_error(error: OSError) -> str:
    """``cannot write <path>: <reason> (errno N)`` for an `OSError` naming its file; else ``cannot write output: <error>``."""
    if error.filename is None:
        return f"cannot write output: {error}"
    number = f" (errno {error.errno})" if error.errno else ""
    return f"cannot write {os.fsdecode(error.filename)}: {error.strerror or error}{number}"
