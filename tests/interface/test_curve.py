"""hovering.Curve: the periodic cubic spline through uniform samples, evaluated by the core.

Checked against exact answers (constants, the eps = 0 circles, interpolation at the samples), the
spline's error bound on smooth curves (the leading-order invariant curve k_eps1 of the theory, exp
cos), its h^4 convergence, the locality of its error at a kink, and, for curves made from orbits,
against held-out points of the same invariant circle and the map's invariance of the circle.
"""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import hovering
from hovering import Above, Below, Curve
from hovering.truncated import theory

FINE = np.linspace(-np.pi, np.pi, 100_001)[:-1]  # dense test angles, not on any sample grid used here


def paper(eps):
    return hovering.TruncatedMap(eps=eps, Omega0=hovering.OMEGA_G, theta_w=3 * np.pi / 4, tau0=1.0, tau1=0.5, lam=0.5)


# ------------------------------------------------------------------------------------------------
# exact cases


def test_samples_grid_and_interpolation_at_the_samples():
    rng = np.random.default_rng(0)
    K = rng.normal(size=37)
    c = Curve(K)
    assert c.n == 37 and c.error is None and np.isnan(c.max_error)
    assert np.array_equal(c.K, K)
    assert np.array_equal(c.phi, -np.pi + 2 * np.pi * np.arange(37) / 37)
    # at a sample the cell polynomial is K_j + 0 s (...): exact, except that phi_j may round into
    # the previous cell at s = 1 - 1e-16, where the polynomial is K_j to ~1e-15 of |K|
    assert np.abs(c(c.phi) - K).max() <= 1e-14 * np.abs(K).max()


def test_constant_curves_are_exact_everywhere():
    for c in (Curve.constant(0.3), Curve([0.3]), Curve(np.full(16, 0.3)), Curve.from_function(lambda p: 0.3, n=8)):
        assert np.all(c(FINE) == 0.3)
    assert Curve.from_function(lambda p: 0.3, n=8).max_error == 0.0
    assert repr(Curve.constant(0.3)) == "Curve.constant(0.3)"


def test_from_orbit_of_an_eps0_circle_is_that_circle():
    # At eps = 0 every orbit keeps its K exactly: the curve from the orbit is K0 everywhere, with error 0.
    m = paper(0.0)
    r = m.iterate([0.2], [0.37], 5000, record=("orbit",))
    assert np.all(r.K == 0.37)
    c = Curve.from_orbit(r.phi, r.K, n=64)
    assert np.all(c.K == 0.37) and np.all(c(FINE) == 0.37) and c.max_error == 0.0


def test_evaluation_is_vectorised_and_wraps_every_angle():
    c = Curve.from_function(lambda p: np.sin(p) + 0.2 * np.cos(2 * p), n=50)
    phi = np.random.default_rng(1).uniform(-np.pi, np.pi, (7, 9))
    out = c(phi)
    assert out.shape == (7, 9)
    assert isinstance(c(0.5), float) and c(0.5) == c(np.array([0.5]))[0]
    # any angle is first wrapped to [-pi, pi) with the package's wrap: bit for bit the same value
    far = phi[None] + 2 * np.pi * np.arange(-4, 5)[:, None, None]
    assert np.array_equal(c(far), c(hovering.wrap(far)))
    assert np.abs(c(far) - out).max() < 1e-13  # wrap loses ~ulp(8 pi) of the angle, |K'| < 2
    assert np.isnan(c(np.nan)) and np.isnan(c([0.1, np.nan])[1])
    assert c(np.pi) == c(-np.pi)
    for bad in (np.inf, -np.inf, 2e6):
        with pytest.raises(ValueError, match="phi"):
            c(bad)


# ------------------------------------------------------------------------------------------------
# accuracy


@pytest.mark.parametrize("eps,K0", [(0.3, 0.6), (0.05, 0.3), (-0.2, 1.0)])
@pytest.mark.parametrize("n", [16, 64, 256])
def test_interpolation_error_on_the_leading_order_invariant_curve(eps, K0, n):
    # k_eps1 = K0 + eps (1 - cos(phi + a)) / (2 sin a): |k''''| <= |eps| / (2 |sin a|). The periodic
    # cubic spline's error is <= 5/384 h^4 max|k''''| (h = 2 pi / n); 1e-15 for rounding.
    p = paper(eps).params
    f = lambda phi: theory.k_eps1(phi, K0, eps, p["Omega0"], p["tau0"])  # noqa: E731
    a = 0.5 * (p["Omega0"] + p["tau0"] * K0)
    bound = 5 / 384 * (2 * np.pi / n) ** 4 * abs(eps) / (2 * abs(np.sin(a))) + 1e-15
    c = Curve.from_function(f, n=n)
    err = np.abs(c(FINE) - f(FINE)).max()
    assert err <= bound
    # the error estimate (deviation at the cell midpoints) is the error, for such a smooth curve
    # (x 1.01: FINE holds points within 3e-5 h of the midpoints, not the midpoints themselves)
    assert 0.9 * err <= c.max_error <= 1.01 * err


