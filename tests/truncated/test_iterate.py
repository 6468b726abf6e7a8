"""Batch iteration TruncatedMap.iterate: result layout, statuses, exit detection, kernels, threads.

Orbits are checked against the independent NumPy implementation (numpy_reference.iterate) with a
propagated round-off bound, and against single steps of the same map.
"""

from __future__ import annotations

import zlib

import numpy as np
import pytest

from conftest import (
    LOCAL_ROUNDOFF,
    PARAM_SETS,
    band_sample,
    cdiff,
    error_bound,
    make_map,
    omega_prime,
    safe_mask,
)
from helpers import numpy_reference as ref
from hovering import Region, Status

KERNELS = ("simd", "scalar")


@pytest.fixture
def paper_map():
    return make_map(PARAM_SETS["paper_eps+0.3"])


def _reference_orbits(m, phi0, K0, n, margin):
    """Reference orbits, and a mask of those that stay `margin` away from every discontinuity."""
    rp, rK, rreg, rrho = ref.iterate(phi0, K0, n, m.params)
    ok = np.all(np.isfinite(rK), axis=1)
    ok[ok] = np.all(safe_mask(m, rp[ok, :-1], rK[ok, :-1], margin), axis=1)
    ok[ok] &= rK[ok, -1] > m.valid_band()[0] + margin  # the last image is still inside the band
    return rp, rK, rreg, rrho, ok


# ------------------------------------------------------------------------------------------------
# layout


@pytest.mark.parametrize("kernel", KERNELS)
def test_result_shapes_and_record_selection(paper_map, rng, kernel):
    m = paper_map
    n_orb, n = 37, 11
    phi0, K0 = band_sample(m, n_orb, rng, K_hi=0.5, margin=1.0)
    res = m.iterate(phi0, K0, n, kernel=kernel)
    assert res.n_orbits == n_orb and res.n_steps == n
    assert res.phi.shape == res.K.shape == (n_orb, n + 1)
    assert res.region.shape == (n_orb, n) and res.region.dtype == np.int8
    assert res.rotation.shape == (n_orb,)
    assert res.phi_final.shape == res.K_final.shape == res.status.shape == res.steps_done.shape == (n_orb,)
    assert res.exit_step is None  # no exit_regions given
    assert np.array_equal(res.phi[:, 0], phi0) and np.array_equal(res.K[:, 0], K0)

    for record, present in (
        (("rotation",), {"rotation"}),
        ("orbit", {"phi", "K"}),  # a single string is accepted
        (("regions",), {"region"}),
        ((), set()),
        (("orbit", "regions"), {"phi", "K", "region"}),
    ):
        r = m.iterate(phi0, K0, n, record=record, kernel=kernel)
        for attr in ("phi", "K", "region", "rotation"):
            assert (getattr(r, attr) is not None) == (attr in present), (record, attr)
        # the final state does not depend on what is recorded
        assert np.array_equal(r.phi_final, res.phi_final) and np.array_equal(r.K_final, res.K_final)
        assert np.array_equal(r.status, res.status) and np.array_equal(r.steps_done, res.steps_done)
        if "rotation" in present:
            assert np.array_equal(r.rotation, res.rotation)
        if "region" in present:
            assert np.array_equal(r.region, res.region)


def test_scalar_and_broadcast_initial_points(paper_map):
    m = paper_map
    r = m.iterate(0.4, -0.5, 5)
    assert r.n_orbits == 1 and r.phi.shape == (1, 6) and r.region.shape == (1, 5)
    ra = m.iterate(np.array([0.4]), np.array([-0.5]), 5)
    assert np.array_equal(r.phi, ra.phi) and np.array_equal(r.K, ra.K)
    # a row of phases against one height; a 2-D grid is flattened to n_orbits orbits
    rb = m.iterate(np.linspace(-3, 3, 7), 0.2, 4)
    assert rb.phi.shape == (7, 5) and np.all(rb.K[:, 0] == 0.2)
    rc = m.iterate(np.zeros((3, 4)), np.linspace(-1, 1, 4), 2)
    assert rc.phi.shape == (12, 3)
    assert np.array_equal(rc.K[:, 0], np.tile(np.linspace(-1, 1, 4), 3))
    # numpy integer n_steps is an integer
    assert m.iterate(0.4, -0.5, np.int64(3)).phi.shape == (1, 4)


