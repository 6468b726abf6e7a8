"""Cost of a hovering-set measurement: 1e5 initial conditions x 1e4 iterates, printed as ratios.

Compares, on the same sample points of the box below K = 0 (eps = 0.2, paper parameters):
  * hovering.TruncatedMap.hovering_area: C++ lane kernel with early exit (an orbit stops at its
    first impact and its lane is refilled at once), F_0 check included;
  * the same C++ iteration without early exit (every orbit runs all steps): what early exit saves;
  * NumPy with early exit by active-set compression (the best one can do in NumPy), timed on a
    subsample and scaled (it would take minutes on the full set).

Not a test. Run: python benchmarks/bench_hovering.py
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

import hovering
from hovering import Status, paper

TWO_PI = 2 * np.pi


def numpy_never_impacts(phi, K, n_steps, p):
    """Early-exit NumPy: iterate only the orbits that have not impacted yet."""
    x, k = phi.copy(), K.copy()
    alive = np.ones(phi.size, bool)
    idx = np.arange(phi.size)
    a = 2 * (np.pi - p["theta_w"])
    for _ in range(n_steps):
        if idx.size == 0:
            break
        xi, ki = x[idx], k[idx]
        neg = ki < 0
        Om = p["Omega0"] + p["tau0"] * ki
        JR = np.where(neg, a + p["tau1"] * ki, 0.0)
        J1 = 2 * p["lam"] * np.sqrt(np.maximum(-ki, 0.0))
        d = np.mod(xi - (np.pi - 0.5 * (Om + JR + J1)), TWO_PI)
        impact = neg & (d < J1 + JR)
        alive[idx[impact]] = False
        keep = ~impact
        idx, xi, ki, Om = idx[keep], xi[keep], ki[keep], Om[keep]
        xi = np.mod(xi + Om + np.pi, TWO_PI) - np.pi
        x[idx] = xi
        k[idx] = ki + p["eps"] * np.sin(xi)
    return alive


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--samples", type=int, default=100_000)
    ap.add_argument("--steps", type=int, default=10_000)
    ap.add_argument("--eps", type=float, default=0.2)
    ap.add_argument("--numpy-fraction", type=float, default=0.05, help="share of the points NumPy is timed on")
    args = ap.parse_args(argv)

    p = dict(eps=args.eps, **paper.FIGURE)
    m = hovering.TruncatedMap(**p)
    K_low = -2 * args.eps / math.sin(p["Omega0"] / 2)

    t0 = time.perf_counter()
    hv = hovering.hovering_area(m, n_steps=args.steps, n_samples=args.samples, K_low=K_low)
    t_ours = time.perf_counter() - t0

    rng = np.random.default_rng(0)
    phi = rng.uniform(-np.pi, np.pi, hv.n_samples)
    K = rng.uniform(K_low, 0.0, hv.n_samples)
    t0 = time.perf_counter()
    r = m.iterate(phi, K, args.steps, record=(), exit_regions={"0u", "0"}, stop_on_exit=True)
    t_exit = time.perf_counter() - t0
    t0 = time.perf_counter()
    m.iterate(phi, K, args.steps, record=(), exit_regions={"0u", "0"})
    t_full = time.perf_counter() - t0

    n_np = max(1000, int(args.numpy_fraction * hv.n_samples))
    t0 = time.perf_counter()
    alive_np = numpy_never_impacts(phi[:n_np], K[:n_np], args.steps, p)
    t_np = (time.perf_counter() - t0) * hv.n_samples / n_np
    # Same orbits, same verdicts (a chaotic orbit may differ by rounding after many steps: count them).
    mismatch = int(np.count_nonzero(alive_np != (r.status[:n_np] == Status.OK)))

    steps_taken = int(r.steps_done.sum())
    print(
        f"hovering-set measurement, eps = {args.eps}, {hv.n_samples} points x {args.steps} iterates "
        f"(F_eps; hovering_area also runs the F_0 check)"
    )
    print(
        f"  |HOV| = {hv.area:.4f} +- {hv.error:.4f} (theory eq:hovsetsize {hv.theory:.4f}); "
        f"{steps_taken:.3e} steps taken with early exit of {hv.n_samples * args.steps:.3e} requested"
    )
    print(f"{'method':52s} {'time [s]':>9s} {'vs NumPy':>9s}")
    rows = [
        ("NumPy, early exit by compression (scaled from subsample)", t_np),
        ("C++ lanes, no early exit (all orbits all steps)", t_full),
        ("C++ lanes, early exit (iterate, F_eps only)", t_exit),
        ("hovering_area (F_0 check + F_eps, early exit)", t_ours),
    ]
    for name, t in rows:
        print(f"{name:52s} {t:9.2f} {t_np / t:8.1f}x")
    print(
        f"early exit saves {t_full / t_exit:.1f}x; NumPy/C++ verdict mismatches on the subsample: {mismatch} of {n_np}"
    )


if __name__ == "__main__":
    main()
