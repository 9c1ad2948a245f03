"""``ballcage sensitivity``: how much each unstated parameter moves each quantity (`ballcage.studies.sensitivity_run`)."""

from __future__ import annotations

import argparse
import math
import shlex
import sys
from typing import Any

from ballcage.cli._common import (
    PROG,
    Commands,
    UsageError,
    add_case_timeout_option,
    add_out_option,
    add_quiet_option,
    add_set_option,
    case_timeout,
    checked_out,
    checked_override,
    count,
    load_cli_scene,
    positive,
    workers,
)

#: Options whose value may be a (wrong) negative number (`ballcage.cli` lets the option's check report it).
NUMBER_OPTIONS = ("--duration", "--trajectories", "--levels", "--seed", "--case-timeout")


def add(commands: Commands) -> None:
    sensitivity = commands.add_parser(
        "sensitivity",
        help="how much each unstated (PROPOSAL) parameter moves each headline quantity: table, ranking, tornado charts",
        description=(
            "Vary the scene's unstated parameters (default: every parameter of the registry, ballcage.proposals(), "
            "of the scene's kind) over their ranges, one at a time (oat: the base run and each parameter at its low "
            "and its high value) or by Morris elementary effects (morris, SALib: pip install 'ballcage[sensitivity]'), "
            "as one sweep (local threads or a Dask cluster; running it again resumes). Measures the headline "
            "quantities of each run (a drill pipe's comparison quantities, its efficiency and smallest "
            "contact-pressure margin; a scene of bodies' contact summary statistics and depths), and the base run's "
            "numerical error against the base run at ballcage run --verify's tighter setting. Writes DIR/sensitivity.parquet, "
            "DIR/sensitivity.md (the parameters ranked for each quantity), DIR/plots/tornado_<quantity>.png and "
            "the runs in DIR/runs. Exit code 1 when a run did not finish (docs/studies.md)."
        ),
    )
    sensitivity.add_argument("scene", nargs="?", metavar="SCENE.toml", help="scene file (default: the paper's scene)")
    add_out_option(sensitivity)
    sensitivity.add_argument(
        "--parameters", metavar="KEY[=LOW:HIGH],...",
        help="the parameters to vary: registry keys (their ranges from the registry) and/or any numeric scene key "
        "with a range in the scene's units, e.g. pipe.neck_radius,pipe.ball_keys.groove_radius=0.02:0.03 "
        "(default: every registry parameter of the scene's kind)",
    )  # fmt: skip
    sensitivity.add_argument("--method", choices=("oat", "morris"), default="oat",
                             help="oat: one at a time at each end of the range (default); morris: Morris elementary "
                             "effects over the ranges (SALib), with interactions")  # fmt: skip
    sensitivity.add_argument("--trajectories", metavar="N", help="with --method morris: trajectories (default 10, at "
                             "least 2); the runs are N x (parameters + 1)")  # fmt: skip
    sensitivity.add_argument("--levels", metavar="L", help="with --method morris: levels of the grid (default 4, even)")
    sensitivity.add_argument("--seed", metavar="N", help="with --method morris: seed of SALib's design (default 1; "
                             "another seed designs other runs, so use another --out)")  # fmt: skip
    sensitivity.add_argument("--duration", metavar="S", help="simulated time of each run [s] (default: the scene's)")
    sensitivity.add_argument("--no-verify", action="store_true", help="no verification run of the base (the numerical "
                             "error then only from the integrator's estimate, for lengths)")  # fmt: skip
    where = sensitivity.add_mutually_exclusive_group()
    where.add_argument("--workers", metavar="N", type=workers, help="local threads running the runs (default: one per CPU)")
    where.add_argument("--scheduler", metavar="ADDRESS", help="run on the Dask cluster at ADDRESS; needs ballcage[dask]")
    add_case_timeout_option(sensitivity, "default: 10x the estimated time of the longest run, at least 60 s; none "
                            "without an estimate, as for a scene of bodies before its base run")  # fmt: skip
    sensitivity.add_argument("--no-plots", action="store_true", help="do not draw DIR/plots/tornado_*.png")
    add_set_option(sensitivity, example="--set 'pipe.hinge=\"ideal-cv\"' --set pipe.joints=8")
    add_quiet_option(sensitivity, "no estimate, progress or summary lines")
    sensitivity.set_defaults(command=command)


