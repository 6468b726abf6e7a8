"""The cost of a Jacobian: a return with its variational equations vs a plain return.

Flow: FlowMap.jacobian vs FlowMap.returns on the same points (the README system, eps = -0.05, near
the tangency: every region visited), for each stepper that carries the tangents with the state;
both in one thread, so the ratio is the per-return work (Taylor: 8 lanes side by side either way).
Also FlowMap.iterate with and without record "jacobian" (the product along orbits). Truncated map:
iterate with and without record "jacobian" (the SIMD and the scalar kernel).

Prints seconds per call (best of 3 after a warm-up) and the ratios; no assertion (speed is shown,
never tested).

    python benchmarks/bench_jacobian.py [--quick]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import hovering as hv
from hovering import paper


def best(fn, repeat=3):
    fn()
    t = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        t = min(t, time.perf_counter() - t0)
    return t


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer points (a smoke run)")
    args = ap.parse_args()
    n = 64 if args.quick else 512
    rng = np.random.default_rng(0)
    phi, K = rng.uniform(-np.pi, np.pi, n), rng.uniform(-0.05, 0.05, n)
    print(f"flow: README system, eps = -0.05, {n} points with |K| < 0.05, one thread")
    print(f"{'stepper':>8} {'rtol':>7} {'plain s':>9} {'jacobian s':>11} {'ratio':>6}")
    for stepper in ("taylor", "rk8pd", "rkck", "rk4imp", "msadams"):
        for rtol in (1e-10, 1e-13) if stepper in ("taylor", "rk8pd") else (1e-10,):
            fm = paper.flow_map(eps=-0.05, stepper=stepper, rtol=rtol)
            t0 = best(lambda: fm.returns(phi, K, n_threads=1))
            t1 = best(lambda: fm.jacobian(phi, K, n_threads=1))
            print(f"{stepper:>8} {rtol:7.0e} {t0:9.4f} {t1:11.4f} {t1 / t0:6.2f}")
    fm = paper.flow_map(eps=-0.05, stepper="taylor")
    m_orbits, m_steps = (8, 50) if args.quick else (32, 200)
    K0 = np.linspace(-0.1, 0.1, m_orbits)
    t0 = best(lambda: fm.iterate(fm.L1(K0), K0, m_steps, record=(), n_threads=1))
    t1 = best(lambda: fm.iterate(fm.L1(K0), K0, m_steps, record=("jacobian",), n_threads=1))
    print(
        f"flow iterate (taylor, {m_orbits} orbits x {m_steps} returns): plain {t0:.3f} s, jacobian {t1:.3f} s, "
        f"ratio {t1 / t0:.2f}"
    )

    m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=3 * np.pi / 4)
    n_orbits, n_steps = (1000, 1000) if args.quick else (10_000, 10_000)
    K0 = np.linspace(-0.3, 0.3, n_orbits)
    print(f"truncated map: {n_orbits} orbits x {n_steps} steps, one thread")
    for kernel in ("simd", "scalar"):
        t0 = best(lambda: m.iterate(0.1, K0, n_steps, record=(), kernel=kernel, n_threads=1))
        t1 = best(lambda: m.iterate(0.1, K0, n_steps, record=("jacobian",), kernel=kernel, n_threads=1))
        per = 1e9 / (n_orbits * n_steps)
        print(f"{kernel:>7}: plain {t0 * per:.2f} ns/step, jacobian {t1 * per:.2f} ns/step, ratio {t1 / t0:.2f}")


if __name__ == "__main__":
    main()
