"""Where a drill-pipe run's forces are largest: the tube force along the chain and the key-force peak's place.

- `TubeProfile` (`tube_profile`): each link's mean tube normal force and mean
  inclination over the summary window, the link with the largest mean and the
  inclination span of the links near it, beside the paper's description
  (largest at 58-78 deg of inclination, none at link 12).
- `PeakPlace` (`peak_place`): a peak's hinge, key and time, the drive's stage
  then (acceleration while ``t < drive.ramp``, steady rotation after) and the
  upper connector's angle in its revolution, beside the paper's (joint 1#,
  during acceleration).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ballcage._links import in_summary_window, link_tube_forces
from ballcage.measures.frames import argmax_where, frame_grid
from ballcage.run import Run

__all__ = ["NEAR_LARGEST", "PeakPlace", "TubeProfile", "drive_angle_deg", "peak_place", "tube_profile"]

#: A link is "near the largest" per-link mean tube force at this fraction of it or more (`TubeProfile.near`).
NEAR_LARGEST = 0.9


@dataclass(frozen=True)
class TubeProfile:
    """Each link's mean tube normal force [N] and mean inclination [deg] over the summary window."""

    normal_mean: Mapping[int, float]  # link -> mean links.tube_normal [N]
    inclination: Mapping[int, float]  # link -> mean links.inclination_deg [deg]

    @property
    def largest(self) -> int:
        """The link with the largest mean tube normal force (ties: the lower number)."""
        return max(sorted(self.normal_mean), key=lambda k: self.normal_mean[k])

    def near(self, fraction: float = NEAR_LARGEST) -> list[int]:
        """The links whose mean is at least `fraction` of the largest, ascending."""
        top = self.normal_mean[self.largest]
        return [k for k in sorted(self.normal_mean) if self.normal_mean[k] >= fraction * top]

    def span(self, fraction: float = NEAR_LARGEST) -> tuple[float, float]:
        """Smallest and largest mean inclination [deg] of the links `near` the largest mean."""
        angles = [self.inclination[k] for k in self.near(fraction)]
        return min(angles), max(angles)

    def share(self, link: int) -> float:
        """Link `link`'s mean as a fraction of the largest per-link mean (NaN when the largest is 0)."""
        top = self.normal_mean[self.largest]
        return self.normal_mean[link] / top if top > 0.0 else math.nan


def tube_profile(run: Run) -> TubeProfile | None:
    """The run's `TubeProfile`; ``None`` without a links table or a frame in the summary window."""
    tube = link_tube_forces(run)
    if tube is None or not tube.normal_mean or tube.frames == 0:
        return None
    links = run.tables["links"]
    inside = in_summary_window(run.scene, links.column("t").to_numpy())
    link = links.column("link").to_numpy()
    incl = links.column("inclination_deg").to_numpy()
    inclination = {}
    for k in tube.normal_mean:
        mask = inside & (link == k)
        inclination[k] = float(incl[mask].mean()) if mask.any() else math.nan
    return TubeProfile(dict(tube.normal_mean), inclination)


def drive_angle_deg(run: Run, t: float) -> float:
    """The upper connector's angle in its revolution at `t` [deg, 0-360): ``drive.input_speed`` integrated from 0.

    Trapezoidal over the recorded frames (the drive's prescribed speed); NaN without a drive table.
    """
    drive = run.tables.get("drive")
    if drive is None or drive.num_rows == 0 or not math.isfinite(t):
        return math.nan
    times = drive.column("t").to_numpy()
    speed = drive.column("input_speed").to_numpy()
    order = np.argsort(times)
    times, speed = times[order], speed[order]
    upto = times <= t + 1e-12
    angle = float(np.trapezoid(speed[upto], times[upto])) if upto.sum() > 1 else 0.0
    return math.degrees(angle) % 360.0


@dataclass(frozen=True)
class PeakPlace:
    """Where and when a peak force occurred, and what the drive was doing."""

    value: float  # N
    ids: tuple[int, ...]  # (hinge, key) of the peak's row
    t: float  # s
    ramp: float  # s, drive.ramp: the drive accelerates while t < ramp
    angle_deg: float  # upper connector's angle in its revolution at t [deg], NaN without a drive table
    during_ramp: tuple[float, tuple[int, ...], float]  # the largest while t < ramp: (value, ids, t); NaN when none
    by_hinge: Mapping[int, float]  # hinge -> its largest value over keys and frames [N]

    @property
    def stage(self) -> str:
        """``"acceleration"`` while ``t < drive.ramp``, else ``"steady rotation"``."""
        return "acceleration" if self.t < self.ramp else "steady rotation"


def peak_place(run: Run, column: str, table: str = "keys", ids: tuple[str, ...] = ("hinge", "key")) -> PeakPlace | None:
    """The `PeakPlace` of `column` of `table` (largest over rows and frames); ``None`` without the table or a value."""
    data = run.tables.get(table)
    if data is None or data.num_rows == 0:
        return None
    times = np.unique(data.column("t").to_numpy())
    grid = frame_grid(data, times, list(ids), [column])[column]
    value, where, t = argmax_where(grid, times)
    if not math.isfinite(value):
        return None
    ramp = float(run.scene.value("drive.ramp"))
    early = times < ramp - 1e-12
    during = argmax_where(grid[early], times[early]) if early.any() else (math.nan, (), math.nan)
    per_hinge = np.nanmax(grid.reshape(len(times), grid.shape[1], -1), axis=(0, 2), initial=-np.inf)
    by_hinge = {h: float(v) for h, v in enumerate(per_hinge) if math.isfinite(v)}
    return PeakPlace(value, where, t, ramp, drive_angle_deg(run, t), during, by_hinge)
