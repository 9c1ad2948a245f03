"""The wear map's cells: patches (`ballcage.measures.wear_patches`) summed onto a grid, and the map's table.

A patch's volume k/H·F·v·dt is split over the cells it covers in proportion
to the area it covers in each (its along and around intervals cut at the
cell edges: exact for the uniform pressure the patches carry). A patch whose
mean pressure is below ``wear.threshold_pressure`` wears nothing; its
friction energy still counts.
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np
import pyarrow as pa

from ballcage.measures.wear_patches import Patches

__all__ = ["MAP_COLUMNS", "deposit", "map_table"]

#: The wear map's columns: name, type, unit, meaning.
MAP_COLUMNS: tuple[tuple[str, pa.DataType, str, str], ...] = (
    ("surface", pa.string(), "", ("tube (the guide tube's wall), link (a link's outer surface), inner-race, outer-race "
     "or window (a key's groove on the head, in the seat, or its cage window)")),
    ("link", pa.int32(), "", "the link, on a link's surface; null elsewhere"),
    ("hinge", pa.int32(), "", "the hinge, on a groove or window; null elsewhere"),
    ("key", pa.int32(), "", "the key, on a groove or window; null elsewhere"),
    ("pair", pa.string(), "", "the contact pair, on a groove or window; null elsewhere"),
    ("axial_start", pa.float64(), "m", ("cell start along the surface: tube, arc length s along the centreline from "
     "its start; link, along the link's axis (body x) from its centre; groove or window, along the axis of the body "
     "that carries it from that body's centre")),
    ("axial_end", pa.float64(), "m", "cell end along the surface"),
    ("angle_start", pa.float64(), "deg", ("cell start around the surface: tube, azimuth from the bend's outer wall "
     "(0°) through tangent × outward (90°) to its inner wall (180°); link, from body y toward body z; null on a "
     "groove or window")),
    ("angle_end", pa.float64(), "deg", "cell end around the surface"),
    ("area", pa.float64(), "m^2", "cell area (groove or window: cell length × the worn track's width, volume / depth)"),
    ("depth", pa.float64(), "m", "Archard wear depth over the window, the cell's mean: volume / area"),
    ("volume", pa.float64(), "m^3", ("Archard wear volume over the window, k/H · Σ F_n·v_slip·dt of the patches "
     "over the cell")),
    ("energy", pa.float64(), "J", ("friction energy over the window, Σ |F_t|·v_slip·dt of the patches over the cell "
     "(a pair's energy counts on both its surfaces)")),
    ("depth_rate", pa.float64(), "m/s", "depth / window length: the mean rate at the run's duty"),
    ("hours_to_depth", pa.float64(), "h", ("hours of the run's duty to wear wear.map_depth at depth_rate; null where "
     "the cell does not wear")),
)  # fmt: skip


def _cells(lo: np.ndarray, hi: np.ndarray, cell: float) -> tuple[np.ndarray, np.ndarray]:
    """Cell indices (N, S) and the fraction of each interval [lo, hi] in each (a zero-length one: all in its cell)."""
    i0 = np.floor(lo / cell).astype(np.int64)
    span = int((np.floor(hi / cell).astype(np.int64) - i0).max()) + 1
    k = np.arange(span)
    i = i0[:, None] + k[None, :]
    length = hi - lo
    overlap = np.clip(np.minimum(hi[:, None], (i + 1) * cell) - np.maximum(lo[:, None], i * cell), 0.0, None)
    safe = np.where(length > 0.0, length, 1.0)
    frac = np.where(length[:, None] > 0.0, overlap / safe[:, None], (k[None, :] == 0).astype(float))
    return i, frac


def deposit(
    patches: Patches,
    k_over_h: np.ndarray,
    cfg: dict[str, float],
    *,
    surface: str,
    radius: float,
    owner: bool,
    half_length: float | None = None,
) -> dict[str, Any] | None:
    """Sums the patches onto the cells of `surface` (``"tube"``, ``"link"`` or ``"groove"``).

    Returns the cells that got anything: ``owner``, ``i``, ``j`` (cell indices
    along and around), ``volume`` [m³], ``energy`` [J], ``depth`` [m] and the
    cell sizes; ``None`` without patches.
    """
    if patches.force.size == 0:
        return None
    groove = surface == "groove"
    along = patches.other_along if surface == "link" else patches.along
    around = patches.other_around if surface == "link" else patches.around
    assert along is not None and around is not None
    if half_length is not None:
        along = np.clip(along, -half_length, half_length)
    cell = cfg["cell_length"] / 10.0 if groove else cfg["cell_length"]
    n_around = 1 if groove else round(360.0 / cfg["cell_angle_deg"])
    worn = patches.pressure >= cfg["threshold_pressure"]
    volume = np.where(worn, k_over_h * patches.force * patches.slip * patches.dt, 0.0)
    energy = patches.power * patches.dt
    width = around[:, 1] - around[:, 0]
    per_depth = volume / (cell * np.maximum(width, 1e-300)) if groove else np.zeros_like(volume)
    i, fi = _cells(along[:, 0], along[:, 1], cell)
    if groove:
        j, fj = np.zeros((volume.size, 1), dtype=np.int64), np.ones((volume.size, 1))
    else:
        j, fj = _cells(around[:, 0], around[:, 1], 2.0 * math.pi / n_around)
        j = np.mod(j, n_around)
    who = patches.owner.astype(np.int64) if owner else np.zeros(volume.size, dtype=np.int64)
    i_min = int(i.min())
    n_i = int(i.max()) - i_min + 1
    keys, weights = [], []
    for a in range(i.shape[1]):
        for b in range(j.shape[1]):
            w = fi[:, a] * fj[:, b]
            use = w > 0.0
            keys.append((who[use] * n_i + (i[use, a] - i_min)) * n_around + j[use, b])
            weights.append((np.flatnonzero(use), w[use]))
    flat = np.concatenate(keys)
    unique, inverse = np.unique(flat, return_inverse=True)
    rows = np.concatenate([r for r, _ in weights])
    w = np.concatenate([x for _, x in weights])
    sums = {
        name: np.bincount(inverse, weights=values[rows] * w, minlength=unique.size)
        for name, values in (("volume", volume), ("energy", energy), ("depth", per_depth))
    }
    out: dict[str, Any] = {
        "owner": unique // (n_i * n_around),
        "i": (unique // n_around) % n_i + i_min,
        "j": unique % n_around,
        "cell": cell,
        "n_around": n_around,
        "radius": radius,
        "half_length": half_length,
        **sums,
    }
    return out


def map_table(
    cells: dict[str, Any] | None,
    surface: str,
    cfg: dict[str, float],
    window: tuple[float, float],
    ids: dict[int, dict[str, Any]] | None = None,
) -> pa.Table:
    """The map's rows of one surface from `deposit`'s cells (an empty table for ``None``), with units and meanings."""
    columns: dict[str, list[Any]] = {name: [] for name, *_ in MAP_COLUMNS}
    span = max(window[1] - window[0], 1e-300)
    if cells is not None:
        cell, n = cells["cell"], cells["n_around"]
        start = cells["i"] * cell
        end = start + cell
        if surface == "groove":
            area = np.where(cells["depth"] > 0.0, cells["volume"] / np.maximum(cells["depth"], 1e-300), 0.0)
            depth = cells["depth"]
        else:
            if cells["half_length"] is not None:
                half = cells["half_length"]
                start, end = np.clip(start, -half, half), np.clip(end, -half, half)
            area = (end - start) * cells["radius"] * 2.0 * math.pi / n
            depth = cells["volume"] / np.maximum(area, 1e-300)
        keep = (cells["volume"] > 0.0) | (cells["energy"] != 0.0)
        for k in np.flatnonzero(keep):
            _row(columns, cells, int(k), surface, ids, (start[k], end[k], area[k], depth[k]), cfg, span)
    return pa.table(columns, schema=_schema(cfg, window))


def _row(columns: dict[str, list[Any]], cells: dict[str, Any], k: int, surface: str, ids: dict[int, dict[str, Any]] | None, geo: tuple[float, float, float, float], cfg: dict[str, float], span: float) -> None:  # fmt: skip
    start, end, area, depth = (float(v) for v in geo)
    owner = int(cells["owner"][k])
    pair = ids[owner] if ids is not None else None
    step = 360.0 / cells["n_around"]
    rate = depth / span
    values = {
        "surface": pair["feature"] if pair is not None else surface,
        "link": owner if surface == "link" else None,
        "hinge": pair["hinge"] if pair is not None else None,
        "key": pair["key"] if pair is not None else None,
        "pair": str(pair["pair"]) if pair is not None else None,
        "axial_start": start,
        "axial_end": end,
        "angle_start": None if surface == "groove" else float(cells["j"][k]) * step,
        "angle_end": None if surface == "groove" else float(cells["j"][k] + 1) * step,
        "area": area,
        "depth": depth,
        "volume": float(cells["volume"][k]),
        "energy": float(cells["energy"][k]),
        "depth_rate": rate,
        "hours_to_depth": cfg["map_depth"] / rate / 3600.0 if rate > 0.0 else None,
    }
    for name, v in values.items():
        columns[name].append(v)


def _schema(cfg: dict[str, float], window: tuple[float, float]) -> pa.Schema:
    fields = [pa.field(n, t, metadata={"unit": u, "description": d}) for n, t, u, d in MAP_COLUMNS]
    params = {**cfg, "window_start": window[0], "window_end": window[1], "pressure": "uniform over the Hertz area"}
    meta = {
        "ballcage.table": "wear_map",
        "ballcage.row": "one row per surface cell that wore or rubbed over the window",
        "ballcage.wear_map": json.dumps(params),
        "ballcage.units": json.dumps({n: u for n, _, u, _ in MAP_COLUMNS}),
    }
    return pa.schema(fields, metadata=meta)
