"""Torque buckling of a chain of constant-velocity hinges: when it leaves the arc (docs/buckling.md).

A hinge bent by β that passes a torque T puts a couple T·tan(β/2) across each
of its shafts. On an arc whose bends are equal these couples are carried by a
constant out-of-plane hinge shear; where two bends around a hinge differ (at
the connectors, which sit tangent to the tube while the links are chords),
hinge k needs an out-of-plane force

    W_k = T·D_k / l,   D_k = tan(β_{k+1}/2) − tan(β_{k−1}/2)

from the wall (docs/buckling.md §2). Nothing in an ideal CV chain resists it:
the torque is its only load, so its shape does not depend on T and it leaves
the arc at any torque. `buckling` gives the torque at which the hinge with the
largest such drive swings 1 rad about the chord of its neighbours against
what can hold it (§3): gravity on its two links (a pendulum), a joint bending
stiffness and a hinge friction moment, and, for longer chains, the discrete
Greenhill torque of a bending stiffness with axial tension (the scene's
``load.axial_force`` when its lower end is axially free). With the paper's
fixed lower end, the hinges' axial play is the only length the global mode
can coil into: `Buckling.play_excursion` is how far off the axis that lets it
go (docs/buckling.md §3a). Everything is SI: torques in N·m, forces in N,
lengths in m, stiffness in N·m/rad.

    >>> import ballcage
    >>> b = ballcage.buckling()                        # the paper's scene
    >>> round(b.threshold)                             # N·m, held by gravity alone
    62
    >>> ballcage.buckling(bending_stiffness=3400.0).threshold > 1800.0
    True

``ballcage buckling`` (`ballcage.cli.buckling`) prints the same from the
command line, and with ``--simulate`` checks it against three quasi-static
runs (`simulate_check`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ballcage._native import InputError
from ballcage.scene import SceneSource, default_scene, load_scene

__all__ = [
    "Buckling",
    "HingeDrive",
    "SimulatedTorque",
    "buckling",
    "end_wall_force",
    "finite_greenhill",
    "play_excursion",
    "simulate_check",
]

#: Swing about the chord of its neighbours [rad] at which a hinge counts as having left the arc.
LEFT_AT_SWING = 1.0
#: |D_k| below which a hinge has no first-order drive (its two neighbouring bends are equal).
NO_DRIVE = 1e-12


@dataclass(frozen=True)
class HingeDrive:
    """One free hinge of the chain placed on the tube's centreline (docs/buckling.md §2–3)."""

    #: Hinge number, 0 between the upper connector and link 1.
    hinge: int
    #: D_k = tan(β_{k+1}/2) − tan(β_{k−1}/2) [1]: the wall force W_k = T·D_k/l that holds it on the arc.
    imbalance: float
    #: Distance of the hinge from the chord of its two neighbours [m]: the radius it swings on.
    swing_radius: float
    #: Gravity across that chord [m/s²]: what the hinge's pendulum hangs in.
    gravity_across: float
    #: Torque [N·m] at which this hinge swings `LEFT_AT_SWING` rad; ``inf`` without drive.
    threshold: float


@dataclass(frozen=True)
class Buckling:
    """What `buckling` found: the threshold torque and every term it used (SI)."""

    #: Torque [N·m] above which the chain leaves the arc; 0 when nothing holds it.
    threshold: float
    #: Which mode sets it: ``"hinge k"`` (a hinge pushed off the arc) or ``"Greenhill"``.
    mode: str
    #: Per free hinge (1 … n−1), the drive and the hinge's own threshold.
    hinges: tuple[HingeDrive, ...]
    #: Discrete Greenhill torque [N·m] of the stiffness and tension terms; ``inf`` when neither is given.
    greenhill: float
    #: Bend of every hinge on the placed chain [rad], 0 … n.
    bends: tuple[float, ...]
    #: The terms, SI with the unit in the key.
    terms: dict[str, float] = field(default_factory=dict)
    #: Largest hinge offset from the tube's axis [m] the global (Greenhill) mode reaches when it
    #: takes up the hinges' play: the quarter-turn helix through the end hinges whose excess length is
    #: (n + 1)·play (eq. 3.8). ``inf`` with an axially free lower end, which lets it coil freely.
    play_excursion: float = math.inf
    #: The global mode's threshold torque [N·m] of the finite chain between its clamped connectors
    #: (eq. 3.9; ``inf`` when neither tension nor stiffness is given); eq. 3.7 (`greenhill`) is its
    #: long-chain limit: 1.030× it for 12 links, 1.115× for 6 under tension alone.
    finite_greenhill: float = math.inf

    def __str__(self) -> str:
        rows = [f"threshold torque          {self.threshold:12.4g} N·m  ({self.mode})"]
        rows += [f"{k:<26}{v:12.4g}" for k, v in self.terms.items()]
        rows.append(f"Greenhill torque          {self.greenhill:12.4g} N·m")
        rows.append(f"finite-chain Greenhill    {self.finite_greenhill:12.4g} N·m")
        rows.append(f"play excursion            {self.play_excursion:12.4g} m")
        rows.append("hinge  bend [deg]  D_k [1]     W_k/T [1/m]  swing radius [mm]  g across [m/s²]  T_c [N·m]")
        pitch = self.terms["pitch [m]"]
        for h in self.hinges:
            rows.append(
                f"{h.hinge:5d}  {math.degrees(self.bends[h.hinge]):10.3f}  {h.imbalance:+.5f}  "
                f"{h.imbalance / pitch:+11.5f}  {1e3 * h.swing_radius:17.3f}  {h.gravity_across:15.3f}  "
                f"{h.threshold:9.4g}"
            )
        return "\n".join(rows)


