"""The view as one self-contained HTML page: plotly.js (shipped inside the plotly package) and the frames, offline.

One ``mesh3d`` trace per drawn body (links coloured by their tube force
through one colour axis, connectors grey), the semi-transparent tube, the
spin marks and the ball keys (where recorded); one plotly frame per chosen
run frame, a play/pause menu and a time slider. Numbers go into the page as
plotly.js typed arrays (float32, base64: 0.2 µm resolution over metres):
120 frames of the paper's chain take 2.0 MiB beside the 4.6 MiB library.

After plotly's first render the page appends a hidden marker,
``<div id="ballcage-status" data-link-meshes="N" data-webgl="true|false" ...>``,
read back by the browser test (tests/test_view.py).
"""

from __future__ import annotations

import base64
import html
import math
from typing import Any

import numpy as np

from ballcage.view.meshes import cylinder_triangles, cylinder_vertices, spin_marks, tube_mesh, tube_rings
from ballcage.view.poses import TUBE_SPACING, ChainFrames
from ballcage.view.wear import WallWear, wall_mesh

__all__ = ["COLORSCALE", "STATUS_ID", "view_html"]

#: plotly colour scale of the links' tube force (0 N at its first colour).
COLORSCALE = "Viridis"
#: id of the marker the page writes after its first render.
STATUS_ID = "ballcage-status"
#: Static traces before the moving ones: the tube's wall and its rings (and its worn cells, when coloured by wear).
TUBE_TRACES = 2
#: plotly colour scale of the tube wall's wear depth, 0 to the deepest cell: orange to dark red, apart from the
#: links' viridis (only worn cells are drawn, so even the shallowest is saturated).
WEAR_COLORSCALE = [[0.0, "#feb24c"], [0.5, "#f03b20"], [1.0, "#800026"]]
#: Opacity of the tube wall: more would show WebGL's blending as swirls over the links behind it.
_TUBE_OPACITY = 0.1
#: Spacing [m] of the rings outlining the tube.
_RING_SPACING = 0.1
#: Colours of what is not coloured by force.
_CONNECTOR, _TUBE, _MARKS, _KEYS = "#8c8c8c", "#9db4c8", "#ffffff", "#404040"
#: After the first render: go to the frame nearest ``#t=<seconds>`` in the address, if given, then write the
#: marker of what plotly built (for tests, and for anyone checking a page): link meshes in the data and in the
#: WebGL scene, frames, keys, and the scene's box in CSS pixels (left, top, right, bottom) for screenshots.
_STATUS_SCRIPT = """
var gd = document.getElementById('{plot_id}');
var frames = (gd._transitionData || {})._frames || [];
var wanted = /[#&]t=([0-9.eE+-]+)/.exec(window.location.hash);
var ready = Promise.resolve();
if (wanted && frames.length) {
  var best = frames[0];
  frames.forEach(function (f) { if (Math.abs(+f.name - +wanted[1]) < Math.abs(+best.name - +wanted[1])) { best = f; } });
  ready = Plotly.animate(gd, [best.name], {mode: 'immediate', frame: {duration: 0, redraw: true}, transition: {duration: 0}});
}
ready.then(function () {
  var full = gd._fullData || [];
  var layout = gd._fullLayout;
  var scene = layout.scene && layout.scene._scene;
  var links = full.filter(function (t) { return t.type === 'mesh3d' && t.meta === 'link' && t.visible === true; });
  var drawn = scene && scene.glplot ? links.filter(function (t) {
    var gl = scene.traces[t.uid]; return gl && gl.mesh && scene.glplot.objects.indexOf(gl.mesh) >= 0;
  }).length : 0;
  var keys = full.filter(function (t) { return t.meta === 'keys'; });
  var r = gd.getBoundingClientRect(), size = layout._size, domain = layout.scene.domain;
  var box = [r.left + size.l + domain.x[0] * size.w, r.top + size.t + (1 - domain.y[1]) * size.h,
             r.left + size.l + domain.x[1] * size.w, r.top + size.t + (1 - domain.y[0]) * size.h];
  var marker = document.createElement('div');
  marker.id = 'STATUS_ID';
  marker.hidden = true;
  marker.setAttribute('data-link-meshes', String(links.length));
  marker.setAttribute('data-drawn-link-meshes', String(drawn));
  marker.setAttribute('data-webgl', String(!!(scene && scene.glplot)));
  marker.setAttribute('data-frames', String(frames.length));
  marker.setAttribute('data-keys', String(keys.length ? keys[0]._length || 0 : 0));
  marker.setAttribute('data-scene-box', box.map(Math.round).join(','));
  marker.setAttribute('data-time', wanted && frames.length ? best.name : frames.length ? frames[0].name : '');
  var meta = (gd.layout && gd.layout.meta) || {};
  marker.setAttribute('data-scale', String(meta.scale || 1));
  var wear = full.filter(function (t) { return t.meta === 'wear'; });
  marker.setAttribute('data-wear-faces', String(wear.length ? wear[0].intensity.length : 0));
  var wearGl = wear.length && scene && scene.glplot ? scene.traces[wear[0].uid] : null;
  marker.setAttribute('data-drawn-wear', String(!!(wearGl && wearGl.mesh && scene.glplot.objects.indexOf(wearGl.mesh) >= 0)));
  document.body.appendChild(marker);
});
""".replace("STATUS_ID", STATUS_ID)


