"""Where each recorded contact of a drill-pipe run rubs, and how hard: the patches the wear map (`wear_map`) sums.

A *patch* is one contact point of one frame, spread over the area it presses:
its extent on each surface (an interval along the surface's axis and one
around it), its normal force, slip speed and friction power, and the time it
stands for. The pressure is taken uniform over the Hertz contact area
(p_mean = F/area), not Hertz's ellipsoid (p₀ = 1.5·p_mean at the centre): the
map's cells (10 mm × 5° by default) are tens of times larger than a patch
(0.1–2 mm), so the distribution inside a patch only decides how a patch on a
cell border is split; and the ellipsoid's peak is worn flat in the first
micrometres of running in, after which a worn groove carries the load over
its whole width. A uniform patch keeps Archard's local law exact on average:
a cell under a patch that stays put wears k/H·p_mean·v per second.

Hertz patches (docs/model.md §8.1, the same models as the engine's
``drillpipe/stress.rs``):
- link–tube, within ``pipe.link_edge_radius`` of a link end: the rounded rim,
  elliptical, semi-axes ∝ F^(1/3) (solved here once, exact Hertz by the AGM);
- link–tube elsewhere: a line contact over the link's length L, half-width
  b = √(4·F·R′/(π·L·E*)), 1/R′ = 1/r_link − 1/r_bore (Johnson, *Contact
  Mechanics*, 1985, eq. 4.43);
- a connected piece of the level-set law (two depth maxima and the interior
  minimum between them, docs/model.md §4): the piece's net force F₁ + F₂ − |F_m|
  as a line contact over the stretch between its maxima;
- key–race, key–window: elliptical, semi-axes scaled from the ``wear`` table's
  largest-pressure patch of the same pair as (F/F_peak)^(1/3), exact for a
  point contact of fixed curvatures.

Everything SI (m, s, N, Pa); angles in radians inside this module.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Patches", "elliptic_ke", "frame_weights", "line_half_width", "rim_semi_axes", "rotate_into"]


@dataclass(frozen=True)
class Patches:
    """Contact patches on two surfaces at once: each row is one contact of one frame.

    ``along`` and ``around`` are (N, 2) intervals [start, end]: along the
    surface's axis [m] and around it [rad] (the around interval may run past
    2π or below 0; the map wraps it). ``other_*`` are the same patch on the
    second surface (the link under a tube contact), or ``None``.
    """

    along: np.ndarray
    around: np.ndarray
    other_along: np.ndarray | None
    other_around: np.ndarray | None
    force: np.ndarray  # (N,) normal force [N]
    area: np.ndarray  # (N,) contact area [m²]
    slip: np.ndarray  # (N,) slip speed [m/s]
    power: np.ndarray  # (N,) friction power [W]
    dt: np.ndarray  # (N,) time the frame stands for [s]
    owner: np.ndarray  # (N,) int: link (tube contacts) or pair id (key contacts) of the patch

    @property
    def pressure(self) -> np.ndarray:
        """Mean contact pressure [Pa] of each patch, F/area."""
        return self.force / np.maximum(self.area, 1e-300)


def frame_weights(t: np.ndarray, window: tuple[float, float], interval: float) -> np.ndarray:
    """The time [s] each recorded frame at `t` stands for: its share of the window [start, end].

    Midpoint rule over frames recorded every `interval` [s]: a frame covers
    (t − interval/2, t + interval/2) cut to the window, so the weights of a
    complete run add up to the window's length.
    """
    lo = np.maximum(t - interval / 2.0, window[0])
    hi = np.minimum(t + interval / 2.0, window[1])
    return np.clip(hi - lo, 0.0, None)


def line_half_width(force: np.ndarray, length: np.ndarray, radius: float, e_star: float) -> np.ndarray:
    """Hertz half-width b [m] of a line contact: force [N] over `length` [m], relative radius `radius` [m]."""
    per_length = np.clip(force, 0.0, None) / np.maximum(length, 1e-12)
    return np.sqrt(4.0 * per_length * radius / (math.pi * e_star))


def elliptic_ke(m: float) -> tuple[float, float]:
    """Complete elliptic integrals K(m), E(m) of parameter m = e² (0 ≤ m < 1), by the arithmetic–geometric mean."""
    a, b, c = 1.0, math.sqrt(1.0 - m), math.sqrt(m)
    total, power = 0.5 * c * c, 0.5
    while abs(c) > 1e-16:
        a, b, c = (a + b) / 2.0, math.sqrt(a * b), (a - b) / 2.0
        power *= 2.0
        total += power * c * c
    k = math.pi / (2.0 * a)
    return k, k * (1.0 - total)


def rim_semi_axes(curvature_major: float, curvature_minor: float, e_star: float) -> tuple[float, float]:
    """Hertz semi-axes (a, b) [m] of an elliptical contact under 1 N; multiply by F^(1/3) for F [N].

    `curvature_major` < `curvature_minor` [1/m] are the two principal sums of
    curvature of the bodies (the major axis a lies along the smaller). Johnson
    §4.2: B/A = (E(e)/(1 − e²) − K(e)) / (K(e) − E(e)) fixes e, then
    a³ = 3F·(K − E)/(2π·A·E*·e²) with A = curvature_major/2, b = a·√(1 − e²).
    """
    big_a, big_b = curvature_major / 2.0, curvature_minor / 2.0
    if big_b <= big_a * (1.0 + 1e-12):
        a = (3.0 / (4.0 * e_star * (big_a + big_b))) ** (1.0 / 3.0)
        return a, a

    def ratio(m: float) -> float:
        k, e = elliptic_ke(m)
        return (e / (1.0 - m) - k) / (k - e)

    lo, hi = 1e-12, 1.0 - 1e-15
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if ratio(mid) < big_b / big_a:
            lo = mid
        else:
            hi = mid
    m = 0.5 * (lo + hi)
    k, e = elliptic_ke(m)
    a = (3.0 * (k - e) / (2.0 * math.pi * big_a * e_star * m)) ** (1.0 / 3.0)
    return a, a * math.sqrt(1.0 - m)


def rotate_into(quat: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """World vectors (N, 3) in the body frames of the unit quaternions (N, 4) [w, x, y, z]: q⁻¹·v·q."""
    w = quat[:, :1]
    q = -quat[:, 1:]
    t = 2.0 * np.cross(q, vectors)
    return vectors + w * t + np.cross(q, t)


@dataclass(frozen=True)
class TubeContacts:
    """The link–tube contact points of a run, one row per point per frame (the ``contacts`` table's rows).

    ``x`` and ``theta`` place the point on its link (along the body x axis
    from the link's centre [m], around it from body y toward body z [rad]);
    ``s`` and ``phi`` on the tube (arc length along the centreline [m],
    azimuth from the bend's outer wall [rad]).
    """

    frame: np.ndarray  # (N,) int: frame index
    pair: np.ndarray  # (N,) int: pair id
    link: np.ndarray  # (N,) int: link id
    force: np.ndarray  # (N,) signed normal force [N] (negative at a level-set minimum)
    slip: np.ndarray  # (N,) [m/s]
    power: np.ndarray  # (N,) signed friction power |F_t|·v·sign(F) [W]
    dt: np.ndarray  # (N,) [s]
    x: np.ndarray
    theta: np.ndarray
    s: np.ndarray
    phi: np.ndarray


@dataclass(frozen=True)
class LinkGeometry:
    """The link in its tube, as the Hertz models see it [m, Pa]."""

    radius: float
    half_length: float
    edge: float
    bore: float
    e_star: float

    @property
    def line_radius(self) -> float:
        """Relative radius R′ of the link's side in the bore: 1/R′ = 1/r_link − 1/r_bore."""
        return 1.0 / (1.0 / self.radius - 1.0 / self.bore)

    def rim(self) -> tuple[float, float]:
        """Semi-axes under 1 N of the rim's ellipse: (around the wall, along the axis)."""
        around = 1.0 / self.radius - 1.0 / self.bore
        return rim_semi_axes(around, 1.0 / self.edge, self.e_star)


def _pieces(c: TubeContacts) -> tuple[np.ndarray, list[tuple[int, int, int]]]:
    """The level-set pieces: each interior minimum (negative force) with its nearest maximum on either side.

    Returns the mask of rows left as single points and the pieces as
    (first maximum, minimum, second maximum) row indices (a maximum missing on
    one side is given as −1).
    """
    single = c.force > 0.0
    pieces: list[tuple[int, int, int]] = []
    group = c.frame.astype(np.int64) * (int(c.pair.max(initial=0)) + 1) + c.pair
    order = np.argsort(group, kind="stable")
    sorted_group = group[order]
    for n in np.flatnonzero(c.force < 0.0):
        lo_g, hi_g = np.searchsorted(sorted_group, group[n]), np.searchsorted(sorted_group, group[n], side="right")
        same = order[lo_g:hi_g]
        same = same[single[same]]
        below = same[c.x[same] < c.x[n]]
        above = same[c.x[same] > c.x[n]]
        lo = int(below[np.argmax(c.x[below])]) if below.size else -1
        hi = int(above[np.argmin(c.x[above])]) if above.size else -1
        for k in (lo, hi):
            if k >= 0:
                single[k] = False
        pieces.append((lo, int(n), hi))
    return single, pieces


def tube_patches(c: TubeContacts, g: LinkGeometry) -> Patches:
    """The patches of the link–tube contacts on the tube (along s, around φ) and on the link (x, θ)."""
    single, pieces = _pieces(c)
    rows = np.flatnonzero(single)
    f = c.force[rows]
    x = c.x[rows]
    rim = np.abs(x) > g.half_length - g.edge
    a1, b1 = g.rim()
    cube = np.cbrt(np.clip(f, 0.0, None))
    root_pi = math.sqrt(math.pi) / 2.0  # a rectangle of the ellipse's area: half-sides a·√π/2, b·√π/2
    b_line = line_half_width(f, np.full_like(f, 2.0 * g.half_length), g.line_radius, g.e_star)
    half_around = np.where(rim, a1 * cube * root_pi, b_line)
    lo = np.where(rim, x - b1 * cube * root_pi, -g.half_length)
    hi = np.where(rim, x + b1 * cube * root_pi, g.half_length)
    # pieces: the net force as a line contact between the two maxima
    p_rows, p_force, p_slip, p_power, p_lo, p_hi = [], [], [], [], [], []
    for lo_k, m, hi_k in pieces:
        members = [k for k in (lo_k, m, hi_k) if k >= 0]
        net = float(np.sum(c.force[members]))
        if net <= 0.0:
            continue
        p_rows.append(m)
        p_force.append(net)
        p_slip.append(float(np.sum(c.force[members] * c.slip[members])) / net)
        p_power.append(float(np.sum(c.power[members])))
        p_lo.append(float(c.x[lo_k]) if lo_k >= 0 else float(c.x[m]))
        p_hi.append(float(c.x[hi_k]) if hi_k >= 0 else float(c.x[m]))
    pr = np.asarray(p_rows, dtype=int)
    pf, plo, phi_ = np.asarray(p_force, dtype=float), np.asarray(p_lo, dtype=float), np.asarray(p_hi, dtype=float)
    length = np.maximum(phi_ - plo, 1e-4)
    pb = line_half_width(pf, length, g.line_radius, g.e_star)
    all_rows = np.concatenate([rows, pr])
    force = np.concatenate([f, pf])
    along_link = np.column_stack([np.concatenate([lo, plo]), np.concatenate([hi, plo + length])])
    half = np.concatenate([half_around, pb])
    shift = c.s[all_rows] - c.x[all_rows]
    theta, phi = c.theta[all_rows], c.phi[all_rows]
    return Patches(
        along=along_link + shift[:, None],
        around=np.column_stack([phi - half / g.bore, phi + half / g.bore]),
        other_along=along_link,
        other_around=np.column_stack([theta - half / g.radius, theta + half / g.radius]),
        force=force,
        area=(along_link[:, 1] - along_link[:, 0]) * 2.0 * half,
        slip=np.concatenate([c.slip[rows], np.asarray(p_slip, dtype=float)]),
        power=np.concatenate([c.power[rows], np.asarray(p_power, dtype=float)]),
        dt=c.dt[all_rows],
        owner=c.link[all_rows],
    )
