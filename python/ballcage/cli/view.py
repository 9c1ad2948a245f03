"""``ballcage view``: a drill-pipe run's chain turning in 3D, as HTML, GIF or MP4 (`ballcage.view.write_view`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ballcage.cli._common import Commands, UsageError, add_quiet_option, count, human_size, positive

#: Options whose value may be a (wrong) negative number (`ballcage.cli` lets the option's check report it).
NUMBER_OPTIONS = ("--frames", "--fps", "--scale")


def add(commands: Commands) -> None:
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
    view.add_argument(
        "--scale", metavar="S", default="1",
        help="draw the links' offsets from the tube centreline S times their true size, 1 to 50 (default 1), as "
        "finite-element post-processors exaggerate a deformed shape; the tube stays at true scale and the title says so",
    )
    view.add_argument(
        "--wear", action="store_true",
        help="colour the tube wall's worn cells by their Archard wear depth [µm] from RUN_DIR/wear_map.parquet "
        "(written by `ballcage run`; HTML only)",
    )
    add_quiet_option(view, "no summary line")
    view.set_defaults(command=command)


def command(args: argparse.Namespace) -> int:
    from ballcage.view import VIEW_SUFFIXES, write_view  # deferred: numpy, plotly or matplotlib

    frames = count("--frames", args.frames, 1)
    fps = positive("--fps", args.fps, "a positive number of frames per second")
    assert fps is not None
    scale = positive("--scale", args.scale, "a number from 1 to 50")
    assert scale is not None
    if not 1.0 <= scale <= 50.0:
        raise UsageError(f"--scale {args.scale}: must be from 1 to 50 (the links' offsets drawn that many times)")
    if args.wear and args.out.suffix.lower() != ".html":
        raise UsageError(f"--wear: the wear colouring is drawn on the HTML page; write --out {args.out.with_suffix('.html')}")
    if args.out.suffix.lower() not in VIEW_SUFFIXES:
        suffix = repr(args.out.suffix) if args.out.suffix else "no suffix"
        raise UsageError(f"--out {args.out}: {suffix}: the suffix picks the kind; write {', '.join(VIEW_SUFFIXES)}")
    if args.out.is_dir():
        raise UsageError(f"--out {args.out}: is a directory; name the file, e.g. --out {args.out / 'chain.html'}")
    path = write_view(args.run_dir, args.out, frames=frames, fps=fps, scale=scale, wear=args.wear)  # an InputError names the folder: exit 2
    if not args.quiet:
        print(f"wrote {path}  (3D view, {human_size(path.stat().st_size)})")
    return 0
