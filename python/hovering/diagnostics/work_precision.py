"""Work-precision: what each accuracy setting costs in time, measured on the system at hand.

:func:`work_precision` runs one target (the flow's :class:`~hovering.Section` or
:class:`~hovering.FlowMap`, a truncated map, or a map's hovering area) at a ladder of settings
and measures, for each, the error against a reference and the time it took:

* **the flow**: one curve per GSL stepper over its tolerances. The error of a setting is the
  largest section-coordinate error ``max(|wrap(d theta)|, |d I|)`` of one return over a set of
  starting points, against the exact flow (``stepper="exact"``) where the system has one, else
  against a reference run (rk8pd at rtol 1e-14) whose own error is estimated by its distance to a
  run at 10x its tolerance. Long orbits: the error after each of ``returns`` (e.g. 1, 1e2, 1e4)
  returns and the reversal error (m returns forward, m back by time reversal, distance to the
  start), which needs no reference. Errors of an integrator of order p grow as m^2 with the number
  of returns m on these oscillations (the frequency error a drifting action makes accumulates in
  the phase), so a portrait of 1e4 returns needs a one-return error 1e8 times below its target.
* **the truncated map** (``quantity="rotation"``): the rotation number after n iterations (mean,
  and weighted Birkhoff) against a long weighted-Birkhoff reference, for both SIMD sin accuracies.
* **the hovering area** (``quantity="hovering_area"``): area vs samples x iterations against the
  largest setting, with the stated error bars.

Times are wall-clock seconds on one thread (per return, per iteration, or per call), the best of
``repeat`` runs; they are measurements of this machine, never asserted anywhere.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .._checks import integer, is_choice, random_seed, real_number
from .._deprecated import renamed_keywords
from ..analysis.hovering import hovering_area
from ..analysis.rotation import rotation_number
from ..flow.section import STEPPERS, Section
from ..normal.flowmap import FlowMap
from .references import heyoka_return_map, scipy_return_map

__all__ = ["WorkPrecision", "work_precision", "exact_available", "stepper_applies", "FLOW_STEPPERS_DEFAULT"]

#: Steppers of the default flow diagram (rk4 and rk2 reach 1e-10 only at ~100x rk8pd's cost);
#: those that do not apply to a system (taylor: Harmonic and Tan potentials only) are left out.
FLOW_STEPPERS_DEFAULT = ("taylor", "rk8pd", "rkck", "rkf45", "msadams")
_FLOW_TOLERANCES = (1e-6, 1e-8, 1e-10, 1e-12, 1e-14)
_FLOW_TOLERANCES_QUICK = (1e-6, 1e-9, 1e-12)
#: Documented error bound of the closed-form flow (rounding of O(1) angles over a few events).
_EXACT_ERROR = 1e-13


@dataclass
class WorkPrecision:
    """A measured work-precision diagram.

    Attributes
    ----------
    kind : str
        ``"flow"``, ``"rotation"`` or ``"hovering_area"``.
    rows : list of dict
        One row per (method, tolerance): ``method``, ``tolerance``, ``error``, ``seconds`` (per
        ``unit``), ``unit``, and per kind: flow rows also ``failed`` (points whose return did
        not end OK), ``steps`` (integrator steps per return), ``error_after`` and
        ``reversal_after`` (dicts: number of returns -> error).
    reference : dict
        ``method`` (what the errors are measured against), ``error`` (its own error: 0 for an
        exact reference, else an estimate), ``note``.
    target : str
        What was measured.
    n_points : int
        Starting points (orbits) per measurement.
    """

    kind: str
    rows: list
    reference: dict
    target: str
    n_points: int
    notes: list = field(default_factory=list)

    @property
    def table(self) -> list:
        """The rows (list of dicts with ``method``, ``tolerance``, ``error``, ``seconds``, ...)."""
        return self.rows

    def methods(self) -> list:
        """Method names in the order measured."""
        out = []
        for r in self.rows:
            if r["method"] not in out:
                out.append(r["method"])
        return out

    def curve(self, method: str):
        """(tolerances, errors, seconds) of one method, as arrays in the order measured."""
        rs = [r for r in self.rows if r["method"] == method]
        if not rs:
            raise ValueError(f"no method {method!r}; measured: {self.methods()}")
        return (
            np.array([r["tolerance"] for r in rs], dtype=object),
            np.array([r["error"] for r in rs], float),
            np.array([r["seconds"] for r in rs], float),
        )

    def fastest(self, error: float, returns: int | None = None) -> dict | None:
        """The fastest row whose error is at most ``error`` (after ``returns`` returns: flow only), or None.

        Parameters
        ----------
        error : float
            Target error (> 0).
        returns : int, optional
            Judge by the error after this many returns (a key of ``error_after``) instead of one.
        """
        error = real_number("error", error, 0, True)
        ok = []
        for r in self.rows:
            e = r["error"] if returns is None else r.get("error_after", {}).get(int(returns), math.nan)
            if e <= error:
                ok.append(r)
        return min(ok, key=lambda r: r["seconds"]) if ok else None

    def format(self) -> str:
        """The table as Markdown (errors and times with 3 significant digits)."""
        extra = sorted({m for r in self.rows for m in r.get("error_after", {})})
        rev = sorted({m for r in self.rows for m in r.get("reversal_after", {})})
        head = ["method", "tolerance", "error", f"seconds per {self.rows[0]['unit']}" if self.rows else "seconds"]
        head += [f"error after {m}" for m in extra] + [f"reversal after {m}" for m in rev]
        lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        for r in self.rows:
            tol = r["tolerance"]
            cells = [
                r["method"],
                tol if isinstance(tol, str) else f"{tol:.3g}",
                f"{r['error']:.3g}",
                f"{r['seconds']:.3g}",
            ]
            cells += [f"{r.get('error_after', {}).get(m, math.nan):.3g}" for m in extra]
            cells += [f"{r.get('reversal_after', {}).get(m, math.nan):.3g}" for m in rev]
            lines.append("| " + " | ".join(cells) + " |")
        ref = self.reference
        lines.append("")
        lines.append(
            f"reference: {ref['method']} (own error {ref['error']:.2g}){'; ' + ref['note'] if ref.get('note') else ''}"
        )
        lines += self.notes
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """Plain data (JSON-ready): kind, rows, reference, target, n_points, notes."""

        def plain(v):
            if isinstance(v, dict):
                return {str(k): plain(x) for k, x in v.items()}
            if isinstance(v, (list, tuple)):
                return [plain(x) for x in v]
            if isinstance(v, (np.floating, np.integer)):
                return v.item()
            return v

        return plain(
            {
                "kind": self.kind,
                "rows": self.rows,
                "reference": self.reference,
                "target": self.target,
                "n_points": self.n_points,
                "notes": self.notes,
            }
        )

    def plot(self, fig=None):
        """Draw the diagram: error vs time per unit, one curve per method (tolerances labelled);
        for the flow a second panel with the long-orbit errors (error and reversal error vs the
        number of returns, at each method's tightest tolerance).

        Parameters
        ----------
        fig : matplotlib Figure, optional
            Drawn into (cleared); a new figure if None.

        Returns
        -------
        matplotlib.figure.Figure
        """
        import matplotlib.pyplot as plt

        long = any(r.get("error_after") for r in self.rows)
        if fig is None:
            fig = plt.figure(figsize=(11 if long else 6.5, 4.8))
        fig.clf()
        axes = fig.subplots(1, 2 if long else 1, squeeze=False)[0]
        ax = axes[0]
        for k, m in enumerate(self.methods()):
            tol, err, sec = self.curve(m)
            floor = np.maximum(err, 1e-17)  # an exact 0 still shows, on the axis floor
            ax.loglog(sec, floor, "o-", color=f"C{k}", label=m, gid=f"method:{m}")
            for t, e, s in zip(tol, floor, sec):
                ax.annotate(
                    t if isinstance(t, str) else f"{t:.0e}",
                    (s, e),
                    fontsize=6,
                    xytext=(3, 2),
                    textcoords="offset points",
                    color=f"C{k}",
                )
        ref = self.reference
        if ref["error"] > 0:
            ax.axhline(
                ref["error"],
                color="0.5",
                ls=":",
                lw=1,
                gid="reference_error",
                label=f"reference's own error ({ref['method']})",
            )
        unit = self.rows[0]["unit"] if self.rows else "call"
        ax.set_xlabel(f"seconds per {unit} (one thread)")
        # Times span one or two decades: labelled minor ticks (2e-5, 3e-5, ...) would overlap.
        from matplotlib.ticker import LogFormatterSciNotation

        ax.xaxis.set_minor_formatter(LogFormatterSciNotation(labelOnlyBase=False, minor_thresholds=(1, 0.4)))
        ax.set_ylabel(
            {
                "flow": "max error of one return (section coordinates)",
                "rotation": "rotation-number error",
                "hovering_area": "|area - reference|",
            }[self.kind]
        )
        fig.suptitle(f"{self.target}; reference: {ref['method']}", fontsize=8)
        ax.legend(fontsize=7)
        ax.grid(True, which="both", alpha=0.2)
        if long:
            ax2 = axes[1]
            for k, m in enumerate(self.methods()):
                rs = [r for r in self.rows if r["method"] == m and r.get("error_after")]
                if not rs:
                    continue
                r = min(rs, key=lambda r: r["tolerance"])
                ms = sorted(r["error_after"])
                ax2.loglog(
                    ms,
                    np.maximum([r["error_after"][x] for x in ms], 1e-17),
                    "o-",
                    color=f"C{k}",
                    label=f"{m} {r['tolerance']:.0e}",
                    gid=f"long:{m}",
                )
                rv = sorted(r.get("reversal_after", {}))
                if rv:
                    ax2.loglog(
                        rv,
                        np.maximum([r["reversal_after"][x] for x in rv], 1e-17),
                        "s--",
                        color=f"C{k}",
                        alpha=0.6,
                        gid=f"reversal:{m}",
                    )
            ax2.set_xlabel("returns m")
            ax2.set_ylabel("error after m returns (solid), reversal error (dashed)")
            ax2.set_title("long orbits (each method at its tightest tolerance)", fontsize=8)
            ax2.legend(fontsize=7)
            ax2.grid(True, which="both", alpha=0.2)
        fig.tight_layout()
        return fig


# ------------------------------------------------------------------------------------------------
# helpers


def _best_time(fn, repeat: int):
    best, out = math.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def _wrap(a):
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


def _section_distance(th_a, I_a, th_b, I_b) -> np.ndarray:
    return np.maximum(np.abs(_wrap(np.asarray(th_a) - th_b)), np.abs(np.asarray(I_a) - I_b))


def stepper_applies(section, stepper: str) -> bool:
    """Whether a stepper applies to this section's system (the core's own check, no integration).

    Parameters
    ----------
    section : Section
        The system (its energy is not read).
    stepper : str
        One of :data:`hovering.flow.STEPPERS`.

    Returns
    -------
    bool
        False for ``"exact"`` without a closed-form flow and for ``"taylor"`` on a potential
        without Taylor recurrences (a :class:`~hovering.CustomPotential`).
    """
    from .._core import flow as _core_flow

    try:
        _core_flow.FlowOptions(stepper=stepper).validate_for(section.sys.core)
    except ValueError:
        return False
    return True


def exact_available(section) -> bool:
    """Whether the flow of this section's system has the closed-form ``stepper="exact"``."""
    try:
        section.return_map(
            [0.0], [_default_actions(section, 1, np.random.default_rng(0))[0]], stepper="exact", n_threads=1
        )
    except ValueError:  # not a stepper of this build, or no closed form for this system
        return False
    return True


