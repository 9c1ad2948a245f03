"""A drill-pipe run's quantities, one number each: what a sweep's ``summary.parquet`` holds per case.

`DRILL_PIPE` is the sweep plug-in (`ballcage.studies.sweep_quantities.SweepQuantities`):
its columns (`QUANTITIES`, then two per link, `link_columns`) with unit and
meaning, and their values for one run. The paper's comparison
(`ballcage.paper.compare`) takes its values from the same functions and adds
its notes, so a summary column and the comparison row of the same key agree:

- Table 3's motion at the four phases of the last revolution (`table3_motion`:
  the most deformed joint k, the hinge with the largest mean bend over the
  revolution (`ballcage.measures.shape`); the included angle at hinge k, in
  3-D and projected on the bend plane; link k's ranges of motion);
- tube forces per link (`ballcage._links.link_tube_forces`) and where along
  the chain they are largest (`ballcage.measures.places.tube_profile`);
- the peak cage and key forces (`column_peaks`, `CAGE_PEAKS`, `KEY_PEAKS`) and
  the largest race force on a key (`race_peak`);
- the drive efficiency (`efficiency`).

Means (tube forces, efficiency) are over the scene's summary window; peaks of
key and cage forces are over the whole run. A quantity a hinge model does not
have (cages and keys of the ideal CV hinge) or a run too short for (Table 3's
phases lie in the last revolution) is ``None`` (null in ``summary.parquet``).
"""

from __future__ import annotations

import math
import re
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ballcage._links import in_summary_window, link_tube_forces
from ballcage.measures.frames import argmax_where, frame_grid, frame_times
from ballcage.measures.motion import CentrePaths, centre_paths, last_revolution
from ballcage.measures.phases import Phase, SceneFacts, phases, scene_facts
from ballcage.measures.places import tube_profile
from ballcage.measures.shape import BendRanking, projected_angles, rank_bends
from ballcage.run import Run

__all__ = [
    "CAGE_PEAKS",
    "DRILL_PIPE",
    "KEY_PEAKS",
    "MEASURES",
    "QUANTITIES",
    "DrillPipeQuantities",
    "Peak",
    "Table3Motion",
    "column_peaks",
    "efficiency",
    "link_columns",
    "race_peak",
    "table3_motion",
]

