"""Per-link link–tube contact forces of a drill-pipe run over its summary window, from the ``links`` table.

The window is the scene's ``record.summary_window`` (the whole run when it is
not set) with the summary table's semantics: the frames with
``window_start - 1e-12 <= t <= window_end + 1e-12``; a frame without contact
counts as 0 N, which ``links.tube_normal`` already is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ballcage import _native
from ballcage.run import Run

__all__ = ["LinkTubeForces", "in_summary_window", "link_tube_forces", "summary_window"]

#: Slack [s] on the window's ends, as the engine's summary table applies it.
WINDOW_SLACK = 1e-12


@dataclass(frozen=True)
class LinkTubeForces:
    """Each link's contact with the guide tube over the summary window, by link number (1 at the top)."""

    start: float  # first time of the window [s]
    end: float  # last time of the window, at most the last frame [s]
    frames: int  # frames in the window
    normal_mean: dict[int, float]  # mean of links.tube_normal [N]
    normal_peak: dict[int, float]  # largest links.tube_normal [N]
    tangential_mean: dict[int, float]  # mean of links.tube_tangential [N]


def summary_window(scene: _native.Scene) -> tuple[float, float]:
    """The scene's ``record.summary_window`` (start, end) [s]; (0, inf) when it is not set (the whole run)."""
    window = scene.value("record.summary_window")
    if isinstance(window, list) and len(window) == 2:
        return float(window[0]), float(window[1])
    return 0.0, math.inf


def in_summary_window(scene: _native.Scene, t: np.ndarray) -> np.ndarray:
    """Which of the times `t` [s] lie in the scene's summary window (`summary_window`, with `WINDOW_SLACK`)."""
    start, end = summary_window(scene)
    return (t >= start - WINDOW_SLACK) & (t <= end + WINDOW_SLACK)


def link_tube_forces(run: Run) -> LinkTubeForces | None:
    """Mean and peak link–tube forces [N] per link over the summary window; ``None`` without a ``links`` table."""
    links = run.tables.get("links")
    if links is None or links.num_rows == 0:
        return None
    start, end = summary_window(run.scene)
    t = links.column("t").to_numpy()
    inside = in_summary_window(run.scene, t)
    link = links.column("link").to_numpy()
    normal = links.column("tube_normal").to_numpy()
    tangential = links.column("tube_tangential").to_numpy()
    normal_mean: dict[int, float] = {}
    normal_peak: dict[int, float] = {}
    tangential_mean: dict[int, float] = {}
    for k in sorted(int(k) for k in np.unique(link)):
        mask = inside & (link == k)
        found = bool(mask.any())
        normal_mean[k] = float(normal[mask].mean()) if found else 0.0
        normal_peak[k] = float(normal[mask].max()) if found else 0.0
        tangential_mean[k] = float(tangential[mask].mean()) if found else 0.0
    frames = int(np.unique(t[inside]).size)
    return LinkTubeForces(start, min(end, float(t.max())), frames, normal_mean, normal_peak, tangential_mean)