def test_zero_steps(paper_map):
    m = paper_map
    res = m.iterate([0.1, 0.2], [0.0, -1.0], 0)
    assert res.phi.shape == (2, 1) and res.region.shape == (2, 0)
    assert np.all(res.status == Status.OK) and np.all(res.steps_done == 0)
    assert np.all(np.isnan(res.rotation))  # the mean over no step is undefined
    assert np.array_equal(res.phi_final, [0.1, 0.2]) and np.array_equal(res.K_final, [0.0, -1.0])


def test_iterate_equals_repeated_steps(any_map, rng):
    """The scalar kernel and step() share the libm arithmetic: identical orbits, even if chaotic."""
    m = any_map
    phi0, K0 = band_sample(m, 300, rng, K_hi=1.0, margin=0.5)
    n = 300
    res = m.iterate(phi0, K0, n, kernel="scalar")
    alive = np.ones(phi0.size, bool)
    p, k = phi0.copy(), K0.copy()
    lo = m.valid_band()[0]
    for j in range(n):
        alive &= res.steps_done > j
        if not alive.any():
            break
        reg = m.region(p[alive], k[alive])
        assert np.array_equal(res.region[alive, j], reg)
        p[alive], k[alive] = m.step(p[alive], k[alive])
        assert np.array_equal(res.phi[alive, j + 1], p[alive])
        assert np.array_equal(res.K[alive, j + 1], k[alive])
    esc = res.status == Status.ESCAPED
    assert np.all(res.K_final[esc] <= lo) and np.all(res.status[~esc] == Status.OK)


# ------------------------------------------------------------------------------------------------
# 4. agreement with the NumPy reference


@pytest.mark.parametrize("kernel", KERNELS)
def test_iterate_matches_numpy_reference_few_steps(any_map, rng, kernel):
    m = any_map
    n = 8  # chaotic orbits: only a few steps before 1-ulp differences of sin are amplified
    phi0, K0 = band_sample(m, 3000, rng, K_hi=1.0, margin=0.05)
    rp, rK, rreg, rrho, ok = _reference_orbits(m, phi0, K0, n, margin=1e-6)
    bound = error_bound(rp[ok], rK[ok], m.params)
    small = bound.max(axis=1) < 1e-9  # << the 1e-6 distance to any discontinuity
    idx = np.flatnonzero(ok)[small]
    bound = bound[small]
    assert idx.size > 1500
    res = m.iterate(phi0[idx], K0[idx], n, kernel=kernel)
    assert np.all(res.status == Status.OK)
    # regions: identical (every point is 1e-6 from a discontinuity, errors are < 1e-9)
    assert np.array_equal(res.region.astype(int), rreg[idx])
    # Tolerance: 10 x the first-order round-off bound propagated along the reference orbit
    # (conftest.error_bound; factor 2 for two implementations, 5 for the linearisation).
    assert np.all(cdiff(res.phi, rp[idx]) <= 10 * bound)
    assert np.all(np.abs(res.K - rK[idx]) <= 10 * bound)
    # rho = mean omega_a: with identical regions |d omega_j| <= |omega'(K_j)| e_j + round-off, so
    # |d rho| <= 10 x (max_j |omega'_j| bound_j + LOCAL_ROUNDOFF)   (same factor 10 as above)
    wp = np.abs(omega_prime(rp[idx, :-1], rK[idx, :-1], m.params))
    tol_rho = 10 * ((wp * bound[:, :-1]).max(axis=1) + LOCAL_ROUNDOFF)
    assert np.all(np.abs(res.rotation - rrho[idx]) <= tol_rho)