def test_fourth_order_convergence_on_a_smooth_curve():
    # exp(cos phi) is analytic: doubling n divides the spline's error by 2^4 = 16 asymptotically
    # (measured 16.4, 16.1, 16.0 from n = 32); [14, 18] would fail a second- or trigonometric-order
    # interpolant (ratios 4 or >> 100).
    f = lambda p: np.exp(np.cos(p))  # noqa: E731
    errs = [np.abs(Curve.from_function(f, n=n)(FINE) - f(FINE)).max() for n in (32, 64, 128, 256)]
    ratios = np.array(errs[:-1]) / np.array(errs[1:])
    assert np.all((ratios > 14) & (ratios < 18)), ratios


def test_error_at_a_kink_stays_local():
    # |phi - 0.3| (wrapped) has kinks at 0.3 and 0.3 - pi. The spline's error is largest in the
    # kink's cell (~h / 16 measured) and decays by 2 - sqrt(3) = 0.268 per cell away from it:
    # within a factor 2 of 0.268^d (relative to the kink cell) in the cells d = 1..10 cells away.
    n = 128
    h = 2 * np.pi / n
    f = lambda p: np.abs(hovering.wrap(p - 0.3))  # noqa: E731
    c = Curve.from_function(f, n=n)
    e = np.abs(c(FINE) - f(FINE))
    d = np.minimum(np.abs(hovering.wrap(FINE - 0.3)), np.abs(hovering.wrap(FINE - 0.3 + np.pi))) / h
    e0 = e[d < 1].max()
    assert 0.02 * h < e0 < 0.2 * h
    for k in range(1, 11):
        ek = e[(d >= k) & (d < k + 1)].max()
        assert 0.5 * (2 - np.sqrt(3)) ** k < ek / e0 < 2 * (2 - np.sqrt(3)) ** k, k
    # the error estimate shows the kink: from_function's error is largest in the kink's cells
    assert c.max_error >= 0.5 * e0 and c.error[np.argmin(np.abs(hovering.wrap(c.phi - 0.3)))] >= 0.25 * e0


@pytest.mark.parametrize("eps,K0", [(0.3, 0.6), (0.3, 1.0), (0.05, 0.3)])
def test_from_orbit_recovers_an_invariant_circle_to_its_bin_error(eps, K0):
    # The orbit through L1 at K0 fills an invariant circle (a graph over phi, no impact: regions
    # '0u' / '0' only). A curve from its first 20000 points must hold the next 20000 (not used to
    # build it) to its own error estimate (x 1.5: the estimate is the largest deviation of the points it was
    # built from, measured 1.00 of the held-out one), and the map must carry the curve into
    # itself: F(phi, c(phi)) lies on c to ~ the error times the map's stretch (measured <= 1.3).
    m = paper(eps)
    r = m.iterate([m.L1(K0)], [K0], 40_000, record=("orbit", "regions"))
    assert r.status[0] == hovering.Status.OK and np.all(
        np.isin(r.region, [hovering.Region.BESIDE, hovering.Region.ABOVE])
    )
    phi, K = r.phi[0], r.K[0]
    c = Curve.from_orbit(phi[:20_000], K[:20_000], n=256)
    assert c.n == 256 and c.error.shape == (256,)
    assert 0 < c.max_error < 1e-7  # the spline's h^4 error: a circle, not a layer
    assert np.abs(K[20_000:] - c(phi[20_000:])).max() <= 1.5 * c.max_error
    g = np.linspace(-np.pi, np.pi, 5000, endpoint=False)
    P, Q = m.step(g, c(g))
    assert np.abs(Q - c(P)).max() <= 4 * c.max_error


def test_from_orbit_agrees_with_the_theory_to_second_order_in_eps():
    # k_eps1 is the invariant circle to O(eps^2): the deviation of the curve from an orbit, over
    # eps^2, is ~0.56 for K0 = 0.6 (measured at eps = 0.05 and 0.3) and must not grow as eps -> 0.
    devs = []
    for eps in (0.1, 0.05, 0.025):
        m = paper(eps)
        p = m.params
        r = m.iterate([m.L1(0.6)], [0.6], 20_000, record=("orbit",))
        c = Curve.from_orbit(r.phi, r.K, n=256)
        devs.append(np.abs(c(FINE) - theory.k_eps1(FINE, 0.6, eps, p["Omega0"], p["tau0"])).max() / eps**2)
    assert all(0.3 < d < 1.0 for d in devs), devs


def test_from_orbit_default_size_and_dropped_padding():
    m = paper(0.3)
    r = m.iterate([m.L1(0.6)], [0.6], 800, record=("orbit",))
    padded = np.concatenate([r.phi[0], [np.nan] * 5])
    c = Curve.from_orbit(padded, np.concatenate([r.K[0], [np.nan] * 5]))
    assert c.n == 801 // 8  # about 8 points per bin
    assert c == Curve.from_orbit(r.phi[0], r.K[0])