def _default_actions(section, n: int, rng) -> np.ndarray:
    """Actions of starting points: around the tangent circle (0.3 .. 1.3 I_tan) when the step's
    energy lies below h, else spread over the actions Sigma_h has (5% .. 95% of I(h))."""
    sys, h = section.sys, section.h
    V2 = sys.V2
    I_max = V2.action(h)  # H2 < h on Sigma_h (V1 >= 0)
    try:
        I_tan = V2.action(h - sys.V1.V(sys.qw1)) if sys.geometry != "none" else None
    except ValueError:
        I_tan = None
    if I_tan is not None and 0 < I_tan < I_max:
        return np.minimum(I_tan * rng.uniform(0.3, 1.3, n), 0.98 * I_max)
    return I_max * rng.uniform(0.05, 0.95, n)


def _reference_run(section, theta, I, n_threads, classify=None):
    """One return by the reference: exact where available, else the most accurate integrator that
    applies (taylor at rtol 1e-16, order 20; else rk8pd at 1e-14), its own error estimated by its
    distance to the next tolerance up (1e-15 / 1e-13). ``classify``: the grazing and corner bands of
    the runs measured, so that the reference calls the same starts regular."""
    classify = classify or {}
    if exact_available(section):
        r = section.return_map(theta, I, stepper="exact", n_threads=n_threads, **classify)
        return r, {"method": "exact (closed-form flow)", "error": 0.0, "stepper": "exact", "rtol": None}
    stepper, rtol, rtol2 = ("taylor", 1e-16, 1e-15) if stepper_applies(section, "taylor") else ("rk8pd", 1e-14, 1e-13)
    r = section.return_map(theta, I, stepper=stepper, rtol=rtol, atol=rtol, n_threads=n_threads, **classify)
    r2 = section.return_map(theta, I, stepper=stepper, rtol=rtol2, atol=rtol2, n_threads=n_threads, **classify)
    ok = (r.status == 0) & (r2.status == 0)
    est = float(np.max(_section_distance(r.theta[ok], r.I[ok], r2.theta[ok], r2.I[ok]), initial=0.0))
    return r, {
        "method": f"{stepper} rtol {rtol:g}",
        "error": est,
        "stepper": stepper,
        "rtol": rtol,
        "note": f"own error estimated as its distance to {stepper} at rtol {rtol2:g}",
    }


