"""Issue 22 (high accuracy at low cost): hovering's steppers "taylor" and "rk8pd" against heyoka.py.

What is measured (one run, all ratios from this run; times are this machine's, indicative only):

1. Work-precision of ONE return of the flow to Sigma_h, on five systems (h = 1, step corner (-1, -0.5)):
     (a) wall only, eps = 0          V1 = Harmonic(1), V2 = Tan(1.4, 0.7)
     (b) step, eps = 0               same potentials
     (c) step, eps = 0.05            the README system (bilinear coupling q1 q2)
     (d) step, eps = 0.05            V1 = Harmonic(1), V2 = Harmonic(sqrt 2), bilinear coupling
     (e) wall only, eps = 0.05       V1 = Harmonic(1), V2 = Tan(1.4, 0.7), bilinear coupling
   ~200 random starts per system (theta uniform, I = I_tan * U(0.3, 1.3) as bench_flow.py: both
   sides of the tangency, every region visited; the counts are printed). Each method runs a grid
   of tolerances (half decades 1e-4 .. 1e-16, rtol = atol = tol); its error is measured two ways
   against an exact reference: max over orbits of max(|wrap(d theta)|, |d I|) after the return,
   and of max |d z| over the state z = (q1, p1, q2, p2) after the return. The reference is
   stepper="exact" (closed form) for (a), (b), (d); for (c) and (e), which have none, hovering
   "taylor" at rtol = atol = 1e-16, whose own error is estimated by its distance to rk8pd at 1e-14
   (printed; targets below it are "n/r": not resolved, and taylor at 1e-16, the reference itself,
   is left out of their curves). Only orbits that every method at every tolerance returned OK (hovering
   status OK, heyoka: a return found) are compared; exclusions are printed. Per target error
   1e-6 .. 1e-14 each method's FASTEST setting whose error is within it is shown (time per
   return, its tolerance) with the ratios heyoka / ours (ours = the faster of taylor and rk8pd
   at that target). Timing: best of --repeat runs, the methods interleaved at each tolerance
   (rotating order) so that this VM's drifts hit all alike; one thread everywhere. Every timed
   call follows an untimed call of the same method and setting: a call right after another
   method's (whose code and data evicted its own from the caches) or after an idle pause was
   measured up to 1.4x (after the other method) and 2x (after 50 ms idle) slower than a warm one
   on this VM, whichever method it was; warm calls are what a long computation sees.

   Methods:
     taylor, rk8pd   hovering Section.return_map (public API, one call for all starts, n_threads=1;
                     the section point solve and the image's coordinates are inside the time:
                     printed separately as "overhead").
     hy loop         heyoka.py driven as bench_flow.py does: every event terminal without
                     callback, one propagate_until per event, Python reflects and decides.
                     (Leaner than bench_flow: the start's own section event at t = 0 is skipped by
                     its time instead of an extra "arming" event at q1's minimum.)
     hy 1call        one propagate_until per return: walls are terminal events whose Python
                     callbacks reflect the state and return True (integration goes on), the
                     section is a stopping terminal event. heyoka detects the start's own section
                     crossing at t = 0, so one extra (empty) propagate_until consumes it first.
     hy stream       ONE propagate_until per start for ~M returns: wall callbacks as in 1call,
                     the section a non-terminal event whose callback records the state at the
                     crossing (dense output), so the steps are not cut at the section. Time per
                     return = total / returns recorded; the error is that of the first return.
     hy batch        the stream form in taylor_adaptive_batch (batch = heyoka's SIMD width, 4 on
                     AVX2), 4 starts per propagate_until, t_event_batch / nt_event_batch.
   heyoka.py has no compiled callbacks: every form costs a Python call per wall crossing (a
   reflection, or a step-wall crossing beside / above the step that reflects nothing) and the
   stream forms one per return. All heyoka forms integrate the same equations (Tan's force as
   (w^2/a) t (1 + t^2), t = tan(a q), one tan per force) and are timed from the state z0 to the
   returned state (setting the state and cooldowns included, compilation and coordinates not).

2. FlowMap.iterate (the n-return iteration in C++, section coordinates) on (c) at rtol = atol =
   1e-10: returns/s for taylor and rk8pd on 1 and 2 threads, and the error after 1 and K
   returns against FlowMap taylor at 1e-16; heyoka.py's stream and batch forms at tol 1e-10
   beside them (their k-th section crossing against the same reference; heyoka does not restart
   each return on H = h as FlowMap does).

3. Missed near-grazing impacts (as bench_flow.py): system (a), orbits whose q1 dips 1e-4 .. 1e-14
   below the wall (A1 = 1 + dip): each must reflect exactly once. Per dip depth, out of m
   orbits: hovering (taylor, rk8pd) reports "missed" (OK but no 'R') and "flagged" (status not
   OK, e.g. GRAZING: dips within grazing_tol = 1e-12 are reported, not guessed); heyoka (1call
   form) "missed" = impacts != 1 or no return.

Run (hovering, numpy, heyoka.py installed; a full run takes ~4 minutes on this 2-core VM, --quick ~10 s):

    python bench_taylor.py                      # everything
    python bench_taylor.py --quick              # smoke run: few points, decade grid, small parts 2/3
    python bench_taylor.py --systems a,c --parts 1           # some systems, part 1 only
"""

