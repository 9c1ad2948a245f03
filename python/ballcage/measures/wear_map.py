"""Wear maps of a drill-pipe run: Archard wear depth per cell of each surface the contacts move over.

Read from the recorded frames (``contacts``, ``bodies`` and the pair ids of
``wear`` or ``pairs``): every contact point of every frame is a patch
(`ballcage.measures.wear_patches`) that wears the cells it covers at
k/H·p·v_slip for the time its frame stands for (the output interval, midpoint
rule, cut to ``record.summary_window``). Summed over the frames, a cell's wear
volume over its area is its depth: the *mean* depth over the cell, exact where
the contact's track covers the cell, a lower bound of a groove narrower than
the cell. The surfaces:

- ``tube``: the guide tube's wall, in arc length s along the centreline [m]
  (`ballcage.Scene.centreline`) × azimuth [deg] from the bend's outer wall
  (0°, ``outward``) through tangent × outward (90°) to the inner wall (180°);
- ``link``: each link's outer surface, along its axis from its centre [m] ×
  around it from its body y axis toward body z [deg];
- ``inner-race``, ``outer-race``, ``window``: each key's groove or window
  face, along the axis of the body that carries it [m] (cells a tenth of
  ``wear.map_cell_length``), where that body's pose is recorded (the cage's,
  for a window, only when ``record.bodies`` lists it) and the ``wear`` table
  gives the pair's Hertz patch; the depth is the volume over the cell length
  times the patch's width across the groove.

The frame rate is the assumption: a patch moves less than a cell between
frames (at the paper's 1 ms the link turns 0.6°, its rim crosses 0.5 mm of a
5.1 mm cell), which tests/test_wear_map.py checks by halving the output
interval. Volume is conserved: the map's volume is k/H·Σ F·v·dt over the
frames (the ``wear`` table integrates the same every step).
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from ballcage._native import InputError
from ballcage.measures.wear_grid import deposit, map_table
from ballcage.measures.wear_patches import (
    LinkGeometry,
    Patches,
    TubeContacts,
    frame_weights,
    rotate_into,
    tube_patches,
)
from ballcage.run import Run

__all__ = ["deepest", "hours_line", "wear_map"]

_KEY_FEATURES = ("inner-race", "outer-race", "window")
_CONTACT_COLUMNS = (
    "t", "pair_id", "body_a", "body_b", "normal_force", "slip_speed", "point_x", "point_y", "point_z",
    "tangential_force_x", "tangential_force_y", "tangential_force_z",
)  # fmt: skip


def _settings(run: Run) -> dict[str, float]:
    value = run.scene.value
    steel = "materials.pipe_steel"
    e, nu = float(value(f"{steel}.youngs_modulus")), float(value(f"{steel}.poisson_ratio"))
    h = min(float(value(f"{steel}.hardness")), float(value("materials.key_steel.hardness")))
    return {
        "tube_k_over_h": float(value("wear.tube_coefficient")) / float(value(f"{steel}.hardness")),
        "internal_k_over_h": float(value("wear.internal_coefficient")) / h,
        "threshold_pressure": float(value("wear.threshold_pressure")),
        "cell_length": float(value("wear.map_cell_length")),
        "cell_angle_deg": 360.0 / max(1, round(360.0 / float(value("wear.map_cell_angle_deg")))),
        "map_depth": float(value("wear.map_depth")),
        "e_star": e / (2.0 * (1.0 - nu * nu)),
    }


def _window(run: Run, t_last: float) -> tuple[float, float]:
    w = run.scene.value("record.summary_window")
    if w:
        return float(w[0]), min(float(w[1]), t_last)
    return 0.0, t_last


def _pair_ids(run: Run) -> dict[int, dict[str, Any]]:
    """pair id → its feature, link, hinge, key and (from ``wear``) the largest-pressure patch."""
    for name in ("wear", "pairs"):
        if name in run.tables:
            return {int(r["pair_id"]): r for r in run.tables[name].to_pylist()}
    raise InputError("the wear map needs the pair ids of the `wear` or `pairs` table; record one of them")


class _Poses:
    """The recorded body poses by (frame time, body name)."""

    def __init__(self, bodies: pa.Table) -> None:
        cols = bodies.select(["t", "body", "part", "pos_x", "pos_y", "pos_z", "quat_w", "quat_x", "quat_y", "quat_z"])
        self.times = np.unique(cols.column("t").to_numpy())
        names = [str(n) for n in cols.column("body").to_pylist()]
        self.code = {n: i for i, n in enumerate(dict.fromkeys(names))}
        parts = dict(zip(names, cols.column("part").to_pylist(), strict=True))
        self.keys = {n for n, p in parts.items() if p == "key"}
        self.pose = np.full((self.times.size, len(self.code), 7), np.nan)
        frame = self.frame_of(cols.column("t").to_numpy())
        body = np.array([self.code[n] for n in names])
        values = np.column_stack([cols.column(c).to_numpy() for c in cols.column_names[3:]])
        self.pose[frame, body] = values

    def frame_of(self, t: np.ndarray) -> np.ndarray:
        i = np.clip(np.searchsorted(self.times, t - 1e-9), 0, self.times.size - 1)
        if np.any(np.abs(self.times[i] - t) > 1e-9):
            raise InputError("the contacts table has frames the bodies table lacks; record both at one interval")
        return i

    def body_of(self, body_a: pa.ChunkedArray, body_b: pa.ChunkedArray) -> np.ndarray:
        """The recorded, non-key body of each pair (−1 where neither is recorded); the body names as Arrow columns."""
        a, b = self._codes(body_a), self._codes(body_b)
        return np.where(a >= 0, a, b)

    def _codes(self, names: pa.ChunkedArray) -> np.ndarray:
        """Each name's body code, −1 for a key or a body not recorded: looked up once per distinct name."""
        if pa.types.is_dictionary(names.type):
            names = names.unify_dictionaries()
        column = names.combine_chunks()
        if not pa.types.is_dictionary(column.type):
            column = column.dictionary_encode()
        lut = np.array([self.code.get(n, -1) if n not in self.keys else -1 for n in column.dictionary.to_pylist()],
                       dtype=int)  # fmt: skip
        return lut[column.indices.to_numpy(zero_copy_only=False)]

    def local(self, frame: np.ndarray, body: np.ndarray, points: np.ndarray) -> np.ndarray:
        pose = self.pose[frame, body]
        return rotate_into(pose[:, 3:], points - pose[:, :3])