def _iterate_final(fm, theta, I, m: int, n_threads: int):
    res = fm.iterate(theta, I, m, record=(), n_threads=n_threads)
    return res.phi_final, res.K_final, res.status


def _reverse(fm, theta, I, m: int, n_threads: int):
    th, ii = np.array(theta, float), np.array(I, float)
    alive = np.ones(th.shape, bool)
    for _ in range(m):
        r = fm.returns(th, ii, inverse=True, n_threads=n_threads)
        alive &= r.status == 0
        th, ii = np.where(alive, r.phi, th), np.where(alive, r.K, ii)
    return th, ii, alive


# ------------------------------------------------------------------------------------------------
# the flow


def _flow(
    section,
    tolerances,
    steppers,
    n_points,
    returns,
    repeat,
    seed,
    n_threads,
    progress,
    reversal=True,
    external=(),
    options=None,
):
    # options: the event options of the map being chosen for (FlowMap's **options); every run
    # measured uses them, so the cost and error measured are that map's.
    options = dict(options or {})
    classify = {k: options[k] for k in ("grazing_tol", "corner_tol") if k in options}
    rng = np.random.default_rng(seed)
    theta = rng.uniform(-np.pi, np.pi, n_points)
    I = _default_actions(section, n_points, rng)
    ref, refinfo = _reference_run(section, theta, I, n_threads, classify)
    keep = ref.status == 0  # points whose reference return is regular (no corner, graze, ...)
    theta, I = theta[keep], I[keep]
    ref_th, ref_I = ref.theta[keep], ref.I[keep]
    if theta.size == 0:
        raise ValueError("no starting point returns regularly under the reference; nothing to measure")
    long_ms = sorted(int(m) for m in returns if int(m) > 1)
    n_long = min(theta.size, 4)
    ref_long = {}
    if long_ms:
        ref_fm = FlowMap(
            section.sys,
            section.h,
            coordinates="section",
            **classify,
            **(
                {"stepper": "exact"}
                if refinfo["stepper"] == "exact"
                else {"stepper": refinfo["stepper"], "rtol": refinfo["rtol"], "atol": refinfo["rtol"]}
            ),
        )
        for m in long_ms:
            ref_long[m] = _iterate_final(ref_fm, theta[:n_long], I[:n_long], m, n_threads)
    rows = []
    total = len(steppers) * len(tolerances)
    done = 0
    for st in steppers:
        for tol in tolerances:
            sec, r = _best_time(
                lambda: section.return_map(theta, I, rtol=tol, atol=tol, stepper=st, n_threads=n_threads, **options),
                repeat,
            )
            ok = r.status == 0
            # an error below the reference's own cannot be resolved: it is reported as that error
            err = (
                max(
                    float(np.max(_section_distance(r.theta[ok], r.I[ok], ref_th[ok], ref_I[ok]), initial=0.0)),
                    refinfo["error"],
                )
                if ok.any()
                else math.nan
            )  # no return: no error to speak of
            row = {
                "method": st,
                "tolerance": float(tol),
                "error": err,
                "seconds": sec / theta.size,
                "unit": "return",
                "failed": int(np.count_nonzero(~ok)),
                "steps": float(np.mean(r.steps)),
            }
            if long_ms:
                fm = FlowMap(section.sys, section.h, coordinates="section", rtol=tol, atol=tol, stepper=st, **options)
                row["error_after"] = {1: err}
                if reversal:
                    bt, bi, alive = _reverse(fm, r.theta, r.I, 1, n_threads)
                    good = ok & alive
                    row["reversal_after"] = {
                        1: float(np.max(_section_distance(bt[good], bi[good], theta[good], I[good]), initial=0.0))
                    }
                for m in long_ms:
                    pf, kf, s = _iterate_final(fm, theta[:n_long], I[:n_long], m, n_threads)
                    rp, rk, rs = ref_long[m]
                    good = (s == 0) & (rs == 0)
                    row["error_after"][m] = float(
                        np.max(
                            _section_distance(pf[good], kf[good], rp[good], rk[good]),
                            initial=math.nan if not good.any() else 0.0,
                        )
                    )
                    if not reversal:
                        continue
                    bt, bi, alive = _reverse(fm, pf, kf, m, n_threads)
                    good &= alive
                    row["reversal_after"][m] = float(
                        np.max(
                            _section_distance(bt[good], bi[good], theta[:n_long][good], I[:n_long][good]),
                            initial=math.nan if not good.any() else 0.0,
                        )
                    )
            rows.append(row)
            done += 1
            if callable(progress):
                progress(done, total)
    notes = []
    for name in external:
        extra, note = _external_rows(name, section, theta, I, ref_th, ref_I, tolerances)
        rows += extra
        notes.append(note)
    s = section.sys
    target = (
        f"flow {s.V1!r} + {s.V2!r}, eps={s.eps:g}, geometry={s.geometry}, qw=({s.qw1:g}, {s.qw2:g}), h={section.h:g}"
    )
    if long_ms:
        notes.append(
            f"long orbits: {n_long} points; the error after m returns is against the reference's own "
            "m returns (at eps != 0 chaotic orbits separate exponentially, whatever the method)"
        )
    return WorkPrecision("flow", rows, refinfo, target, int(theta.size), notes)


