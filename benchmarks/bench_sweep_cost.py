"""What a sweep point costs, per kind, and what a full-resolution flow |HOV| vs eps curve costs.

Measured in one run on this machine (all core threads). A point is the same core calls in both
programs (python -m hovering scene's run_point and hovering_sweep --plan), so it is timed once, in
Python; with --exe the executable's time for the whole plan is printed too:

* a truncated-map |HOV| point of examples/scenes/fig_hov_vs_eps.toml (paper map, eps = 0.1):
  100,000 samples x 20,000 steps at full size;
* a flow |HOV| point of examples/scenes/flow_hov_vs_eps.toml at each of its eps, with SAMPLES samples
  x N returns (flow + both truncated models).

The flow's cost is dominated by the orbits that hover (they take all N returns; the others exit at
their first impact), so a point costs ~ samples x N x (hovering fraction) x (time per return); the
extrapolation to 1e4 samples x 1e4 returns scales the measured seconds by (1e4 / samples) x
(1e4 / N) and is printed per eps, for 40 eps spread like these, and for W workers of this machine's
size. Run: python benchmarks/bench_sweep_cost.py [--samples 400] [--returns 1000] [--exe PATH]
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import subprocess
import tempfile
import time
from pathlib import Path

from hovering.scenes.compute import run_point
from hovering.scenes.plan import plan_points, plan_text
from hovering.scenes.schema import load_scene

ROOT = Path(__file__).resolve().parents[1]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=400)
    ap.add_argument("--returns", type=int, default=1000)
    ap.add_argument("--exe", default=None, help="a hovering_sweep to time on the same points")
    args = ap.parse_args()
    cores = os.cpu_count()

    sc = load_scene(ROOT / "examples/scenes/fig_hov_vs_eps.toml", check_output=False)
    sc = dataclasses.replace(sc, eps=(0.1,), series=sc.series[:1])
    p = plan_points(sc)[0]
    t0 = time.perf_counter()
    row = run_point(sc.kind, p)
    t = time.perf_counter() - t0
    n = row["n_samples"]
    print(f"## truncated |HOV| point (paper map, eps = 0.1, {n} samples x {p['n_steps']} steps), {cores} cores")
    print(f"{t:.2f} s, {t / n * 1e6:.1f} us per sample (area {row['area']:.6f} +- {row['error']:.2g})")

    sc = load_scene(ROOT / "examples/scenes/flow_hov_vs_eps.toml", check_output=False)
    sc = dataclasses.replace(sc, samples=args.samples, n_steps=args.returns)
    points = plan_points(sc)
    print(f"\n## flow |HOV| points ({args.samples} samples x {args.returns} returns, flow + models), {cores} cores")
    print("| eps | s | hovering fraction | s per 1e4 x 1e4 point (extrapolated) |")
    print("|---:|---:|---:|---:|")
    total = 0.0
    for p in points:
        t0 = time.perf_counter()
        row = run_point(sc.kind, p)
        t = time.perf_counter() - t0
        frac = row["area"] / (2 * 3.141592653589793 * -row["K_low"])
        full = t * (1e4 / row["n_samples"]) * (1e4 / args.returns)
        total += full
        print(f"| {p['system']['eps']:+.2f} | {t:.2f} | {frac:.2f} | {full:,.0f} |")
    if args.exe:
        with tempfile.TemporaryDirectory() as d:
            plan = Path(d) / "p.toml"
            plan.write_text(plan_text(sc, points=points))
            t0 = time.perf_counter()
            subprocess.run(
                [args.exe, "--plan", str(plan), "--out", str(Path(d) / "c.jsonl")], check=True, capture_output=True
            )
            print(f"hovering_sweep on the same {len(points)} points: {time.perf_counter() - t0:.2f} s")
    per_eps = total / len(points)
    curve = 40 * per_eps
    print(f"\nmean per eps at 1e4 samples x 1e4 returns: {per_eps:,.0f} s on this machine ({cores} cores)")
    print(f"40 eps: {curve / 3600:.1f} h on this machine = {curve * cores / 3600:.0f} core-hours")
    for w in (1, 2, 8, 32):
        print(
            f"  on {w:>2} machines of {cores} cores, ideal division (pieces per eps on a Dask scheduler): "
            f"{curve / w / 3600:6.2f} h"
        )


if __name__ == "__main__":
    main()