#: What each quantity shared with the paper's comparison measures; the comparison's definitions
#: (`ballcage.paper.definitions.DEFINITIONS`) are these, prefixed ``ours: `` unless they start ``differs: ``.
MEASURES: dict[str, str] = {
    "included_angle_min_deg": (
        "at each of the four phases, the included angle at hinge k between link k and link k+1 (as in Fig. 9: "
        "links.included_angle_deg of link k = 180 - hinges.bend_deg of hinge k; hinge 12 joins link 12 and the lower "
        "connector), k = most_deformed_joint; smallest over the phases"
    ),
    "included_angle_max_deg": (
        "at each of the four phases, the included angle at hinge k between link k and link k+1 "
        "(links.included_angle_deg of link k), k = most_deformed_joint; largest over the phases"
    ),
    "included_angle_projected_min_deg": (
        "as included_angle_min_deg with both axes projected on the bend plane (the plane of the tube's "
        "centreline): 180 - |psi(k+1) - psi(k)|, psi the axis's angle in that plane from the downward vertical "
        "(links.inclination_deg, links.azimuth_deg; the lower connector's from the bodies table); an out-of-plane "
        "fold shows a smaller projected bend; smallest over the phases"
    ),
    "included_angle_projected_max_deg": (
        "as included_angle_max_deg with both axes projected on the bend plane (included_angle_projected_min_deg); "
        "largest over the phases"
    ),
    "range_of_motion_mm": (
        "differs: ours is the largest centre offset, link k's centre-of-mass distance from the tube centreline "
        "(links.radial_offset, mm, k = most_deformed_joint), largest over the phases; a centre offset cannot exceed "
        "the radial clearance, so the paper's 23.6 / 24.5 / 25.0 / 25.3 mm (Table 3) can only be an excursion: "
        "range_of_motion_peak_to_peak_mm is the definition that fits the paper"
    ),
    "range_of_motion_peak_to_peak_mm": (
        "peak-to-peak excursion of link k's centre (k = most_deformed_joint) over the last revolution of the upper "
        "connector: the largest distance between two positions of the centre in the tube cross-section "
        "(links.offset_outward, links.offset_lateral, i.e. projected on the plane normal to the tube centreline), "
        "mm; this is the definition that fits the paper's 23.6-25.3 mm, which exceed the radial clearance a centre "
        "offset is bounded by"
    ),
    "most_deformed_joint": (
        "the hinge k (1-12: between link k and the next body; the paper's joint k) whose bend (180 - "
        "links.included_angle_deg of link k = hinges.bend_deg of hinge k), averaged over the frames of the upper "
        "connector's last revolution, is largest; one joint for all four phases, never a mean of link numbers. Not "
        "the link whose centre is furthest out (every centre of the buckled chain reaches the clearance) nor the "
        "largest bend (the articulation limit caps it): both are decided by sub-millimetre penetrations"
    ),
    "tube_normal_mean_max_inclination_deg": (
        "mean links.inclination_deg over the summary window of the link with the largest per-link mean "
        "links.tube_normal (tube_normal_mean_max_n): where along the chain the tube force is largest"
    ),
    "tube_normal_mean_all_n": (
        "differs: ours is the SUM over links 1-12 of the time mean of links.tube_normal over the summary window "
        "(reading 1: a sum, the only reading that can exceed a single joint's peak)"
    ),
    "tube_tangential_mean_all_n": (
        "differs: ours is the SUM over links 1-12 of the time mean of links.tube_tangential over the summary window "
        "(magnitude of the per-frame summed friction vector; reading 1: a sum)"
    ),
    "seat_cage_normal_peak_n": "maximum of hinges.cage_seat_normal (ball seat-ball cage) over all hinges and frames",
    "head_cage_normal_peak_n": (
        "maximum of hinges.cage_head_normal (ball head-ball cage) over all hinges and frames; the paper reports "
        "no value (section 3.3 quotes only ball seat-ball cage, 23.8 kN, and calls the ball head's contacts "
        "approximately equal to the seat's)"
    ),
    "cage_key_normal_peak_n": (
        "maximum of keys.window_normal (cage window faces, both window pairs of one key summed) "
        "over all keys and frames"
    ),
    "seat_key_normal_peak_n": (
        "maximum of keys.outer_normal (seat race, both flanks of one key summed) over all keys and frames"
    ),
    "seat_key_tangential_peak_n": (
        "maximum of keys.outer_tangential (seat race friction magnitude) over all keys and frames"
    ),
}
_UNITS: dict[str, str] = {
    "included_angle_min_deg": "deg",
    "included_angle_max_deg": "deg",
    "included_angle_projected_min_deg": "deg",
    "included_angle_projected_max_deg": "deg",
    "range_of_motion_mm": "mm",
    "range_of_motion_peak_to_peak_mm": "mm",
    "most_deformed_joint": "",
    "tube_normal_mean_max_inclination_deg": "deg",
    "tube_normal_mean_all_n": "N",
    "tube_tangential_mean_all_n": "N",
    "seat_cage_normal_peak_n": "N",
    "head_cage_normal_peak_n": "N",
    "cage_key_normal_peak_n": "N",
    "seat_key_normal_peak_n": "N",
    "seat_key_tangential_peak_n": "N",
}
_EXTRA: dict[str, tuple[str, str]] = {
    "tube_normal_mean_max_n": (
        "N",
        "largest per-link time mean of links.tube_normal over the summary window (the paper's sweep quantity tube_mean_max)",
    ),
    "tube_normal_peak_max_n": ("N", "largest links.tube_normal of any link over the summary window, at the integrator's stages (links.tube_normal_max)"),
    "key_peak_n": (
        "N",
        "largest race normal force on one key, max of keys.inner_normal and keys.outer_normal over all keys and "
        "frames (the paper's sweep quantity key_peak); null without ball keys",
    ),
    "efficiency": (
        "1",
        "drive efficiency over the summary window: mean drive.output_power / mean drive.input_power "
        "(null while the mean input power is not positive)",
    ),
}
#: Every fixed quantity column: name -> (unit, description). Per-link columns are `link_columns`.
QUANTITIES: dict[str, tuple[str, str]] = {k: (unit, MEASURES[k]) for k, unit in _UNITS.items()} | _EXTRA
#: Peak cage forces: quantity -> column of the ``hinges`` table (over hinges and frames; ball-key hinges only).
CAGE_PEAKS: dict[str, str] = {
    "seat_cage_normal_peak_n": "cage_seat_normal",
    "head_cage_normal_peak_n": "cage_head_normal",
}
#: Peak key forces: quantity -> column of the ``keys`` table (over keys and frames).
KEY_PEAKS: dict[str, str] = {
    "cage_key_normal_peak_n": "window_normal",
    "seat_key_normal_peak_n": "outer_normal",
    "seat_key_tangential_peak_n": "outer_tangential",
}

