"""Long orbits: the reversal error after 1e2, 1e4 and 1e5 returns, Taylor vs rk8pd.

m returns forward (FlowMap.iterate), m back by time reversal (R2 F R2 = F^-1, FlowMap.returns with
inverse=True), distance to the start in section coordinates ``max(|wrap d theta|, |d I|)``: no
reference needed, and it grows with the integrator's error per return (as m^2 for a phase error on
these oscillations; exponentially on chaotic orbits, whatever the integrator). Systems: the wall
system at eps = 0 (integrable: the integrator's error alone) and the README step system at
eps = 0.05 (orbits near the tangency are chaotic: their reversal error says where that begins).
Settings: rk8pd at rtol 1e-12 (the previous best practice) and taylor at 1e-12, 1e-14 and 1e-16.
Prints median and max over the points, and the time per return of each setting.

    python benchmarks/bench_reversal.py [--quick] [--points 8] [--threads 2]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import hovering as hv
from hovering import paper
from hovering.diagnostics.work_precision import _default_actions, _iterate_final, _reverse, _section_distance

SETTINGS = [("rk8pd", 1e-12), ("taylor", 1e-12), ("taylor", 1e-14), ("taylor", 1e-16)]


def reversal(sys, h, stepper, tol, theta, I, m, threads):
    """Reversal errors of each point after m returns, and the seconds per forward return (the
    backward returns are taken one Python call per return, so they are not timed)."""
    fm = hv.FlowMap(sys, h, coordinates="section", stepper=stepper, rtol=tol, atol=tol)
    t0 = time.perf_counter()
    th, ii, st = _iterate_final(fm, theta, I, m, threads)
    dt = time.perf_counter() - t0
    ok = st == 0
    bth, bii, alive = _reverse(fm, th, ii, m, threads)
    ok &= alive
    err = np.full(theta.shape, np.nan)
    err[ok] = _section_distance(bth[ok], bii[ok], theta[ok], I[ok])
    return err, dt * min(threads, theta.size) / (m * theta.size)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="1e2 and 1e3 returns only")
    ap.add_argument("--points", type=int, default=8)
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    ms = (100, 1000) if a.quick else (100, 10_000, 100_000)
    systems = {"wall, eps = 0": paper.section(0.0, "wall"), "step, eps = 0.05": paper.section(0.05)}
    print(f"{a.points} points per system, {a.threads} threads; reversal error median / max (failed orbits: n/a)\n")
    print(
        f"{'system':18s} {'setting':16s} "
        + " ".join(f"{f'm = {m:g}':>22s}" for m in ms)
        + "   us/return (forward, per thread)"
    )
    for name, sec in systems.items():
        rng = np.random.default_rng(0)
        theta = rng.uniform(-np.pi, np.pi, a.points)
        I = _default_actions(sec, a.points, rng)
        for stepper, tol in SETTINGS:
            cells, cost = [], []
            for m in ms:
                err, dt = reversal(sec.sys, sec.h, stepper, tol, theta, I, m, a.threads)
                good = err[np.isfinite(err)]
                cells.append(f"{np.median(good):9.2e} / {good.max():9.2e}" if good.size else f"{'n/a':>21s}")
                cost.append(dt)
            print(
                f"{name:18s} {stepper + f' {tol:g}':16s} "
                + " ".join(f"{c:>22s}" for c in cells)
                + f"   {1e6 * min(cost):7.2f}"
            )


if __name__ == "__main__":
    main()