def view_html(chain: ChainFrames, fps: float = 12.0, wall: WallWear | None = None) -> str:
    """The page (HTML text) animating `chain` at `fps` frames per second, with plotly.js embedded; with `wall`, the
    tube wall's worn cells drawn coloured by their wear depth (`ballcage.view.wear`)."""
    import plotly.io as pio  # deferred: only the view needs plotly

    static = _tube(chain, wall)
    figure = {"data": _traces(chain, 0, static), "frames": _frames(chain, len(static)), "layout": _layout(chain, fps, wall)}
    return pio.to_html(
        figure,
        include_plotlyjs=True,
        full_html=True,
        div_id="ballcage-view",
        default_height="96vh",
        validate=False,
        auto_play=False,
        post_script=_STATUS_SCRIPT,
        config={"displaylogo": False, "responsive": True},
    )


def _typed(values: np.ndarray, decimals: int = 6) -> dict[str, str]:
    """A plotly.js typed array (float32, base64) of `values`, rounded to `decimals` (µm for metres)."""
    data = np.ascontiguousarray(np.round(np.asarray(values, dtype=float), decimals), dtype="<f4")
    return {"dtype": "f4", "bdata": base64.b64encode(data.tobytes()).decode("ascii")}


def _indices(values: np.ndarray) -> dict[str, str]:
    data = np.ascontiguousarray(values, dtype="<u4")
    return {"dtype": "u4", "bdata": base64.b64encode(data.tobytes()).decode("ascii")}


def _force_range(chain: ChainFrames) -> tuple[float, float]:
    """The colour bar's range [N]: 0 to the largest tube force of the shown frames (1 N when none)."""
    force = chain.tube_force[:, chain.is_link]
    peak = float(np.nanmax(force)) if np.isfinite(force).any() else 0.0
    return 0.0, peak if peak > 0 else 1.0


def _bodies(chain: ChainFrames, f: int) -> list[dict[str, Any]]:
    """The drawn bodies at frame `f`: vertices and, for links, the per-vertex tube force [N]."""
    sides = chain.sides[f] if chain.sides is not None else None
    vertices = cylinder_vertices(chain.centres[f], chain.axes[f], sides, chain.radii, chain.lengths_at(f))
    out = []
    for b in range(len(chain.labels)):
        trace: dict[str, Any] = {"x": _typed(vertices[b, :, 0]), "y": _typed(vertices[b, :, 1]), "z": _typed(vertices[b, :, 2])}
        if chain.is_link[b]:
            force = chain.tube_force[f, b]
            trace["intensity"] = _typed(np.full(vertices.shape[1], force if math.isfinite(force) else 0.0), 1)
        out.append(trace)
    return out


def _moving(chain: ChainFrames, f: int) -> list[dict[str, Any]]:
    """Everything that moves at frame `f`: bodies, spin marks, keys (in trace order after the tube)."""
    traces = _bodies(chain, f)
    if chain.sides is not None:
        marks = spin_marks(chain.centres[f], chain.axes[f], chain.sides[f], chain.radii, chain.lengths_at(f))
        traces.append(_polylines(marks.reshape(-1, 2, 3)))
    if chain.keys is not None:
        keys = chain.keys[f]
        traces.append({"x": _typed(keys[:, 0]), "y": _typed(keys[:, 1]), "z": _typed(keys[:, 2])})
    return traces


