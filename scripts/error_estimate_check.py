#!/usr/bin/env python3
"""The adaptive integrator's built-in error estimate against the error measured by a ten-times-tighter run.

    python3 scripts/error_estimate_check.py [--out FILE.json] [--cases NAME,...] [--set KEY=VALUE ...]

For the paper scene and three extremes, runs the default (ESDIRK3(2), rtol 1e-4) and the same scene at
rtol 1e-5 (ten times tighter), each with the ``--set`` overrides (``--set 'simulation.integrator="trbdf2"'``
for TR-BDF2), and compares:
- the run's `ballcage.error_estimate_position_m` (the sum over its accepted steps of the largest local
  error estimate on a position) with the largest difference of any body's position between the two runs,
  over every recorded frame ("measured", m);
- the same for velocities (`ballcage.error_estimate_velocity_m_s`, m/s);
- the largest relative difference of the headline quantities (`ballcage.verify.headline`).
Prints a markdown table (docs/accuracy.md). Takes about 10 minutes on this project's machine.
"""

from __future__ import annotations

import argparse
import json

import numpy as np

import ballcage
from ballcage.verify import headline

CASES: dict[str, list[str]] = {
    "the paper's scene": [],
    "600 rpm": ["drive.speed_rpm=600"],
    "contact stiffness 100×": ["materials.internal.normal.stiffness=1e7", "materials.tube.normal.stiffness=1e7"],
    "24 joints": ["pipe.joints=24"],
}


def largest_difference(a: ballcage.Run, b: ballcage.Run, columns: tuple[str, str, str]) -> float:
    """The largest |a − b| of the 3-vector `columns` of the bodies table over every body and frame."""
    ta, tb = a.bodies, b.bodies
    va = np.stack([ta.column(c).to_numpy() for c in columns], axis=1)
    vb = np.stack([tb.column(c).to_numpy() for c in columns], axis=1)
    return float(np.max(np.linalg.norm(va - vb, axis=1)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default="error_estimate_check.json", help="where the raw results go")
    parser.add_argument("--cases", default=",".join(CASES), help="comma-separated case names (default: all)")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="an override of every run")
    args = parser.parse_args()
    rows = {}
    tables = 'record.tables=["bodies","links","hinges","keys","drive","summary"]'
    for name in args.cases.split(","):
        try:
            runs = [
                ballcage.simulate({"kind": "drill-pipe"}, overrides=[*CASES[name], *args.set, *tol, tables], progress=False)
                for tol in ([], ["simulation.rtol=1e-5"])
            ]
        except ballcage.SimulationError as e:
            print(f"{name}: a run failed: {e}", flush=True)
            continue
        meta = runs[0].metadata
        qa, qb = headline(runs[0]), headline(runs[1])
        rel = max(
            (abs(qa[k][1] - v) / abs(v), k) for k, (_, v) in qb.items() if v and qa.get(k, ("", None))[1] is not None
        )
        rows[name] = {
            "estimate_position_m": float(meta["ballcage.error_estimate_position_m"]),
            "measured_position_m": largest_difference(runs[0], runs[1], ("pos_x", "pos_y", "pos_z")),
            "estimate_velocity_m_s": float(meta["ballcage.error_estimate_velocity_m_s"]),
            "measured_velocity_m_s": largest_difference(runs[0], runs[1], ("vel_x", "vel_y", "vel_z")),
            "headline_relative": rel[0],
            "headline_quantity": rel[1],
        }
        print(name, rows[name], flush=True)
    with open(args.out, "w") as f:
        json.dump(rows, f, indent=1)
    print("\n| case | position: estimate [m] | measured [m] | velocity: estimate [m/s] | measured [m/s] | headline: largest relative difference |")
    print("|---|---:|---:|---:|---:|---|")
    for name, r in rows.items():
        print(
            f"| {name} | {r['estimate_position_m']:.2e} | {r['measured_position_m']:.2e} | "
            f"{r['estimate_velocity_m_s']:.2e} | {r['measured_velocity_m_s']:.2e} | "
            f"{100 * r['headline_relative']:.3g} % ({r['headline_quantity']}) |"
        )


if __name__ == "__main__":
    main()
