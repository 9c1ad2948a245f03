#!/usr/bin/env python3
"""The ideal-CV chain at a loose setting: error of its summed mean tube force and real-time factor, in draws.

    python3 scripts/ideal_cv_draws.py [--duration S] [--window A B] [--rtol R] [--integrator NAME]
                                      [--set KEY=VALUE ...] [--out FILE.json] [--references EARLIER.json]
                                      [--verify {1,2}]

Runs the embedded paper scene with ``pipe.hinge="ideal-cv"`` (docs/performance.md, "What limits the
ideal-CV chain at loose tolerances"):

- two references by different methods, SDIRK2 at 25 µs and ESDIRK3(2) at rtol 1e-6, 33 samples per link;
  their difference is the reference's own error;
- the setting given by ``--set`` (default: rtol 3e-2, steps up to 20 ms, Newton 3e-3, 3 samples per link,
  frames every 10 ms) with ``--integrator`` (default the scene's, ESDIRK3(2); ``trbdf2`` for TR-BDF2) seven
  times, its rtol scaled by 0.9, 0.95, 0.97, 1, 1.03, 1.05 and 1.1: a change no result should care about, so
  the spread of the seven is what one run of that setting is worth.

A draw whose run fails (``ballcage.SimulationError``: diverged, a step it cannot take) is listed with its
message and counted, and the others go on. Prints each run's summed mean tube force
(``tube_normal_mean_all_n`` over the window, default 0.4-1.8 s), its difference from the SDIRK2 reference, the real-time factor of the run's metadata and its force
evaluations. With ``--verify 1`` or ``--verify 2`` each draw is run with ``simulate(..., verify=...)``, and
the table adds what the verification says of the sum: its measured error (against the rtol/10 run) and, with
2, the rtol/10 run's own error as the rtol/100 run measures it and whether that confirms the measured error
(`ballcage.verify.CONFIRM_RULE`), beside the true error against the reference; and whether the verdict over
every headline quantity is confirmed. Takes about 20 s on this project's machine (17 s on 2026-11-27,
08:00:46-08:01:03 UTC; the SDIRK2 reference is most of it), 4 s with ``--references``; with ``--verify 2``
about 3 times that of the draws.
"""

from __future__ import annotations

import argparse
import json
import statistics
from pathlib import Path

import ballcage
from ballcage.verify import headline

QUANTITY = "tube_normal_mean_all_n"
REFERENCES = {
    "SDIRK2 25 µs": ['simulation.integrator="sdirk2"', "simulation.rtol=0", "simulation.dt=2.5e-5", "pipe.tube_contact_points=33"],
    "ESDIRK3(2) rtol 1e-6": ["simulation.rtol=1e-6", "pipe.tube_contact_points=33"],
}
LOOSE = [
    "simulation.max_step=2e-2",
    "simulation.newton.tolerance=3e-3",
    "pipe.tube_contact_points=3",
    "simulation.output_interval=1e-2",
]
RTOL = 3e-2
SCALES = (0.9, 0.95, 0.97, 1.0, 1.03, 1.05, 1.1)