def _tube(chain: ChainFrames, wall: WallWear | None = None) -> list[dict[str, Any]]:
    """The static traces: the tube's semi-transparent wall (unlit, so it only tints), rings outlining it and, with
    `wall`, its worn cells coloured by depth [µm] (one colour per cell)."""
    vertices, triangles = tube_mesh(chain.tube)
    tint = {
        "type": "mesh3d", "name": "guide tube", "meta": "tube", "opacity": _TUBE_OPACITY, "color": _TUBE,
        "x": _typed(vertices[:, 0]), "y": _typed(vertices[:, 1]), "z": _typed(vertices[:, 2]),
        "i": _indices(triangles[:, 0]), "j": _indices(triangles[:, 1]), "k": _indices(triangles[:, 2]),
        "hoverinfo": "skip", "lighting": {"ambient": 1.0, "diffuse": 0.0, "specular": 0.0, "fresnel": 0.0},
    }
    rings = tube_rings(chain.tube, max(1, round(_RING_SPACING / TUBE_SPACING)))
    outline = {
        "type": "scatter3d", "mode": "lines", "name": "guide tube rings", "meta": "tube", "hoverinfo": "skip",
        "line": {"color": _TUBE, "width": 2}, "connectgaps": False,
    }
    traces = [tint, outline | _polylines(rings)]
    if wall is not None:
        worn, faces, depth = wall_mesh(chain.tube, wall)
        traces.append({
            "type": "mesh3d", "name": "tube wall wear", "meta": "wear", "opacity": 1.0, "coloraxis": "coloraxis2",
            "x": _typed(worn[:, 0]), "y": _typed(worn[:, 1]), "z": _typed(worn[:, 2]),
            "i": _indices(faces[:, 0]), "j": _indices(faces[:, 1]), "k": _indices(faces[:, 2]),
            "intensity": _typed(1e6 * depth, 4), "intensitymode": "cell",
            "hovertemplate": "wear %{intensity:.3g} µm<extra></extra>",
            "lighting": {"ambient": 0.9, "diffuse": 0.2, "specular": 0.0, "fresnel": 0.0},
        })  # fmt: skip
    return traces


def _polylines(lines: np.ndarray) -> dict[str, Any]:
    """``x``, ``y``, ``z`` of one lines trace drawing each of `lines` ``[L, points, 3]`` apart (NaN between them)."""
    gaps = np.concatenate([lines, np.full((len(lines), 1, 3), np.nan)], axis=1).reshape(-1, 3)
    return {"x": _typed(gaps[:, 0]), "y": _typed(gaps[:, 1]), "z": _typed(gaps[:, 2])}


def _traces(chain: ChainFrames, f: int, static: list[dict[str, Any]] | None = None) -> list[dict[str, Any]]:
    """Every trace at frame `f`: the tube's first (`static`, default `_tube`'s), then `_moving`'s."""
    faces = cylinder_triangles()
    styled: list[dict[str, Any]] = []
    moving = _moving(chain, f)
    for b, label in enumerate(chain.labels):
        body = {
            "type": "mesh3d", "name": label, "flatshading": True,  # cap and wall keep their own normals
            "i": _indices(faces[:, 0]), "j": _indices(faces[:, 1]), "k": _indices(faces[:, 2]),
        }
        if chain.is_link[b]:
            hover = f"{label}<br>tube force %{{intensity:.0f}} N<extra></extra>"
            body.update(meta="link", coloraxis="coloraxis", hovertemplate=hover)
        else:
            body.update(meta="connector", color=_CONNECTOR, hovertemplate=f"{label}<extra></extra>")
        styled.append(body | moving[b])
    rest = moving[len(chain.labels):]
    if chain.sides is not None:
        marks = {"type": "scatter3d", "mode": "lines", "name": "spin marks", "meta": "marks", "hoverinfo": "skip"}
        styled.append(marks | {"line": {"color": _MARKS, "width": 4}, "connectgaps": False} | rest.pop(0))
    if chain.keys is not None:
        keys = {"type": "scatter3d", "mode": "markers", "name": "ball keys", "meta": "keys", "hoverinfo": "skip"}
        styled.append(keys | {"marker": {"size": 4, "color": _KEYS}} | rest[0])
    tube = _tube(chain) if static is None else static
    return [*tube, *styled]


def _frames(chain: ChainFrames, static: int = TUBE_TRACES) -> list[dict[str, Any]]:
    count = len(_moving(chain, 0))
    return [
        {"name": _frame_name(chain, f), "data": _moving(chain, f), "traces": list(range(static, static + count))}
        for f in range(len(chain.times))
    ]


def _frame_name(chain: ChainFrames, f: int) -> str:
    return f"{chain.times[f]:.4f}"


