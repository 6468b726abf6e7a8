"""Cost of the transport records of ``iterate``, relative to ``record=()``, on every map.

For the truncated map (SIMD and scalar kernels) and FlowMap, in one run and on the same orbits,
the time of ``iterate`` with

  * ``record=()`` (the reference: final state and status only),
  * ``record=("extrema",)`` (per-orbit min and max of K),
  * ``record=("residence",)`` (returns per region),
  * ``stop=Above(K)`` with a constant K above every orbit (tested every step, never reached),
  * ``stop=Above(curve)`` with an invariant circle above the orbits as the curve: the circles
    below it overlap its range of K, so the spline is evaluated at (nearly) every step,
  * ``record=("orbit",), every=1000`` (every 1000th state kept),

printed as the ratio to ``record=()`` (the target of issue 20: at most 2 on the SIMD kernel).
Then the whole orbit (``every=1``, 16 bytes per step, and the regions, 1 more) on 1 and 2
threads against the map alone and against writing as many bytes into fresh NumPy arrays (the
machine's write rate with the same page faults): what recording costs beyond its bytes.
Each time is the best of ``--repeat`` runs on one thread (the other core of a shared machine
stays free); the truncated orbits are invariant circles of the paper's map at eps = 0.3 (K0 in
[0.02, 0.45] on L1), so none stops or escapes and every configuration does the same steps.

Not a test: timings depend on the machine. Run: python benchmarks/bench_iterate_records.py
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import hovering
from hovering import paper


def best_times(fns: list, repeat: int) -> list:
    """Best wall time of each callable over ``repeat`` rounds, the callables interleaved in each
    round so that a change of the machine's load hits all alike."""
    best = [np.inf] * len(fns)
    for _ in range(repeat):
        for j, fn in enumerate(fns):
            t0 = time.perf_counter()
            fn()
            best[j] = min(best[j], time.perf_counter() - t0)
    return best


def configurations(ceiling: hovering.Curve, K_top: float) -> list:
    """(name, keyword arguments of iterate) in the order printed."""
    return [
        ("record=()", dict(record=())),
        ("extrema", dict(record=("extrema",))),
        ("residence", dict(record=("residence",))),
        ("stop=constant", dict(record=(), stop=hovering.Above(K_top))),
        ("stop=curve", dict(record=(), stop=hovering.Above(ceiling))),
        ("every=1000", dict(record=("orbit",), every=1000)),
    ]


def truncated(n_orbits: int, n_steps: int, repeat: int) -> None:
    m = paper.truncated_map(eps=0.3)
    K0 = np.linspace(0.02, 0.45, n_orbits)
    phi0 = m.L1(K0)
    # The invariant circle through L1 at K = 0.6 (from a recorded orbit), lifted by 0.02: above
    # every orbit, inside their range of K.
    circ = m.iterate([m.L1(0.6)], [0.6], 20_000, record=("orbit",))
    c = hovering.Curve.from_orbit(circ.phi[0], circ.K[0], n=512)
    ceiling = hovering.Curve(c.K + 0.02)
    ext = m.iterate(phi0, K0, n_steps, record=("extrema",), n_threads=1)
    K_top = float(np.max(ext.K_max)) + 0.1
    overlap = np.mean(ext.K_max >= ceiling.K.min())
    print(
        f"\nTruncatedMap eps = 0.3: {n_orbits} orbits x {n_steps} steps, 1 thread, best of {repeat}; "
        f"{overlap:.0%} of the orbits reach above the curve's minimum"
    )
    for kernel in ("simd", "scalar"):
        confs = configurations(ceiling, K_top)
        for name, kw in confs:  # every configuration takes every step
            res = m.iterate(phi0, K0, n_steps, n_threads=1, kernel=kernel, **kw)
            assert res.count(hovering.Status.OK) == n_orbits, (name, np.unique(res.status, return_counts=True))
        times = best_times(
            [lambda kw=kw: m.iterate(phi0, K0, n_steps, n_threads=1, kernel=kernel, **kw) for _, kw in confs], repeat
        )
        print(
            f"  {kernel:6s}  record=() {times[0] * 1e9 / (n_orbits * n_steps):.2f} ns/step;  "
            + "  ".join(f"{name} {t / times[0]:.2f}" for (name, _), t in zip(confs[1:], times[1:]))
        )


