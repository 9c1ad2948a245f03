"""Internal loads at a link's critical sections: a free-body cut of the rigid link (docs/model.md §8.6).

A link is rigid, so the force and moment its material carries across a plane
section follow from the loads on one side of the cut alone: the contact
forces recorded on that side (``contacts``, each assigned to the side it
acts on by ``pairs``), its share of the link's weight, and its d'Alembert
inertial load (the link's recorded velocities differentiated in time). No
flexible model enters.

Three sections per link, in its body frame (x along the link, the head end
downhole at +pitch/2, the seat end at −pitch/2; docs/model.md §3):

- ``neck``: `fatigue.neck_offset` behind the head's hinge centre; the free
  body is the ball head and its neck, loaded by its hinge's joint contacts
  (keys on the inner race, the cage on the head, the neck on the seat's mouth).
  The link's tube contacts act on the seat's Ø86 tube, never on the Ø62 head.
- ``body``: at the link's centre; the free body is the downhole half, with
  the head's joint contacts and the tube contacts on that half.
- ``seat``: `fatigue.seat_offset` behind the seat's hinge centre; the free
  body is the seat, with its hinge's joint contacts (keys on the outer race,
  the cage in the seat, the mouth under the next link's neck) and the tube
  contacts behind the cut.

The weight and inertia of a piece take the model's mass as it is spread: the
link's envelope tube (`pipe.link_mass`, `pipe.link_inertia`), uniform along
its length.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from ballcage._native import InputError
from ballcage.run import Run

__all__ = ["Section", "SectionLoads", "link_sections", "section_loads"]


@dataclass(frozen=True)
class Section:
    """A plane section of every link and the free body on one side of it."""

    name: str  # "neck", "body" or "seat"
    x: float  # the section's position along the link's axis from its centre [m]
    side: int  # +1: the free body lies at x > `x` (toward the head); −1: at x < `x`
    outer_diameter: float  # [m]
    inner_diameter: float  # [m]
    scf: float  # stress concentration factor K_t [–]
    joints: str  # the link end whose joint contacts load the free body: "head" or "seat"
    tube: bool  # whether the tube contacts on the free body's side of the cut load it

    @property
    def area(self) -> float:
        """Cross-section area [m²]."""
        return float(np.pi / 4.0 * (self.outer_diameter**2 - self.inner_diameter**2))

    @property
    def second_moment(self) -> float:
        """Second moment of area about a diameter, I [m⁴] (the polar moment is 2I)."""
        return float(np.pi / 64.0 * (self.outer_diameter**4 - self.inner_diameter**4))


def link_sections(run: Run) -> list[Section]:
    """The neck, body and seat sections of the run's scene (`[fatigue]` and `pipe.*`); no neck without one."""
    scene = run.scene
    if scene.kind != "drill-pipe":
        raise InputError(f"scene kind = {scene.kind!r}: section loads need a drill-pipe scene")
    half = float(scene.value("pipe.pitch")) / 2.0
    neck_radius = float(scene.value("pipe.neck_radius"))
    link_d = float(scene.value("pipe.link_diameter"))
    seat_bore = float(scene.value("fatigue.seat_bore_diameter"))
    out = []
    if neck_radius > 0.0:
        out.append(Section(
            "neck", half - float(scene.value("fatigue.neck_offset")), 1, 2.0 * neck_radius,
            float(scene.value("fatigue.head_bore_diameter")), float(scene.value("fatigue.neck_scf")), "head", False,
        ))  # fmt: skip
    out.append(Section("body", 0.0, 1, link_d, seat_bore, float(scene.value("fatigue.body_scf")), "head", True))
    out.append(Section(
        "seat", -half + float(scene.value("fatigue.seat_offset")), -1, link_d, seat_bore,
        float(scene.value("fatigue.seat_scf")), "seat", True,
    ))  # fmt: skip
    return out


@dataclass(frozen=True)
class SectionLoads:
    """Internal loads of every link at the sections, per frame, in each link's body frame.

    `force` and `moment` [frame, link index, 3] are what the material on the
    section's +x side exerts on the material on its −x side, the moment about
    the section's centre: x is the axial force N (tension positive) and the
    torque T; y and z are the shear forces and bending moments.
    """

    times: np.ndarray  # [s]
    links: np.ndarray  # link numbers, 1 at the top
    force: dict[str, np.ndarray]  # by section name [N]
    moment: dict[str, np.ndarray]  # by section name [N·m]


@dataclass(frozen=True)
class _Frames:
    """The links' recorded motion: [frame, link index, …] arrays in the world frame."""

    times: np.ndarray
    links: np.ndarray
    rot: np.ndarray  # body → world rotation matrices [F, K, 3, 3]
    pos: np.ndarray
    vel: np.ndarray
    angvel: np.ndarray


def _quat_matrices(q: np.ndarray) -> np.ndarray:
    """Rotation matrices [..., 3, 3] of unit quaternions [..., 4] (w, x, y, z)."""
    w, x, y, z = (q[..., i] for i in range(4))
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], -2)  # fmt: skip


