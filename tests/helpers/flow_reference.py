"""Independent pure-NumPy reference for ONE return of the step-impact flow (cross-check oracle).

Written from the problem statement only (it shares no code with ``hovering``):

    H = p1^2/2 + q1^2/2 + p2^2/2 + V2(q2) + eps*q1*q2,
    V2(q) = (omega^2 / (2 alpha^2)) tan^2(alpha q),   omega = 1.4, alpha = 0.7,

with the solid step {q1 < qw1, q2 < qw2}, qw1 = -1, qw2 = -0.5.  The right wall (q1 = qw1,
q2 < qw2) reflects p1, the upper wall (q2 = qw2, q1 < qw1) reflects p2.  The section is
Sigma_h = {p1 = 0, dp1/dt < 0, H = h}; one return goes from a maximum of q1 through its minimum
(or a right-wall reflection) to the next maximum of q1.

Integration: classical RK4 with a fixed step ``dt`` for all points at once (vectorised over the
points; each point keeps its own clock).  Events are found from sign changes at step ends:

* q1 - qw1 (crossing the line of the right wall, either direction),
* q2 - qw2 downwards while q1 is near or left of qw1 (upper wall),
* p1 from - to + (q1 minimum: q1 has turned; also catches dips of q1 below qw1 inside a step),
* p1 from + to - after the turn (the return to Sigma_h),
* p2 from - to + while q1 is near or left of qw1 (q2 minimum: dips below qw2 inside a step),

and located by bisection (to ``TIME_TOL``) on RK4 sub-steps of length tau taken from the start
of the step, i.e. on the same discrete integrator.  After the earliest event of a step the
orbit restarts from the event point (with the reflected momentum after an impact).

The angle-action coordinates (theta, I) of the unperturbed oscillator 2 use the exact solution
of the Tan oscillator: with s = sin(alpha q2) and E = H2(q2, p2),

    ds/dt = alpha cos(alpha q2) p2,   (ds/dt)^2 + Omega^2 s^2 = 2 alpha^2 E,
    Omega(E) = sqrt(omega^2 + 2 alpha^2 E) = omega + alpha^2 I   (dH2/dI),

so s = A cos(theta), ds/dt = -A Omega sin(theta) with A = alpha sqrt(2E) / Omega, theta = Omega t
(theta = 0 at the right turning point, increasing with time), and I = 2E / (Omega + omega)
(the root of H2(I) = omega I + alpha^2 I^2 / 2 = E).
"""

from __future__ import annotations

import math

import numpy as np

OMEGA2 = 1.4
ALPHA = 0.7
QW1 = -1.0
QW2 = -0.5
H_LEVEL = 1.0

#: RK4 step: one return is then accurate to ~1e-12 in theta, ~1e-13 in I (measured by step
#: halving; the error scales as DT^4).
DT = 1.0e-3
#: Bisection of an event time stops when its bracket is shorter than this.
TIME_TOL = 1e-13
#: The q2 events (upper wall, q2 minima) are examined only while q1 - qw1 < NEAR at a step end
#: (q1 moves by at most |p1| dt < 0.003 within a step).
NEAR = 0.02
#: A return longer than this is abandoned (status failed, NaN image).
MAX_TIME = 60.0

_K2 = OMEGA2**2 / ALPHA  # V2'(q) = _K2 tan(alpha q) (1 + tan^2(alpha q))


# --------------------------------------------------------------------------------------------
# Unperturbed oscillator 2: angle-action variables
# --------------------------------------------------------------------------------------------


def energy2(I):
    """H2 as a function of the action: omega I + alpha^2 I^2 / 2."""
    return OMEGA2 * I + 0.5 * ALPHA**2 * I**2


def frequency2(E):
    """Omega(E) = dH2/dI = sqrt(omega^2 + 2 alpha^2 E)."""
    return np.sqrt(OMEGA2**2 + 2.0 * ALPHA**2 * E)


def hamiltonian2(q2, p2):
    t = np.tan(ALPHA * np.asarray(q2, float))
    return 0.5 * np.asarray(p2, float) ** 2 + 0.5 * (OMEGA2 / ALPHA) ** 2 * t**2


def hamiltonian(q1, p1, q2, p2, eps):
    return 0.5 * p1**2 + 0.5 * q1**2 + hamiltonian2(q2, p2) + eps * q1 * q2


def coordinates(q2, p2):
    """(theta, I) of oscillator 2 alone; theta in [-pi, pi), sign(theta) = -sign(p2)."""
    q2 = np.asarray(q2, float)
    p2 = np.asarray(p2, float)
    E = hamiltonian2(q2, p2)
    Om = frequency2(E)
    I = 2.0 * E / (Om + OMEGA2)
    # A cos(theta) = s,  A sin(theta) = -(ds/dt) / Omega = -alpha cos(alpha q2) p2 / Omega.
    theta = np.arctan2(-ALPHA * np.cos(ALPHA * q2) * p2 / Om, np.sin(ALPHA * q2))
    theta = np.where(theta >= np.pi, theta - 2.0 * np.pi, theta)
    return theta, I


