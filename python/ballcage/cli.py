"""Command line: ``ballcage run``, ``paper``, ``accuracy``, ``stability``, ``scene show`` and ``schema``.

``ballcage run`` without a scene runs the embedded paper scene (Zhu et al.
2023's drill pipe); ``ballcage scene show`` prints it (or a scene file) as TOML
with every default and each number's unit, to copy and edit.
``ballcage paper`` runs it with every table recorded and writes the paper's
figures and a comparison with its numbers (`ballcage.paper.run_paper`).
``ballcage accuracy`` and ``ballcage stability`` are the integrator studies of
`ballcage.studies`.

Exit codes: 0 success; 1 the run diverged (`SimulationError`; ``ballcage run``
then still writes what was recorded, marked incomplete); 2 bad input (an
invalid scene, a TOML syntax error, a missing file, a malformed ``--set``, an
unknown ``--tables`` name, an ``--out`` folder holding another run, a usage
error); 3 the output could not be written; 130 interrupted (Ctrl-C, after
writing what was recorded). Errors are one line on stderr,
``ballcage: error: <message>``, never a traceback.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shlex
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import NoReturn, TypeAlias

from ballcage import _native
from ballcage.run import simulate
from ballcage.scene import default_scene, load_scene

__all__ = ["main"]

PROG = "ballcage"
#: Output tables, in the order `ballcage schema` prints them.
TABLE_NAMES: tuple[str, ...] = tuple(_native.TABLE_NAMES)
#: `ballcage stability --parameters` names (`ballcage.studies.PARAMETER_NAMES`, not imported here:
#: the studies module pulls in numpy and pyarrow, which the other commands do not need to start).
STABILITY_PARAMETERS: tuple[str, ...] = ("stiffness", "speed", "curvature_radius", "key_mass", "damping")
#: What `ballcage run` names the embedded scene in messages.
DEFAULT_SCENE_NAME = "default scene"


class UsageError(Exception):
    """Bad command-line input; reported as one line, exit code 2."""


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (usage stays available through --help)."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{PROG}: error: {message} (see `{self.prog} --help`)\n")


#: Exit code of an internal error (a bug in ballcage): sysexits' EX_SOFTWARE.
EXIT_INTERNAL = 70


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``ballcage`` script; returns the exit code."""
    given = list(sys.argv[1:] if argv is None else argv)
    args = _build_parser().parse_args(_attach_negative_numbers(given))
    args.argv = given
    try:
        return int(args.command(args))
    except (UsageError, _native.SceneError) as e:
        return _fail(str(e), 2)
    except _native.SimulationError as e:
        return _fail(str(e), 1)
    except _native.InputError as e:  # an option value the API refused (e.g. a sizing length)
        return _fail(str(e), 2)
    except _native.InternalError as e:  # a bug: a Rust panic, caught in the glue
        return _fail(str(e), EXIT_INTERNAL)
    except _study_error() as e:
        return _fail(str(e), 1)
    except OSError as e:
        return _fail(_write_error(e), 3)
    except KeyboardInterrupt:
        return _fail("interrupted", 130)


#: `ballcage size` options, all lengths in mm.
_SIZE_OPTIONS = ("--radius", "--tube-id", "--joint-od", "--length")
#: Options whose value may be a (wrong) negative number, which argparse would take for an option.
_NUMBER_OPTIONS = frozenset(
    {"--steps", "--reference-dt", "--duration", "--values-per-parameter", "--bisections", "--frames", "--fps", *_SIZE_OPTIONS}
)


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


def _build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog=PROG, description="Rigid-body contact dynamics with Arrow/Parquet output.")
    parser.add_argument("--version", action="version", version=f"{PROG} {_native.__version__}")
    commands = parser.add_subparsers(title="commands", required=True, metavar="COMMAND", parser_class=_Parser)
    _add_run_command(commands)
    _add_paper_command(commands)
    _add_accuracy_command(commands)
    _add_stability_command(commands)
    _add_scene_command(commands)
    _add_schema_command(commands)
    _add_buckling_command(commands)
    _add_size_command(commands)
    _add_sweep_command(commands)
    _add_chart_command(commands)
    _add_view_command(commands)
    return parser


