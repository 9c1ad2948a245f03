#!/usr/bin/env python3
"""The extremes of docs/performance.md on the full paper scene, each alone.

    python3 scripts/extremes.py [--integrator NAME --rtol R] [--out FILE.json]

Runs the embedded paper scene (ball keys, 1.8 s) with each extreme below, by
default with the shipped setting (ESDIRK3(2), adaptive at rtol 1e-4, frames
within steps interpolated); `--integrator sdirk2 --rtol 0` runs them at SDIRK2's fixed 100 µs. Prints a markdown table:
whether the run finished, its CPU time [s], Newton iterations per stage,
rejected steps, step halvings and first-order fallback part steps.
Takes about 1 to 2 minutes on this project's machine (1 min 11 s on
2026-11-27; 5–10 minutes before the adaptive default).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import ballcage
from ballcage.studies.common import newton_per_stage

EXTREMES: dict[str, list[str]] = {
    "the paper's scene (reference)": [],
    "600 rpm": ["drive.speed_rpm=600"],
    "tightest radius the hinge allows (0.771 m)": ["borehole.curvature_radius=0.771"],
    "contact stiffness 1e7 N/mm^2.2 (100×)": [
        "materials.internal.normal.stiffness=1e7",
        "materials.tube.normal.stiffness=1e7",
    ],
    "no contact damping": ["materials.internal.normal.damping=0", "materials.tube.normal.damping=0"],
    "μs = 1": ["materials.internal.friction.mu_static=1.0", "materials.tube.friction.mu_static=1.0"],
    "5 kN·m": ["load.resisting_moment=5000"],
    "24 joints": ["pipe.joints=24"],
}


def one(overrides: list[str]) -> dict:
    """Runs one case; its outcome, CPU time [s] and solver counts."""
    start = time.process_time()
    try:
        run = ballcage.simulate({"kind": "drill-pipe"}, overrides=overrides, progress=False)
        meta, finished = run.metadata, "yes"
    except ballcage.SimulationError as e:
        meta, finished = e.run.metadata, f"no: {e}"  # type: ignore[attr-defined]
    keys = ("newton_iterations", "steps", "accepted_steps", "rejected_steps", "step_halvings", "fallback_steps")
    counts = {k: meta.get(f"ballcage.{k}") for k in keys}
    return {"finished": finished, "cpu_s": time.process_time() - start, "per_stage": newton_per_stage(meta) or float("nan"), **counts}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--integrator", default=None, help="simulation.integrator (default: the scene's)")
    parser.add_argument("--rtol", type=float, default=None, help="simulation.rtol (0: fixed steps of simulation.dt)")
    parser.add_argument("--out", default="out/extremes.json", help="where the raw results go (out/ is not tracked)")
    args = parser.parse_args()
    base = [] if args.integrator is None else [f'simulation.integrator="{args.integrator}"']
    if args.rtol is not None:
        base.append(f"simulation.rtol={args.rtol!r}")
    results = {}
    for name, overrides in EXTREMES.items():
        results[name] = one([*base, *overrides])
        print(f"{name}: {results[name]['finished']}, {results[name]['cpu_s']:.1f} s", flush=True)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    with open(args.out, "w") as f:
        json.dump(results, f, indent=1)
    print("\n| case | finished | CPU [s] | Newton its/stage | rejected | halvings | fallbacks |")
    print("|---|---|---:|---:|---:|---:|---:|")
    for name, r in results.items():
        print(
            f"| {name} | {r['finished']} | {r['cpu_s']:.1f} | {r['per_stage']:.2f} | "
            f"{r['rejected_steps'] or '—'} | {r['step_halvings']} | {r['fallback_steps']} |"
        )


if __name__ == "__main__":
    main()
