"""Per-link link–tube contact forces of a drill-pipe run over its summary window, from the ``links`` table.

The window is the scene's ``record.summary_window`` (the whole run when it is
not set) with the summary table's semantics: the frames with
``window_start - 1e-12 <= t <= window_end + 1e-12``; a frame without contact
counts as 0 N, which ``links.tube_normal`` already is.

A mean is a mean over time, not over the frames: the difference of the link's
cumulative impulse (``links.tube_normal_impulse``, ``tube_tangential_impulse``
[N*s], which the integrator accumulates over its own steps) between the
window's ends, over the window's length. It therefore does not depend on
``simulation.output_interval`` (docs/accuracy.md, "A mean force is a mean over
time"). A ``links`` table without those columns (written before they existed)
gives the impulse by the trapezoid rule over its frames.

A peak is the largest force the integrator saw: ``links.tube_normal_max`` holds,
at each frame, the largest ``tube_normal`` at any stage of the steps accepted
since the frame before, so the peak over a window is the window's first frame's
``tube_normal`` and the largest ``tube_normal_max`` after it. That too does not
depend on the output interval; an impact between two frames counts. A ``links``
table without the column gives the largest value at a frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ballcage import _native
from ballcage.run import Run

__all__ = ["LinkTubeForces", "in_summary_window", "link_tube_forces", "summary_window", "time_mean", "window_peak"]

#: Slack [s] on the window's ends, as the engine's summary table applies it.
WINDOW_SLACK = 1e-12


@dataclass(frozen=True)
class LinkTubeForces:
    """Each link's contact with the guide tube over the summary window, by link number (1 at the top)."""

    start: float  # first time of the window [s]
    end: float  # last time of the window, at most the last frame [s]
    frames: int  # frames in the window
    normal_mean: dict[int, float]  # time mean of links.tube_normal [N]
    normal_peak: dict[int, float]  # largest links.tube_normal the integrator saw (links.tube_normal_max) [N]
    tangential_mean: dict[int, float]  # time mean of links.tube_tangential [N]


def summary_window(scene: _native.Scene) -> tuple[float, float]:
    """The scene's ``record.summary_window`` (start, end) [s]; (0, inf) when it is not set (the whole run)."""
    window = scene.value("record.summary_window")
    if isinstance(window, list) and len(window) == 2:
        return float(window[0]), float(window[1])
    return 0.0, math.inf


def in_summary_window(scene: _native.Scene, t: np.ndarray) -> np.ndarray:
    """Which of the times `t` [s] lie in the scene's summary window (`summary_window`, with `WINDOW_SLACK`)."""
    start, end = summary_window(scene)
    return (t >= start - WINDOW_SLACK) & (t <= end + WINDOW_SLACK)


def link_tube_forces(run: Run) -> LinkTubeForces | None:
    """Mean and peak link–tube forces [N] per link over the summary window; ``None`` without a ``links`` table."""
    links = run.tables.get("links")
    if links is None or links.num_rows == 0:
        return None
    start, end = summary_window(run.scene)
    t = links.column("t").to_numpy()
    inside = in_summary_window(run.scene, t)
    link = links.column("link").to_numpy()
    normal = links.column("tube_normal").to_numpy()
    tangential = links.column("tube_tangential").to_numpy()
    since = links.column("tube_normal_max").to_numpy() if "tube_normal_max" in links.column_names else None
    integrals = {
        name: links.column(name).to_numpy() if name in links.column_names else None
        for name in ("tube_normal_impulse", "tube_tangential_impulse")
    }
    normal_mean: dict[int, float] = {}
    normal_peak: dict[int, float] = {}
    tangential_mean: dict[int, float] = {}
    for k in sorted(int(k) for k in np.unique(link)):
        rows = np.flatnonzero(link == k)
        rows = rows[np.argsort(t[rows], kind="stable")]
        mask = inside[rows]
        if not mask.any():
            normal_mean[k] = normal_peak[k] = tangential_mean[k] = 0.0
            continue
        normal_peak[k] = window_peak(normal[rows], None if since is None else since[rows], mask)
        for out, value, integral in (
            (normal_mean, normal, integrals["tube_normal_impulse"]),
            (tangential_mean, tangential, integrals["tube_tangential_impulse"]),
        ):
            out[k] = time_mean(t[rows], value[rows], None if integral is None else integral[rows], mask)
    frames = int(np.unique(t[inside]).size)
    return LinkTubeForces(start, min(end, float(t.max())), frames, normal_mean, normal_peak, tangential_mean)


def window_peak(value: np.ndarray, since: np.ndarray | None, inside: np.ndarray) -> float:
    """The largest `value` over the frames `inside` (a window of frames at ascending times).

    With `since` (each frame's largest value since the frame before, at the integrator's stages): the first
    frame's `value` and the largest `since` of the frames after it, which covers every step that starts
    within the window; without it, the largest `value` at a frame.
    """
    if since is None:
        return float(value[inside].max())
    rows = np.flatnonzero(inside)
    return float(max(value[rows[0]], since[rows[1:]].max(initial=-np.inf)))


def time_mean(t: np.ndarray, value: np.ndarray, impulse: np.ndarray | None, inside: np.ndarray) -> float:
    """The time mean of `value` over the frames `inside` (a window of frames at ascending times `t` [s]).

    ``(I(b) - I(a)) / (b - a)``, `a` and `b` the first and last time inside, `I` the cumulative `impulse`
    (the integrator's) or, without it, the trapezoid rule over the frames; a window of one frame is that
    frame's value.
    """
    times = t[inside]
    a, b = float(times[0]), float(times[-1])
    if b - a <= 0.0:
        return float(value[inside].mean())
    if impulse is None:
        impulse = np.concatenate(([0.0], np.cumsum(0.5 * (value[1:] + value[:-1]) * np.diff(t))))
    cumulative = impulse[inside]
    return float((cumulative[-1] - cumulative[0]) / (b - a))
