"""Peer comparison with MuJoCo: speed and accuracy on ballcage's paper scene with ideal-CV hinges.

Optional, outside the test suite (issue 12, item 2 and the MuJoCo parts of
items 3-4). Needs ``pip install mujoco`` (or ``pip install .[bench]``);
matplotlib is used for the optional plots when installed.

The MuJoCo model is built from ballcage's own resolved scene (``ballcage.load_scene``
with ``pipe.hinge="ideal-cv"``): link and connector masses and inertias (as built,
``Scene.placed_chain()["masses"]``), pitch, link diameter, tube bore, curvature
radius and build angle, placed hinge centres and axes, gravity, drive speed and
ramp, resisting moment and ramp, articulation limit and tube friction are all read
from it. How the two models differ is listed in docs/peers.md and printed
with ``--describe``.

Examples::

    python benchmarks/peers.py                                   # 12 joints, dt 1e-3 and 1e-4, 1.8 s
    python benchmarks/peers.py --dt 1e-3 --joints 6 12 24 48 96 --duration 0.6 --no-reference \\
        --out out/peers-scaling.json
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import platform
import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import ballcage
import numpy as np

try:
    import mujoco
except ImportError:  # pragma: no cover - optional dependency
    mujoco = None

#: Quaternion turning a MuJoCo cylinder's or capsule's axis (local z) onto a body's x axis.
Z_TO_X = "0.7071067811865476 0 0.7071067811865476 0"
#: Most MuJoCo steps run in one call between checks for divergence.
MAX_CHUNK = 100
#: Arm [m] of the articulation-limit tendon: its sites sit this far from the hinge on either body's axis.
LIMIT_ARM = 0.05
#: Tube wall of the box ring: half the radial thickness of each box [m].
BOX_HALF_THICKNESS = 0.005
#: The bend plane's normal: every ballcage body's z axis, and the z axis of the upper connector's MuJoCo frame.
BEND_NORMAL = np.array([0.0, -1.0, 0.0])


# --------------------------------------------------------------------------- ballcage side


#: Extra ``key=value`` scene overrides for both engines (``--set``), and whether to lengthen the arc with the chain.
SCENE_SETTINGS: dict[str, Any] = {"overrides": [], "fit_arc": False}


def scene_overrides(joints: int) -> list[str]:
    """The ``--set`` overrides, plus with ``--fit-arc`` a curvature radius scaled with the chain (paper: 12 joints)."""
    extra = list(SCENE_SETTINGS["overrides"])
    if SCENE_SETTINGS["fit_arc"] and joints > 12:
        base = ballcage.load_scene({"kind": "drill-pipe"}, extra)
        extra.append(f"borehole.curvature_radius={float(base.value('borehole.curvature_radius')) * joints / 12.0!r}")
    return extra


def ballcage_scene(joints: int, dt: float, duration: float) -> ballcage.Scene:
    """The paper's drill pipe with ideal-CV hinges, `joints` links, SDIRK2's fixed step `dt`, recording only ``links``."""
    overrides = [
        'pipe.hinge="ideal-cv"',
        'simulation.integrator="sdirk2"',
        "simulation.rtol=0",
        f"pipe.joints={joints}",
        f"simulation.dt={dt!r}",
        f"simulation.duration={duration!r}",
        'record.tables=["links"]',
        *scene_overrides(joints),
    ]
    return ballcage.load_scene({"kind": "drill-pipe"}, overrides)


def _step(x: float, x0: float, h0: float, x1: float, h1: float) -> float:
    """The Adams STEP function (cubic, C1)."""
    if x <= x0:
        return h0
    if x >= x1:
        return h1
    d = (x - x0) / (x1 - x0)
    return h0 + (h1 - h0) * d * d * (3.0 - 2.0 * d)


def window_means(
    t: np.ndarray, link: np.ndarray, normal: np.ndarray, window: tuple[float, float], joints: int
) -> list[float]:
    """Per-link mean of the per-frame tube normal force over the frames in `window` (links 1..joints)."""
    inside = (t >= window[0] - 1e-9) & (t <= window[1] + 1e-9)
    out = []
    for k in range(1, joints + 1):
        mask = inside & (link == k)
        out.append(float(normal[mask].mean()) if mask.any() else 0.0)
    return out


@dataclass
class Result:
    engine: str
    dt: float
    joints: int
    duration: float
    wall_s: float  # wall time of the stepping loop [s]
    steps: int
    frames: int  # frames averaged in the window
    means: list[float]  # per-link mean tube normal force [N], links 1..joints
    complete: bool = True
    note: str = ""
    extra: dict[str, Any] = field(default_factory=dict)
    reached: float | None = None  # simulated time reached [s]; None: the whole duration

    @property
    def rtf(self) -> float:
        """Real-time factor: simulated time reached over wall time."""
        t = self.duration if self.reached is None else self.reached
        return t / self.wall_s if self.wall_s > 0 else math.inf


def run_ballcage(joints: int, dt: float, duration: float, window: tuple[float, float]) -> Result:
    scene = ballcage_scene(joints, dt, duration)
    sim = ballcage.Simulation(scene)
    note, complete = "", True
    t0, c0 = time.perf_counter(), time.process_time()
    try:
        sim.advance(scene.duration)
    except ballcage.SimulationError as e:  # a diverged run still reports what it recorded
        note, complete = str(e).splitlines()[0][:200], False
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    steps, reached = sim.steps, sim.time
    links = sim.finish()["links"]
    t = links.column("t").to_numpy()
    link = links.column("link").to_numpy()
    normal = links.column("tube_normal").to_numpy()
    inside = (t >= window[0] - 1e-9) & (t <= window[1] + 1e-9)
    frames = int(np.unique(t[inside]).size)
    means = window_means(t, link, normal, window, joints)
    return Result(
        "ballcage",
        dt,
        joints,
        duration,
        wall,
        steps,
        frames,
        means,
        complete,
        note,
        {"integrator": scene.integrator, "cpu_s": cpu},
        reached=reached,
    )


# --------------------------------------------------------------------------- MuJoCo model


@dataclass
class PipeFacts:
    """What the MuJoCo model is built from, all read from the resolved ballcage scene (SI)."""

    joints: int
    pitch: float
    link_radius: float
    link_mass: float
    link_inertia: list[float]
    connector_length: float
    connector_radius: float
    connector_mass: float
    connector_inertia: list[float]
    bore_radius: float
    curvature_radius: float
    build_angle: float  # rad
    gravity: float
    omega: float  # rad/s
    drive_ramp: float
    moment: float  # N·m
    load_ramp: float
    beta_max: float | None  # rad
    mu: float  # constant Coulomb coefficient used in MuJoCo
    mu_note: str
    hinges: list[list[float]]
    axes: list[list[float]]
    output_interval: float


def adams_mu(speed: float, mu_s: float, mu_d: float, v_s: float, v_d: float) -> float:
    """ballcage's Adams friction coefficient at slip speed `speed` (docs/model.md §2.2)."""
    if speed < v_s:
        u = speed / v_s
        return mu_s * u * (3.0 - u * u) / 2.0
    return _step(speed, v_s, mu_s, v_d, mu_d)


