"""What a sweep point costs, per kind, and what a full-resolution flow |HOV| vs eps curve costs.

Measured in one run on this machine (all core threads), each point by the C++ runner of
hovering_sweep (hovering._core.scene.run_point: the executable's code) and by Python
(python -m hovering scene's point functions):

* a truncated-map |HOV| point of examples/scenes/fig_hov_vs_eps.toml (paper map, eps = 0.1):
  100,000 samples x 20,000 steps at full size;
* a flow |HOV| point of examples/scenes/flow_hov_vs_eps.toml at each of its eps, with SAMPLES samples
  x N returns (flow + onset model; Python's point also measures the "measured" model).

The flow's cost is dominated by the orbits that hover (they take all N returns; the others exit at
their first impact), so a point costs ~ samples x N x (hovering fraction) x (time per return); the
extrapolation to 1e4 samples x 1e4 returns scales the measured seconds by (1e4 / samples) x
(1e4 / N) and is printed per eps, for 40 eps spread like these, and for W workers of this machine's
size. Run: python benchmarks/bench_sweep_cost.py [--samples 400] [--returns 1000]
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from hovering import _core
from hovering.scenes.compute import _flow_point, _truncated_point
from hovering.scenes.schema import load_scene

ROOT = Path(__file__).resolve().parents[1]


def _with(text: str, **kv) -> str:
    lines = []
    for line in text.splitlines():
        key = line.split("=")[0].strip()
        lines.append(f"{key} = {kv.pop(key)}" if key in kv else line)
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=400)
    ap.add_argument("--returns", type=int, default=1000)
    args = ap.parse_args()
    cores = os.cpu_count()

    path = ROOT / "examples/scenes/fig_hov_vs_eps.toml"
    text = path.read_text()
    sc = load_scene(path, check_output=False)
    i = sc.eps.index(0.1)
    t0 = time.perf_counter()
    row = _core.scene.run_point(text, path.name, i, False, 0)
    t_cpp = time.perf_counter() - t0
    ms = sc.series[0].map_at(0.1)
    t0 = time.perf_counter()
    py = _truncated_point(ms, sc.n_steps, sc.samples, sc.seed, {})
    t_py = time.perf_counter() - t0
    n = row["n_samples"]
    print(f"## truncated |HOV| point (paper map, eps = 0.1, {int(n)} samples x {sc.n_steps} steps), {cores} cores")
    print(f"C++ runner: {t_cpp:.2f} s, Python: {t_py:.2f} s (ratio {t_py / t_cpp:.2f}); same area: "
          f"{row['area'] == py['area']} ({row['area']:.6f} +- {row['error']:.2g})")
    # Steps actually taken: F_0 exits at the first impact; under F_eps the hovering points run N.
    print(f"per sample: {t_cpp / n * 1e6:.1f} us (hovering fraction {row['area'] / (2 * 3.141592653589793 * -row['K_low']):.2f})")

    path = ROOT / "examples/scenes/flow_hov_vs_eps.toml"
    text = _with(path.read_text(), samples=args.samples, n_steps=args.returns)
    sc = load_scene(path, check_output=False)
    print(f"\n## flow |HOV| points ({args.samples} samples x {args.returns} returns, flow + onset model), {cores} cores")
    print("| eps | C++ s | Python s | hovering fraction | s per 1e4 x 1e4 point (extrapolated) |")
    print("|---:|---:|---:|---:|---:|")
    total = 0.0
    for i, e in enumerate(sc.eps):
        t0 = time.perf_counter()
        row = _core.scene.run_point(text, path.name, i, False, 0)
        t_cpp = time.perf_counter() - t0
        t0 = time.perf_counter()
        _flow_point(sc, e, args.returns, args.samples)
        t_py = time.perf_counter() - t0
        frac = row["area"] / (2 * 3.141592653589793 * -row["K_low"])
        full = t_cpp * (1e4 / row["n_samples"]) * (1e4 / args.returns)
        total += full
        print(f"| {e:+.2f} | {t_cpp:.2f} | {t_py:.2f} | {frac:.2f} | {full:,.0f} |")
    per_eps = total / len(sc.eps)
    curve = 40 * per_eps
    print(f"\nmean per eps at 1e4 samples x 1e4 returns: {per_eps:,.0f} s on this machine ({cores} cores)")
    print(f"40 eps: {curve / 3600:.1f} h on this machine = {curve * cores / 3600:.0f} core-hours")
    for w in (1, 2, 8, 32):
        print(f"  on {w:>2} machines of {cores} cores, ideal division (pieces per eps on a Dask scheduler): "
              f"{curve / w / 3600:6.2f} h")


if __name__ == "__main__":
    main()