#: What `commands.add_parser` returns for each subcommand.
_Commands: TypeAlias = "argparse._SubParsersAction[_Parser]"


def _add_run_command(commands: _Commands) -> None:
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
    _add_out_option(run)
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
    _add_set_option(run)
    _add_quiet_option(run, "no progress bar and no summary")
    run.set_defaults(command=_run)


def _add_paper_command(commands: _Commands) -> None:
    paper = commands.add_parser(
        "paper",
        help="run the paper's scene; write tables, the paper's figures and a comparison",
        description=(
            "Run the embedded paper scene (Zhu et al., Machines 2023) recording every table; write "
            "<table>.parquet, scene.toml, the figures fig09-fig13 and table3_shape as PNG, and "
            "comparison.parquet / comparison.md against the paper's numbers. The full run takes minutes."
        ),
    )
    _add_out_option(paper)
    _add_set_option(paper, example="--set simulation.duration=0.2 --set drive.speed_rpm=60")
    paper.add_argument(
        "--sweeps",
        action="store_true",
        help="also run the paper's section 4 as a sweep into DIR/sweeps (R = 1.0-2.5 m at 100 rpm, 60-120 rpm at "
        "1.5 m, and the baseline with R +-1 um for the run-to-run spread: 9 runs, resumed when run again); fill the "
        "sweep rows, draw Figures 16-17 and check the paper's trends (trends.parquet)",
    )
    paper.add_argument("--workers", metavar="N", type=_workers, help="with --sweeps: local threads (default: one per CPU)")
    paper.add_argument(
        "--scheduler", metavar="ADDRESS", help="with --sweeps: run the sweep on the Dask cluster at ADDRESS; needs ballcage[dask]"
    )
    _add_quiet_option(paper, "no progress bar and no summary")
    paper.set_defaults(command=_paper)


def _add_accuracy_command(commands: _Commands) -> None:
    accuracy = commands.add_parser(
        "accuracy",
        help="error against run time of each integrator over a ladder of steps (work-precision)",
        description=(
            "Run a scene with each integrator over a ladder of steps and compare named quantities (drill pipe: "
            "peak key-seat force, mean tube force per joint, final link bends, energy; generic scenes: peak force "
            "per pair, final body states, energy) with a reference: the same scene at a much smaller step with "
            "the most accurate integrator, also run at twice that step to show it has converged. Writes "
            "work_precision.parquet, work_precision.png (error against wall time, log-log) and work_precision.md. "
            "Runs that diverge are recorded as diverged, not errors."
        ),
    )
    accuracy.add_argument(
        "scene",
        metavar="SCENE.toml",
        nargs="?",
        help="scene file (TOML); without it, the embedded paper scene (use --duration to keep it affordable)",
    )
    _add_out_option(accuracy)
    _add_integrators_option(
        accuracy, "all; on drill pipes the implicit ones only, the explicit ones needing 0.1-2 us steps there"
    )
    accuracy.add_argument(
        "--steps",
        metavar="[INTEGRATOR=]DT,DT,...",
        action="append",
        default=[],
        help=(
            "ladder of steps [s] for every integrator, or for one with INTEGRATOR=...; repeatable "
            "(default: drill pipes 20-200 us implicit, 0.1-2 us explicit when named; generic scenes 0.25-2x the scene's dt "
            "explicit, 1-8x implicit)"
        ),
    )
    accuracy.add_argument("--reference-integrator", metavar="NAME", help="integrator of the reference (default sdirk2)")
    accuracy.add_argument(
        "--reference-dt",
        metavar="DT",
        help="step of the reference [s] (default: the reference integrator's smallest default step / 4)",
    )
    accuracy.add_argument("--duration", metavar="S", help="simulated duration [s] (default: the scene's)")
    _add_set_option(accuracy, example="--set pipe.joints=4 --set 'pipe.hinge=\"ideal-cv\"'")
    _add_quiet_option(accuracy, "no progress lines and no summary")
    accuracy.set_defaults(command=_accuracy)


