"""``ballcage buckling``: the torque above which a drill-pipe chain leaves its arc (`ballcage.buckling`, docs/buckling.md)."""

from __future__ import annotations

import argparse
import math

from ballcage.cli._common import Commands, UsageError, load_cli_scene


def add(commands: Commands) -> None:
    parser = commands.add_parser(
        "buckling",
        help="torque above which a drill-pipe chain leaves the arc of its tube (docs/buckling.md)",
        description=(
            "Print the torque [N·m] above which the chain of a drill-pipe scene (default: the paper's) "
            "leaves the arc of its tube, with every term used (SI). --simulate checks it against quasi-static "
            "runs (drive held, torque ramped) at a fifth of, at, and five times the threshold."
        ),
    )
    parser.add_argument("scene", nargs="?", help="scene TOML file (default: the embedded paper scene)")
    parser.add_argument("--set", metavar="KEY=VALUE", action="append", default=[], dest="overrides",
                        help="override a scene field, e.g. --set 'pipe.hinge=\"ideal-cv\"' --set pipe.joints=3")
    for option, unit, what in (
        ("--friction-moment", "N·m", "static friction moment each hinge opposes to bending"),
        ("--bending-stiffness", "N·m/rad", "bending stiffness of each hinge"),
        ("--hinge-play", "m", "axial play of each hinge, the length a fixed lower end leaves the chain to coil into"),
    ):
        parser.add_argument(option, type=float, default=0.0, metavar=unit, help=f"{what} [{unit}] (default 0)")
    parser.add_argument("--axial-tension", type=float, default=None, metavar="N",
                        help="axial tension along the chain [N] (compression negative; default: the scene's "
                        "load.axial_force with pipe.lower_end = \"axially-free\", else 0)")
    parser.add_argument("--simulate", action="store_true", help="also run the three-torque check (seconds to minutes)")
    parser.set_defaults(command=command)


def command(args: argparse.Namespace) -> int:
    from ballcage.buckling import buckling, simulate_check

    scene = load_cli_scene(args.scene, args.overrides)
    try:
        result = buckling(
            scene,
            friction_moment=args.friction_moment,
            bending_stiffness=args.bending_stiffness,
            axial_tension=args.axial_tension,
            hinge_play=args.hinge_play,
        )
    except ValueError as e:
        raise UsageError(str(e)) from e
    print(result)
    if args.simulate:
        if not 0.0 < result.threshold < math.inf:
            raise UsageError(f"threshold = {result.threshold} N·m: --simulate needs a finite, positive threshold")
        torques = [result.threshold / 5.0, result.threshold, 5.0 * result.threshold]
        print("\ntorque [N·m]  mean bend [deg]  max bend [deg]  wall force [N]  lateral offset [mm]")
        for r in simulate_check(scene, torques):
            print(f"{r.torque:12.4g}  {r.mean_bend_deg:15.3f}  {r.max_bend_deg:14.3f}  {r.wall_force:14.4g}  "
                  f"{1e3 * r.lateral_offset:19.3f}")
    return 0
