"""A drill-pipe run as the view draws it: the chain's poses over chosen frames, its tube forces, and the tube.

Poses come from the ``bodies`` table where it holds the links' bodies (the
body x axis is the link axis, as the drill pipe places them: crates/
ballcage-core/src/drillpipe/expand.rs, ``Placement``; the body y axis shows
the spin); otherwise from the ``links`` table (``com_*`` and the eq. (4)
angles: the axis, but not the spin). Ball keys are drawn where the ``bodies``
table holds their poses (a scene recording them in ``record.bodies``); the
bodies are then drawn a cage length shorter at each hinge, so that the keys
inside the joints show. Bodies are told apart by the ``bodies`` table's part
ids (``part``, ``link``, ``hinge``, ``key``), never by their names. The
geometry is the run's own scene (``scene.toml``), and the tube's centreline
is the native module's (`ballcage.Scene.centreline`). Everything is SI (m, s, N).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from ballcage import _native
from ballcage._native import InputError
from ballcage.run import Run

__all__ = ["ChainFrames", "TubeShape", "chain_frames", "read_run", "tube_shape"]

#: Columns the view reads from each table it uses.
_COLUMNS: dict[str, tuple[str, ...]] = {
    "bodies": ("t", "part", "link", "hinge", "key", "pos_x", "pos_y", "pos_z", "quat_w", "quat_x", "quat_y", "quat_z"),
    "links": ("t", "link", "com_x", "com_y", "com_z", "inclination_deg", "azimuth_deg", "tube_normal"),
}
#: ``bodies.part`` labels of the connectors, links and ball keys (crates/ballcage-core/src/drillpipe/layout.rs, `Part::LABELS`).
UPPER, LOWER, LINK, KEY = "upper", "lower", "link", "key"
#: Two frame times closer than this [s] are the same frame.
_TIME_TOLERANCE = 1e-9
#: Spacing [m] of the centreline samples that the tube is drawn through.
TUBE_SPACING = 0.02


@dataclass(frozen=True)
class TubeShape:
    """The guide tube along the chain: centreline samples from above the upper connector to past the lower one."""

    points: np.ndarray  # (M, 3) centreline points [m], world frame
    tangents: np.ndarray  # (M, 3) unit tangents, down the tube
    outward: np.ndarray  # (M, 3) unit normals in the bend plane, toward the outer wall
    inner_radius: float  # [m]
    s: np.ndarray | None = None  # (M,) arc length of each sample along the centreline [m] (negative above its start)


@dataclass(frozen=True)
class ChainFrames:
    """The chain's drawn bodies at the chosen frames: upper connector, links 1…n, lower connector (chain order).

    Connectors are left out when their poses are not recorded (a view from the ``links`` table).
    """

    times: np.ndarray  # (F,) frame times [s]
    labels: tuple[str, ...]  # (B,) "link 1", …, "upper connector"
    is_link: np.ndarray  # (B,) bool: a link (coloured by its tube force) or a connector
    centres: np.ndarray  # (F, B, 3) body centres [m]
    axes: np.ndarray  # (F, B, 3) unit body axes (body x)
    sides: np.ndarray | None  # (F, B, 3) unit body y axes (the spin); None from the links table
    radii: np.ndarray  # (B,) [m]
    lengths: np.ndarray  # (B,) [m]
    tube_force: np.ndarray  # (F, B) links.tube_normal [N]; NaN for connectors or when not recorded
    keys: np.ndarray | None  # (F, K, 3) ball key centres [m]; None when not recorded
    key_radius: float  # [m]
    source: str  # "bodies" or "links"
    tube: TubeShape
    scene_name: str
    complete: bool  # False for a run that stopped early (ballcage.complete = "false")
    scale: float = 1.0  # the links' offsets from the tube centreline are drawn this many times true size
    frame_lengths: np.ndarray | None = None  # (F, B) drawn lengths per frame [m] where a scale stretches them

    def lengths_at(self, f: int) -> np.ndarray:
        """The bodies' drawn lengths [m] at frame `f`: `lengths`, or as a displacement scale stretched them."""
        return self.lengths if self.frame_lengths is None else self.frame_lengths[f]

    @property
    def links(self) -> int:
        """Number of links drawn."""
        return int(self.is_link.sum())


