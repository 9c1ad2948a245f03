"""``ballcage chart``: the design chart over curvature radius x joint length (`ballcage.studies.design_chart`).

The options are in mm and converted to metres here, once; `design_chart` takes SI.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from ballcage.cli._common import (
    Commands,
    UsageError,
    add_out_option,
    add_quiet_option,
    add_set_option,
    checked_out,
    checked_override,
    positive,
    workers,
)


def add(commands: Commands) -> None:
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
    add_out_option(chart)
    chart.add_argument("--radius-mm", metavar="MM", nargs="+", help="curvature radii R [mm] (default 1000 1500 2000 3000 4000)")
    chart.add_argument("--length-mm", metavar="MM", nargs="+", help="joint lengths L [mm] (default 150 200 300 400 500 1000)")
    chart.add_argument("--tube-id", metavar="MM", help="inner diameter D of the guide tube [mm] (default 116, the paper's)")
    chart.add_argument("--joint-od", metavar="MM", help="outer diameter d of the joint [mm] (default 86, the paper's)")
    chart.add_argument(
        "--hinge", choices=("ball-keys", "ideal-cv"), default="ball-keys",
        help="hinge model (default ball-keys, the paper's; ideal-cv is ~3.5x faster but has no keys and about half "
        "the tube force, docs/studies.md)",
    )
    chart.add_argument("--duration", metavar="S", help="simulated time per cell [s] (default 1.8)")
    chart.add_argument(
        "--window", metavar=("START", "END"), nargs=2, help="summary window of the tube forces [s] (default: the run's second half)"
    )
    chart.add_argument("--fixed-mass", action="store_true", help="keep the base link's mass and inertia at every length")
    chart.add_argument(
        "--no-verify", dest="verify", action="store_false",
        help="skip the verification runs: by default each feasible cell runs again at ballcage run --verify's tighter "
        "setting (rtol/10), and the chart gives each quantity's numerical error in that cell (about 3x the time)",
    )
    chart.add_argument("--workers", metavar="N", type=workers, help="local threads running cells (default: one per CPU)")
    chart.add_argument("--scheduler", metavar="ADDRESS", help="run on the Dask cluster at ADDRESS; needs ballcage[dask]")
    add_set_option(chart, example="--set drive.speed_rpm=60 --set pipe.joints=8")
    add_quiet_option(chart, "no estimate, progress or summary lines")
    chart.set_defaults(command=command)


def command(args: argparse.Namespace) -> int:
    """Checks and converts the options, runs the chart; 0 when every feasible cell finished, 1 when some did not."""
    from ballcage.studies.sweep_spec import SweepError  # deferred: pyarrow, numpy, matplotlib

    inputs = _inputs(args)
    args.overrides = [checked_override(o) for o in args.overrides]
    checked_out(args.out)
    try:
        return _chart(args, inputs)
    except SweepError as e:
        raise UsageError(str(e)) from e


def _inputs(args: argparse.Namespace) -> dict[str, Any]:
    """The options `design_chart` takes as keywords, lengths converted from mm to m."""
    from ballcage import sizing
    from ballcage.studies.design_chart import DEFAULT_DURATION

    def metres(option: str, text: str | None) -> float | None:
        value = positive(option, text, "a positive length in mm")
        return None if value is None else value / 1e3

    inputs: dict[str, Any] = {"hinge": args.hinge, "scale_mass": not args.fixed_mass, "verify": args.verify}
    for option, key, texts in (("--radius-mm", "radii", args.radius_mm), ("--length-mm", "lengths", args.length_mm)):
        if texts is not None:
            inputs[key] = [metres(option, t) for t in texts]
    tube, joint = metres("--tube-id", args.tube_id), metres("--joint-od", args.joint_od)
    bore = tube or sizing.PAPER_TUBE_INNER_DIAMETER
    if joint is not None and joint >= bore:
        raise UsageError(f"--joint-od {args.joint_od}: not narrower than the tube, --tube-id {1e3 * bore:g}")
    inputs.update(tube_inner_diameter=tube, joint_diameter=joint)
    inputs["duration"] = positive("--duration", args.duration) or DEFAULT_DURATION
    if args.window is not None:
        try:
            inputs["window"] = (float(args.window[0]), float(args.window[1]))
        except ValueError:
            raise UsageError(f"--window {' '.join(args.window)}: give START END in seconds, e.g. --window 0.9 1.8") from None
    return inputs


def _chart(args: argparse.Namespace, inputs: dict[str, Any]) -> int:
    """Prints the estimate before and the files after (`describe`); 1 when a feasible cell did not finish."""
    from ballcage.studies.design_chart import describe, design_chart
    from ballcage.studies.design_chart_grid import LENGTH, RADIUS
    from ballcage.studies.sweep_run import scheduler_client

    try:
        with scheduler_client(args.scheduler) as client:
            chart = design_chart(
                args.out, **inputs, overrides=args.overrides, workers=args.workers, client=client,
                progress=False if args.quiet else None,
            )
    except KeyboardInterrupt:
        print(f"ballcage: chart interrupted; run the same command again to resume from {args.out}", file=sys.stderr)
        raise
    if not args.quiet:
        for line in describe(chart):
            print(line)
    if chart.failed:
        bad = [r for r in chart.table.to_pylist() if r["feasible"] and r["status"] != "ok"]
        where = f"R = {bad[0][RADIUS]:g} m, L = {bad[0][LENGTH]:g} m: {bad[0]['status']}" if bad else "see summary.parquet"
        print(f"ballcage: error: {chart.failed} feasible cells did not finish (first {where}); "
              f"see {chart.out / 'summary.parquet'}", file=sys.stderr)
        return 1
    return 0
