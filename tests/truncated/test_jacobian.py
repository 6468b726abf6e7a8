"""The truncated map's exact Jacobian (``m.jacobian``) and the product along orbits
(``iterate(record=("jacobian",))``), for TruncatedMap and TruncatedFamily.

Oracles: central differences with their own error bound (tests/helpers/tangent.py: truncation
estimated from two steps, noise = rounding / h), the standard map's closed-form Jacobian on J_0u and
J_0 (converse_kam's), det J = 1, and the explicit product of the steps' Jacobians.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import hovering as hv
from helpers import tangent as fd

H = 1e-6  # step of the central differences: truncation ~1e-12 |F'''|, rounding 1e-15 / 1e-6


@st.composite
def maps(draw):
    """A random member of the family: F_eps's six parameters, or a TruncatedFamily splined from it
    with a random odd forcing of up to three modes."""
    m = hv.TruncatedMap(
        eps=draw(st.floats(-0.9, 0.9)),
        Omega0=draw(st.floats(-12.0, 12.0)),
        theta_w=draw(st.floats(0.3, 2.8)),
        tau0=draw(st.floats(-2.0, 2.0)),
        tau1=draw(st.floats(-1.0, 1.0)),
        lam=draw(st.floats(0.1, 1.5)),
    )
    if draw(st.booleans()):
        lo = max(m.valid_band()[0], -1.0)
        K = np.concatenate([-np.linspace(0, -0.999 * lo, 40)[::-1], np.linspace(0.02, 1.0, 30)])
        b = [1.0] + [draw(st.floats(-0.5, 0.5)) for _ in range(draw(st.integers(0, 2)))]
        m = hv.TruncatedFamily.from_map(m, K, forcing=b)
    return m


def _points(m, rng, n):
    lo, hi = m.valid_band()
    lo, hi = max(lo, -1.0) * 0.98, min(hi, 1.0) * 0.98
    return rng.uniform(-np.pi, np.pi, n), rng.uniform(lo, hi, n)


@settings(max_examples=25, deadline=None)
@given(maps(), st.integers(0, 2**32 - 1))
def test_the_jacobian_is_the_derivative_of_the_step(m, seed):
    rng = np.random.default_rng(seed)
    phi, K = _points(m, rng, 40)
    t = m.jacobian(phi, K)
    # the image is step()'s, bit for bit
    p1, k1 = m.step(phi, K)
    assert np.array_equal(t.phi, p1) and np.array_equal(t.K, k1)
    # rounding of one step: a few ulps of |phi| + |omega| in phi, of |K| + |eps| in K
    delta = 1e-14 * (1 + abs(getattr(m, "Omega0", 10.0)) + np.abs(K).max())
    checked = 0
    for i in range(phi.size):
        P, Q = fd.stencil(phi[i], K[i], H)
        if np.any(Q <= m.valid_band()[0]) or not np.all(m.region(P, Q) == t.region[i]):
            continue  # the stencil leaves the point's arc: no derivative across a corner curve
        ip, ik = m.step(P, Q)
        Dh, D2h = fd.differences(ip, ik, H)
        err = np.abs(Dh - t.J[i])
        assert np.all(err <= 2 * fd.bound(Dh, D2h, delta, H)), (m, phi[i], K[i], t.J[i], Dh)
        checked += 1
    assert checked >= 20
    # area preservation: det J = 1 + g w - g w, to the rounding of g w
    scale = 1 + np.abs(t.J[:, 1, 0] * t.J[:, 0, 1])
    assert np.all(np.abs(t.det - 1) <= 4e-16 * scale)


def test_on_the_no_impact_regions_it_is_the_standard_maps():
    # J_0u and J_0: phibar = phi + Omega0 + tau0 K, Kbar = K + eps sin(phibar) (converse_kam's form)
    m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=3 * np.pi / 4, tau0=1.3)
    rng = np.random.default_rng(1)
    phi, K = rng.uniform(-np.pi, np.pi, 500), rng.uniform(-0.3, 0.5, 500)
    t = m.jacobian(phi, K)
    smooth = np.isin(t.region, [hv.Region.BESIDE, hv.Region.ABOVE])
    c = 0.3 * np.cos(t.phi[smooth])
    expect = np.stack([np.ones_like(c), np.full_like(c, 1.3), c, 1 + 1.3 * c], axis=-1).reshape(-1, 2, 2)
    assert smooth.sum() > 200
    # The first row (1, tau0) is exact. The second holds eps cos(phibar): the core's cos and NumPy's
    # are different implementations (numpy 1.23's differed from the core's in the last bit where
    # numpy 2's agreed), each within an ulp, so the entries (|.| <= 1.4) agree to two ulps of 1.
    assert np.array_equal(t.J[smooth][:, 0], expect[:, 0])
    assert np.all(np.abs(t.J[smooth][:, 1] - expect[:, 1]) <= 2 * np.finfo(float).eps)
    # J_R: the slope of omega_R = Omega0 + tau0 K - 2 lam sqrt(-K) is tau0 + lam / sqrt(-K)
    right = t.region == hv.Region.RIGHT
    assert right.sum() > 20
    assert np.allclose(t.J[right, 0, 1], 1.3 + 0.5 / np.sqrt(-K[right]), rtol=1e-15, atol=0)


def test_arc_starts_are_corners_with_the_one_sided_derivative():
    m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=3 * np.pi / 4)
    K = np.full(3, -0.2)
    starts = np.array(list(m.corner_curves(K[:1]).values())).ravel()
    t = m.jacobian(starts, K)
    assert np.all(t.status == hv.Status.CORNER)
    # the arc that owns the start gives the derivative (1R is J_R's start: its slope has lam/sqrt(-K))
    assert t.region.tolist() == [hv.Region.UPPER, hv.Region.RIGHT, hv.Region.ABOVE]
    assert np.all(np.isfinite(t.J))
    inside = m.jacobian(starts + 1e-9, K)
    assert np.all(inside.status == hv.Status.OK)


def test_scalar_and_array_results_and_bad_input():
    m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=3 * np.pi / 4)
    t = m.jacobian(0.3, -0.2)
    assert t.J.shape == (2, 2) and isinstance(t.phi, float) and t.status == hv.Status.OK
    t2 = m.jacobian(np.zeros((3, 2)), -0.1)
    assert t2.J.shape == (3, 2, 2, 2) and t2.status.shape == (3, 2)
    with pytest.raises(ValueError, match="outside the band"):
        m.jacobian(0.0, -10.0)
    with pytest.raises(ValueError, match="jacobian: phi"):
        m.jacobian(np.nan, 0.0)


@pytest.mark.parametrize("kernel", ["simd", "scalar"])
def test_the_recorded_product_is_the_product_and_leaves_the_orbit_alone(kernel):
    m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=3 * np.pi / 4)
    K0 = np.linspace(-0.3, 0.3, 40)
    phi0 = m.L1(K0) + 0.1
    r = m.iterate(phi0, K0, 60, record=("orbit", "jacobian"), kernel=kernel)
    plain = m.iterate(phi0, K0, 60, record=("orbit",), kernel=kernel)
    assert np.array_equal(r.phi, plain.phi) and np.array_equal(r.K, plain.K)
    M = np.broadcast_to(np.eye(2), (40, 2, 2)).copy()
    for n in range(60):
        M = m.jacobian(r.phi[:, n], r.K[:, n]).J @ M
    P = r.jacobian()
    scale = np.abs(M).max(axis=(1, 2))
    assert np.all(np.abs(P - M).max(axis=(1, 2)) <= 1e-12 * scale)
    # det = 1 for every factor: L1 + L2 = 0 to the rounding of the logs
    assert np.all(np.abs(r.jacobian_log.sum(axis=1)) < 1e-11)
    assert np.all(r.jacobian_status == hv.Status.OK)
    # Q is a rotation
    q = r.jacobian_q
    assert np.allclose(np.einsum("nji,njk->nik", q, q), np.eye(2), atol=1e-14)


def test_the_product_is_kept_finite_on_long_chaotic_orbits_and_both_kernels_agree():
    # eps = -0.6: the impact zone's chaotic layer (K0 in [-0.26, -0.06]: L1 / n ~ 0.17, so the
    # product itself would overflow after ~4,000 steps)
    m = hv.TruncatedMap(eps=-0.6, Omega0=hv.OMEGA_G, theta_w=3 * np.pi / 4)
    K0 = np.linspace(-0.25, -0.1, 8)
    a = m.iterate(0.1, K0, 20_000, record=("jacobian",), kernel="simd")
    b = m.iterate(0.1, K0, 20_000, record=("jacobian",), kernel="scalar")
    assert np.all(a.status == hv.Status.OK) and np.all(b.status == hv.Status.OK)
    assert np.all(a.jacobian_log[:, 0] / 20_000 > 0.1)
    assert np.all(np.isfinite(a.jacobian_log)) and np.all(np.isfinite(a.jacobian_r12))
    assert np.all(np.abs(a.jacobian_log.sum(axis=1)) < 1e-8 * a.jacobian_log[:, 0])
    # the kernels' orbits part after ~100 steps (the sin's ulps, amplified; one may stick to an
    # island for a while): the layer's exponent, as a median over the orbits, is the same
    assert abs(np.median(a.jacobian_log[:, 0]) - np.median(b.jacobian_log[:, 0])) / 20_000 < 0.02


def test_a_step_from_an_arc_start_marks_the_product():
    m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=3 * np.pi / 4)
    s = m.corner_curves(np.array([-0.2]))["1R"]
    for kernel in ("simd", "scalar"):
        r = m.iterate(s, -0.2, 5, record=("jacobian",), kernel=kernel)
        assert r.jacobian_status[0] == hv.Status.CORNER
        r = m.iterate(s + 1e-9, -0.2, 5, record=("jacobian",), kernel=kernel)
        assert r.jacobian_status[0] == hv.Status.OK


def test_the_record_does_not_thin_with_every():
    m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=3 * np.pi / 4)
    a = m.iterate(0.2, -0.1, 100, record=("jacobian",), every=7)
    b = m.iterate(0.2, -0.1, 100, record=("jacobian",))
    assert np.array_equal(a.jacobian_log, b.jacobian_log) and np.array_equal(a.jacobian_q, b.jacobian_q)
    with pytest.raises(ValueError, match="no jacobian was recorded"):
        m.iterate(0.2, -0.1, 10).jacobian()
