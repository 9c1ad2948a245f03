"""The tube wall's wear from a run's wear map (``wear_map.parquet``, `ballcage.measures.wear_map`): unrolled as a figure, and
sampled on the 3D view's tube mesh.

The wall is unrolled as arc length s along the centreline [m] × azimuth [deg]
(0° the bend's outer wall, 180° its inner wall); the colour is the cell's mean
Archard depth over the run's window [µm].
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pyarrow as pa

from ballcage._native import InputError
from ballcage.view.poses import TubeShape

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["WEAR_FIGURE_FILE", "WEAR_MAP_FILE", "WallWear", "read_wear_map", "wall_mesh", "wall_wear", "wear_figure", "write_wear_figure"]

#: The wear map's file name in a run directory, and its figure's.
WEAR_MAP_FILE = "wear_map.parquet"
WEAR_FIGURE_FILE = "wear_map.png"


class WallWear:
    """The tube wall's wear on a full grid: ``depth[i, j]`` [m] of the cell s ∈ [s_edges[i], s_edges[i+1]] [m],
    azimuth ∈ [angle_edges[j], angle_edges[j+1]] [deg]; the map's parameters in ``params``."""

    def __init__(self, table: pa.Table) -> None:
        rows = [r for r in table.to_pylist() if r["surface"] == "tube"]
        meta = {k.decode(): v.decode() for k, v in (table.schema.metadata or {}).items()}
        if "ballcage.wear_map" not in meta:
            raise InputError(f"not a wear map: columns {table.column_names} (`ballcage run` writes {WEAR_MAP_FILE})")
        self.params: dict[str, float] = json.loads(meta["ballcage.wear_map"])
        cell, step = self.params["cell_length"], self.params["cell_angle_deg"]
        n_around = round(360.0 / step)
        starts = np.array([r["axial_start"] for r in rows]) if rows else np.zeros(1)
        first = int(np.floor(starts.min() / cell + 0.5))
        count = int(np.floor(starts.max() / cell + 0.5)) - first + 1
        self.s_edges = (first + np.arange(count + 1)) * cell
        self.angle_edges = np.arange(n_around + 1) * step
        self.depth = np.zeros((count, n_around))
        for r in rows:
            i = int(np.floor(r["axial_start"] / cell + 0.5)) - first
            j = int(np.floor(r["angle_start"] / step + 0.5))
            self.depth[i, j % n_around] = r["depth"]

    def at(self, s: np.ndarray, angle_deg: np.ndarray) -> np.ndarray:
        """Depth [m] of the cells holding points at arc length `s` [m] and azimuth `angle_deg` (0 outside the map)."""
        i = np.searchsorted(self.s_edges, s, side="right") - 1
        j = np.mod(np.floor(np.asarray(angle_deg) / self.params["cell_angle_deg"]).astype(int), self.depth.shape[1])
        inside = (i >= 0) & (i < self.depth.shape[0])
        return np.where(inside, self.depth[np.clip(i, 0, self.depth.shape[0] - 1), j], 0.0)


def read_wear_map(directory: str | os.PathLike[str]) -> pa.Table | None:
    """The wear map of the run written to `directory`, or ``None`` when it has none."""
    import pyarrow.parquet as pq  # deferred: only readers pay for it

    path = Path(directory) / WEAR_MAP_FILE
    if not path.exists():
        return None
    try:
        return pq.read_table(path)
    except (OSError, pa.ArrowInvalid) as e:
        raise InputError(f"{path}: cannot read: {e}") from e


def wall_wear(table: pa.Table) -> WallWear:
    """The tube wall's part of a wear map on its full grid."""
    return WallWear(table)


def write_wear_figure(table: pa.Table, path: str | os.PathLike[str]) -> Path:
    """The tube wall's wear unrolled (`wear_figure`), written as PNG to `path`, atomically; returns `path`."""
    from ballcage._files import write_png

    return write_png(wear_figure(table), Path(path))


