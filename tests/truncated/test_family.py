"""The general truncated family F_{eps1,eps2} (eq:trunceps1eps2) with tabulated arcs.

Oracles: exact reproduction of linear data by natural cubic splines (Omega, |J_R| linear in K,
|J_1| linear in s = sqrt(-K)), reversibility of every member (lem:truncreturnmap), and the
independent NumPy implementation numpy_reference.*_general with callables.
"""

from __future__ import annotations

import numpy as np
import pytest

import hovering
from conftest import PAPER, PARAM_SETS, cdiff, make_map
from helpers import numpy_reference as ref
from hovering import TruncatedFamily

BOUNDARY = 1e-9  # distance to arc ends / K = 0 below which points are not compared (round-off)


def k_grid(K_lo, K_hi, n_neg, n_pos):
    """Grid uniform in s = sqrt(-K) below 0 (|J_1| is splined in s) and uniform in K above."""
    s = np.linspace(np.sqrt(-K_lo), 0.0, n_neg)
    Kn = -(s**2)
    Kn[-1] = 0.0
    return np.concatenate([Kn, np.linspace(0.0, K_hi, n_pos)[1:]])


def arc_distance(fam, phi, K):
    """Circular distance to the nearest arc end of fam (inf for K >= 0)."""
    a = fam.arcs(K)
    d = np.full(np.shape(K), np.inf)
    neg = K < 0
    for key in ("start_1", "start_R", "start_0"):
        d[neg] = np.minimum(d[neg], cdiff(phi[neg], a[key][neg]))
    return d


