"""Issue 33, part 3: what a user who takes the defaults gets, against each stepper named.

FlowMap.iterate on the README system (hovering.paper.system(-0.05), h = 1, section coordinates,
rtol default), --n orbits near the tangency (I = I_tan +- 0.05, as bench_taylor.py part 2) x
--returns returns, one thread. Configurations: the default (no stepper given), "taylor" and
"rk8pd", interleaved in rotating order, best of --repeat (each timed call after an untimed one);
returns/s and the ratio to rk8pd, all from this run. Also prints which stepper the default chose.

Run:  python benchmarks/bench_default_stepper.py [--n 200] [--returns 200] [--repeat 5]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

import hovering as hv


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument("--returns", type=int, default=200)
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    sys = hv.paper.system(-0.05)
    h = 1.0
    I_tan = sys.V2.action(h - sys.V1.V(sys.qw1))
    rng = np.random.default_rng(0)
    th0, I0 = rng.uniform(-np.pi, np.pi, a.n), I_tan + rng.uniform(-0.05, 0.05, a.n)
    maps = {
        "default": hv.FlowMap(sys, h, coordinates="section"),
        "taylor": hv.FlowMap(sys, h, coordinates="section", stepper="taylor"),
        "rk8pd": hv.FlowMap(sys, h, coordinates="section", stepper="rk8pd"),
    }
    print(
        f"README system (eps -0.05), h = 1, {a.n} orbits x {a.returns} returns, one thread; "
        f"default: {maps['default'].integrator_options}"
    )
    best = dict.fromkeys(maps, math.inf)
    names = list(maps)
    for rep in range(a.repeat + 1):
        for name in names[rep % 3 :] + names[: rep % 3]:
            fm = maps[name]
            fm.iterate(th0, I0, a.returns, record=(), n_threads=1)  # untimed warm call
            t0 = time.perf_counter()
            fm.iterate(th0, I0, a.returns, record=(), n_threads=1)
            if rep:
                best[name] = min(best[name], time.perf_counter() - t0)
    for name in names:
        rate = a.n * a.returns / best[name]
        print(f"{name:8} {rate / 1e3:7.1f}k returns/s   {best['rk8pd'] / best[name]:.2f}x rk8pd")


if __name__ == "__main__":
    main()