#: A per-link mean column's name (`link_columns`), the link number in group 1.
_LINK_MEAN = re.compile(r"tube_normal_mean_link_(\d+)_n")


def link_columns(link: int) -> dict[str, tuple[str, str]]:
    """The two per-link columns of link `link` (1 at the top): mean and peak tube normal force [N]."""
    return {
        f"tube_normal_mean_link_{link:02d}_n": ("N", f"time mean of links.tube_normal of link {link} over the summary window"),
        f"tube_normal_peak_link_{link:02d}_n": ("N", f"largest links.tube_normal of link {link} over the summary window, at the integrator's stages"),
    }


class DrillPipeQuantities:
    """The sweep plug-in of drill-pipe scenes: `QUANTITIES` and the per-link tube forces of each case."""

    def columns(self, recorded: Collection[str]) -> dict[str, tuple[str, str]]:
        """Every fixed column, then the per-link ones of the links any case `recorded` (name -> unit, meaning)."""
        out = dict(QUANTITIES)
        links = sorted({int(m.group(1)) for k in recorded if (m := _LINK_MEAN.fullmatch(k))})
        for link in links:
            out.update(link_columns(link))
        return out

    def __call__(self, run: Run) -> dict[str, float | None]:
        """The quantities of one case's run (complete or partial); empty for a run that is not a drill pipe."""
        if run.scene.kind != "drill-pipe":
            return {}
        out: dict[str, float | None] = dict.fromkeys(QUANTITIES)
        motion = table3_motion(run, scene_facts(run))
        if motion is not None:
            out.update(motion.values())
        tube = link_tube_forces(run)
        if tube is not None and tube.normal_mean:
            out["tube_normal_mean_all_n"] = _finite(sum(tube.normal_mean.values()))
            out["tube_tangential_mean_all_n"] = _finite(sum(tube.tangential_mean.values()))
            out["tube_normal_mean_max_n"] = _finite(max(tube.normal_mean.values()))
        profile = tube_profile(run)
        if profile is not None:
            out["tube_normal_mean_max_inclination_deg"] = _finite(profile.inclination[profile.largest])
        for peaks in (_cage_peaks(run), column_peaks(run, "keys", ["hinge", "key"], KEY_PEAKS)):
            out.update({k: _finite(p.value) for k, p in (peaks or {}).items()})
        key = race_peak(run)
        out["key_peak_n"] = _finite(key.value) if key is not None else None
        if tube is not None and tube.frames > 0:
            out["tube_normal_peak_max_n"] = max(tube.normal_peak.values(), default=None)
            for link in sorted(tube.normal_mean):
                mean, peak = link_columns(link)
                out[mean], out[peak] = tube.normal_mean[link], tube.normal_peak[link]
        out["efficiency"] = efficiency(run)
        return out

    def __repr__(self) -> str:
        return "ballcage.measures.DRILL_PIPE"


#: The plug-in `ballcage sweep`, `ballcage chart` and ``ballcage paper --sweeps`` pass for drill-pipe scenes.
DRILL_PIPE = DrillPipeQuantities()


@dataclass(frozen=True)
class Table3Motion:
    """Table 3's motion in a run: the most deformed joint k over the last revolution and its values at the phases."""

    found: list[Phase]
    skipped: list[str]  # labels of the phases outside the run
    ranking: BendRanking  # hinges by mean bend over the last revolution; k = ranking.winner
    before: BendRanking | None  # the same over the revolution before, None when it holds no frame
    angles: list[float]  # included angle at hinge k at each found phase [deg]
    projected: list[float]  # the same projected on the bend plane [deg] (NaN without the next body's axis)
    offsets_mm: list[float]  # link k's centre offset at each found phase [mm]
    window: tuple[float, float]  # the last revolution [s]
    paths: CentrePaths | None  # None: no frame of the links table in `window`

    @property
    def joint(self) -> int:
        """The most deformed joint k (hinge k, link k)."""
        assert self.ranking.winner is not None  # `table3_motion` returns None otherwise
        return self.ranking.winner

    def values(self) -> dict[str, float | None]:
        """The Table 3 quantities (angles [deg], ranges of motion [mm], the joint number)."""
        excursion = 1e3 * self.paths.peak_to_peak(self.joint) if self.paths is not None else None
        projected = [a for a in self.projected if math.isfinite(a)]
        return {
            "included_angle_min_deg": _finite(min(self.angles)),
            "included_angle_max_deg": _finite(max(self.angles)),
            "included_angle_projected_min_deg": _finite(min(projected)) if projected else None,
            "included_angle_projected_max_deg": _finite(max(projected)) if projected else None,
            "range_of_motion_mm": _finite(max(self.offsets_mm)),
            "range_of_motion_peak_to_peak_mm": _finite(excursion),
            "most_deformed_joint": float(self.joint),
        }