def command(args: argparse.Namespace) -> int:
    """Checks the options, runs the study; 0 when every run finished, 1 when some did not."""
    from ballcage.studies.sweep_spec import SweepError  # deferred: pyarrow, numpy, matplotlib

    options: dict[str, Any] = dict(_morris_options(args))
    parameters = _parameters(args.parameters)
    overrides = [checked_override(o) for o in args.overrides]
    duration = positive("--duration", args.duration)
    limit = case_timeout(args.case_timeout)
    options["case_timeout"] = "auto" if limit is None else limit
    checked_out(args.out)
    load_cli_scene(args.scene, overrides)  # a missing or invalid scene file: one line, exit code 2
    try:
        return _run(args, parameters, overrides, duration, options)
    except SweepError as e:
        raise UsageError(str(e)) from e


def _morris_options(args: argparse.Namespace) -> dict[str, int]:
    given = {o: v for o, v in (("--trajectories", args.trajectories), ("--levels", args.levels), ("--seed", args.seed))
             if v is not None}  # fmt: skip
    if args.method != "morris":
        if given:
            raise UsageError(f"{next(iter(given))} {next(iter(given.values()))}: only with --method morris")
        return {}
    out = {}
    if args.trajectories is not None:
        out["trajectories"] = count("--trajectories", args.trajectories, 2)
    if args.levels is not None:
        levels = count("--levels", args.levels, 2)
        if levels % 2:
            raise UsageError(f"--levels {levels}: must be even (SALib's Morris design jumps half the grid)")
        out["levels"] = levels
    if args.seed is not None:
        out["seed"] = count("--seed", args.seed, 0)
    return out


def _parameters(text: str | None) -> list[str] | dict[str, tuple[float, float] | None] | None:
    """``--parameters``: registry keys and ``KEY=LOW:HIGH`` ranges; a list of keys when no range is given."""
    if text is None:
        return None
    entries = [e.strip() for e in text.split(",") if e.strip()]
    if not entries:
        raise UsageError(f"--parameters {text!r}: name at least one parameter")
    out: dict[str, tuple[float, float] | None] = {}
    for entry in entries:
        key, sep, span = entry.partition("=")
        key = key.strip()
        if not key:
            raise UsageError(f"--parameters {entry!r}: no key before '='")
        if key in out:
            raise UsageError(f"--parameters {key}: named twice")
        out[key] = _span(entry, span) if sep else None
    return out if any(v is not None for v in out.values()) else list(out)


def _span(entry: str, text: str) -> tuple[float, float]:
    low_text, sep, high_text = text.partition(":")
    if not sep:
        raise UsageError(f"--parameters {entry}: give the range as KEY=LOW:HIGH, e.g. pipe.neck_radius=0.017:0.021")
    try:
        low, high = float(low_text), float(high_text)
    except ValueError:
        raise UsageError(f"--parameters {entry}: LOW and HIGH must be numbers (in the scene's units)") from None
    if not (math.isfinite(low) and math.isfinite(high)):
        raise UsageError(f"--parameters {entry}: LOW and HIGH must be finite")
    if not low < high:
        raise UsageError(f"--parameters {entry}: LOW {low:g} must be below HIGH {high:g}")
    return low, high


def _run(
    args: argparse.Namespace,
    parameters: Any,
    overrides: list[str],
    duration: float | None,
    options: dict[str, Any],
) -> int:
    from ballcage.studies.sensitivity_run import describe, sensitivity
    from ballcage.studies.sweep_run import scheduler_client

    try:
        with scheduler_client(args.scheduler) as client:
            result = sensitivity(
                args.scene, args.out, parameters=parameters, method=args.method, **options, overrides=overrides,
                duration=duration, verify=not args.no_verify, workers=args.workers, client=client,
                plots=not args.no_plots, progress=False if args.quiet else None,
                command=shlex.join([PROG, *args.argv]),
            )  # fmt: skip
    except KeyboardInterrupt:
        print(f"ballcage: sensitivity interrupted; run the same command again to resume from {args.out}",
              file=sys.stderr)  # fmt: skip
        raise
    if not args.quiet:
        for line in describe(result):
            print(line)
    if result.failed:
        bad = [r for r in result.sweep.summary.to_pylist() if r["status"] != "ok"]
        first = bad[0]
        print(
            f"ballcage: error: {result.failed} of {result.sweep.summary.num_rows} runs did not finish "
            f"(case {first['case_id']} {first['status']}: {' '.join(str(first['error']).split())}); "
            f"see {result.sweep.paths['summary']}",
            file=sys.stderr,
        )
        return 1
    return 0
