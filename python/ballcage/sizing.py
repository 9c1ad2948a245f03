"""Link sizing: the paper's eq. (8)–(9) both ways (``ballcage size``).

A flexible joint's link taken as a rigid cylinder of length L and outer
diameter d = 2r fits a guide tube of inner diameter D bent to centreline
radius R while its corners stay inside the outer wall and its middle clears
the inner wall (Zhu et al. 2023, Figure 14). Eq. (8) is that right triangle,
(L/2)² + (R − D/2 + 2r)² = (R + D/2)², and eq. (9) solves it for L:

    L = 2·√(2RD − 4Rr + 2Dr − 4r²) = 2·√(2(D − 2r)(R + r)).

The functions here give it three ways: the longest link for a bend
(`longest_link`), the tightest bend for a link (`tightest_radius_for_link`)
and the widest link for a length and bend (`largest_link_diameter`). Names
and arguments (diameters, as the paper's Table 1 and ``ballcage size
--joint-od`` give them) are the Rust core's (``drillpipe/sizing.rs``), which
the scene validator also uses, so ``ballcage size`` and a refused scene
always agree; these add the argument checks. Everything is SI (metres).
What a hinge allows besides fitting the tube is its articulation limit:
`tightest_radius_for_bend`, and `ballcage.Scene.tightest_radius` for a whole
drill-pipe scene.

The names of the previous release (`longest_joint`,
`smallest_curvature_radius`, `largest_joint_diameter`,
`smallest_curvature_radius_for_bend`) still work for this release, with a
`DeprecationWarning`.

    >>> round(longest_link(1.5, 0.116, 0.086), 5)
    0.60854
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from pathlib import Path

from ballcage import _native
from ballcage._native import InputError

__all__ = [
    "PAPER_JOINT_OUTER_DIAMETER",
    "PAPER_TUBE_INNER_DIAMETER",
    "largest_link_diameter",
    "longest_link",
    "plot_joint_lengths",
    "tightest_radius_for_bend",
    "tightest_radius_for_link",
]

#: The paper's guide tube bore [m] (Table 1).
PAPER_TUBE_INNER_DIAMETER = 0.116
#: The paper's flexible joint outer diameter [m] (Table 1).
PAPER_JOINT_OUTER_DIAMETER = 0.086


def _positive(name: str, value: float) -> float:
    value = float(value)
    if not (math.isfinite(value) and value > 0):
        raise InputError(f"{name} = {value!r} m: must be a positive, finite length in metres")
    return value


def _link_in_tube(tube_inner_diameter: float, link_outer_diameter: float) -> tuple[float, float]:
    tube = _positive("tube_inner_diameter", tube_inner_diameter)
    link = _positive("link_outer_diameter", link_outer_diameter)
    if link >= tube:
        raise InputError(f"link_outer_diameter = {link} m: not narrower than the bore, tube_inner_diameter = {tube} m")
    return tube, link


def _bend(curvature_radius: float, tube_inner_diameter: float) -> float:
    radius = _positive("curvature_radius", curvature_radius)
    if radius < tube_inner_diameter / 2:
        raise InputError(
            f"curvature_radius = {radius} m: below half the bore ({tube_inner_diameter / 2} m), "
            "a tube cannot bend that tightly"
        )
    return radius


def longest_link(curvature_radius: float, tube_inner_diameter: float, link_outer_diameter: float) -> float:
    """The longest rigid link [m] of outer diameter `link_outer_diameter` [m] that fits a tube of
    bore `tube_inner_diameter` [m] bent to centreline radius `curvature_radius` [m] (eq. (9)).

    Raises `ValueError` naming the argument for a length that is not positive, a
    link not narrower than the bore, or a radius below half the bore.
    """
    tube, link = _link_in_tube(tube_inner_diameter, link_outer_diameter)
    radius = _bend(curvature_radius, tube)
    return _native.longest_link(radius, tube, link)


def tightest_radius_for_link(link_length: float, tube_inner_diameter: float, link_outer_diameter: float) -> float:
    """The tightest centreline radius [m] a tube of bore `tube_inner_diameter` [m] may bend to and
    still hold a rigid link `link_length` [m] long of outer diameter `link_outer_diameter` [m]:
    eq. (9) solved for R, (L/2)² / (2(D − d)) − d/2.

    Never below D/2 (the tightest bend a tube of that bore has): a link so short
    that eq. (9) gives less fits every bend, and the answer is D/2. Raises
    `ValueError` naming the argument for bad input.
    """
    tube, link = _link_in_tube(tube_inner_diameter, link_outer_diameter)
    length = _positive("link_length", link_length)
    return max(_native.tightest_radius_for_link(length, tube, link), tube / 2)


def largest_link_diameter(link_length: float, curvature_radius: float, tube_inner_diameter: float) -> float:
    """The widest rigid link [m, outer diameter] `link_length` [m] long that fits a tube of bore
    `tube_inner_diameter` [m] bent to centreline radius `curvature_radius` [m]: eq. (9) solved
    for d, d = 2r = (D − 2R + √((2R + D)² − L²)) / 2.

    Raises `ValueError` naming `link_length` when no link that long fits, L > 2·√(2RD)
    (the longest link of no diameter), and naming the argument for bad input.
    """
    tube = _positive("tube_inner_diameter", tube_inner_diameter)
    radius = _bend(curvature_radius, tube)
    length = _positive("link_length", link_length)
    d = _native.largest_link_diameter(length, radius, tube)
    if d is None or d <= 0:
        most = _native.longest_link(radius, tube, 0.0)
        raise InputError(
            f"link_length = {length} m: no link that long fits a {tube} m bore bent to {radius} m "
            f"(eq. (9): at most {most:.6g} m, for a link of no diameter)"
        )
    return d


def tightest_radius_for_bend(pitch: float, bend_limit_deg: float) -> float:
    """The tightest centreline radius [m] at which hinges `pitch` [m] apart along the centreline
    bend no more than `bend_limit_deg` [deg] each: R = p / (2 sin(β / 2)).

    A drill-pipe scene's own limit is `ballcage.Scene.articulation_limit_deg`; the
    tighter of this and `tightest_radius_for_link` binds (`ballcage.Scene.tightest_radius`).
    """
    p = _positive("pitch", pitch)
    beta = float(bend_limit_deg)
    if not (math.isfinite(beta) and 0 < beta <= 180):
        raise InputError(f"bend_limit_deg = {beta!r}: must be an angle in (0, 180] degrees")
    return _native.tightest_radius_for_bend(p, math.radians(beta))


def _deprecated(old: str, new: str) -> None:
    warnings.warn(
        f"ballcage.sizing.{old} is deprecated and goes in the next release: use {new} (same arguments, in order)",
        DeprecationWarning,
        stacklevel=3,
    )


def longest_joint(curvature_radius: float, tube_inner_diameter: float, joint_outer_diameter: float) -> float:
    """Deprecated: `longest_link`."""
    _deprecated("longest_joint", "longest_link")
    return longest_link(curvature_radius, tube_inner_diameter, joint_outer_diameter)


def smallest_curvature_radius(joint_length: float, tube_inner_diameter: float, joint_outer_diameter: float) -> float:
    """Deprecated: `tightest_radius_for_link`."""
    _deprecated("smallest_curvature_radius", "tightest_radius_for_link")
    return tightest_radius_for_link(joint_length, tube_inner_diameter, joint_outer_diameter)


def largest_joint_diameter(joint_length: float, curvature_radius: float, tube_inner_diameter: float) -> float:
    """Deprecated: `largest_link_diameter`."""
    _deprecated("largest_joint_diameter", "largest_link_diameter")
    return largest_link_diameter(joint_length, curvature_radius, tube_inner_diameter)


def smallest_curvature_radius_for_bend(pitch: float, bend_limit_deg: float) -> float:
    """Deprecated: `tightest_radius_for_bend`."""
    _deprecated("smallest_curvature_radius_for_bend", "tightest_radius_for_bend")
    return tightest_radius_for_bend(pitch, bend_limit_deg)


def plot_joint_lengths(
    path: str | Path,
    tube_inner_diameter: float = PAPER_TUBE_INNER_DIAMETER,
    joint_outer_diameters: Sequence[float] | None = None,
    curvature_radii: Sequence[float] = (1.0, 1.5, 2.0, 2.5),
    mark: tuple[float, float, float] | None = None,
) -> Path:
    """Writes a PNG like the paper's Figure 15 to `path` and returns it.

    Left: the longest joint [mm] against the curvature radius [mm] for each of
    `joint_outer_diameters` [m] (default: 60–100 mm around the paper's 86 mm in
    its 116 mm bore, else half to nine tenths of the bore). Right: the longest joint against the joint's
    radius [mm] for each of `curvature_radii` [m] (the paper's 1.0–2.5 m), the
    falling curves the paper describes. `mark` = (curvature radius, joint outer
    diameter, length) [m] is drawn as a point on the left. SI in, mm on the axes.
    """
    import numpy as np

    from ballcage import _plot

    tube = _positive("tube_inner_diameter", tube_inner_diameter)
    diameters = [d for d in (joint_outer_diameters or _default_diameters(tube)) if 0 < d < tube]
    if not diameters:
        raise InputError(f"joint_outer_diameters: none is narrower than the bore, tube_inner_diameter = {tube} m")
    fig = _plot.figure(figsize=(11, 4.5))
    left, right = fig.subplots(1, 2)
    radii = np.linspace(max(tube / 2, 0.1), max(3.0, 1.2 * mark[0] if mark else 0.0), 300)
    for d, style in zip(diameters, _plot.series_styles(len(diameters)), strict=True):
        lengths = [1e3 * longest_link(float(r), tube, d) for r in radii]
        left.plot(1e3 * radii, lengths, color=style["color"], ls=style["ls"], label=f"d = {1e3 * d:g} mm")
    if mark is not None:
        left.plot(1e3 * mark[0], 1e3 * mark[2], "ko", label=f"{1e3 * mark[2]:.2f} mm at R = {1e3 * mark[0]:g} mm")
    left.set(xlabel="curvature radius R [mm]", ylabel="longest joint length L [mm]",
             title=f"eq. (9), tube bore D = {1e3 * tube:g} mm")
    left.legend(fontsize="small")
    joint_radii = np.linspace(0.0, 0.999 * tube / 2, 200)
    for r, style in zip(curvature_radii, _plot.series_styles(len(curvature_radii)), strict=True):
        lengths = [1e3 * _native.longest_link(_bend(r, tube), tube, 2 * float(a)) for a in joint_radii]
        right.plot(1e3 * joint_radii, lengths, color=style["color"], ls=style["ls"], label=f"R = {1e3 * r:g} mm")
    right.set(xlabel="joint radius r [mm]", ylabel="longest joint length L [mm]",
              title=f"as the paper's Figure 15: L against r, D = {1e3 * tube:g} mm")
    right.legend(fontsize="small")
    for ax in (left, right):
        ax.grid(True, alpha=0.3)
        ax.set_ylim(bottom=0)
    out = Path(path)
    fig.savefig(out, dpi=120)
    return out


def _default_diameters(tube: float) -> list[float]:
    """Joint diameters [m] to plot in a bore of `tube` [m]: the paper's 60–100 mm in its bore,
    else a half to nine tenths of the bore in whole millimetres."""
    if tube == PAPER_TUBE_INNER_DIAMETER:
        return [0.060, 0.070, 0.080, 0.086, 0.090, 0.100]
    return [round(f * tube * 1e3) / 1e3 for f in (0.5, 0.6, 0.7, 0.8, 0.9)]