def test_scalar_kernel_matches_numpy_reference_long_run(rng):
    """Longer runs on regular orbits of the shifted standard map (K > 0, eps tau0 = 0.3 < 0.97)."""
    m = make_map(PARAM_SETS["paper_eps+0.3"])
    n = 100
    phi0 = rng.uniform(-np.pi, np.pi, 300)
    K0 = rng.uniform(0.6, 1.2, 300)
    rp, rK, rreg, rrho, ok = _reference_orbits(m, phi0, K0, n, margin=1e-6)
    bound = error_bound(rp[ok], rK[ok], m.params)
    small = bound.max(axis=1) < 1e-9
    idx = np.flatnonzero(ok)[small]
    bound = bound[small]
    assert idx.size > 100  # most of these orbits lie on KAM circles: round-off grows only linearly
    res = m.iterate(phi0[idx], K0[idx], n, kernel="scalar")
    assert np.array_equal(res.region.astype(int), rreg[idx])
    # same 10 x propagated-bound tolerance as above
    assert np.all(cdiff(res.phi, rp[idx]) <= 10 * bound)
    assert np.all(np.abs(res.K - rK[idx]) <= 10 * bound)


@pytest.mark.parametrize("name", list(PARAM_SETS))
def test_simd_and_scalar_kernels_agree(name, rng):
    m = make_map(PARAM_SETS[name])
    n = 10
    phi0, K0 = band_sample(m, 2000, rng, K_hi=1.0, margin=0.05)
    rp, rK, _, _, ok = _reference_orbits(m, phi0, K0, n, margin=1e-6)
    bound = error_bound(rp[ok], rK[ok], m.params)
    small = bound.max(axis=1) < 1e-9
    idx = np.flatnonzero(ok)[small]
    bound = bound[small]
    a = m.iterate(phi0[idx], K0[idx], n, kernel="simd")
    b = m.iterate(phi0[idx], K0[idx], n, kernel="scalar")
    assert np.array_equal(a.status, b.status) and np.array_equal(a.region, b.region)
    # SLEEF's vector sin and libm's sin differ by <= 1 ulp: 10 x propagated bound (see conftest)
    assert np.all(cdiff(a.phi, b.phi) <= 10 * bound)
    assert np.all(np.abs(a.K - b.K) <= 10 * bound)


@pytest.mark.parametrize("kernel", KERNELS)
def test_thread_count_does_not_change_results(kernel, rng):
    m = make_map(PARAM_SETS["paper_eps+0.92"])
    phi0, K0 = band_sample(m, 5000, rng, K_hi=1.0)
    r1 = m.iterate(phi0, K0, 200, n_threads=1, kernel=kernel, exit_regions={"0u", "0"})
    r2 = m.iterate(phi0, K0, 200, n_threads=2, kernel=kernel, exit_regions={"0u", "0"})
    r0 = m.iterate(phi0, K0, 200, n_threads=0, kernel=kernel, exit_regions={"0u", "0"})
    assert np.count_nonzero(r1.status == Status.ESCAPED) > 0  # chunks of different lengths
    for r in (r2, r0):
        for attr in ("phi", "K", "region", "rotation", "phi_final", "K_final", "status", "steps_done", "exit_step"):
            assert np.array_equal(
                getattr(r1, attr),
                getattr(r, attr),
                equal_nan=attr not in ("region", "status", "steps_done", "exit_step"),
            ), attr


# ------------------------------------------------------------------------------------------------
# rotation


@pytest.mark.parametrize("kernel", KERNELS)
def test_rotation_is_mean_of_omega_over_points(any_map, rng, kernel):
    m = any_map
    n = 200
    phi0, K0 = band_sample(m, 400, rng, K_hi=1.0, margin=0.3)
    res = m.iterate(phi0, K0, n, kernel=kernel)
    assert res.count(Status.ESCAPED) + res.count(Status.OK) == res.n_orbits
    for i in range(res.n_orbits):
        k = res.steps_done[i]
        if k == 0:
            assert np.isnan(res.rotation[i])
            continue
        w = m.rotation(res.phi[i, :k], res.K[i, :k])
        # Tolerance: a sum of k <= 200 terms |w| < 16 in another order: <= k ulp(16 k)/k ~ 1e-12.
        assert res.rotation[i] == pytest.approx(w.mean(), abs=1e-12)
        # the recorded regions are those of the recorded points
        assert np.array_equal(res.region[i, :k], m.region(res.phi[i, :k], res.K[i, :k]))


