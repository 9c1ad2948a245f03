"""Work-precision and scaling figures of ballcage, MuJoCo and rapier on the ideal-CV chain.

Reads what the two peer comparisons wrote and draws, in docs/performance.md's terms:

- error of the per-link mean tube forces against ballcage's converged reference
  (the L2 norm of the differences over the L2 norm of the reference) against the
  wall time of the stepping loop, one marker per engine and step;
- wall time of the stepping loop against the number of joints, and against the simulated time.

Inputs:

- ``--peers FILE.json``: `benchmarks/peers.py --out` results (ballcage, MuJoCo and the
  reference; repeatable). Their reference defines the error of every point.
- ``--rapier FILE.txt``: the printed output of the rapier example
  (`cargo run --release -p ballcage-bench --example rapier_forces -- ...`; repeatable). Its
  averaging window must equal the reference's.

Usage::

    python3 benchmarks/plot_peers.py --peers main.json ladder.json --rapier w12-dt1e-3.txt \\
        --scaling scaling-fit-1ms.json --rapier-scaling r6.txt r12.txt --out docs/
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
from pathlib import Path

WALL = re.compile(r"^(ballcage|rapier):\s+([0-9.]+) s wall for ([0-9.]+) s simulated")
HEAD = re.compile(r"^step ([0-9.e-]+) s, duration ([0-9.]+) s, .*averaged over \[([0-9.]+), ([0-9.]+)\] s")
JOINTS = re.compile(r"^scene: (\d+) ideal-CV joints")
ROW = re.compile(r"^\| link\d+ \| ([0-9.]+) \| ([0-9.]+) \|")


def read_rapier(path: Path) -> dict:
    """dt [s], window [s], joints, wall times [s] and per-link means [N] of one rapier_forces output."""
    out: dict = {"file": str(path), "wall": {}, "ballcage": [], "rapier": []}
    for line in path.read_text().splitlines():
        if m := WALL.match(line):
            out["wall"][m.group(1)] = float(m.group(2))
        elif m := HEAD.match(line):
            out["dt"], out["duration"] = float(m.group(1)), float(m.group(2))
            out["window"] = (float(m.group(3)), float(m.group(4)))
        elif m := JOINTS.match(line):
            out["joints"] = int(m.group(1))
        elif m := ROW.match(line):
            out["ballcage"].append(float(m.group(1)))
            out["rapier"].append(float(m.group(2)))
    if "dt" not in out or "rapier" not in out["wall"]:
        raise SystemExit(f"plot_peers: {path}: not an output of the rapier_forces example")
    return out


def l2_error(means: list[float], ref: list[float]) -> float:
    """‖means − ref‖₂ / ‖ref‖₂ (the measure of benchmarks/peers.py)."""
    num = math.sqrt(sum((a - b) ** 2 for a, b in zip(means, ref, strict=True)))
    return num / math.sqrt(sum(b * b for b in ref))


def work_precision_points(peers: list[dict], rapier: list[dict]) -> tuple[list[tuple], list[float]]:
    """(engine, dt, wall [s], L2 error) per run, and the reference's per-link means [N]."""
    ref = None
    points = []
    for doc in peers:
        for r in doc["results"]:
            if r["engine"] == "ballcage-ref":
                ref = ref or (r["means"], r.get("x_window"))
            elif r.get("complete") and r.get("err_l2") is not None:
                points.append((r["engine"], r["dt"], r["wall_s"], r["err_l2"]))
    if ref is None:
        raise SystemExit("plot_peers: no ballcage reference in the --peers files")
    means, window = ref
    for r in rapier:
        if window and any(abs(a - b) > 1e-6 for a, b in zip(r["window"], window, strict=True)):
            raise SystemExit(f"plot_peers: {r['file']}: window {r['window']} is not the reference's {window}")
        points.append(("rapier", r["dt"], r["wall"]["rapier"], l2_error(r["rapier"], means)))
    return points, means


