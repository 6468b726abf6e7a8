"""Issue 33, part 4: the error floor of one return, against the exact solution of a linear system.

What is measured (one run):

The system is linear: V1 = Harmonic(w1), V2 = Harmonic(w2), bilinear coupling eps q1 q2, walls at
(qw1, qw2) = (-1, -0.5), h = 1. Its flow is q'' = -K q with K = [[w1^2, eps], [eps, w2^2]]: the
reference is that flow in closed form through its normal modes at 40 digits (mpmath), every event
(section crossing p1 = 0 downward once armed, wall crossings, a wall distance's minimum dipping
below zero) a root of the closed form refined by findroot to 40 digits; reflections exact (the
wall coordinate set, the momentum negated). Starts: --n random points of Sigma_h (theta uniform,
I uniform in (0.02, 0.6)), the same for every method.

For each method and rtol = atol = 1e-8 .. 1e-16 it prints the maximum over the starts of
  dz    max |z - z_ref| over the image state (q1, p1, q2, p2) (section coordinates of the flow),
  dt    |t - t_ref| of the return time,
  dthI  max(|wrap(d theta)|, |d I|) of the image's (theta, I) = S2(q2, p2) (the core's conversion of
        the core's state, against the conversion of the reference state at 40 digits),
and the median of dz. Methods: each hovering stepper that applies (taylor, rk8pd, rkck, and
"exact" once: it ignores the tolerances), and heyoka.py's Taylor integrator with events
(hovering.diagnostics.heyoka_return_map) at the same tolerances (its tol is clamped at 1e-16
by heyoka itself, below machine epsilon it is not meaningful).

Run:  python benchmarks/bench_error_floor.py [--n 200] [--seed 1] [--eps -0.05] [--geometry step]
      python benchmarks/bench_error_floor.py --classes   (the floor on the Tan and strong-coupling
      systems, which have no exact solution: see classes())
"""

from __future__ import annotations

import argparse
import math
import pathlib
import sys as _sys
import time

import mpmath as mp
import numpy as np

import hovering
from hovering import _core

_sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests"))
from helpers.linear_reference import QW1, QW2, LinearFlow, theta_I, wrap  # noqa: E402 (the tests' reference, one copy)

mp.mp.dps = 40


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--eps", type=float, default=-0.05)
    ap.add_argument("--w2", type=float, default=1.3)
    ap.add_argument("--geometry", default="step", choices=("step", "wall", "none"))
    ap.add_argument("--steppers", default="taylor,rk8pd,rkck")
    ap.add_argument("--no-heyoka", action="store_true")
    a = ap.parse_args()
    w1, w2 = 1.0, a.w2
    sys = hovering.StepSystem(
        hovering.Harmonic(w1),
        hovering.Harmonic(w2),
        hovering.Bilinear(),
        eps=a.eps,
        qw1=QW1,
        qw2=QW2,
        geometry=a.geometry,
    )
    rng = np.random.default_rng(a.seed)
    z0, ok, _ = _core.flow.section_points(
        sys.core, 1.0, rng.uniform(-np.pi, np.pi, 4 * a.n), rng.uniform(0.02, 0.6, 4 * a.n)
    )
    z0 = np.ascontiguousarray(z0[ok][: a.n])
    t0 = time.perf_counter()
    flow = LinearFlow(w1, w2, a.eps)
    ref = [flow.ret(z, a.geometry) for z in z0]
    zr = np.array([[float(x) for x in r[0]] for r in ref])
    tr = np.array([float(r[1]) for r in ref])
    thIr = [theta_I(w2, r[0][2], r[0][3]) for r in ref]
    itin = [r[2] for r in ref]
    print(
        f"linear system: Harmonic({w1}) x Harmonic({w2}), eps {a.eps}, geometry {a.geometry}, h = 1, "
        f"{len(z0)} starts (seed {a.seed}); reference at {mp.mp.dps} digits in {time.perf_counter() - t0:.1f} s; "
        f"itineraries {dict(zip(*(x.tolist() for x in np.unique(itin, return_counts=True))))}"
    )

    def errors(z, t, good):
        if not good.all():
            return None
        dz = np.max(np.abs(z - zr), axis=1)
        dt = np.abs(t - tr)
        c = _core.flow.section_coordinates(sys.core, np.ascontiguousarray(z))
        dth = [abs(float(wrap(mp.mpf(c[k, 0]) - thIr[k][0]))) for k in range(len(z))]
        dI = [abs(float(mp.mpf(c[k, 1]) - thIr[k][1])) for k in range(len(z))]
        return dz.max(), np.median(dz), dt.max(), max(max(dth), max(dI))

    rows = []
    tols = [10.0**-k for k in range(8, 17)]
    for st in a.steppers.split(","):
        for tol in tols:
            d = _core.flow.return_maps(sys.core, z0, hovering.flow.flow_options(rtol=tol, atol=tol, stepper=st), 1)
            good = d["status"] == 0
            rows.append((st, tol, errors(d["z"], d["time"], good), int((~good).sum())))
    d = _core.flow.return_maps(sys.core, z0, hovering.flow.flow_options(stepper="exact"), 1)
    rows.append(("exact", math.nan, errors(d["z"], d["time"], d["status"] == 0), int((d["status"] != 0).sum())))
    if not a.no_heyoka:
        from hovering.diagnostics import heyoka_return_map

        for tol in tols:
            out, _ = heyoka_return_map(sys, list(z0), tol)
            good = np.array([o is not None for o in out])
            z = np.array([o[:4] if o is not None else [np.nan] * 4 for o in out])
            # heyoka's returned state has no time here: dt is not measured for it (NaN).
            e = errors(z, tr, good)
            rows.append(("heyoka", tol, None if e is None else (e[0], e[1], math.nan, e[3]), int((~good).sum())))
    print(f"{'method':8} {'rtol':>7} {'max dz':>9} {'med dz':>9} {'max dt':>9} {'max dthI':>9}  failed")
    for st, tol, e, bad in rows:
        if e is None:
            print(f"{st:8} {tol:7.0e}  (not every start returned: {bad} failed)")
            continue
        print(f"{st:8} {tol:7.0e} {e[0]:9.2e} {e[1]:9.2e} {e[2]:9.2e} {e[3]:9.2e}  {bad}")
    for st in {r[0] for r in rows}:
        best = min((r for r in rows if r[0] == st and r[2] is not None), key=lambda r: r[2][0], default=None)
        if best:
            print(f"floor {st:8}: max dz {best[2][0]:.2e} at rtol {best[1]:.0e}")