def wear_figure(table: pa.Table) -> Figure:
    """The tube wall's wear unrolled, arc length × azimuth, coloured by depth [µm]."""
    from ballcage._plot import colormap, figure, no_data

    wall = WallWear(table)
    p = wall.params
    fig = figure(figsize=(10.0, 4.8))
    ax = fig.add_subplot()
    deepest = float(wall.depth.max())
    if deepest <= 0.0:
        no_data(ax, "no wear on the tube wall in this run's window")
    else:
        mesh = ax.pcolormesh(wall.s_edges, wall.angle_edges, 1e6 * wall.depth.T, cmap=colormap("viridis"), shading="flat")
        bar = fig.colorbar(mesh, ax=ax)
        bar.set_label("wear depth, cell mean [µm]")
        i, j = np.unravel_index(int(np.argmax(wall.depth)), wall.depth.shape)
        span = p["window_end"] - p["window_start"]
        hours = p["map_depth"] / (deepest / span) / 3600.0 if span > 0 else float("nan")
        ax.plot(
            0.5 * (wall.s_edges[i] + wall.s_edges[i + 1]), 0.5 * (wall.angle_edges[j] + wall.angle_edges[j + 1]),
            marker="o", linestyle="none", markerfacecolor="none", markeredgecolor="red", markersize=12,
            label=f"deepest {1e6 * deepest:.3g} µm: {1e3 * p['map_depth']:g} mm after {hours:.3g} h of this duty",
        )  # fmt: skip
        ax.legend(loc="upper right")
    ax.set_xlabel("arc length s along the tube's centreline [m]")
    ax.set_ylabel("azimuth [deg]: 0 outer wall of the bend, 180 inner")
    ax.set_yticks([0, 90, 180, 270, 360])
    ax.set_title(
        f"Tube wall wear, unrolled: Archard k/H = {p['tube_k_over_h']:.3g} 1/Pa, t = {p['window_start']:g}–"
        f"{p['window_end']:g} s, cells {1e3 * p['cell_length']:g} mm × {p['cell_angle_deg']:g}°"
    )
    return fig


def wall_mesh(tube: TubeShape, wall: WallWear) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The worn cells of the tube wall as quads on the wall: vertices ``[V, 3]`` [m], triangles ``[T, 3]`` and each
    triangle's depth [m]. Only the cells that wore are drawn; each is two triangles between its corners."""
    s_tube = tube.s
    if s_tube is None:
        raise InputError("the tube's arc lengths are unknown: draw it with ballcage.view.tube_shape")
    s_edges = wall.s_edges
    s_edges = s_edges[(s_edges >= s_tube[0]) & (s_edges <= s_tube[-1])]

    def along(values: np.ndarray) -> np.ndarray:
        return np.stack([np.interp(s_edges, s_tube, values[:, c]) for c in range(3)], axis=-1)

    centre, tangent, outward = along(tube.points), along(tube.tangents), along(tube.outward)
    tangent /= np.linalg.norm(tangent, axis=-1, keepdims=True)
    outward -= (outward * tangent).sum(-1, keepdims=True) * tangent
    outward /= np.linalg.norm(outward, axis=-1, keepdims=True)
    binormal = np.cross(tangent, outward)
    angle = np.radians(wall.angle_edges[:-1])
    n = angle.size
    ring = np.cos(angle)[:, None] * outward[:, None, :] + np.sin(angle)[:, None] * binormal[:, None, :]
    vertices = (centre[:, None, :] + tube.inner_radius * ring).reshape(-1, 3)
    first = int(np.searchsorted(wall.s_edges, s_edges[0])) if s_edges.size else 0
    depth = wall.depth[first : first + max(s_edges.size - 1, 0)]
    i, j = np.nonzero(depth > 0.0)
    a, b = i * n + j, i * n + (j + 1) % n
    triangles = np.concatenate([np.stack([a, b, b + n], 1), np.stack([a, b + n, a + n], 1)])
    return vertices, triangles, np.concatenate([depth[i, j], depth[i, j]])
