"""One return of the linear flow (Harmonic x Harmonic, bilinear coupling eps q1 q2) in closed form at
mpmath precision: the exact reference of the error floor (tests/flow/test_default_stepper.py,
benchmarks/bench_error_floor.py).

The flow is q'' = -K q, K = [[w1^2, eps], [eps, w2^2]], through its normal modes; every event (the
section crossing p1 = 0 downward once armed, a wall crossing, a wall distance's minimum dipping below
zero) is a root of the closed form refined by findroot at the working precision (40 digits), and a
reflection sets the wall coordinate and negates its momentum exactly. Walls at (QW1, QW2).
"""

from __future__ import annotations

import mpmath as mp

QW1, QW2 = -1.0, -0.5


class LinearFlow:
    """q'' = -K q in closed form at mpmath precision (K symmetric positive definite)."""

    def __init__(self, w1, w2, eps, dps=40):
        self.dps = dps
        with mp.workdps(dps):  # the modes at the working precision, not mpmath's global one
            K = mp.matrix([[mp.mpf(w1) ** 2, mp.mpf(eps)], [mp.mpf(eps), mp.mpf(w2) ** 2]])
            lam, U = mp.eigsy(K)
            assert min(lam) > 0, "the linear flow must be oscillatory"
            self.U = U
            self.om = [mp.sqrt(lam[k]) for k in range(2)]

    def at(self, z, tau):
        """The state tau after z (a list of 4 mpf)."""
        U, om = self.U, self.om
        a = [U[0, k] * z[0] + U[1, k] * z[2] for k in range(2)]
        b = [U[0, k] * z[1] + U[1, k] * z[3] for k in range(2)]
        c = [mp.cos(om[k] * tau) for k in range(2)]
        s = [mp.sin(om[k] * tau) for k in range(2)]
        at = [a[k] * c[k] + b[k] / om[k] * s[k] for k in range(2)]
        bt = [-a[k] * om[k] * s[k] + b[k] * c[k] for k in range(2)]
        return [
            U[0, 0] * at[0] + U[0, 1] * at[1],
            U[0, 0] * bt[0] + U[0, 1] * bt[1],
            U[1, 0] * at[0] + U[1, 1] * at[1],
            U[1, 0] * bt[0] + U[1, 1] * bt[1],
        ]

    def ret(self, z0, geometry, dt="0.05"):
        """One return to Sigma_h from z0: (state, time, itinerary; "none" without impact)."""
        with mp.workdps(self.dps):
            return self._ret(z0, geometry, mp.mpf(dt))

    def _ret(self, z0, geometry, dt):
        z = [mp.mpf(float(x)) for x in z0]
        t, armed, itinerary = mp.mpf(0), False, ""
        walls = geometry != "none"

        def root(z, j, off, lo, hi):
            return mp.findroot(lambda tau: self.at(z, tau)[j] - off, (lo, hi), solver="anderson")

        for _ in range(100000):
            z1 = self.at(z, dt)
            events = []
            for j, off, kind, on in ((0, QW1, "R", walls), (2, QW2, "U", geometry == "step")):
                if not on:
                    continue
                if z[j] > off and z1[j] <= off:
                    events.append((root(z, j, off, 0, dt), kind))
                elif z[j] > off and z1[j] > off and z[j + 1] < 0 and z1[j + 1] > 0:  # a minimum may dip through
                    tm = mp.findroot(lambda tau: self.at(z, tau)[j + 1], (0, dt), solver="anderson")
                    if self.at(z, tm)[j] < off:
                        events.append((root(z, j, off, 0, tm), kind))
            if z[1] < 0 and z1[1] >= 0:  # q1's minimum: the next downward crossing of p1 = 0 returns
                armed = True
            if armed and z[1] > 0 and z1[1] <= 0:
                events.append((root(z, 1, 0, 0, dt), "section"))
            handled = False
            for tau, kind in sorted(events, key=lambda e: e[0]):
                ze = self.at(z, tau)
                if kind == "section":
                    return ze, t + tau, itinerary or "none"
                if kind == "R":
                    hit = geometry == "wall" or ze[2] < QW2
                    j = 0
                else:
                    hit = ze[0] < QW1
                    j = 2
                if not hit:
                    continue
                ze[j] = mp.mpf(QW1 if kind == "R" else QW2)
                ze[j + 1] = -ze[j + 1]
                itinerary += "R" if kind == "R" else "1"
                z, t, armed, handled = ze, t + tau, True, True
                break
            if not handled:
                z, t = z1, t + dt
        raise AssertionError("no return")


def wrap(x):
    """x in [-pi, pi) modulo 2 pi."""
    return x - 2 * mp.pi * mp.nint(x / (2 * mp.pi))


def theta_I(w2, q2, p2):
    """(theta, I) of Harmonic(w2) at (q2, p2), at mpmath precision: the core's convention
    (theta in [-pi, pi), sign(theta) = -sign(p2)): q2 = sqrt(2 I / w2) cos(theta)."""
    w2 = mp.mpf(w2)
    I = (p2**2 + w2**2 * q2**2) / (2 * w2)
    return mp.atan2(-p2 / w2, q2), I
