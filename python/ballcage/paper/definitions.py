"""The shipped reference numbers (``ballcage/data/paper-2023.toml``) and how we compute and qualify each."""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from importlib import resources
from typing import Any

from ballcage.measures.quantities import MEASURES

__all__ = [
    "BASELINE_RADIUS",
    "BASELINE_RPM",
    "DEFINITIONS",
    "EXTRA_ROWS",
    "MUCH_LARGER",
    "NORMAL_TANGENTIAL_PAIRS",
    "REFERENCE_FILE",
    "SECTION4_RADII",
    "SECTION4_SPEEDS",
    "SWEEPS",
    "SWEEP_DEFINITIONS",
    "TREND_RULES",
    "TUBE_DISTRIBUTION_PAPER",
    "TUBE_LINKS",
    "ExtraRow",
    "SweepVariant",
    "reference",
]

#: The reference file, in ``ballcage/data``.
REFERENCE_FILE = "paper-2023.toml"


@dataclass(frozen=True)
class SweepVariant:
    """A case of the paper's §4 sweep that the reference file quotes numbers for."""

    radius: float  # borehole.curvature_radius [m]
    rpm: float  # drive.speed_rpm [rpm]
    label: str


#: The section-4 cases with numbers in the reference file: id → variant. The id is the one in the reference
#: keys, ``sweep_<id>_...``; every case of the sweep (`ballcage.paper.section4`) is in `SECTION4_RADII` or
#: `SECTION4_SPEEDS`.
SWEEPS: dict[str, SweepVariant] = {
    "R1000": SweepVariant(1.0, 100.0, "R = 1.0 m"),
    "R2500": SweepVariant(2.5, 100.0, "R = 2.5 m"),
    "rpm60": SweepVariant(1.5, 60.0, "60 rpm"),
    "rpm120": SweepVariant(1.5, 120.0, "120 rpm"),
}
#: §4.2: the curvature radii [m], at `BASELINE_RPM`; §4.3: the drive speeds [rpm], at `BASELINE_RADIUS`.
SECTION4_RADII: tuple[float, ...] = (1.0, 1.5, 2.0, 2.5)
SECTION4_SPEEDS: tuple[float, ...] = (60.0, 80.0, 100.0, 120.0)
BASELINE_RADIUS = 1.5  # m, the paper's scene
BASELINE_RPM = 100.0  # rpm

#: How each ``[[trend]]`` of the reference file is checked: key → (summary column, swept scene key, +1 rises /
#: -1 falls as the key grows). ``normal_exceeds_tangential`` is checked by `NORMAL_TANGENTIAL_PAIRS`.
TREND_RULES: dict[str, tuple[str, str, int]] = {
    "tube_mean_max_falls_with_R": ("tube_normal_mean_max_n", "borehole.curvature_radius", -1),
    "key_peak_falls_with_R": ("key_peak_n", "borehole.curvature_radius", -1),
    "tube_mean_max_rises_with_rpm": ("tube_normal_mean_max_n", "drive.speed_rpm", +1),
    "key_peak_rises_with_rpm": ("key_peak_n", "drive.speed_rpm", +1),
}
#: ``normal_exceeds_tangential``: (normal column, tangential column) of the summary, on the tube and in the joints.
NORMAL_TANGENTIAL_PAIRS: tuple[tuple[str, str], ...] = (
    ("tube_normal_mean_all_n", "tube_tangential_mean_all_n"),
    ("seat_key_normal_peak_n", "seat_key_tangential_peak_n"),
)
#: Our reading of "much larger" in ``normal_exceeds_tangential``: the normal force at least this many times the
#: tangential one, in every case (the smallest ratio is reported beside the verdict).
MUCH_LARGER = 3.0


@dataclass(frozen=True)
class ExtraRow:
    """A comparison row the reference file has no ``[[quantity]]`` for: a second definition or a missing value."""

    key: str
    after: str  # the reference key this row follows in the comparison
    unit: str
    paper_from: str | None  # the reference key holding the paper's value for this row; None: the paper gives none


#: Rows beyond the reference file's, in the order they follow their `after` keys.
EXTRA_ROWS: tuple[ExtraRow, ...] = (
    ExtraRow("included_angle_projected_min_deg", "included_angle_min_deg", "deg", "included_angle_min_deg"),
    ExtraRow("included_angle_projected_max_deg", "included_angle_max_deg", "deg", "included_angle_max_deg"),
    ExtraRow("range_of_motion_peak_to_peak_mm", "range_of_motion_mm", "mm", "range_of_motion_mm"),
    ExtraRow("tube_normal_mean_max_inclination_deg", "tube_normal_mean_joint12_n", "deg", None),
    ExtraRow("head_cage_normal_peak_n", "seat_cage_normal_peak_n", "N", None),
)
#: What the paper says about where along the chain the tube force is largest (the note of
#: ``tube_normal_mean_max_inclination_deg``; docs/model.md §6.2).
TUBE_DISTRIBUTION_PAPER = (
    "the paper: the largest per-joint mean at joint 10 (876.8 N, section 3.2; joint 10's chord lies at 72.6 deg "
    "of inclination on the arc), 'largest at 30-70 deg slope' in its text, 58-78 deg in its section 4 cases (78 deg at R = 1.0 m, 58 deg "
    "at R = 2.5 m, 75 deg at 60 rpm, 60 deg at 120 rpm), and 0 N at joint 12"
)
#: Links whose tube forces the paper plots (Figs. 10–11) and quotes.
TUBE_LINKS: tuple[int, ...] = (2, 4, 6, 8, 10)