def test_from_orbit_default_size_lowers_itself_until_every_bin_holds_a_point():
    # points clustered in 400 groups (an orbit near the rotation 1/400): N // 8 = 1000 bins would
    # leave most empty; the default takes the most bins whose width exceeds the widest gap.
    phi = (-np.pi + 2 * np.pi * np.arange(400) / 400)[:, None] + 1e-4 * np.arange(20)[None, :]
    K = 0.1 * np.sin(phi)
    c = Curve.from_orbit(phi, K)
    widest = 2 * np.pi / 400 - 19e-4
    assert c.n == int(0.999 * 2 * np.pi / widest) <= 8000 // 8
    # samples interpolate linearly across gaps: error <= max|K''| gap**2 / 8 (the spline adds ~1e-11)
    assert np.max(np.abs(c(FINE) - 0.1 * np.sin(FINE))) < 1.01 * 0.1 * widest**2 / 8
    with pytest.raises(ValueError, match="bins empty"):
        Curve.from_orbit(phi, K, n=1000)  # an explicit n is kept, and refused


# ------------------------------------------------------------------------------------------------
# pickling and saving


def test_curves_and_stop_conditions_pickle_and_save(tmp_path):
    c = Curve.from_function(lambda p: 0.2 + 0.1 * np.cos(3 * p), n=40)
    for obj in (c, Above(c), Below(0.25), Curve.constant(-1.5)):
        back = pickle.loads(pickle.dumps(obj))
        assert back == obj and type(back) is type(obj)
        loaded = hovering.load(hovering.save(obj, tmp_path / f"{type(obj).__name__}.npz"))
        assert loaded == obj and type(loaded) is type(obj)
    back = pickle.loads(pickle.dumps(c))
    assert np.array_equal(back(FINE), c(FINE)) and np.array_equal(back.error, c.error)


def test_a_curve_record_is_validated_on_load():
    with pytest.raises(ValueError, match="a curve's record has the fields K and error"):
        Curve._from_record({"K": np.ones(4), "extra": 1})
    with pytest.raises(ValueError, match=r"K \(curve samples\)"):
        Curve._from_record({"K": np.array([1.0, np.nan, 2.0]), "error": None})


# ------------------------------------------------------------------------------------------------
# bad input


@pytest.mark.parametrize(
    "K,match",
    [
        ([1.0, 2.0], r"the number of samples must be 1 \(a constant\) or in \[3, 16777216\].*got 2"),
        ([], r"the number of samples must be 1 \(a constant\) or in \[3, 16777216\]"),
        (np.ones((3, 3)), r"K \(curve samples\) must be a 1-D array, got shape \(3, 3\)"),
        ([0.1, np.nan, 0.2, 0.3], r"K \(curve samples\)"),
        ([0.1, 0.2, np.inf], r"K \(curve samples\)"),
        (["a", "b", "c"], r"K \(curve samples\)"),
    ],
)
def test_bad_samples(K, match):
    with pytest.raises(ValueError, match=match):
        Curve(K)


def test_bad_error_estimates():
    with pytest.raises(ValueError, match=r"error must have the shape of K \(4,\), got \(3,\)"):
        Curve(np.ones(4), error=np.zeros(3))
    with pytest.raises(ValueError, match=r"error must be >= 0, got -1.0 at sample 2"):
        Curve(np.ones(4), error=[0, 0, -1.0, 0])


def test_bad_functions_and_sizes():
    with pytest.raises(ValueError, match=r"n must be 1 \(a constant\) or in \[3, 16777216\]"):
        Curve.from_function(np.cos, n=2)
    with pytest.raises(ValueError, match=r"n must be an integer"):
        Curve.from_function(np.cos, n=10.5)
    with pytest.raises(ValueError, match=r"f must be a callable"):
        Curve.from_function(0.3)
    with pytest.raises(ValueError, match=r"f\(phi\) must return an array of the shape of phi"):
        Curve.from_function(lambda p: np.ones(3), n=8)
    with pytest.raises(ValueError, match=r"f\(phi\)"):
        Curve.from_function(lambda p: np.where(p > 0, 1.0, np.nan), n=8)


def test_bad_orbits():
    with pytest.raises(ValueError, match=r"phi and K must have the same number of points, got 3 and 2"):
        Curve.from_orbit([0.0, 1.0, 2.0], [0.0, 1.0])
    with pytest.raises(ValueError, match=r"an orbit needs at least 3 points"):
        Curve.from_orbit([0.0, np.nan, 1.0], [0.1, 0.2, 0.3])
    # points in half of the circle only: empty bins, named with the widest gap
    with pytest.raises(
        ValueError, match=r"the orbit leaves 16 of the n = 32 bins empty \(its widest gap in phi is 3\.2"
    ):
        Curve.from_orbit(np.linspace(0.0, 3.0, 300), np.ones(300), n=32)
    with pytest.raises(ValueError, match=r"n must be in \[3, 2\*\*24\] for a curve from an orbit, got 1"):
        Curve.from_orbit(np.linspace(-3, 3, 30), np.ones(30), n=1)
