"""Table 3's range of motion of a link: its centre's path in the tube cross-section over the last revolution.

Pure helpers on numpy data (`peak_to_peak`, `largest_offset`) and the runs'
side of them (`last_revolution`, `centre_paths`). The most deformed joint,
whose range of motion Table 3 gives, is chosen in `ballcage.measures.shape`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ballcage.measures.phases import SceneFacts
from ballcage.measures.frames import frame_grid, frame_times
from ballcage.run import Run

__all__ = [
    "CentrePaths",
    "centre_paths",
    "largest_offset",
    "last_revolution",
    "peak_to_peak",
]


def _hull(points: np.ndarray) -> np.ndarray:
    """The convex hull's vertices of 2-D `points` ``[n, 2]`` (Andrew's monotone chain)."""
    pts = np.unique(points, axis=0)
    if len(pts) <= 2:
        return pts

    def half(seq: np.ndarray) -> list[np.ndarray]:
        chain: list[np.ndarray] = []
        for p in seq:
            while len(chain) >= 2:
                a, b = chain[-2], chain[-1]
                if (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) > 0.0:
                    break
                chain.pop()
            chain.append(p)
        return chain

    lower, upper = half(pts), half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


def peak_to_peak(outward: np.ndarray, lateral: np.ndarray) -> float:
    """Peak-to-peak excursion of a centre's path in the tube cross-section [same unit as the inputs].

    The largest distance between two positions ``(outward[i], lateral[i])``
    of the path (its diameter); NaN positions are skipped, NaN when none is
    left. A centre on a circle of radius r gives 2 r.
    """
    points = np.column_stack([np.asarray(outward, float), np.asarray(lateral, float)])
    points = points[np.isfinite(points).all(axis=1)]
    if len(points) == 0:
        return math.nan
    hull = _hull(points)
    diff = hull[:, None, :] - hull[None, :, :]
    return float(np.sqrt((diff**2).sum(axis=-1)).max())


def largest_offset(outward: np.ndarray, lateral: np.ndarray) -> float:
    """Largest distance of a centre from the tube centreline, ``max hypot(outward, lateral)`` [input unit]."""
    r = np.hypot(np.asarray(outward, float), np.asarray(lateral, float))
    return float(np.nanmax(r)) if np.isfinite(r).any() else math.nan


def last_revolution(facts: SceneFacts) -> tuple[float, float]:
    """The upper connector's last revolution, ``(duration - 60/rpm, duration)`` [s]."""
    period = 60.0 / facts.rpm if facts.rpm > 0 else math.inf
    return facts.duration - period, facts.duration


@dataclass(frozen=True)
class CentrePaths:
    """Every link's centre path in the tube cross-section over a time window."""

    start: float  # s, first frame in the window
    end: float  # s, last frame in the window
    frames: int
    outward: np.ndarray  # m, [frame, link - 1]: links.offset_outward
    lateral: np.ndarray  # m, [frame, link - 1]: links.offset_lateral

    def peak_to_peak(self, link: int) -> float:
        """Peak-to-peak excursion of link `link`'s centre over the window [m]."""
        return peak_to_peak(self.outward[:, link - 1], self.lateral[:, link - 1])

    def largest_offset(self, link: int) -> float:
        """Largest centre offset of link `link` over the window [m]."""
        return largest_offset(self.outward[:, link - 1], self.lateral[:, link - 1])

    @property
    def links(self) -> range:
        return range(1, self.outward.shape[1] + 1)


def centre_paths(run: Run, start: float, end: float) -> CentrePaths | None:
    """The links' centre paths (``links.offset_outward``, ``offset_lateral``) over frames in [start, end] s.

    None when the run has no links table or no frame in the window.
    """
    links = run.tables.get("links")
    times = frame_times(run)
    if links is None or links.num_rows == 0 or len(times) == 0:
        return None
    tol = 1e-9
    inside = (times >= start - tol) & (times <= end + tol)
    if not inside.any():
        return None
    g = frame_grid(links, times, ["link"], ["offset_outward", "offset_lateral"])
    t = times[inside]
    return CentrePaths(
        float(t[0]), float(t[-1]), int(inside.sum()), g["offset_outward"][inside, 1:], g["offset_lateral"][inside, 1:]
    )