# ------------------------------------------------------------------------------------------------
# statuses


@pytest.mark.parametrize("kernel", KERNELS)
def test_escape_through_band_floor(paper_map, kernel):
    m = paper_map
    p = m.params
    lo = m.valid_band()[0]
    n_orb = 4000
    phi0 = np.linspace(-np.pi, np.pi, n_orb, endpoint=False)
    K0 = np.full(n_orb, lo + 1e-3)
    n = 5
    res = m.iterate(phi0, K0, n, kernel=kernel)
    # the first image, from the reference
    r1p, r1K = ref.step(phi0, K0, p)
    clear = np.abs(r1K - lo) > 1e-12  # round-off can't decide escapes closer than this
    esc1 = clear & (r1K < lo)
    stay1 = clear & (r1K > lo)
    assert esc1.sum() > 500 and stay1.sum() > 500
    assert np.all(res.status[esc1] == Status.ESCAPED)
    assert np.all(res.steps_done[esc1] == 1)
    # the escaped image is kept as the final state (outside the band), tails are NaN / NONE
    # tolerance 1e-12: one step of round-off against the reference (see test_truncated_map)
    assert np.all(res.K_final[esc1] <= lo)
    assert np.all(np.abs(res.K_final[esc1] - r1K[esc1]) <= 1e-12)
    assert np.all(cdiff(res.phi_final[esc1], r1p[esc1]) <= 1e-12)
    assert np.array_equal(res.phi[esc1, 1], res.phi_final[esc1])
    assert np.array_equal(res.K[esc1, 1], res.K_final[esc1])
    assert np.all(np.isnan(res.phi[esc1, 2:])) and np.all(np.isnan(res.K[esc1, 2:]))
    assert np.array_equal(res.region[esc1, 0].astype(int), ref.region(phi0[esc1], K0[esc1], p))
    assert np.all(res.region[esc1, 1:] == Region.NONE)
    assert np.allclose(res.rotation[esc1], ref.rotation(phi0[esc1], K0[esc1], p), rtol=0, atol=1e-12)
    # those that stayed took at least 2 steps
    assert np.all(res.steps_done[stay1] >= 2)
    # every escape, at whatever step: final K outside the band, the orbit is finite up to it
    esc = res.status == Status.ESCAPED
    for i in np.flatnonzero(esc):
        k = res.steps_done[i]
        assert res.K[i, k] == res.K_final[i] and res.K_final[i] <= lo
        assert np.all(res.K[i, :k] > lo)
        assert np.all(np.isnan(res.K[i, k + 1 :]))
    ok = res.status == Status.OK
    assert np.all(res.steps_done[ok] == n) and np.all(np.isfinite(res.K[ok]))


@pytest.mark.parametrize("kernel", KERNELS)
def test_escape_through_K_max(kernel):
    m = make_map(PARAM_SETS["paper_eps+0.3"], K_max=0.5)
    phi0 = np.linspace(-np.pi, np.pi, 1000, endpoint=False)
    res = m.iterate(phi0, 0.45, 3, kernel=kernel)
    esc = res.status == Status.ESCAPED
    assert esc.sum() > 100
    assert np.all(res.K_final[esc] >= 0.5)
    assert np.all(res.K_final[~esc] < 0.5)


@pytest.mark.parametrize("kernel", KERNELS)
def test_initial_point_outside_band(paper_map, kernel):
    m = paper_map
    lo = m.valid_band()[0]
    phi0 = np.array([0.3, -1.0, 2.0, 0.5])
    K0 = np.array([lo - 0.1, lo, -0.5, -100.0])  # lo itself is outside: the band is open
    res = m.iterate(phi0, K0, 4, kernel=kernel)
    out = np.array([True, True, False, True])
    assert np.all(res.status[out] == Status.ESCAPED) and np.all(res.steps_done[out] == 0)
    assert np.array_equal(res.phi_final[out], phi0[out]) and np.array_equal(res.K_final[out], K0[out])
    assert np.array_equal(res.phi[out, 0], phi0[out]) and np.all(np.isnan(res.phi[out, 1:]))
    assert np.all(res.region[out] == Region.NONE)
    assert np.all(np.isnan(res.rotation[out]))
    assert res.status[2] == Status.OK and res.steps_done[2] == 4