def read_run(directory: str | os.PathLike[str]) -> Run:
    """The run written to `directory` (``ballcage run --out DIR``, `Run.write`): its scene and the tables the view uses.

    Reads ``scene.toml`` and, where present, ``bodies.parquet`` and
    ``links.parquet`` (only the columns the view needs). Raises `InputError`
    naming the path for a missing or unreadable directory or file.
    """
    path = Path(directory)
    if not path.is_dir():
        reason = "not a directory" if path.exists() else "no such directory"
        raise InputError(f"run directory {path}: {reason} (write one with `ballcage run --out DIR`)")
    scene_path = path / "scene.toml"
    try:
        text = scene_path.read_text(encoding="utf-8")
    except FileNotFoundError:
        reason = "no scene.toml, so not a run directory (`ballcage run --out DIR` writes one)"
        raise InputError(f"run directory {path}: {reason}") from None
    except (OSError, UnicodeDecodeError) as e:
        raise InputError(f"{scene_path}: cannot read: {e}") from e
    try:
        scene = _native.Scene.from_toml(text)
    except _native.SceneError as e:
        raise InputError(f"{scene_path}: {e}") from e
    return Run(_read_tables(path), text, scene=scene)


def _read_tables(path: Path) -> dict[str, pa.Table]:
    """The tables the view uses that `path` holds.

    A ``bodies.parquet`` without the part ids (written before they were recorded) is left out: the view then draws
    from the ``links`` table.
    """
    import pyarrow.parquet as pq  # deferred: only readers pay for it

    tables: dict[str, pa.Table] = {}
    for name, columns in _COLUMNS.items():
        file = path / f"{name}.parquet"
        if not file.exists():
            continue
        try:
            if name == "bodies" and not set(columns) <= set(pq.read_schema(file).names):
                continue
            tables[name] = pq.read_table(file, columns=list(columns))
        except (pa.ArrowException, OSError) as e:
            raise InputError(f"{file}: cannot read the columns {', '.join(columns)}: {e}") from e
    return tables


def chain_frames(run: Run, max_frames: int = 120) -> ChainFrames:
    """The chain of a drill-pipe `run` at no more than `max_frames` frames, evenly spaced over the run.

    Raises `InputError` for a run of a generic scene, a `max_frames` below 1,
    or a run that recorded no link poses (neither the links' bodies in
    ``bodies`` nor the ``links`` table).
    """
    if not isinstance(max_frames, int) or max_frames < 1:
        raise InputError(f"max_frames = {max_frames!r}: must be a whole number of at least 1")
    scene = run.scene
    if scene.kind != "drill-pipe":
        raise InputError(f"scene kind = {scene.kind!r}: the view draws drill-pipe runs only")
    links = _nonempty(run.tables.get("links"))
    bodies = _nonempty(run.tables.get("bodies"))
    joints = int(scene.value("pipe.joints"))
    if bodies is not None and set(range(1, joints + 1)) <= set(_chain_positions(bodies, joints)):
        return _from_bodies(run, bodies, links, joints, max_frames)
    if links is not None:
        return _from_links(run, links, joints, max_frames)
    raise InputError(
        "no link poses: the run recorded neither the links' bodies in the bodies table nor the links table; "
        "record them, e.g. `ballcage run --tables bodies,links`"
    )


def _nonempty(table: pa.Table | None) -> pa.Table | None:
    return table if table is not None and table.num_rows else None


def _strings(table: pa.Table, column: str) -> np.ndarray:
    """A (dictionary-encoded) string column as a numpy array of str (None where null)."""
    return np.asarray(pc.cast(table.column(column), pa.string()).to_pylist(), dtype=object)


def _ids(table: pa.Table, column: str) -> np.ndarray:
    """An id column as int64, -1 where null."""
    return pc.cast(table.column(column), pa.int64()).fill_null(-1).to_numpy()


def _chain_positions(bodies: pa.Table, joints: int) -> np.ndarray:
    """Each row's chain position by its part ids: 0 the upper connector, k link k, joints + 1 the lower, else -1."""
    part = _strings(bodies, "part")
    return np.select([part == UPPER, part == LINK, part == LOWER], [0, _ids(bodies, "link"), joints + 1], -1)


def _frames(times: np.ndarray, max_frames: int) -> np.ndarray:
    """At most `max_frames` of the sorted frame `times` [s], evenly spaced, the first and the last included."""
    picked = np.unique(np.round(np.linspace(0, len(times) - 1, min(len(times), max_frames))).astype(int))
    return times[picked]