def _layout(chain: ChainFrames, fps: float, wall: WallWear | None = None) -> dict[str, Any]:
    cmin, cmax = _force_range(chain)
    recorded = bool(np.isfinite(chain.tube_force[:, chain.is_link]).any())
    axis = {"showbackground": True, "backgroundcolor": "#f4f6f8", "gridcolor": "#d0d4d8"}
    extra: dict[str, Any] = {"meta": {"scale": chain.scale}}
    if wall is not None:
        deepest = 1e6 * float(wall.depth.max())
        extra["coloraxis2"] = {
            "colorscale": WEAR_COLORSCALE, "cmin": 0.0, "cmax": deepest if deepest > 0 else 1.0,
            "colorbar": {
                "title": {"text": "tube wall wear [µm]"}, "len": 0.6, "x": 0.0, "xanchor": "left", "thickness": 18,
                "exponentformat": "e",
            },
        }  # fmt: skip
    return extra | {
        "title": {"text": _title(chain, recorded, wall), "x": 0.02, "font": {"size": 15}},
        "showlegend": False,
        "margin": {"l": 0, "r": 0, "t": 80 if chain.scale != 1.0 or wall is not None else 60, "b": 0},
        "scene": {
            "aspectmode": "data",
            "domain": {"x": [0.0, 0.88], "y": [0.0, 1.0]},
            "xaxis": {"title": {"text": "x [m]"}, **axis},
            "yaxis": {"title": {"text": "y [m]"}, **axis},
            "zaxis": {"title": {"text": "z [m]"}, **axis},
            "camera": {"eye": {"x": 0.8, "y": -3.0, "z": 0.7}, "center": {"x": 0, "y": 0, "z": -0.08}, "up": {"x": 0, "y": 0, "z": 1}},
        },
        "coloraxis": {
            "colorscale": COLORSCALE, "cmin": cmin, "cmax": cmax, "showscale": recorded,
            "colorbar": {"title": {"text": "tube force [N]"}, "len": 0.6, "x": 0.98, "xanchor": "right", "thickness": 18},
        },
        "sliders": [_slider(chain)],
        "updatemenus": [_buttons(fps)],
    }


def _title(chain: ChainFrames, recorded: bool, wall: WallWear | None = None) -> str:
    what = "links coloured by their tube normal force" if recorded else "tube force not recorded (no links table)"
    source = "" if chain.source == "bodies" else "; poses from the links table (eq. (4) axes: no spin, no connectors)"
    keys = f"; {chain.keys.shape[1]} ball keys" if chain.keys is not None else ""
    partial = "; the run stopped early" if not chain.complete else ""
    second = []
    if chain.scale != 1.0:
        second.append(f"DISPLACEMENT SCALE ×{chain.scale:g}: offsets from the tube centreline drawn {chain.scale:g} times true size (the tube at true scale)")
    if wall is not None:
        p = wall.params
        second.append(
            f"tube wall coloured by Archard wear depth over t = {p['window_start']:g}–{p['window_end']:g} s "
            f"(wear map, {1e3 * p['cell_length']:g} mm × {p['cell_angle_deg']:g}° cells)"
        )
    line = html.escape(f"ballcage: {chain.scene_name}: {what}{keys}{source}{partial}")
    return line + "".join(f"<br><span style='font-size:13px'>{html.escape(t)}</span>" for t in second)


#: Animation options of a slider step: straight to its frame.
_JUMP = {"mode": "immediate", "frame": {"duration": 0, "redraw": True}, "transition": {"duration": 0}}


def _slider(chain: ChainFrames) -> dict[str, Any]:
    steps = [
        {
            "label": f"{t:.3f}",
            "method": "animate",
            "args": [[_frame_name(chain, f)], _JUMP],
        }
        for f, t in enumerate(chain.times)
    ]
    return {
        "active": 0, "steps": steps, "x": 0.1, "len": 0.88, "y": 0.0, "yanchor": "top", "pad": {"t": 10, "b": 0},
        "currentvalue": {"prefix": "t = ", "suffix": " s", "visible": True, "font": {"color": "#303030"}},
        "font": {"color": "rgba(0, 0, 0, 0)"},  # no label under each of up to hundreds of steps; the current one shows above
        "transition": {"duration": 0},
    }


def _buttons(fps: float) -> dict[str, Any]:
    play = {"frame": {"duration": 1000.0 / fps, "redraw": True}, "fromcurrent": True, "transition": {"duration": 0}, "mode": "immediate"}
    pause = {"frame": {"duration": 0, "redraw": False}, "mode": "immediate", "transition": {"duration": 0}}
    return {
        "type": "buttons", "direction": "left", "showactive": False, "x": 0.09, "xanchor": "right", "y": 0.0, "yanchor": "top",
        "pad": {"t": 20, "r": 10},
        "buttons": [
            {"label": "▶ play", "method": "animate", "args": [None, play]},
            {"label": "❚❚ pause", "method": "animate", "args": [[None], pause]},
        ],
    }
