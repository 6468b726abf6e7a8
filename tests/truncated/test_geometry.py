"""Closed-form geometry of the truncated map (sec:truncatedmapnum); its plots are in plot/test_phase_portrait.py.

Oracles: the defining properties of each curve (k_eps1 passes through (L1(K0), K0) and has its
extremum there; K_c is where it touches the corner lines; eq:hovsetsize is the area under it),
the closed forms of the corner-singularity curves, the rotation of the shifted standard map, and
the paper's printed value rho_c = 3.7694...
"""

from __future__ import annotations

import numpy as np
import pytest

import hovering
from conftest import PARAM_SETS, cdiff, make_map
from helpers import numpy_reference as ref

OMEGA_G = 2 * np.pi * (np.sqrt(5.0) - 1.0) / 2  # written out independently of the package


def test_golden_mean_constant():
    assert hovering.OMEGA_G == pytest.approx(OMEGA_G, rel=1e-15)
    assert hovering.OMEGA_G == pytest.approx(3.88322, abs=1e-5)  # printed in the paper


def test_rho_crit_of_the_paper_figure():
    # eq:rhocrit for (eps, Omega0, theta_w, tau0) = (0.3, Omega_G, 3 pi/4, 1): the paper prints
    # rho_c = 3.7694...; 1e-4 is the precision of the printed digits.
    rc = hovering.rho_crit(0.3, 3 * np.pi / 4, OMEGA_G, 1.0)
    assert abs(rc - 3.7694) < 1e-4
    m = make_map(PARAM_SETS["paper_eps+0.3"])
    assert m.rho_crit() == pytest.approx(rc, rel=1e-15)
    assert m.K_crit() == pytest.approx(hovering.K_crit(0.3, 3 * np.pi / 4, OMEGA_G), rel=1e-15)


@pytest.mark.parametrize("eps", [0.3, -0.2, 0.05])
@pytest.mark.parametrize("theta_w", [3 * np.pi / 4, 1.0])
def test_K_crit_is_where_the_leading_curve_meets_the_corner_lines(eps, theta_w):
    # eq:kcrit: k_{eps,1}(phi, rho_1(K_c)) crosses K = 0 at phi_{1,2} = -Omega0/2 -+ theta_w.
    # With tau0 = 0 the half rotation a = Omega0/2 is exact, so the crossing is exact.
    O0 = OMEGA_G
    Kc = hovering.K_crit(eps, theta_w, O0)
    for phi12 in (-O0 / 2 - theta_w, -O0 / 2 + theta_w):
        # |k| <= a few roundings of |K_c| ~ 0.3 (1e-15)
        assert abs(hovering.k_eps1(phi12, Kc, eps, O0, 0.0)) <= 1e-15
    # below zero exactly when eps sin(Omega0/2) > 0 (the curve dips below the tangency)
    assert np.sign(Kc) == -np.sign(eps * np.sin(O0 / 2))


@pytest.mark.parametrize("K0", [-0.4, 0.0, 0.3, 1.1])
@pytest.mark.parametrize("eps", [0.3, -0.3])
@pytest.mark.parametrize("Omega0,tau0", [(OMEGA_G, 1.0), (1.2, -0.7), (5.5, 2.0)])
def test_invariant_curves_pass_through_L1_L2_with_extremum_there(K0, eps, Omega0, tau0):
    a = 0.5 * (Omega0 + tau0 * K0)
    L1 = hovering.L1(K0, Omega0, tau0)
    L2 = hovering.L2(K0, Omega0, tau0)
    # def:L1L2 closed forms, wrapped into [-pi, pi)
    assert -np.pi <= L1 < np.pi and -np.pi <= L2 < np.pi
    assert cdiff(L1, -a) <= 1e-15 and cdiff(L2, np.pi - a) <= 1e-15
    # the curves go through (L1(K0), K0) and (L2(K0), K0): cos(L1 + a) = 1 up to an ulp of L1
    assert hovering.k_eps1(L1, K0, eps, Omega0, tau0) == pytest.approx(K0, abs=1e-14)
    assert hovering.k_eps2(L2, K0, eps, Omega0, tau0) == pytest.approx(K0, abs=1e-14)
    # extremum on L1 (thm:minmaxinvriantcurves): minimum if eps sin(a) > 0, maximum otherwise
    phi = np.linspace(-np.pi, np.pi, 20_001)
    k = hovering.k_eps1(phi, K0, eps, Omega0, tau0)
    i = np.argmin(k) if eps * np.sin(a) > 0 else np.argmax(k)
    assert cdiff(phi[i], L1) <= 2 * np.pi / 20_000  # one grid cell
    # k_eps2 has the opposite extremum on L2
    k2 = hovering.k_eps2(phi, K0, eps, Omega0, tau0)
    i2 = np.argmax(k2) if eps * np.sin(a) > 0 else np.argmin(k2)
    assert cdiff(phi[i2], L2) <= 2 * np.pi / 20_000