def _contacts(run: Run, pair_ids: set[int]) -> dict[str, Any] | None:
    table = run.contacts.select(list(_CONTACT_COLUMNS))
    table = table.filter(pc.is_in(table.column("pair_id"), pa.array(sorted(pair_ids), pa.uint32())))
    if table.num_rows == 0:
        return None
    out: dict[str, Any] = {}
    for c in _CONTACT_COLUMNS:
        col = table.column(c)
        out[c] = col if c.startswith("body") else col.to_numpy()
    out["point"] = np.column_stack([out.pop(f"point_{a}") for a in "xyz"])
    tangential = np.column_stack([out.pop(f"tangential_force_{a}") for a in "xyz"])
    out["power"] = np.linalg.norm(tangential, axis=1) * out["slip_speed"] * np.sign(out["normal_force"])
    return out


def _on_tube(run: Run, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Arc length s [m] along the centreline and azimuth φ [rad] from the bend's outer wall of each point."""
    total = float(run.scene.centreline(2)["s"][-1])
    line = run.scene.centreline(min(max(math.ceil(total / 0.002) + 1, 2), 50_000))
    c, t, o = (np.asarray(line[k], dtype=float) for k in ("point", "tangent", "outward"))
    s0 = np.asarray(line["s"], dtype=float)
    nearest = np.empty(len(points), dtype=int)
    for start in range(0, len(points), 1024):
        p = points[start : start + 1024]
        d2 = (p * p).sum(1)[:, None] - 2.0 * p @ c.T + (c * c).sum(1)[None, :]
        nearest[start : start + 1024] = np.argmin(d2, axis=1)
    r = points - c[nearest]
    along = (r * t[nearest]).sum(1)
    r -= along[:, None] * t[nearest]
    b = np.cross(t[nearest], o[nearest])
    phi = np.mod(np.arctan2((r * b).sum(1), (r * o[nearest]).sum(1)), 2.0 * math.pi)
    return s0[nearest] + along, phi


def _tube_part(run: Run, ids: dict[int, dict[str, Any]], poses: _Poses, cfg: dict[str, float], window: tuple[float, float]) -> list[pa.Table]:
    tube_ids = {k for k, r in ids.items() if r["feature"] == "tube"}
    rows = _contacts(run, tube_ids)
    if rows is None:
        return []
    frame = poses.frame_of(rows["t"])
    body = poses.body_of(rows["body_a"], rows["body_b"])
    keep = body >= 0
    local = poses.local(frame[keep], body[keep], rows["point"][keep])
    s, phi = _on_tube(run, rows["point"][keep])
    pair = rows["pair_id"][keep].astype(int)
    contacts = TubeContacts(
        frame=frame[keep],
        pair=pair,
        link=np.array([int(ids[p]["link"] or 0) for p in pair], dtype=int),
        force=rows["normal_force"][keep],
        slip=rows["slip_speed"][keep],
        power=rows["power"][keep],
        dt=frame_weights(rows["t"][keep], window, run.scene.output_interval),
        x=local[:, 0],
        theta=np.mod(np.arctan2(local[:, 2], local[:, 1]), 2.0 * math.pi),
        s=s,
        phi=phi,
    )
    value = run.scene.value
    geometry = LinkGeometry(
        radius=float(value("pipe.link_diameter")) / 2.0,
        half_length=float(value("pipe.pitch")) / 2.0,
        edge=float(value("pipe.link_edge_radius")),
        bore=float(value("borehole.inner_diameter")) / 2.0,
        e_star=cfg["e_star"],
    )
    patches = tube_patches(contacts, geometry)
    k_h = np.full(patches.force.size, cfg["tube_k_over_h"])
    tube = deposit(patches, k_h, cfg, surface="tube", radius=geometry.bore, owner=False)
    link = deposit(patches, k_h, cfg, surface="link", radius=geometry.radius, owner=True, half_length=geometry.half_length)
    return [map_table(tube, "tube", cfg, window), map_table(link, "link", cfg, window)]


def _key_part(run: Run, ids: dict[int, dict[str, Any]], poses: _Poses, cfg: dict[str, float], window: tuple[float, float]) -> list[pa.Table]:
    key_ids = {k for k, r in ids.items() if r["feature"] in _KEY_FEATURES and r.get("pressure_peak_force")}
    rows = _contacts(run, key_ids)
    if rows is None:
        return []
    frame = poses.frame_of(rows["t"])
    body = poses.body_of(rows["body_a"], rows["body_b"])
    keep = (body >= 0) & (rows["normal_force"] > 0.0)
    if not keep.any():
        return []
    x = poses.local(frame[keep], body[keep], rows["point"][keep])[:, 0]
    pair = rows["pair_id"][keep].astype(int)
    f = rows["normal_force"][keep]
    pairs, which = np.unique(pair, return_inverse=True)
    peak = np.array([[ids[p]["semi_major"], ids[p]["semi_minor"], ids[p]["pressure_peak_force"]] for p in pairs])[which]
    scale = np.cbrt(f / peak[:, 2])
    root_pi = math.sqrt(math.pi) / 2.0
    across, along = peak[:, 0] * scale * root_pi, peak[:, 1] * scale * root_pi
    patches = Patches(
        along=np.column_stack([x - along, x + along]),
        around=np.column_stack([-across, across]),
        other_along=None,
        other_around=None,
        force=f,
        area=4.0 * along * across,
        slip=rows["slip_speed"][keep],
        power=rows["power"][keep],
        dt=frame_weights(rows["t"][keep], window, run.scene.output_interval),
        owner=pair,
    )
    k_h = np.full(f.size, cfg["internal_k_over_h"])
    grooves = deposit(patches, k_h, cfg, surface="groove", radius=0.0, owner=True)
    return [map_table(grooves, "groove", cfg, window, ids=ids)]


def wear_map(run: Run) -> pa.Table:
    """The wear map of a drill-pipe `run`: one row per surface cell that wore (columns and units in the schema).

    Needs the run's ``contacts`` and ``bodies`` tables and the pair ids of its
    ``wear`` (or ``pairs``) table; raises `InputError` naming what is missing.
    """
    for name in ("contacts", "bodies"):
        if name not in run.tables:
            raise InputError(f"the wear map needs the run's `{name}` table (record.tables)")
    cfg = _settings(run)
    ids = _pair_ids(run)
    poses = _Poses(run.bodies)
    t = run.contacts.column("t").to_numpy()
    window = _window(run, float(t.max()) if t.size else 0.0)
    parts = _tube_part(run, ids, poses, cfg, window) + _key_part(run, ids, poses, cfg, window)
    table = pa.concat_tables(parts) if parts else map_table(None, "tube", cfg, window)
    meta = dict(table.schema.metadata or {})
    meta[b"ballcage.frame_interval_s"] = repr(run.scene.output_interval).encode()
    return table.replace_schema_metadata(meta)


def deepest(table: pa.Table, surface: str | None = None) -> dict[str, Any] | None:
    """The row of the deepest cell (of `surface`, ``"tube"``, ``"link"``, …, or of all); ``None`` when nothing wore."""
    rows = [r for r in table.to_pylist() if (surface is None or r["surface"] == surface) and r["depth"] > 0.0]
    return max(rows, key=lambda r: r["depth"]) if rows else None


def _where(row: dict[str, Any]) -> str:
    """A cell in words: ``the tube wall, s = 2.00–2.01 m, azimuth 145–150°``."""
    if row["surface"] == "tube":
        return f"the tube wall, s = {row['axial_start']:.2f}–{row['axial_end']:.2f} m, azimuth {row['angle_start']:.0f}–{row['angle_end']:.0f}°"
    if row["surface"] == "link":
        return (
            f"link {row['link']}'s surface, {1e3 * row['axial_start']:.0f}–{1e3 * row['axial_end']:.0f} mm from its "
            f"centre, {row['angle_start']:.0f}–{row['angle_end']:.0f}° round it"
        )
    return f"the {row['surface']} of {row['pair']}, {1e3 * row['axial_start']:.1f}–{1e3 * row['axial_end']:.1f} mm along"


def hours_line(table: pa.Table) -> str | None:
    """One line: where the map reaches ``wear.map_depth`` first and after how many hours of the run's duty."""
    row = deepest(table)
    if row is None:
        return None
    meta = {k.decode(): v.decode() for k, v in (table.schema.metadata or {}).items()}
    params = json.loads(meta["ballcage.wear_map"])
    where = _where(row)
    tube = deepest(table, "tube")
    tail = f"; on {_where(tube)}: {tube['hours_to_depth']:.3g} h" if tube is not None and tube != row else ""
    cell = (
        f"a {1e3 * params['cell_length']:g} mm × {params['cell_angle_deg']:g}° cell"
        if row["angle_start"] is not None
        else f"a {1e2 * params['cell_length']:g} mm cell along the groove"
    )
    return (
        f"wear map: {1e3 * params['map_depth']:g} mm of wear first at {where} after {row['hours_to_depth']:.3g} h "
        f"of this duty (mean depth of {cell}; Archard k/H, scales with k){tail}"
    )