def _add_stability_command(commands: _Commands) -> None:
    stability = commands.add_parser(
        "stability",
        help="largest stable step of each integrator against stiffness, speed, curvature, key mass, damping",
        description=(
            "For each integrator, find the largest step at which a short probe run finishes without a divergence "
            "error (bracketing by factors of 4, then bisection in log dt), varying one parameter at a time around "
            "the defaults: contact stiffness of the key and cage contacts (1e3-1e7 N/mm^2.2), drive speed "
            "(30-600 rpm), curvature radius (from the tightest the hinge allows, pitch / (2 sin(limit / 2)) = "
            "0.770 m for the paper's pipe, to 5 m), key mass (1/4-4x) and contact damping (0 and 0.1-100 N s/mm). "
            "The probe scene is the paper's drill pipe with pipe.joints = 2, 0.03 s simulated and the drive and "
            "load ramped in over 0.01 s (--set and --duration change it). Writes stability.parquet, "
            "stability_<parameter>.png heat maps (integrator x value, colour log10 max stable dt) and stability.md."
        ),
    )
    _add_out_option(stability)
    _add_integrators_option(stability)
    stability.add_argument(
        "--parameters",
        metavar="NAME,...",
        help=f"parameters to vary (default all: {','.join(STABILITY_PARAMETERS)})",
    )
    stability.add_argument(
        "--values-per-parameter",
        metavar="N",
        default="5",
        help="values of each parameter (default 5, at least 2)",
    )
    stability.add_argument("--duration", metavar="S", help="simulated duration of each probe [s] (default 0.03)")
    stability.add_argument(
        "--bisections",
        metavar="N",
        default="5",
        help="bisections after bracketing (default 5: the step is found to 4.4%%)",
    )
    stability.add_argument("--grid", action="store_true", help="also map every stiffness x speed pair (stability_grid.png)")
    _add_set_option(stability, example="--set pipe.joints=3 --set 'pipe.hinge=\"ideal-cv\"'")
    _add_quiet_option(stability, "no progress lines and no summary")
    stability.set_defaults(command=_stability)


def _add_scene_command(commands: _Commands) -> None:
    scene = commands.add_parser(
        "scene",
        help="show a scene (by default the embedded one) with every default and unit",
        description="Work with scenes: the embedded default one (the paper's drill pipe) or a file.",
    )
    scene_commands = scene.add_subparsers(title="commands", required=True, metavar="COMMAND", parser_class=_Parser)
    show = scene_commands.add_parser(
        "show",
        help="print a scene (default: the embedded one) as TOML, with units",
        description=(
            "Print a scene as TOML (without SCENE.toml, the embedded paper scene), every default written out "
            "and each number's unit as a comment at the end of its line (contact laws in their own units, "
            "e.g. N/mm^2.2): copy it, edit it, run it."
        ),
    )
    show.add_argument("scene", metavar="SCENE.toml", nargs="?", help="scene file (TOML); default: the embedded one")
    _add_set_option(show)
    show.set_defaults(command=_scene_show)


def _add_schema_command(commands: _Commands) -> None:
    schema = commands.add_parser(
        "schema",
        help="print the columns of the output tables",
        description="Print each output column with its type, unit and description.",
    )
    schema.add_argument("table", nargs="?", choices=TABLE_NAMES, metavar="TABLE", help=f"one of {', '.join(TABLE_NAMES)}")
    schema.set_defaults(command=_schema)


def _add_sweep_command(commands: _Commands) -> None:
    sweep = commands.add_parser(
        "sweep",
        help="run a grid or a list of scene variants in parallel (locally or on Dask); one summary row per case",
        description=(
            "Run every case of a sweep file (a [grid] of dotted scene keys, their Cartesian product, and/or [[case]] "
            "tables of overrides, on a base scene; docs/studies.md) in parallel. Writes DIR/<table>/case=NNNN/"
            "part.parquet (hive-partitioned datasets), DIR/summary.parquet (one row per case: parameters, derived "
            "quantities, status, cost) and DIR/plots/<parameter>.png. A diverging case is recorded and the sweep goes "
            "on; running the same command again resumes, skipping finished cases. Exit code 1 when a case did not finish."
        ),
    )
    sweep.add_argument("sweep", metavar="SWEEP.toml", help="sweep file (TOML), e.g. examples/sweeps/curvature_rpm.toml")
    _add_out_option(sweep)
    sweep.add_argument("--workers", metavar="N", type=_workers, help="local threads running cases (default: one per CPU)")
    sweep.add_argument(
        "--scheduler", metavar="ADDRESS", help="run on the Dask cluster at ADDRESS (tcp://host:8786); needs ballcage[dask]"
    )
    sweep.add_argument("--retry-failed", action="store_true", help="also run again the cases that diverged or failed")
    sweep.add_argument("--no-plots", action="store_true", help="do not draw DIR/plots/*.png")
    _add_quiet_option(sweep, "no progress and no summary lines")
    sweep.set_defaults(command=_sweep)