def test_rho_crit_is_rho1_at_K_crit_to_second_order():
    # eq:rhocrit: rho_c := rho_1(K_c) = Omega0 + eps tau0 cos(theta_w)/(2 sin(Omega0/2)) + O(eps^2).
    O0, tw, t0 = OMEGA_G, 3 * np.pi / 4, 1.0
    d = []
    for eps in (0.04, 0.02, 0.01):
        Kc = hovering.K_crit(eps, tw, O0)
        d.append(hovering.rho1(Kc, eps, O0, t0) - hovering.rho_crit(eps, tw, O0, t0))
    # second order: halving eps divides the difference by 4 (3.5..4.5 allows the O(eps^3) term)
    assert 3.5 < d[0] / d[1] < 4.5 and 3.5 < d[1] / d[2] < 4.5
    # and rho2 is the mirror: rho2(K, eps) = rho1(K, -eps)
    assert hovering.rho2(0.1, 0.3, O0, t0) == pytest.approx(hovering.rho1(0.1, -0.3, O0, t0), rel=1e-15)


def test_rho1_is_the_rotation_of_the_standard_map_curve():
    # eq:rotationscaled: the invariant circle through (L1(K0), K0), K0 > 0 (J_0u, standard map),
    # rotates by rho_1(K0) + O(eps^2).  Measured over 50,000 steps (finite-time error ~1/n).
    K0 = 0.5
    err = []
    for eps in (0.08, 0.04):
        m = make_map(dict(PARAM_SETS["paper_eps+0.3"], eps=eps))
        res = m.iterate(m.L1(K0), K0, 50_000, record=("rotation",))
        assert res.status[0] == hovering.Status.OK
        err.append(abs(res.rotation[0] - hovering.rho1(K0, eps, m.Omega0, m.tau0)))
    assert err[0] < 0.5 * 0.08**2  # O(eps^2) with a moderate constant ...
    assert 3.0 < err[0] / err[1] < 5.0  # ... and it scales like eps^2


def test_hovering_area_is_the_area_under_the_critical_curve():
    # eq:hovsetsize is the area of {k_{eps,1}(phi, rho_c) <= K < 0, phi in [phi_1, phi_2]}
    # with phi_{1,2} = -Omega0/2 -+ theta_w.  tau0 = 0 makes a = Omega0/2 exact (leading order).
    for eps, tw, O0 in ((0.3, 3 * np.pi / 4, OMEGA_G), (0.1, 1.2, 2.0)):
        Kc = hovering.K_crit(eps, tw, O0)
        phi = np.linspace(-O0 / 2 - tw, -O0 / 2 + tw, 200_001)
        depth = -hovering.k_eps1(phi, Kc, eps, O0, 0.0)
        # trapezoid rule on a smooth integrand: error ~ (2 tw)^3 max|f''| / (12 n^2) < 1e-10
        area = np.sum(0.5 * (depth[1:] + depth[:-1]) * np.diff(phi))
        assert hovering.hovering_area_theory(eps, tw, O0) == pytest.approx(area, abs=1e-9)
        assert area > 0


@pytest.mark.parametrize("eps", [0.1, 0.3, 0.6])
@pytest.mark.parametrize("c", [0.9, -0.9, 0.0, 0.5])
def test_golden_family_has_critical_rotation_omega_G(eps, c):
    Omega0, tw = hovering.golden_family(eps, c)
    # thm:hoveringc: Omega0 = Omega_G - c eps/2, theta_w = arccos((c/tau0) sin(Omega_G/2 - c eps/4))
    assert Omega0 == pytest.approx(OMEGA_G - 0.5 * c * eps, abs=1e-15)
    assert 0 < tw < np.pi
    # cos theta_w = 2 (Omega_G - Omega0) sin(Omega0/2) / (eps tau0)  (proof of thm:hoveringc)
    if c != 0:
        assert np.cos(tw) == pytest.approx(2 * (OMEGA_G - Omega0) * np.sin(Omega0 / 2) / eps, abs=1e-13)
    # The family is built so that eq:rhocrit gives exactly Omega_G (the O(eps^2) of the theorem
    # comes from eq:rhocrit itself): equal up to round-off of O(1) numbers.
    assert hovering.rho_crit(eps, tw, Omega0, 1.0) == pytest.approx(OMEGA_G, abs=1e-13)
    # and rho_1 at K_c stays O(eps^2) away from Omega_G
    Kc = hovering.K_crit(eps, tw, Omega0)
    assert abs(hovering.rho1(Kc, eps, Omega0, 1.0) - OMEGA_G) < eps**2