from __future__ import annotations

import argparse
import math
import sys
import time

import numpy as np

import hovering as hv
from hovering import paper
from hovering.diagnostics.work_precision import _best_time
from hovering.flow.system import Harmonic

try:
    import heyoka as hy
except ImportError:  # the comparison is the point of this script
    sys.exit("heyoka.py is not installed (pip install heyoka)")

from heyoka_forms import NEG, HeyokaFlow, collect_crossings  # noqa: E402  (after the check that heyoka.py is there)

H = paper.H
TARGETS = (1e-6, 1e-8, 1e-10, 1e-12, 1e-14)
HOV = ("taylor", "rk8pd")
HEY = ("hy loop", "hy 1call", "hy stream", "hy batch")


# ----------------------------------------------------------------------------------- systems


def systems() -> dict:
    """The five systems of the comparison: key -> (description, Section)."""
    d = paper.system(0.05, V2=Harmonic(math.sqrt(2.0)))
    return {
        "a": ("wall, eps = 0, V2 = Tan(1.4, 0.7)", paper.section(0.0, "wall")),
        "b": ("step, eps = 0, V2 = Tan(1.4, 0.7)", paper.section(0.0)),
        "c": ("step, eps = 0.05 (README system)", paper.section(0.05)),
        "d": ("step, eps = 0.05, V2 = Harmonic(sqrt 2)", hv.Section(d, H)),
        "e": ("wall, eps = 0.05, V2 = Tan(1.4, 0.7)", paper.section(0.05, "wall")),
    }


#: Systems without a closed form: their reference is taylor at 1e-16, its own error estimated by its
#: distance to rk8pd at 1e-14.
NO_CLOSED_FORM = ("c", "e")


def tangent_action(sec) -> float:
    """I_tan at eps = 0: the action whose q1 oscillation just touches q1 = qw1."""
    s = sec.sys
    return s.V2.action(sec.h - s.V1.V(s.qw1))


def starts(sec, n: int, seed: int = 0):
    """bench_flow's starts: theta uniform, I = I_tan * U(0.3, 1.3) (both sides of the tangency)."""
    rng = np.random.default_rng(seed)
    th = rng.uniform(-np.pi, np.pi, n)
    return th, tangent_action(sec) * rng.uniform(0.3, 1.3, n)


def section_error(sec, za, zb) -> np.ndarray:
    """Per orbit max(|wrap(d theta)|, |d I|) between states (NaN rows stay NaN)."""
    ca, cb = sec.coordinates(za), sec.coordinates(zb)
    return np.maximum(np.abs(hv.wrap(ca[:, 0] - cb[:, 0])), np.abs(ca[:, 1] - cb[:, 1]))


def state_error(za, zb) -> np.ndarray:
    """Per orbit max |d z| over (q1, p1, q2, p2)."""
    return np.abs(np.asarray(za) - np.asarray(zb)).max(axis=1)