def oscillator2(theta, I):
    """Inverse of :func:`coordinates`: (q2, p2) of the unperturbed oscillator 2."""
    theta = np.asarray(theta, float)
    I = np.asarray(I, float)
    E = energy2(I)
    Om = OMEGA2 + ALPHA**2 * I
    A = ALPHA * np.sqrt(2.0 * E) / Om
    s = A * np.cos(theta)
    q2 = np.arcsin(s) / ALPHA
    p2 = -A * Om * np.sin(theta) / (ALPHA * np.sqrt(1.0 - s * s))
    return q2, p2


def section_point(theta, I, eps, h=H_LEVEL):
    """State (q1, p1, q2, p2) of the point (theta, I) of Sigma_h (NaN q1 where there is none).

    q1 is the positive root of q1^2/2 + eps q1 q2 = h - H2(I); it satisfies q1 + eps q2 > 0,
    i.e. dp1/dt < 0.
    """
    q2, p2 = oscillator2(theta, I)
    disc = (eps * q2) ** 2 + 2.0 * (h - energy2(np.asarray(I, float)))
    root = np.sqrt(np.where(disc >= 0.0, disc, np.nan))
    q1 = -eps * q2 + root
    return q1, np.zeros_like(q1), q2, p2


# --------------------------------------------------------------------------------------------
# Integrator (works on float arrays with np.tan, or on Python floats with math.tan)
# --------------------------------------------------------------------------------------------


def _deriv(q1, p1, q2, p2, eps, tan):
    t = tan(ALPHA * q2)
    return p1, -q1 - eps * q2, p2, -_K2 * t * (1.0 + t * t) - eps * q1


def _rk4(y, tau, eps, tan=np.tan):
    """One classical RK4 step of length tau (scalar or one per point) from y = (q1, p1, q2, p2)."""
    k1 = _deriv(*y, eps, tan)
    k2 = _deriv(*[a + 0.5 * tau * k for a, k in zip(y, k1)], eps, tan)
    k3 = _deriv(*[a + 0.5 * tau * k for a, k in zip(y, k2)], eps, tan)
    k4 = _deriv(*[a + tau * k for a, k in zip(y, k3)], eps, tan)
    return tuple(a + (tau / 6.0) * (b1 + 2.0 * b2 + 2.0 * b3 + b4) for a, b1, b2, b3, b4 in zip(y, k1, k2, k3, k4))


def _substep(y0, tau, eps):
    return _rk4(y0, tau, eps, math.tan)


def _locate(y0, g, lo, hi, eps, positive_at_lo):
    """Bisection of a sign change of g(RK4 sub-step of length tau from y0) on [lo, hi]."""
    while hi - lo > TIME_TOL:
        mid = 0.5 * (lo + hi)
        if (g(_substep(y0, mid, eps)) > 0.0) == positive_at_lo:
            lo = mid
        else:
            hi = mid
    return lo, hi


def _g1(y):
    return y[0] - QW1


def _g2(y):
    return y[2] - QW2


def _p1(y):
    return y[1]


def _p2(y):
    return y[3]


def _events(y0, y1, dt, eps, turned):
    """All events of the step y0 -> y1 (length dt): (time, kind, lo, hi), bracket [lo, hi]."""
    g1a, g1b = _g1(y0), _g1(y1)
    g2a, g2b = _g2(y0), _g2(y1)
    near = min(g1a, g1b) < NEAR
    ev = []
    if g1a > 0.0 >= g1b:
        lo, hi = _locate(y0, _g1, 0.0, dt, eps, True)
        ev.append((lo, "x1down", lo, hi))
    if g1a < 0.0 <= g1b:
        lo, hi = _locate(y0, _g1, 0.0, dt, eps, False)
        ev.append((lo, "x1up", lo, hi))
    if near and g2a > 0.0 >= g2b:
        lo, hi = _locate(y0, _g2, 0.0, dt, eps, True)
        ev.append((lo, "x2down", lo, hi))
    if y0[1] < 0.0 <= y1[1]:  # q1 minimum
        lo, hi = _locate(y0, _p1, 0.0, dt, eps, False)
        ev.append((lo, "min1", lo, hi))
        if g1a > 0.0 and g1b > 0.0 and _g1(_substep(y0, hi, eps)) < 0.0:  # dip inside the step
            lo2, hi2 = _locate(y0, _g1, 0.0, hi, eps, True)
            ev.append((lo2, "x1down", lo2, hi2))
    if turned and y0[1] > 0.0 >= y1[1]:  # q1 maximum: back on Sigma_h
        lo, hi = _locate(y0, _p1, 0.0, dt, eps, True)
        ev.append((lo, "max1", lo, hi))
    if near and y0[3] < 0.0 <= y1[3]:  # q2 minimum near the upper wall
        lo, hi = _locate(y0, _p2, 0.0, dt, eps, False)
        ev.append((lo, "min2", lo, hi))
        if g2a > 0.0 and g2b > 0.0 and _g2(_substep(y0, hi, eps)) < 0.0:
            lo2, hi2 = _locate(y0, _g2, 0.0, hi, eps, True)
            ev.append((lo2, "x2down", lo2, hi2))
    return ev


