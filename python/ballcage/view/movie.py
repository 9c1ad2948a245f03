"""The view as a GIF or MP4 for reports: the same chain, tube and colours drawn by matplotlib's 3D axes.

GIF frames are written by Pillow (which comes with matplotlib), MP4 by
matplotlib's ffmpeg writer (Debian's ``ffmpeg`` package). Each frame is
rendered with Agg off screen; nothing is shown.
"""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ballcage._native import InputError
from ballcage._plot import colormap, figure
from ballcage.view.meshes import cylinder_vertices, spin_marks, tube_mesh
from ballcage.view.page import COLORSCALE
from ballcage.view.poses import ChainFrames

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["ffmpeg_available", "write_gif", "write_mp4"]

#: Frame size [px] (even, as H.264 in yuv420p needs) at `_DPI`.
_SIZE_PX = (960, 640)
_DPI = 100
#: Sides of the drawn cylinders and tube rings (coarser than the page's: Agg draws every polygon each frame).
_SIDES, _TUBE_SIDES = 12, 16
#: Spacing [m] of the tube's rings in the movie.
_TUBE_SPACING = 0.06
#: Where the light comes from (world frame), for the flat shading of the bodies.
_LIGHT = np.array([0.3, -0.8, 0.5]) / np.linalg.norm([0.3, -0.8, 0.5])


def ffmpeg_available() -> bool:
    """Whether matplotlib finds ``ffmpeg`` (``rcParams["animation.ffmpeg_path"]``, by default on the PATH)."""
    import matplotlib

    return shutil.which(matplotlib.rcParams["animation.ffmpeg_path"]) is not None


def write_gif(chain: ChainFrames, tmp: Path, fps: float) -> None:
    """Writes the animation of `chain` as an endlessly looping GIF to `tmp` at `fps` frames per second."""
    from PIL import Image

    images = [Image.fromarray(rgba).convert("RGB").quantize(colors=255) for rgba in _rendered(chain)]
    images[0].save(tmp, format="GIF", save_all=True, append_images=images[1:], duration=round(1000 / fps), loop=0, optimize=False)


def write_mp4(chain: ChainFrames, tmp: Path, fps: float) -> None:
    """Writes the animation of `chain` as H.264 MP4 to `tmp` at `fps` frames per second; needs ffmpeg."""
    from matplotlib.animation import FFMpegWriter

    if not ffmpeg_available():
        raise InputError("writing .mp4 needs ffmpeg (Debian: apt-get install ffmpeg); write .gif or .html instead")
    # matplotlib types fps as int; ffmpeg's -r takes any rate
    writer = FFMpegWriter(fps=fps, codec="libx264", extra_args=["-pix_fmt", "yuv420p", "-f", "mp4"])  # type: ignore[arg-type]
    fig, update = _scene_figure(chain)
    with writer.saving(fig, str(tmp), dpi=_DPI):
        for f in range(len(chain.times)):
            update(f)
            writer.grab_frame()


def _rendered(chain: ChainFrames) -> Iterator[np.ndarray]:
    """The frames as RGBA arrays ``[height, width, 4]``."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig, update = _scene_figure(chain)
    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    for f in range(len(chain.times)):
        update(f)
        canvas.draw()
        yield np.asarray(canvas.buffer_rgba()).copy()


def _scene_figure(chain: ChainFrames) -> tuple[Figure, Any]:
    """The figure with the tube drawn and an ``update(frame)`` that moves the chain, keys and marks."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    fig = figure(figsize=(_SIZE_PX[0] / _DPI, _SIZE_PX[1] / _DPI), dpi=_DPI)
    ax = fig.add_subplot(projection="3d")
    _draw_tube(ax, chain)
    _frame_axes(ax, chain)
    force = chain.tube_force[:, chain.is_link]
    peak = float(np.nanmax(force)) if np.isfinite(force).any() else 0.0
    norm, cmap = Normalize(0.0, peak if peak > 0 else 1.0), colormap(COLORSCALE.lower())
    if np.isfinite(force).any():
        fig.colorbar(ScalarMappable(norm, cmap), ax=ax, shrink=0.6, label="tube force [N]")
    bodies = Poly3DCollection([], edgecolor="none")
    ax.add_collection3d(bodies)
    marks = [ax.plot([], [], [], color="white", lw=1.2)[0] for _ in range(2 * len(chain.labels))] if chain.sides is not None else []
    towards_viewer = _towards_viewer(ax)
    keys = ax.scatter([], [], [], s=4, color="#404040", depthshade=False) if chain.keys is not None else None

    def update(f: int) -> None:
        polygons, colours = _body_polygons(chain, f, norm, cmap)
        bodies.set_verts(polygons)
        bodies.set_facecolor(colours)
        if marks:
            sides = chain.sides[f]  # type: ignore[index]
            ends = spin_marks(chain.centres[f], chain.axes[f], sides, chain.radii, chain.lengths_at(f)).reshape(-1, 2, 3)
            centres = np.repeat(chain.centres[f], 2, axis=0)
            facing = (ends.mean(axis=1) - centres) @ towards_viewer > 0  # marks on the far side are hidden
            for line, (a, b), shown in zip(marks, ends, facing):
                line.set_data_3d([a[0], b[0]], [a[1], b[1]], [a[2], b[2]])
                line.set_visible(bool(shown))
        if keys is not None:
            keys._offsets3d = tuple(chain.keys[f].T)  # type: ignore[index]  # mplot3d has no public setter
        ax.set_title(f"{chain.scene_name}\nt = {chain.times[f]:.3f} s", fontsize=10)

    update(0)
    FigureCanvasAgg(fig).draw()
    fig.set_layout_engine("none")  # laid out once: constrained layout on every frame would double the cost
    return fig, update