def _workers(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: not a whole number") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text}: must be at least 1")
    return value


def _sweep(args: argparse.Namespace) -> int:
    from ballcage.studies.sweep_run import command  # deferred: pyarrow, numpy, matplotlib
    from ballcage.studies.sweep_spec import SweepError

    try:
        return command(args)
    except SweepError as e:
        raise UsageError(str(e)) from e


def _add_chart_command(commands: _Commands) -> None:
    chart = commands.add_parser(
        "chart",
        help="design chart: key and tube forces over curvature radius x joint length, infeasible cells marked",
        description=(
            "For one tube ID and joint OD, check every cell of curvature radius x joint length (pipe.pitch) against "
            "the paper's eq. (9) and the hinge's articulation limit before running, run the feasible cells as one sweep "
            "(locally or on Dask; running it again resumes), and write DIR/design_chart.png (heat maps of the peak key "
            "force and the mean and peak tube forces, excluded cells hatched with the constraint that excludes them) "
            "and DIR/design_chart.parquet (one row per cell). Link mass and inertia scale with the length "
            "(docs/studies.md). Exit code 1 when a feasible cell did not finish."
        ),
    )
    _add_out_option(chart)
    chart.add_argument("--radius-mm", metavar="MM", nargs="+", help="curvature radii R [mm] (default 1000 1500 2000 3000 4000)")
    chart.add_argument("--length-mm", metavar="MM", nargs="+", help="joint lengths L [mm] (default 150 200 300 400 500 1000)")
    chart.add_argument("--tube-id", metavar="MM", help="inner diameter D of the guide tube [mm] (default 116, the paper's)")
    chart.add_argument("--joint-od", metavar="MM", help="outer diameter d of the joint [mm] (default 86, the paper's)")
    chart.add_argument(
        "--hinge", choices=("ball-keys", "ideal-cv"), default="ball-keys",
        help="hinge model (default ball-keys, the paper's; ideal-cv is ~7x faster but has no keys and about half "
        "the tube force, docs/studies.md)",
    )
    chart.add_argument("--duration", metavar="S", help="simulated time per cell [s] (default 1.8)")
    chart.add_argument(
        "--window", metavar=("START", "END"), nargs=2, help="summary window of the tube forces [s] (default: the run's second half)"
    )
    chart.add_argument("--fixed-mass", action="store_true", help="keep the base link's mass and inertia at every length")
    chart.add_argument("--workers", metavar="N", type=_workers, help="local threads running cells (default: one per CPU)")
    chart.add_argument("--scheduler", metavar="ADDRESS", help="run on the Dask cluster at ADDRESS; needs ballcage[dask]")
    _add_set_option(chart, example="--set drive.speed_rpm=60 --set pipe.joints=8")
    _add_quiet_option(chart, "no estimate, progress or summary lines")
    chart.set_defaults(command=_chart)


