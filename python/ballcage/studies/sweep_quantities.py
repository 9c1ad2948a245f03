"""A sweep case's row of derived quantities, computed by the paper module's own definitions.

Nothing new is defined here except the drive efficiency: the included
angles, the ranges of motion, the most deformed joint and the peak cage and
key forces are the ``ours`` column of `ballcage.paper.comparison`; the largest
per-link mean tube force and the largest race force on a key are its sweep
quantities (``tube_mean_max``, ``key_peak``); the per-link mean and peak tube
forces are `ballcage._links.link_tube_forces`. Means (tube forces,
efficiency) are over the scene's summary window; peaks of key and cage
forces are over the whole run, as in the comparison. A quantity a hinge model does not have (cages and keys of the ideal
CV hinge) or a run too short for (Table 3's phases lie in the last
revolution) is ``None`` (null in ``summary.parquet``).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ballcage._links import in_summary_window, link_tube_forces
from ballcage.run import Run

__all__ = ["QUANTITIES", "case_quantities", "link_columns"]

#: The comparison rows a sweep keeps, by their key (the column name), with unit and description.
_FROM_COMPARISON: dict[str, str] = {
    "included_angle_min_deg": "deg",
    "included_angle_max_deg": "deg",
    "range_of_motion_mm": "mm",
    "range_of_motion_peak_to_peak_mm": "mm",
    "most_deformed_joint": "",
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
        "largest per-link mean of links.tube_normal over the summary window (the paper's sweep quantity tube_mean_max)",
    ),
    "tube_normal_peak_max_n": ("N", "largest links.tube_normal of any link and frame of the summary window"),
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


def _descriptions() -> dict[str, tuple[str, str]]:
    from ballcage.paper.definitions import DEFINITIONS

    out = {k: (unit, DEFINITIONS[k].removeprefix("ours: ")) for k, unit in _FROM_COMPARISON.items()}
    out.update(_EXTRA)
    return out


#: Every fixed quantity column: name -> (unit, description). Per-link columns are `link_columns`.
QUANTITIES: dict[str, tuple[str, str]] = _descriptions()


def link_columns(link: int) -> dict[str, tuple[str, str]]:
    """The two per-link columns of link `link` (1 at the top): mean and peak tube normal force [N]."""
    return {
        f"tube_normal_mean_link_{link:02d}_n": ("N", f"mean of links.tube_normal of link {link} over the summary window"),
        f"tube_normal_peak_link_{link:02d}_n": ("N", f"largest links.tube_normal of link {link} over the summary window"),
    }


def case_quantities(run: Run | None) -> dict[str, float | None]:
    """The derived quantities of one case's run (complete or partial); empty for a run that is not a drill pipe."""
    if run is None or run.scene.kind != "drill-pipe":
        return {}
    from ballcage.paper.compare import _sweep_value, comparison  # deferred: matplotlib-free but heavy

    out: dict[str, float | None] = dict.fromkeys(QUANTITIES)
    table = comparison(run)
    for key, ours in zip(table.column("key").to_pylist(), table.column("ours").to_pylist(), strict=True):
        if key in _FROM_COMPARISON:
            out[key] = ours
    out["tube_normal_mean_max_n"] = _finite(_sweep_value(run, "case", "tube_mean_max").ours)
    out["key_peak_n"] = _finite(_sweep_value(run, "case", "key_peak").ours)
    tube = link_tube_forces(run)
    if tube is not None and tube.frames > 0:
        out["tube_normal_peak_max_n"] = max(tube.normal_peak.values(), default=None)
        for link in sorted(tube.normal_mean):
            mean, peak = link_columns(link)
            out[mean], out[peak] = tube.normal_mean[link], tube.normal_peak[link]
    out["efficiency"] = efficiency(run)
    return out


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
