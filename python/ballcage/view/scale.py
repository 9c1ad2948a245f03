"""A displacement scale for the view, as finite-element post-processors draw deformed shapes exaggerated.

At true scale the chain's fold (15 mm of offset on a 2.4 m chain) is invisible:
the chain seems to follow the arc. `scaled` draws each body's offset from the
tube centreline `scale` times its true size: each end of a body (its axis
point at ± half its drawn length) is moved to foot + scale·(end − foot), foot
its nearest point on the centreline, and the body is drawn between its two
moved ends, stretched where the exaggerated tilt makes them farther apart (as
a finite-element mesh's elements stretch under scaled nodal displacements).
Bodies that meet at a hinge have ends of nearly the same offset, so they
still meet. Ball keys move with the nearest moved
body end. The tube stays at true scale. Lengths in m.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ballcage._native import InputError
from ballcage.view.poses import ChainFrames, TubeShape

__all__ = ["MAX_SCALE", "MIN_SCALE", "centreline_offset", "scaled"]

#: The displacement scales the view accepts.
MIN_SCALE, MAX_SCALE = 1.0, 50.0


def centreline_offset(tube: TubeShape, points: np.ndarray) -> np.ndarray:
    """Each point's offset [m] from its nearest point on the tube's centreline, ``[..., 3]`` as `points`.

    The foot is the nearest centreline sample moved along its tangent (the
    samples are 20 mm apart: on the paper's 1.5 m bend its error is under 40 µm).
    """
    flat = points.reshape(-1, 3)
    d2 = (flat * flat).sum(1)[:, None] - 2.0 * flat @ tube.points.T + (tube.points * tube.points).sum(1)[None, :]
    k = np.argmin(d2, axis=1)
    r = flat - tube.points[k]
    r -= (r * tube.tangents[k]).sum(1)[:, None] * tube.tangents[k]
    return r.reshape(points.shape)


def scaled(chain: ChainFrames, scale: float) -> ChainFrames:
    """`chain` with its bodies' offsets from the tube centreline drawn `scale` times (1 to 50) their true size."""
    if not (isinstance(scale, (int, float)) and MIN_SCALE <= scale <= MAX_SCALE):
        raise InputError(f"scale = {scale!r}: must be a number from {MIN_SCALE:g} to {MAX_SCALE:g} (the links' offsets drawn that many times)")
    if scale == 1.0:
        return chain
    half = 0.5 * chain.lengths[None, :, None] * chain.axes
    ends = np.stack([chain.centres - half, chain.centres + half], axis=2)  # (F, B, 2, 3)
    moved = ends + (scale - 1.0) * centreline_offset(chain.tube, ends)
    centres = moved.mean(axis=2)
    axis = moved[:, :, 1] - moved[:, :, 0]
    lengths = np.linalg.norm(axis, axis=-1)
    axes = axis / np.maximum(lengths, 1e-12)[..., None]
    keys = chain.keys
    if keys is not None:
        flat_ends = ends.reshape(len(chain.times), -1, 3)
        shift = (moved - ends).reshape(len(chain.times), -1, 3)
        nearest = np.argmin(((keys[:, :, None, :] - flat_ends[:, None, :, :]) ** 2).sum(-1), axis=2)
        keys = keys + np.take_along_axis(shift, nearest[..., None], axis=1)
    return dataclasses.replace(chain, centres=centres, axes=axes, keys=keys, scale=float(scale), frame_lengths=lengths)
