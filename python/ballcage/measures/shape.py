"""The chain's shape over a window: the most deformed joint (`rank_bends`) and included angles on the bend plane.

- The **most deformed joint** is the hinge whose bend, averaged over a window
  (Table 3's: the upper connector's last revolution), is largest. Hinge k
  (1 to the number of links) joins link k and the next body (link k+1; the
  lower connector after the last link), the paper's joint k; its bend is
  ``180 - links.included_angle_deg`` of link k (``hinges.bend_deg`` of
  hinge k). Neither the largest centre offset (every link centre of the
  buckled chain reaches the clearance) nor the largest bend (the articulation
  limit caps it) separates the links: both are decided by sub-millimetre
  penetrations. The mean bend over a revolution is not capped.
- The **projected included angle** at hinge k is the angle between link k's
  axis and the next body's, both projected on the bend plane (the plane of the
  tube's centreline, world x-z): ``180 - |psi_(k+1) - psi_k|`` with ``psi``
  an axis's angle in that plane from the downward vertical toward +x. An
  out-of-plane fold shows a smaller projected bend than its 3-D one.

Pure functions on arrays (`link_axes`, `in_plane_angle`, `projected_included_angle`,
`rank_mean_bends`) and the runs' side of them (`rank_bends`, `projected_angles`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pyarrow as pa

from ballcage.measures.frames import frame_grid
from ballcage.run import Run

__all__ = [
    "BendRanking",
    "in_plane_angle",
    "link_axes",
    "lower_connector_axes",
    "projected_angles",
    "projected_included_angle",
    "rank_bends",
    "rank_mean_bends",
]

#: Slack [s] on a window's ends when selecting frames.
_SLACK = 1e-9


def link_axes(inclination_deg: np.ndarray, azimuth_deg: np.ndarray) -> np.ndarray:
    """Unit axes ``[..., 3]`` (world frame, z up) from the paper's eq. (4) angles [deg].

    ``links.inclination_deg`` is the angle from the downward vertical and
    ``links.azimuth_deg`` the azimuth about the vertical from the bend
    direction (+x): the axis is ``(sin phi cos theta, sin phi sin theta, -cos phi)``.
    """
    phi, theta = np.radians(np.asarray(inclination_deg, float)), np.radians(np.asarray(azimuth_deg, float))
    return np.stack([np.sin(phi) * np.cos(theta), np.sin(phi) * np.sin(theta), -np.cos(phi)], axis=-1)


def in_plane_angle(axes: np.ndarray) -> np.ndarray:
    """Angle [rad] of each axis ``[..., 3]`` projected on the bend plane (x-z), from the downward vertical to +x."""
    axes = np.asarray(axes, float)
    return np.arctan2(axes[..., 0], -axes[..., 2])


def projected_included_angle(upper: np.ndarray, lower: np.ndarray) -> np.ndarray:
    """Included angle [deg] between two axes ``[..., 3]`` projected on the bend plane; 180 when in line there.

    ``180 - |psi_lower - psi_upper|`` with `in_plane_angle` psi (wrapped to
    [0, 180] deg of bend). NaN where an axis is NaN.
    """
    bend = np.abs(in_plane_angle(lower) - in_plane_angle(upper))
    bend = np.where(bend > math.pi, 2.0 * math.pi - bend, bend)
    return 180.0 - np.degrees(bend)


def _rotate_x(w: np.ndarray, x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    """The body x axis (a link's and a connector's axis) rotated by unit quaternions ``(w, x, y, z)`` ``[n, 3]``."""
    return np.stack([1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + w * z), 2.0 * (x * z - w * y)], axis=-1)


def lower_connector_axes(run: Run, times: np.ndarray) -> np.ndarray:
    """The lower connector's axis at each frame ``[frame, 3]`` from the ``bodies`` table; NaN where not recorded."""
    out = np.full((len(times), 3), np.nan)
    bodies = run.tables.get("bodies")
    if bodies is None or bodies.num_rows == 0 or "part" not in bodies.column_names:
        return out
    part = bodies.column("part").to_pylist()
    rows = np.array([p == "lower" for p in part], dtype=bool)
    if not rows.any():
        return out
    t = bodies.column("t").to_numpy()[rows]
    quat = [bodies.column(f"quat_{c}").to_numpy()[rows] for c in "wxyz"]
    idx = np.searchsorted(times, t)
    ok = (idx < len(times)) & (np.abs(times[np.minimum(idx, len(times) - 1)] - t) <= _SLACK)
    out[idx[ok]] = _rotate_x(*(q[ok] for q in quat))
    return out


