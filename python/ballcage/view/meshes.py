"""Triangle meshes of the view: the chain's bodies as cylinders, the tube as a ring-swept surface, spin marks.

Vectorised over any leading shape (frames, bodies): a cylinder's vertices are
``[..., vertex, xyz]`` with one fixed triangle list for all of them. Lengths in m.
"""

from __future__ import annotations

import numpy as np

from ballcage.view.poses import TubeShape

__all__ = [
    "CYLINDER_SIDES",
    "cylinder_triangles",
    "cylinder_vertices",
    "perpendicular",
    "spin_marks",
    "tube_mesh",
    "tube_rings",
]

#: Sides of the prism a cylinder is drawn as.
CYLINDER_SIDES = 16
#: Sides of the tube's rings.
TUBE_SIDES = 24
#: A spin mark stands off the cylinder surface by this fraction of the radius, so it is never hidden by it.
MARK_STANDOFF = 1.04


def perpendicular(axes: np.ndarray, sides: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """Unit vectors u, v with (axis, u, v) right-handed: u the part of `sides` across the axis.

    Without `sides`, u is any direction across the axis (the view from the
    links table, where the spin is not known).
    """
    if sides is None:
        reference = np.broadcast_to(np.array([0.0, 1.0, 0.0]), axes.shape)
        parallel = np.abs(axes[..., 1]) > 0.9
        sides = np.where(parallel[..., None], np.array([1.0, 0.0, 0.0]), reference)
    u = sides - np.sum(sides * axes, axis=-1, keepdims=True) * axes
    u = u / np.linalg.norm(u, axis=-1, keepdims=True)
    return u, np.cross(axes, u)


def cylinder_vertices(
    centres: np.ndarray,
    axes: np.ndarray,
    sides: np.ndarray | None,
    radii: np.ndarray,
    lengths: np.ndarray,
    count: int = CYLINDER_SIDES,
) -> np.ndarray:
    """Vertices ``[..., 2·count + 2, 3]`` [m]: the ring at the axis's − end, the ring at its + end, the two cap centres.

    `centres`, `axes` (unit) and `sides` are ``[..., 3]``; `radii` and
    `lengths` [m] broadcast against ``[...]``. Vertex 0 of each ring lies
    along u of `perpendicular`, so that it turns with the body.
    """
    u, v = perpendicular(axes, sides)
    angle = 2 * np.pi * np.arange(count) / count
    r = np.asarray(radii)[..., None, None]
    ring = r * (np.cos(angle)[:, None] * u[..., None, :] + np.sin(angle)[:, None] * v[..., None, :])
    half = (0.5 * np.asarray(lengths))[..., None] * axes
    bottom, top = centres - half, centres + half
    return np.concatenate(
        [bottom[..., None, :] + ring, top[..., None, :] + ring, bottom[..., None, :], top[..., None, :]], axis=-2
    )


def cylinder_triangles(count: int = CYLINDER_SIDES) -> np.ndarray:
    """Triangles ``[T, 3]`` (vertex indices of `cylinder_vertices`): two per side, `count` per cap."""
    s = np.arange(count)
    nxt = (s + 1) % count
    wall = np.concatenate([np.stack([s, nxt, count + nxt], 1), np.stack([s, count + nxt, count + s], 1)])
    bottom = np.stack([np.full(count, 2 * count), nxt, s], 1)
    top = np.stack([np.full(count, 2 * count + 1), count + s, count + nxt], 1)
    return np.concatenate([wall, bottom, top])


def tube_mesh(tube: TubeShape, count: int = TUBE_SIDES) -> tuple[np.ndarray, np.ndarray]:
    """The tube wall at its inner radius: vertices ``[M·count, 3]`` [m] and triangles ``[T, 3]``."""
    binormal = np.cross(tube.tangents, tube.outward)
    angle = 2 * np.pi * np.arange(count) / count
    ring = np.cos(angle)[:, None] * tube.outward[:, None, :] + np.sin(angle)[:, None] * binormal[:, None, :]
    vertices = (tube.points[:, None, :] + tube.inner_radius * ring).reshape(-1, 3)
    rings = len(tube.points)
    first = (np.arange(rings - 1)[:, None] * count + np.arange(count)[None, :]).ravel()
    nxt = (np.arange(rings - 1)[:, None] * count + ((np.arange(count) + 1) % count)[None, :]).ravel()
    triangles = np.concatenate(
        [np.stack([first, nxt, nxt + count], 1), np.stack([first, nxt + count, first + count], 1)]
    )
    return vertices, triangles


def tube_rings(tube: TubeShape, every: int, count: int = TUBE_SIDES) -> np.ndarray:
    """Closed rings of the tube wall at every `every`-th centreline sample, ``[R, count + 1, 3]`` [m]: its outline."""
    points, tangents, outward = tube.points[::every], tube.tangents[::every], tube.outward[::every]
    binormal = np.cross(tangents, outward)
    angle = 2 * np.pi * np.arange(count + 1) / count
    ring = np.cos(angle)[:, None] * outward[:, None, :] + np.sin(angle)[:, None] * binormal[:, None, :]
    return points[:, None, :] + tube.inner_radius * ring


def spin_marks(centres: np.ndarray, axes: np.ndarray, sides: np.ndarray, radii: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """Two lines along each body's surface, on its +y and −y sides, ``[..., 2, 2, 3]`` (mark, end, xyz) [m].

    They show the body turning about its axis; with two, one always faces the viewer.
    """
    u, _ = perpendicular(axes, sides)
    offset = (MARK_STANDOFF * np.asarray(radii))[..., None] * u
    half = (0.5 * np.asarray(lengths))[..., None] * axes
    marks = [np.stack([centres - half + sign * offset, centres + half + sign * offset], axis=-2) for sign in (1.0, -1.0)]
    return np.stack(marks, axis=-3)
