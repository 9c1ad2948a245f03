"""The chain seen turning in 3D (``ballcage view``): an offline HTML page, or a GIF or MP4 for reports.

`write_view(run_or_directory, "chain.html")` draws a drill-pipe run: its
links as cylinders coloured by their tube normal force [N] (``links.tube_normal``),
the connectors, the ball keys where their poses are recorded, a line on each
body that shows it turning, and the semi-transparent guide tube. The page
embeds plotly.js from the plotly package (nothing is fetched when it opens)
and has play, pause and a time slider; ``.gif`` and ``.mp4`` are rendered by
matplotlib (``.mp4`` needs ffmpeg).

Modules, one job each: `poses` (a run's chain at the chosen frames and the
tube, from the tables and the scene), `meshes` (cylinders, tube, spin marks),
`page` (the HTML), `movie` (GIF and MP4), `export` (`write_view`: the suffix
picks the writer, written atomically).
"""

from ballcage.view.export import DEFAULT_FPS, DEFAULT_FRAMES, VIEW_SUFFIXES, write_view
from ballcage.view.poses import ChainFrames, TubeShape, chain_frames, read_run, tube_shape

__all__ = [
    "DEFAULT_FPS",
    "DEFAULT_FRAMES",
    "VIEW_SUFFIXES",
    "ChainFrames",
    "TubeShape",
    "chain_frames",
    "read_run",
    "tube_shape",
    "write_view",
]