def pipe_facts(scene: ballcage.Scene) -> PipeFacts:
    v = scene.value
    chain = scene.placed_chain()
    masses = chain["masses"]
    fr = v("materials.tube.friction")
    scale = 1e-3 if fr.get("units") == "N-mm-s" else 1.0  # speeds in mm/s
    omega = float(v("drive.speed_rpm")) * 2.0 * math.pi / 60.0
    r_link = float(v("pipe.link_diameter")) / 2.0
    if fr.get("law") == "adams":
        slip = omega * r_link
        mu = adams_mu(slip, fr["mu_static"], fr["mu_dynamic"], fr["v_static"] * scale, fr["v_dynamic"] * scale)
        mu_note = (
            f"Adams law (mu_s {fr['mu_static']}, mu_d {fr['mu_dynamic']}) evaluated at the link's "
            f"surface speed omega*r = {slip * 1e3:.0f} mm/s"
        )
    else:  # tanh or other: take its nominal coefficient
        mu = float(fr.get("mu", fr.get("mu_dynamic", 0.3)))
        mu_note = f"nominal coefficient of the {fr.get('law')} law"
    limit = scene.articulation_limit_deg()
    return PipeFacts(
        joints=int(v("pipe.joints")),
        pitch=float(v("pipe.pitch")),
        link_radius=r_link,
        link_mass=float(masses[1]),
        link_inertia=[float(x) for x in v("pipe.link_inertia")],
        connector_length=float(v("pipe.connector_length")),
        connector_radius=float(v("pipe.connector_diameter")) / 2.0,
        connector_mass=float(masses[0]),
        connector_inertia=[float(x) for x in v("pipe.connector_inertia")],
        bore_radius=float(v("borehole.inner_diameter")) / 2.0,
        curvature_radius=float(v("borehole.curvature_radius")),
        build_angle=math.radians(float(v("borehole.build_angle_deg"))),
        gravity=float(v("world.gravity")),
        omega=omega,
        drive_ramp=float(v("drive.ramp")),
        moment=float(v("load.resisting_moment")),
        load_ramp=float(v("load.ramp")),
        beta_max=None if limit is None else math.radians(limit),
        mu=mu,
        mu_note=mu_note,
        hinges=chain["hinges"],
        axes=chain["axes"],
        output_interval=float(scene.output_interval),
    )