def end_wall_force(torque: float, bends: Sequence[float], pitch: float) -> list[float]:
    """Out-of-plane wall force [N] each free hinge 1 … n−1 needs to stay on a planar placed chain.

    ``W_k = T·(tan(β_{k+1}/2) − tan(β_{k−1}/2))/l`` for `torque` T [N·m], `bends` β_0 … β_n [rad]
    and hinge `pitch` l [m] (docs/buckling.md §2, eq. 2.4); the sign is the side it pushes toward.
    """
    if not pitch > 0.0:
        raise InputError(f"pitch = {pitch} m: must be positive (the hinge-to-hinge length)")
    half = [math.tan(b / 2.0) for b in bends]
    return [torque * (half[k + 1] - half[k - 1]) / pitch for k in range(1, len(bends) - 1)]


def buckling(
    scene: SceneSource | None = None,
    *,
    friction_moment: float = 0.0,
    bending_stiffness: float = 0.0,
    axial_tension: float | None = None,
    hinge_play: float = 0.0,
    overrides: Iterable[str] = (),
) -> Buckling:
    """The torque [N·m] above which a drill-pipe scene's chain leaves the arc of its tube.

    `scene` is anything `ballcage.load_scene` takes (default: the paper's scene) and
    `overrides` ``dotted.key=value`` strings. The stabilising terms the scene does not
    model are given here: `friction_moment` M_f [N·m], a static friction moment each
    hinge opposes to bending; `bending_stiffness` k_b [N·m/rad] of each hinge;
    `axial_tension` N [N] along the chain (compression negative; default: the scene's
    ``load.axial_force`` with ``pipe.lower_end = "axially-free"``, else 0); `hinge_play`
    [m], each hinge's axial play, which a fixed lower end leaves as the only length the
    global mode can take up (`Buckling.play_excursion`). Gravity and the link mass come
    from the scene. Raises `ValueError` naming a bad term or a scene that is not a drill
    pipe, and `ballcage.SceneError` for an invalid scene.
    """
    patches = list(overrides)
    s = default_scene(patches) if scene is None else load_scene(scene, patches)
    if s.kind != "drill-pipe":
        raise InputError(f"scene kind = {s.kind!r}: buckling needs a drill-pipe scene (kind = \"drill-pipe\")")
    free_end = s.value("pipe.lower_end") == "axially-free"
    if axial_tension is None:
        axial_tension = float(s.value("load.axial_force")) if free_end else 0.0
    _check_terms(friction_moment, bending_stiffness, axial_tension, hinge_play)
    pitch, n = float(s.value("pipe.pitch")), int(s.value("pipe.joints"))
    placed = s.placed_chain()
    # Link 1's mass as built (the ideal-CV links carry their hinges' cage and keys).
    mass, gravity = float(placed["masses"][1]), float(s.value("world.gravity"))
    # The bend plane is x–z (world y is its normal): work in (x, z).
    points = [(p[0], p[2]) for p in placed["hinges"]]
    tangents = [(a[0], a[2]) for a in placed["axes"]]
    bends = tuple(math.acos(max(-1.0, min(1.0, _dot(a, b)))) for a, b in zip(tangents, tangents[1:], strict=False))
    hinges = tuple(
        _hinge_drive(k, points, bends, mass, gravity, pitch, friction_moment, bending_stiffness) for k in range(1, n)
    )
    greenhill = _greenhill(n, pitch, bending_stiffness, axial_tension)
    weakest = min(hinges, key=lambda h: h.threshold, default=None)
    threshold, mode = (weakest.threshold, f"hinge {weakest.hinge}") if weakest else (math.inf, "none")
    if greenhill < threshold:
        threshold, mode = greenhill, "Greenhill"
    terms = {
        "pitch [m]": pitch,
        "links": float(n),
        "link mass [kg]": mass,
        "gravity [m/s^2]": gravity,
        "tube clearance [m]": (float(s.value("borehole.inner_diameter")) - float(s.value("pipe.link_diameter"))) / 2,
        "friction moment [N·m]": friction_moment,
        "bending stiffness [N·m/rad]": bending_stiffness,
        "axial tension [N]": axial_tension,
        "hinge play [m]": hinge_play,
        "lower end axially free": float(free_end),
    }
    excursion = math.inf if free_end else play_excursion(n, pitch, hinge_play)
    finite = finite_greenhill(n, pitch, axial_tension, bending_stiffness)
    return Buckling(threshold, mode, hinges, greenhill, bends, terms, excursion, finite)