def best_of(fn, repeat: int):
    """Best wall time of repeat calls and the last result (the work-precision harness's timer)."""
    return _best_time(fn, repeat)


# ----------------------------------------------------------------------------------- heyoka.py
# The heyoka.py forms (HeyokaFlow) live in heyoka_forms.py, shared with bench_per_call.py.


def heyoka_semantics() -> list:
    """The event semantics of this heyoka.py the forms rely on, checked on x'' = -x (lines to print)."""
    x, v = hy.make_vars("x", "v")
    eqs = [(x, v), (v, -x)]
    ta = hy.taylor_adaptive(eqs, [1.0, 0.0], t_events=[hy.t_event(v, direction=NEG)], tol=1e-12)
    oc0, t_first = int(ta.propagate_until(10.0)[0]), ta.time
    ta.propagate_until(10.0)
    t_second = ta.time
    lines = [
        (
            f"a terminal event the start sits on fires at t = 0 (outcome {oc0} at t = {t_first:g}); the next "
            f"propagate_until, in its cooldown, stops at the real crossing t = {t_second:.12f} (2 pi)"
        )
    ]
    B = int(hy.recommended_simd_size())
    seen = [[] for _ in range(B)]

    def cb(ta, d_sgn, b):  # element 1 stops at its first crossing after t = 0, the others go on
        if ta.time[b] > 0:
            seen[b].append(ta.time[b])
            return b != 1
        return True

    amp = np.linspace(1.0, 0.7, B)
    tb = hy.taylor_adaptive_batch(
        eqs,
        np.vstack([amp, np.zeros(B)]),
        t_events=[hy.t_event_batch(v, callback=cb, direction=NEG)],
        tol=1e-12,
    )
    tb.set_time(np.zeros(B))
    tb.propagate_until(np.full(B, 30.0))
    lines.append(
        f"batch ({B}): when element 1's terminal callback returns False at t = 2 pi, propagate_until stops for ALL "
        f"elements (times {np.array2string(tb.time, precision=3)}, outcomes "
        f"{[int(r[0]) for r in tb.propagate_res]}): one return per element in one call cannot stop each element at "
        "its own return, so the batch form streams (records crossings in a non-terminal callback, returns True)"
    )
    lines.append(
        "non-terminal callbacks must not change the state (heyoka.py docs, Event detection): a reflection is a "
        "terminal event whose Python callback flips the momentum and returns True; there are no compiled "
        "callbacks in heyoka.py, so every wall crossing and (stream forms) every return is one Python call"
    )
    return lines


# ----------------------------------------------------------------------------------- part 1


def tolerance_grid(quick: bool):
    """Half decades 1e-4 .. 1e-16 (decades with --quick)."""
    step = 2 if quick else 1
    return [10.0 ** (-k / 2) for k in range(8, 33, step)]


def reference(key, sec, th, I):
    """Reference states, their OK mask, a description, an estimate of the reference's own error
    (section, state): 0 for the closed form, the distance to rk8pd 1e-14 for (c) and (e), and the itineraries."""
    if key not in NO_CLOSED_FORM:
        r = sec.return_map(th, I, stepper="exact", n_threads=1)
        return r.z, r.status == hv.FlowStatus.OK, 'stepper="exact" (closed form)', (0.0, 0.0), r.itinerary
    r = sec.return_map(th, I, stepper="taylor", rtol=1e-16, atol=1e-16, n_threads=1)
    c = sec.return_map(th, I, stepper="rk8pd", rtol=1e-14, atol=1e-14, n_threads=1)
    ok = (r.status == hv.FlowStatus.OK) & (c.status == hv.FlowStatus.OK)
    est = (float(np.max(section_error(sec, r.z[ok], c.z[ok]))), float(np.max(state_error(r.z[ok], c.z[ok]))))
    return r.z, r.status == hv.FlowStatus.OK, "hovering taylor at rtol = atol = 1e-16", est, r.itinerary


