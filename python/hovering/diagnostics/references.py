"""Independent implementations of one return of the flow, for work-precision comparisons: scipy's
``solve_ivp`` (DOP853) and heyoka.py's Taylor integrator, each with events, written the way a user
of those libraries writes them. Neither shares code with the core; both are optional (imported
only when called).
"""

from __future__ import annotations

import time

import numpy as np

from .._extras import require
from ..flow.system import Harmonic, Tan, _terms

__all__ = ["scipy_return_map", "heyoka_return_map"]


def scipy_return_map(sys, z0, rtol: float):
    """One return of the flow by scipy's ``solve_ivp`` (DOP853, atol = rtol / 100) with events, for the
    work-precision comparison (scipy must be installed: hovering[scipy]). Walls reflect; a crossing of a wall's line
    beside / above the step does nothing; the section is the first p1 sign change + -> - after q1's
    minimum or a reflection. Events within 1e-9 of a restart are ignored (a restart sits on the
    event it handled). Grazing and corner hits are not classified: this is a reference for regular
    returns, as users write it, not a second product.

    Returns
    -------
    ndarray or None
        The state at the return (None if it did not return within 50 segments).
    """
    solve_ivp = require("scipy.integrate", "the scipy reference of the accuracy diagram").solve_ivp

    V1, V2, eps, qw1, qw2 = sys.V1, sys.V2, sys.eps, sys.qw1, sys.qw2
    terms = _terms(sys.coupling) if eps != 0 else []

    def rhs(t, z):
        g1 = g2 = 0.0
        for c, i, j in terms:
            if i:
                g1 += c * i * z[0] ** (i - 1) * z[2] ** j
            if j:
                g2 += c * j * z[0] ** i * z[2] ** (j - 1)
        return [z[1], -V1.dV(z[0]) - eps * g1, z[3], -V2.dV(z[2]) - eps * g2]

    def right(t, z):
        return z[0] - qw1

    def upper(t, z):
        return z[2] - qw2

    def p1(t, z):
        return z[1]

    right.direction = upper.direction = -1
    walls = sys.geometry != "none"
    step = sys.geometry == "step"
    z, t, armed = np.array(z0, float), 0.0, False
    # Segments of 1.37 periods: an event at a segment's very end (a return after exactly one
    # period, as at eps = 0 without impact) can be missed there and is filtered at the next start.
    T = 1.37 * 2 * np.pi / max(V1.frequency(max(1e-12, 0.5 * z[1] ** 2 + V1.V(z[0]))), 1e-3)
    for _ in range(50):
        sol = solve_ivp(
            rhs,
            (t, t + T),
            z,
            method="DOP853",
            rtol=rtol,
            atol=rtol * 1e-2,
            events=[right, upper, p1],
            dense_output=False,
        )
        evs = []
        for k in range(3):
            for te, ye in zip(sol.t_events[k], sol.y_events[k]):
                if te > t + 1e-9:
                    evs.append((te, k, ye))
        handled = False
        for te, k, ye in sorted(evs, key=lambda e: e[0]):
            if k == 2:
                # The direction of the p1 crossing is the sign of dp1/dt = -V1'(q1), not of p1 at
                # the root: scipy may return p1 = 0.0 there exactly (it did at q1's minimum).
                dp = -V1.dV(ye[0])
                if dp > 0:
                    armed = True
                elif armed:
                    return ye
                continue
            if k == 0 and walls and (not step or ye[2] < qw2):
                z = ye.copy()
                z[0], z[1] = qw1, -z[1]
            elif k == 1 and step and ye[0] < qw1:
                z = ye.copy()
                z[2], z[3] = qw2, -z[3]
            else:
                continue
            t, armed, handled = te, True, True
            break
        if not handled:
            z, t = sol.y[:, -1], sol.t[-1]
    return None


def heyoka_return_map(sys, z0_list, rtol: float):
    """Returns of the flow by heyoka.py's Taylor integrator with events (heyoka must be installed; V1,
    V2 Harmonic or Tan, polynomial coupling), for the work-precision comparison: same event logic
    as :func:`scipy_return_map`. Compiles one integrator (JIT, ~1 s) and returns (states, seconds of
    the returns alone); None for a state that did not return.
    """
    import heyoka as hy

    q1, p1, q2, p2 = hy.make_vars("q1", "p1", "q2", "p2")

    def force(V, q):
        if isinstance(V, Tan):
            return (V.omega**2 / V.alpha) * hy.tan(V.alpha * q) / hy.cos(V.alpha * q) ** 2
        if isinstance(V, Harmonic):
            return V.omega**2 * q
        raise ValueError(f"heyoka curve: V must be Harmonic or Tan, got {V!r}")

    f1, f2 = force(sys.V1, q1), force(sys.V2, q2)
    if sys.eps != 0:
        for c, i, j in _terms(sys.coupling):
            i, j = int(i), int(j)
            if i:
                f1 = f1 + sys.eps * c * i * q1 ** (i - 1) * q2**j
            if j:
                f2 = f2 + sys.eps * c * j * q1**i * q2 ** (j - 1)
    ev = [
        hy.t_event(q1 - sys.qw1, direction=hy.event_direction.negative),
        hy.t_event(p1, direction=hy.event_direction.negative),
        hy.t_event(p1, direction=hy.event_direction.positive),
        hy.t_event(q2 - sys.qw2, direction=hy.event_direction.negative),
    ]
    ta = hy.taylor_adaptive([(q1, p1), (p1, -f1), (q2, p2), (p2, -f2)], list(z0_list[0]), t_events=ev, tol=rtol)
    walls, step = sys.geometry != "none", sys.geometry == "step"
    out = []
    t0 = time.perf_counter()
    for z0 in z0_list:
        ta.time = 0.0
        ta.state[:] = z0
        ta.reset_cooldowns()
        armed, res = False, None
        for _ in range(60):
            oc = int(ta.propagate_until(ta.time + 50.0)[0])
            st = ta.state
            if oc == -1 and walls and (not step or st[2] < sys.qw2):
                st[0], st[1] = sys.qw1, -st[1]
                armed = True
            elif oc == -4 and step and st[0] < sys.qw1:
                st[2], st[3] = sys.qw2, -st[3]
                armed = True
            elif oc == -3:
                armed = True
            elif oc == -2 and armed:
                res = st.copy()
                break
        out.append(res)
    return out, time.perf_counter() - t0
