"""Rotation numbers, hovering-set area and critical curves (issue 3) against theory and an
independent brute-force count built on the NumPy reference."""

from __future__ import annotations

import math

import numpy as np
import pytest

import hovering
from conftest import PAPER  # hovering.paper.FIGURE
from helpers import numpy_reference as ref
from hovering.analysis import birkhoff_average, birkhoff_weights, regularity, rotation_number


def paper_map(eps):
    return hovering.TruncatedMap(eps=eps, **PAPER)


# ------------------------------------------------------------------------------------------------
# Birkhoff averages and rotation numbers


def test_birkhoff_weights_normalised_and_flat_ends():
    w = birkhoff_weights(1000)
    assert abs(w.sum() - 1) < 1e-14
    assert w[0] < 1e-100 and w[-1] < 1e-100  # vanishes to all orders at the ends
    assert np.argmax(w) in (499, 500)


def test_birkhoff_average_is_exact_on_a_pure_rotation():
    # f(x) = cos(x) along x_n = x_0 + n alpha, golden alpha: the mean over the circle is 0. The
    # plain average errs by O(1/N) ~ 1e-4; the weighted one converges super-polynomially: < 1e-10
    # at N = 5000 (Das-Sander-Yorke report ~1e-14 at a few thousand for Diophantine rotations).
    alpha = hovering.OMEGA_G
    n = np.arange(5000)
    f = np.cos(0.3 + n * alpha)
    assert abs(f.mean()) > 1e-5
    assert abs(birkhoff_average(f)) < 1e-10


def test_rotation_number_is_exact_on_rigid_rotations():
    # eps = 0, K >= 0: every step rotates by Omega0 + tau0 K exactly; both methods return it to
    # rounding (1e-12: a weighted sum of 4000 equal numbers).
    m = paper_map(0.0)
    K0 = np.array([0.0, 0.1, 0.5, 1.3])
    res = m.iterate(m.L1(K0), K0, 4000, record=("orbit", "rotation"))
    want = m.Omega0 + m.tau0 * K0
    assert np.abs(rotation_number(res, "birkhoff") - want).max() < 1e-12
    assert np.abs(rotation_number(res, "mean") - want).max() < 1e-12


def test_birkhoff_rotation_beats_the_mean_on_an_invariant_curve():
    # On a KAM curve of the shifted standard map (eps = 0.3, far above the step) the Birkhoff
    # rotation over N and over 2N steps agree to ~1e-12, the plain means only to ~1/N.
    m = paper_map(0.3)
    K0 = np.array([0.6])
    a = m.iterate(m.L1(K0), K0, 4000, record=("orbit", "rotation"))
    b = m.iterate(m.L1(K0), K0, 8000, record=("orbit", "rotation"))
    dw = abs(rotation_number(a, "birkhoff")[0] - rotation_number(b, "birkhoff")[0])
    dm = abs(rotation_number(a, "mean")[0] - rotation_number(b, "mean")[0])
    assert dw < 1e-10
    assert dm > 100 * dw


def test_regularity_separates_curves_from_chaos():
    # Independent classification: two starts 1e-10 apart separate to O(1) on a chaotic orbit, but
    # only linearly (<~ 1e-10 x 2e4 steps x twist ~ 1e-5) on an invariant curve or island. The
    # regularity digits must agree: > 10 for the regular ones, < 6 for the chaotic ones.
    starts = [(0.3, K) for K in (0.3, 0.45, 0.6, -0.2)] + [(-0.3, K) for K in np.linspace(-0.2, -0.8, 7)]
    regular, chaotic = [], []
    for eps, K0 in starts:
        m = paper_map(eps)
        res = m.iterate([m.L1(K0), m.L1(K0) + 1e-10], [K0, K0], 20_000, record=("orbit",))
        d = np.abs(hovering.wrap(res.phi[0] - res.phi[1])) + np.abs(res.K[0] - res.K[1])
        dig = regularity(res)[0]
        if d.max() > 1e-2:
            chaotic.append(dig)
        elif d.max() < 1e-4:
            regular.append(dig)
    assert len(regular) >= 3 and len(chaotic) >= 2, (regular, chaotic)
    assert min(regular) > 10, regular
    assert max(chaotic) < 6, chaotic