def work_precision(key, label, sec, args):
    """Part 1 on one system: prints its summary tables, returns nothing."""
    n, repeat, m_ret = args.n, args.repeat, args.m_returns
    th, I = starts(sec, n)
    z0 = sec.point(th, I)
    zref, ref_ok, ref_name, ref_err, itinerary = reference(key, sec, th, I)
    regions = {}
    for it in itinerary:
        regions[it] = regions.get(it, 0) + 1
    print(f"\n=== ({key}) {label}: {n} starts, itineraries of the reference {regions}")
    print(f"    reference: {ref_name}", end="")
    if key in NO_CLOSED_FORM:
        print(
            f"; its distance to rk8pd at 1e-14 (its own error estimate): section {ref_err[0]:.1e}, state {ref_err[1]:.1e}"
        )
        print("    errors below that are not resolved: targets under it are marked n/r")
    else:
        print()

    hf = HeyokaFlow(sec)
    runs = {
        "taylor": lambda tol: hov_run(sec, th, I, "taylor", tol),
        "rk8pd": lambda tol: hov_run(sec, th, I, "rk8pd", tol),
        "hy loop": lambda tol: hf.loop(z0, tol)[:3],
        "hy 1call": lambda tol: hf.onecall(z0, tol)[:3],
        "hy stream": lambda tol: hf.stream(z0, tol, m_ret),
        "hy batch": lambda tol: hf.batched(z0, tol, m_ret),
    }
    names = list(runs)
    rows = []  # (method, tol, per-orbit section error, per-orbit state error, ok mask, us per return)
    t_start = time.perf_counter()
    grid = tolerance_grid(args.quick)
    for tol in grid:
        for form in ("loop", "1call", "stream", "batch"):
            hf.integrator(form, tol)  # compile outside the timing
    # Repeats outermost: every (method, tol) is sampled across the whole measurement, so the VM's
    # drifts over seconds hit all settings alike; the methods' order rotates inside.
    best, last = {}, {}
    for rep in range(repeat):
        for i, tol in enumerate(grid):
            k = (rep + i) % len(names)
            for m in names[k:] + names[:k]:
                runs[m](tol)  # warm-up, untimed: see the module docstring
                z, count, secs = runs[m](tol)
                best[m, tol] = min(best.get((m, tol), math.inf), secs / count)
                last[m, tol] = z
    for tol in grid:
        for m in names:
            z = last[m, tol]
            ok = np.isfinite(z).all(axis=1)
            rows.append((m, tol, section_error(sec, z, zref), state_error(z, zref), ok, 1e6 * best[m, tol]))
    elapsed = time.perf_counter() - t_start

    # Orbits compared: OK in the reference and in every run.
    mask = ref_ok.copy()
    for r in rows:
        mask &= r[4]
    bad = [(m, tol, int((~ok & ref_ok).sum())) for m, tol, _, _, ok, _ in rows if (~ok & ref_ok).any()]
    print(f"    compared: {int(mask.sum())} of {n} orbits (reference OK: {int(ref_ok.sum())})", end="")
    print("; runs with failures: " + ", ".join(f"{m} {t:.0e}: {k}" for m, t, k in bad) if bad else "")
    curves = {m: [] for m in names}  # method -> [(tol, section err, state err, us)]
    for m, tol, es, ez, _ok, us in rows:
        if key in NO_CLOSED_FORM and m == "taylor" and tol == 1e-16:
            continue  # the reference itself
        curves[m].append((tol, float(np.max(es[mask])), float(np.max(ez[mask])), us))
    print("    work-precision: max error in (theta, I) over the compared orbits, us per return")
    print(f"    {'tol':>7s} " + " ".join(f"{m:>18s}" for m in names))
    for tol in tolerance_grid(args.quick):
        cells = []
        for m in names:
            r = [x for x in curves[m] if x[0] == tol]
            cells.append(f"{'(reference)':>18s}" if not r else f"{r[0][1]:9.1e} {r[0][3]:8.1f}")
        print(f"    {tol:7.0e} " + " ".join(cells))
    floor = [min(r[c] for rs in curves.values() for r in rs) for c in (1, 2)]
    print(
        f"    lowest error any run reached: (theta, I) {floor[0]:.1e}, state {floor[1]:.1e} (a floor shared by all "
        "methods is the reference's own resolution: targets below it cannot be judged)"
    )
    for kind, col, est in (("(theta, I)", 1, ref_err[0]), ("state (q1, p1, q2, p2)", 2, ref_err[1])):
        print(f"  fastest setting reaching the target, error in {kind}: us per return (its tolerance)")
        print(f"    {'target':>7s} " + " ".join(f"{m:>15s}" for m in names))
        ratio_rows = []
        for target in TARGETS:
            if target < est:
                print(f"    {target:7.0e} " + " ".join(f"{'n/r':>15s}" for _ in names))
                continue
            fast = {}
            for m in names:
                okr = [r for r in curves[m] if r[col] <= target]
                fast[m] = min(okr, key=lambda r: r[3]) if okr else None
            print(
                f"    {target:7.0e} "
                + " ".join(f"{'-':>15s}" if f is None else f"{f[3]:7.1f} ({f[0]:.0e})" for f in fast.values())
            )
            ratio_rows.append((target, fast))
        print(
            f"    ratios   {'rk8pd/taylor':>13s} "
            + " ".join(f"{m + '/ours':>15s}" for m in HEY)
            + "   (ours = faster of taylor, rk8pd)"
        )
        for target, fast in ratio_rows:
            ours = [fast[m][3] for m in HOV if fast[m] is not None]
            cells = [
                f"{fast['rk8pd'][3] / fast['taylor'][3]:13.2f}" if fast["rk8pd"] and fast["taylor"] else f"{'-':>13s}"
            ]
            cells += [f"{fast[m][3] / min(ours):15.2f}" if fast[m] and ours else f"{'-':>15s}" for m in HEY]
            print(f"    {target:7.0e}  " + " ".join(cells))
    # What the hovering times include that the heyoka ones do not: the section point and coordinates.
    t_pt, _ = best_of(lambda: sec.coordinates(sec.point(th, I)), repeat)
    print(
        f"    (hovering times include the section point solve + image coordinates: {1e6 * t_pt / n:.1f} us per "
        f"return; part 1 on this system took {elapsed:.0f} s)"
    )