def _chart(args: argparse.Namespace) -> int:
    from ballcage import sizing
    from ballcage.studies.design_chart import DEFAULT_DURATION, command  # deferred: pyarrow, numpy, matplotlib
    from ballcage.studies.sweep_spec import SweepError

    def metres(option: str, text: str | None) -> float | None:
        value = _positive(option, text, "a positive length in mm")
        return None if value is None else value / 1e3

    inputs: dict[str, object] = {"hinge": args.hinge, "scale_mass": not args.fixed_mass}
    for option, key, texts in (("--radius-mm", "radii", args.radius_mm), ("--length-mm", "lengths", args.length_mm)):
        if texts is not None:
            inputs[key] = [metres(option, t) for t in texts]
    tube, joint = metres("--tube-id", args.tube_id), metres("--joint-od", args.joint_od)
    bore = tube or sizing.PAPER_TUBE_INNER_DIAMETER
    if joint is not None and joint >= bore:
        raise UsageError(f"--joint-od {args.joint_od}: not narrower than the tube, --tube-id {1e3 * bore:g}")
    inputs.update(tube_inner_diameter=tube, joint_diameter=joint)
    inputs["duration"] = _positive("--duration", args.duration) or DEFAULT_DURATION
    if args.window is not None:
        try:
            inputs["window"] = (float(args.window[0]), float(args.window[1]))
        except ValueError:
            raise UsageError(f"--window {' '.join(args.window)}: give START END in seconds, e.g. --window 0.9 1.8") from None
    args.overrides = [_checked_override(o) for o in args.overrides]
    _checked_out(args.out)
    try:
        return command(args, **inputs)
    except SweepError as e:
        raise UsageError(str(e)) from e


def _add_buckling_command(commands: _Commands) -> None:
    from ballcage.buckling import add_command  # the command lives with its model (docs/buckling.md)

    add_command(commands)


def _add_size_command(commands: _Commands) -> None:
    size = commands.add_parser(
        "size",
        help="joint sizing by the paper's eq. (9), in mm: longest joint, tightest bend or widest joint",
        description=(
            "The paper's eq. (8)-(9) for a rigid joint in a bent guide tube, lengths in mm. Give --tube-id and two "
            "of --radius, --joint-od and --length; it prints the third: --radius and --joint-od the longest joint, "
            "--length and --joint-od the smallest curvature radius, --length and --radius the largest joint OD. "
            "--plot draws the longest joint against the curvature radius for several joint diameters (the "
            "paper's Figure 15; --tube-id, default 116). It checks the fit in the tube only; the hinge's "
            "articulation limit binds first for the paper's pipe (ballcage.Scene.tightest_radius)."
        ),
    )
    for option, what in (
        ("--radius", "curvature radius R of the tube's centreline"),
        ("--tube-id", "inner diameter D of the guide tube"),
        ("--joint-od", "outer diameter d = 2r of the joint"),
        ("--length", "length L of the joint"),
    ):
        size.add_argument(option, metavar="MM", help=f"{what} [mm]")
    size.add_argument("--plot", metavar="FILE.png", type=Path, help="also write a PNG of the eq. (9) curves")
    size.set_defaults(command=_size)


def _size(args: argparse.Namespace) -> int:
    from ballcage import sizing  # deferred with the rest of the subcommands' modules

    mm = {o: _positive(o, getattr(args, o[2:].replace("-", "_")), "a positive length in mm") for o in _SIZE_OPTIONS}
    given = [o for o in ("--radius", "--joint-od", "--length") if mm[o] is not None]
    if len(given) in (1, 3) or (not given and args.plot is None):
        raise UsageError(f"give --tube-id and two of --radius, --joint-od and --length (got {', '.join(given) or 'none'})")
    if len(given) == 2 and mm["--tube-id"] is None:
        raise UsageError(f"--tube-id missing: {' and '.join(given)} need the tube's inner diameter in mm")
    tube = mm["--tube-id"] or 1e3 * sizing.PAPER_TUBE_INNER_DIAMETER
    joint, radius, length = mm["--joint-od"], mm["--radius"], mm["--length"]
    if joint is not None and joint >= tube:
        raise UsageError(f"--joint-od {args.joint_od}: not narrower than the bore, --tube-id {tube:g}")
    if radius is not None and radius < tube / 2:
        raise UsageError(f"--radius {args.radius}: below half the bore ({tube / 2:g} mm); a tube cannot bend that tightly")
    if joint is not None and radius is not None:
        length = 1e3 * sizing.longest_joint(radius / 1e3, tube / 1e3, joint / 1e3)
        print(f"{length:.2f}")
    elif joint is not None and length is not None:
        radius = 1e3 * sizing.smallest_curvature_radius(length / 1e3, tube / 1e3, joint / 1e3)
        print(f"{radius:.2f}")
    elif radius is not None and length is not None:
        most = 1e3 * _native.longest_link(radius / 1e3, tube / 1e3, 0.0)
        if length >= most:
            raise UsageError(
                f"--length {args.length}: no joint that long fits a {tube:g} mm bore bent to R = {radius:g} mm "
                f"(eq. (9): under {most:.2f} mm, the length of a joint of no diameter)"
            )
        joint = 1e3 * sizing.largest_joint_diameter(length / 1e3, radius / 1e3, tube / 1e3)
        print(f"{joint:.2f}")
    if args.plot is not None:
        mark = (radius / 1e3, joint / 1e3, length / 1e3) if radius and joint and length else None
        path = sizing.plot_joint_lengths(args.plot, tube / 1e3, mark=mark)
        print(_paper_summary("figure", path))
    return 0


