"""Table 3's motion of a link, as the paper defines it: the most deformed joint and its range of motion.

Pure helpers on numpy data (`most_frequent`, `peak_to_peak`, `largest_offset`)
and the runs' side of them (`last_revolution`, `centre_paths`).
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ballcage._native import InputError
from ballcage.paper.facts import SceneFacts
from ballcage.paper.frames import frame_grid, frame_times
from ballcage.run import Run

__all__ = [
    "CentrePaths",
    "MostFrequent",
    "centre_paths",
    "largest_offset",
    "last_revolution",
    "most_frequent",
    "peak_to_peak",
]


@dataclass(frozen=True)
class MostFrequent:
    """The most frequent link of the phases, and whether a tie had to be broken."""

    link: int
    count: int  # phases at which `link` is the most deformed
    tied: tuple[int, ...]  # every link with `count` phases, ascending (one link: no tie)

    @property
    def tie(self) -> bool:
        return len(self.tied) > 1


def most_frequent(links: Sequence[int], deformation: Sequence[float]) -> MostFrequent:
    """The link most often the most deformed over the phases (never a mean of link numbers).

    `links[i]` is the most deformed link at phase i and `deformation[i]` its
    deformation there (any unit, e.g. the centre offset [m]). A tie between
    links of equal count goes to the one with the largest deformation at any
    of its phases (then to the lower link number). `ValueError` on no phases.
    """
    if len(links) == 0 or len(links) != len(deformation):
        raise InputError(f"need one deformation per phase, got {len(links)} links and {len(deformation)} values")
    counts = Counter(int(k) for k in links)
    top = max(counts.values())
    tied = tuple(sorted(k for k, c in counts.items() if c == top))
    largest = {k: max(float(d) for kk, d in zip(links, deformation, strict=True) if int(kk) == k) for k in tied}
    link = max(tied, key=lambda k: (largest[k], -k))
    return MostFrequent(link, top, tied)


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
