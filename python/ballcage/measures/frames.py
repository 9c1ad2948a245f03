"""Per-frame access to a run's tables: frame times and ``[frame, row ids]`` grids of the drill-pipe tables."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pyarrow as pa

from ballcage.run import Run

__all__ = ["argmax_where", "frame_grid", "frame_index", "frame_times"]


def frame_times(run: Run) -> np.ndarray:
    """The run's frame times [s], sorted, from the first drill-pipe table recorded."""
    for name in ("links", "drive", "hinges", "keys", "bodies"):
        table = run.tables.get(name)
        if table is not None and table.num_rows:
            return np.unique(table.column("t").to_numpy())
    return np.zeros(0)


def frame_index(times: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The index in `times` of each time in `t` [s] (clipped to the frames)."""
    idx = np.searchsorted(times, t)
    return np.clip(idx, 0, max(len(times) - 1, 0))


def frame_grid(table: pa.Table, times: np.ndarray, row_cols: Sequence[str], value_cols: Sequence[str]) -> dict[str, np.ndarray]:
    """Per-frame arrays ``[frame, *row ids]`` of `value_cols` (NaN where a row is missing)."""
    fi = frame_index(times, table.column("t").to_numpy())
    ids = [table.column(c).to_numpy().astype(np.int64) for c in row_cols]
    shape = (len(times), *[(int(i.max()) + 1 if len(i) else 0) for i in ids])
    out = {}
    for col in value_cols:
        arr = np.full(shape, np.nan)
        arr[(fi, *ids)] = table.column(col).to_numpy()
        out[col] = arr
    return out


def argmax_where(values: np.ndarray, times: np.ndarray) -> tuple[float, tuple[int, ...], float]:
    """Largest finite value of a per-frame grid, its (row ids) and its time."""
    if values.size == 0 or not np.isfinite(values).any():
        return math.nan, (), math.nan
    flat = int(np.nanargmax(values))
    idx = np.unravel_index(flat, values.shape)
    return float(values[idx]), tuple(int(i) for i in idx[1:]), float(times[idx[0]])