def hov_run(sec, th, I, stepper, tol):
    """One hovering return_map call: (states with NaN rows where not OK, returns, seconds)."""
    t0 = time.perf_counter()
    r = sec.return_map(th, I, stepper=stepper, rtol=tol, atol=tol, n_threads=1)
    secs = time.perf_counter() - t0
    z = r.z.copy()
    z[r.status != hv.FlowStatus.OK] = np.nan
    return z, len(th), secs


# ----------------------------------------------------------------------------------- part 2


def flowmap_part(args):
    """Part 2: FlowMap.iterate returns/s and error on (c), heyoka's stream forms beside it."""
    sec = paper.section(0.05)
    n, ns, K = (40, 40, 5) if args.quick else (200, 200, 5)
    rng = np.random.default_rng(1)
    I_tan = tangent_action(sec)
    th0, I0 = rng.uniform(-np.pi, np.pi, n), I_tan + rng.uniform(-0.05, 0.05, n)
    print(
        f"\n=== Part 2: FlowMap.iterate on (c), section coordinates, {n} orbits x {ns} returns, "
        f"I = I_tan +- 0.05, rtol = atol = 1e-10, best of {args.repeat}"
    )
    print("  errors: max (median) over the orbits of max(|wrap(d theta)|, |d I|) against FlowMap taylor at 1e-16")
    ref = hv.FlowMap(sec.sys, H, coordinates="section", stepper="taylor", rtol=1e-16, atol=1e-16).iterate(
        th0, I0, K, record=("section",), n_threads=0
    )

    def errors(theta, I):
        """Section error after 1 and after K returns: 'max (median)' over the orbits."""
        e = np.maximum(np.abs(hv.wrap(theta - ref.theta)), np.abs(I - ref.I))
        return tuple(f"{np.nanmax(e[:, k]):.1e} ({np.nanmedian(e[:, k]):.1e})" for k in (1, K))

    # Accuracy first (untimed): FlowMap's first K returns, heyoka's first K crossings.
    maps = {st: hv.FlowMap(sec.sys, H, coordinates="section", stepper=st, rtol=1e-10, atol=1e-10) for st in HOV}
    err = {}
    for st, fm in maps.items():
        r = fm.iterate(th0, I0, K, record=("section",), n_threads=1)
        err[st] = errors(r.theta, r.I)
    hf = HeyokaFlow(sec)
    z0 = sec.point(th0, I0)
    m = min(ns, 50)
    for form in ("stream", "batch"):
        c = np.array([sec.coordinates(x) for x in collect_crossings(hf, form, z0, K)])  # (n, K, 2)
        theta = np.hstack([th0[:, None], c[:, :, 0]])
        I = np.hstack([I0[:, None], c[:, :, 1]])
        err["hy " + form] = errors(theta, I)

    # Timing, the configurations interleaved (rotating order) in every repeat. Each returns (returns
    # done, seconds, statuses): FlowMap is timed around the call, the heyoka forms time their hot part.
    def flowmap_run(fm, thr):
        t0 = time.perf_counter()
        r = fm.iterate(th0, I0, ns, record=(), n_threads=thr)
        return n * ns, time.perf_counter() - t0, dict(zip(*np.unique(r.status, return_counts=True)))

    configs = {
        f"{st} {thr} thr": (lambda fm=fm, thr=thr: flowmap_run(fm, thr)) for st, fm in maps.items() for thr in (1, 2)
    }
    configs["hy stream"] = lambda: hf.stream(z0, 1e-10, m)[1:] + (None,)
    configs["hy batch"] = lambda: hf.batched(z0, 1e-10, m)[1:] + (None,)
    names = list(configs)
    best, statuses = dict.fromkeys(names, math.inf), {}
    for rep in range(args.repeat + 1):  # the first round warms up (thread pool, caches) and is not kept
        for name in names[rep % len(names) :] + names[: rep % len(names)]:
            configs[name]()  # warm-up, untimed: see the module docstring
            count, secs, st = configs[name]()
            if st is not None:
                statuses[name] = st
            if rep:
                best[name] = min(best[name], secs / count)
    rate = {name: 1 / t for name, t in best.items()}
    for name in names:
        key = name.split()[0] if not name.startswith("hy") else name
        extra = f"; statuses {statuses[name]}" if name in statuses else f" ({m} returns per start, tol 1e-10)"
        print(
            f"  {name:13s} {rate[name]:9.0f} returns/s ({1e6 * best[name]:6.2f} us/return); error after 1 return "
            f"{err[key][0]}, after {K} {err[key][1]}{extra}"
        )
    print(
        f"  thread scaling (2 threads / 1): taylor {rate['taylor 2 thr'] / rate['taylor 1 thr']:.2f}x, "
        f"rk8pd {rate['rk8pd 2 thr'] / rate['rk8pd 1 thr']:.2f}x; taylor / rk8pd on 1 thread "
        f"{rate['taylor 1 thr'] / rate['rk8pd 1 thr']:.2f}x"
    )
    ours1, ours2 = max(rate["taylor 1 thr"], rate["rk8pd 1 thr"]), max(rate["taylor 2 thr"], rate["rk8pd 2 thr"])
    for form in ("hy stream", "hy batch"):
        print(
            f"  ratio heyoka {form[3:]} time / ours (faster of taylor, rk8pd): 1 thread {ours1 / rate[form]:.2f}x, "
            f"ours on 2 threads {ours2 / rate[form]:.2f}x"
        )


