"""Arc lengths measured from the impact flow settle typo 2 of PAPER-NOTES (sign of tau1 K)."""

from __future__ import annotations

import numpy as np

import hovering
from hovering import paper


def _measure_arcs(sec, I, n=720):
    """|J_R| and |J_1| on the circle I (eps = 0): itinerary boundaries by bisection in theta."""

    def itin(th):
        return sec.return_map(np.atleast_1d(th), np.full(np.size(th), I), rtol=1e-12, atol=1e-14).itinerary

    def boundary(a, b):
        first = itin(a)[0]
        for _ in range(45):  # 2 pi / 720 / 2^45: far below the 1e-8 differences tested
            m = 0.5 * (a + b)
            a, b = (m, b) if itin(m)[0] == first else (a, m)
        return 0.5 * (a + b)

    th = np.linspace(-np.pi, np.pi, n + 1)[:-1]
    it = itin(th)
    bds = {}
    for k in range(n):
        a, b = it[k], it[(k + 1) % n]
        if a != b:
            bds[(a, b)] = boundary(th[k], th[(k + 1) % n] + (2 * np.pi if k + 1 == n else 0.0))
    gap = lambda x, y: (y - x) % (2 * np.pi)  # noqa: E731
    return gap(bds[("1", "R")], bds[("R", "0")]), gap(bds[("0", "1")], bds[("1", "R")])


def test_arc_lengths_from_the_flow_fix_the_sign_of_tau1():
    # thm:cornersing prints |J_R| = 2(pi - theta_w) - tau1 K, the truncated map uses + tau1 K.
    # Measured on circles K = I - I_tan < 0 of the eps = 0 step flow: + holds, to O(K^2)
    # (measured deviation ~10 K^2), while - is off by 2 tau1 |K|. |J_1| = 2 lam sqrt(-K) to
    # relative O(|K|) (measured 1.4 |K|). Both use onset parameters from the definitions.
    sys = paper.system(0.0)
    sec = hovering.Section(sys, 1.0)
    p = hovering.onset_parameters(sys, 1.0)
    for K in (-4e-4, -4e-3, -1e-2):
        JR, J1 = _measure_arcs(sec, p.I_tan + K)
        plus = 2 * (np.pi - p.theta_w) + p.tau1 * K
        minus = 2 * (np.pi - p.theta_w) - p.tau1 * K
        assert abs(JR - plus) < 20 * K**2, (K, JR, plus)
        assert abs(JR - minus) > 1.5 * p.tau1 * abs(K), (K, JR, minus)
        assert abs(J1 / (2 * p.lam * np.sqrt(-K)) - 1) < 3 * abs(K), (K, J1)