def plot_work_precision(points: list[tuple], out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for engine, marker in (("ballcage", "o"), ("mujoco", "s"), ("rapier", "^")):
        pts = sorted((p for p in points if p[0] == engine), key=lambda p: p[1])
        if not pts:
            continue
        ax.plot([p[2] for p in pts], [p[3] for p in pts], marker=marker, linestyle="none", label=engine)
        for _, dt, wall, err in pts:
            ax.annotate(f"{dt * 1e3:g} ms", (wall, err), textcoords="offset points", xytext=(4, 3), fontsize=7)
    for _, dt, _, err in (p for p in points if p[0] == "ballcage-ref-check"):
        ax.axhline(err, color="grey", linestyle="--", linewidth=1)
        ax.annotate(f"reference against itself at {dt * 1e3:g} ms: below this, unresolved", (0.01, err),
                    xycoords=("axes fraction", "data"), xytext=(0, -10), textcoords="offset points", fontsize=7)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time of the stepping loop, 1.8 s simulated [s]")
    ax.set_ylabel("L2 error of the per-link mean tube forces [-]")
    ax.set_title("ideal-CV chain, 12 joints: error against wall time")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


def plot_scaling(scaling: list[dict], rapier: list[dict], out: Path, along: str = "joints") -> None:
    """Wall time of each engine's stepping loop against `along`: ``"joints"`` or ``"duration"`` [s]."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    series: dict[str, list[tuple[float, float]]] = {}
    for doc in scaling:
        for r in doc["results"]:
            if r["engine"] != "ballcage-ref" and r.get("complete"):
                series.setdefault(r["engine"], []).append((r[along], r["wall_s"]))
    for r in rapier:
        series.setdefault("rapier", []).append((r[along], r["wall"]["rapier"]))
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for engine, pts in sorted(series.items()):
        pts.sort()
        ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", label=engine)
    ax.set_xscale("log", base=2)
    ax.set_yscale("log")
    ax.set_xlabel("joints [-]" if along == "joints" else "simulated time [s]")
    ax.set_ylabel("wall time of the stepping loop [s]")
    what = "the number of joints" if along == "joints" else "the simulated time, 12 joints"
    ax.set_title(f"ideal-CV chain at 1 ms: run time against {what}")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--peers", nargs="+", type=Path, default=[], help="benchmarks/peers.py --out JSON files")
    p.add_argument("--rapier", nargs="*", type=Path, default=[], help="rapier_forces outputs, same window")
    p.add_argument("--scaling", nargs="*", type=Path, default=[], help="peers.py JSON of a --joints scan")
    p.add_argument("--rapier-scaling", nargs="*", type=Path, default=[], help="rapier_forces outputs per joints")
    p.add_argument("--durations", nargs="*", type=Path, default=[], help="peers.py JSON of a --duration scan")
    p.add_argument("--rapier-durations", nargs="*", type=Path, default=[], help="rapier_forces outputs per duration")
    p.add_argument("--out", type=Path, default=Path("."), help="directory for the PNGs")
    a = p.parse_args(argv)
    peers = [json.loads(f.read_text()) for f in a.peers]
    points, _ = work_precision_points(peers, [read_rapier(f) for f in a.rapier])
    print("| engine | dt [s] | wall [s] | L2 error |\n|---|---:|---:|---:|")
    for engine, dt, wall, err in sorted(points):
        print(f"| {engine} | {dt:g} | {wall:.3g} | {err:.3f} |")
    a.out.mkdir(parents=True, exist_ok=True)
    plot_work_precision(points, a.out / "work-precision-peers.png")
    if a.scaling or a.rapier_scaling:
        scaling = [json.loads(f.read_text()) for f in a.scaling]
        plot_scaling(scaling, [read_rapier(f) for f in a.rapier_scaling], a.out / "scaling-peers.png")
    if a.durations or a.rapier_durations:
        durations = [json.loads(f.read_text()) for f in a.durations]
        rapier = [read_rapier(f) for f in a.rapier_durations]
        plot_scaling(durations, rapier, a.out / "duration-peers.png", along="duration")
    return 0


if __name__ == "__main__":
    sys.exit(main())
