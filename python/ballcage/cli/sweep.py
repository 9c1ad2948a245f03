"""``ballcage sweep``: every case of a sweep file, in parallel (`ballcage.studies.sweep_run.sweep`, docs/studies.md)."""

from __future__ import annotations

import argparse
import sys

from ballcage.cli._common import (
    Commands,
    UsageError,
    add_case_timeout_option,
    add_out_option,
    add_quiet_option,
    case_timeout,
    workers,
)

#: Options whose value may be a (wrong) negative number (`ballcage.cli` lets the option's check report it).
NUMBER_OPTIONS = ("--case-timeout",)


def add(commands: Commands) -> None:
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
    add_out_option(sweep)
    sweep.add_argument("--workers", metavar="N", type=workers, help="local threads running cases (default: one per CPU)")
    sweep.add_argument(
        "--scheduler", metavar="ADDRESS", help="run on the Dask cluster at ADDRESS (tcp://host:8786); needs ballcage[dask]"
    )
    sweep.add_argument("--retry-failed", action="store_true", help="also run again the cases that diverged or failed")
    add_case_timeout_option(sweep, "default: none, a sweep having no estimate of its cases' time")
    sweep.add_argument("--no-plots", action="store_true", help="do not draw DIR/plots/*.png")
    sweep.add_argument(
        "--verify", action="store_true",
        help="run every case again at ballcage run --verify's tighter setting (rtol/10 for adaptive steps, dt/d for "
        "fixed ones), after all of them, and give each quantity's numerical error per case in summary.parquet "
        "(<quantity>_error; about 3x the time)",
    )
    add_quiet_option(sweep, "no progress and no summary lines")
    sweep.set_defaults(command=command)


def command(args: argparse.Namespace) -> int:
    """Runs the sweep, prints what it wrote; 0 when every case is ok, 1 when some are not, 2 for a bad sweep file."""
    from ballcage.studies.sweep_spec import SweepError  # deferred: pyarrow, numpy, matplotlib

    limit = case_timeout(args.case_timeout)
    try:
        return _sweep(args, limit)
    except SweepError as e:
        raise UsageError(str(e)) from e


def _sweep(args: argparse.Namespace, limit: float | None) -> int:
    from ballcage.studies.sweep_run import describe, scheduler_client, sweep
    from ballcage.studies.sweep_spec import with_verification

    source = with_verification(args.sweep) if args.verify else args.sweep
    try:
        with scheduler_client(args.scheduler) as client:
            result = sweep(
                source,
                args.out,
                client=client,
                workers=args.workers,
                retry_failed=args.retry_failed,
                plots=not args.no_plots,
                progress=False if args.quiet else None,
                case_timeout=limit,
            )
    except KeyboardInterrupt:
        print(f"ballcage: sweep interrupted; run the same command again to resume from {args.out}", file=sys.stderr)
        raise
    if not args.quiet:
        for line in describe(result):
            print(line)
    if result.failed:
        bad = [r for r in result.summary.to_pylist() if r["status"] != "ok"]
        first = bad[0]
        print(
            f"ballcage: error: {result.failed} of {result.summary.num_rows} cases did not finish "
            f"(case {first['case_id']} {first['status']}: {' '.join(str(first['error']).split())}); "
            f"see {result.paths['summary']}",
            file=sys.stderr,
        )
        return 1
    return 0