# ----------------------------------------------------------------------------------- part 3


def grazing_part(args):
    """Part 3: missed near-grazing impacts on (a) per dip depth."""
    sec = paper.section(0.0, "wall")
    V1, V2 = sec.sys.V1, sec.sys.V2
    m = 12 if args.quick else 40
    tt = np.linspace(-3.1, 3.1, m)
    dips = [10.0**-k for k in range(4, 15)]
    hf = HeyokaFlow(sec)
    cols = [("taylor", 1e-6), ("taylor", 1e-12), ("rk8pd", 1e-6), ("rk8pd", 1e-12), ("heyoka", 1e-6), ("heyoka", 1e-12)]
    print(f"\n=== Part 3: near-grazing impacts on (a), {m} orbits per dip (each must reflect once)")
    print("    hovering cells: missed (OK without 'R') / flagged (status not OK: GRAZING etc.); heyoka: impacts != 1")
    print(f"    {'dip':>7s} " + " ".join(f"{f'{a} {b:.0e}':>15s}" for a, b in cols))
    flagged = {}
    for dip in dips:
        h1 = 0.5 * (1 + dip) ** 2  # A1 = 1 + dip: q1 dips `dip` below qw1 = -1 (V1 = Harmonic(1), eps = 0)
        I = np.full(m, V2.action(H - h1))
        cells = []
        for meth, tol in cols:
            if meth == "heyoka":
                z, _, _, imp = hf.onecall(sec.point(tt, I), tol)
                cells.append(f"{int(((imp != 1) | ~np.isfinite(z).all(axis=1)).sum()):15d}")
            else:
                r = sec.return_map(tt, I, stepper=meth, rtol=tol, atol=tol, n_threads=1)
                ok = r.status == hv.FlowStatus.OK
                missed = sum(1 for s, o in zip(r.itinerary, ok) if o and s != "R")
                for st in r.status[~ok]:
                    flagged[hv.FlowStatus(st).name] = flagged.get(hv.FlowStatus(st).name, 0) + 1
                cells.append(f"{f'{missed} / {int((~ok).sum())}':>15s}")
        print(f"    {dip:7.0e} " + " ".join(cells))
    print(f"    hovering's flagged statuses: {flagged or 'none'}")
    assert V1.omega == 1.0  # the dip formula above assumes it


