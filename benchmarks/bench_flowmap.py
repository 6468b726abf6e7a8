"""Iterating the full return map: FlowMap.iterate vs a Python loop over Section.return_map vs heyoka.py.

System of the FlowMap issue: V1 = Harmonic(1), V2 = Tan(1.4, 0.7), bilinear coupling, eps = -0.05,
step at (-1, -0.5), h = 1; orbits near the tangency (|K| < 0.05, all four regions visited).
Prints returns per second and the ratios, measured in this run (best of 3 after a warm-up; this
VM's speed drifts up to 1.5x over minutes), plus the cost of one full-flow hovering-area
measurement (2000 points x 2000 returns). heyoka.py rows appear when it is installed (pip install
heyoka): its Taylor integrator with terminal events for the walls and the section, driven by the
Python loop a heyoka.py user writes; its images are compared with ours to show the accuracy matches.

    python benchmarks/bench_flowmap.py [--quick]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import hovering as hv
from hovering import paper
from hovering.paper import QW1, QW2, H

EPS = -0.05
SYS = paper.system(EPS)


def best(fn, repeat=3):
    """Best wall time of repeat calls (after one warm-up call) and the last result."""
    out = fn()
    t = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        t = min(t, time.perf_counter() - t0)
    return t, out


def heyoka_loop(theta, I, n_returns, tol):
    """The step system in heyoka.py: terminal events at q1 = qw1, q2 = qw2 (reflect if the wall is
    there, else go on), p1 = 0 upward (arms) and downward (the section once armed)."""
    import heyoka as hy

    q1, p1, q2, p2 = hy.make_vars("q1", "p1", "q2", "p2")
    w2, a2 = 1.4, 0.7
    sys = [
        (q1, p1),
        (p1, -q1 - EPS * q2),
        (q2, p2),
        (p2, -(w2**2 / a2) * hy.tan(a2 * q2) / hy.cos(a2 * q2) ** 2 - EPS * q1),
    ]
    neg, pos = hy.event_direction.negative, hy.event_direction.positive
    ev = [
        hy.t_event(q1 - QW1, direction=neg),
        hy.t_event(q2 - QW2, direction=neg),
        hy.t_event(p1, direction=neg),
        hy.t_event(p1, direction=pos),
    ]
    ta = hy.taylor_adaptive(sys, [1.0, 0.0, 0.0, 0.1], t_events=ev, tol=tol)
    z0 = hv.Section(SYS, H).point(theta, I)
    out = np.empty((len(theta), 4))

    def run():
        for i in range(len(theta)):
            ta.time = 0.0
            ta.state[:] = z0[i]
            for _ in range(n_returns):
                ta.reset_cooldowns()
                armed = False
                while True:
                    oc = int(ta.propagate_until(ta.time + 50.0)[0])
                    if oc == -1 and ta.state[2] < QW2:
                        ta.state[1] = -ta.state[1]
                        armed = True  # a right-wall reflection is q1's turn (p1 from - to +)
                    elif oc == -2 and ta.state[0] < QW1:
                        ta.state[3] = -ta.state[3]
                    elif oc == -4:
                        armed = True
                    elif oc == -3 and armed:
                        break
            out[i] = ta.state
        return out

    return run


def main(argv=None) -> None:
    """Print the table."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller batches")
    args = ap.parse_args(argv)
    n, ns = (60, 50) if args.quick else (200, 200)
    rng = np.random.default_rng(0)
    fm = hv.FlowMap(SYS, h=H, rtol=1e-10)
    phi0, K0 = rng.uniform(-np.pi, np.pi, n), rng.uniform(-0.05, 0.05, n)
    print(f"FlowMap.iterate, {n} orbits x {ns} returns, rtol = atol = 1e-10 (and atol 1e-12), best of 3:")
    rows = {}
    for atol in (1e-10, 1e-12):
        f = hv.FlowMap(SYS, h=H, rtol=1e-10, atol=atol, curve=fm.curve)
        for thr in (1, 2):
            t, _ = best(lambda: f.iterate(phi0, K0, ns, record=(), n_threads=thr))
            rows[(atol, thr)] = n * ns / t
            print(
                f"  atol {atol:g}, {thr} thread(s): {n * ns / t:9.0f} returns/s  ({t / (n * ns) * 1e6:.2f} us per return)"
            )
    ref = rows[(1e-10, 1)]
    print(f"  thread scaling: {rows[(1e-10, 2)] / ref:.2f}x on 2 threads")

    # The starting point: a Python loop calling Section.return_map once per return.
    sec = fm.section
    m1, n1 = (10, 30) if args.quick else (30, 100)

    def python_loop():
        th, I = fm.curve.from_normal(phi0[:m1], K0[:m1])
        for _ in range(n1):
            out = sec.return_map(th, I, rtol=1e-10, atol=1e-10, n_threads=1)
            th, I = out.theta, out.I
        return th

    def one_at_a_time():
        th, I = fm.curve.from_normal(phi0[:m1], K0[:m1])
        for i in range(m1):
            a, b = th[i : i + 1], I[i : i + 1]
            for _ in range(n1):
                out = sec.return_map(a, b, rtol=1e-10, atol=1e-10, n_threads=1)
                a, b = out.theta, out.I
        return a

    t_loop, _ = best(one_at_a_time, 1)
    t_batch, _ = best(python_loop, 1)
    r_loop, r_batch = m1 * n1 / t_loop, m1 * n1 / t_batch
    print(
        f"Python loop over Section.return_map, one orbit per call: {r_loop:9.0f} returns/s -> FlowMap 1 thread "
        f"{ref / r_loop:.1f}x, 2 threads {rows[(1e-10, 2)] / r_loop:.1f}x"
    )
    print(
        f"Python loop over returns, all {m1} orbits per call (1 thread): {r_batch:9.0f} returns/s -> FlowMap 1 thread "
        f"{ref / r_batch:.1f}x"
    )

    try:
        import heyoka  # noqa: F401
    except ImportError:
        print("heyoka.py not installed: pip install heyoka for its rows")
    else:
        th, I = fm.curve.from_normal(phi0[:m1], K0[:m1])
        fs = hv.FlowMap(SYS, h=H, rtol=1e-10, coordinates="section")
        ours = fs.iterate(th, I, n1, record=())
        tight = hv.FlowMap(SYS, h=H, rtol=1e-14, atol=1e-14, coordinates="section").iterate(th, I, 1, record=())
        for tol in (1e-10, 1e-14):
            run = heyoka_loop(th, I, n1, tol)
            t_hy, z = best(run, 1)
            c = sec.coordinates(z)
            one = heyoka_loop(th, I, 1, tol)()
            c1 = sec.coordinates(one)
            err1 = max(np.abs(hv.wrap(c1[:, 0] - tight.phi_final)).max(), np.abs(c1[:, 1] - tight.K_final).max())
            dev = max(np.abs(hv.wrap(c[:, 0] - ours.phi_final)).max(), np.abs(c[:, 1] - ours.K_final).max())
            print(
                f"heyoka.py tol {tol:g}: {m1 * n1 / t_hy:9.0f} returns/s -> FlowMap 1 thread {ref * t_hy / (m1 * n1):.2f}x, "
                f"2 threads {rows[(1e-10, 2)] * t_hy / (m1 * n1):.2f}x; one-return error vs rtol 1e-14 {err1:.1e}; "
                f"after {n1} returns |ours - heyoka| = {dev:.1e}"
            )
        one_ours = hv.FlowMap(SYS, h=H, rtol=1e-10, coordinates="section").iterate(th, I, 1, record=())
        err_ours = max(
            np.abs(hv.wrap(one_ours.phi_final - tight.phi_final)).max(), np.abs(one_ours.K_final - tight.K_final).max()
        )
        print(f"  (ours at rtol = atol = 1e-10: one-return error vs rtol 1e-14 {err_ours:.1e})")

    samples, steps = (500, 500) if args.quick else (2000, 2000)
    t0 = time.perf_counter()
    area = hv.hovering_area(fm, n_steps=steps, n_samples=samples)
    print(
        f"hovering_area of the flow, {samples} points x {steps} returns (2 threads): {time.perf_counter() - t0:.1f} s "
        f"(|HOV| = {area.area:.4f} +- {area.error:.4f}, theory {area.theory:.4f})"
    )


if __name__ == "__main__":
    main()
