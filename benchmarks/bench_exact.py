"""Stepper "exact" vs GSL rk8pd: time per return and error, measured in one run.

Systems (h = 1, qw1 = -1, qw2 = -0.5): V1 = Harmonic(1), V2 = Tan(1.4, 0.7) at eps = 0 (the
event-driven angle flow), wall and step geometries; and the linear flow V1 = Harmonic(1),
V2 = Harmonic(1.3), bilinear eps = 0.1 (normal modes, stepped by the Tracer). Each method runs the
same starts (precomputed points of Sigma_h, so only returns are timed) on one thread; the best of
REPEATS runs is reported. "error" is the largest state difference to the exact stepper (whose own
error is ~1e-15, tests/flow/test_exact_flow.py). Not run in CI. Run: python benchmarks/bench_exact.py
"""

from __future__ import annotations

import time

import numpy as np

import hovering
from hovering import _core, paper
from hovering.flow import flow_options

N, REPEATS, H = 20000, 3, 1.0


def case(V2, eps, geometry):
    return paper.system(eps, geometry, V2=V2)


def timed(sys, z, opts):
    best, out = np.inf, None
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        out = _core.flow.return_maps(sys.core, z, opts, 1, 0.0, 0, None)
        best = min(best, time.perf_counter() - t0)
    return best / len(z) * 1e6, out


def main():
    cases = [
        ("eps=0 wall", case(paper.V2, 0.0, "wall")),
        ("eps=0 step", case(paper.V2, 0.0, "step")),
        ("linear eps=0.1 step", case(hovering.Harmonic(1.3), 0.1, "step")),
    ]
    rng = np.random.default_rng(0)
    print(f"{'system':22s} {'method':16s} {'us/return':>10s} {'ratio':>7s} {'error':>9s} {'steps':>7s}")
    for name, sys in cases:
        z, ok, _ = _core.flow.section_points(sys.core, H, rng.uniform(-np.pi, np.pi, N), rng.uniform(0.02, 0.6, N))
        z = np.ascontiguousarray(z[ok])
        t_exact, ref = timed(sys, z, flow_options(stepper="exact"))
        print(f"{name:22s} {'exact':16s} {t_exact:10.3f} {1.0:7.1f} {0.0:9.1e} {np.mean(ref['steps']):7.1f}")
        for rtol in (1e-13, 1e-10):
            t, d = timed(sys, z, flow_options(stepper="rk8pd", rtol=rtol, atol=rtol))
            both = (d["status"] == 0) & (ref["status"] == 0)
            err = np.max(np.abs(d["z"][both] - ref["z"][both]))
            print(
                f"{name:22s} {'rk8pd ' + format(rtol, 'g'):16s} {t:10.3f} {t / t_exact:7.1f} {err:9.1e} "
                f"{np.mean(d['steps']):7.1f}"
            )


if __name__ == "__main__":
    main()