def _add_view_command(commands: _Commands) -> None:
    view = commands.add_parser(
        "view",
        help="the chain seen turning in 3D: an offline HTML page (or a GIF or MP4) of a drill-pipe run",
        description=(
            "Draw a drill-pipe run's chain turning in its guide tube: links coloured by their tube normal force [N], "
            "the connectors, the ball keys where their poses are recorded (record.bodies), a mark on each body that "
            "shows it turning, and the semi-transparent tube; lengths in m. The suffix of --out picks the kind: "
            ".html is one self-contained page with plotly.js embedded (it opens offline) with play, pause and a time "
            "slider (FILE.html#t=1.2 opens at t = 1.2 s); .gif (Pillow) and .mp4 (needs ffmpeg) are for reports. "
            "Poses come from bodies.parquet, or from links.parquet (com and eq. (4) angles) without it."
        ),
    )
    view.add_argument(
        "run_dir", metavar="RUN_DIR", type=Path,
        help="a run's folder (`ballcage run --out DIR`, `ballcage paper --out DIR`, Run.write): scene.toml and "
        "bodies.parquet or links.parquet",
    )
    view.add_argument(
        "--out", "-o", metavar="FILE", required=True, type=Path,
        help="chain.html (interactive page), chain.gif or chain.mp4 (needs ffmpeg); its folder is created",
    )
    view.add_argument("--frames", metavar="N", default="120", help="draw at most N frames, evenly spaced over the run (default 120)")
    view.add_argument("--fps", metavar="FPS", default="12", help="frames per second when played (default 12)")
    _add_quiet_option(view, "no summary line")
    view.set_defaults(command=_view)


def _view(args: argparse.Namespace) -> int:
    from ballcage.view import VIEW_SUFFIXES, write_view  # deferred: numpy, plotly or matplotlib

    frames = _count("--frames", args.frames, 1)
    fps = _positive("--fps", args.fps, "a positive number of frames per second")
    assert fps is not None
    if args.out.suffix.lower() not in VIEW_SUFFIXES:
        suffix = repr(args.out.suffix) if args.out.suffix else "no suffix"
        raise UsageError(f"--out {args.out}: {suffix}: the suffix picks the kind; write {', '.join(VIEW_SUFFIXES)}")
    if args.out.is_dir():
        raise UsageError(f"--out {args.out}: is a directory; name the file, e.g. --out {args.out / 'chain.html'}")
    path = write_view(args.run_dir, args.out, frames=frames, fps=fps)  # an InputError names the folder: exit 2
    if not args.quiet:
        print(f"wrote {path}  (3D view, {_human_size(path.stat().st_size)})")
    return 0


def _add_out_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", "-o", metavar="DIR", required=True, type=Path, help="output directory (created)")


def _add_quiet_option(parser: argparse.ArgumentParser, what: str) -> None:
    parser.add_argument("--quiet", "-q", action="store_true", help=what)


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


def _add_integrators_option(parser: argparse.ArgumentParser, default: str | None = None) -> None:
    parser.add_argument(
        "--integrators",
        metavar="NAME,...",
        help=f"integrators to study (default {default or 'all: ' + ','.join(_native.INTEGRATORS)})",
    )


def _study_error() -> type[Exception]:
    from ballcage.studies import StudyError

    return StudyError


def _checked_out(out: Path) -> Path:
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {out} exists and is not a directory")
    return out


def _load_cli_scene(arg: str | None, overrides: Sequence[str]) -> _native.Scene:
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