def _upper_wall_distance(q1, q2):
    """Distance from (q1, q2) to the upper wall {q2 = qw2, q1 <= qw1}."""
    if q1 <= QW1:
        return abs(q2 - QW2)
    return math.hypot(q1 - QW1, q2 - QW2)


def return_map_details(theta, I, eps, h=H_LEVEL, dt=DT, max_impacts=100):
    """One return of every point (theta, I) of Sigma_h, with diagnostics.

    Returns a dict of flat arrays: ``theta``, ``I``, ``state`` (image (q1, p1, q2, p2), shape
    (4, n)), ``time`` (return time), ``itinerary`` (list of str), ``ok`` (bool), ``margin``
    (smallest distance, at an event, to a wall or the corner: |q2 - qw2| at every crossing of
    q1 = qw1, |q1 - qw1| at every downward crossing of q2 = qw2 near the step and at the q1
    minimum, the distance to the upper wall at q2 minima near it) and ``energy_error``.
    """
    theta = np.asarray(theta, float).ravel()
    I = np.asarray(I, float).ravel()
    theta, I = np.broadcast_arrays(theta, I)
    n = theta.size
    y = np.array(section_point(theta, I, eps, h), dtype=float)  # (4, n)
    h0 = hamiltonian(*y, eps)
    t = np.zeros(n)
    turned = np.zeros(n, bool)
    crossed = np.zeros(n, bool)
    impacts = [""] * n
    margin = np.full(n, np.inf)
    ok = np.isfinite(y).all(axis=0)
    done = ~ok
    out = np.full((4, n), np.nan)

    while True:
        idx = np.flatnonzero(~done)
        if idx.size == 0:
            break
        y0 = y[:, idx]
        y1 = np.array(_rk4(tuple(y0), dt, eps))
        g1a, g1b = y0[0] - QW1, y1[0] - QW1
        g2a, g2b = y0[2] - QW2, y1[2] - QW2
        p1a, p1b, p2a, p2b = y0[1], y1[1], y0[3], y1[3]
        near = np.minimum(g1a, g1b) < NEAR
        flag = (
            ((g1a > 0) & (g1b <= 0))
            | ((g1a < 0) & (g1b >= 0))
            | (near & (g2a > 0) & (g2b <= 0))
            | ((p1a < 0) & (p1b >= 0))
            | (turned[idx] & (p1a > 0) & (p1b <= 0))
            | (near & (p2a < 0) & (p2b >= 0))
        )
        plain = idx[~flag]
        y[:, plain] = y1[:, ~flag]
        t[plain] += dt

        for k in np.flatnonzero(flag):
            i = idx[k]
            s0 = tuple(float(v) for v in y0[:, k])
            s1 = tuple(float(v) for v in y1[:, k])
            ev = _events(s0, s1, dt, eps, turned[i])
            if not ev:  # cannot happen (every flag yields an event); just take the step
                y[:, i] = s1
                t[i] += dt
                continue
            _, kind, lo, hi = min(ev)
            before, after = _substep(s0, lo, eps), _substep(s0, hi, eps)
            q1, p1, q2, p2 = before
            new, tau = after, hi
            if kind == "x1down":
                margin[i] = min(margin[i], abs(q2 - QW2))
                if q2 < QW2:  # right wall
                    new, tau = (q1, -p1, q2, p2), lo
                    impacts[i] += "R"
                    turned[i] = True
                else:
                    crossed[i] = True
            elif kind == "x1up":
                margin[i] = min(margin[i], abs(q2 - QW2))
            elif kind == "x2down":
                margin[i] = min(margin[i], abs(q1 - QW1))
                if q1 < QW1:  # upper wall
                    new, tau = (q1, p1, q2, -p2), lo
                    impacts[i] += "1"
            elif kind == "min1":
                turned[i] = True
                margin[i] = min(margin[i], abs(q1 - QW1))
            elif kind == "min2":
                margin[i] = min(margin[i], _upper_wall_distance(q1, q2))
            elif kind == "max1":
                out[:, i] = before
                t[i] += lo
                done[i] = True
                continue
            y[:, i] = new
            t[i] += tau
            if len(impacts[i]) > max_impacts:
                ok[i], done[i] = False, True
        too_long = (t > MAX_TIME) & ~done
        ok[too_long] = False
        done[too_long] = True

    out[:, ~ok] = np.nan
    theta1, I1 = coordinates(out[2], out[3])
    itinerary = [(imp if imp else ("0" if c else "u")) if good else "?" for imp, c, good in zip(impacts, crossed, ok)]
    return {
        "theta": theta1,
        "I": I1,
        "state": out,
        "time": np.where(ok, t, np.nan),
        "itinerary": itinerary,
        "ok": ok,
        "margin": margin,
        "energy_error": np.abs(hamiltonian(*out, eps) - h0),
    }


def return_map(theta, I, eps, h=H_LEVEL, dt=DT):
    """One return of many points of Sigma_h: (theta1, I1, itineraries)."""
    d = return_map_details(theta, I, eps, h=h, dt=dt)
    return d["theta"], d["I"], d["itinerary"]
