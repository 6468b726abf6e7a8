"""Continuation of periodic orbits in a map parameter (eps, or any parameter a map's ``with_eps``
or a user's family gives), by pseudo-arclength on the multiple-shooting system, with fold and
period-doubling detection.

The unknowns are the segment starts X = (x_0, ..., x_{S-1}) of :func:`periodic_orbit`'s
multiple shooting and the parameter p; G(X, p) = (F_p^m(x_i) - x_{i+1})_i. Along the branch
(X(s), p(s)), s its arclength, each step predicts along the tangent (the null vector of
[dG/dX, dG/dp], oriented as the last one) and corrects by Newton on G = 0 with the arclength
condition t . (Y - Y_pred) = 0 (Keller). dG/dX are the segments' Jacobian products (the core);
dG/dp a central difference in p (the maps at p +- h). A fold is where dp/ds changes sign (a
saddle-node: the residue passes through 0, a multiplier through +1); a period doubling where the
residue crosses 1 (a multiplier through -1).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .._checks import _short, integer, real_number
from .._display import Summarized
from .._enums import wrap
from .._io.serial import Saveable
from ..interface import require_map
from . import _tangent as T
from .periodic import PeriodicOrbit, _segments, periodic_orbit

__all__ = ["Branch", "continue_orbit", "pseudo_arclength"]


@dataclass(frozen=True, repr=False)
class Branch(Summarized, Saveable):
    """A branch of periodic orbits followed in a parameter (:func:`continue_orbit`).

    Attributes
    ----------
    parameter : ndarray
        The parameter p at each point of the branch.
    phi, K : ndarray
        The orbit's first point at each p.
    residue : ndarray
        Greene's residue of the orbit at each p.
    stability : list of str
        Its stability at each p.
    events : list of dict
        Folds (``{"kind": "fold", "parameter": p, "index": i}``: dp/ds changed sign between
        points i and i + 1, p interpolated where it turns) and period doublings (``"period
        doubling"``: the residue crossed 1, p interpolated linearly).
    period : int
        The orbits' period.
    status : str
        ``"complete"`` (the parameter range or the step count was covered), ``"corrector failed"``
        (Newton did not converge even with the step halved to ``min_step``), ``"step_failed"`` (an
        orbit's step had no number: it hit a corner, left the band, ...).
    steps : int
        Continuation steps taken.
    """

    parameter: np.ndarray
    phi: np.ndarray
    K: np.ndarray
    residue: np.ndarray
    stability: list
    events: list = field(default_factory=list)
    period: int = 0
    status: str = "complete"
    steps: int = 0

    def _summary(self) -> list:
        return [
            ("period", self.period),
            ("points", self.parameter.size),
            ("parameter", f"{self.parameter.min():.6g}..{self.parameter.max():.6g}" if self.parameter.size else "-"),
            ("events", ", ".join(f"{e['kind']} at {e['parameter']:.6g}" for e in self.events) or "none"),
            ("status", self.status),
        ]


def pseudo_arclength(G, J, y0, t0, ds, n_steps, *, tol=1e-10, max_iter=12, min_step=None, bounds=None, on_point=None):
    """Pseudo-arclength continuation of G(y) = 0, y = (x, p) in R^{n+1}, G: R^{n+1} -> R^n.

    Parameters
    ----------
    G : callable
        y -> residual (n,), or None where it cannot be evaluated.
    J : callable
        y -> Jacobian (n, n + 1), or None.
    y0 : ndarray
        A point on the branch (G(y0) ~ 0).
    t0 : ndarray
        The direction to go (a tangent, normalised here; its sign chooses the way).
    ds : float
        Step length (reduced by halving where the corrector fails, regrown after successes).
    n_steps : int
        Steps at most.
    tol, max_iter : optional
        Corrector tolerance (max norm of G) and iterations.
    min_step : float, optional
        Smallest step (default ds / 1024).
    bounds : (float, float), optional
        Stop once the last coordinate (the parameter) leaves this interval.
    on_point : callable, optional
        Called with each new point; returning False stops.

    Returns
    -------
    (points, tangents, status)
        ``points`` (k, n + 1) and the unit tangents there; status ``"complete"`` or ``"corrector
        failed"``.
    """
    y = np.asarray(y0, dtype=float).copy()
    t = np.asarray(t0, dtype=float) / np.linalg.norm(t0)
    min_step = abs(ds) / 1024 if min_step is None else min_step
    pts, tans = [y.copy()], [t.copy()]
    h = abs(ds)
    status = "complete"
    for _ in range(n_steps):
        while True:
            yp = y + h * t
            yc, ok = yp.copy(), False
            for _ in range(max_iter):
                g = G(yc)
                Jc = J(yc) if g is not None else None
                if g is None or Jc is None:
                    break
                if np.max(np.abs(g)) <= tol:
                    ok = True
                    break
                A = np.vstack([Jc, t[None, :]])
                rhs = -np.concatenate([g, [t @ (yc - yp)]])
                try:
                    dy = np.linalg.solve(A, rhs)
                except np.linalg.LinAlgError:
                    break
                yc = yc + dy
            if ok:
                break
            h *= 0.5
            if h < min_step:
                return np.array(pts), np.array(tans), "corrector failed"
        Jc = J(yc)
        # the new tangent: the null vector of J, oriented along the old one
        _, _, vt = np.linalg.svd(Jc)
        tn = vt[-1]
        tn = tn if tn @ t >= 0 else -tn
        y, t = yc, tn
        pts.append(y.copy())
        tans.append(t.copy())
        h = min(abs(ds), 1.5 * h)
        if bounds is not None and not (bounds[0] <= y[-1] <= bounds[1]):
            break
        if on_point is not None and on_point(y) is False:
            break
    return np.array(pts), np.array(tans), status


def continue_orbit(
    m,
    orbit: PeriodicOrbit,
    stop: float,
    *,
    family: Callable | None = None,
    parameter: float | None = None,
    ds: float | None = None,
    n_steps: int = 200,
    dp: float = 1e-6,
    tol: float | None = None,
    n_threads: int = 0,
) -> Branch:
    """Follow a periodic orbit as a map parameter moves, by pseudo-arclength continuation.

    Parameters
    ----------
    m : TruncatedMap, TruncatedFamily or FlowMap
        The map at the orbit's parameter.
    orbit : PeriodicOrbit
        A converged orbit of m (the branch's start).
    stop : float
        The parameter value to reach (the branch is followed towards it, and stops once past it,
        at a fold where it turns back beyond its start, or after ``n_steps``).
    family : callable, optional
        p -> the map at parameter p (default ``m.with_eps``: p is eps). Any map parameter: e.g.
        ``lambda w: hovering.TruncatedMap(eps, Omega0=w, theta_w=...)``.
    parameter : float, optional
        The value of p at m (default ``m.eps``; required with a ``family``).
    ds : float, optional
        Arclength step (default |stop - p0| / 50).
    n_steps : int, optional
        Steps at most.
    dp : float, optional
        Step of the central difference dG/dp (relative to max(1, |p|)).
    tol : float, optional
        Corrector tolerance (default 10x the map's accuracy).
    n_threads : int, optional
        Worker threads.

    Returns
    -------
    Branch

    Raises
    ------
    ValueError
        For an orbit that is not converged, a bad parameter or step, or a family that does not
        give a map.

    Examples
    --------
    The standard map's elliptic fixed point (residue k / 4) loses stability by period doubling
    where its residue reaches 1, at k = 4:

    >>> import numpy as np, hovering
    >>> sm = hovering.TruncatedMap(eps=1.0, Omega0=0.3, theta_w=2.0)
    >>> fixed = hovering.periodic_orbit(sm, 3.0, 6.0, 1)
    >>> branch = hovering.continue_orbit(sm, fixed, 5.0)
    >>> [(e["kind"], round(e["parameter"], 6)) for e in branch.events]
    [('period doubling', 4.0)]
    """
    require_map("m", m)
    if not isinstance(orbit, PeriodicOrbit) or not orbit.converged:
        raise ValueError(f"orbit must be a converged PeriodicOrbit, got {_short(orbit)}")
    if family is None:
        family = m.with_eps
        p0 = float(m.eps) if parameter is None else real_number("parameter", parameter)
    else:
        if not callable(family):
            raise ValueError(f"family must be a callable p -> map, got {_short(family)}")
        if parameter is None:
            raise ValueError("parameter (the value of p at m) is required with a family")
        p0 = real_number("parameter", parameter)
    stop = real_number("stop", stop)
    if stop == p0:
        raise ValueError(f"stop must differ from the start parameter {p0}")
    ds = abs(stop - p0) / 50 if ds is None else real_number("ds", ds, lo=0.0)
    n_steps = integer("n_steps", n_steps, 1, 100_000)
    dp = real_number("dp", dp, lo=0.0, hi=1.0)
    tol = 10 * T.map_tolerance(m) if tol is None else real_number("tol", tol, lo=0.0)
    period = orbit.period
    m_steps, S = _segments(period, None)
    cache: dict = {p0: m}

    def at(p):
        if p not in cache:
            mp = family(p)
            require_map("family(p)", mp)
            if len(cache) > 64:
                cache.clear()
            cache[p] = mp
        return cache[p]

    def unpack(y):
        return wrap(y[0:-1:2]), y[1:-1:2], y[-1]

    state = {"fail": None}

    def seg(y, p=None):
        phi, K, pp = unpack(y)
        try:
            s = T.advance(at(pp if p is None else p), phi, K, m_steps, n_threads)
        except ValueError:
            return None
        if not np.all(s.ok):
            state["fail"] = int(s.status[~s.ok][0])
            return None
        return s

    def G(y):
        phi, K, _ = unpack(y)
        s = seg(y)
        if s is None:
            return None
        r = np.empty(2 * S)
        r[0::2] = T.angle_gap(s.phi, np.roll(phi, -1))
        r[1::2] = s.K - np.roll(K, -1)
        return r

    def Jac(y):
        phi, K, p = unpack(y)
        s = seg(y)
        if s is None:
            return None
        A = np.zeros((2 * S, 2 * S + 1))
        for i in range(S):
            A[2 * i : 2 * i + 2, 2 * i : 2 * i + 2] = s.M[i]
            j = (i + 1) % S
            A[2 * i : 2 * i + 2, 2 * j : 2 * j + 2] -= np.eye(2)
        h = dp * max(1.0, abs(p))
        a, b = seg(y, p + h), seg(y, p - h)
        if a is None or b is None:
            return None
        A[0::2, -1] = T.angle_gap(a.phi, b.phi) / (2 * h)
        A[1::2, -1] = (a.K - b.K) / (2 * h)
        return A

    idx = np.arange(S) * m_steps
    y0 = np.empty(2 * S + 1)
    y0[0:-1:2], y0[1:-1:2], y0[-1] = orbit.phi[idx], orbit.K[idx], p0
    J0 = Jac(y0)
    if J0 is None:
        raise ValueError("the orbit's steps have no Jacobian at its parameter")
    _, _, vt = np.linalg.svd(J0)
    t0 = vt[-1] if vt[-1][-1] * (stop - p0) >= 0 else -vt[-1]
    lo, hi = sorted((p0, stop))
    margin = 0.5 * ds
    pts, tans, status = pseudo_arclength(G, Jac, y0, t0, ds, n_steps, tol=tol, bounds=(lo - margin, hi + margin))
    if status == "corrector failed" and state["fail"] is not None:
        status = "step_failed"
    # each point's residue, and the events between points
    res, stab, P, Ph, Kk = [], [], pts[:, -1], [], []
    for y in pts:
        phi, K, p = unpack(y)
        o = periodic_orbit(
            at(p), float(phi[0]), float(K[0]), period, tol=max(tol, 1e-13), max_iter=5, n_threads=n_threads
        )
        res.append(o.residue if o.converged else math.nan)
        stab.append(o.stability if o.converged else "unknown")
        Ph.append(float(phi[0]))
        Kk.append(float(K[0]))
    res = np.array(res)
    events = []
    dpds = tans[:, -1]
    for i in range(len(pts) - 1):
        if dpds[i] * dpds[i + 1] < 0:
            # the turning point of p(s) between the two: the vertex of the parabola through p_i,
            # p_{i+1} with slopes dp/ds there (linear interpolation of dp/ds)
            f = dpds[i] / (dpds[i] - dpds[i + 1])
            ds_i = np.linalg.norm(pts[i + 1] - pts[i])
            p_turn = P[i] + dpds[i] * f * ds_i / 2
            events.append({"kind": "fold", "parameter": float(p_turn), "index": i})
        if np.isfinite(res[i]) and np.isfinite(res[i + 1]) and (res[i] - 1) * (res[i + 1] - 1) < 0:
            f = (1 - res[i]) / (res[i + 1] - res[i])
            events.append({"kind": "period doubling", "parameter": float(P[i] + f * (P[i + 1] - P[i])), "index": i})
    # the last point may overshoot stop: keep it (the events near stop need it), stop there
    return Branch(
        parameter=P,
        phi=np.array(Ph),
        K=np.array(Kk),
        residue=res,
        stability=stab,
        events=events,
        period=period,
        status=status,
        steps=len(pts) - 1,
    )