def _earlier_run(out: Path) -> list[str]:
    """Files of an earlier run in `out`: its ``<table>.parquet`` and ``scene.toml``."""
    names = [f"{t}.parquet" for t in _native.TABLE_NAMES] + ["scene.toml"]
    return [n for n in names if (out / n).exists()]


def _run(args: argparse.Namespace) -> int:
    overrides = [_checked_override(o) for o in args.overrides]
    out = _checked_out(args.out)
    earlier = _earlier_run(out)
    if earlier and not args.overwrite:
        raise UsageError(
            f"--out {out} holds another run's output ({', '.join(earlier)}); "
            "pass --overwrite to replace it, or choose another folder"
        )
    chosen = _names("--tables", args.tables, TABLE_NAMES, "table")
    scene = _load_cli_scene(args.scene, overrides)
    tables = chosen
    if tables is not None:
        try:
            scene = _load_cli_scene(args.scene, [*overrides, "record.tables=" + json.dumps(tables)])
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
        return _fail(f"{partial.error}; the output in {out} is incomplete (written up to then, ballcage.complete = false)", code)
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
    return 0


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


def _positive(option: str, text: str | None, what: str = "a positive time in seconds") -> float | None:
    if text is None:
        return None
    try:
        value = float(text)
    except ValueError:
        raise UsageError(f"{option} {text!r}: not a number; give {what}") from None
    if not (math.isfinite(value) and value > 0):
        raise UsageError(f"{option} {text}: must be {what}")
    return value


def _count(option: str, text: str, least: int) -> int:
    try:
        value = int(text)
    except ValueError:
        raise UsageError(f"{option} {text!r}: not a whole number") from None
    if value < least:
        raise UsageError(f"{option} {text}: must be at least {least}")
    return value


def _names(option: str, text: str | None, known: Sequence[str], what: str) -> list[str] | None:
    if text is None:
        return None
    names = [n.strip() for n in text.split(",") if n.strip()]
    if not names:
        raise UsageError(f"{option} {text!r}: name at least one {what}")
    for name in names:
        if name not in known:
            raise UsageError(f"{option} {name}: unknown {what} (known: {', '.join(known)})")
    return names


def _ladder(option: str, text: str) -> list[float]:
    steps = []
    for item in text.split(","):
        if not item.strip():
            raise UsageError(f"{option} {text!r}: empty step; write e.g. {option} 1e-5,5e-6")
        step = _positive(option, item.strip(), "a positive step in seconds")
        assert step is not None
        steps.append(step)
    return steps


def _steps_option(texts: Sequence[str], integrators: Sequence[str]) -> list[float] | dict[str, list[float]] | None:
    """``--steps``: one ladder for all (``1e-5,5e-6``) and/or per integrator (``rk4=1e-6,5e-7``)."""
    common: list[float] | None = None
    per: dict[str, list[float]] = {}
    for text in texts:
        name, sep, ladder = text.partition("=")
        if sep:
            name = name.strip()
            if name not in integrators:
                raise UsageError(f"--steps {text}: {name!r} is not one of the studied integrators ({', '.join(integrators)})")
            per[name] = _ladder("--steps", ladder)
        else:
            common = _ladder("--steps", text)
    if not per:
        return common
    if common is not None:
        for name in integrators:
            per.setdefault(name, common)
    return per


def _accuracy(args: argparse.Namespace) -> int:
    from ballcage.studies import accuracy, write_accuracy  # deferred: numpy, matplotlib
    from ballcage.studies.accuracy_run import default_integrators

    known = list(_native.INTEGRATORS)
    reference = _names("--reference-integrator", args.reference_integrator, known, "integrator")
    reference_dt = _positive("--reference-dt", args.reference_dt, "a positive step in seconds")
    duration = _positive("--duration", args.duration)
    overrides = [_checked_override(o) for o in args.overrides]
    out = _checked_out(args.out)
    scene = _load_cli_scene(args.scene, overrides)
    integrators = _names("--integrators", args.integrators, known, "integrator") or default_integrators(scene)
    steps = _steps_option(args.steps, integrators)
    table = accuracy(
        scene,
        integrators=integrators,
        steps=steps,
        reference_integrator=reference[0] if reference else None,
        reference_dt=reference_dt,
        duration=duration,
        progress=not args.quiet,
    )
    paths = write_accuracy(table, out, command=shlex.join([PROG, *args.argv]))
    if not args.quiet:
        for path in paths.values():
            print(f"wrote {path}  ({_human_size(path.stat().st_size)})")
    return 0


