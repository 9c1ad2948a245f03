#!/usr/bin/env python3
"""Side-by-side table of `ballcage paper` runs that differ in one parameter.

    python3 scripts/sensitivity_table.py LABEL=DIR [LABEL=DIR ...]   (split at the last "=")

Each DIR is the output folder of a `ballcage paper` run. Prints a markdown
table: a column per run; rows are the chain's shape statistics computed here
from the hinges and links tables over 0.4 s to the end (after the drive and
load ramps), then every quantity of the run's comparison.parquet that has a
value. Shape rows: mean, 95th percentile and largest bend [deg] of hinges
1–11 (between two links), the share of frames × hinges with the neck on the
seat's mouth (hinges.neck_normal > 0) and the peak neck force, the sum over
links and the largest of the per-link mean tube normal forces [N] (and at
which link), the seat-race contact angle of the keys (median over loads above
5 kN, and at the largest load), and how many h/16 part steps SDIRK2 took by
its fallback (`ballcage.fallback_steps`). Ideal-CV runs have no keys table
and get no key rows.
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
    means = {int(k): float(normal[link == k].mean()) for k in np.unique(link)}
    tube_sum = sum(means.values())
    busiest = max(means, key=means.get)
    keys = _window(pq.read_table(folder / "keys.parquet")) if (folder / "keys.parquet").is_file() else None
    rows_keys = keys is not None and keys.num_rows > 0
    force = keys["outer_normal"].to_numpy() if rows_keys else np.zeros(1)
    angle = (
        keys["outer_contact_angle_deg"].to_numpy(zero_copy_only=False).astype(float) if rows_keys else np.full(1, np.nan)
    )
    loaded = (force > 5000.0) & np.isfinite(angle)
    meta = pq.read_schema(folder / "links.parquet").metadata or {}
    fallbacks = int(meta.get(b"ballcage.fallback_steps", b"0"))
    return {
        "mean bend, hinges 1–11 [deg]": float(bend.mean()),
        "95th percentile bend [deg]": float(np.percentile(bend, 95)),
        "largest bend [deg]": float(bend.max()),
        "neck on the mouth [% of hinge-frames]": 100.0 * float((neck > 0).mean()),
        "peak neck force [N]": float(neck.max()),
        "sum of per-link mean tube forces [N]": float(tube_sum),
        "largest per-link mean tube force [N]": means[busiest],
        "link with the largest mean tube force": float(busiest),
        "seat-race contact angle, median over keys above 5 kN [deg]": float(np.median(angle[loaded]))
        if loaded.any()
        else float("nan"),
        "seat-race contact angle at the largest seat-key force [deg]": float(angle[np.argmax(force)]),
        "SDIRK2 part steps taken by the fallback": float(fallbacks),
    }


def comparison_rows(folder: Path) -> dict[str, tuple[float, str]]:
    table = pq.read_table(folder / "comparison.parquet").to_pylist()
    return {r["key"]: (r["ours"], r["unit"], r["paper"]) for r in table if r["ours"] is not None}


def main(argv: list[str]) -> int:
    runs = [a.rsplit("=", 1) for a in argv]
    if not runs or any(len(r) != 2 for r in runs):
        print(__doc__, file=sys.stderr)
        return 2
    shapes = {label: shape_rows(Path(d)) for label, d in runs}
    comparisons = {label: comparison_rows(Path(d)) for label, d in runs}
    labels = [label for label, _ in runs]
    print("| quantity | paper | " + " | ".join(labels) + " |")
    print("|---|---:|" + "---:|" * len(labels))
    for key in next(iter(shapes.values())):
        cells = ["" if not np.isfinite(shapes[lab][key]) else f"{shapes[lab][key]:.4g}" for lab in labels]
        print(f"| {key} | | " + " | ".join(cells) + " |")
    keys = [k for k in comparisons[labels[0]]]
    for key in keys:
        unit, paper = comparisons[labels[0]][key][1], comparisons[labels[0]][key][2]
        cells = [comparisons[lab].get(key, (None,))[0] for lab in labels]
        paper_cell = "" if paper is None else f"{paper:.4g}"
        print(f"| {key} [{unit}] | {paper_cell} | " + " | ".join("" if c is None else f"{c:.4g}" for c in cells) + " |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