def _ours(key: str) -> str:
    """How we compute `key`, as measured in `ballcage.measures.quantities.MEASURES`, with ``ours: `` before it."""
    text = MEASURES[key]
    return text if text.startswith("differs: ") else f"ours: {text}"


_TABLE3 = (
    "included_angle_min_deg",
    "included_angle_max_deg",
    "included_angle_projected_min_deg",
    "included_angle_projected_max_deg",
    "range_of_motion_mm",
    "range_of_motion_peak_to_peak_mm",
    "most_deformed_joint",
)
_SUMS_AND_PEAKS = (
    "tube_normal_mean_all_n",
    "tube_tangential_mean_all_n",
    "seat_cage_normal_peak_n",
    "head_cage_normal_peak_n",
    "cage_key_normal_peak_n",
    "seat_key_normal_peak_n",
    "seat_key_tangential_peak_n",
)
#: How we compute each reference quantity; repeated in the row's note. The quantities a sweep's summary also
#: holds are defined once, in `ballcage.measures.quantities.MEASURES`.
DEFINITIONS: dict[str, str] = {
    **{key: _ours(key) for key in _TABLE3},
    "tube_normal_peak_joint10_n": (
        "ours: largest links.tube_normal of link 10 (total normal force of its contact with the tube) over the "
        "summary window, at every stage of the integrator's steps (links.tube_normal_max), not only at the frames"
    ),
    "tube_normal_mean_joint10_n": (
        "ours: time mean of links.tube_normal of link 10 over the summary window (its impulse "
        "links.tube_normal_impulse over the window's length; no contact counts as 0)"
    ),
    "tube_normal_mean_joint12_n": "ours: time mean of links.tube_normal of link 12 over the summary window",
    "tube_normal_mean_max_inclination_deg": _ours("tube_normal_mean_max_inclination_deg"),
    **{key: _ours(key) for key in _SUMS_AND_PEAKS},
}
SWEEP_DEFINITIONS: dict[str, str] = {
    "tube_mean_max": (
        "ours: largest per-link time mean of links.tube_normal over the summary window of the {label} variant"
    ),
    "key_peak": (
        "differs: ours is the maximum race normal force on one key, max of keys.inner_normal and "
        "keys.outer_normal over all keys and frames of the {label} variant; the paper does not say which race"
    ),
}
#: Why the paper's value is suspect (docs/model.md §6), for the keys the reference marks `suspect`.
SUSPECT_REASONS: dict[str, str] = {
    "tube_normal_mean_all_n": (
        "suspect (docs/model.md §6.1): an average of 7.1 kN exceeds every joint's peak (<= 5952.9 N) and is 8x the "
        "largest per-joint average (876.8 N); it can only be a sum over about 8-12 joints or a typo for 0.71 kN; "
        "compare as order of magnitude only"
    ),
    "tube_tangential_mean_all_n": (
        "suspect (docs/model.md §6.1): same reading question as the 7.1 kN normal average (sum over joints or "
        "typo); the ratio 1.4/7.1 = 0.20 is plausible against mu(450 mm/s) = 0.233; order of magnitude only"
    ),
    "sweep_R2500_key_peak_n": (
        "suspect (docs/model.md §6.3): 36.8 kN at R = 2.5 m exceeds the 33.5 kN baseline at R = 1.5 m, "
        "contradicting the paper's claim that the key peak falls as R grows; order of magnitude only"
    ),
    "sweep_rpm60_key_peak_n": (
        "suspect (docs/model.md §6.3): 36.7 kN at 60 rpm exceeds the 33.5 kN baseline at 100 rpm, "
        "contradicting the paper's claim that the key peak rises with speed; order of magnitude only"
    ),
}
SUSPECT_FALLBACK = (
    "suspect: the reference marks this value as contradicting other values of the same paper "
    "(docs/model.md §6); compare as order of magnitude only"
)
NOT_SWEPT = "not run: pass --sweeps"


def reference() -> dict[str, Any]:
    """The shipped reference numbers (``ballcage/data/paper-2023.toml``), parsed."""
    text = resources.files("ballcage").joinpath("data", REFERENCE_FILE).read_text(encoding="utf-8")
    return tomllib.loads(text)