def measure(overrides: list[str], duration: float, window: tuple[float, float], verify: int = 0) -> dict:
    """One ideal-CV run: its summed mean tube force [N], real-time factor and force evaluations; with `verify`, what
    its verification says of the sum and overall."""
    common = ['pipe.hinge="ideal-cv"', f"simulation.duration={duration}", f"record.summary_window=[{window[0]}, {window[1]}]"]
    run = ballcage.simulate({"kind": "drill-pipe"}, overrides=[*common, *overrides], progress=False, verify=verify)
    meta = run.metadata
    out = {
        "overrides": overrides,
        "sum_n": headline(run)[QUANTITY][1],
        "real_time_factor": float(meta["ballcage.real_time_factor"]),
        "force_evaluations": int(meta["ballcage.force_evaluations"]),
    }
    if run.verification is not None:
        row = next(r for r in run.verification.table.to_pylist() if r["quantity"] == QUANTITY)
        out |= {key: row[key] for key in ("rel_difference", "confirm_rel_difference", "confirmed")}
        out["verdict_confirmed"] = run.verification.confirmed
        out["time_ratio"] = run.verification.time_ratio
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--duration", type=float, default=1.8, help="simulated time [s] (default 1.8)")
    parser.add_argument("--window", type=float, nargs=2, default=(0.4, 1.8), metavar=("A", "B"), help="the means' window [s]")
    parser.add_argument("--out", default="out/ideal_cv_draws.json", help="where the raw results go (out/ is not tracked)")
    parser.add_argument("--set", action="append", default=None, metavar="KEY=VALUE", help="the loose setting, besides rtol")
    parser.add_argument("--rtol", type=float, default=RTOL, help=f"the loose setting's middle rtol (default {RTOL})")
    parser.add_argument("--integrator", help="simulation.integrator of the draws (default the scene's, esdirk32)")
    parser.add_argument("--references", metavar="FILE.json", help="reuse the references of an earlier --out (same duration and window)")
    parser.add_argument("--verify", type=int, choices=(1, 2), default=0, help="verify each draw (1: at rtol/10; 2: also at rtol/100)")
    args = parser.parse_args()
    window = (args.window[0], args.window[1])
    loose = LOOSE if args.set is None else args.set
    if args.integrator:
        loose = [f'simulation.integrator="{args.integrator}"', *loose]
    if args.references:
        earlier = json.loads(Path(args.references).read_text())
        if tuple(earlier["window"]) != window or earlier.get("duration") != args.duration:
            parser.error(f"--references {args.references}: its duration and window differ from this run's")
        refs = earlier["references"]
    else:
        refs = {name: measure(o, args.duration, window) for name, o in REFERENCES.items()}
    ref = refs["SDIRK2 25 µs"]["sum_n"]
    other = refs["ESDIRK3(2) rtol 1e-6"]["sum_n"]
    print(f"references: SDIRK2 25 µs {ref:.2f} N, ESDIRK3(2) rtol 1e-6 {other:.2f} N ({100 * abs(other - ref) / ref:.3f} % apart)")
    print(f"setting: rtol {args.rtol:g} x scale, {' '.join(loose)}")
    checked = " verified error | rtol/10 run's own error | sum confirmed | verdict confirmed | verification time |"
    print("| rtol | sum [N] | error | real-time factor | force evaluations |" + (checked if args.verify else ""))
    print("|---:|---:|---:|---:|---:|" + ("---:|---:|---|---|---:|" if args.verify else ""))
    draws, failed = [], []
    for scale in SCALES:
        try:
            d = measure([f"simulation.rtol={args.rtol * scale:.6g}", *loose], args.duration, window, args.verify)
        except ballcage.SimulationError as e:
            failed.append({"rtol": args.rtol * scale, "message": str(e)})
            print(f"| {args.rtol * scale:.4g} | failed: {str(e)[:110]}… | | | |")
            continue
        d["error"] = abs(d["sum_n"] - ref) / ref
        draws.append(d)
        line = f"| {args.rtol * scale:.4g} | {d['sum_n']:.2f} | {100 * d['error']:.3f} % | {d['real_time_factor']:.1f} | {d['force_evaluations']} |"
        if args.verify:
            own = "" if d["confirm_rel_difference"] is None else f"{100 * d['confirm_rel_difference']:.3f} %"
            ratio = "" if d["time_ratio"] is None else f"{d['time_ratio']:.1f}x"
            line += f" {100 * d['rel_difference']:.3f} % | {own} | {d['confirmed']} | {d['verdict_confirmed']} | {ratio} |"
        print(line)
    errors = [d["error"] for d in draws]
    factors = [d["real_time_factor"] for d in draws]
    if draws:
        print(f"error {100 * min(errors):.3f}-{100 * max(errors):.3f} %, real-time factor {min(factors):.1f}-{max(factors):.1f} (median {statistics.median(factors):.1f})")
    print(f"{len(failed)} of {len(SCALES)} draws failed")
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    result = {"references": refs, "draws": draws, "failed": failed, "window": window, "duration": args.duration}
    out.write_text(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