def recording(n_orbits: int, n_steps: int, repeat: int) -> None:
    m = paper.truncated_map(eps=0.3)
    K0 = np.linspace(0.02, 0.45, n_orbits)
    phi0 = m.L1(K0)
    shape = (n_orbits, n_steps + 1)
    steps = n_orbits * n_steps

    def write():  # the bytes of record=("orbit",) into fresh arrays, as iterate allocates them
        a, b = np.empty(shape), np.empty(shape)
        a.fill(1.0)
        b.fill(1.0)

    print(f"\nRecording every state: {n_orbits} orbits x {n_steps} steps (SIMD kernel), best of {repeat}")
    for threads in (1, 2):
        fns = [
            lambda: m.iterate(phi0, K0, n_steps, n_threads=threads, record=()),  # (the default records)
            lambda: m.iterate(phi0, K0, n_steps, n_threads=threads, record=("orbit",)),
            lambda: m.iterate(phi0, K0, n_steps, n_threads=threads, record=("orbit", "regions")),
            write,
        ]
        t_map, t_orbit, t_reg, t_write = best_times(fns, repeat)
        print(
            f"  {threads} thread(s): map {steps / t_map / 1e6:.0f} M steps/s; orbit {steps / t_orbit / 1e6:.0f} M "
            f"steps/s ({t_orbit / t_map:.2f}x the map, {16 * steps / t_orbit / 1e9:.1f} GB/s); orbit + regions "
            f"{t_reg / t_map:.2f}x; writing 16 B/step into fresh arrays alone (1 thread): "
            f"{16 * steps / t_write / 1e9:.1f} GB/s, recording's cost beyond the map "
            f"{(t_orbit - t_map) / t_write:.2f}x that write"
        )


def flow(n_orbits: int, n_steps: int, repeat: int) -> None:
    fm = paper.flow_map(eps=0.05)
    K0 = np.linspace(0.02, 0.1, n_orbits)
    phi0 = np.linspace(-3.0, 3.0, n_orbits)
    ext = fm.iterate(phi0, K0, n_steps, record=("extrema",), n_threads=1)
    ok = ext.status == hovering.Status.OK
    phi0, K0 = phi0[ok], K0[ok]
    K_top = float(np.max(ext.K_max[ok])) + 0.1
    # a wavy curve above every orbit: evaluated at every return, never reached
    ceiling = hovering.Curve.from_function(lambda p: K_top + 0.05 + 0.05 * np.cos(3 * p), n=512)
    print(f"\nFlowMap (paper system, eps = 0.05): {phi0.size} orbits x {n_steps} returns, 1 thread, best of {repeat}")
    confs = configurations(ceiling, K_top)
    times = best_times([lambda kw=kw: fm.iterate(phi0, K0, n_steps, n_threads=1, **kw) for _, kw in confs], repeat)
    print(
        f"  flow    record=() {times[0] * 1e6 / (phi0.size * n_steps):.1f} us/return;  "
        + "  ".join(f"{name} {t / times[0]:.2f}" for (name, _), t in zip(confs[1:], times[1:]))
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--orbits", type=int, default=2048)
    ap.add_argument("--steps", type=int, default=20_000)
    ap.add_argument("--record-steps", type=int, default=2000, help="steps of the every-state rows")
    ap.add_argument("--flow-orbits", type=int, default=16)
    ap.add_argument("--flow-returns", type=int, default=200)
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    print(f"hovering {hovering.__version__}, SIMD width {hovering.simd_width()}")
    truncated(a.orbits, a.steps, a.repeat)
    recording(a.orbits, a.record_steps, a.repeat)
    flow(a.flow_orbits, a.flow_returns, a.repeat)


if __name__ == "__main__":
    main()