def _columns(table: pa.Table, names: list[str]) -> np.ndarray:
    return np.stack([table.column(n).to_numpy() for n in names], -1)


def _link_frames(bodies: pa.Table) -> tuple[_Frames, dict[str, int]]:
    """The links' motion per frame and the link number of each body name."""
    links_only = bodies.filter(pc.is_valid(bodies.column("link")))
    if links_only.num_rows == 0:
        raise InputError("the bodies table records no link: section loads need every link (record.bodies = [])")
    times = np.unique(links_only.column("t").to_numpy())
    numbers = np.unique(links_only.column("link").to_numpy().astype(np.int64))
    fi = np.searchsorted(times, links_only.column("t").to_numpy())
    li = np.searchsorted(numbers, links_only.column("link").to_numpy().astype(np.int64))
    if links_only.num_rows != len(times) * len(numbers):
        raise InputError("the bodies table misses some link in some frame: section loads need every link every frame")

    def grid(names: list[str]) -> np.ndarray:
        out = np.zeros((len(times), len(numbers), len(names)))
        out[fi, li] = _columns(links_only, names)
        return out

    quat = grid(["quat_w", "quat_x", "quat_y", "quat_z"])
    frames = _Frames(
        times, numbers, _quat_matrices(quat / np.linalg.norm(quat, axis=-1, keepdims=True)),
        grid(["pos_x", "pos_y", "pos_z"]), grid(["vel_x", "vel_y", "vel_z"]),
        grid(["angvel_x", "angvel_y", "angvel_z"]),
    )  # fmt: skip
    names = links_only.column("body").to_pylist()
    return frames, dict(zip(names, links_only.column("link").to_numpy().astype(int).tolist(), strict=True))


@dataclass(frozen=True)
class _LinkLoads:
    """Every recorded contact force on a link, one row each, in the link's body frame."""

    frame: np.ndarray  # frame index
    link: np.ndarray  # link index into `_Frames.links`
    point: np.ndarray  # contact point [n, 3], from the link's centre of mass [m]
    force: np.ndarray  # force on the link [n, 3] [N]
    end: np.ndarray  # "head", "seat" or "tube": which end's joint the pair belongs to, or the tube


def _dictionary_links(column: pa.ChunkedArray, link_of: dict[str, int]) -> np.ndarray:
    """The link number of each row's body (0 for a body that is not a link), looked up once per name."""
    array = column.combine_chunks()
    if isinstance(array, pa.DictionaryArray):
        lookup = np.array([link_of.get(v, 0) for v in array.dictionary.to_pylist()], dtype=np.int64)
        return lookup[array.indices.to_numpy(zero_copy_only=False).astype(np.int64)]
    return np.array([link_of.get(v, 0) for v in array.to_pylist()], dtype=np.int64)


def _contact_loads(contacts: pa.Table, pairs: pa.Table, frames: _Frames, link_of: dict[str, int]) -> _LinkLoads:
    """The force each contact row puts on a link (b gets +F, a gets −F: the contacts table's convention)."""
    feature_of = dict(zip(pairs.column("pair_id").to_pylist(), pairs.column("feature").to_pylist(), strict=True))
    hinge_of = dict(zip(pairs.column("pair_id").to_pylist(), pairs.column("hinge").to_pylist(), strict=True))
    pid = contacts.column("pair_id").to_numpy().astype(np.int64)
    top = int(pid.max()) + 1 if len(pid) else 1
    is_tube = np.array([feature_of.get(i) == "tube" for i in range(top)])
    hinge = np.array([-2 if hinge_of.get(i) is None else hinge_of[i] for i in range(top)], dtype=np.int64)
    f = contacts.column("normal_force").to_numpy()[:, None] * _columns(contacts, ["normal_x", "normal_y", "normal_z"])
    f = f + _columns(contacts, ["tangential_force_x", "tangential_force_y", "tangential_force_z"])
    p = _columns(contacts, ["point_x", "point_y", "point_z"])
    fi = np.clip(np.searchsorted(frames.times, contacts.column("t").to_numpy()), 0, len(frames.times) - 1)
    parts = []
    for name, sign in (("body_b", 1.0), ("body_a", -1.0)):
        k = _dictionary_links(contacts.column(name), link_of)
        on = k > 0
        parts.append((fi[on], k[on], p[on], sign * f[on], pid[on]))
    frame, k, point, force, pair = (np.concatenate(x) for x in zip(*parts, strict=True))
    li = np.searchsorted(frames.links, k)
    end = np.where(
        is_tube[pair], "tube", np.where(hinge[pair] == k, "head", np.where(hinge[pair] == k - 1, "seat", ""))
    )
    rot = frames.rot[frame, li]  # body → world; its transpose takes world vectors into the body frame
    local_point = np.einsum("nji,nj->ni", rot, point - frames.pos[frame, li])
    local_force = np.einsum("nji,nj->ni", rot, force)
    return _LinkLoads(frame, li, local_point, local_force, end)