def test_rotation_number_needs_recorded_orbit():
    m = paper_map(0.3)
    res = m.iterate([0.0], [0.1], 10, record=("rotation",))
    assert rotation_number(res, "mean")[0] == res.rotation[0]
    with pytest.raises(ValueError, match="record=\\('orbit'"):
        rotation_number(res, "birkhoff")
    with pytest.raises(ValueError, match="method must be 'mean' or 'birkhoff'"):
        rotation_number(res, "median")


# ------------------------------------------------------------------------------------------------
# Hovering set


def brute_force_area(p, n_steps, n_phi, n_K, K_low):
    """|HOV| on a plain lattice of cell centres, iterating the independent NumPy reference."""
    phi = -np.pi + (np.arange(n_phi) + 0.5) * (2 * np.pi / n_phi)
    K = K_low + (np.arange(n_K) + 0.5) * (-K_low / n_K)
    phi, K = (a.ravel() for a in np.meshgrid(phi, K, indexing="ij"))

    def never_impacts(pp):
        x, k = phi.copy(), K.copy()
        alive = np.ones(phi.size, bool)
        for _ in range(n_steps):
            idx = np.flatnonzero(alive)
            if idx.size == 0:
                break
            r = ref.region(x[idx], k[idx], pp)
            # an impact, or (region -1) a point outside the band: either way not "never impacts"
            hit = (r == ref.UPPER) | (r == ref.RIGHT) | (r < 0)
            alive[idx[hit]] = False
            go = idx[~hit]
            x[go], k[go] = ref.step(x[go], k[go], pp)
        return alive

    p0 = dict(p, eps=0.0)
    hov = (~never_impacts(p0)) & never_impacts(p)
    frac = hov.mean()
    box = 2 * np.pi * (-K_low)
    return box * frac, box * math.sqrt(max(frac * (1 - frac), 1 / hov.size) / hov.size)


@pytest.mark.parametrize("eps", [0.1, 0.2])
def test_hovering_area_matches_brute_force_and_theory(eps):
    m = paper_map(eps)
    p = dict(PAPER, eps=eps)
    K_low = -2 * eps / math.sin(PAPER["Omega0"] / 2)
    hv = hovering.hovering_area(m, n_steps=2000, n_samples=40_000, K_low=K_low, rng=1)
    bf, bf_sigma = brute_force_area(p, 2000, 160, 40, K_low)
    # Two independent estimates of one area (different point sets, different implementations):
    # they differ by sampling noise only; 3 combined standard deviations + both iteration errors.
    tol = 3 * math.hypot(hv.sampling_error, bf_sigma) + hv.iteration_error
    assert abs(hv.area - bf) <= tol, (hv, bf, tol)
    # eq:hovsetsize is leading order: |area - theory| = O(eps^2). Measured C ~ 0.3 at eps 0.1 and
    # 0.2 (deviation 0.003 and 0.011); C = 1 is a bound that a wrong area (e.g. missing J_0 points,
    # or a factor 2 in the box) would break.
    assert abs(hv.area - hv.theory) <= 1.0 * eps**2 + hv.error
    assert hv.impact_fraction_F0 > 0.99  # under F_0 nearly every point of J_0 impacts


@pytest.mark.parametrize("eps", [-0.1, -0.2])
def test_hovering_set_is_empty_for_negative_eps(eps):
    hv = hovering.hovering_area(paper_map(eps), n_steps=4000, n_samples=40_000)
    assert hv.area == 0.0 and hv.theory == 0.0


def test_hovering_area_grows_monotonically_in_eps():
    eps = [0.05, 0.1, 0.15, 0.2, 0.25, 0.3]
    hv = [hovering.hovering_area(paper_map(e), n_steps=4000, n_samples=40_000, K_low=-0.7) for e in eps]
    areas = np.array([h.area for h in hv])
    errs = np.array([h.error for h in hv])
    # Each increment exceeds the combined errors of its two ends (increments ~0.12 vs errors ~0.02).
    assert np.all(np.diff(areas) > errs[1:] + errs[:-1])


def test_hovering_area_reports_errors_and_validates():
    m = paper_map(0.2)
    hv = hovering.hovering_area(m, n_steps=400, n_samples=2000, keep_points=True)
    n4, n2, n1 = sorted(hv.areas)
    assert hv.areas[n4] >= hv.areas[n2] >= hv.areas[n1] == hv.area  # estimates only fall with N
    assert hv.error == pytest.approx(2 * hv.sampling_error + hv.iteration_error)
    assert hv.hovering.sum() / hv.n_samples * 2 * np.pi * -hv.box[2] == pytest.approx(hv.area)
    with pytest.raises(ValueError, match="K_low must lie in the band below 0"):
        hovering.hovering_area(m, K_low=0.1)
    with pytest.raises(ValueError, match=r"n_steps must be an integer in \[4, "):
        hovering.hovering_area(m, n_steps=2)