# ----------------------------------------------------------------------------------- main


def main(argv=None) -> None:
    """Parse the options and print the parts asked for."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smoke run: few points, decade grid, small parts 2 and 3")
    ap.add_argument("--systems", default="a,b,c,d,e", help="comma-separated subset of a,b,c,d,e (part 1)")
    ap.add_argument("--parts", default="1,2,3", help="comma-separated subset of 1,2,3")
    ap.add_argument("--n", type=int, default=None, help="starts per system (default 200, --quick 24)")
    ap.add_argument("--repeat", type=int, default=None, help="timed repeats (default 7, --quick 2)")
    ap.add_argument("--m-returns", type=int, default=10, help="returns per start of the heyoka stream forms")
    args = ap.parse_args(argv)
    args.n = args.n or (24 if args.quick else 200)
    args.repeat = args.repeat or (2 if args.quick else 7)
    keys = [k.strip() for k in args.systems.split(",") if k.strip()]
    parts = {p.strip() for p in args.parts.split(",")}
    all_sys = systems()
    unknown = [k for k in keys if k not in all_sys]
    if unknown or not parts <= {"1", "2", "3"}:
        ap.error(f"--systems takes a subset of a,b,c,d,e and --parts of 1,2,3; got {args.systems!r}, {args.parts!r}")
    print(
        f"hovering {hv.__version__}, heyoka.py {hy.__version__} (SIMD batch {hy.recommended_simd_size()}), "
        f"numpy {np.__version__}; one thread unless said; {'QUICK run' if args.quick else 'full run'}"
    )
    t0 = time.perf_counter()
    print("heyoka.py event semantics, checked here:")
    for line in heyoka_semantics():
        print("  - " + line)
    if "1" in parts:
        print(
            f"\n=== Part 1: one return, work-precision over tol {tolerance_grid(args.quick)[0]:.0e} .. "
            f"{tolerance_grid(args.quick)[-1]:.0e} ({len(tolerance_grid(args.quick))} settings), best of {args.repeat}; "
            f"heyoka stream forms: ~{args.m_returns} returns per start"
        )
        for k in keys:
            work_precision(k, *all_sys[k], args)
    if "2" in parts:
        flowmap_part(args)
    if "3" in parts:
        grazing_part(args)
    print(f"\ntotal {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
