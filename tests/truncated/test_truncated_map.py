"""Single steps of the truncated map F_eps (eq:truncatedmap, corrected as in PAPER-NOTES.md).

Oracles: the reversibility lemma (lem:truncreturnmap), area preservation, the symmetries and the
rescaling of sec:truncatedmapnum, exact solutions (standard map for K >= 0, interval exchange for
eps = 0) and the independent NumPy implementation tests/helpers/numpy_reference.py.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import hovering
from conftest import (
    LOCAL_ROUNDOFF,
    PARAM_SETS,
    band_sample,
    cdiff,
    error_bound,
    make_map,
    safe_mask,
)
from helpers import numpy_reference as ref

N_POINTS = 100_000
#: Points closer than this to an arc end (or to K = 0, or to the band floor) are excluded: there
#: the two sides of a discontinuity are legitimately assigned differently by round-off.
BOUNDARY = 1e-9


# ------------------------------------------------------------------------------------------------
# 1. Reversibility and inverse


def test_reversibility_and_inverse(any_map, rng):
    m = any_map
    p = m.params
    eps = p["eps"]
    # K >= lo + |eps| + margin keeps the preimage height K - eps sin(phi) (= height of R(x)) in the band
    phi, K = band_sample(m, N_POINTS, rng, K_hi=1.5, margin=abs(eps) + 1e-6)
    pr, Kr = ref.reversal(phi, K, p)
    # F is evaluated at x (forward) and at R(x) (which is where F^{-1}(x) is classified); the arcs
    # map isometrically onto the reflected arcs, so F^{-1}(x) is as far from an arc end as R(x).
    ok = safe_mask(m, phi, K, BOUNDARY) & safe_mask(m, pr, Kr, BOUNDARY)
    assert ok.mean() > 0.99  # the excluded set has measure ~1e-8; nearly all points are tested
    phi, K = phi[ok], K[ok]

    # R F R = F^{-1}
    a, b = m.reversal(phi, K)
    a, b = m.step(a, b)
    a, b = m.reversal(a, b)
    c, d = m.step_inverse(phi, K)
    # Tolerance 1e-12: each side is 2-3 roundings of quantities |.| < 16 (<= ~1e-14 each, see
    # LOCAL_ROUNDOFF); 1e-12 leaves a factor ~30 and is still 10^3 below any arc-misassignment.
    assert cdiff(a, c).max() <= 1e-12
    assert np.abs(b - d).max() <= 1e-12

    # F(F^{-1}(x)) = x   (same 1e-12 budget: two steps of round-off)
    e, f = m.step(c, d)
    assert cdiff(e, phi).max() <= 1e-12
    assert np.abs(f - K).max() <= 1e-12

    # F^{-1}(F(x)) = x
    g, h = m.step(phi, K)
    gi, hi = m.step_inverse(g, h)
    assert cdiff(gi, phi).max() <= 1e-12
    assert np.abs(hi - K).max() <= 1e-12

    # The test visits every region of the band.
    regs = set(np.unique(m.region(phi, K)).tolist())
    assert regs == {0, 1, 2, 3}


def test_reversal_is_an_involution(any_map, rng):
    m = any_map
    phi, K = band_sample(m, 10_000, rng, margin=abs(m.eps) * 2 + 1e-3)
    a, b = m.reversal(*m.reversal(phi, K))
    # R(R(phi,K)) = (phi, K - eps sin(phi) - eps sin(-phi)): exact up to 2 roundings of K (|K| < 4)
    assert cdiff(a, phi).max() <= 1e-15
    assert np.abs(b - K).max() <= 4e-15


# ------------------------------------------------------------------------------------------------
# 2. Area preservation


def _third_derivative_bounds(K, reg, p, h):
    """Bounds on |d^3 F / d phi^3| and |d^3 F / dK^3| over [x-h, x+h] (both components)."""
    eps, lam, tau0 = abs(p["eps"]), p["lam"], p["tau0"]
    # smallest s on the stencil (K + h < 0 for the K < -0.05 used); unused (1.0) for K >= 0
    s = np.where(K < 0, np.sqrt(np.abs(K + h)), 1.0)
    right = reg == ref.RIGHT
    w1 = np.abs(tau0) + np.abs(p["tau1"]) + np.where(right, lam / s, 0.0)  # |omega'|
    w2 = np.where(right, lam / (2 * s**3), 0.0)  # |omega''| (only J_R has the sqrt(-K) rotation)
    w3 = np.where(right, 3 * lam / (4 * s**5), 0.0)  # |omega'''|
    d3_phi = np.full_like(K, eps)  # phi-component linear in phi; K-component eps sin(phi + ...)
    d3_K = np.maximum(w3, eps * (w1**3 + 3 * w1 * w2 + w3))  # chain rule for eps sin(phi + omega(K))
    return np.maximum(d3_phi, d3_K), w1


@pytest.mark.parametrize("name", ["paper_eps+0.3", "paper_eps+0.92", "tau1_negative"])
def test_area_preservation(name, rng):
    m = make_map(PARAM_SETS[name])
    p = m.params
    h = 1e-5  # FD step: balances h^2 truncation against round-off / h
    n = 20_000
    phi = rng.uniform(-np.pi, np.pi, n)
    # K < -0.05 keeps d omega_R / dK = tau0 + lam / sqrt(-K) (and its derivatives) moderate.
    K = np.concatenate([rng.uniform(-1.5, -0.05, 3 * n // 4), rng.uniform(0.05, 1.0, n - 3 * n // 4)])
    # The arc ends move by |d phi_01 / dK| h < 3h when K moves by h: 1e-3 >> h keeps every stencil
    # point in one arc.
    keep = ref.boundary_distance(phi, K, p) > 1e-3
    phi, K = phi[keep], K[keep]
    reg = ref.region(phi, K, p)
    for r in (ref.BESIDE, ref.ABOVE, ref.UPPER, ref.RIGHT):
        assert np.count_nonzero(reg == r) >= 200, f"region {r} under-sampled"

    def F(a, b):
        return m.step(ref.wrap(a), b)

    pp, kp = F(phi + h, K)
    pm, km = F(phi - h, K)
    qp, lp = F(phi, K + h)
    qm, lm = F(phi, K - h)
    j11 = ref.wrap(pp - pm) / (2 * h)
    j21 = (kp - km) / (2 * h)
    j12 = ref.wrap(qp - qm) / (2 * h)
    j22 = (lp - lm) / (2 * h)
    det = j11 * j22 - j12 * j21

    # Tolerance, pointwise: each FD entry errs by <= h^2/6 * |F'''| (Taylor remainder of the
    # central difference) + LOCAL_ROUNDOFF / h (round-off of the two evaluations over 2h).
    # Then |det - 1| <= 2 A e + e^2 with A >= every |entry| = |1 + eps cos * omega'| etc.
    d3, w1 = _third_derivative_bounds(K, reg, p, h)
    e = h**2 / 6 * d3 + LOCAL_ROUNDOFF / h
    A = (1 + abs(p["eps"])) * (1 + w1)
    tol = 2 * (2 * A * e + e**2)  # factor 2: slack for neglected higher-order terms
    assert np.all(np.abs(det - 1.0) <= tol)
    # The bound is meaningful: far below the O(1) deviation of a non-symplectic step.
    assert tol.max() < 1e-5
    # The FD Jacobian matches the analytic one (a wrong omega'(K) would be caught here as well).
    s = np.sqrt(np.maximum(-K, 0.0))
    wprime = (
        p["tau0"]
        + np.where(reg == ref.UPPER, p["tau1"], 0.0)
        + np.where(reg == ref.RIGHT, p["lam"] / np.where(s > 0, s, 1.0), 0.0)
    )
    assert np.all(np.abs(j12 - wprime) <= e + 1e-12)


# ------------------------------------------------------------------------------------------------
# 3. Symmetries and rescaling of sec:truncatedmapnum


def test_rescaling_by_power_of_two_is_exact(rng):
    # tau0 = 4: K' = 4K, eps' = 4 eps, tau1' = tau1/4, lam' = lam/2 are all exact in binary, and
    # sqrt(4x) = 2 sqrt(x) exactly, so the two maps must give bit-identical orbits (K' = 4 K).
    base = dict(eps=0.3, Omega0=hovering.OMEGA_G, theta_w=3 * np.pi / 4, tau0=4.0, tau1=0.5, lam=0.5)
    m = make_map(base)
    ms = make_map(dict(base, eps=1.2, tau0=1.0, tau1=0.125, lam=0.25))
    assert ms.valid_band()[0] == 4.0 * m.valid_band()[0]
    phi0, K0 = band_sample(m, 500, rng, K_hi=0.5, margin=0.05)
    for kernel in ("scalar", "simd"):
        r = m.iterate(phi0, K0, 200, kernel=kernel)
        rs = ms.iterate(phi0, 4.0 * K0, 200, kernel=kernel)
        assert np.array_equal(rs.status, r.status)
        assert np.array_equal(rs.phi, r.phi, equal_nan=True)
        assert np.array_equal(rs.K, 4.0 * r.K, equal_nan=True)
        assert np.array_equal(rs.region, r.region)


@pytest.mark.parametrize("tau0", [2.5, -1.7, 0.4])
def test_rescaling_of_K(tau0, rng):
    """K -> |tau0| K maps F(eps, tau0, tau1, lam) to F(|tau0| eps, sign tau0, tau1/|tau0|, lam/sqrt|tau0|)."""
    a = abs(tau0)
    base = dict(eps=0.3, Omega0=hovering.OMEGA_G, theta_w=3 * np.pi / 4, tau0=tau0, tau1=0.5, lam=0.5)
    m = make_map(base)
    ms = make_map(dict(base, eps=a * 0.3, tau0=math.copysign(1.0, tau0), tau1=0.5 / a, lam=0.5 / math.sqrt(a)))
    # The band is mapped too: lo' = |tau0| lo (a few roundings of O(1) numbers).
    assert ms.valid_band()[0] == pytest.approx(a * m.valid_band()[0], rel=1e-14)
    n_steps = 6
    phi0, K0 = band_sample(m, 3000, rng, K_hi=1.0, margin=0.05)
    rp, rK, _, _ = ref.iterate(phi0, K0, n_steps, m.params)  # independent orbit for the bound
    finite = np.all(np.isfinite(rK), axis=1)
    ok = finite.copy()
    ok[finite] = np.all(safe_mask(m, rp[finite, :-1], rK[finite, :-1], 1e-6), axis=1)
    ok[finite] &= rK[finite, -1] > m.valid_band()[0] + 1e-6  # the last image stays in the band too
    bound = error_bound(rp[ok], rK[ok], m.params)
    small = bound.max(axis=1) < 1e-9  # far below the 1e-6 distance to any discontinuity
    ok_idx = np.flatnonzero(ok)[small]
    bound = bound[small]
    assert ok_idx.size > 1000
    r = m.iterate(phi0[ok_idx], K0[ok_idx], n_steps, kernel="scalar")
    rs = ms.iterate(phi0[ok_idx], a * K0[ok_idx], n_steps, kernel="scalar")
    assert np.all(r.status == hovering.Status.OK) and np.all(rs.status == hovering.Status.OK)
    # Tolerance: 10 x the propagated round-off bound (factor 2 for two computations, 5 slack for
    # the first-order linearisation); both maps compute the same orbit in different units.
    assert np.all(cdiff(rs.phi, r.phi) <= 10 * bound)
    assert np.all(np.abs(rs.K / a - r.K) <= 10 * bound)
    assert np.array_equal(rs.region, r.region)


def test_omega0_plus_4pi_is_the_same_map(any_map, rng):
    m = any_map
    m4 = make_map(dict(m.params, Omega0=m.Omega0 + 4 * np.pi))
    # Same band, but its top (|Omega0 + tau0 K| = 1e6, where wrapping stays accurate) moves by 4 pi / tau0.
    assert m4.valid_band()[0] == m.valid_band()[0]
    assert m4.valid_band()[1] == pytest.approx(m.valid_band()[1] - 4 * np.pi / m.tau0, rel=1e-15)
    phi, K = band_sample(m, N_POINTS, rng, K_hi=1.5, margin=1e-6)
    ok = safe_mask(m, phi, K, BOUNDARY)
    phi, K = phi[ok], K[ok]
    a, b = m.step(phi, K)
    c, d = m4.step(phi, K)
    # Tolerance 1e-13: the two differ only by the rounding of Omega0 + 4 pi and of phi + omega
    # (|.| < 20, ulp 3.6e-15) plus the 2 pi shift of phi_01: a few ulps of 16, well below 1e-13.
    assert cdiff(a, c).max() <= 1e-13
    assert np.abs(b - d).max() <= 1e-13
    assert np.array_equal(m.region(phi, K), m4.region(phi, K))
    # The rotations differ by exactly 4 pi (up to the same rounding).
    assert np.abs(m4.rotation(phi, K) - m.rotation(phi, K) - 4 * np.pi).max() <= 1e-13


def test_sign_of_eps_is_a_half_turn_above_tangency(any_map, rng):
    """F_eps(phi, K) = F_{-eps}(phi + pi, K) - (pi, 0) on K >= 0 (the shifted standard map)."""
    m = any_map
    mm = m.with_eps(-m.eps)
    phi = rng.uniform(-np.pi, np.pi, N_POINTS)
    K = rng.uniform(0.0, 2.0, N_POINTS)
    K[:1000] = 0.0  # the tangency circle itself belongs to J_0u
    a, b = m.step(phi, K)
    c, d = mm.step(ref.wrap(phi + np.pi), K)
    # Tolerance 1e-13: the half turn adds ~2 roundings of |.| < 16 to phi, and sin(x + pi) = -sin(x)
    # up to 1 ulp; both far below 1e-13.
    assert cdiff(c - np.pi, a).max() <= 1e-13
    assert np.abs(d - b).max() <= 1e-13


def test_sign_of_eps_below_tangency_needs_omega0_shift(any_map, rng):
    """Below the tangency circle the arcs are not invariant under phi -> phi + pi.

    The paper's F_eps(phi, K) = F_{-eps}(phi + pi, K) is exact only for K >= 0 (see the test above).
    On the whole band the half turn must be combined with Omega0 -> Omega0 + 2 pi, which moves
    phi_01 by -pi (so J_a(K) -> J_a(K) + pi) and changes every omega_a by 2 pi (no effect mod 2 pi):
    F_eps(phi, K; Omega0) = F_{-eps}(phi + pi, K; Omega0 + 2 pi) - (pi, 0).
    """
    m = any_map
    mm = make_map(dict(m.params, eps=-m.eps, Omega0=m.Omega0 + 2 * np.pi))
    phi, K = band_sample(m, N_POINTS, rng, K_hi=1.0, margin=1e-6)
    ok = safe_mask(m, phi, K, BOUNDARY)
    phi, K = phi[ok], K[ok]
    a, b = m.step(phi, K)
    c, d = mm.step(ref.wrap(phi + np.pi), K)
    # Same 1e-13 budget as above (Omega0 + 2 pi adds one more rounding of a number < 16).
    assert cdiff(c - np.pi, a).max() <= 1e-13
    assert np.abs(d - b).max() <= 1e-13
    assert np.array_equal(m.region(phi, K), mm.region(ref.wrap(phi + np.pi), K))


# ------------------------------------------------------------------------------------------------
# 5. Exact solutions


def test_shifted_standard_map_above_tangency(any_map, rng):
    m = any_map
    p = m.params
    phi = rng.uniform(-np.pi, np.pi, N_POINTS)
    K = rng.uniform(0.0, 3.0, N_POINTS)
    K[:100] = 0.0
    a, b = m.step(phi, K)
    # K >= 0: phi1 = phi + Omega0 + tau0 K, K1 = K + eps sin(phi1)
    phi1 = phi + p["Omega0"] + p["tau0"] * K
    K1 = K + p["eps"] * np.sin(phi1)
    # Tolerance 1e-13: wrapping phi1 into [-pi, pi) changes sin(phi1) by <= 2 ulp(|phi1| < 12);
    # 1e-13 leaves ample room and is 10^10 below a wrong rotation.
    assert cdiff(a, phi1).max() <= 1e-13
    assert np.abs(b - K1).max() <= 1e-13
    assert np.all((a >= -np.pi) & (a < np.pi))
    assert np.all(m.region(phi, K) == hovering.Region.BESIDE)
    assert np.abs(m.rotation(phi, K) - (p["Omega0"] + p["tau0"] * K)).max() <= 1e-13


@pytest.mark.parametrize("name", ["paper_eps+0.3", "tau1_negative"])
def test_eps_zero_is_a_three_interval_exchange(name, rng):
    p = dict(PARAM_SETS[name], eps=0.0)
    m = make_map(p)
    lo = m.valid_band()[0]
    K = np.linspace(0.98 * lo, -1e-3, 60)
    s = np.sqrt(-K)
    tw, O0, t0, t1, lam = p["theta_w"], p["Omega0"], p["tau0"], p["tau1"], p["lam"]
    # Closed forms of the arcs (PAPER-NOTES, eq:Jdeftrunc corrected), independent of the package.
    l1 = tw - O0 / 2 - (t0 + t1) * K / 2 - lam * s
    L1, LR = 2 * lam * s, 2 * (np.pi - tw) + t1 * K
    L0 = 2 * np.pi - L1 - LR
    lR, l0 = l1 + L1, l1 + L1 + LR
    ends = {"1": (l1, l1 + L1), "R": (lR, lR + LR), "0": (l0, l0 + L0)}
    delta = 1e-7  # well inside each arc: the shortest arc here has length 2 lam sqrt(1e-3) ~ 0.03
    # Tolerance 1e-12: one step rounds phi + omega (|.| < 16, ulp 3.6e-15); the closed forms above
    # add a few more roundings.  An arc sent to the wrong place is off by > 0.03.
    tol = 1e-12
    image_mid = {}
    for a, (left, right) in ends.items():
        mid = 0.5 * (left + right)
        for x, expected in ((mid, -mid), (left + delta, -right + delta), (right - delta, -left - delta)):
            y, Ky = m.step(ref.wrap(x), K)
            assert np.array_equal(Ky, K), "eps = 0 must preserve K exactly"
            assert cdiff(y, expected).max() <= tol, f"arc J_{a} is not sent onto -J_{a}"
        image_mid[a] = ref.wrap(m.step(ref.wrap(mid), K)[0])
    # Order reversed: going up in phi from -(right end of J_0) = -l1 - 2 pi, the images are
    # -J_0, -J_R, -J_1.
    off = {a: np.mod(image_mid[a] + l1, 2 * np.pi) for a in image_mid}
    assert np.all(off["0"] < off["R"]) and np.all(off["R"] < off["1"])

    # Random points: K preserved exactly and -phi1 lies in the arc phi came from.
    phi, Kr = band_sample(m, 20_000, rng, K_hi=-1e-6, margin=1e-3)
    ok = safe_mask(m, phi, Kr, BOUNDARY)
    phi, Kr = phi[ok], Kr[ok]
    y, Ky = m.step(phi, Kr)
    assert np.array_equal(Ky, Kr)
    assert np.array_equal(ref.region(-y, Kr, p), ref.region(phi, Kr, p))


# ------------------------------------------------------------------------------------------------
# 4. Agreement with the independent NumPy implementation


def test_step_and_inverse_match_numpy_reference(any_map, rng):
    m = any_map
    p = m.params
    phi, K = band_sample(m, N_POINTS, rng, K_hi=1.5, margin=abs(m.eps) + 1e-6)
    pr, Kr = ref.reversal(phi, K, p)
    ok = safe_mask(m, phi, K, BOUNDARY) & safe_mask(m, pr, Kr, BOUNDARY)
    phi, K = phi[ok], K[ok]
    # Tolerance 1e-12: one step of round-off on either side (<= LOCAL_ROUNDOFF = 1e-14 each),
    # different association of the arc formulas and sin implementations (<= 1 ulp); factor 50 slack.
    tol = 1e-12
    a, b = m.step(phi, K)
    ra, rb = ref.step(phi, K, p)
    assert cdiff(a, ra).max() <= tol and np.abs(b - rb).max() <= tol
    c, d = m.step_inverse(phi, K)
    rc, rd = ref.step_inverse(phi, K, p)
    assert cdiff(c, rc).max() <= tol and np.abs(d - rd).max() <= tol
    reg = m.region(phi, K)
    assert reg.dtype == np.int8
    assert np.array_equal(reg.astype(int), ref.region(phi, K, p))
    assert np.abs(m.rotation(phi, K) - ref.rotation(phi, K, p)).max() <= tol
    # Shapes are preserved and broadcasting works (2-D phi against a K row).
    P = phi[:600].reshape(20, 30)
    Kb = K[:30]
    a2, b2 = m.step(P, Kb)
    ra2, rb2 = ref.step(P, Kb, p)
    assert a2.shape == (20, 30) and b2.shape == (20, 30)
    assert m.region(P, Kb).shape == (20, 30)
    # (P, Kb) are not all boundary-safe as pairs; compare only those that are
    sm = safe_mask(m, *np.broadcast_arrays(P, Kb), BOUNDARY)
    assert cdiff(a2, ra2)[sm].max() <= tol and np.abs(b2 - rb2)[sm].max() <= tol


VALID_BAND_CASES = {
    **PARAM_SETS,
    # |J_0| > 0 is the binding condition (PAPER-NOTES typo 3): lo = -(first root of
    # tau1 s^2 - 2 lam s + 2 theta_w)^2 ~ -0.051, not -2 (pi - theta_w)/tau1 ~ -12.2.
    "J0_binding": dict(eps=0.2, Omega0=2.0, theta_w=0.1, tau0=1.0, tau1=0.5, lam=0.5),
    "tau1_zero": dict(eps=0.2, Omega0=2.0, theta_w=1.0, tau0=1.0, tau1=0.0, lam=0.8),
}


@pytest.mark.parametrize("name", list(VALID_BAND_CASES))
def test_valid_band_matches_reference(name):
    p = VALID_BAND_CASES[name]
    m = make_map(p)
    lo, hi = m.valid_band()
    rlo, rhi = ref.valid_band(p)
    # The reference bisects to 1e-13 on the valid side; 1e-12 allows for that and a few ulps.
    assert lo == pytest.approx(rlo, abs=1e-12)
    # The reference has no top; the map's is where the rotation Omega0 + tau0 K reaches 1e6 rad
    # (beyond, phi + Omega cannot be wrapped accurately).
    top = (1e6 - p["Omega0"]) / p["tau0"] if p["tau0"] > 0 else (1e6 + p["Omega0"]) / -p["tau0"]
    assert rhi == math.inf and hi == top
    # Just inside the band every arc length is in (0, 2 pi); just outside one is not.
    a = m.arcs(np.array([lo * (1 - 1e-9)]))
    for key in ("len_1", "len_R", "len_0"):
        assert 0 < a[key][0] < 2 * np.pi
    _, L1, LR, L0 = ref.arcs(lo * (1 + 1e-9), p)
    assert not all(0 < L < 2 * np.pi for L in (L1, LR, L0))


def test_K_max_caps_the_band():
    m = make_map(PARAM_SETS["paper_eps+0.3"], K_max=0.75)
    assert m.valid_band() == (make_map(PARAM_SETS["paper_eps+0.3"]).valid_band()[0], 0.75)
    assert m.with_eps(-0.3).valid_band()[1] == 0.75


# ------------------------------------------------------------------------------------------------
# Scalar calls


@pytest.mark.parametrize("method", ["step", "step_inverse", "rotation", "reversal", "region"])
def test_scalar_inputs_return_python_scalars(method):
    """Documented: 'Floats when both inputs are scalars' (a Region for region())."""
    m = make_map(PARAM_SETS["paper_eps+0.3"])
    phi, K = 0.4, -0.5
    out = getattr(m, method)(phi, K)
    arr = getattr(m, method)(np.array([phi]), np.array([K]))
    if method == "region":
        assert isinstance(out, hovering.Region)
        assert int(out) == int(arr[0])
    elif method == "rotation":
        assert isinstance(out, float)
        assert out == arr[0]
    else:
        assert isinstance(out, tuple) and all(isinstance(v, float) for v in out)
        assert out == (arr[0][0], arr[1][0])


# ------------------------------------------------------------------------------------------------
# 6. Bad input


BAD_CONSTRUCTOR = [
    (dict(theta_w=0.0), r"theta_w must lie in \(0, pi\)"),
    (dict(theta_w=np.pi), r"theta_w must lie in \(0, pi\)"),
    (dict(theta_w=-1.0), r"theta_w must lie in \(0, pi\)"),
    (dict(theta_w=4.0), r"theta_w must lie in \(0, pi\)"),
    (dict(lam=0.0), r"lam must be > 0"),
    (dict(lam=-0.5), r"lam must be > 0"),
    (dict(eps=np.nan), r"eps must be finite"),
    (dict(eps=np.inf), r"eps must be finite"),
    (dict(Omega0=np.inf), r"Omega0 must be finite"),
    (dict(theta_w=np.nan), r"theta_w must be finite"),
    (dict(tau0=-np.inf), r"tau0 must be finite"),
    (dict(tau1=np.nan), r"tau1 must be finite"),
    (dict(lam=np.inf), r"lam must be finite"),
    (dict(eps="abc"), r"eps must be a real number"),
    (dict(K_max=0.0), r"K_max must be > 0"),
    (dict(K_max=-1.0), r"K_max must be > 0"),
    (dict(K_max=np.nan), r"K_max must be > 0"),
]


@pytest.mark.parametrize("override,match", BAD_CONSTRUCTOR, ids=[str(c[0]) for c in BAD_CONSTRUCTOR])
def test_bad_constructor_arguments(override, match):
    p = dict(PARAM_SETS["paper_eps+0.3"])
    kw = {}
    if "K_max" in override:
        kw["K_max"] = override["K_max"]
    else:
        p.update(override)
    with pytest.raises(ValueError, match=match):
        hovering.TruncatedMap(**p, **kw)


# Maps whose band below K = 0 is below double-precision resolution, and what the message must name:
# the parameter, its value and the bound (the TruncatedMap docstring's Notes). Each used to be
# built; tau0 = 1e308 then measured hovering_area 0 +- 1.3e-303 against a theory of 0.764.
UNRESOLVED = [
    (dict(tau0=1e308), r"floor .* is set by tau0 = 1e\+308.*allowed: \|tau0\| <= 4\.84e\+30"),
    (dict(tau0=-1e308), r"set by tau0 = -1e\+308.*allowed: \|tau0\| <= 4\.84e\+30"),
    (dict(tau1=1e308), r"set by tau1 = 1e\+308: \|J_R\|.*allowed: tau1 <= 7\.6e\+24"),
    (dict(lam=5e-324), r"J_1 opens to at most 1\.98e-323 rad.*allowed: lam >= 1\.28e-13"),
    (dict(lam=1e300), r"the band has no part below K = 0 .*\|J_0\|.*lam = 1e\+300.*allowed: .*smaller lam"),
    (dict(theta_w=5e-324), r"no part below K = 0 .*theta_w = 5e-324.*allowed: a larger theta_w"),
    (dict(Omega0=-1e6), r"no part below K = 0 .*tau0 = 1\.0.*allowed: \|Omega0\| < 1e6"),
    (dict(eps=1e308), r"eps = 1e\+308 .* kicks K .*allowed: \|eps\| max\|f\| <= 8\.79609e\+18"),
    (dict(eps=-1e19), r"eps = -1e\+19 .*allowed: .*\|eps\| <= 8\.79609e\+18"),
]


@pytest.mark.parametrize("override,match", UNRESOLVED, ids=[str(c[0]) for c in UNRESOLVED])
def test_a_band_below_double_precision_resolution_is_refused(override, match):
    p = dict(PARAM_SETS["paper_eps+0.3"], **override)
    with pytest.raises(ValueError, match=r"below double-precision resolution"):
        hovering.TruncatedMap(**p)
    with pytest.raises(ValueError, match=match):
        hovering.TruncatedMap(**p)


def test_the_resolution_bounds_lie_where_the_docstring_says():
    # Each bound is checked on both sides, 1% away (far above the few roundings of the band's
    # ends, far below the factor of 2^10 the rules leave before resolution is really gone), and
    # the accepted map's J_1 is measured through the core's own arcs() just above the floor.
    p = dict(PARAM_SETS["paper_eps+0.3"])  # tau1 = lam = 0.5, theta_w = 3 pi / 4: floor -pi
    need = (2.0**-41 / (2 * p["lam"])) ** 2  # the depth where 2 lam sqrt(-K) reaches 2^-41
    room = 1e6 + p["Omega0"]  # the rotation bound's floor: -(1e6 + Omega0) / tau0
    # tau0 (eps = 0: the kick rule does not apply), ~2e31 lam^2 as documented
    bound = room / need
    assert 2e31 * 0.25 * 0.9 < bound < 2e31 * 0.25 * 1.1
    m = hovering.TruncatedMap(**dict(p, eps=0.0, tau0=0.99 * bound))
    lo = m.valid_band()[0]
    assert m.arcs(lo * (1 - 2**-20))["len_1"] >= 2.0**-41
    with pytest.raises(ValueError, match=r"J_1 opens to at most 4\.5\de-13 rad"):
        hovering.TruncatedMap(**dict(p, eps=0.0, tau0=1.01 * bound))
    # lam >= 2^-42 / sqrt(-K_lo), with the floor -pi set by |J_R|
    lam_min = 2.0**-42 / math.sqrt(math.pi)
    m = hovering.TruncatedMap(**dict(p, lam=1.01 * lam_min))
    assert m.valid_band()[0] == -math.pi and m.arcs(-math.pi * (1 - 2**-20))["len_1"] >= 2.0**-41
    with pytest.raises(ValueError, match=r"allowed: tau1 <= 0\.49 with these theta_w and lam, or lam >= 1\.28e-13"):
        hovering.TruncatedMap(**dict(p, lam=0.99 * lam_min))
    # eps: 2^43 x the band's height
    lo, hi = hovering.TruncatedMap(**p).valid_band()
    eps_max = 2.0**43 * (hi - lo)
    assert hovering.TruncatedMap(**dict(p, eps=-0.99 * eps_max)).eps == -0.99 * eps_max
    with pytest.raises(ValueError, match=r"kicks K"):
        hovering.TruncatedMap(**dict(p, eps=1.01 * eps_max))


@pytest.mark.parametrize("value", ["1", True, np.bool_(True), None, 1j, [1.0], np.array([1.0, 2.0])])
def test_K_max_is_checked_like_every_parameter(value):
    # Used to go through float(): '1' and True gave K_max = 1, None a TypeError's message.
    p = dict(PARAM_SETS["paper_eps+0.3"])
    with pytest.raises(ValueError, match=r"K_max must be a real number"):
        hovering.TruncatedMap(**p, K_max=value)
    K, Om, JR, J1 = _paper_family()._tables
    with pytest.raises(ValueError, match=r"K_max must be a real number"):
        hovering.TruncatedFamily(0.3, K, Om, JR, J1, K_max=value)
    # while inf, in any of its real-number forms, is no cap, and any positive real is one
    uncapped = hovering.TruncatedMap(**p).valid_band()[1]  # where the rotation reaches 1e6
    for top in (math.inf, np.float64(np.inf), np.array(np.inf), 2, np.float32(0.5)):
        assert hovering.TruncatedMap(**p, K_max=top).valid_band()[1] == min(float(top), uncapped)


def _paper_family():
    grid = np.concatenate([-(np.linspace(2.0, 0.0, 21) ** 2), np.linspace(0.0, 1.0, 11)[1:]])
    return hovering.TruncatedFamily.from_map(make_map(PARAM_SETS["paper_eps+0.3"]), grid)


_LO = -np.pi  # band floor of the paper's parameters: -2 (pi - theta_w) / tau1


BAD_CALLS = [
    ("step", (np.nan, -0.5), r"step: phi(\[0\])? must be finite"),
    ("step", (0.1, np.inf), r"step: K(\[0\])? must be finite"),
    ("step", (0.1, -np.inf), r"step: K(\[0\])? must be finite"),
    ("step", (0.1, _LO - 0.1), r"step: K = -3\.24.* is outside the band \(-3\.14159265358979"),
    ("step", (0.1, _LO), r"step: K = -3\.14.* is outside the band"),  # the band is open
    ("step", (np.zeros(3), np.zeros(4)), r"step: phi and K must have broadcastable shapes"),
    ("step_inverse", (np.pi / 2, _LO + 0.1), r"step_inverse \(preimage\): K = .* is outside the band"),
    ("step_inverse", (np.nan, 0.0), r"step_inverse: phi(\[0\])? must be finite"),
    ("step_inverse", (np.zeros(2), np.zeros(5)), r"step_inverse: phi and K must have broadcastable"),
    ("region", (0.0, np.nan), r"region: K(\[0\])? must be finite"),
    ("region", (0.0, -4.0), r"region: K = -4 is outside the band"),
    # rotation() reports through region() (message prefix 'region:'); the parameter and band are named
    ("rotation", (0.0, -4.0), r"K = -4 is outside the band \(-3\.14159265358979"),
    ("rotation", (np.inf, 0.0), r"phi(\[0\])? must be finite"),
]


@pytest.mark.parametrize("method,args,match", BAD_CALLS, ids=[f"{c[0]}-{i}" for i, c in enumerate(BAD_CALLS)])
def test_bad_point_arguments(method, args, match):
    m = make_map(PARAM_SETS["paper_eps+0.3"])
    assert m.valid_band()[0] == _LO
    # Pass arrays: the error must come from the argument check, not from scalar conversion.
    a, b = (np.atleast_1d(np.asarray(v, dtype=float)) for v in args)
    with pytest.raises(ValueError, match=match):
        getattr(m, method)(a, b)


def test_step_above_K_max_raises():
    m = make_map(PARAM_SETS["paper_eps+0.3"], K_max=1.0)
    with pytest.raises(ValueError, match=r"step: K = 1 is outside the band \(.*, 1\)"):
        m.step(np.array([0.0]), np.array([1.0]))
    with pytest.raises(ValueError, match=r"step: K = 2 is outside the band"):
        m.step(np.array([0.0]), np.array([2.0]))


def test_bad_region_names():
    with pytest.raises(ValueError, match=r"unknown region 'X'; allowed: BESIDE \('0u'\), ABOVE"):
        hovering.Region.parse("X")
    with pytest.raises(ValueError, match=r"unknown region 7"):
        hovering.Region.parse(7)
    with pytest.raises(ValueError, match=r"unknown region -1"):
        hovering.region_mask([-1])
    # and every accepted spelling maps to the right code
    assert hovering.region_mask(["0u", "ABOVE", "upper", "R"]) == 0b1111
    assert hovering.region_mask([]) == 0
    assert hovering.Region.parse("0") is hovering.Region.ABOVE
    assert hovering.Region.parse(3) is hovering.Region.RIGHT


def test_huge_angles_are_rejected_not_mis_wrapped():
    # Beyond |phi| ~ 1e16 wrapping is off by whole turns; the map refuses angles above 1e6.
    m = make_map(PARAM_SETS[next(iter(PARAM_SETS))])
    with pytest.raises(ValueError, match=r"step: phi must be an angle in \[-1e6, 1e6\]"):
        m.step(-1e18, 0.1)
    with pytest.raises(ValueError, match=r"phi0\[1\] must be an angle in \[-1e6, 1e6\].*got 10000000.0"):
        m.iterate([0.0, 1e7], [0.1, 0.1], 3)
    # Large but admissible angles wrap like their reduced values (error ~ ulp(1e5) ~ 1e-11).
    a = m.step(1e5, 0.1)
    b = m.step(hovering.wrap(1e5), 0.1)
    assert abs(hovering.wrap(a[0] - b[0])) < 1e-9 and abs(a[1] - b[1]) < 1e-9