# ------------------------------------------------------------------------------------------------
# exit_regions / stop_on_exit


def _first_exit(region, allowed):
    """First n with a recorded region outside `allowed` (NONE entries are not points), else -1."""
    bad = (region >= 0) & ~np.isin(region, list(allowed))
    return np.where(bad.any(axis=1), np.argmax(bad, axis=1), -1)


@pytest.mark.parametrize("kernel", KERNELS)
@pytest.mark.parametrize(
    "allowed_names,allowed", [({"0u", "0"}, {0, 1}), (["RIGHT"], {3}), ({"BESIDE", "1", 3}, {0, 2, 3})]
)
def test_exit_step_and_stop_on_exit(any_map, rng, kernel, allowed_names, allowed):
    m = any_map
    n = 60
    phi0, K0 = band_sample(m, 1500, rng, K_hi=0.6, margin=0.2)
    res = m.iterate(phi0, K0, n, exit_regions=allowed_names, kernel=kernel)
    expected = _first_exit(res.region, allowed)
    assert np.array_equal(res.exit_step, expected)
    assert (expected >= 0).sum() > 50  # the test exercises exits ...
    if allowed != {3}:
        assert (expected == -1).sum() > 50  # ... and orbits that stay in the set
    # watching changes nothing else
    plain = m.iterate(phi0, K0, n, kernel=kernel)
    for attr in ("phi", "K", "region", "status", "steps_done"):
        assert np.array_equal(getattr(res, attr), getattr(plain, attr), equal_nan=attr in ("phi", "K"))

    st = m.iterate(phi0, K0, n, exit_regions=allowed_names, stop_on_exit=True, kernel=kernel)
    assert np.array_equal(st.exit_step, expected)
    ex = expected >= 0
    assert np.all(st.status[ex] == Status.EXITED)
    assert np.array_equal(st.steps_done[ex], expected[ex])
    # the state kept is the first point outside the set, i.e. x_{exit_step} of the full run
    rows = np.flatnonzero(ex)
    assert np.array_equal(st.phi_final[ex], res.phi[rows, expected[ex]])
    assert np.array_equal(st.K_final[ex], res.K[rows, expected[ex]])
    for i in rows:
        k = expected[i]
        assert np.array_equal(st.phi[i, : k + 1], res.phi[i, : k + 1])
        assert np.all(np.isnan(st.phi[i, k + 1 :]))
        # the exiting return is recorded (its region, outside the set), though not taken; after it, padding
        assert np.array_equal(st.region[i, : k + 1], res.region[i, : k + 1])
        assert int(st.region[i, k]) not in allowed
        assert np.all(st.region[i, k + 1 :] == Region.NONE)
        if k > 0:  # mean omega over the k steps taken (1e-12: k <= 60 terms summed in another order)
            assert st.rotation[i] == pytest.approx(m.rotation(res.phi[i, :k], res.K[i, :k]).mean(), abs=1e-12)
        else:
            assert np.isnan(st.rotation[i])  # no step taken
    # orbits that never left are untouched
    assert np.array_equal(st.status[~ex], res.status[~ex])
    assert np.array_equal(st.phi[~ex], res.phi[~ex], equal_nan=True)


def test_exit_with_all_regions_never_fires(paper_map, rng):
    m = paper_map
    phi0, K0 = band_sample(m, 500, rng, K_hi=0.5, margin=0.5)
    res = m.iterate(phi0, K0, 50, exit_regions=["0u", "0", "1", "R"], stop_on_exit=True)
    assert np.all(res.exit_step == -1)
    assert res.count(Status.EXITED) == 0


# ------------------------------------------------------------------------------------------------
# 6. bad input