def finite_greenhill(links: int, pitch: float, tension: float, stiffness: float) -> float:
    """Smallest torque [N·m] at which a straight chain of `links` CV links leaves its axis (eq. 3.9).

    The linearised link equations of docs/buckling.md §3, i·l·(V + N·s_i) = (T/2)·(s_{i−1} − s_{i+1})
    + i·k_b·(s_{i+1} − 2s_i + s_{i−1}), for the slopes s_1 … s_n of `links` links of `pitch` l [m],
    with the connectors' axes held (s_0 = s_{n+1} = 0) and both end hinges on the axis (Σ s_i = 0),
    under axial `tension` N [N] and hinge bending `stiffness` k_b [N·m/rad]: the smallest T > 0 at
    which they have a solution. ``inf`` when neither term is given (as `Buckling.greenhill`) or no
    torque buckles the chain, 0 when nothing holds it (compression without stiffness).
    """
    n = links
    if tension == 0.0 and stiffness == 0.0:
        return math.inf
    if tension < 0.0 and stiffness == 0.0:
        return 0.0
    # A(T) = A0 + T·A1 singular ⟺ μ = −1/T an eigenvalue of A0⁻¹·A1.
    c = pitch * tension * np.eye(n) + stiffness * (2.0 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1))
    a0 = np.zeros((n + 1, n + 1), dtype=complex)
    a0[:n, :n], a0[:n, n], a0[n, :n] = 1j * c, 1j * pitch, 1.0
    a1 = np.zeros((n + 1, n + 1), dtype=complex)
    a1[:n, :n] = 0.5 * (np.eye(n, k=1) - np.eye(n, k=-1))
    try:
        mu = np.linalg.eigvals(np.linalg.solve(a0, a1))
    except np.linalg.LinAlgError:
        return 0.0  # C singular: a mode that nothing holds
    torques = [-1.0 / m for m in mu if abs(m) > 1e-12]
    real = [t.real for t in torques if abs(t.imag) <= 1e-9 * abs(t) and t.real > 0.0]
    return min(real, default=math.inf)


def play_excursion(links: int, pitch: float, play: float) -> float:
    """Largest hinge offset [m] of the global mode that the hinges' axial `play` [m] each allows.

    A chain of `links` links of `pitch` l [m] between two held ends has n + 1 hinges, so
    (n + 1)·play of excess length. The Greenhill mode of a chain under torque and tension is
    a helix of a quarter turn per link (eq. 3.7, θ = π/2); through the two end hinges it is
    w_k = a·(e^{iθk} − 1), whose links each lose 2a²·sin²(θ/2)/l = a²/l of axial length.
    Taking up the excess: a = √((n + 1)·play·l/n), and the hinges reach 2a off the axis
    (docs/buckling.md eq. 3.8).
    """
    return 2.0 * math.sqrt((links + 1) * play * pitch / links)


@dataclass(frozen=True)
class SimulatedTorque:
    """One quasi-static run of `simulate_check`: what the chain did at one torque (SI)."""

    #: Resisting moment of the run [N·m].
    torque: float
    #: Mean over hinges 0 … n of the bend [deg], averaged over the settled window.
    mean_bend_deg: float
    #: Largest hinge bend [deg] in the settled window.
    max_bend_deg: float
    #: Sum over links of the mean link–tube normal force [N].
    wall_force: float
    #: Largest mean offset of a link's centre from the bend plane [m].
    lateral_offset: float