def _grid(table: pa.Table, times: np.ndarray, ids: np.ndarray, count: int, columns: list[str]) -> np.ndarray:
    """``[frame, id, column]`` of `columns` at `times` [s] for rows with `ids` in 0…count-1 (NaN where missing)."""
    t = table.column("t").to_numpy()
    frame = np.clip(np.searchsorted(times, t - _TIME_TOLERANCE), 0, len(times) - 1)
    keep = (np.abs(times[frame] - t) <= _TIME_TOLERANCE) & (ids >= 0)
    out = np.full((len(times), count, len(columns)), np.nan)
    values = np.column_stack([table.column(c).to_numpy().astype(float) for c in columns])
    out[frame[keep], ids[keep]] = values[keep]
    return out


def _index_of(values: list[object], wanted: list[object]) -> np.ndarray:
    """Position of each of `values` in `wanted`, -1 for values not wanted."""
    position = {v: i for i, v in enumerate(wanted)}
    return np.fromiter((position.get(v, -1) for v in values), dtype=np.int64, count=len(values))


def _key_ids(bodies: pa.Table) -> list[tuple[int, int] | None]:
    """Each row's ``(hinge, key)`` for a ball key's row, None for other bodies."""
    part, hinge, key = _strings(bodies, "part"), _ids(bodies, "hinge"), _ids(bodies, "key")
    return [(int(h), int(j)) if p == KEY else None for p, h, j in zip(part, hinge, key, strict=True)]


def _from_bodies(run: Run, bodies: pa.Table, links: pa.Table | None, joints: int, max_frames: int) -> ChainFrames:
    """The chain from the bodies table: connectors where recorded, every link, and the ball keys where recorded."""
    geometry = _Geometry.of(run.scene)
    positions = _chain_positions(bodies, joints)
    chain = sorted({int(p) for p in positions if p >= 0})  # chain positions recorded, upper connector first
    times = _frames(np.unique(bodies.column("t").to_numpy()), max_frames)
    columns = ["pos_x", "pos_y", "pos_z", "quat_w", "quat_x", "quat_y", "quat_z"]
    grid = _grid(bodies, times, _index_of(list(positions), list(chain)), len(chain), columns)
    whole = np.isfinite(grid).all(axis=(1, 2))  # frames where every body of the chain is recorded
    grid, times = grid[whole], times[whole]
    axes, sides = _body_axes(grid[..., 3:])
    is_link = np.array([0 < p <= joints for p in chain])
    force = np.full((len(times), len(chain)), np.nan)
    if links is not None:
        link_ids = links.column("link").to_numpy().astype(np.int64) - 1
        force[:, is_link] = _grid(links, times, link_ids, joints, ["tube_normal"])[..., 0]
    key_rows = _key_ids(bodies)
    key_ids: list[object] = sorted({k for k in key_rows if k is not None})
    keys = _grid(bodies, times, _index_of(key_rows, key_ids), len(key_ids), columns[:3]) if key_ids else None
    lengths = np.where(is_link, geometry.pitch, geometry.connector_length)
    centres = grid[..., :3]
    if keys is not None:  # open the joints, so that the keys inside them show
        centres, lengths = _open_joints(centres, axes, lengths, chain, joints, geometry.cage_length)
    return ChainFrames(
        times=times,
        labels=tuple(_label(p, joints) for p in chain),
        is_link=is_link,
        centres=centres,
        axes=axes,
        sides=sides,
        radii=np.where(is_link, geometry.link_radius, geometry.connector_radius),
        lengths=lengths,
        tube_force=force,
        keys=keys,
        key_radius=geometry.key_radius,
        source="bodies",
        tube=tube_shape(run.scene),
        scene_name=run.scene.name,
        complete=run.complete,
    )