def projected_angles(run: Run, times: np.ndarray) -> np.ndarray:
    """Projected included angle at every hinge k = 1…n, ``[frame, k - 1]`` [deg] (`projected_included_angle`).

    Link k's axis from ``links.inclination_deg`` and ``azimuth_deg``, the next
    body's likewise, the lower connector's (after the last link) from the
    ``bodies`` table: NaN at hinge n without it. ``[len(times), 0]`` without a links table.
    """
    links = run.tables.get("links")
    if links is None or links.num_rows == 0:
        return np.zeros((len(times), 0))
    g = frame_grid(links, times, ["link"], ["inclination_deg", "azimuth_deg"])
    axes = link_axes(g["inclination_deg"][:, 1:], g["azimuth_deg"][:, 1:])  # [frame, link - 1, 3]
    below = np.concatenate([axes[:, 1:], lower_connector_axes(run, times)[:, None, :]], axis=1)
    return projected_included_angle(axes, below)


@dataclass(frozen=True)
class BendRanking:
    """Each hinge's mean bend over a window [deg], and which hinge bends most."""

    start: float  # s, first frame in the window
    end: float  # s, last frame in the window
    frames: int
    mean_bend: Mapping[int, float]  # hinge k (1…n) -> mean bend over the window [deg]

    @property
    def order(self) -> list[int]:
        """Hinges by mean bend, largest first (ties: the lower number first; NaN means left out)."""
        finite = [k for k, v in self.mean_bend.items() if math.isfinite(v)]
        return sorted(finite, key=lambda k: (-self.mean_bend[k], k))

    @property
    def winner(self) -> int | None:
        """The most deformed joint: the hinge with the largest mean bend; ``None`` without a finite one."""
        order = self.order
        return order[0] if order else None

    @property
    def runner_up(self) -> int | None:
        order = self.order
        return order[1] if len(order) > 1 else None

    @property
    def margin(self) -> float:
        """Winner's mean bend minus the runner-up's [deg]; NaN with fewer than two hinges."""
        if self.winner is None or self.runner_up is None:
            return math.nan
        return self.mean_bend[self.winner] - self.mean_bend[self.runner_up]


def rank_mean_bends(t: np.ndarray, hinge: np.ndarray, bend_deg: np.ndarray, start: float, end: float) -> BendRanking | None:
    """`BendRanking` of rows ``(t [s], hinge, bend [deg])`` with t in [start, end]; ``None`` when none lies there."""
    t, hinge, bend = np.asarray(t, float), np.asarray(hinge, int), np.asarray(bend_deg, float)
    inside = (t >= start - _SLACK) & (t <= end + _SLACK)
    if not inside.any():
        return None
    means = {}
    for k in np.unique(hinge[inside]):
        values = bend[inside & (hinge == k)]
        values = values[np.isfinite(values)]
        means[int(k)] = float(values.mean()) if len(values) else math.nan
    window = t[inside]
    return BendRanking(float(window.min()), float(window.max()), int(np.unique(window).size), means)


def rank_bends(links: pa.Table, start: float, end: float) -> BendRanking | None:
    """Hinges 1…n ranked by their mean bend over [start, end] s, from a ``links`` table.

    Hinge k's bend is ``180 - links.included_angle_deg`` of link k. ``None``
    when no row lies in the window.
    """
    if links.num_rows == 0:
        return None
    bend = 180.0 - links.column("included_angle_deg").to_numpy()
    return rank_mean_bends(links.column("t").to_numpy(), links.column("link").to_numpy(), bend, start, end)