@dataclass(frozen=True)
class _Mass:
    """The link's mass model: uniform along its length `length` [m], `mass` [kg], axial inertia [kg·m²]."""

    mass: float
    axial_inertia: float
    length: float
    gravity: float  # [m/s²], along −z


def _piece_inertia(section: Section, mass: _Mass, frames: _Frames) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The free body's weight [F, K, 3] [N], d'Alembert force [F, K, 3] [N] (−m·a) and its moment about the
    section's centre [F, K, 3] [N·m] (−dH/dt), in the body frame; accelerations by central differences."""
    half = mass.length / 2.0
    lo, hi = (section.x, half) if section.side > 0 else (-half, section.x)
    m = mass.mass * (hi - lo) / mass.length
    r = np.array([(lo + hi) / 2.0, 0.0, 0.0])  # the piece's centre from the link's centre of mass
    k2 = mass.axial_inertia / (2.0 * mass.mass)  # (r_o² + r_i²)/4 of the envelope tube
    inertia = m * np.array([2.0 * k2, k2 + (hi - lo) ** 2 / 12.0, k2 + (hi - lo) ** 2 / 12.0])
    t = frames.times
    acc = np.gradient(frames.vel, t, axis=0) if len(t) > 1 else np.zeros_like(frames.vel)
    alpha = np.gradient(frames.angvel, t, axis=0) if len(t) > 1 else np.zeros_like(frames.angvel)

    def body(v: np.ndarray) -> np.ndarray:
        return np.einsum("fkji,fkj->fki", frames.rot, v)

    w, a_b, al_b = body(frames.angvel), body(acc), body(alpha)
    g_b = body(np.broadcast_to(np.array([0.0, 0.0, -mass.gravity]), frames.vel.shape))
    a_c = a_b + np.cross(al_b, r) + np.cross(w, np.cross(w, r))
    arm = r - np.array([section.x, 0.0, 0.0])  # the piece's centre from the section's centre
    weight = m * g_b
    d_h = inertia * al_b + np.cross(w, inertia * w) + np.cross(arm, m * a_c)
    return weight, -m * a_c, np.cross(arm, weight) - d_h


def section_loads(run: Run, sections: list[Section] | None = None) -> SectionLoads:
    """The internal force and moment at each of `sections` (default `link_sections`) of every link, every frame.

    Needs the run's ``bodies`` (every link), ``contacts`` (every pair: ``record.contacts = []``) and ``pairs``
    tables and a ball-key hinge: the penalty joints of ``pipe.hinge = "ideal-cv"`` are not in ``contacts``.
    """
    scene = run.scene
    secs = link_sections(run) if sections is None else sections
    if not run.has_ball_keys:
        raise InputError(
            f"pipe.hinge = {scene.value('pipe.hinge')!r}: section loads need the ball-key hinge, whose joint loads "
            "are contacts; the ideal CV joint's forces are not recorded"
        )
    missing = [t for t in ("bodies", "contacts", "pairs") if t not in run.tables]
    if missing:
        raise InputError(f"record.tables lacks {', '.join(missing)}: section loads need bodies, contacts and pairs")
    if scene.value("record.contacts"):
        raise InputError(
            "record.contacts names some pairs only: section loads need every contact (record.contacts = [])"
        )
    frames, link_of = _link_frames(run.tables["bodies"])
    loads = _contact_loads(run.tables["contacts"], run.tables["pairs"], frames, link_of)
    inertia = scene.value("pipe.link_inertia")
    mass = _Mass(
        float(scene.value("pipe.link_mass")), float(inertia[0]), float(scene.value("pipe.pitch")),
        float(scene.value("world.gravity")),
    )  # fmt: skip
    force, moment = {}, {}
    shape = (len(frames.times), len(frames.links), 3)
    for sec in secs:
        beyond = sec.side * (loads.point[:, 0] - sec.x) > 0.0
        on = (loads.end == sec.joints) | ((loads.end == "tube") & sec.tube & beyond)
        f_ext, m_ext = np.zeros(shape), np.zeros(shape)
        idx = (loads.frame[on], loads.link[on])
        np.add.at(f_ext, idx, loads.force[on])
        np.add.at(m_ext, idx, np.cross(loads.point[on] - np.array([sec.x, 0.0, 0.0]), loads.force[on]))
        weight, d_alembert, m_inertial = _piece_inertia(sec, mass, frames)
        # The free body is in equilibrium with its loads, its d'Alembert load and the cut's resultant: the
        # +x side's material carries what the −x side's free body is loaded with, and the reverse.
        total_f, total_m = f_ext + weight + d_alembert, m_ext + m_inertial
        force[sec.name] = total_f if sec.side > 0 else -total_f
        moment[sec.name] = total_m if sec.side > 0 else -total_m
    return SectionLoads(frames.times, frames.links, force, moment)
