"""Issue 33, part 6: the taylor stepper against heyoka.py on systems it was NOT tuned on.

The README system (Harmonic x Tan, bilinear coupling) is where the Taylor lanes were tuned; here
the potentials and the coupling change: Tan x Tan, Tan x Harmonic and Harmonic x Tan, each with the
polynomial coupling Vc = q1^2 q2 + q1 q2^3 (eps = 0.05), in both geometries (the right wall only,
and the step), corner (-1, -0.5), h = 1.

What is measured (one run, all ratios from this run; the VM is a shared, loaded 2-core box):

* ours: FlowMap.iterate (section coordinates, record nothing, n_threads=1, stepper "taylor",
  rtol = atol = 1e-10: the defaults a user gets) for n orbits x ns returns: returns/s.
* heyoka.py: the stream and batch forms of heyoka_forms.HeyokaFlow (one propagate_until per start,
  resp. per SIMD batch of starts, for ~m returns each; walls reflected by Python callbacks, the
  section a non-terminal event that records): returns/s.
* matched error: each method's error is max over the orbits of max |dz| over the state (q1, p1, q2,
  p2) after ONE return from the same start, against hovering "taylor" at rtol = atol = 1e-16
  (Section.return_map; heyoka: its first section crossing). heyoka runs at the LOOSEST tolerance of
  the grid whose error is within ours (so its time is the least it needs to match our accuracy);
  the stream form at the batch form's tolerance (same algorithm, scalar). If no grid tolerance
  matches, the tightest is used and marked "(!)".
* per orbit-step: each method's steps per return (ours: FlowMap's work counter; heyoka.py: the
  n_steps of its batch propagate_res, real starts only) and its time per step. The ratio is their
  product: ours takes fewer, longer steps of higher order (21 against heyoka's 13 at 1e-10).
* timing: process time (time.process_time: CPU time of this process, insensitive to the other
  jobs on the box), best of --repeat, the three methods interleaved in rotating order, each timed
  call right after an untimed warm call of the same method (as bench_taylor.py; compilation is
  outside the timing).

Run (hovering, numpy, heyoka.py):

    python bench_systems.py                 # all six systems (~2-4 minutes)
    python bench_systems.py --quick         # smoke run
    python bench_systems.py --systems TT-wall,HT-step --repeat 7
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time

import numpy as np

import hovering as hv

try:
    import heyoka as hy
except ImportError:
    sys.exit("heyoka.py is not installed (pip install heyoka)")

from heyoka_forms import HeyokaFlow, collect_crossings  # noqa: E402

H = 1.0
COUPLING = {(2, 1): 1.0, (1, 3): 1.0}
EPS = 0.05
TOL = 1e-10
HY_GRID = (1e-8, 3e-9, 1e-9, 3e-10, 1e-10, 3e-11, 1e-11, 3e-12)


def systems() -> dict:
    """key -> StepSystem: three pairs of potentials x two geometries, all with the polynomial coupling."""
    pairs = {
        "TT": (hv.Tan(1.0, 0.6), hv.Tan(1.4, 0.7)),
        "TH": (hv.Tan(1.0, 0.6), hv.Harmonic(math.sqrt(2.0))),
        "HT": (hv.Harmonic(1.0), hv.Tan(1.4, 0.7)),
    }
    out = {}
    for key, (V1, V2) in pairs.items():
        for geo in ("wall", "step"):
            out[f"{key}-{geo}"] = hv.StepSystem(
                V1, V2, hv.Polynomial(dict(COUPLING)), eps=EPS, qw1=-1.0, qw2=-0.5, geometry=geo
            )
    return out


def starts(sys_, n, seed=0):
    """theta uniform, I = I_tan * U(0.3, 1.3) (both sides of the tangency, as bench_taylor.py)."""
    rng = np.random.default_rng(seed)
    I_tan = sys_.V2.action(H - sys_.V1.V(sys_.qw1))
    return rng.uniform(-np.pi, np.pi, n), I_tan * rng.uniform(0.3, 1.3, n)


def state_error(za, zb, mask):
    return float(np.max(np.abs(np.asarray(za)[mask] - np.asarray(zb)[mask])))


def timed(fn):
    """(count, process seconds) of one call of fn() -> count."""
    t0 = time.process_time()
    count = fn()
    return count, time.process_time() - t0


def run_system(key, s, args):
    sec = hv.Section(s, H)
    th, I = starts(s, args.n)
    z0 = sec.point(th, I)
    ref = sec.return_map(th, I, stepper="taylor", rtol=1e-16, atol=1e-16, n_threads=1)
    ours1 = sec.return_map(th, I, stepper="taylor", rtol=TOL, atol=TOL, n_threads=1)
    ok = (ref.status == hv.FlowStatus.OK) & (ours1.status == hv.FlowStatus.OK)
    err_ours = state_error(ours1.z, ref.z, ok)
    hf = HeyokaFlow(sec)
    hy_err = {}
    for tol in HY_GRID:
        zc = collect_crossings(hf, "batch", z0, 1, tol)[:, 0]
        good = ok & np.isfinite(zc).all(axis=1)
        hy_err[tol] = (state_error(zc, ref.z, good), int(good.sum()))
    fits = [t for t in HY_GRID if hy_err[t][0] <= err_ours]
    tol_hy = max(fits) if fits else min(HY_GRID)
    flag = "" if fits else " (!)"
    hf.integrator("stream", tol_hy)

    fm = hv.FlowMap(s, H, coordinates="section", stepper="taylor", rtol=TOL, atol=TOL)
    ns, m = args.ns, args.ns
    statuses = {}

    steps = {}

    def ours():
        r = fm.iterate(th, I, ns, record=(), n_threads=1)
        statuses.update(dict(zip(*np.unique(r.status, return_counts=True))))
        steps["ours"] = r.work["steps"] / (args.n * ns)
        return args.n * ns

    def hy_batch():
        out, total, secs = hf.batched(z0, tol_hy, m)
        steps["hy batch"] = hf.last_steps / max(total, 1)
        return total

    configs = {
        "ours": ours,
        "hy batch": hy_batch,
        "hy stream": lambda: hf.stream(z0, tol_hy, m)[1],
    }
    names = list(configs)
    best = dict.fromkeys(names, math.inf)
    for rep in range(args.repeat):
        for name in names[rep % 3 :] + names[: rep % 3]:
            configs[name]()  # warm, untimed
            count, secs = timed(configs[name])
            best[name] = min(best[name], secs / count)
    rate = {k: 1 / v for k, v in best.items()}
    return dict(
        err_ours=err_ours,
        tol_hy=tol_hy,
        err_hy=hy_err[tol_hy][0],
        flag=flag,
        rate=rate,
        steps=steps,
        statuses={hv.FlowStatus(int(k)).name: int(v) for k, v in statuses.items()},
        compared=int(ok.sum()),
    )


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--systems", default=None, help="comma-separated keys (default: all)")
    ap.add_argument("--n", type=int, default=None, help="orbits (default 64, --quick 16)")
    ap.add_argument("--ns", type=int, default=None, help="returns per orbit (default 40, --quick 10)")
    ap.add_argument("--repeat", type=int, default=None, help="timed repeats (default 5, --quick 2)")
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    args.n = args.n or (16 if args.quick else 64)
    args.ns = args.ns or (10 if args.quick else 40)
    args.repeat = args.repeat or (2 if args.quick else 5)
    allsys = systems()
    keys = args.systems.split(",") if args.systems else list(allsys)
    print(
        f"hovering {hv.__version__}, heyoka.py {hy.__version__} (SIMD batch {hy.recommended_simd_size()}); "
        f"Vc = q1^2 q2 + q1 q2^3, eps = {EPS}, h = {H}; {args.n} orbits x {args.ns} returns, best of "
        f"{args.repeat} (process time), ours at rtol = atol = {TOL:g}"
    )
    print(f"load average at start: {os.getloadavg()[0]:.2f}")
    hdr = (
        f"{'system':8s} {'err ours':>9s} {'hy tol':>7s} {'err hy':>9s} {'ours r/s':>9s} {'batch r/s':>9s} "
        f"{'stream r/s':>10s} {'/batch':>7s} {'/stream':>7s}"
    )
    print(hdr)
    t0 = time.perf_counter()
    per_step = []
    for k in keys:
        r = run_system(k, allsys[k], args)
        rt = r["rate"]
        print(
            f"{k:8s} {r['err_ours']:9.1e} {r['tol_hy']:7.0e} {r['err_hy']:9.1e}{r['flag']} {rt['ours']:9.0f} "
            f"{rt['hy batch']:9.0f} {rt['hy stream']:10.0f} {rt['ours'] / rt['hy batch']:6.2f}x "
            f"{rt['ours'] / rt['hy stream']:6.2f}x   statuses {r['statuses']}, compared {r['compared']}",
            flush=True,
        )
        per_step.append((k, r["steps"], rt))
    # Where the ratio comes from: steps per return (order and step rule) times time per step.
    print("\nper orbit-step: steps per return and ns per step (ours; heyoka.py batch)")
    for k, st, rt in per_step:
        ns_ours = 1e9 / rt["ours"] / st["ours"]
        ns_hy = 1e9 / rt["hy batch"] / st["hy batch"]
        print(
            f"{k:8s} steps/return {st['ours']:5.1f} ; {st['hy batch']:5.1f}   ns/step {ns_ours:6.0f} ; {ns_hy:6.0f}"
            f"   (fewer steps {st['hy batch'] / st['ours']:.2f}x, time per step {ns_hy / ns_ours:.2f}x)"
        )
    print(f"load average at end: {os.getloadavg()[0]:.2f}; total {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