def table3_motion(run: Run, facts: SceneFacts) -> Table3Motion | None:
    """Table 3's motion; ``None`` without a links table, a phase in the run or a bend in the last revolution."""
    links = run.tables.get("links")
    if links is None:
        return None
    found, skipped = phases(run, facts)
    start, end = last_revolution(facts)
    ranking = rank_bends(links, start, end)
    if not found or ranking is None or ranking.winner is None:
        return None
    before = rank_bends(links, 2.0 * start - end, start - 0.5 * facts.output_interval) if start > 0.0 else None
    k = ranking.winner
    times = frame_times(run)
    g = frame_grid(links, times, ["link"], ["included_angle_deg", "radial_offset"])
    frames = [p.frame for p in found]
    projected = projected_angles(run, times)
    return Table3Motion(
        found,
        skipped,
        ranking,
        before,
        [float(a) for a in g["included_angle_deg"][frames, k]],
        [float(a) for a in projected[frames, k - 1]],
        [1e3 * float(r) for r in g["radial_offset"][frames, k]],
        (start, end),
        centre_paths(run, start, end),
    )


@dataclass(frozen=True)
class Peak:
    """The largest finite value of a table column over its rows and frames (NaN, ``()``, NaN when none)."""

    value: float
    ids: tuple[int, ...]  # the row's ids, in the order asked for (hinge, key)
    t: float  # s
    column: str = ""


def column_peaks(
    run: Run, table: str, ids: Sequence[str], columns: Mapping[str, str], times: np.ndarray | None = None
) -> dict[str, Peak] | None:
    """The `Peak` of each of `columns` (quantity -> column of `table`) over rows and frames; ``None`` unrecorded."""
    data = run.tables.get(table)
    if data is None:
        return None
    times = frame_times(run) if times is None else times
    grids = frame_grid(data, times, list(ids), list(columns.values()))
    return {key: Peak(*argmax_where(grids[column], times), column) for key, column in columns.items()}


def _cage_peaks(run: Run, times: np.ndarray | None = None) -> dict[str, Peak] | None:
    """`CAGE_PEAKS` of a ball-key pipe; ``None`` without cages (another hinge) or a hinges table."""
    if not run.has_ball_keys:
        return None
    return column_peaks(run, "hinges", ["hinge"], CAGE_PEAKS, times)


def race_peak(run: Run) -> Peak | None:
    """The largest race normal force on one key, max of ``keys.inner_normal`` and ``keys.outer_normal`` [N].

    ``Peak.column`` names the race column it was found in; ``None`` without a keys table.
    """
    peaks = column_peaks(run, "keys", ["hinge", "key"], {"inner": "inner_normal", "outer": "outer_normal"})
    if peaks is None:
        return None
    best = Peak(math.nan, (), math.nan)
    for peak in peaks.values():
        if math.isfinite(peak.value) and not (peak.value <= best.value):
            best = peak
    return best


def efficiency(run: Run) -> float | None:
    """Drive efficiency over the summary window: mean output power / mean input power; ``None`` without a drive."""
    drive = run.tables.get("drive")
    if drive is None or drive.num_rows == 0:
        return None
    inside = in_summary_window(run.scene, drive.column("t").to_numpy())
    if not inside.any():
        return None
    p_in = float(np.mean(drive.column("input_power").to_numpy()[inside]))
    p_out = float(np.mean(drive.column("output_power").to_numpy()[inside]))
    return p_out / p_in if p_in > 0 and math.isfinite(p_out) else None


def _finite(value: Any) -> float | None:
    return float(value) if value is not None and math.isfinite(value) else None
