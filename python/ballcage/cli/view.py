"""``ballcage view``: a drill-pipe run's chain turning in 3D, as HTML, GIF or MP4 (`ballcage.view.write_view`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ballcage.cli._common import Commands, UsageError, add_quiet_option, count, human_size, positive

#: Options whose value may be a (wrong) negative number (`ballcage.cli` lets the option's check report it).
NUMBER_OPTIONS = ("--frames", "--fps")


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
    add_quiet_option(view, "no summary line")
    view.set_defaults(command=command)


def command(args: argparse.Namespace) -> int:
    from ballcage.view import VIEW_SUFFIXES, write_view  # deferred: numpy, plotly or matplotlib

    frames = count("--frames", args.frames, 1)
    fps = positive("--fps", args.fps, "a positive number of frames per second")
    assert fps is not None
    if args.out.suffix.lower() not in VIEW_SUFFIXES:
        suffix = repr(args.out.suffix) if args.out.suffix else "no suffix"
        raise UsageError(f"--out {args.out}: {suffix}: the suffix picks the kind; write {', '.join(VIEW_SUFFIXES)}")
    if args.out.is_dir():
        raise UsageError(f"--out {args.out}: is a directory; name the file, e.g. --out {args.out / 'chain.html'}")
    path = write_view(args.run_dir, args.out, frames=frames, fps=fps)  # an InputError names the folder: exit 2
    if not args.quiet:
        print(f"wrote {path}  (3D view, {human_size(path.stat().st_size)})")
    return 0