def _stability(args: argparse.Namespace) -> int:
    from ballcage.studies import probe_scene, stability, write_stability  # deferred: numpy, matplotlib

    known = list(_native.INTEGRATORS)
    integrators = _names("--integrators", args.integrators, known, "integrator") or known
    parameters = _names("--parameters", args.parameters, STABILITY_PARAMETERS, "parameter")
    values = _count("--values-per-parameter", args.values_per_parameter, 2)
    bisections = _count("--bisections", args.bisections, 0)
    duration = _positive("--duration", args.duration)
    overrides = [_checked_override(o) for o in args.overrides]
    out = _checked_out(args.out)
    try:
        scene = probe_scene(overrides, duration)
    except _native.SceneError as e:
        raise UsageError(f"{DEFAULT_SCENE_NAME}: {e}") from e
    table = stability(
        scene,
        parameters=parameters if parameters is not None else list(STABILITY_PARAMETERS),
        integrators=integrators,
        values_per_parameter=values,
        grid=args.grid,
        bisections=bisections,
        progress=not args.quiet,
    )
    paths = write_stability(table, out, command=shlex.join([PROG, *args.argv]))
    if not args.quiet:
        for path in paths.values():
            print(f"wrote {path}  ({_human_size(path.stat().st_size)})")
    return 0


def _paper(args: argparse.Namespace) -> int:
    from ballcage.paper import run_paper  # deferred: imports matplotlib

    from ballcage.studies.sweep_run import scheduler_client
    from ballcage.studies.sweep_spec import SweepError

    overrides = [_checked_override(o) for o in args.overrides]
    out = _checked_out(args.out)
    if (args.workers or args.scheduler) and not args.sweeps:
        raise UsageError(f"--{'workers' if args.workers else 'scheduler'}: only with --sweeps (it sets where the sweep runs)")
    try:
        with scheduler_client(args.scheduler) as client:
            paths = run_paper(
                out, overrides, sweeps=args.sweeps, progress=False if args.quiet else None, workers=args.workers,
                client=client,
            )
    except _native.SceneError as e:
        raise UsageError(f"{DEFAULT_SCENE_NAME}: {e}") from e
    except SweepError as e:
        raise UsageError(str(e)) from e
    if not args.quiet:
        for name, path in paths.items():
            print(_paper_summary(name, path))
    return 0


def _paper_summary(name: str, path: Path) -> str:
    if path.is_dir():
        return f"wrote {path}/  (the section-4 sweep: summary.parquet, the cases' tables, plots/)"
    if path.suffix == ".parquet":
        import pyarrow.parquet as pq

        meta = pq.ParquetFile(path).metadata
        return f"wrote {path}  ({meta.num_rows} rows x {meta.num_columns} columns, {_human_size(path.stat().st_size)})"
    what = {"scene": "resolved scene", "comparison_md": "comparison and trends", "view": "3D view, `ballcage view`"}.get(
        name, "figure" if path.suffix == ".png" else name
    )
    return f"wrote {path}  ({what}, {_human_size(path.stat().st_size)})"


def _scene_show(args: argparse.Namespace) -> int:
    overrides = [_checked_override(o) for o in args.overrides]
    text = _load_cli_scene(args.scene, overrides).to_toml(units=True)
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


def _write_error(error: OSError) -> str:
    """``cannot write <path>: <reason> (errno N)`` for an `OSError` naming its file; else ``cannot write output: <error>``."""
    if error.filename is None:
        return f"cannot write output: {error}"
    number = f" (errno {error.errno})" if error.errno else ""
    return f"cannot write {os.fsdecode(error.filename)}: {error.strerror or error}{number}"


def _fail(message: str, code: int) -> int:
    first_line = " ".join(message.split()) if message else "failed"
    print(f"{PROG}: error: {first_line}", file=sys.stderr)
    return code


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main(sys.argv[1:]))
