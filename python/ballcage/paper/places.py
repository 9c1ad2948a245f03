"""Where our forces are largest, beside where the paper says its are: the notes and ``comparison.md`` lines.

The values come from `ballcage.measures.places` (the tube force along the
chain, `tube_profile`; the key-force peak's hinge, time and drive stage,
`peak_place`); this module words them for the comparison.
"""

from __future__ import annotations

import math

from ballcage.measures.places import NEAR_LARGEST, PeakPlace, TubeProfile, peak_place, tube_profile
from ballcage.paper.definitions import DEFINITIONS, TUBE_DISTRIBUTION_PAPER
from ballcage.run import Run

__all__ = ["PAPER_KEY_PEAK", "distribution_row", "key_place_text", "link12_text", "place_lines"]

#: Where the paper's key-force peak is (section 3.3, the reference's ``seat_key_normal_peak_n``).
PAPER_KEY_PEAK = "the paper's peak (33.5 kN) is at joint 1# during the acceleration"
_KEY = "tube_normal_mean_max_inclination_deg"


def _runs(numbers: list[int]) -> str:
    """``2-5, 7, 9-12``: ascending link numbers with consecutive runs joined."""
    parts: list[str] = []
    last = -2
    for k in numbers:
        if parts and k == last + 1:
            parts[-1] = f"{parts[-1].split('-')[0]}-{k}"
        else:
            parts.append(str(k))
        last = k
    return ", ".join(parts)


def _near_text(profile: TubeProfile) -> str:
    """The links near the largest mean with their inclinations, and the inclination span of those above half of it."""
    near = ", ".join(f"{k} ({profile.inclination[k]:.1f} deg)" for k in profile.near())
    half = profile.near(0.5)
    low, high = profile.span(0.5)
    least = min(profile.share(k) for k in half)
    return (
        f"links {near}; at least half of it: links {_runs(half)}, {low:.1f}-{high:.1f} deg of inclination "
        f"({100 * least:.0f}-100 % of the largest)"
    )


def distribution_row(run: Run) -> tuple[float | None, str]:
    """The value [deg] and note of ``tube_normal_mean_max_inclination_deg``; ``(None, why)`` without tube forces."""
    profile = tube_profile(run)
    if profile is None:
        return None, "not computed: the run did not record the links table"
    k = profile.largest
    note = (
        f"{DEFINITIONS[_KEY]}; ours: largest at link {k} ({profile.normal_mean[k]:.0f} N mean, "
        f"{profile.inclination[k]:.1f} deg); within {100 * (1 - NEAR_LARGEST):.0f} % of it: {_near_text(profile)}; "
        f"{TUBE_DISTRIBUTION_PAPER}"
    )
    return profile.inclination[k], note


def link12_text(run: Run) -> str:
    """``; link 12 carries … % of the largest per-link mean (link k), at … deg`` (empty without link 12)."""
    profile = tube_profile(run)
    if profile is None or 12 not in profile.normal_mean:
        return ""
    share = profile.share(12)
    if not math.isfinite(share):
        return ""
    return (
        f"; link 12 carries {100 * share:.0f} % of the largest per-link mean (link {profile.largest}), "
        f"at a mean inclination of {profile.inclination[12]:.1f} deg"
    )


def key_place_text(place: PeakPlace) -> str:
    """Where and when the peak is, what the drive was doing, and the largest during the acceleration and at hinges 0-1."""
    hinge, key = place.ids
    text = (
        f"at hinge {hinge:02d} key {key}, t = {place.t:.4g} s, during the {place.stage} (drive.ramp "
        f"{place.ramp:g} s), the upper connector at {place.angle_deg:.0f} deg of its revolution"
    )
    value, ids, t = place.during_ramp
    if math.isfinite(value):
        text += f"; the largest during the acceleration: {value:.0f} N at hinge {ids[0]:02d} key {ids[1]}, t = {t:.4g} s"
    at = [f"hinge {h:02d} {place.by_hinge[h]:.0f} N" for h in (0, 1) if h in place.by_hinge]
    if at:
        text += f"; the largest at {', '.join(at)} (hinge 0 joins the upper connector and link 1)"
    return f"{text}; {PAPER_KEY_PEAK}"


def place_lines(run: Run) -> list[str]:
    """``comparison.md``'s section: the key-force peak and the tube force along the chain, beside the paper's."""
    place = peak_place(run, "outer_normal")
    profile = tube_profile(run)
    if place is None and profile is None:
        return []
    lines = ["", "## Where the forces are largest, beside the paper", ""]
    if place is not None:
        lines.append(f"- Seat-key force peak ({place.value:.0f} N, `keys.outer_normal`): {key_place_text(place)}.")
    if profile is None:
        return lines
    k = profile.largest
    lines += [
        f"- Tube force along the chain (means over the summary window): largest at link {k} "
        f"({profile.normal_mean[k]:.0f} N, {profile.inclination[k]:.1f} deg); within "
        f"{100 * (1 - NEAR_LARGEST):.0f} % of it: {_near_text(profile)}{link12_text(run)}. {TUBE_DISTRIBUTION_PAPER[0].upper()}"
        f"{TUBE_DISTRIBUTION_PAPER[1:]}.",
        "",
        "| link | mean inclination [deg] | mean tube normal force [N] | share of the largest |",
        "| ---: | ---: | ---: | ---: |",
    ]
    lines += [
        f"| {j} | {profile.inclination[j]:.1f} | {profile.normal_mean[j]:.0f} | {profile.share(j):.2f} |"
        for j in sorted(profile.normal_mean)
    ]
    return lines