def _towards_viewer(ax: Any) -> np.ndarray:
    """Unit vector from the scene toward the camera of `ax` (its elevation and azimuth)."""
    elev, azim = np.radians(ax.elev), np.radians(ax.azim)
    return np.array([np.cos(elev) * np.cos(azim), np.cos(elev) * np.sin(azim), np.sin(elev)])


def _body_polygons(chain: ChainFrames, f: int, norm: Any, cmap: Any) -> tuple[list[np.ndarray], np.ndarray]:
    """Each body's side quads and two caps at frame `f`, and their shaded colours (links by tube force)."""
    sides = chain.sides[f] if chain.sides is not None else None
    vertices = cylinder_vertices(chain.centres[f], chain.axes[f], sides, chain.radii, chain.lengths_at(f), _SIDES)
    s = np.arange(_SIDES)
    nxt = (s + 1) % _SIDES
    polygons: list[np.ndarray] = []
    colours: list[np.ndarray] = []
    for b in range(len(chain.labels)):
        v = vertices[b]
        quads = np.stack([v[s], v[nxt], v[_SIDES + nxt], v[_SIDES + s]], axis=1)
        faces = [*quads, v[:_SIDES], v[_SIDES : 2 * _SIDES]]
        force = chain.tube_force[f, b]
        base = np.array(cmap(norm(force if np.isfinite(force) else 0.0))) if chain.is_link[b] else np.array([0.55, 0.55, 0.55, 1.0])
        for face in faces:
            normal = np.cross(face[1] - face[0], face[2] - face[0])
            light = abs(float(normal @ _LIGHT)) / (float(np.linalg.norm(normal)) or 1.0)
            colours.append(np.concatenate([base[:3] * (0.45 + 0.55 * light), [1.0]]))
        polygons.extend(faces)
    return polygons, np.array(colours)


def _draw_tube(ax: Any, chain: ChainFrames) -> None:
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    from ballcage.view.poses import TubeShape

    tube = chain.tube
    step = max(1, round(_TUBE_SPACING / max(float(np.linalg.norm(tube.points[2] - tube.points[1])), 1e-9)))
    coarse = TubeShape(tube.points[::step], tube.tangents[::step], tube.outward[::step], tube.inner_radius)
    vertices, triangles = tube_mesh(coarse, _TUBE_SIDES)
    walls = Poly3DCollection(vertices[triangles], facecolor=(0.62, 0.71, 0.78, 0.10), edgecolor="none")
    ax.add_collection3d(walls)


def _frame_axes(ax: Any, chain: ChainFrames) -> None:
    """Equal scales on x, y, z around the whole chain and tube, labelled in m, seen across the bend plane."""
    points = np.concatenate([chain.tube.points, chain.centres.reshape(-1, 3)])
    low, high = points.min(axis=0) - chain.tube.inner_radius, points.max(axis=0) + chain.tube.inner_radius
    centre, half = (low + high) / 2, max(float((high - low).max()) / 2, 1e-3)
    spans = np.maximum(high - low, 0.25 * half)
    for set_lim, c, span in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre, spans):
        set_lim(c - span / 2, c + span / 2)
    ax.set_box_aspect(tuple(spans))
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.set_yticks([round(float(centre[1]), 2)])  # the bend is in x-z: y spans the tube only
    ax.view_init(elev=12, azim=-80)
    ax.computed_zorder = False  # drawn in the order added: tube, bodies, then marks and keys on them
