"""Throughput of the truncated-map engine: orbit-steps per second, printed as ratios.

Compares, in one run and on the same orbits:
  * NumPy: a vectorised implementation over all orbits (in-place, preallocated: the fastest
    straightforward NumPy, not a strawman);
  * C++ scalar loop: one orbit at a time with libm sin (kernel="scalar");
  * C++ SIMD: Eigen arrays + SLEEF vector sin over chunks of orbits (kernel="simd");
each C++ kernel on 1 thread and on all threads. Also the cost of recording outputs.

Not a test: timings depend on the machine. Run: python benchmarks/bench_truncated_map.py
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

import hovering
from hovering import paper

TWO_PI = 2 * np.pi


def numpy_iterate(phi, K, n_steps, p):
    """Vectorised NumPy F_eps (same arithmetic as the engine), final state only."""
    phi = phi.copy()
    K = K.copy()
    n = phi.size
    s, Om, JR, J1, d, omega, tmp = (np.empty(n) for _ in range(7))
    neg, up, rt = (np.empty(n, dtype=bool) for _ in range(3))
    a = 2 * (np.pi - p["theta_w"])
    for _ in range(n_steps):
        np.less(K, 0.0, out=neg)
        np.negative(K, out=s)
        np.maximum(s, 0.0, out=s)
        np.sqrt(s, out=s)
        np.multiply(K, p["tau0"], out=Om)
        Om += p["Omega0"]
        np.multiply(K, p["tau1"], out=JR)
        JR += a
        JR *= neg
        np.multiply(s, 2 * p["lam"], out=J1)
        # offset from the left end of J_1, reduced to [0, 2 pi)
        np.add(Om, JR, out=d)
        d += J1
        d *= -0.5
        d += np.pi
        np.subtract(phi, d, out=d)
        np.multiply(d, 1 / TWO_PI, out=tmp)
        np.floor(tmp, out=tmp)
        tmp *= TWO_PI
        d -= tmp
        np.less(d, J1, out=up)
        up &= neg
        np.add(J1, JR, out=tmp)
        np.less(d, tmp, out=rt)
        rt &= neg
        rt &= ~up
        np.copyto(omega, Om)
        omega += JR * up
        omega -= J1 * rt
        phi += omega
        np.add(phi, np.pi, out=tmp)
        tmp *= 1 / TWO_PI
        np.floor(tmp, out=tmp)
        tmp *= TWO_PI
        phi -= tmp
        np.sin(phi, out=tmp)
        tmp *= p["eps"]
        K += tmp
    return phi, K


def numpy_iterate_plain(phi, K, n_steps, p):
    """The same map written the way a NumPy user usually writes it: one expression per line."""
    for _ in range(n_steps):
        s = np.sqrt(np.maximum(-K, 0.0))
        Om = p["Omega0"] + p["tau0"] * K
        neg = K < 0
        JR = np.where(neg, 2 * (np.pi - p["theta_w"]) + p["tau1"] * K, 0.0)
        J1 = 2 * p["lam"] * s
        d = np.mod(phi - (np.pi - 0.5 * (Om + JR + J1)), TWO_PI)
        up = neg & (d < J1)
        rt = neg & ~up & (d < J1 + JR)
        omega = Om + np.where(up, JR, 0.0) - np.where(rt, J1, 0.0)
        phi = np.mod(phi + omega + np.pi, TWO_PI) - np.pi
        K = K + p["eps"] * np.sin(phi)
    return phi, K


def best_time(fn, repeat):
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--orbits", type=int, default=100_000)
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)

    p = dict(eps=0.3, **paper.FIGURE)
    m = hovering.TruncatedMap(**p)
    rng = np.random.default_rng(1)
    phi0 = rng.uniform(-np.pi, np.pi, args.orbits)
    K0 = rng.uniform(-0.6, 0.6, args.orbits)
    work = args.orbits * args.steps
    ncores = os.cpu_count()

    rows = []
    t_np, (pn, kn) = best_time(lambda: numpy_iterate(phi0, K0, args.steps, p), args.repeat)
    rows.append(("NumPy vectorised (in-place, preallocated)", t_np))
    t_npp, _ = best_time(lambda: numpy_iterate_plain(phi0, K0, args.steps, p), args.repeat)
    rows.append(("NumPy vectorised (plain expressions)", t_npp))

    def run(kernel, threads, record=(), sin_ulp=1.0):
        return best_time(
            lambda: m.iterate(phi0, K0, args.steps, record=record, kernel=kernel, n_threads=threads, sin_ulp=sin_ulp),
            args.repeat,
        )

    t_sc1, r_sc = run("scalar", 1)
    rows.append(("C++ scalar loop, 1 thread", t_sc1))
    t_sc, _ = run("scalar", 0)
    rows.append((f"C++ scalar loop, {ncores} threads", t_sc))
    t_si1, r_si = run("simd", 1)
    rows.append(("C++ SIMD (Eigen+SLEEF), 1 thread", t_si1))
    t_si, _ = run("simd", 0)
    rows.append((f"C++ SIMD (Eigen+SLEEF), {ncores} threads", t_si))
    t_f1, _ = run("simd", 1, sin_ulp=3.5)
    rows.append(("C++ SIMD, sin_ulp=3.5, 1 thread", t_f1))
    t_f, _ = run("simd", 0, sin_ulp=3.5)
    rows.append((f"C++ SIMD, sin_ulp=3.5, {ncores} threads", t_f))
    t_rot, _ = run("simd", 0, ("rotation", "regions"))
    rows.append((f"C++ SIMD, {ncores} thr, + regions, rotation", t_rot))
    t_orb, _ = run("simd", 0, ("orbit", "regions", "rotation"))
    rows.append((f"C++ SIMD, {ncores} thr, + full orbits", t_orb))

    # The three implementations iterate the same orbits; the map is chaotic, so compare the first
    # step only (agreement to rounding) and check no orbit stopped early (rates are comparable).
    a1, b1 = numpy_iterate(phi0, K0, 1, p)
    c1, d1 = m.step(phi0, K0)
    assert np.max(np.abs(hovering.wrap(a1 - c1))) < 1e-12 and np.max(np.abs(b1 - d1)) < 1e-12
    assert (r_si.status == 0).all() and (r_sc.status == 0).all(), "an orbit stopped early"
    a2, b2 = numpy_iterate_plain(phi0, K0, 1, p)
    assert np.max(np.abs(hovering.wrap(a2 - c1))) < 1e-12 and np.max(np.abs(b2 - d1)) < 1e-12

    print(
        f"truncated map F_eps, {args.orbits} orbits x {args.steps} steps = {work:.2e} orbit-steps, "
        f"best of {args.repeat}; SIMD width: {hovering.simd_width()} doubles "
        f"({ {8: 'AVX-512', 4: 'AVX2', 2: 'SSE2'}.get(hovering.simd_width(), 'scalar') })"
    )
    print(f"{'method':46s} {'orbit-steps/s':>14s} {'ns/step':>8s} {'vs NumPy':>9s} {'vs NumPy':>9s} {'vs scalar':>10s}")
    print(f"{'':46s} {'':>14s} {'':>8s} {'in-place':>9s} {'plain':>9s} {'C++ 1T':>10s}")
    for name, t in rows:
        rate = work / t
        print(f"{name:46s} {rate:14.3e} {1e9 * t / work:8.2f} {t_np / t:8.1f}x {t_npp / t:8.1f}x {t_sc1 / t:9.2f}x")
    print(f"thread scaling: SIMD {t_si1 / t_si:.2f}x, scalar {t_sc1 / t_sc:.2f}x on {ncores} threads")


if __name__ == "__main__":
    main()