def classes():
    """The floor per system class where no exact solution exists: taylor (rtol 1e-16, 1e-15) and rk8pd
    (1e-14) against heyoka.py at tol 1e-16 (two independent Taylor codes: their distance bounds the
    sum of their errors), and against the closed form at eps = 0 (the event-driven angle flow,
    rounding only); 200 starts each, max |dz| over the starts every method returned."""
    from hovering.diagnostics import heyoka_return_map

    def starts(s, n=200, h=1.0):
        rng = np.random.default_rng(1)
        z, ok, _ = _core.flow.section_points(
            s.core, h, rng.uniform(-np.pi, np.pi, 8 * n), rng.uniform(0.02, 0.6, 8 * n)
        )
        return np.ascontiguousarray(z[ok][:n])

    hv = hovering
    cases = {
        "Tan, eps=0 (exact ref)": (
            hv.StepSystem(hv.Harmonic(1.0), hv.Tan(1.4, 0.7), hv.Bilinear(), eps=0.0, qw1=-1, qw2=-0.5),
            True,
        ),
        "README Tan eps=-0.05": (hv.paper.system(-0.05), False),
        "Tan x Tan eps=0.05": (
            hv.StepSystem(hv.Tan(1.0, 0.5), hv.Tan(1.4, 0.7), hv.Bilinear(), eps=0.05, qw1=-1, qw2=-0.5),
            False,
        ),
        "strong coupling eps=0.6": (hv.paper.system(0.6), False),
    }
    for name, (s, ex) in cases.items():
        z0 = starts(s)
        t = _core.flow.return_maps(s.core, z0, hv.flow.flow_options(rtol=1e-16, atol=1e-16, stepper="taylor"), 1)
        t15 = _core.flow.return_maps(s.core, z0, hv.flow.flow_options(rtol=1e-15, atol=1e-15, stepper="taylor"), 1)
        r8 = _core.flow.return_maps(s.core, z0, hv.flow.flow_options(rtol=1e-14, atol=1e-14, stepper="rk8pd"), 1)
        if ex:
            ref = _core.flow.return_maps(s.core, z0, hv.flow.flow_options(stepper="exact"), 1)["z"]
            rn = "exact"
        else:
            out, _ = heyoka_return_map(s, list(z0), 1e-16)
            ref = np.array([o[:4] if o is not None else [np.nan] * 4 for o in out])
            rn = "heyoka 1e-16"
        ok = (t["status"] == 0) & np.isfinite(ref).all(1) & (t15["status"] == 0) & (r8["status"] == 0)

        def f(d, ok=ok, ref=ref):
            return np.max(np.abs(d["z"][ok] - ref[ok]))

        print(f"{name:28} n={ok.sum()} vs {rn}: taylor1e-16 {f(t):.2e} taylor1e-15 {f(t15):.2e} rk8pd1e-14 {f(r8):.2e}")


if __name__ == "__main__":
    if "--classes" in _sys.argv:
        classes()
    else:
        main()
