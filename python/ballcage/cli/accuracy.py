"""``ballcage accuracy``: the work-precision study (`ballcage.studies.accuracy`, `write_accuracy`)."""

from __future__ import annotations

import argparse
import shlex
from collections.abc import Sequence

from ballcage import _native
from ballcage.cli._common import (
    PROG,
    Commands,
    UsageError,
    add_integrators_option,
    add_out_option,
    add_quiet_option,
    add_set_option,
    checked_out,
    checked_override,
    human_size,
    load_cli_scene,
    names,
    positive,
)

#: Options whose value may be a (wrong) negative number (`ballcage.cli` lets the option's check report it).
NUMBER_OPTIONS = ("--steps", "--reference-dt", "--duration")


def add(commands: Commands) -> None:
    accuracy = commands.add_parser(
        "accuracy",
        help="error against run time of each integrator over a ladder of steps (work-precision)",
        description=(
            "Run a scene with each integrator over a ladder of steps and compare named quantities (drill pipe: "
            "peak key-seat force, mean tube force per joint, final link bends, energy; generic scenes: peak force "
            "per pair, final body states, energy) with a reference: the same scene at a much smaller step with "
            "the most accurate integrator, also run at twice that step (its self-error) and checked by a second "
            "method, ESDIRK3(2) with adaptive steps at rtol 1e-5 (the two agreeing). Writes "
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
    add_out_option(accuracy)
    add_integrators_option(
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
    add_set_option(accuracy, example="--set pipe.joints=4 --set 'pipe.hinge=\"ideal-cv\"'")
    add_quiet_option(accuracy, "no progress lines and no summary")
    accuracy.set_defaults(command=command)


def command(args: argparse.Namespace) -> int:
    from ballcage.studies import accuracy, write_accuracy  # deferred: numpy, matplotlib
    from ballcage.studies.accuracy_run import default_integrators

    known = list(_native.INTEGRATORS)
    reference = names("--reference-integrator", args.reference_integrator, known, "integrator")
    reference_dt = positive("--reference-dt", args.reference_dt, "a positive step in seconds")
    duration = positive("--duration", args.duration)
    overrides = [checked_override(o) for o in args.overrides]
    out = checked_out(args.out)
    scene = load_cli_scene(args.scene, overrides)
    integrators = names("--integrators", args.integrators, known, "integrator") or default_integrators(scene)
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
            print(f"wrote {path}  ({human_size(path.stat().st_size)})")
    return 0


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


def _ladder(option: str, text: str) -> list[float]:
    steps = []
    for item in text.split(","):
        if not item.strip():
            raise UsageError(f"{option} {text!r}: empty step; write e.g. {option} 1e-5,5e-6")
        step = positive(option, item.strip(), "a positive step in seconds")
        assert step is not None
        steps.append(step)
    return steps