def simulate_check(
    scene: SceneSource | None = None,
    torques: Sequence[float] = (),
    *,
    overrides: Iterable[str] = (),
    duration: float = 1.0,
    ramp: float = 0.3,
    window: float = 0.2,
) -> list[SimulatedTorque]:
    """Runs the scene held still (``drive.speed_rpm = 0``) at each of `torques` [N·m], ramped over `ramp` [s].

    Each run lasts `duration` [s]; bends, wall forces and lateral offsets are averaged
    over its last `window` [s] (docs/buckling.md §5). Raises `ValueError` for a bad
    time and `ballcage.SimulationError` if a run diverges.
    """
    from ballcage.run import simulate  # deferred: pyarrow is only needed here

    if not 0.0 < window < duration or not 0.0 <= ramp < duration - window:
        raise InputError(
            f"duration = {duration} s, ramp = {ramp} s, window = {window} s: "
            "need 0 < window and ramp + window < duration, so the window sees the full torque"
        )
    base = list(overrides) + [
        "drive.speed_rpm=0",
        f"load.ramp={ramp}",
        f"simulation.duration={duration}",
        "simulation.output_interval=0.01",
        'record.tables=["links", "hinges"]',
    ]
    out = []
    for torque in torques:
        patches = base + [f"load.resisting_moment={float(torque)!r}"]
        s = default_scene(patches) if scene is None else load_scene(scene, patches)
        run = simulate(s, progress=False)
        out.append(_observe(float(torque), run.tables["links"], run.tables["hinges"], duration - window))
    return out


def _observe(torque: float, links: Any, hinges: Any, since: float) -> SimulatedTorque:
    """Averages the settled window (t > `since`) of the links and hinges tables."""

    def settled(table: Any, key: str, value: str) -> dict[int, list[float]]:
        rows: dict[int, list[float]] = {}
        columns = (table.column(name).to_pylist() for name in ("t", key, value))
        for t, k, v in zip(*columns, strict=True):
            if t > since + 1e-9:
                rows.setdefault(k, []).append(v)
        return rows

    def mean(v: list[float]) -> float:
        return sum(v) / len(v)

    bends = settled(hinges, "hinge", "bend_deg")
    return SimulatedTorque(
        torque=torque,
        mean_bend_deg=mean([mean(v) for v in bends.values()]),
        max_bend_deg=max(max(v) for v in bends.values()),
        wall_force=sum(mean(v) for v in settled(links, "link", "tube_normal").values()),
        lateral_offset=max(abs(mean(v)) for v in settled(links, "link", "offset_lateral").values()),
    )


def _check_terms(friction_moment: float, bending_stiffness: float, axial_tension: float, hinge_play: float) -> None:
    resistances = (
        ("friction_moment", friction_moment, "N·m", "a resistance, not a drive"),
        ("bending_stiffness", bending_stiffness, "N·m/rad", "a resistance, not a drive"),
        ("hinge_play", hinge_play, "m", "a clearance"),
    )
    for name, value, unit, what in resistances:
        if not (math.isfinite(value) and value >= 0.0):
            raise InputError(f"{name} = {value} {unit}: must be a finite number ≥ 0 ({what})")
    if not math.isfinite(axial_tension):
        raise InputError(f"axial_tension = {axial_tension} N: must be finite (tension positive, compression negative)")


def _hinge_drive(
    k: int,
    points: Sequence[tuple[float, float]],
    bends: Sequence[float],
    mass: float,
    gravity: float,
    pitch: float,
    friction_moment: float,
    bending_stiffness: float,
) -> HingeDrive:
    """Hinge k's drive D_k and the torque that swings it 1 rad (docs/buckling.md eq. 3.4)."""
    imbalance = math.tan(bends[k + 1] / 2.0) - math.tan(bends[k - 1] / 2.0)
    a, h, b = points[k - 1], points[k], points[k + 1]
    chord = ((b[0] - a[0]) / _dist(a, b), (b[1] - a[1]) / _dist(a, b))
    rho = abs((h[0] - a[0]) * chord[1] - (h[1] - a[1]) * chord[0])
    g_across = gravity * abs(chord[0])  # |g × chord| for g along −z
    hold = mass * g_across * pitch + 6.0 * bending_stiffness * rho / pitch + 4.0 * friction_moment
    threshold = LEFT_AT_SWING * hold / abs(imbalance) if abs(imbalance) > NO_DRIVE else math.inf
    return HingeDrive(k, imbalance, rho, g_across, threshold)


def _greenhill(n: int, pitch: float, stiffness: float, tension: float) -> float:
    """Discrete Greenhill torque [N·m]: min over θ ∈ [2π/n, π) of (l·N + 4k_b·sin²(θ/2))/sin θ (eq. 3.7)."""
    if n < 3 or (stiffness == 0.0 and tension == 0.0):
        return math.inf
    lowest = 2.0 * math.pi / n
    thetas = [lowest + (math.pi - lowest) * i / 4000 for i in range(4000)]
    return max(0.0, min((pitch * tension + 4.0 * stiffness * math.sin(t / 2.0) ** 2) / math.sin(t) for t in thetas))


def _dist(a: tuple[float, float], b: tuple[float, float]) -> float:
    return math.hypot(b[0] - a[0], b[1] - a[1])


def _dot(a: tuple[float, float], b: tuple[float, float]) -> float:
    return a[0] * b[0] + a[1] * b[1]
