"""What the analysis needs from a run's drill-pipe scene, and Table 3's phases of the last revolution."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ballcage._native import InputError
from ballcage.measures.frames import frame_grid, frame_times
from ballcage.run import Run

__all__ = ["PHASES", "Phase", "SceneFacts", "phases", "scene_facts"]

#: Phase labels of Table 3 (upper connector angle in the last revolution).
PHASES: tuple[str, ...] = ("0°", "90°", "180°", "270°")


@dataclass(frozen=True)
class SceneFacts:
    """What the analysis needs from a run's drill-pipe scene."""

    duration: float  # s
    output_interval: float  # s
    rpm: float  # drive speed [rpm]
    curvature_radius: float  # m
    tube_inner_radius: float  # m
    link_radius: float  # m

    @property
    def clearance(self) -> float:
        """Radial play of a link's centre in the tube [m]."""
        return self.tube_inner_radius - self.link_radius

    def phase_times(self) -> list[tuple[str, float]]:
        """Table 3's phases: 0°, 90°, 180°, 270° of the last revolution, ending at the duration [s]."""
        quarter = 15.0 / self.rpm if self.rpm > 0 else math.inf
        return [(label, self.duration - (3 - i) * quarter) for i, label in enumerate(PHASES)]


def scene_facts(run: Run) -> SceneFacts:
    """Asks the run's scene for what the analysis needs; `ValueError` unless it is a drill pipe."""
    scene = run.scene
    if scene.kind != "drill-pipe":
        raise InputError(f"scene kind = {scene.kind!r}: the paper analysis needs a drill-pipe scene")
    return SceneFacts(
        duration=scene.duration,
        output_interval=scene.output_interval,
        rpm=float(scene.value("drive.speed_rpm")),
        curvature_radius=float(scene.value("borehole.curvature_radius")),
        tube_inner_radius=float(scene.value("borehole.inner_diameter")) / 2.0,
        link_radius=float(scene.value("pipe.link_diameter")) / 2.0,
    )


@dataclass(frozen=True)
class Phase:
    """One of Table 3's phases found in a run, and the link whose centre is furthest out there.

    The most deformed joint is not chosen per phase (the furthest centre is an
    argmax over links that all sit near the clearance) but over the last
    revolution: `ballcage.measures.shape.rank_bends`.
    """

    label: str
    t: float
    frame: int
    furthest: int  # link whose centre is furthest from the tube centreline (largest links.radial_offset)
    furthest_offset_mm: float  # its centre offset [mm]


def phases(run: Run, facts: SceneFacts) -> tuple[list[Phase], list[str]]:
    """Table 3's phases present in the run, and the labels of those outside it."""
    links = run.tables.get("links")
    times = frame_times(run)
    if links is None or links.num_rows == 0 or len(times) == 0:
        return [], list(PHASES)
    by_link = frame_grid(links, times, ["link"], ["radial_offset"])
    tol = max(facts.output_interval, 1e-9) * 0.5 + 1e-9
    found, skipped = [], []
    for label, t in facts.phase_times():
        if not math.isfinite(t) or t < times[0] - tol:
            skipped.append(label)
            continue
        f = int(np.argmin(np.abs(times - t)))
        if abs(times[f] - t) > tol:
            skipped.append(label)
            continue
        offsets = by_link["radial_offset"][f, 1:]
        k = int(np.nanargmax(offsets)) + 1
        found.append(Phase(label, float(times[f]), f, k, 1e3 * float(offsets[k - 1])))
    return found, skipped