def test_golden_family_with_other_tau0():
    Omega0, tw = hovering.golden_family(0.2, 1.5, tau0=2.0)
    assert hovering.rho_crit(0.2, tw, Omega0, 2.0) == pytest.approx(OMEGA_G, abs=1e-13)


@pytest.mark.parametrize(
    "args,match",
    [
        ((0.1, 1.0), r"c must satisfy \|c\| < \|tau0\| = 1\.0, got c = 1\.0"),
        ((0.1, -1.0), r"c must satisfy \|c\| < \|tau0\|"),
        ((0.1, 2.5, -2.0), r"c must satisfy \|c\| < \|tau0\| = 2\.0"),
        ((0.1, 0.5, 0.3), r"c must satisfy \|c\| < \|tau0\| = 0\.3"),
        ((np.nan, 0.5), r"eps must be finite"),
        ((0.1, np.inf), r"c must be finite"),
        ((0.1, 0.5, np.nan), r"tau0 must be finite"),
    ],
)
def test_golden_family_rejects_bad_arguments(args, match):
    with pytest.raises(ValueError, match=match):
        hovering.golden_family(*args)


# ------------------------------------------------------------------------------------------------
# corner-singularity curves and arcs


@pytest.mark.parametrize("name", list(PARAM_SETS))
def test_corner_curves_closed_forms(name):
    p = PARAM_SETS[name]
    m = make_map(p)
    lo = m.valid_band()[0]
    K = np.linspace(0.999 * lo, -1e-6, 400)
    cc = m.corner_curves(K)
    s = np.sqrt(-K)
    tw, O0, t0, t1, lam = p["theta_w"], p["Omega0"], p["tau0"], p["tau1"], p["lam"]
    phi01 = tw - O0 / 2 - (t0 + t1) * K / 2 - lam * s
    phi1R = phi01 + 2 * lam * s
    phiR0 = phi1R + 2 * (np.pi - tw) + t1 * K
    # Tolerance 1e-13: the formulas are assembled in another order (a few ulps of |.| < 8)
    for key, ref_val in (("01", phi01), ("1R", phi1R), ("R0", phiR0)):
        assert np.all((cc[key] >= -np.pi) & (cc[key] < np.pi))
        assert cdiff(cc[key], ref_val).max() <= 1e-13
    a = m.arcs(K)
    assert cdiff(a["start_1"], phi01).max() <= 1e-13
    assert np.abs(a["len_1"] - 2 * lam * s).max() <= 1e-13
    assert np.abs(a["len_R"] - (2 * (np.pi - tw) + t1 * K)).max() <= 1e-13
    assert np.abs(a["len_0"] - (2 * tw - t1 * K - 2 * lam * s)).max() <= 1e-13
    assert np.abs(a["len_1"] + a["len_R"] + a["len_0"] - 2 * np.pi).max() <= 1e-13
    # J_0 ends where J_1 starts (eq:Jdeftrunc corrected, PAPER-NOTES typo 1)
    assert cdiff(a["start_0"] + a["len_0"], a["start_1"]).max() <= 1e-13
    # ... and the arcs agree with the independent reference
    r01, rL1, rLR, rL0 = ref.arcs(K, p)
    assert cdiff(a["start_1"], r01).max() <= 1e-13 and np.abs(a["len_0"] - rL0).max() <= 1e-13
    # L1 is the midline of J_0 (def:L1L2): J_0 is centred at -(Omega0 + tau0 K)/2 (mod 2 pi)
    mid0 = a["start_0"] + 0.5 * a["len_0"]
    assert cdiff(mid0, m.L1(K)).max() <= 1e-13
    # above the tangency circle there are no arcs
    up = m.arcs(np.array([0.0, 0.5]))
    assert np.all(np.isnan(up["start_1"])) and np.array_equal(up["len_0"], [2 * np.pi, 2 * np.pi])
    assert np.array_equal(up["len_1"], [0.0, 0.0]) and np.array_equal(up["len_R"], [0.0, 0.0])
    assert np.all(np.isnan(m.corner_curves(np.array([0.0, 0.2]))["01"]))


def test_wrap():
    x = np.array([-np.pi, np.pi, 3 * np.pi, -3 * np.pi, 0.0, 7.0, -7.0, 1e3])
    w = hovering.wrap(x)
    assert np.all((w >= -np.pi) & (w < np.pi))
    # wrap(x) - x is a multiple of 2 pi (to rounding of |x| <= 1e3: 1e-12)
    k = (w - x) / (2 * np.pi)
    assert np.abs(k - np.round(k)).max() <= 1e-12
    assert isinstance(hovering.wrap(1.0), float)
