"""``ballcage size``: joint sizing by the paper's eq. (9), lengths in mm (`ballcage.sizing`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ballcage import _native
from ballcage.cli._common import Commands, UsageError, human_size, positive

#: The options, all lengths in mm; each may be a (wrong) negative number (`ballcage.cli` lets the check report it).
NUMBER_OPTIONS = ("--radius", "--tube-id", "--joint-od", "--length")


def add(commands: Commands) -> None:
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
    size.set_defaults(command=command)


def command(args: argparse.Namespace) -> int:
    from ballcage import sizing  # deferred with the rest of the subcommands' modules

    mm = {o: positive(o, getattr(args, o[2:].replace("-", "_")), "a positive length in mm") for o in NUMBER_OPTIONS}
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
        length = 1e3 * sizing.longest_link(radius / 1e3, tube / 1e3, joint / 1e3)
        print(f"{length:.2f}")
    elif joint is not None and length is not None:
        radius = 1e3 * sizing.tightest_radius_for_link(length / 1e3, tube / 1e3, joint / 1e3)
        print(f"{radius:.2f}")
    elif radius is not None and length is not None:
        most = 1e3 * _native.longest_link(radius / 1e3, tube / 1e3, 0.0)
        if length >= most:
            raise UsageError(
                f"--length {args.length}: no joint that long fits a {tube:g} mm bore bent to R = {radius:g} mm "
                f"(eq. (9): under {most:.2f} mm, the length of a joint of no diameter)"
            )
        joint = 1e3 * sizing.largest_link_diameter(length / 1e3, radius / 1e3, tube / 1e3)
        print(f"{joint:.2f}")
    if args.plot is not None:
        mark = (radius / 1e3, joint / 1e3, length / 1e3) if radius and joint and length else None
        path = sizing.plot_joint_lengths(args.plot, tube / 1e3, mark=mark)
        print(f"wrote {path}  (figure, {human_size(path.stat().st_size)})")
    return 0