# ------------------------------------------------------------------------------------------------
# Critical curves


def test_critical_curve_at_paper_parameters():
    # eq:rhocrit predicts rho_c = 3.7694 at eps = 0.3; the paper measures 3.79 for the orbit
    # started at K~_c. The issue asks for agreement to 0.03.
    m = paper_map(0.3)
    cc = hovering.critical_curve(m, n_steps=20_000)
    assert abs(cc.rotation - cc.rotation_pred) < 0.03
    assert abs(cc.rotation_pred - 3.7694) < 1e-4
    # Its lowest point is near K~_c (eq:kcrit, O(eps^2) = 0.09 away at most) and on L1 (the start).
    assert abs(cc.K_min - cc.K_pred) < 0.09
    assert cc.K_min == pytest.approx(cc.K0, abs=1e-3)
    # The curve stays in J_0 u J_0u: re-iterate it with an exit watch.
    res = m.iterate([m.L1(cc.K0)], [cc.K0], 20_000, record=(), exit_regions={"0u", "0"})
    assert res.exit_step[0] == -1
    # Just below the bracket the orbit impacts or is not regular.
    assert cc.K_fail < cc.K0


def test_golden_family_critical_rotation_and_monotone_area():
    # thm:hoveringc: the critical rotation is O(eps^2)-close to Omega_G, and |HOV| is monotone in c.
    devs, areas = {}, {}
    for eps in (0.15, 0.3):
        for c in (-0.9, 0.0, 0.9):
            m = hovering.TruncatedMap(eps, *hovering.golden_family(eps, c))
            devs[eps, c] = abs(hovering.critical_curve(m, n_steps=20_000).rotation - hovering.OMEGA_G)
            if eps == 0.3:
                areas[c] = hovering.hovering_area(m, n_steps=3000, n_samples=30_000).area
    # Measured deviations <= 0.0024 at eps 0.15 and <= 0.0098 at 0.3; bound 0.15 eps^2.
    for (eps, c), d in devs.items():
        assert d < 0.15 * eps**2, (eps, c, d)
    assert areas[-0.9] > areas[0.0] > areas[0.9] > 0


def test_lowest_curve_above_the_step_for_both_signs():
    # k^{u0}: the lowest curve in K >= 0. For eps > 0 its minimum is near L1, for eps < 0 near L2,
    # and F_eps(phi, K) = F_{-eps}(phi + pi, K) above the step makes the two mirror images:
    # equal rotation numbers (paper, before thm:hoveringc).
    up = hovering.critical_curve(paper_map(0.3), n_steps=20_000, regions=("0u",), K_range=(1e-6, 0.5), line="L1")
    dn = hovering.critical_curve(paper_map(-0.3), n_steps=20_000, regions=("0u",), K_range=(1e-6, 0.5), line="L2")
    assert up.K_min >= 0 and dn.K_min >= 0
    assert abs(up.rotation - dn.rotation) < 1e-3
    with pytest.raises(RuntimeError, match="no invariant curve"):
        hovering.critical_curve(paper_map(0.3), n_steps=2000, K_range=(-0.6, -0.5), n_grid=4)


def test_critical_curve_is_a_rotational_curve_not_an_island():
    # At eps = 0.92 on the golden family (c = -0.9) a period-3 island chain lies in J_0 far below
    # K = 0 (K ~ -2.7): regular and non-impacting, but not a rotational invariant curve. The
    # search over the whole band must not return it: the critical orbit fills the circle.
    from hovering.analysis import max_angular_gap

    m = hovering.TruncatedMap(0.92, *hovering.golden_family(0.92, -0.9))
    lo = m.valid_band()[0]
    cc = hovering.critical_curve(m, n_steps=20_000, K_range=(lo * 0.999, 0.5))
    assert cc.K_min > -1.5
    assert max_angular_gap(cc.phi) < 20 * 2 * np.pi / 20_000
    island = m.iterate([m.L1(-2.73)], [-2.73], 6000, record=("orbit",))
    assert max_angular_gap(island.phi[0]) > 0.5  # islands leave large gaps: the criterion can fail
    assert abs(max_angular_gap([0.0, 1.0, 2.0]) - (2 * np.pi - 2.0)) < 1e-15