def _from_links(run: Run, links: pa.Table, joints: int, max_frames: int) -> ChainFrames:
    """The links alone from the links table: centre of mass and the eq. (4) axis; no spin, no connectors, no keys."""
    geometry = _Geometry.of(run.scene)
    times = _frames(np.unique(links.column("t").to_numpy()), max_frames)
    ids = links.column("link").to_numpy().astype(np.int64) - 1
    columns = ["com_x", "com_y", "com_z", "inclination_deg", "azimuth_deg", "tube_normal"]
    grid = _grid(links, times, ids, joints, columns)
    whole = np.isfinite(grid[..., :5]).all(axis=(1, 2))
    grid, times = grid[whole], times[whole]
    phi, theta = np.radians(grid[..., 3]), np.radians(grid[..., 4])
    axes = np.stack([np.sin(phi) * np.cos(theta), np.sin(phi) * np.sin(theta), -np.cos(phi)], axis=-1)
    return ChainFrames(
        times=times,
        labels=tuple(_label(k, joints) for k in range(1, joints + 1)),
        is_link=np.ones(joints, dtype=bool),
        centres=grid[..., :3],
        axes=axes,
        sides=None,
        radii=np.full(joints, geometry.link_radius),
        lengths=np.full(joints, geometry.pitch),
        tube_force=grid[..., 5],
        keys=None,
        key_radius=geometry.key_radius,
        source="links",
        tube=tube_shape(run.scene),
        scene_name=run.scene.name,
        complete=run.complete,
    )


def _open_joints(
    centres: np.ndarray, axes: np.ndarray, lengths: np.ndarray, chain: list[int], joints: int, gap: float
) -> tuple[np.ndarray, np.ndarray]:
    """Bodies drawn `gap` [m] shorter at each hinge: links at both ends, connectors at their hinge end only.

    `chain` holds the bodies' chain positions (0 the upper connector, joints + 1 the lower). The upper connector's
    hinge is at its + end (its axis points down the tube), the lower one's at its − end.
    """
    lengths = np.array(lengths, dtype=float)
    shift = np.zeros(len(chain))
    for b, position in enumerate(chain):
        if position in (0, joints + 1):
            lengths[b] -= gap / 2
            shift[b] = -gap / 4 if position == 0 else gap / 4
        else:
            lengths[b] -= gap
    return centres + shift[None, :, None] * axes, np.maximum(lengths, 0.0)


def _label(position: int, joints: int) -> str:
    """The label of chain position `position`: the connectors by name, links by number."""
    if position == 0:
        return "upper connector"
    if position == joints + 1:
        return "lower connector"
    return f"link {position}"


def _body_axes(quaternions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The body x and y axes (world frame) of unit quaternions ``[..., (w, x, y, z)]``."""
    w, x, y, z = np.moveaxis(quaternions, -1, 0)
    body_x = np.stack([1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)], axis=-1)
    body_y = np.stack([2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x)], axis=-1)
    return body_x, body_y


@dataclass(frozen=True)
class _Geometry:
    """The sizes the view draws with, from the scene [m]."""

    pitch: float
    link_radius: float
    connector_length: float
    connector_radius: float
    key_radius: float
    cage_length: float
    tube_radius: float
    joints: int

    @staticmethod
    def of(scene: _native.Scene) -> _Geometry:
        value = scene.value
        return _Geometry(
            pitch=float(value("pipe.pitch")),
            link_radius=float(value("pipe.link_diameter")) / 2,
            connector_length=float(value("pipe.connector_length")),
            connector_radius=float(value("pipe.connector_diameter")) / 2,
            key_radius=float(value("pipe.ball_keys.ball_radius")),
            cage_length=float(value("pipe.ball_keys.cage_length")),
            tube_radius=float(value("borehole.inner_diameter")) / 2,
            joints=int(value("pipe.joints")),
        )


def tube_shape(scene: _native.Scene, spacing: float = TUBE_SPACING) -> TubeShape:
    """The tube around the chain: the scene's centreline (`ballcage.Scene.centreline`) every `spacing` [m].

    It starts one connector length above the chain's top hinge (the centreline's
    start, continued straight back up, where the upper connector sits) and
    ends one pitch past the lower connector, measured along the centreline.
    """
    geometry = _Geometry.of(scene)
    total = float(scene.centreline(2)["s"][-1])
    count = min(max(math.ceil(total / spacing) + 1, 2), 20_000)
    line = scene.centreline(count)
    s = np.asarray(line["s"])
    reach = geometry.joints * geometry.pitch + geometry.connector_length + geometry.pitch
    keep = s <= reach + spacing
    points, tangents, outward = (np.asarray(line[k], dtype=float)[keep] for k in ("point", "tangent", "outward"))
    top = points[0] - geometry.connector_length * tangents[0]
    return TubeShape(
        points=np.vstack([top, points]),
        tangents=np.vstack([tangents[0], tangents]),
        outward=np.vstack([outward[0], outward]),
        inner_radius=geometry.tube_radius,
        s=np.concatenate([[-geometry.connector_length], s[keep]]),
    )