BAD_ITERATE = [
    (dict(n_steps=-1), r"n_steps must be >= 0, got -1"),
    (dict(n_steps=2.5), r"n_steps must be an integer >= 0, got 2\.5"),
    (dict(n_steps="3"), r"n_steps must be an integer >= 0"),
    (dict(n_steps=None), r"n_steps must be an integer >= 0"),
    (
        dict(record=("orbit", "foo")),
        r"record: unknown key\(s\) \['foo'\]; allowed: \['orbit', 'regions', 'rotation', 'visited', 'extrema', 'residence', 'jacobian'\]",
    ),
    (dict(record="orbits"), r"record: unknown key\(s\) \['orbits'\]; allowed"),
    (
        dict(exit_regions=["X"]),
        r"unknown region 'X'; allowed: BESIDE \('0u'\), ABOVE \('0'\), UPPER \('1'\), RIGHT \('R'\), MULTI \('m'\)",
    ),
    (dict(exit_regions=[9]), r"unknown region 9; allowed"),
    (dict(exit_regions=[]), r"exit_regions must name at least one region"),
    (dict(stop_on_exit=True), r"stop_on_exit needs exit_regions"),
    (dict(kernel="avx"), r"kernel must be 'simd' or 'scalar', got 'avx'"),
    (dict(n_threads=-1), r"n_threads must be an integer in \[0, 4096\] \(0 = all cores\), got -1"),
    (dict(n_threads=2**29), r"n_threads must be an integer in \[0, 4096\]"),
    (dict(phi0=[0.0, np.nan]), r"phi0\[1\] must be finite"),
    (dict(K0=[np.inf, 0.0]), r"K0\[0\] must be finite"),
    (dict(phi0=[np.inf, 0.0]), r"phi0\[0\] must be finite"),
    (dict(phi0=np.zeros(3), K0=np.zeros(4)), r"phi0 and K0 must have broadcastable shapes"),
]


@pytest.mark.parametrize("kw,match", BAD_ITERATE, ids=[str(i) for i in range(len(BAD_ITERATE))])
def test_bad_iterate_arguments(paper_map, kw, match):
    args = dict(phi0=[0.1, 0.2], K0=[0.0, -0.5], n_steps=3)
    args.update(kw)
    with pytest.raises(ValueError, match=match):
        paper_map.iterate(**args)


@pytest.mark.parametrize("name", list(PARAM_SETS))
def test_each_recorded_state_is_the_final_state_of_a_run_that_long(name):
    # The SIMD kernel buffers the recorded states and regions and writes them in blocks per
    # orbit; the final state of a run goes another way (written when the orbit stops). So x_n of
    # a recorded run is checked, bit for bit, against the final state of a run of n steps (the same
    # kernel and the same operations, whatever lane an orbit lands in), and the recorded region of
    # the return from x_n against m.region(x_n). Orbits outnumber the lanes (refills), some escape
    # through the band floor or stop mid-block (padding), and the lengths straddle block ends.
    m = make_map(PARAM_SETS[name])
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    phi0, K0 = band_sample(m, 150, rng, K_hi=0.8)
    for n_steps, every in ((95, 1), (64, 1), (70, 3), (33, 32), (131, 7)):
        rec = m.iterate(phi0, K0, n_steps, record=("orbit", "regions"), every=every, n_threads=1)
        assert 0 < rec.count(Status.ESCAPED) < phi0.size or name == "paper_eps+0.92"
        for col, n in enumerate(range(0, n_steps + 1, every)):
            short = m.iterate(phi0, K0, n, n_threads=1)
            reached = rec.steps_done >= n
            assert np.array_equal(rec.phi[reached, col], short.phi_final[reached])
            assert np.array_equal(rec.K[reached, col], short.K_final[reached])
            assert np.all(np.isnan(rec.phi[~reached, col]) & np.isnan(rec.K[~reached, col]))
            if n < n_steps:
                taken = rec.steps_done > n
                assert np.array_equal(rec.region[taken, col], m.region(rec.phi[taken, col], rec.K[taken, col]))
                assert np.all(rec.region[~taken, col] == Region.NONE)