# ------------------------------------------------------------------------------------------------
# independent implementations as extra curves (hovering.references)


def _external_rows(name, section, theta, I, ref_th, ref_I, tolerances, n_max: int = 16):
    """Rows of an independent implementation (``"scipy"`` or ``"heyoka"``) on the first n_max points,
    and a note (what it is, or why it is missing)."""
    import importlib.util

    if importlib.util.find_spec(name) is None:
        return [], f"{name} not installed: no {name} curve (pip install {name})"
    z0 = section.point(theta[:n_max], I[:n_max])

    def run_scipy(tol):
        t0 = time.perf_counter()
        out = [scipy_return_map(section.sys, z, max(tol, 1e-13)) for z in z0]
        return out, time.perf_counter() - t0

    def run_heyoka(tol):
        return heyoka_return_map(section.sys, z0, max(tol, 1e-15))

    run, method, note = {
        "scipy": (run_scipy, "scipy DOP853", "scipy DOP853 (solve_ivp with events, Python field)"),
        "heyoka": (
            run_heyoka,
            "heyoka.py Taylor",
            "heyoka.py Taylor + events (its Python-side cost per propagate_until call included, JIT compilation not)",
        ),
    }[name]
    rows = []
    for tol in tolerances:
        try:
            out, sec = run(tol)
        except ValueError as e:  # a system the implementation cannot express
            return [], f"no {name} curve: {e}"
        ok = np.array([o is not None for o in out])
        c = section.coordinates(np.array([o if o is not None else np.full(4, np.nan) for o in out]))
        err = (
            float(np.nanmax(_section_distance(c[ok, 0], c[ok, 1], ref_th[:n_max][ok], ref_I[:n_max][ok]), initial=0.0))
            if ok.any()
            else math.nan
        )
        rows.append(
            {
                "method": method,
                "tolerance": float(tol),
                "error": err,
                "seconds": sec / len(z0),
                "unit": "return",
                "failed": int(np.count_nonzero(~ok)),
            }
        )
    return rows, f"{note}: {len(z0)} points"


