"""Independent SciPy reference integrator for ONE return of the two-oscillator impact flow.

Test oracle written from the problem statement only; it imports nothing from ``hovering``.

    H = p1^2/2 + V1(q1) + p2^2/2 + V2(q2) + eps*Vc(q1, q2),   y = (q1, p1, q2, p2),

V = omega^2 q^2/2 (harmonic) or omega^2/(2 alpha^2) tan^2(alpha q) (tan), Vc = q1 q2 or
sum c q1^i q2^j.  Geometry "step" (solid {q1 < qw1, q2 < qw2}: right wall q1 = qw1, q2 < qw2
flips p1; upper wall q2 = qw2, q1 < qw1 flips p2), "wall" (q1 = qw1 for all q2) or "none".
One return runs from z0 (a maximum of q1) until p1 goes + -> - after it has been armed by a
q1 minimum (p1: - -> +) or a right-wall reflection.

Method
------
The flow is integrated piecewise with ``solve_ivp(method="DOP853", dense_output=True)`` over
chunks of about one local period; solve_ivp's own event machinery is not used.  On every
accepted step [t_a, t_b] of a chunk the dense output is sampled at ``N_SAMPLE = 32`` equal
sub-intervals and four functions are monitored, each with its exact time derivative:

    g0 = q1 - qw1 (g0' = p1),  g1 = q2 - qw2 (g1' = p2),  g2 = p1 (g2' = F1),  g3 = p2 (g3' = F2),

with F = -grad(V1 + V2 + eps Vc).  On each sample interval where g' changes sign the extremum of
g is located first (brentq on g'), which splits the interval into pieces on which g is
monotone; every sign change of g on a piece is bracketed, refined by brentq (xtol = rtol =
1e-15) on the dense output and polished by two Newton steps with g'.  So a dip of q1 (q2) below
a wall and back inside one sample interval is found through the sign change of p1 (p2), and a
double root of p1, p2 through that of F1, F2.  All roots of a chunk are handled in time order;
an impact (or a terminal event) discards the rest of the chunk and integration restarts from the
impact point, put exactly on the wall with the momentum reflected.  An exact zero of g at a
sample (e.g. on the wall right after an impact) takes the sign of g', i.e. of the motion.

Step cap rule
-------------
Let Lam(q) = max |eigenvalue| of the Hessian of V1 + V2 + eps Vc and P(q) = 2 pi / sqrt(Lam)
the shortest local oscillation period.  A chunk is kept only if every step satisfies
t_b - t_a <= P_min / step_fraction (default 128), P_min the minimum of P over the step's 33
samples; otherwise it is recomputed with ``max_step`` halved below the offending bound (the
first try uses P(start) / step_fraction, at most 0.5).  Sample spacing <= P_min / 4096.  The cap
is much tighter than the tolerance alone would pick: the DOP853 dense output at rtol = 1e-13 and
its natural step (~P/40) errs by ~3e-13, at P/128 by ~1e-15, which puts event times and states
at the rounding floor (~1e-14), not at the tolerance.

Why no event is missed
----------------------
g0, g1 are positions and g2, g3 momenta of oscillators of local angular frequency at most
sqrt(Lam): consecutive zeros of g (and of g') are about pi / sqrt(Lam) = P/2 apart (exact for a
linear oscillator, by Sturm comparison for a scalar one), i.e. >= 2000 sample spacings.  Hence
g' has at most one zero per sample interval, which shows as a sign change of g' at the samples,
and g is monotone on each side of it, so every zero of g is bracketed.  What can escape is a dip
shallower than the dense output's error (~1e-15), far inside the grazing band, and a double zero
of g' itself (a tangency of g' = 0, a codimension-2 event).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

__all__ = ["harmonic", "tan", "reference_return", "energy"]

N_SAMPLE = 32  # samples per accepted step
MAX_IMPACTS = 10000


CHUNK_EVALUATIONS = 200_000  # right-hand-side evaluations one chunk may spend (reference_return)


class _OutOfBudget(Exception):
    """Raised by the right-hand side once ``max_evaluations`` (or a chunk's share) is spent."""


def harmonic(omega):
    """Harmonic potential V(q) = omega^2 q^2 / 2.

    Parameters
    ----------
    omega : float
        Angular frequency.

    Returns
    -------
    dict
        ``{"kind": "harmonic", "omega": omega}``.
    """
    return {"kind": "harmonic", "omega": float(omega)}


def tan(omega, alpha):
    """Tan potential V(q) = omega^2 / (2 alpha^2) tan(alpha q)^2, defined for |alpha q| < pi/2.

    Parameters
    ----------
    omega, alpha : float
        Small-amplitude frequency and the well's width parameter.

    Returns
    -------
    dict
        ``{"kind": "tan", "omega": omega, "alpha": alpha}``.
    """
    return {"kind": "tan", "omega": float(omega), "alpha": float(alpha)}


def _pot(P, q, order):
    """V (order 0), V' (1) or V'' (2) of potential dict ``P`` at ``q`` (array)."""
    w = P["omega"]
    if P["kind"] == "harmonic":
        return (0.5 * w * w * q * q, w * w * q, w * w + 0.0 * q)[order]
    a = P["alpha"]
    T = np.tan(a * q)
    if order == 0:
        return w * w / (2 * a * a) * T * T
    if order == 1:
        return w * w / a * T * (1 + T * T)
    return w * w * (1 + T * T) * (1 + 3 * T * T)


def _inside(P, q):
    """True where q lies inside the potential's domain."""
    return np.ones_like(q, bool) if P["kind"] == "harmonic" else np.abs(P["alpha"] * q) < math.pi / 2


def _terms(coupling):
    if isinstance(coupling, str):
        if coupling != "bilinear":
            raise ValueError(f"unknown coupling {coupling!r}")
        return [(1, 1, 1.0)]
    return [(int(i), int(j), float(c)) for (i, j), c in coupling.items() if c != 0]


def _mono(x, k, d):
    """d-th derivative of x^k (k, d >= 0 integers), elementwise."""
    if d > k:
        return 0.0 * x
    return math.perm(k, d) * x ** (k - d)


def _vc(terms, q1, q2, d1, d2):
    """d1-th q1- and d2-th q2-derivative of the coupling sum c q1^i q2^j."""
    out = 0.0 * q1
    for i, j, c in terms:
        out = out + c * _mono(q1, i, d1) * _mono(q2, j, d2)
    return out


def energy(V1, V2, coupling, eps, y):
    """Hamiltonian H at state(s) ``y`` = (q1, p1, q2, p2) (last axis or first axis of length 4).

    Parameters
    ----------
    V1, V2 : dict
        Potentials from :func:`harmonic` or :func:`tan`.
    coupling : str or dict
        ``"bilinear"`` or ``{(i, j): c}``.
    eps : float
        Coupling strength.
    y : array_like
        State, shape (4,) or (4, m).

    Returns
    -------
    float or ndarray
    """
    q1, p1, q2, p2 = np.asarray(y, float)
    return 0.5 * p1 * p1 + _pot(V1, q1, 0) + 0.5 * p2 * p2 + _pot(V2, q2, 0) + eps * _vc(_terms(coupling), q1, q2, 0, 0)


def reference_return(
    V1,
    V2,
    coupling,
    eps,
    geometry,
    qw1,
    qw2,
    z0,
    rtol=1e-13,
    atol=1e-13,
    t_max=1000.0,
    corner_tol=1e-9,
    grazing_tol=1e-12,
    step_fraction=128,
    max_evaluations=10_000_000,
):
    """One return to Sigma_h = {p1 = 0, dp1/dt < 0} from ``z0``, by DOP853 with robust event search.

    Parameters
    ----------
    V1, V2 : dict
        Potentials from :func:`harmonic` or :func:`tan`.
    coupling : str or dict
        ``"bilinear"`` (Vc = q1 q2) or ``{(i, j): c}`` (Vc = sum c q1^i q2^j).
    eps : float
        Coupling strength.
    geometry : {"step", "wall", "none"}
        Wall geometry (see the module docstring).
    qw1, qw2 : float
        Wall positions (the step's corner is (qw1, qw2); "wall" uses qw1 only).
    z0 : array_like, shape (4,)
        Start (q1, p1, q2, p2), p1 ~ 0 at a maximum of q1.
    rtol, atol : float
        Tolerances of DOP853.
    t_max : float
        Time limit; beyond it the status is "limit" (also after more than 10000 impacts).
    corner_tol, grazing_tol : float
        Corner band for impacts and grazing band for wall-distance minima.
    step_fraction : int
        Every DOP853 step is at most 1/step_fraction of the shortest local period (module
        docstring).  128 puts the error at the rounding floor (~1e-14); 64 is ~2x faster, ~1e-13.
    max_evaluations : int
        Budget of right-hand-side evaluations; once spent the status is "limit".  An orbit that
        runs toward a Tan well's edge or off along a coupling unbounded below shrinks the steps
        without bound: unbounded, one such start ran for more than 15 minutes and took GBs of
        dense output.  1e7 evaluations is ~3 minutes: an ordinary return takes 3,900-6,000 at
        step_fraction 64, a long chaotic one (t = 54, 128) 1.1e6.  One chunk (about a local
        period) may spend at most ``CHUNK_EVALUATIONS`` of them, which bounds the dense output
        held at once (~17k steps, ~20 MB of samples; an ordinary chunk takes ~1,500).

    Returns
    -------
    dict
        ``status`` ("ok", "corner", "grazing", "limit", "failed"), ``time``, ``z`` (state at the
        end, ndarray (4,)), ``itinerary`` (str of 'R' and '1' in order), ``energy_error``
        (|H(z) - H(z0)|), and also ``crossed`` (True if q1 = qw1 was crossed where the right wall
        is absent), ``steps`` (accepted DOP853 steps of the kept pieces) and ``evaluations``
        (right-hand-side evaluations spent).
    """
    if geometry not in ("step", "wall", "none"):
        raise ValueError(f"unknown geometry {geometry!r}")
    terms = _terms(coupling)
    z0 = np.asarray(z0, float).copy()
    is_step, has_walls = geometry == "step", geometry != "none"
    active = (0, 1, 2, 3) if is_step else (0, 2) if has_walls else (2,)  # the g_k that matter

    def force(q1, q2):
        return (-_pot(V1, q1, 1) - eps * _vc(terms, q1, q2, 1, 0), -_pot(V2, q2, 1) - eps * _vc(terms, q1, q2, 0, 1))

    spent = [0, 0]  # in all, in this chunk

    def rhs(t, y):
        spent[0] += 1
        spent[1] += 1
        if spent[0] > max_evaluations or spent[1] > CHUNK_EVALUATIONS:
            raise _OutOfBudget
        f1, f2 = force(y[0], y[2])
        return np.array([y[1], f1, y[3], f2])

    def period(Y):
        """Shortest local period 2 pi / sqrt(max |eig Hess V|) at states Y (4, m)."""
        q1, q2 = Y[0], Y[2]
        a = _pot(V1, q1, 2) + eps * _vc(terms, q1, q2, 2, 0)
        d = _pot(V2, q2, 2) + eps * _vc(terms, q1, q2, 0, 2)
        b = eps * _vc(terms, q1, q2, 1, 1)
        m, r = 0.5 * (a + d), np.sqrt(0.25 * (a - d) ** 2 + b * b)
        lam = np.maximum(np.abs(m + r), np.abs(m - r))
        return 2 * math.pi / np.sqrt(np.maximum(lam, 1e-30))

    def gfun(Y):
        f1, f2 = force(Y[0], Y[2])
        return (np.array([Y[0] - qw1, Y[2] - qw2, Y[1], Y[3]]), np.array([Y[1], Y[3], f1, f2]))

    def comp(sol, k, deriv):
        def f(t):
            g, d = gfun(sol(t)[:, None])
            return float((d if deriv else g)[k, 0])

        return f

    def root(sol, k, a, b):
        """Zero of g_k in [a, b] (a sign change): brentq, then Newton steps on (g_k, g_k')."""
        g, d = comp(sol, k, False), comp(sol, k, True)
        r = brentq(g, a, b, xtol=1e-15, rtol=1e-15)
        for _ in range(2):
            dr = d(r)
            rn = r - g(r) / dr if dr != 0 else r
            if not a <= rn <= b:
                break
            r = rn
        return r

    def in_wells(Y):
        return bool(np.all(_inside(V1, Y[0]) & _inside(V2, Y[2]) & np.isfinite(Y).all(axis=0)))

    h0 = float(energy(V1, V2, coupling, eps, z0))
    out = {"itinerary": "", "crossed": False, "steps": 0}

    def finish(status, t, y):
        y = np.asarray(y, float)
        out.update(
            status=status,
            time=float(t),
            z=y.copy(),
            energy_error=abs(float(energy(V1, V2, coupling, eps, y)) - h0),
            evaluations=spent[0],
        )
        return out

    if not in_wells(z0[:, None]):
        return finish("failed", 0.0, z0)
    t, y, armed, impacts = 0.0, z0.copy(), False, 0
    cap = min(0.5, float(period(y[:, None])[0]) / step_fraction)
    while True:
        if t >= t_max:
            return finish("limit", t, y)
        # --- integrate one chunk, refining max_step until every step obeys the cap rule
        while True:
            t_end = min(t + step_fraction * cap, t_max * (1 + 1e-12) + 1e-12)
            spent[1] = 0
            try:
                sol = solve_ivp(
                    rhs, (t, t_end), y, method="DOP853", rtol=rtol, atol=atol, dense_output=True, max_step=cap
                )
            except _OutOfBudget:
                return finish("limit", t, y)
            ts = sol.t
            if sol.status != 0 or len(ts) < 2:
                return finish("failed", t, y)
            T = (ts[:-1, None] + (ts[1:] - ts[:-1])[:, None] * np.arange(N_SAMPLE)[None, :] / N_SAMPLE).ravel()
            T = np.append(T, ts[-1])
            Y = sol.sol(T)
            if not in_wells(Y):
                if cap < 1e-12 * max(1.0, abs(t)):
                    return finish("failed", t, y)
                cap *= 0.25
                continue
            P = period(Y)
            Pstep = np.minimum(P[:-1].reshape(-1, N_SAMPLE).min(axis=1), P[N_SAMPLE::N_SAMPLE])
            hs = np.diff(ts)
            if np.all(hs <= Pstep / step_fraction * (1 + 1e-12)):
                break
            cap = 0.5 * float(np.min(Pstep)) / step_fraction
        # --- every root of g0..g3 on the chunk
        G, D = gfun(Y)
        SG = np.where(G != 0, np.sign(G), np.sign(D))  # an exact zero takes the direction of motion
        events = []
        for k in active:
            sd = np.sign(D[k])
            for j in np.nonzero((sd[:-1] * sd[1:] < 0) | (SG[k, :-1] != SG[k, 1:]))[0]:
                ta, tb = T[j], T[j + 1]
                cuts = [(ta, SG[k, j])]
                if sd[j] * sd[j + 1] < 0:  # extremum of g_k inside: split into monotone pieces
                    te = brentq(comp(sol.sol, k, True), ta, tb, xtol=1e-15, rtol=1e-15)
                    ge = comp(sol.sol, k, False)(te)
                    cuts.append((te, np.sign(ge) if ge != 0 else SG[k, j]))
                cuts.append((tb, SG[k, j + 1]))
                for (a, sa), (b, sb) in zip(cuts[:-1], cuts[1:]):
                    if sa != sb and b > a:
                        r = root(sol.sol, k, a, b)
                        events.append((r, k, int(sb)))
        events.sort()
        out["steps"] += len(ts) - 1
        restart = None
        for te, k, direction in events:
            ye = sol.sol(te)
            if te > t_max:
                return finish("limit", te, ye)
            if k == 2:  # p1 = 0
                if direction > 0:  # minimum of q1
                    wall_here = geometry == "wall" or (is_step and ye[2] < qw2)
                    if wall_here and 0 <= ye[0] - qw1 < grazing_tol:
                        return finish("grazing", te, ye)
                    armed = True
                elif armed:
                    return finish("ok", te, ye)
            elif k == 3:  # p2 = 0
                if is_step and direction > 0 and ye[0] < qw1 and 0 <= ye[2] - qw2 < grazing_tol:
                    return finish("grazing", te, ye)
            elif has_walls and direction < 0 and (k == 0 or is_step):
                other = ye[2] - qw2 if k == 0 else ye[0] - qw1
                if is_step and abs(other) <= corner_tol:
                    return finish("corner", te, ye)
                if k == 0 and is_step and other > 0:
                    out["crossed"] = True
                    continue
                if k == 1 and other > 0:
                    continue
                if impacts >= MAX_IMPACTS:
                    return finish("limit", te, ye)
                impacts += 1
                ye = ye.copy()
                if k == 0:
                    ye[0], ye[1] = qw1, -ye[1]
                    armed = True
                    out["itinerary"] += "R"
                else:
                    ye[2], ye[3] = qw2, -ye[3]
                    out["itinerary"] += "1"
                restart = (te, ye)
                break
        if restart is not None:
            t, y = restart
        else:
            t, y = float(ts[-1]), Y[:, -1].copy()
        cap = min(cap, float(period(y[:, None])[0]) / step_fraction)  # keep a cap that worked