def _frame(x: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Quaternion (w, x, y, z) of the frame with axes x, y = z × x, z."""
    y = np.cross(z, x)
    mat = np.column_stack([x, y, z]).reshape(-1)
    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, mat)
    return q


def _fmt(a: Any) -> str:
    return " ".join(f"{float(x):.12g}" for x in a)


@dataclass
class Ring:
    segments: int
    sectors: int
    boxes: int
    chord_circumferential: float  # m, outward bulge of the polygonal section at a face edge
    sagitta_outer: float  # m, outer wall of the bend (face ends lie outside the torus)
    sagitta_inner: float  # m, inner wall of the bend (face ends stand into the bore)


def bore_ring(f: PipeFacts, step_deg: float, sectors: int) -> tuple[list[str], Ring]:
    """The tube arc as a ring of boxes whose inner faces are tangent to the torus at their centres.

    Segment j spans [alpha_j, alpha_j+1] of the arc; sector i faces the direction
    phi_i = 2 pi (i + 1/2) / sectors from the outward normal of the bend. Each face is
    as long, along the arc, as the torus is at the face's centre, so consecutive
    faces meet at the segments' bisecting plane.
    """
    R, r, A = f.curvature_radius, f.bore_radius, f.build_angle
    n_seg = max(1, math.ceil(math.degrees(A) / step_deg - 1e-9))
    da = A / n_seg
    if sectors <= 0:  # no bore (a debugging aid: the chain in free space)
        return [], Ring(n_seg, 0, 0, math.nan, math.nan, math.nan)
    half_w = r * math.tan(math.pi / sectors)
    b = np.array([0.0, 1.0, 0.0])  # the bend plane's normal: u sweeps the section from n through b
    geoms = []
    for j in range(n_seg):
        # one static body per ring, so that MuJoCo's broad phase (over bodies) prunes the boxes
        geoms.append(f'<body name="ring{j}">')
        a = (j + 0.5) * da
        p = np.array([R * (1.0 - math.cos(a)), 0.0, -R * math.sin(a)])
        t = np.array([math.sin(a), 0.0, -math.cos(a)])
        n = np.array([-math.cos(a), 0.0, -math.sin(a)])
        for i in range(sectors):
            phi = 2.0 * math.pi * (i + 0.5) / sectors
            u = math.cos(phi) * n + math.sin(phi) * b
            half_t = (R + r * math.cos(phi)) * math.tan(da / 2.0)
            centre = p + (r + BOX_HALF_THICKNESS) * u
            q = _frame(t, u)
            geoms.append(
                f'<geom class="bore" type="box" size="{half_t:.9g} {half_w:.9g} {BOX_HALF_THICKNESS}" '
                f'pos="{_fmt(centre)}" quat="{_fmt(q)}"/>'
            )
        geoms.append("</body>")
    ring = Ring(
        segments=n_seg,
        sectors=sectors,
        boxes=n_seg * sectors,
        chord_circumferential=r * (1.0 / math.cos(math.pi / sectors) - 1.0),
        sagitta_outer=(R + r) * (1.0 / math.cos(da / 2.0) - 1.0),
        sagitta_inner=(R - r) * (1.0 / math.cos(da / 2.0) - 1.0),
    )
    return geoms, ring


def ring_step_deg(f: PipeFacts, opts: argparse.Namespace) -> float:
    """The arc angle of one ring of boxes [deg] for ``--ring-step`` metres of centreline."""
    return math.degrees(opts.ring_step / f.curvature_radius)


def _signed_bend(a: np.ndarray, b: np.ndarray, normal: np.ndarray) -> float:
    return math.atan2(float(np.dot(np.cross(a, b), normal)), float(np.dot(a, b)))


def _inertial(mass: float, inertia: list[float]) -> str:
    """The MJCF inertial element of a body of `mass` [kg] and principal `inertia` [kg m^2]."""
    return f'<inertial pos="0 0 0" mass="{mass:.12g}" diaginertia="{_fmt(inertia)}"/>'


def _bend_range(f: PipeFacts) -> str:
    """The range attribute of a bend hinge at the articulation limit ("" without one)."""
    return "" if f.beta_max is None else f'range="{-f.beta_max:.12g} {f.beta_max:.12g}"'


def _cv_joints(f: PipeFacts, h: int, anchor_x: float, opts: argparse.Namespace) -> str:
    """The hinges of CV joint `h` (``--cv``) at `anchor_x` [m] on the child body's axis."""
    pos = f'pos="{anchor_x:.12g} 0 0"'
    arm = f'armature="{opts.cv_armature:g}"'
    if opts.cv == "mirror":  # Ry(a) Rz(c) Ry(a): a pure swing (double-Cardan symmetry), zero twist
        return (
            f'<joint name="h{h}_a1" type="hinge" axis="0 1 0" {pos} {arm}/>'
            f'<joint name="h{h}_c" type="hinge" axis="0 0 1" {pos}/>'
            f'<joint name="h{h}_a2" type="hinge" axis="0 1 0" {pos} {arm}/>'
        )
    if opts.cv == "swing":  # Rx(psi) Ry(beta) Rx(-psi): a pure swing, zero twist
        return (
            f'<joint name="h{h}_psi1" type="hinge" axis="1 0 0" {pos} {arm}/>'
            f'<joint name="h{h}_beta" type="hinge" axis="0 1 0" {pos} {_bend_range(f)}/>'
            f'<joint name="h{h}_psi2" type="hinge" axis="1 0 0" {pos} {arm}/>'
        )
    # universal (Cardan) joint: CV only to first order in the bend
    return (
        f'<joint name="h{h}_a" type="hinge" axis="0 1 0" {pos}/>'
        f'<joint name="h{h}_b" type="hinge" axis="0 0 1" {pos}/>'
    )


def _link_geom(f: PipeFacts, opts: argparse.Namespace) -> str:
    """The type and size attributes of a link's geom (``--link-geom``)."""
    half_p = f.pitch / 2.0
    if opts.link_geom == "cylinder":
        return f'type="cylinder" size="{f.link_radius:.12g} {half_p:.12g}"'
    return f'type="capsule" size="{f.link_radius:.12g} {opts.capsule_half_length or half_p:.12g}"'


def _has_limit_tendons(f: PipeFacts, opts: argparse.Namespace) -> bool:
    """Whether the articulation limit is a tendon (a cone): there is a limit and ``--cv`` is not "swing".

    The limit (neck on mouth at beta_max) is a joint limit on beta for "swing"; otherwise a cone, as a lower
    limit on the length 2 L cos(beta / 2) of a tendon between points L from the hinge on both axes.
    """
    return f.beta_max is not None and opts.cv != "swing"


def _limit_tendons(f: PipeFacts, opts: argparse.Namespace) -> list[str]:
    """The articulation-limit tendon of every hinge, between its two sites LIMIT_ARM from the hinge."""
    if not _has_limit_tendons(f, opts):
        return []
    shortest = 2.0 * LIMIT_ARM * math.cos(f.beta_max / 2.0)
    return [
        f'<spatial name="h{h}_limit" range="{shortest:.12g} {2.0 * LIMIT_ARM + 1.0:.12g}" '
        f'solreflimit="{opts.solref_timeconst:g} 1"><site site="h{h}_p"/><site site="h{h}_c"/></spatial>'
        for h in range(f.joints + 1)
    ]


def _chain_body(f: PipeFacts, k: int, opts: argparse.Namespace) -> str:
    """The opening of body `k` of the chain (link k, or the lower connector for k = joints + 1) with its
    inertia, its CV joint to the parent, its sites and its geom.

    It sits one pitch (or half a connector plus half a pitch) further along its parent's x axis.
    """
    lower = k == f.joints + 1
    half_c, half_p = f.connector_length / 2.0, f.pitch / 2.0
    parent_half = half_c if k == 1 else half_p
    my_half = half_c if lower else half_p
    name = "lower" if lower else f"link{k}"
    s = [f'<body name="{name}" pos="{parent_half + my_half:.12g} 0 0">']
    if _has_limit_tendons(f, opts):  # the points one arm from the hinge on either body's axis
        s.append(f'<site name="h{k - 1}_c" pos="{-my_half + LIMIT_ARM:.12g} 0 0"/>')
        if not lower:
            s.append(f'<site name="h{k}_p" pos="{my_half - LIMIT_ARM:.12g} 0 0"/>')
    if lower:
        s.append(_inertial(f.connector_mass, f.connector_inertia))
        s.append(_cv_joints(f, k - 1, -my_half, opts))
        s.append(
            f'<geom class="visual" type="cylinder" size="{f.connector_radius:.12g} {half_c:.12g}" quat="{Z_TO_X}"/>'
        )
        s.append(f'<site name="lower_a" pos="{-half_c:.12g} 0 0"/><site name="lower_b" pos="{half_c:.12g} 0 0"/>')
    else:
        s.append(_inertial(f.link_mass, f.link_inertia))
        s.append(_cv_joints(f, k - 1, -my_half, opts))
        # MuJoCo cylinders and capsules lie along their local z: turn z onto the link's x axis
        s.append(f'<geom name="link{k}" class="link" {_link_geom(f, opts)} quat="{Z_TO_X}"/>')
    return "".join(s)


def _chain(f: PipeFacts, opts: argparse.Namespace) -> str:
    """The nested bodies below the upper connector: link 1 -> ... -> link n -> lower connector."""
    bodies = [_chain_body(f, k, opts) for k in range(1, f.joints + 2)]
    return "\n".join(bodies) + "</body>" * len(bodies)


def _equalities(n: int, opts: argparse.Namespace) -> list[str]:
    """The CV joints' hinge couplings (``--cv`` mirror or swing) and the lower connector's two world points."""
    tc = opts.solref_timeconst
    equalities = []
    if opts.cv == "mirror":
        for h in range(n + 1):
            equalities.append(f'<joint joint1="h{h}_a2" joint2="h{h}_a1" polycoef="0 1 0 0 0" solref="{tc:g} 1"/>')
    if opts.cv == "swing":
        for h in range(n + 1):
            equalities.append(f'<joint joint1="h{h}_psi2" joint2="h{h}_psi1" polycoef="0 -1 0 0 0" solref="{tc:g} 1"/>')
    for end in ("a", "b"):
        equalities.append(f'<connect site1="lower_{end}" site2="world_{end}" solref="{tc:g} 1"/>')
    return equalities


def _world_sites(f: PipeFacts) -> str:
    """The two world points the lower connector's ends are held to, as placed by ballcage."""
    n, half_c = f.joints, f.connector_length / 2.0
    axis = np.asarray(f.axes[n + 1], float)
    centre = np.asarray(f.hinges[n], float) + half_c * axis
    return "".join(
        f'<site name="world_{end}" pos="{_fmt(centre + sign * half_c * axis)}"/>'
        for end, sign in (("a", -1.0), ("b", 1.0))
    )


def _upper_body(f: PipeFacts, opts: argparse.Namespace) -> str:
    """The upper connector on its drive hinge, holding the whole chain."""
    half_c = f.connector_length / 2.0
    axis = np.asarray(f.axes[0], float)
    pos = np.asarray(f.hinges[0], float) - half_c * axis
    q = _frame(axis, BEND_NORMAL)
    limit_site = f'<site name="h0_p" pos="{half_c - LIMIT_ARM:.12g} 0 0"/>' if _has_limit_tendons(f, opts) else ""
    return f"""<body name="upper" pos="{_fmt(pos)}" quat="{_fmt(q)}">
      {_inertial(f.connector_mass, f.connector_inertia)}
      <joint name="drive" type="hinge" axis="1 0 0"/>
      {limit_site}
      <geom class="visual" type="cylinder" size="{f.connector_radius:.12g} {half_c:.12g}" quat="{Z_TO_X}"/>
      {_chain(f, opts)}
    </body>"""


def mujoco_xml(f: PipeFacts, dt: float, opts: argparse.Namespace) -> tuple[str, dict[str, Any]]:
    """The MJCF text of the chain and the initial joint values it needs (bent chain on the chords).

    The chain is a kinematic tree: upper connector (driven hinge) -> link 1 -> ... -> lower connector,
    whose two ends are held to the world by equalities.
    """
    n = f.joints
    axes = [np.asarray(x, float) for x in f.axes]
    bends = [_signed_bend(axes[h], axes[h + 1], BEND_NORMAL) for h in range(n + 1)]
    tc = opts.solref_timeconst
    ring_geoms, ring = bore_ring(f, ring_step_deg(f, opts), opts.ring_sectors)
    xml = f"""<mujoco model="ballcage-peer-{n}">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="{dt!r}" gravity="0 0 {-f.gravity!r}" integrator="{opts.integrator}" cone="{opts.cone}"/>
  <size memory="{opts.memory}"/>
  <default>
    <joint solreflimit="{tc:g} 1"/>
    <geom contype="0" conaffinity="0" condim="3" friction="{f.mu:.6g} 0 0" solref="{tc:g} 1"/>
    <default class="visual"><geom contype="0" conaffinity="0" group="1" mass="0"/></default>
    <default class="link"><geom contype="1" conaffinity="0" mass="0"/></default>
    <default class="bore"><geom contype="0" conaffinity="1" group="2" rgba=".6 .6 .7 .3"/></default>
  </default>
  <worldbody>
    {_world_sites(f)}
    {"".join(ring_geoms)}
    {_upper_body(f, opts)}
  </worldbody>
  <equality>
    {"".join(_equalities(n, opts))}
  </equality>
  <tendon>
    {"".join(_limit_tendons(f, opts))}
  </tendon>
  <actuator>
    <velocity name="drive" joint="drive" kv="{opts.drive_kv:g}"/>
  </actuator>
</mujoco>
"""
    init = {"bends": bends, "ring": ring}
    return xml, init


@dataclass
class MjModelInfo:
    nbody: int
    njnt: int
    nv: int
    ngeom: int
    neq: int
    ring: Ring


def build_mujoco(f: PipeFacts, dt: float, opts: argparse.Namespace):
    xml, init = mujoco_xml(f, dt, opts)
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    n = f.joints
    for h, beta in enumerate(init["bends"]):
        if opts.cv == "mirror":
            d.joint(f"h{h}_c").qpos[0] = beta
        elif opts.cv == "swing":
            d.joint(f"h{h}_psi1").qpos[0] = math.pi / 2.0
            d.joint(f"h{h}_beta").qpos[0] = beta
            d.joint(f"h{h}_psi2").qpos[0] = -math.pi / 2.0
        else:
            d.joint(f"h{h}_b").qpos[0] = beta
    mujoco.mj_forward(m, d)
    # The placed chain must be ballcage's: link centres at the chord midpoints.
    hinges = np.asarray(f.hinges)
    for k in range(1, n + 1):
        want = 0.5 * (hinges[k - 1] + hinges[k])
        got = d.body(f"link{k}").xpos
        if np.linalg.norm(got - want) > 1e-9:
            raise RuntimeError(f"MuJoCo link {k} placed at {got}, ballcage at {want}")
    for end in ("a", "b"):
        gap = np.linalg.norm(d.site(f"lower_{end}").xpos - d.site(f"world_{end}").xpos)
        if gap > 1e-9:
            raise RuntimeError(f"lower connector closure off by {gap} m at t = 0")
    if d.ncon:
        raise RuntimeError(f"{d.ncon} contacts at t = 0; ballcage has none")
    info = MjModelInfo(m.nbody, m.njnt, m.nv, m.ngeom, m.neq, init["ring"])
    return m, d, info


class MujocoRun:
    """One MuJoCo run of the chain: the drive and the resisting moment applied, each link's tube contact
    normal forces summed over the recorded frames of the window, and what the recording cost."""

    def __init__(
        self, f: PipeFacts, dt: float, duration: float, window: tuple[float, float], opts: argparse.Namespace
    ) -> None:
        self.f, self.dt = f, dt
        self.m, self.d, self.info = build_mujoco(f, dt, opts)
        n = f.joints
        self.link_of_geom = np.zeros(self.m.ngeom, dtype=np.int64)
        for k in range(1, n + 1):
            self.link_of_geom[self.m.geom(f"link{k}").id] = k
        self.lower = self.m.body("lower").id
        self.lower_axis = np.asarray(f.axes[n + 1], float)
        self.stride = max(1, round(f.output_interval / dt))
        self.nsteps = round(duration / dt)
        # the last ramp step sets the final values
        self.ramp_steps = math.ceil(max(f.drive_ramp, f.load_ramp) / dt - 1e-9) + 1
        self.first = math.ceil(window[0] / f.output_interval - 1e-9) * self.stride  # first recorded step index
        self.last = math.floor(window[1] / f.output_interval + 1e-9) * self.stride  # last recorded step index
        self.sums = np.zeros(n + 1)
        self.frames = 0
        self.ncon_sum = 0
        self.force = np.zeros(6)
        self.t_extract = self.c_extract = 0.0  # wall and CPU time of the recording [s]
        self.bad = int(mujoco.mjtWarning.mjWARN_BADQACC)
        self.k = 0  # steps taken

    def controls(self, t: float) -> None:
        """The drive speed and the resisting moment at time `t` [s]."""
        f, d = self.f, self.d
        d.ctrl[0] = _step(t, 0.0, 0.0, f.drive_ramp, f.omega) if f.drive_ramp > 0 else f.omega
        s = _step(t, 0.0, 0.0, f.load_ramp, 1.0) if f.load_ramp > 0 else 1.0
        d.xfrc_applied[self.lower, 3:6] = -f.moment * s * self.lower_axis

    def extract(self) -> None:
        """Records a frame: adds each link's contact normal forces to its sum."""
        m, d = self.m, self.d
        self.frames += 1
        self.ncon_sum += d.ncon
        for i in range(d.ncon):
            c = d.contact[i]
            k = self.link_of_geom[c.geom1] or self.link_of_geom[c.geom2]
            if k and c.efc_address >= 0:
                mujoco.mj_contactForce(m, d, i, self.force)
                self.sums[k] += self.force[0]

    def recorded(self, k: int) -> bool:
        """Whether the state after step `k` is a frame of the window."""
        return self.first <= k <= self.last and k % self.stride == 0

    def next_frame(self, k: int) -> int:
        """The step index of the next recorded frame after step `k` (the run's end once past the window)."""
        if k < self.first:
            return self.first
        return (k // self.stride + 1) * self.stride if k < self.last else self.nsteps

    def advance(self) -> None:
        """Steps to the end of the run, or until MuJoCo reports a bad acceleration (and resets the state)."""
        m, d, dt = self.m, self.d, self.dt
        while self.k < self.nsteps:
            k = self.k
            if d.warning[self.bad].number:  # MuJoCo has reset the state: stop here
                return
            if k < self.ramp_steps or self.recorded(k):
                self.controls(k * dt)
                mujoco.mj_step(m, d)  # its contact forces are those of the state at k*dt
                if self.recorded(k):
                    te, ce = time.perf_counter(), time.process_time()
                    self.extract()
                    self.t_extract += time.perf_counter() - te
                    self.c_extract += time.process_time() - ce
                self.k += 1
            else:  # constant controls, nothing to record: MuJoCo runs the steps up to the next frame in C
                nxt = self.next_frame(k)
                chunk = max(1, min(nxt, self.nsteps, k + MAX_CHUNK) - k)
                mujoco.mj_step(m, d, nstep=chunk)
                self.k += chunk

    def timed_run(self) -> tuple[float, float, str]:
        """Runs to the end: wall and CPU time [s] of the stepping (recording excluded), and why MuJoCo
        stopped ("" if it did not)."""
        fatal = ""
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            self.advance()
        except mujoco.FatalError as e:  # e.g. the arena overflows once a diverging run has thousands of contacts
            fatal = f"MuJoCo stopped by t = {self.k * self.dt:.4g} s: {str(e).splitlines()[0][:120]}"
        wall = time.perf_counter() - t0 - self.t_extract
        cpu = time.process_time() - c0 - self.c_extract
        return wall, cpu, fatal

    def finish(self, fatal: str) -> tuple[str, bool]:
        """The run's note and whether it completed; a complete run records its final frame if it is one."""
        d = self.d
        note, complete = fatal, not fatal
        if complete and (not np.isfinite(d.qpos).all() or d.warning[self.bad].number):
            note, complete = f"unstable by t = {self.k * self.dt:.4g} s (bad qacc; MuJoCo reset the state)", False
        if complete and self.recorded(self.nsteps):  # the frame at the end of the run
            mujoco.mj_forward(self.m, d)
            self.extract()
        return note, complete

    def means(self) -> list[float]:
        """Each link's mean tube normal force over the recorded frames [N], links 1..joints."""
        return [float(self.sums[k] / self.frames) if self.frames else 0.0 for k in range(1, self.f.joints + 1)]

    def extra(self, cpu: float, opts: argparse.Namespace) -> dict[str, Any]:
        """The run's costs (`cpu` [s], recording, MuJoCo's timers per step), contacts and model size."""
        timer = {
            name: self.d.timer[int(getattr(mujoco.mjtTimer, f"mjTIMER_{name.upper()}"))]
            for name in ("step", "pos_collision", "constraint")
        }
        per_step_ms = {
            f"{name}_ms_per_step": (tm.duration / tm.number * 1e3 if tm.number else math.nan)
            for name, tm in timer.items()
        }
        info = self.info
        return {
            "cpu_s": cpu,
            "extract_s": self.t_extract,
            **per_step_ms,
            "mean_ncon_in_window": self.ncon_sum / self.frames if self.frames else math.nan,
            "nbody": info.nbody,
            "nv": info.nv,
            "ngeom": info.ngeom,
            "neq": info.neq,
            "ring_boxes": info.ring.boxes,
            "integrator": opts.integrator,
            "cone": opts.cone,
            "cv": opts.cv,
            "link_geom": opts.link_geom,
            "mujoco": mujoco.__version__,
        }


def run_mujoco(
    f: PipeFacts, dt: float, duration: float, window: tuple[float, float], opts: argparse.Namespace
) -> Result:
    """MuJoCo's run of the chain of `f` at step `dt` for `duration` [s], forces averaged over `window`."""
    run = MujocoRun(f, dt, duration, window, opts)
    wall, cpu, fatal = run.timed_run()
    note, complete = run.finish(fatal)
    extra = run.extra(cpu, opts)
    n, k, frames, means = f.joints, run.k, run.frames, run.means()
    return Result("mujoco", dt, n, duration, wall, k, frames, means, complete, note, extra, reached=k * dt)


# --------------------------------------------------------------------------- comparison and report


def errors(means: list[float], ref: list[float]) -> dict[str, float]:
    a, r = np.asarray(means), np.asarray(ref)
    scale = float(np.abs(r).max()) or 1.0
    return {
        "err_max": float(np.abs(a - r).max() / scale),  # largest per-link error / largest reference mean
        "err_l2": float(np.linalg.norm(a - r) / (np.linalg.norm(r) or 1.0)),
        "err_sum": float(abs(a.sum() - r.sum()) / (abs(r.sum()) or 1.0)),  # total of the per-link means
    }


def default_window(duration: float, facts: PipeFacts) -> tuple[float, float]:
    """The last revolution of the drive, not earlier than the end of the ramps."""
    period = 2.0 * math.pi / facts.omega
    start = max(max(facts.drive_ramp, facts.load_ramp), duration - period)
    return (min(start, duration), duration)


def describe(f: PipeFacts, ring: Ring, opts: argparse.Namespace) -> str:
    lines = [
        f"scene: ballcage paper scene, pipe.hinge=ideal-cv, {f.joints} links, pitch {f.pitch} m, "
        f"overrides {scene_overrides(f.joints) or 'none'}",
        f"  link: cylinder r {f.link_radius} m, mass {f.link_mass} kg (link + one hinge's cage and keys), "
        f"inertia {f.link_inertia} kg m^2",
        f"  connectors: {f.connector_mass} kg, inertia {f.connector_inertia} kg m^2",
        f"  bore: r {f.bore_radius} m on an arc R {f.curvature_radius} m x {math.degrees(f.build_angle):g} deg",
        f"  drive {f.omega:.5g} rad/s (STEP ramp {f.drive_ramp} s); load {f.moment} N m (STEP ramp {f.load_ramp} s)",
        f"  articulation limit {math.degrees(f.beta_max) if f.beta_max else 0:.4g} deg; gravity {f.gravity} m/s^2",
        f"MuJoCo {mujoco.__version__}: integrator {opts.integrator}, cone {opts.cone}, CV as '{opts.cv}', "
        f"link geom {opts.link_geom}, solref timeconst {opts.solref_timeconst} s, drive kv {opts.drive_kv:g}",
        f"  friction mu = {f.mu:.4f} ({f.mu_note})",
        f"  bore ring: {ring.segments} segments x {ring.sectors} sectors = {ring.boxes} boxes; chord error "
        f"circumferential {ring.chord_circumferential * 1e3:.3f} mm (outward), along the arc "
        f"{ring.sagitta_outer * 1e3:.3f} mm outer wall (outward) / "
        f"{ring.sagitta_inner * 1e3:.3f} mm inner wall (inward)",
    ]
    return "\n".join(lines)


def print_tables(results: list[Result], refs: dict[int, Result]) -> list[dict[str, Any]]:
    rows = []
    base = {(r.dt, r.joints): r for r in results if r.engine == "ballcage"}
    for r in results:
        b = base.get((r.dt, r.joints))
        row: dict[str, Any] = {
            "engine": r.engine,
            "dt": r.dt,
            "joints": r.joints,
            "duration": r.duration,
            "wall_s": r.wall_s,
            "rtf": r.rtf,
            "ratio_to_ballcage": (r.wall_s / b.wall_s) if b and r.complete and b.complete else None,
            "cpu_ratio_to_ballcage": (r.extra["cpu_s"] / b.extra["cpu_s"])
            if b and r.complete and b.complete and "cpu_s" in r.extra and "cpu_s" in b.extra
            else None,
            "steps": r.steps,
            "frames": r.frames,
            "complete": r.complete,
            "note": r.note,
            "means": r.means,
        }
        ref = refs.get(r.joints)
        if ref is not None and r.frames:
            row.update(errors(r.means, ref.means))
        if b is not None and r is not b and r.frames and b.frames:
            row["vs_ballcage_same_dt"] = errors(r.means, b.means)
        row.update({f"x_{k}": v for k, v in r.extra.items()})
        rows.append(row)

    print()
    print(
        "| engine | dt [s] | joints | wall of the stepping loop [s] | CPU [s] | real-time factor | wall / ballcage's | "
        "CPU / ballcage's | err max | err L2 | err sum | vs ballcage same dt (L2) |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for row in rows:

        def g(key: str, fmt: str = "{:.3g}", row: dict[str, Any] = row) -> str:
            v = row.get(key)
            return "" if v is None else fmt.format(v)

        same = row.get("vs_ballcage_same_dt", {}).get("err_l2")
        mark = "" if row["complete"] else " (incomplete: " + row["note"] + ")"
        print(
            f"| {row['engine']}{mark} | {row['dt']:g} | {row['joints']} | {row['wall_s']:.3f} | "
            f"{g('x_cpu_s', '{:.3f}')} | {row['rtf']:.3g} | "
            f"{g('ratio_to_ballcage', '{:.3g}')} | {g('cpu_ratio_to_ballcage', '{:.3g}')} | "
            f"{g('err_max')} | {g('err_l2')} | {g('err_sum')} | "
            f"{'' if same is None else f'{same:.3g}'} |"
        )

    for joints, ref in refs.items():
        cols = [r for r in results if r.joints == joints and r.frames and r is not ref]
        print()
        print(
            f"Per-link mean tube normal force [N], {joints} joints, window {ref.extra.get('window')} s; "
            f"reference: ballcage {ref.extra.get('integrator')} at dt {ref.dt:g}"
        )
        head = ["link", f"ref {ref.dt:g}"] + [f"{r.engine} {r.dt:g}" for r in cols]
        print("| " + " | ".join(head) + " |")
        print("|" + "---|" * len(head))
        for k in range(joints):
            vals = [f"{ref.means[k]:.0f}"] + [
                f"{r.means[k]:.0f} ({(r.means[k] - ref.means[k]) / max(abs(ref.means[k]), 1e-9):+.0%})" for r in cols
            ]
            print(f"| {k + 1} | " + " | ".join(vals) + " |")
        tot = [f"{sum(ref.means):.0f}"] + [f"{sum(r.means):.0f}" for r in cols]
        print("| sum | " + " | ".join(tot) + " |")
    return rows


def plot(rows: list[dict[str, Any]], path: Path) -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not installed: no plot", file=sys.stderr)
        return
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    for engine, marker in (("ballcage", "o"), ("mujoco", "s")):
        pts = [(r["wall_s"], r["err_l2"], r["dt"]) for r in rows if r["engine"] == engine and "err_l2" in r]
        if pts:
            ax1.loglog([p[0] for p in pts], [p[1] for p in pts], marker, label=engine)
            for w, e, dt in pts:
                ax1.annotate(f"{dt:g}", (w, e), fontsize=8)
        by_dt: dict[float, list[tuple[int, float]]] = {}
        for r in rows:
            if r["engine"] == engine:
                by_dt.setdefault(r["dt"], []).append((r["joints"], r["wall_s"]))
        for dt, pts2 in by_dt.items():
            pts2.sort()
            if len(pts2) > 1:
                ax2.loglog([p[0] for p in pts2], [p[1] for p in pts2], marker + "-", label=f"{engine} dt {dt:g}")
    ax1.set_xlabel("wall time of the stepping loop [s]")
    ax1.set_ylabel("L2 relative error of per-link mean tube force")
    ax1.set_title("error against ballcage's reference")
    ax1.legend()
    ax2.set_xlabel("joints")
    ax2.set_ylabel("wall time [s]")
    ax2.set_title("scaling")
    if ax2.lines:
        ax2.legend()
    else:  # one number of joints: no scaling panel
        fig.delaxes(ax2)
    if not ax1.lines:
        fig.delaxes(ax1)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"plot: {path}")


def reference(joints: int, dt: float, duration: float, window: tuple[float, float], cache: Path | None) -> Result:
    """ballcage's reference run (its default integrator at a fine step), from `cache` when it holds it."""
    key = f"{joints}|{dt!r}|{duration!r}|{window[0]!r}|{window[1]!r}|{ballcage.__version__}|{scene_overrides(joints)}"
    stored = json.loads(cache.read_text()) if cache is not None and cache.exists() else {}
    if key in stored:
        r = Result(**stored[key])
        r.extra["cached"] = True
        return r
    r = run_ballcage(joints, dt, duration, window)
    r.engine = "ballcage-ref"
    r.extra["window"] = list(window)
    if cache is not None:
        stored[key] = asdict(r)
        cache.parent.mkdir(parents=True, exist_ok=True)
        cache.write_text(json.dumps(stored, indent=1))
    return r


def add_run_arguments(p: argparse.ArgumentParser) -> None:
    """The options of the comparison: steps, chains, window, engines, reference, outputs and the scene."""
    p.add_argument("--dt", type=float, nargs="+", default=[1e-3, 1e-4], help="steps [s] for both engines")
    p.add_argument("--duration", type=float, default=1.8, help="simulated time [s]")
    p.add_argument("--joints", type=int, nargs="+", default=[12], help="numbers of joints (links)")
    p.add_argument(
        "--window",
        type=float,
        nargs=2,
        metavar=("START", "END"),
        default=None,
        help="averaging window [s]; default the last drive revolution, not before the ramps end",
    )
    p.add_argument("--engines", nargs="+", default=["ballcage", "mujoco"], choices=["ballcage", "mujoco"])
    p.add_argument("--reference-dt", type=float, default=2.5e-5, help="step of ballcage's reference run")
    p.add_argument("--no-reference", action="store_true", help="skip the reference run (timing only)")
    p.add_argument(
        "--reference-check",
        action="store_true",
        help="also run ballcage at twice the reference step, to show the reference's own spread",
    )
    p.add_argument(
        "--reference-cache",
        type=Path,
        default=None,
        help="JSON file to keep reference runs in (keyed by joints, step, duration, window) and reuse",
    )
    p.add_argument("--out", type=Path, default=None, help="results file, .json or .csv")
    p.add_argument(
        "--plot", type=Path, default=None, help="PNG of error against wall time and wall time against joints"
    )
    p.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="ballcage scene override applied to both engines (the MuJoCo model is built from the scene)",
    )
    p.add_argument(
        "--fit-arc",
        action="store_true",
        help="for more than 12 joints scale the curvature radius by joints/12, so that the chain fills the arc as "
        "the paper's does; without it the extra links hang straight past the arc, outside the tube",
    )
    p.add_argument("--describe", action="store_true", help="print the MuJoCo model's parameters and exit")
    p.add_argument("--xml", type=Path, default=None, help="also write the MuJoCo model (first joints, first dt) here")


def add_model_arguments(p: argparse.ArgumentParser) -> None:
    """The options of the MuJoCo model, in their own group."""
    g = p.add_argument_group("MuJoCo model")
    g.add_argument(
        "--cv",
        choices=["mirror", "swing", "universal"],
        default="mirror",
        help="mirror: Ry(a1) Rz(c) Ry(a2) with a joint equality a2 = a1 (double-Cardan symmetry), exact CV, "
        "singular only at 90 deg; swing: Rx(psi) Ry(beta) Rx(-psi) with psi2 = -psi1, exact CV but singular at "
        "zero bend (hence --cv-armature); universal: two hinges (Cardan), CV to first order in the bend",
    )
    g.add_argument(
        "--link-geom",
        choices=["capsule", "cylinder"],
        default="capsule",
        help="cylinder-box contacts against the box ring get sideways normals at box edges and diverge",
    )
    g.add_argument("--capsule-half-length", type=float, default=None, help="capsule half length [m]; default pitch/2")
    g.add_argument(
        "--ring-step",
        type=float,
        default=1.5 * math.radians(1.0),
        help="length of one ring of boxes along the centreline [m] (default: 1 deg of the paper's 1.5 m arc)",
    )
    g.add_argument("--ring-sectors", type=int, default=64, help="boxes around the bore")
    g.add_argument("--integrator", default="implicitfast", choices=["Euler", "implicit", "implicitfast", "RK4"])
    g.add_argument("--cone", default="elliptic", choices=["elliptic", "pyramidal"])
    g.add_argument(
        "--solref-timeconst",
        type=float,
        default=0.002,
        help="time constant [s] of contacts, joint limits and equalities (MuJoCo clamps it to >= 2 dt)",
    )
    g.add_argument("--drive-kv", type=float, default=1e5, help="velocity gain of the drive [N m s/rad]")
    g.add_argument(
        "--cv-armature",
        type=float,
        default=1e-2,
        help="armature of the a hinges (mirror) or psi hinges (swing) [kg m^2]: regularizes the tree's mass matrix, "
        "singular at zero bend",
    )
    g.add_argument("--memory", default="64M", help="MuJoCo arena size")


def parser() -> argparse.ArgumentParser:
    """The command line of this script."""
    p = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0], formatter_class=argparse.ArgumentDefaultsHelpFormatter
    )
    add_run_arguments(p)
    add_model_arguments(p)
    return p


