"""Hard cases of the truncated family, each checked against an exact or independent reference.

* Huge rotations: one documented bound, |Omega| <= 1e6, for the constructors, the band, step,
  step_inverse and iterate, and the accuracy phi keeps up to it (exact rational arithmetic).
* Arc ends: the half-open convention (each arc owns its start) in region, step, step_inverse and
  the SIMD kernel, on every boundary point the API hands out (corner_curves, arcs, the band's
  floor and ceiling), for F_eps and the family, several signs of eps and Omega0.
* Images near the band floor: step_inverse accepts every image step() makes of a band point.
* SIMD vs scalar: phi and region bit for bit, K within the bound set by the two sines.
* Long orbits: no OK orbit point has phi outside [-pi, pi) or a non-finite K.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import hovering
from hovering import Region, Status, TruncatedFamily, TruncatedMap

PI = math.pi  # the double kPi the core wraps with: [-pi, pi) means -PI <= phi < PI
ARCS = (("01", "start_1", Region.UPPER), ("1R", "start_R", Region.RIGHT), ("R0", "start_0", Region.ABOVE))

#: F_eps for both signs of eps, eps = 0 (no height rounding at all), a rotation near the bound, and
#: the two kinds of band floor: |J_0| closing (theta_w = 0.1) and |J_R| closing (tau1 > 0).
MAPS = {
    "paper+0.3": dict(eps=0.3, Omega0=hovering.OMEGA_G, theta_w=3 * PI / 4),
    "paper-0.3": dict(eps=-0.3, Omega0=hovering.OMEGA_G, theta_w=3 * PI / 4),
    "eps+0.92": dict(eps=0.92, Omega0=hovering.OMEGA_G, theta_w=3 * PI / 4),
    "eps0": dict(eps=0.0, Omega0=1.0, theta_w=1.0),
    "Omega0-2.5": dict(eps=-0.5, Omega0=-2.5, theta_w=2.0, tau0=-0.7, tau1=-0.4, lam=0.7),
    "Omega0~1e6": dict(eps=0.4, Omega0=999_990.0, theta_w=1.2),
    "J0_floor": dict(eps=0.5, Omega0=2.0, theta_w=0.1),
    "JR_floor": dict(eps=-0.5, Omega0=1.0, theta_w=1.0),
}


def make(name):
    if name.startswith("family"):
        eps = {"family+": 0.4, "family-": -0.35}[name]
        base = TruncatedMap(0.0, 2.2, 1.1, tau0=0.8, tau1=0.3, lam=0.6)
        K = np.concatenate([-np.geomspace(6.0, 1e-6, 40), [0.0], np.linspace(0.05, 3.0, 20)])
        fam = TruncatedFamily.from_map(base, K, forcing=(1.0, 0.25))
        return fam.with_eps(eps)
    return TruncatedMap(**MAPS[name])


ALL = list(MAPS) + ["family+", "family-"]


def ulp(x):
    return np.spacing(np.abs(np.asarray(x, dtype=float)))


def circ(a, b):
    """|a - b| on the circle (a, b in [-pi, pi))."""
    d = np.abs(np.asarray(a, dtype=float) - np.asarray(b, dtype=float))
    return np.minimum(d, 2 * PI - d)


def heights(m, rng, n=400):
    """Heights below 0 in the band: random ones and the hard ones (floor, floor + 1e-16..1e-12,
    tiny |K| where |J_1| = 2 lam sqrt(-K) is below the rounding, the last double below 0)."""
    lo, hi = m.valid_band()
    top = min(hi, 0.0)
    K = list(rng.uniform(max(lo, -10.0), top, n))
    first = np.nextafter(lo, np.inf)
    K += [first] + [max(first, lo + d * max(1.0, abs(lo))) for d in (1e-16, 1e-15, 1e-14, 1e-13, 1e-12)]
    K += [-1e-300, -1e-30, -1e-26, -1e-20, -1e-17, -1e-12, -1e-6, -np.finfo(float).tiny, np.nextafter(0.0, -1.0)]
    K = np.array([k for k in K if lo < k < top])
    return K


def degenerate(m, K):
    """Heights where some arc is shorter than the rounding of its ends' images (16 ulps of
    |Omega| + 3 pi): an arc with no double, or two starts sharing one image (the float map cannot
    tell them apart there, so the inverse can give back only one of them)."""
    a = m.arcs(K)
    omega = np.abs(m.rotation(a["start_0"], K)) + 3 * PI
    shortest = np.minimum(np.minimum(a["len_1"], a["len_R"]), a["len_0"])
    return shortest <= 16 * ulp(omega)


# ------------------------------------------------------------------------------------------------
# 1 and 2. Huge rotations: one bound, |Omega| <= 1e6, everywhere


def test_constructors_refuse_rotations_beyond_the_bound():
    with pytest.raises(ValueError, match=r"Omega0 must lie in \[-1e6, 1e6\].*got -2.4e\+39"):
        TruncatedMap(0.3, -2.4e39, 1.0)
    with pytest.raises(ValueError, match=r"Omega0 must lie in \[-1e6, 1e6\].*got 1000000.5"):
        TruncatedMap(0.3, 1_000_000.5, 1.0)
    TruncatedMap(0.3, 1e6, 1.0)  # the bound itself is allowed
    K = np.array([-1.0, -0.5, 0.0, 1.0])
    with pytest.raises(ValueError, match=r"Omega\[3\] must lie in \[-1e6, 1e6\].*got 2e\+06"):
        TruncatedFamily(0.1, K, [0.0, 0.0, 0.0, 2e6], [4.0] * 4, np.sqrt(np.maximum(-K, 0)))


@pytest.mark.parametrize("tau0", [1.0, -3.0, 4e20, 1e-300])
def test_band_ends_where_the_rotation_reaches_the_bound(tau0):
    # eps 0.3 / |tau0| for large twists: a kick a band 5e-15 tall resolves (eps tau0 is the
    # rescaling invariant; eps = 0.3 at tau0 = 4e20 is refused, as eps = 1.2e20 at tau0 = 1 is).
    m = TruncatedMap(0.3 / max(1.0, abs(tau0)), 2.0, 1.0, tau0=tau0)
    lo, hi = m.valid_band()
    # Closed form: Omega0 + tau0 K = +-1e6 at the band's ends (or the arcs' floor, whichever is
    # higher); the first and last doubles inside have |Omega| <= 1e6 up to one rounding.
    want_hi = (1e6 - 2.0) / tau0 if tau0 > 0 else (1e6 + 2.0) / -tau0
    assert hi == pytest.approx(want_hi, rel=1e-15)
    for k in (np.nextafter(lo, np.inf), np.nextafter(hi, -np.inf)):
        assert abs(2.0 + tau0 * k) <= 1e6 * (1 + 2**-52)
    # K = 1e16 (tau0 = 1) used to step to phi = 0.0: now it is outside the band, said so.
    with pytest.raises(ValueError, match=r"step: K = 1e\+16 is outside the band \(.*, 999998\)"):
        TruncatedMap(0.3, 2.0, 1.0).step(0.3, 1e16)
    with pytest.raises(ValueError, match=r"region: K = 1e\+16 is outside the band"):
        TruncatedMap(0.3, 2.0, 1.0).region(0.3, 1e16)


def test_family_band_stops_where_the_spline_exceeds_the_bound():
    # Every tabulated |Omega| <= 1e6, but the natural spline through them overshoots past K = 0.6.
    K = np.array([-1.0, -0.5, 0.0, 0.5, 0.6, 2.0])
    Om = np.array([0.0, 0.0, 0.0, 9e5, 1e6, -1e6])
    f = TruncatedFamily(0.3, K, Om, np.full(6, 4.0), np.sqrt(np.maximum(-K, 0)))
    lo, hi = f.valid_band()
    # Independent spline (scipy, natural end conditions, as GSL's cspline): the first K > 0
    # where |Omega| > 1e6, on a grid 1e-6 fine; the band's top must be within that grid step.
    from scipy.interpolate import CubicSpline

    x = np.linspace(0.0, 2.0, 2_000_001)
    excess = np.abs(CubicSpline(K, Om, bc_type="natural")(x)) > 1e6
    assert excess.any() and lo == -1.0
    assert x[np.argmax(excess)] - 1e-6 <= hi <= x[np.argmax(excess)]
    assert abs(f.rotation(0.0, np.nextafter(hi, 0.0))) <= 1e6 * (1 + 1e-12)
    with pytest.raises(ValueError, match="outside the band"):
        f.step(0.0, 0.7)


def test_iterate_escapes_rather_than_wrapping_a_huge_rotation():
    m = TruncatedMap(0.3, 2.0, 1.0)  # band top 999998: Omega reaches 1e6 there
    r = m.iterate([0.3, 0.3, 0.3], [1e16, 999_997.9, 0.5], 50, record=("orbit",))
    assert r.status[0] == Status.ESCAPED and r.steps_done[0] == 0
    # An orbit kicked across the top stops there: every recorded point before is in the band.
    big = TruncatedMap(5.0, 2.0, 1.0, K_max=1e6)
    r2 = big.iterate(np.zeros(64), np.linspace(999_990.0, 999_997.9, 64), 200, record=("orbit",))
    assert (r2.status == Status.ESCAPED).any()
    for i in range(64):
        n = r2.steps_done[i]
        assert np.all(r2.K[i, :n] < big.valid_band()[1])
        assert np.all((-PI <= r2.phi[i, : n + 1]) & (r2.phi[i, : n + 1] < PI))


# Decimal digits of pi far beyond double precision (a constant, for the exact reference below).
PI_50 = Fraction("3.14159265358979323846264338327950288419716939937510582097494459")


def exact_rotation(phi, omega):
    """phi + omega reduced to [-pi, pi) with the true pi, in exact rational arithmetic."""
    x = Fraction(phi) + Fraction(omega)
    turns = math.floor((x + PI_50) / (2 * PI_50))
    return float(x - 2 * PI_50 * turns)


@pytest.mark.parametrize("Omega0", [1.0, -3.0, 999_999.9, -1e6, 1e6])
def test_phi_keeps_the_documented_accuracy_up_to_the_bound(Omega0, rng):
    # tau0 = 0: the rotation is Omega0 everywhere, the band has no top, K >= 0 is the shifted
    # standard map, phibar = phi + Omega0 mod 2 pi exactly. Bound per step (documented): rounding
    # of phi + Omega0 and of the 2 pi n subtracted, ulp(|Omega0| + pi) / 2 each, and fl(2 pi)'s
    # error times n = |Omega0| / 2 pi + 1; plus the rounding of the result (ulp(pi) / 2).
    m = TruncatedMap(0.3, Omega0, 1.0, tau0=0.0)
    phi = rng.uniform(-PI, PI, 400)
    got, _ = m.step(phi, np.full(400, 2.0))
    want = np.array([exact_rotation(p, Omega0) for p in phi])
    n_turns = abs(Omega0) / (2 * PI) + 1
    bound = ulp(abs(Omega0) + PI) + n_turns * abs(2 * PI_50 - Fraction(2 * PI)) + ulp(PI) / 2
    err = circ(got, want)
    assert err.max() <= bound
    if abs(Omega0) >= 999_999:
        assert bound < 2e-10  # the figure the docs state for the bound


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    eps=st.one_of(st.floats(-2.0, 2.0), st.floats(-1e300, 1e300)),
    Omega0=st.floats(-1e6, 1e6),
    theta_w=st.floats(0.0, PI, exclude_min=True, exclude_max=True),
    tau0=st.one_of(st.floats(-3.0, 3.0), st.floats(-1e300, 1e300)),
    tau1=st.one_of(st.floats(-3.0, 3.0), st.floats(-1e300, 1e300)),
    lam=st.floats(1e-300, 1e300),
    data=st.data(),
)
def test_every_ok_result_is_wrapped_over_the_whole_parameter_range(eps, Omega0, theta_w, tau0, tau1, lam, data):
    m = built(lambda: TruncatedMap(eps, Omega0, theta_w, tau0=tau0, tau1=tau1, lam=lam))
    if m is None:  # refused, saying why: a band below double-precision resolution
        return
    point = band_point(data, m)
    if point is not None:  # (lam = 1e300 closes the band below 0 and a huge tau0 above)
        check_wrapped(m, *point)


def built(make):
    """The map ``make()`` builds, or None when it is refused for a band below double-precision
    resolution (most huge eps, tau0, tau1 and lam draw such bands): the refusal must name the
    value and what is allowed, which is the property then."""
    try:
        return make()
    except ValueError as e:
        msg = str(e)
        assert "below double-precision resolution" in msg and "allowed: " in msg, msg
        return None


def check_wrapped(m, phi, K):
    """step, step_inverse and both kernels at one band point: every OK angle in [-pi, pi), every
    OK height finite and in the band, every image of a band point accepted by step_inverse."""
    lo, hi = m.valid_band()
    p1, k1 = m.step(phi, K)
    assert -PI <= p1 < PI
    if np.isfinite(k1):  # (k1 overflows only for |eps| ~ 1e308)
        p0, k0 = m.step_inverse(p1, k1)
        assert -PI <= p0 < PI and lo < k0 < hi
    for kernel in ("simd", "scalar"):
        r = m.iterate([phi], [K], 20, kernel=kernel, record=("orbit",))
        n = int(r.steps_done[0])
        kept = n + 1 if r.status[0] == Status.OK else n  # an ESCAPED orbit's last point is outside
        assert r.status[0] in (Status.OK, Status.ESCAPED)
        assert np.all((-PI <= r.phi[0, : n + 1]) & (r.phi[0, : n + 1] < PI))
        assert np.all(np.isfinite(r.K[0, :kept])) and np.all((lo < r.K[0, :kept]) & (r.K[0, :kept] < hi))
        if r.status[0] == Status.ESCAPED:
            assert not lo < r.K_final[0] < hi


def band_point(data, m):
    """A height strictly inside the band (its ends and the last double below 0 often) and an
    angle in [-1e6, 1e6]; None when no double lies inside."""
    lo, hi = m.valid_band()
    inside = [k for k in (np.nextafter(lo, np.inf), np.nextafter(hi, -np.inf), np.nextafter(0.0, -1.0)) if lo < k < hi]
    if not inside:
        return None
    K = data.draw(
        st.one_of(st.floats(lo, hi, exclude_min=True, exclude_max=True, allow_infinity=False), st.sampled_from(inside))
    )
    return data.draw(st.floats(-1e6, 1e6)), K


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    eps=st.one_of(st.floats(-2.0, 2.0), st.floats(-1e300, 1e300)),
    Omega=st.lists(st.floats(-1e6, 1e6), min_size=7, max_size=7),
    jr=st.floats(0.1, 5.0),
    c=st.floats(0.01, 0.5),
    forcing=st.lists(st.floats(-1e3, 1e3), min_size=1, max_size=3),
    data=st.data(),
)
def test_family_ok_results_are_wrapped_over_its_parameter_range(eps, Omega, jr, c, forcing, data):
    # Any tabulated rotation within the bound (the spline between may overshoot it: the band
    # stops there), arcs valid down to the grid's floor (|J_1| + |J_R| <= 1 + 5 < 2 pi).
    K = np.array([-4.0, -2.0, -1.0, -0.25, 0.0, 0.5, 2.0])
    f = built(lambda: TruncatedFamily(eps, K, Omega, np.full(7, jr), c * np.sqrt(np.maximum(-K, 0.0)), forcing=forcing))
    if f is None:  # |eps| max|f| > 2^43 x the band's height: refused, saying why
        return
    point = band_point(data, f)
    if point is not None:
        check_wrapped(f, *point)


# ------------------------------------------------------------------------------------------------
# 3. Arc ends: every boundary point the API hands out


@pytest.mark.parametrize("name", ALL)
def test_boundary_points_are_owned_and_inverted_exactly(name, rng):
    m = make(name)
    K = heights(m, rng)
    a = m.arcs(K)
    cc = m.corner_curves(K)
    deg = degenerate(m, K)
    assert (~deg).sum() >= 400  # the degenerate heights are the few hard ones added on purpose
    n_same = n_merged = 0
    for key, start_key, owner in ARCS:
        s = cc[key]
        assert np.array_equal(s, a[start_key])  # one set of boundary points
        assert np.all((-PI <= s) & (s < PI))
        reg = m.region(s, K)
        # Each arc owns its start: the convention, exactly (no tolerance: the same doubles).
        assert np.all(reg[~deg] == owner)
        y_phi, y_K = m.step(s, K)
        z_phi, z_K = m.step_inverse(y_phi, y_K)
        # Always: z is a float preimage of the image - step(z) gives it back bit for bit - at a
        # height the forward rounding of K + eps f merges with K (within ulp(Kbar)).
        b_phi, b_K = m.step(z_phi, z_K)
        assert np.array_equal(b_phi, y_phi) and np.array_equal(b_K, y_K)
        assert np.all(np.abs(z_K - K) <= ulp(y_K))
        nd = ~deg
        # Non-degenerate heights: z lies in the same arc; at the same height it is x, bit for bit.
        assert np.all(m.region(z_phi[nd], z_K[nd]) == owner)
        same = nd & (z_K == K)
        assert np.array_equal(z_phi[same], s[same])
        n_same += same.sum()
        n_merged += (nd & (z_K != K)).sum()
        # At a merged height z is that height's start (found by search) or, where the search finds
        # no height whose start has exactly this image, p - omega there: either way within what
        # the start and the rotation move between the two heights (from the API) plus 2 ulps of
        # |phi| + |omega| (the rounding of phi + omega and back).
        z_starts = m.corner_curves(z_K[nd])[key]
        w_x, w_z = m.rotation(s[nd], K[nd]), m.rotation(z_phi[nd], z_K[nd])
        tol = circ(z_starts, s[nd]) + np.abs(w_x - w_z) + 2 * ulp(np.abs(s[nd]) + np.abs(w_x))
        assert np.all(circ(z_phi[nd], s[nd]) <= tol)
    if m.eps == 0.0:
        assert n_merged == 0  # no height rounding: every start comes back bit for bit
    # (Measured: 85-100 % of the starts come back bit for bit; 17 % for J0_floor, whose band is
    # |K| < 0.05, where ulp(Kbar) spans up to ~1e4 doubles of K.)
    assert n_same > 0.1 * (n_same + n_merged)


@pytest.mark.parametrize("name", ALL)
def test_simd_kernel_follows_the_convention_at_the_arc_ends(name, rng):
    # Points on the starts and within 1e-300 .. 1e-9 of them, where the kernel's fast offset
    # test hands over to the comparison with the starts: phi and region of the first step
    # must equal step() / region() bit for bit.
    m = make(name)
    K = heights(m, rng, 200)
    cc = m.corner_curves(K)
    phis, Ks = [], []
    for key in ("01", "1R", "R0"):
        for d in (0.0, 1e-300, -1e-300, 1e-16, -1e-16, 4e-16, -4e-16, 1e-12, -1e-12, 1e-9, -1e-9):
            phis.append(hovering.wrap(cc[key] + d))
            Ks.append(K)
    phi, Kk = np.concatenate(phis), np.concatenate(Ks)
    want_phi, _ = m.step(phi, Kk)
    want_reg = m.region(phi, Kk)
    for kernel in ("simd", "scalar"):
        r = m.iterate(phi, Kk, 1, kernel=kernel, record=("regions",))
        assert np.array_equal(r.region[:, 0], want_reg)
        assert np.array_equal(r.phi_final, want_phi)


# ------------------------------------------------------------------------------------------------
# 4. Images near the band floor (and ceiling)


@pytest.mark.parametrize("name", ["paper+0.3", "paper-0.3", "J0_floor", "JR_floor", "Omega0~1e6", "family+"])
def test_step_inverse_accepts_every_image_near_the_band_edges(name, rng):
    m = make(name)
    lo, hi = m.valid_band()
    edges = [np.nextafter(lo, np.inf)] + [
        lo + d * max(1.0, abs(lo)) for d in (1e-16, 3e-16, 1e-15, 1e-14, 1e-13, 1e-12)
    ]
    if np.isfinite(hi):
        edges += [np.nextafter(hi, -np.inf)] + [hi - d * max(1.0, abs(hi)) for d in (1e-16, 1e-15, 1e-14, 1e-12)]
    K = np.repeat([k for k in edges if lo < k < hi], 500)
    phi = rng.uniform(-PI, PI, K.size)
    y_phi, y_K = m.step(phi, K)
    z_phi, z_K = m.step_inverse(y_phi, y_K)  # raised ValueError for ~1 in 100 of these before
    assert np.all((lo < z_K) & (z_K < hi))
    # Generic points (not within rounding of an arc end): back to x up to the rounding of the
    # step - ulp(Kbar) in K, and in phi 2 ulps of |phi| + |omega| plus what omega changes over
    # that change of K (rotation() of the same point at both heights).
    assert np.all(np.abs(z_K - K) <= ulp(y_K))
    w_x, w_z = m.rotation(phi, K), m.rotation(z_phi, z_K)
    assert np.all(circ(z_phi, phi) <= np.abs(w_x - w_z) + 2 * ulp(np.abs(phi) + np.abs(w_x)))
    # An image no band height is sent to is still refused, naming the preimage height.
    with pytest.raises(ValueError, match=r"step_inverse \(preimage\): K = .* is outside the band"):
        m.step_inverse(0.0, lo - 10.0 - abs(m.eps) * 4)


# ------------------------------------------------------------------------------------------------
# 5. SIMD vs scalar


def sine_bound(eps, p, K1, sin_ulp):
    """Largest |K_simd - K_scalar| after one step from the same state with the same phibar = p:
    the two sines differ by <= sin_ulp + 1 ulps of sin(p) (SLEEF's bound plus glibc's < 1 ulp;
    the ulp of the true sine, which can lie a binade above the computed one: hence the factor
    1 + 2^-50), scaled by |eps|, plus the rounding of eps sin (1 ulp) and of the sum (1 ulp of
    Kbar). It is nearly attained: measured up to 0.87-0.996 of it."""
    s = np.abs(np.sin(p))
    return np.abs(eps) * (sin_ulp + 1) * ulp(s * (1 + 2**-50)) + ulp(np.abs(eps) * s) + ulp(K1)


@pytest.mark.parametrize("sin_ulp", [1.0, 3.5])
@pytest.mark.parametrize("name", ["paper+0.3", "paper-0.3", "eps+0.92", "Omega0-2.5", "Omega0~1e6", "JR_floor"])
def test_simd_and_scalar_agree_bit_for_bit_in_phi_and_within_the_sine_bound_in_K(name, sin_ulp, rng):
    m = make(name)
    lo, hi = m.valid_band()
    n = 200_000
    phi = rng.uniform(-PI, PI, n)
    K = rng.uniform(max(lo, -10.0), min(hi, 3.0), n)
    v = m.iterate(phi, K, 1, kernel="simd", sin_ulp=sin_ulp, record=("regions",))
    s = m.iterate(phi, K, 1, kernel="scalar", record=("regions",))
    ok = (v.status == Status.OK) & (s.status == Status.OK)
    assert ok.mean() > 0.9  # the rest leave the band in one step (K within |eps| of its floor)
    # phi and region: same arithmetic, correctly rounded sqrt, no contraction: identical.
    assert np.array_equal(v.phi_final, s.phi_final)
    assert np.array_equal(v.region, s.region)
    dK = np.abs(v.K_final - s.K_final)[ok]
    bound = sine_bound(m.eps, s.phi_final, np.maximum(np.abs(s.K_final), np.abs(v.K_final)), sin_ulp)[ok]
    assert np.all(dK <= bound)
    # (Measured: K differs on 0.4-0.9 % of first steps with the 1-ulp sin, 4-9 % with the 3.5-ulp
    # one, by up to 4 ulps of max(|K|, |eps sin|) - many ulps of Kbar where the two cancel.)


@pytest.mark.parametrize("name", ["paper+0.3", "Omega0-2.5", "J0_floor", "family-"])
def test_every_simd_step_is_step_of_its_own_state(name, rng):
    # Along whole SIMD orbits (2000 steps, near-arc-end lanes included whenever they occur), each
    # recorded step re-done by step() from the recorded state gives the same phi and region bit
    # for bit, and K within the sine bound (F_eps) or its sum over the two modes (family).
    m = make(name)
    lo, hi = m.valid_band()
    phi0 = rng.uniform(-PI, PI, 256)
    K0 = rng.uniform(max(lo, -3.0), min(hi, 1.0), 256)
    r = m.iterate(phi0, K0, 2000, kernel="simd", record=("orbit", "regions"))
    for i in range(256):
        n = int(r.steps_done[i])
        p, k = r.phi[i, :n], r.K[i, :n]
        assert np.array_equal(m.region(p, k), r.region[i, :n])
        sp, sk = m.step(p, k)
        assert np.array_equal(sp, r.phi[i, 1 : n + 1])
        if isinstance(m, TruncatedMap):
            bound = sine_bound(m.eps, sp, sk, 1.0)
        else:  # f = sin(phi) + 0.25 sin(2 phi): each mode's sine bound, and one more sum rounding
            bound = sine_bound(m.eps, sp, sk, 1.0) + sine_bound(m.eps * 0.25, 2 * sp, sk, 1.0) + ulp(m.eps * np.sin(sp))
        assert np.all(np.abs(sk - r.K[i, 1 : n + 1]) <= bound)


# ------------------------------------------------------------------------------------------------
# Long orbits


@pytest.mark.parametrize("name", ["paper+0.3", "eps+0.92", "Omega0~1e6", "family+"])
@pytest.mark.parametrize("kernel", ["simd", "scalar"])
def test_long_orbits_never_leave_the_circle_or_the_reals(name, kernel, rng):
    m = make(name)
    lo, hi = m.valid_band()
    # In the band: near the floor, around the tangency circle, at the arc starts, and anywhere.
    K0 = np.concatenate(
        [[np.nextafter(lo, np.inf), lo + 1e-12, -1e-12, 0.0, 1e-12], rng.uniform(max(lo, -5.0), min(hi, 2.0), 11)]
    )
    phi0 = np.concatenate([m.corner_curves(np.array([-0.3]))["1R"], rng.uniform(-PI, PI, 15)])
    r = m.iterate(phi0, K0, 100_000, kernel=kernel, record=("orbit",))
    for i in range(K0.size):
        n = int(r.steps_done[i])
        kept = n + 1 if r.status[i] == Status.OK else n  # an ESCAPED orbit's last point is outside
        assert r.status[i] in (Status.OK, Status.ESCAPED)
        assert np.all((-PI <= r.phi[i, : n + 1]) & (r.phi[i, : n + 1] < PI))
        assert np.all(np.isfinite(r.K[i, :kept])) and np.all((lo < r.K[i, :kept]) & (r.K[i, :kept] < hi))
        assert np.all(np.isnan(r.phi[i, n + 1 :]))
    assert (r.status == Status.OK).sum() >= 8


def test_simd_width_is_what_the_build_uses():
    # the packet width the kernel was compiled for: AVX2 (4) or AVX-512 (8) builds report AVX2
    w = hovering.simd_width()
    assert w in (1, 2, 4, 8)
    assert hovering.simd_is_avx2() == (w >= 4)
