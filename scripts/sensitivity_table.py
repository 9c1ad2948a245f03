#!/usr/bin/env python3
"""Side-by-side table of `ballcage paper` runs that differ in one parameter.

    python3 scripts/sensitivity_table.py LABEL=DIR [LABEL=DIR ...]

Each DIR is the output folder of a `ballcage paper` run. Prints a markdown
table: a column per run; rows are the chain's shape statistics computed here
from the hinges and links tables over 0.4 s to the end (after the drive and
load ramps), then every quantity of the run's comparison.parquet that has a
value. Shape rows: mean, 95th percentile and largest bend [deg] of hinges
1–11 (between two links), the share of frames × hinges with the neck on the
seat's mouth (hinges.neck_normal > 0), and the sum over links of the mean
tube normal force [N].
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pyarrow.compute as pc
import pyarrow.parquet as pq

START = 0.4  # s, after the 0.3 s drive ramp


def _window(table):
    return table.filter(pc.greater_equal(table["t"], START))


def shape_rows(folder: Path) -> dict[str, float]:
    hinges = _window(pq.read_table(folder / "hinges.parquet"))
    hinges = hinges.filter(pc.and_(pc.greater_equal(hinges["hinge"], 1), pc.less_equal(hinges["hinge"], 11)))
    bend = hinges["bend_deg"].to_numpy()
    neck = hinges["neck_normal"].to_numpy()
    links = _window(pq.read_table(folder / "links.parquet"))
    link = links["link"].to_numpy()
    normal = links["tube_normal"].to_numpy()
    tube_sum = sum(normal[link == k].mean() for k in np.unique(link))
    return {
        "mean bend, hinges 1–11 [deg]": float(bend.mean()),
        "95th percentile bend [deg]": float(np.percentile(bend, 95)),
        "largest bend [deg]": float(bend.max()),
        "neck on the mouth [% of hinge-frames]": 100.0 * float((neck > 0).mean()),
        "peak neck force [N]": float(neck.max()),
        "sum of per-link mean tube forces [N]": float(tube_sum),
    }


def comparison_rows(folder: Path) -> dict[str, tuple[float, str]]:
    table = pq.read_table(folder / "comparison.parquet").to_pylist()
    return {r["key"]: (r["ours"], r["unit"], r["paper"]) for r in table if r["ours"] is not None}


def main(argv: list[str]) -> int:
    runs = [a.split("=", 1) for a in argv]
    if not runs or any(len(r) != 2 for r in runs):
        print(__doc__, file=sys.stderr)
        return 2
    shapes = {label: shape_rows(Path(d)) for label, d in runs}
    comparisons = {label: comparison_rows(Path(d)) for label, d in runs}
    labels = [label for label, _ in runs]
    print("| quantity | paper | " + " | ".join(labels) + " |")
    print("|---|---:|" + "---:|" * len(labels))
    for key in next(iter(shapes.values())):
        print(f"| {key} | | " + " | ".join(f"{shapes[lab][key]:.4g}" for lab in labels) + " |")
    keys = [k for k in comparisons[labels[0]]]
    for key in keys:
        unit, paper = comparisons[labels[0]][key][1], comparisons[labels[0]][key][2]
        cells = [comparisons[lab].get(key, (None,))[0] for lab in labels]
        paper_cell = "" if paper is None else f"{paper:.4g}"
        print(f"| {key} [{unit}] | {paper_cell} | " + " | ".join("" if c is None else f"{c:.4g}" for c in cells) + " |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