def show_model(facts: PipeFacts, joints: int, opts: argparse.Namespace) -> None:
    """Prints how the MuJoCo model of `facts` is built, and writes its MJCF with ``--xml`` (first joints, first dt)."""
    _, ring = bore_ring(facts, ring_step_deg(facts, opts), opts.ring_sectors)
    print(describe(facts, ring, opts))
    if opts.xml and joints == opts.joints[0]:
        opts.xml.write_text(mujoco_xml(facts, opts.dt[0], opts)[0])


def run_references(joints: int, window: tuple[float, float], opts: argparse.Namespace) -> list[Result]:
    """ballcage's reference run for `joints`, and with ``--reference-check`` the one at twice its step."""
    ref = reference(joints, opts.reference_dt, opts.duration, window, opts.reference_cache)
    out = [ref]
    print(f"  reference ballcage dt {opts.reference_dt:g}: {ref.wall_s:.2f} s", flush=True)
    if opts.reference_check:
        check = reference(joints, 2.0 * opts.reference_dt, opts.duration, window, opts.reference_cache)
        check.engine = "ballcage-ref-check"
        out.append(check)
        print(f"  reference check ballcage dt {2.0 * opts.reference_dt:g}: {check.wall_s:.2f} s", flush=True)
    return out


def run_engines(
    facts: PipeFacts, joints: int, window: tuple[float, float], opts: argparse.Namespace
) -> list[Result]:
    """Each engine's run at each step of ``--dt``, forces averaged over `window` [s]."""
    results = []
    for dt in opts.dt:
        for engine in opts.engines:
            if engine == "ballcage":
                r = run_ballcage(joints, dt, opts.duration, window)
            else:
                r = run_mujoco(facts, dt, opts.duration, window, opts)
            r.extra["window"] = list(window)
            results.append(r)
            print(
                f"  {engine} dt {dt:g}, {joints} joints: {r.wall_s:.3f} s"
                + ("" if r.complete else f" INCOMPLETE: {r.note}"),
                flush=True,
            )
    return results


