#!/usr/bin/env python3
"""Work–precision of the paper scene: fixed-step SDIRK2 and adaptive ESDIRK3(2).

    python3 scripts/work_precision.py [--duration S] [--out FILE.json] [--set KEY=VALUE ...]

Runs the embedded paper scene (ball keys, level-set link–tube law) with
each setting below, and compares every drill-pipe comparison quantity
(`ballcage.measures.DRILL_PIPE`, the quantities of `ballcage run --verify`)
with two references by different methods: SDIRK2 at 25 µs and ESDIRK3(2)
at rtol = 1e-5. Their own difference is the reference's error. Prints a
markdown table (docs/accuracy.md): CPU time of the run and the real-time
factor it gives (simulated time / CPU time: less disturbed than the wall
time by other jobs on the machine), Newton
iterations per stage, rejected steps, halvings, fallback steps, and the
largest relative difference from the SDIRK2 reference with its quantity.
Each ``--set KEY=VALUE`` adds one more row: the default with that override
(e.g. ``--set simulation.atol_angular_velocity=1e-3``; several in one
argument, separated by ``;``). Takes about 1.5 minutes on this project's
machine over 1.8 s and half a minute over 0.6 s (2026-11-27; the SDIRK2
reference at 25 µs is 40 % of it).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import ballcage
from ballcage.studies.common import newton_per_stage
from ballcage.verify import headline

ESDIRK = ['simulation.integrator="esdirk32"']
SDIRK2 = ['simulation.integrator="sdirk2"', "simulation.rtol=0"]
CASES: dict[str, list[str]] = {
    "SDIRK2 25 µs (reference)": [*SDIRK2, "simulation.dt=2.5e-5"],
    "ESDIRK3(2) rtol 1e-5 (reference)": [*ESDIRK, "simulation.rtol=1e-5"],
    "SDIRK2 200 µs": [*SDIRK2, "simulation.dt=2e-4"],
    "SDIRK2 100 µs": [*SDIRK2, "simulation.dt=1e-4"],
    "SDIRK2 50 µs": [*SDIRK2, "simulation.dt=5e-5"],
    "ESDIRK3(2) rtol 1e-3": [*ESDIRK, "simulation.rtol=1e-3"],
    "ESDIRK3(2) rtol 3e-4": [*ESDIRK, "simulation.rtol=3e-4"],
    "ESDIRK3(2) rtol 1e-4 (default)": [],
}


def measure(overrides: list[str], duration: float) -> dict:
    """One run: its CPU time [s], solver metadata and headline quantities."""
    start = time.process_time()
    run = ballcage.simulate(
        {"kind": "drill-pipe"}, overrides=[*overrides, f"simulation.duration={duration}"], progress=False
    )
    meta = run.metadata
    keys = ("newton_iterations", "real_time_factor", "steps", "accepted_steps", "rejected_steps")
    keys += ("step_halvings", "fallback_steps", "smallest_step_s")
    return {
        "cpu_s": time.process_time() - start,
        "meta": {k: meta.get(f"ballcage.{k}") for k in keys},
        "per_stage": newton_per_stage(meta) or float("nan"),
        "quantities": {name: value for name, (_, value) in headline(run).items()},
    }


def largest_difference(run: dict, reference: dict) -> tuple[float, str]:
    """The largest |a − b|/|b| over the quantities both have (b ≠ 0), and its quantity."""
    worst = (0.0, "")
    for name, b in reference["quantities"].items():
        a = run["quantities"].get(name)
        if a is None or b is None or b == 0:
            continue
        worst = max(worst, (abs(a - b) / abs(b), name))
    return worst


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--duration", type=float, default=1.8, help="simulated time [s] (default 1.8)")
    parser.add_argument("--out", default="out/work_precision.json", help="where the raw results go (out/ is not tracked)")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE[;KEY=VALUE]",
                        help="one more row: the default with these overrides (repeatable)")
    args = parser.parse_args()
    cases = {**CASES, **{f"default with {extra}": extra.split(";") for extra in args.set}}
    results = {}
    for name, overrides in cases.items():
        results[name] = measure(overrides, args.duration)
        print(f"{name}: {results[name]['cpu_s']:.1f} s", flush=True)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    with open(args.out, "w") as f:
        json.dump(results, f, indent=1)
    reference = results["SDIRK2 25 µs (reference)"]
    print("\n| setting | CPU [s] | real-time factor (CPU) | Newton its/stage | rejected | halvings | fallbacks | largest difference from SDIRK2 25 µs |")
    print("|---|---|---|---|---|---|---|---|")
    for name, r in results.items():
        m = r["meta"]
        diff, quantity = largest_difference(r, reference)
        shown = "—" if r is reference else f"{100 * diff:.3g} % ({quantity})"
        print(
            f"| {name} | {r['cpu_s']:.1f} | {args.duration / r['cpu_s']:.2f} | {r['per_stage']:.2f} | "
            f"{m['rejected_steps'] or '—'} | {m['step_halvings']} | {m['fallback_steps']} | {shown} |"
        )


if __name__ == "__main__":
    main()
