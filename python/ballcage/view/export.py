"""`write_view`: a run's chain seen turning in 3D, as an HTML page, a GIF or an MP4, picked by the file's suffix."""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import TYPE_CHECKING

from ballcage._files import write_atomically
from ballcage._native import InputError
from ballcage.run import Run
from ballcage.view.poses import chain_frames, read_run
from ballcage.view.scale import scaled
from ballcage.view.wear import WEAR_MAP_FILE, WallWear, read_wear_map

if TYPE_CHECKING:
    import pyarrow as pa

__all__ = ["DEFAULT_FPS", "DEFAULT_FRAMES", "VIEW_SUFFIXES", "write_view"]

#: Output kinds by file suffix.
VIEW_SUFFIXES: tuple[str, ...] = (".html", ".gif", ".mp4")
#: Frames drawn at most (evenly spaced over the run), and the animation's frame rate [1/s].
DEFAULT_FRAMES = 120
DEFAULT_FPS = 12.0


def write_view(
    run: Run | str | os.PathLike[str],
    out: str | os.PathLike[str],
    *,
    frames: int = DEFAULT_FRAMES,
    fps: float = DEFAULT_FPS,
    scale: float = 1.0,
    wear: pa.Table | bool = False,
) -> Path:
    """Writes the animated 3D view of a drill-pipe run's chain in its tube to `out`; returns its path.

    `run` is a `Run` or a run directory (``ballcage run --out DIR``,
    `Run.write`). The suffix of `out` picks the kind: ``.html`` a self-contained
    page (plotly.js embedded: it opens offline) with play, pause and a time
    slider; ``.gif`` (Pillow) or ``.mp4`` (ffmpeg) for reports. At most
    `frames` frames are drawn, evenly spaced over the run, played at `fps`
    frames per second. Links are coloured by their tube normal force
    (``links.tube_normal`` [N]); keys are drawn where their poses are recorded.
    The file is written atomically; its folder is created.

    `scale` (1 to 50) draws the bodies' offsets from the tube centreline that
    many times their true size (`ballcage.view.scale`), as finite-element
    post-processors exaggerate a deformed shape; the page's title states it.
    `wear` colours the tube wall's worn cells by their Archard depth on the
    HTML page: a wear map (`ballcage.measures.wear_map.wear_map`), or ``True``
    for the run directory's ``wear_map.parquet``.

    Raises `InputError` naming the argument for an unknown suffix, a bad
    `frames` or `fps`, a directory that is not a run, or a run without link poses.
    """
    path = Path(out)
    suffix = path.suffix.lower()
    if suffix not in VIEW_SUFFIXES:
        raise InputError(f"out = {str(path)!r}: unknown suffix {path.suffix or '(none)'!r}; write .html, .gif or .mp4")
    if not isinstance(fps, (int, float)) or not (math.isfinite(fps) and fps > 0):
        raise InputError(f"fps = {fps!r}: must be a positive number of frames per second")
    if not isinstance(frames, int) or frames < 1:
        raise InputError(f"frames = {frames!r}: must be a whole number of at least 1")
    wall = _wall(run, wear)
    if isinstance(run, Run):
        chain = chain_frames(run, frames)
    else:
        try:
            chain = chain_frames(read_run(run), frames)
        except InputError as e:
            where = f"run directory {Path(run)}"
            raise (e if str(e).startswith(where) else InputError(f"{where}: {e}")) from e
    if len(chain.times) == 0:
        raise InputError("the run has no frame in which every link's pose is recorded")
    chain = scaled(chain, scale)
    path.parent.mkdir(parents=True, exist_ok=True)
    if suffix == ".html":
        from ballcage.view.page import view_html

        text = view_html(chain, fps, wall)
        write_atomically(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    else:
        from ballcage.view import movie

        if suffix == ".mp4" and not movie.ffmpeg_available():
            raise InputError(
                f"out = {str(path)!r}: writing .mp4 needs ffmpeg (Debian: apt-get install ffmpeg); write .gif or .html instead"
            )
        writer = movie.write_gif if suffix == ".gif" else movie.write_mp4
        write_atomically(path, lambda tmp: writer(chain, tmp, fps))
    return path


def _wall(run: Run | str | os.PathLike[str], wear: pa.Table | bool) -> WallWear | None:
    """The tube wall's wear to colour it by: from `wear` (a wear map), or the run directory's map for ``True``."""
    if wear is False:
        return None
    if wear is True:
        if isinstance(run, Run):
            raise InputError("wear = True needs a run directory holding wear_map.parquet; pass the wear map itself")
        table = read_wear_map(run)
        if table is None:
            raise InputError(
                f"run directory {Path(run)}: no {WEAR_MAP_FILE} (`ballcage run` writes it for a drill-pipe run that "
                "records bodies, contacts and wear)"
            )
        return WallWear(table)
    return WallWear(wear)