def write_results(
    path: Path, rows: list[dict[str, Any]], refs: dict[int, Result], opts: argparse.Namespace
) -> None:
    """The result rows as CSV (by the suffix), or as JSON with the options, versions and reference runs."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.suffix == ".csv":
        flat = [{k: (json.dumps(v) if isinstance(v, (list, dict)) else v) for k, v in r.items()} for r in rows]
        keys = sorted({k for r in flat for k in r})
        with path.open("w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=keys)
            w.writeheader()
            w.writerows(flat)
    else:
        meta = {
            "argv": sys.argv,
            "options": {k: (str(v) if isinstance(v, Path) else v) for k, v in vars(opts).items()},
            "ballcage": ballcage.__version__,
            "mujoco": getattr(mujoco, "__version__", None),
            "python": platform.python_version(),
            "results": rows,
            "references": {j: asdict(r) for j, r in refs.items()},
        }
        path.write_text(json.dumps(meta, indent=1))
    print(f"results: {path}")


def main(argv: list[str] | None = None) -> int:
    p = parser()
    opts = p.parse_args(argv)
    SCENE_SETTINGS.update(overrides=list(opts.overrides), fit_arc=opts.fit_arc)

    if "mujoco" in opts.engines and mujoco is None:
        p.error("MuJoCo is not installed: pip install mujoco (or pip install '.[bench]')")

    results: list[Result] = []
    refs: dict[int, Result] = {}
    print(
        f"ballcage {ballcage.__version__}"
        + (f", mujoco {mujoco.__version__}" if mujoco else "")
        + f", Python {platform.python_version()}, {platform.machine()}"
    )
    for joints in opts.joints:
        facts = pipe_facts(ballcage_scene(joints, opts.dt[0], opts.duration))
        window = tuple(opts.window) if opts.window else default_window(opts.duration, facts)
        if mujoco is not None:
            show_model(facts, joints, opts)
            if opts.describe:
                return 0
        print(f"window {window[0]:.4g}-{window[1]:.4g} s")
        if not opts.no_reference:
            references = run_references(joints, window, opts)
            refs[joints] = references[0]
            results += references
        results += run_engines(facts, joints, window, opts)
    rows = print_tables(results, refs)
    if opts.out:
        write_results(opts.out, rows, refs, opts)
    if opts.plot:
        plot(rows, opts.plot)
    return 0

if __name__ == "__main__":
    sys.exit(main())