def sample(fam, n, rng, margin):
    """Random points of the family's band, away from its discontinuities."""
    lo, hi = fam.valid_band()
    phi = rng.uniform(-np.pi, np.pi, n)
    K = rng.uniform(lo + margin, hi - margin, n)
    K[: n // 50] = -rng.uniform(1e-8, 1e-4, n // 50)  # tiny |J_1|: where splining in K would fail
    ok = (arc_distance(fam, phi, K) > BOUNDARY) & (np.abs(K) > BOUNDARY)
    return phi[ok], K[ok]


# ------------------------------------------------------------------------------------------------
# 8. from_map: linear data are reproduced exactly


@pytest.mark.parametrize("name", ["paper_eps+0.3", "tau1_negative"])
def test_from_map_reproduces_the_map(name, rng):
    m = make_map(PARAM_SETS[name])
    grid = k_grid(-2.5, 1.5, 120, 60)
    fam = TruncatedFamily.from_map(m, grid)
    assert fam.eps == m.eps and list(fam.forcing) == [1.0]
    lo, hi = fam.valid_band()
    # the map's band contains [-2.5, 0), so the family's band is the grid: [-2.5, 1.5]
    assert lo == pytest.approx(-2.5, abs=1e-12) and hi == 1.5
    phi, K = sample(fam, 50_000, rng, margin=abs(m.eps) + 1e-6)
    ok = (m.region(phi, K) >= 0) & (ref.boundary_distance(phi, K, m.params) > BOUNDARY)
    pr, Kr = ref.reversal(phi, K, m.params)
    ok &= ref.boundary_distance(pr, Kr, m.params) > BOUNDARY
    phi, K = phi[ok], K[ok]
    # Tolerance 1e-12: the natural cubic spline of linear data is the line itself; what is left is
    # the round-off of the spline coefficients/evaluation (~1e-15 relative) plus one step (1e-14).
    tol = 1e-12
    a, b = fam.step(phi, K)
    c, d = m.step(phi, K)
    assert cdiff(a, c).max() <= tol and np.abs(b - d).max() <= tol
    a, b = fam.step_inverse(phi, K)
    c, d = m.step_inverse(phi, K)
    assert cdiff(a, c).max() <= tol and np.abs(b - d).max() <= tol
    assert np.array_equal(fam.region(phi, K), m.region(phi, K))
    assert np.abs(fam.rotation(phi, K) - m.rotation(phi, K)).max() <= tol
    Kneg = K[K < 0]
    fa, ma = fam.arcs(Kneg), m.arcs(Kneg)
    for key in ("len_1", "len_R", "len_0"):
        assert np.abs(fa[key] - ma[key]).max() <= tol
    for key in ("start_1", "start_R", "start_0"):
        assert cdiff(fa[key], ma[key]).max() <= tol


def test_tables_may_be_callables():
    m = make_map(PARAM_SETS["paper_eps+0.3"])
    grid = k_grid(-2.0, 1.0, 40, 20)
    fam = TruncatedFamily.from_map(m, grid)
    s = lambda k: np.sqrt(max(-k, 0.0))  # noqa: E731
    fam_c = TruncatedFamily(
        m.eps,
        grid,
        Omega=lambda k: m.Omega0 + m.tau0 * k,
        JR=lambda k: 2 * (np.pi - m.theta_w) + m.tau1 * min(k, 0.0),
        J1=lambda k: 2 * m.lam * s(k),
    )
    phi = np.linspace(-3, 3, 101)
    K = np.linspace(-1.9, 0.9, 101)
    a, b = fam.step(phi, K)
    c, d = fam_c.step(phi, K)
    # same tables up to the rounding of one formula evaluation
    assert cdiff(a, c).max() <= 1e-13 and np.abs(b - d).max() <= 1e-13


# ------------------------------------------------------------------------------------------------
# nonlinear tables with a 3-mode forcing: reversibility


NONLIN = dict(
    Omega=lambda K: PAPER["Omega0"] + K + 0.2 * K**2,
    JR=lambda K: 2 * (np.pi - PAPER["theta_w"]) + 0.5 * K + 0.05 * K**2,
    J1=lambda K: 2 * 0.5 * np.sqrt(np.maximum(-K, 0.0)) + 0.1 * np.sqrt(np.maximum(-K, 0.0)) ** 3,
)
B3 = (1.0, 0.3, -0.2)


def _nonlinear_family(eps, grid, b=B3):
    return TruncatedFamily(eps, grid, NONLIN["Omega"](grid), NONLIN["JR"](grid), NONLIN["J1"](grid), forcing=b)


@pytest.mark.parametrize("eps", [0.25, -0.4])
def test_nonlinear_family_is_reversible(eps, rng):
    grid = k_grid(-2.5, 1.5, 200, 80)
    fam = _nonlinear_family(eps, grid)
    assert list(fam.forcing) == list(B3)
    f_max = sum(abs(x) for x in B3)
    phi, K = sample(fam, 50_000, rng, margin=abs(eps) * f_max + 1e-6)
    pr, Kr = fam.reversal(phi, K)
    ok = (arc_distance(fam, pr, Kr) > BOUNDARY) & (np.abs(Kr) > BOUNDARY)
    phi, K = phi[ok], K[ok]
    # R = (-phi, K - eps f(phi)) with the family's odd forcing f
    assert np.abs(fam.forcing_at(phi) - ref.forcing(phi, B3)).max() <= 1e-15
    # Tolerance 1e-12: as for F_eps (a few roundings of |.| < 16 per composition).
    a, b = fam.reversal(*fam.step(*fam.reversal(phi, K)))
    c, d = fam.step_inverse(phi, K)
    assert cdiff(a, c).max() <= 1e-12 and np.abs(b - d).max() <= 1e-12
    e, f = fam.step(c, d)
    assert cdiff(e, phi).max() <= 1e-12 and np.abs(f - K).max() <= 1e-12
    g, h = fam.step_inverse(*fam.step(phi, K))
    assert cdiff(g, phi).max() <= 1e-12 and np.abs(h - K).max() <= 1e-12
    assert set(np.unique(fam.region(phi, K)).tolist()) == {0, 1, 2, 3}


# ------------------------------------------------------------------------------------------------
# agreement with numpy_reference.*_general


def test_linear_family_matches_numpy_reference(rng):
    """Linear data: the spline is exact, so the family and the reference agree to round-off."""
    O0, tw, t0, t1, lam = PAPER["Omega0"], PAPER["theta_w"], 1.0, 0.5, 0.5
    Omega = lambda K: O0 + t0 * np.asarray(K)  # noqa: E731
    JR = lambda K: 2 * (np.pi - tw) + t1 * np.minimum(np.asarray(K), 0.0)  # noqa: E731
    J1 = lambda K: 2 * lam * np.sqrt(np.maximum(-np.asarray(K), 0.0))  # noqa: E731
    eps = 0.3
    grid = k_grid(-4.0, 1.5, 150, 60)  # extends below the band floor -pi (where |J_R| = 0)
    fam = TruncatedFamily(eps, grid, Omega(grid), JR(grid), J1(grid), forcing=B3)
    lo, hi = fam.valid_band()
    rlo, _ = ref.valid_band_general(Omega, JR, J1)
    # the reference bisects to 1e-13; the family's |J_R| = 0 crossing is exact up to spline round-off
    assert lo == pytest.approx(rlo, abs=1e-12) and lo == pytest.approx(-np.pi, abs=1e-12)
    assert hi == 1.5
    f_max = sum(abs(x) for x in B3)
    phi, K = sample(fam, 50_000, rng, margin=abs(eps) * f_max + 1e-6)
    ok = ref.boundary_distance_general(phi, K, Omega, JR, J1) > BOUNDARY
    K0 = K - eps * ref.forcing(phi, B3)
    ok &= ref.boundary_distance_general(-phi, K0, Omega, JR, J1) > BOUNDARY
    ok &= np.abs(K0) > BOUNDARY
    phi, K = phi[ok], K[ok]
    tol = 1e-12  # spline of linear data = the data (round-off ~1e-15) + one step (<= 1e-14)
    a, b = fam.step(phi, K)
    ra, rb = ref.step_general(phi, K, eps, Omega, JR, J1, B3)
    assert cdiff(a, ra).max() <= tol and np.abs(b - rb).max() <= tol
    c, d = fam.step_inverse(phi, K)
    rc, rd = ref.step_inverse_general(phi, K, eps, Omega, JR, J1, B3)
    assert cdiff(c, rc).max() <= tol and np.abs(d - rd).max() <= tol
    assert np.array_equal(fam.region(phi, K).astype(int), ref.region_general(phi, K, Omega, JR, J1))
    assert np.abs(fam.rotation(phi, K) - ref.rotation_general(phi, K, Omega, JR, J1)).max() <= tol


def test_nonlinear_family_matches_numpy_reference_to_spline_accuracy(rng):
    eps = 0.25
    n_neg, n_pos = 1500, 400
    K_lo, K_hi = -2.5, 1.5
    grid = k_grid(K_lo, K_hi, n_neg, n_pos)
    fam = _nonlinear_family(eps, grid)
    # Spline error. A natural cubic spline of f has error O(h^4 |f''''|) in the interior, and the
    # natural end condition (s'' = 0 where f'' != 0) adds an end-layer error <= h^2 |f''| (a
    # conservative form of the classical estimate).  Omega, |J_R| are splined in K (f''' = 0:
    # only the end layer counts); |J_1| in s = sqrt(-K) (f'' = 0.6 s).
    hK = np.diff(grid).max()
    hs = np.sqrt(-K_lo) / (n_neg - 1)
    err_Om = hK**2 * 0.4  # |Omega''| = 0.4
    err_JR = hK**2 * 0.1  # |J_R''| = 0.1
    err_J1 = hs**2 * 0.6 * np.sqrt(-K_lo)  # |d^2 J_1 / ds^2| = 0.6 s
    # the spline reproduces each function within its bound (checked through the arc lengths)
    Kt = np.linspace(K_lo + 1e-9, -1e-9, 5001)
    a = fam.arcs(Kt)
    assert np.abs(a["len_R"] - NONLIN["JR"](Kt)).max() <= err_JR
    assert np.abs(a["len_1"] - NONLIN["J1"](Kt)).max() <= err_J1
    # An arc end moves by at most err_Om/2 + err_JR + err_J1 and omega_a by at most
    # err_Om + max(err_JR, err_J1): compare points farther than 10x the former from any end.
    e_end = err_Om / 2 + err_JR + err_J1
    e_rot = err_Om + max(err_JR, err_J1)
    assert e_rot < 1e-5  # the comparison is still sharp
    Omega = lambda K: NONLIN["Omega"](np.asarray(K))  # noqa: E731
    JR = lambda K: NONLIN["JR"](np.asarray(K))  # noqa: E731
    J1 = lambda K: NONLIN["J1"](np.asarray(K))  # noqa: E731
    phi = rng.uniform(-np.pi, np.pi, 50_000)
    K = rng.uniform(K_lo + 0.01, K_hi - 0.01, 50_000)
    ok = ref.boundary_distance_general(phi, K, Omega, JR, J1) > 10 * e_end
    ok &= np.abs(K) > BOUNDARY
    phi, K = phi[ok], K[ok]
    a, b = fam.step(phi, K)
    ra, rb = ref.step_general(phi, K, eps, Omega, JR, J1, B3)
    # phi1 errs by <= e_rot; K1 = K + eps f(phi1) by <= |eps| max|f'| e_rot (max|f'| <= sum k|b_k|)
    fprime = sum((k + 1) * abs(x) for k, x in enumerate(B3))
    assert cdiff(a, ra).max() <= e_rot + 1e-12
    assert np.abs(b - rb).max() <= abs(eps) * fprime * e_rot + 1e-12
    assert np.array_equal(fam.region(phi, K).astype(int), ref.region_general(phi, K, Omega, JR, J1))
    assert np.abs(fam.rotation(phi, K) - ref.rotation_general(phi, K, Omega, JR, J1)).max() <= e_rot + 1e-12


def test_family_iterate_matches_steps(rng):
    fam = _nonlinear_family(0.25, k_grid(-2.5, 1.5, 200, 80))
    phi0, K0 = sample(fam, 200, rng, margin=0.5)
    n = 50
    for kernel in ("scalar", "simd"):
        res = fam.iterate(phi0, K0, n, kernel=kernel)
        p, k = phi0.copy(), K0.copy()
        alive = np.ones(p.size, bool)
        for j in range(5):  # a few steps: SLEEF and libm sin differ by an ulp
            alive &= res.steps_done > j
            p[alive], k[alive] = fam.step(p[alive], k[alive])
            # Tolerance 1e-11: <= 5 steps of 1e-14 round-off amplified by |J| <= ~5 per step
            assert cdiff(res.phi[alive, j + 1], p[alive]).max() <= 1e-11
            assert np.abs(res.K[alive, j + 1] - k[alive]).max() <= 1e-11
        lo, hi = fam.valid_band()
        esc = res.status == hovering.Status.ESCAPED
        assert np.all((res.K_final[esc] <= lo) | (res.K_final[esc] >= hi))


# ------------------------------------------------------------------------------------------------
# 6. malformed tables


def _table():
    K = k_grid(-2.0, 1.0, 30, 10)
    m = make_map(PARAM_SETS["paper_eps+0.3"])
    s = np.sqrt(np.maximum(-K, 0.0))
    return dict(
        eps=0.3,
        K=K,
        Omega=m.Omega0 + K,
        JR=2 * (np.pi - m.theta_w) + 0.5 * np.minimum(K, 0.0),
        J1=2 * 0.5 * s,
    )


def _with(**changes):
    t = _table()
    for key, fn in changes.items():
        t[key] = fn(t)
    return t


def _set(key, i, v):
    def f(t):
        a = np.array(t[key], dtype=float)
        a[i] = v
        return a

    return f


I0 = 29  # index of K = 0 in _table()'s grid

BAD_TABLES = [
    (_with(K=lambda t: np.concatenate([t["K"][:3], t["K"][2:3], t["K"][4:]])), r"grid must be strictly increasing"),
    (
        _with(K=lambda t: np.concatenate([t["K"][:2], t["K"][3:4], t["K"][2:3], t["K"][4:]])),
        r"grid must be strictly increasing, but K\[3\]",
    ),
    (_with(J1=_set("J1", I0, 0.1)), r"J1 must vanish at K = 0"),
    (_with(Omega=_set("Omega", 5, np.nan)), r"Omega\[5\] must be finite"),
    (_with(JR=_set("JR", 3, np.inf)), r"JR\[3\] must be finite"),
    (_with(J1=_set("J1", 4, np.nan)), r"J1\[4\] must be finite"),
    (_with(K=_set("K", 1, np.nan)), r"K\[1\] must be finite"),
    (_with(eps=lambda t: np.nan), r"eps must be finite"),
    (_with(K=lambda t: t["K"] + 0.01), r"the K grid must contain K = 0 exactly"),
    (
        _with(
            K=lambda t: t["K"][I0 - 1 :],
            Omega=lambda t: t["Omega"][I0 - 1 :],
            JR=lambda t: t["JR"][I0 - 1 :],
            J1=lambda t: t["J1"][I0 - 1 :],
        ),
        r"at least 3 points with K <= 0, got 2",
    ),
    (
        _with(
            K=lambda t: t["K"][: I0 + 1],
            Omega=lambda t: t["Omega"][: I0 + 1],
            JR=lambda t: t["JR"][: I0 + 1],
            J1=lambda t: t["J1"][: I0 + 1],
        ),
        r"the K grid must extend above K = 0",
    ),
    (_with(JR=lambda t: t["JR"][:-1]), r"JR must have the shape of K"),
    (_with(K=lambda t: t["K"].reshape(1, -1)), r"K must be a 1-D grid"),
    (_with(JR=lambda t: -np.ones_like(t["JR"])), r"no valid band below K = 0"),
]


@pytest.mark.parametrize("table,match", BAD_TABLES, ids=[str(i) for i in range(len(BAD_TABLES))])
def test_malformed_tables_raise(table, match):
    t = dict(table)
    with pytest.raises(ValueError, match=match):
        TruncatedFamily(t["eps"], t["K"], t["Omega"], t["JR"], t["J1"])


@pytest.mark.parametrize(
    "kw,match",
    [
        (dict(forcing=(1.0, np.nan)), r"forcing\[1\] must be finite"),
        (dict(forcing=()), r"forcing must be a 1-D sequence of 1 to 64 sine coefficients, got shape \(0,\)"),
        (dict(forcing=[[1.0]]), r"forcing must be a 1-D sequence of 1 to 64 sine coefficients, got shape \(1, 1\)"),
        (dict(forcing="12"), r"forcing must be a sequence of sine coefficients, got '12'"),
        (dict(forcing=[1.0] * 65), r"1 to 64 sine coefficients, got shape \(65,\)"),
        (dict(K_max=0.0), r"K_max must be > 0"),
        (dict(K_max=np.nan), r"K_max must be > 0"),
    ],
)
def test_bad_forcing_and_K_max(kw, match):
    t = _table()
    with pytest.raises(ValueError, match=match):
        TruncatedFamily(t["eps"], t["K"], t["Omega"], t["JR"], t["J1"], **kw)


def test_good_table_builds():
    t = _table()
    assert t["K"][I0] == 0.0
    fam = TruncatedFamily(t["eps"], t["K"], t["Omega"], t["JR"], t["J1"], K_max=0.5)
    assert fam.valid_band()[1] == 0.5
    assert fam.valid_band()[0] == pytest.approx(-2.0, abs=1e-12)


# ------------------------------------------------------------------------------------------------
# Size, speed and resolution of the tables


def _counting(fn):
    """fn, counting its calls (.calls) and whether any took an array (.arrays)."""

    def wrapped(k):
        wrapped.calls += 1
        wrapped.arrays += np.ndim(k) > 0
        return fn(k)

    wrapped.calls = wrapped.arrays = 0
    return wrapped


def test_a_grid_beyond_MAX_GRID_is_refused_before_anything_is_sampled_or_built():
    # 1e6 points took 12 s and 0.5 GB in the core, Ctrl-C unheard; MAX_GRID is the sweep plans' limit.
    from hovering.truncated.maps import MAX_GRID

    assert MAX_GRID == 100_000
    n = MAX_GRID // 2 + 1
    K = np.concatenate([np.linspace(-1.0, 0.0, n), np.linspace(0.0, 1.0, n)[1:]])  # MAX_GRID + 1 points
    Om = _counting(lambda k: 3.0 + 0 * k)
    with pytest.raises(ValueError, match=r"K has 100001 grid points; allowed: at most MAX_GRID = 100000"):
        TruncatedFamily(0.1, K, Om, np.ones_like(K), np.sqrt(np.maximum(-K, 0.0)))
    assert Om.calls == 0


def test_a_vectorised_callable_is_called_once_with_the_whole_grid():
    # Each Python call cost ~1 us a grid point (~0.3 s of a MAX_GRID build); a function of one
    # float still works, called per point after its call on the array fails.
    t = _table()
    K = t["K"]
    Om = _counting(lambda k: PAPER["Omega0"] + k)
    JR = _counting(lambda k: 2 * (np.pi - PAPER["theta_w"]) + 0.5 * np.minimum(k, 0.0))
    J1 = _counting(lambda k: 0.5 * 2 * np.sqrt(max(-k, 0.0)))  # max(): one float only
    fam = TruncatedFamily(t["eps"], K, Om, JR, J1)
    assert (Om.calls, Om.arrays, JR.calls, JR.arrays) == (1, 1, 1, 1)
    assert J1.calls == 1 + K.size and J1.arrays == 1
    ref_fam = TruncatedFamily(t["eps"], K, t["Omega"], t["JR"], t["J1"])
    for a, b in zip(fam._tables, ref_fam._tables):
        assert np.array_equal(a, b)  # the same doubles either way


def test_family_K_max_none_is_a_named_error():
    t = _table()
    # Used to be "float() argument must be a string or a real number, not 'NoneType'" (TypeError).
    with pytest.raises(ValueError, match=r"K_max must be a real number, got None"):
        TruncatedFamily(t["eps"], t["K"], t["Omega"], t["JR"], t["J1"], K_max=None)


@pytest.mark.parametrize(
    "change,match",
    [
        # the band (-2, 1) is 3 tall: |eps| max|f| up to 2^43 x 3 = 2.64e13
        (
            dict(eps=1e14),
            r"eps = 100000000000000\.0 with the forcing's max\|f\| <= 1 kicks K .*allowed: \|eps\| max\|f\| <= 2\.63883e\+13",
        ),
        (dict(eps=1e4, forcing=(1e10, -1e10)), r"max\|f\| <= 2e\+10 kicks K .*\|eps\| <= 1319\.41 with this forcing"),
        # J_1 = 1e-14 sqrt(-K) <= 1.4e-14 rad: never 2^-41 = 4.5e-13 wide
        (dict(J1=lambda t: 1e-14 * np.sqrt(np.maximum(-t["K"], 0.0))), r"J_1 opens to at most 1\.4\de-14 rad"),
    ],
)
def test_family_tables_below_double_precision_resolution_are_refused(change, match):
    t = _table()
    kw = {"forcing": change.pop("forcing")} if "forcing" in change else {}
    for key, v in change.items():
        t[key] = v(t) if callable(v) else v
    with pytest.raises(ValueError, match=r"below double-precision resolution"):
        TruncatedFamily(t["eps"], t["K"], t["Omega"], t["JR"], t["J1"], **kw)
    with pytest.raises(ValueError, match=match):
        TruncatedFamily(t["eps"], t["K"], t["Omega"], t["JR"], t["J1"], **kw)