# ------------------------------------------------------------------------------------------------
# the truncated map


def _rotation(m, tolerances, steppers, n_points, repeat, seed, n_threads, progress):

    rng = np.random.default_rng(seed)
    K0 = rng.uniform(-0.05, 0.05, n_points) if not hasattr(m, "L1") else None
    if K0 is None:
        K0 = np.linspace(0.05, 0.3, n_points)  # above the tangency: no impacts, regular orbits
    phi0 = np.zeros(n_points) if not hasattr(m, "L1") else m.L1(K0)
    n_ref = 4 * max(tolerances)
    rec = ("orbit", "rotation")
    res = m.iterate(phi0, K0, n_ref, record=rec, n_threads=n_threads)
    ref = rotation_number(res, "birkhoff")
    half = m.iterate(phi0, K0, n_ref // 2, record=rec, n_threads=n_threads)
    ref_err = float(np.nanmax(np.abs(rotation_number(half, "birkhoff") - ref)))
    rows = []
    for u in steppers:
        for n in tolerances:
            sec, r = _best_time(lambda: m.iterate(phi0, K0, int(n), record=rec, n_threads=n_threads, sin_ulp=u), repeat)
            for est in ("mean", "birkhoff"):
                err = float(np.nanmax(np.abs(rotation_number(r, est) - ref)))
                rows.append(
                    {
                        "method": f"{est}, sin_ulp={u:g}",
                        "tolerance": int(n),
                        "error": err,
                        "seconds": sec / (n * n_points),
                        "unit": "iteration",
                    }
                )
    return WorkPrecision(
        "rotation",
        rows,
        {
            "method": f"weighted Birkhoff after {n_ref} iterations",
            "error": ref_err,
            "note": f"own error: its change from {n_ref // 2} iterations",
        },
        repr(m),
        n_points,
    )


def _hovering(m, tolerances, n_points, repeat, seed, n_threads, progress):

    settings = sorted(tolerances, key=lambda t: t[0] * t[1])
    runs = []
    for samples, n in settings:
        sec, a = _best_time(
            lambda: hovering_area(m, n_steps=int(n), n_samples=int(samples), rng=seed, n_threads=n_threads), repeat
        )
        runs.append((samples, n, sec, a))
    ref = runs[-1][3]
    rows = [
        {
            "method": "hovering_area",
            "tolerance": f"{s}x{n}",
            "error": abs(a.area - ref.area),
            "seconds": sec,
            "unit": "call",
            "stated_error": a.error,
            "area": a.area,
        }
        for s, n, sec, a in runs[:-1]
    ]
    return WorkPrecision(
        "hovering_area",
        rows,
        {
            "method": f"hovering_area {runs[-1][0]}x{runs[-1][1]}",
            "error": float(ref.error),
            "note": "its own stated error bar",
        },
        repr(m),
        int(runs[-1][0]),
    )


# ------------------------------------------------------------------------------------------------


@renamed_keywords(seed="rng")
def work_precision(
    target,
    tolerances: Sequence | None = None,
    steppers: Sequence | None = None,
    *,
    quantity: str = "auto",
    n_points: int | None = None,
    returns: Sequence[int] = (1, 100, 10_000),
    quick: bool = False,
    repeat: int = 2,
    rng: int | np.random.Generator | None = 0,
    n_threads: int = 1,
    external: Sequence[str] = (),
    progress=False,
) -> WorkPrecision:
    """Measure what accuracy costs in time for a target (see the module docstring).

    Parameters
    ----------
    target : Section, FlowMap, TruncatedMap or TruncatedFamily
        What to measure. A FlowMap is measured through its section (the flow's own error does not
        depend on the map's coordinates).
    tolerances : sequence, optional
        Flow: rtol = atol values (default 1e-6, 1e-8, 1e-10, 1e-12). Rotation: iteration counts
        (default 1e2, 1e3, 1e4, 1e5). Hovering area: (n_samples, n_steps) pairs, the largest being
        the reference (default (400, 250), (1600, 500), (6400, 1000), (25600, 2000)).
    steppers : sequence, optional
        Flow: steppers (default ``FLOW_STEPPERS_DEFAULT``, those that apply to the system). Rotation: SIMD sin accuracies in ulp
        (default 1.0 and 3.5).
    quantity : {"auto", "return", "rotation", "hovering_area"}, optional
        ``auto``: one return for the flow, the rotation number for a truncated map.
    n_points : int, optional
        Starting points (default 64 for the flow, 8 orbits for the rotation; 16 / 4 when quick).
    returns : sequence of int, optional
        Flow: numbers of returns of the long-orbit errors (1 always; with ``quick`` those above
        100 are dropped).
    quick : bool, optional
        A smaller, faster diagram (fewer tolerances, points and returns).
    repeat : int, optional
        Timed runs per setting (the best is kept: this machine's single runs vary by up to 1.5x).
    rng : int, numpy.random.Generator or None, optional
        The starting points' randomness (SPEC 7): an integer seed in [0, 2**63 - 1] (default 0), a
        Generator (one seed is drawn from it) or None (fresh OS entropy). Formerly ``seed=``
        (deprecated, still accepted with a DeprecationWarning; giving both is a TypeError).
    n_threads : int, optional
        Threads of the timed runs (default 1, so times are per core).
    external : sequence of str, optional
        Flow only: independent implementations to add as curves when installed: ``"scipy"``
        (solve_ivp DOP853 with events, :func:`hovering.references.scipy_return_map`), ``"heyoka"``
        (heyoka.py's Taylor integrator with events, :func:`hovering.references.heyoka_return_map`; Harmonic/Tan only); one-return errors on
        16 points. A missing package or an unsupported system adds a note instead of a curve.
    progress : callable, optional
        ``progress(done, total)`` after each flow setting.

    Returns
    -------
    WorkPrecision
        ``.table`` rows (``method``, ``tolerance``, ``error``, ``seconds``; one-return errors below
        the reference's own error are reported as that error), ``.plot()``,
        ``.fastest(error)``, ``.format()``.

    Raises
    ------
    TypeError
        For an ``rng`` that is not None, an int or a Generator, or both ``rng`` and ``seed``.
    ValueError
        For an unknown target or quantity, or bad settings (named, with the allowed range).
    """

    if not is_choice(quantity, ("auto", "return", "rotation", "hovering_area")):
        raise ValueError(f"quantity must be 'auto', 'return', 'rotation' or 'hovering_area', got {quantity!r}")
    quick = bool(quick)
    repeat = integer("repeat", repeat, 1, 100)
    seed = random_seed(rng)
    n_threads = integer("n_threads", n_threads, 0, 1024)
    if progress is not False and progress is not None and not callable(progress):
        raise ValueError(f"progress must be a callable progress(done, total) or False, got {progress!r}")
    is_flow = isinstance(target, (Section, FlowMap))
    if quantity == "hovering_area":
        if tolerances is None:
            tolerances = (
                [(400, 250), (1600, 500), (6400, 1000)]
                if quick
                else [(400, 250), (1600, 500), (6400, 1000), (25600, 2000)]
            )
        tolerances = [(integer("n_samples", s, 16, 10**9), integer("n_steps", n, 1, 10**9)) for s, n in tolerances]
        if len(tolerances) < 2:
            raise ValueError(
                "hovering_area needs at least two (n_samples, n_steps) settings (the largest is the reference)"
            )
        return _hovering(target, tolerances, None, repeat, seed, n_threads, progress)
    if is_flow:
        if quantity not in ("auto", "return"):
            raise ValueError(f"quantity {quantity!r} is for maps; the flow's is 'return'")
        section = target.section if isinstance(target, FlowMap) else target
        tols = tuple(_FLOW_TOLERANCES_QUICK if quick else _FLOW_TOLERANCES) if tolerances is None else tuple(tolerances)
        tols = tuple(real_number("tolerance", t, 1e-16, False, 1, True) for t in tols)
        if steppers is None:
            sts = tuple(
                st for st in (("taylor", "rk8pd") if quick else FLOW_STEPPERS_DEFAULT) if stepper_applies(section, st)
            )
        else:
            sts = tuple(steppers)
        for st in sts:
            if not is_choice(st, STEPPERS):
                raise ValueError(f"stepper must be one of {STEPPERS}, got {st!r}")
        n = integer("n_points", n_points if n_points is not None else (16 if quick else 64), 1, 10**7)
        rets = sorted({integer("returns", m, 1, 10**7) for m in returns} | {1})
        if quick:
            rets = [m for m in rets if m <= 100]
        ext = tuple(external)
        for e in ext:
            if e not in ("scipy", "heyoka"):
                raise ValueError(f"external must name 'scipy' or 'heyoka', got {e!r}")
        return _flow(section, tols, sts, n, rets, repeat, seed, n_threads, progress, external=ext)
    if not hasattr(target, "iterate") or not hasattr(target, "step"):
        raise ValueError(f"target must be a Section, FlowMap, TruncatedMap or TruncatedFamily, got {target!r}")
    if quantity not in ("auto", "rotation"):
        raise ValueError(f"quantity {quantity!r} is for the flow; a map's is 'rotation' or 'hovering_area'")
    tols = ((100, 1000, 10_000) if quick else (100, 1000, 10_000, 100_000)) if tolerances is None else tolerances
    tols = tuple(integer("n_steps", t, 10, 10**8) for t in tols)
    uls = (1.0, 3.5) if steppers is None else tuple(steppers)
    for u in uls:
        if u not in (1.0, 3.5):
            raise ValueError(f"a truncated map's methods are sin_ulp values 1.0 or 3.5, got {u!r}")
    n = integer("n_points", n_points if n_points is not None else (4 if quick else 8), 1, 10**6)
    return _rotation(target, tols, uls, n, repeat, seed, n_threads, progress)
