"""Orbit classes by order statistics and the converse-KAM cone crossing (hovering.analysis.orbits),
against known answers: rigid rotations, the standard map (an independent NumPy implementation
here), the eps = 0 truncated map, resonances of the truncated map, and the README system's flow
map against its truncated model. Brute-force cross-check: box counting on a fixed grid."""

import math

import numpy as np
import pytest

import hovering
from hovering.analysis import birkhoff_average, cyclic_order_violations, rank_rotation

GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0
TWO_PI = 2.0 * math.pi


def standard_map_orbits(k, x0, p0, n):
    """Chirikov's standard map p' = p + k sin x, x' = x + p' (twist dx'/dp = 1): the wrapped
    angles, the momenta and the lifted angles, shape (n_orbits, n + 1)."""
    x = np.array(x0, dtype=float).ravel()
    p = np.array(p0, dtype=float).ravel() + 0 * x
    x = x + 0 * p
    X = np.empty((x.size, n + 1))
    P = np.empty_like(X)
    X[:, 0], P[:, 0] = x, p
    for j in range(n):
        p = p + k * np.sin(x)
        x = x + p
        X[:, j + 1], P[:, j + 1] = x, p
    return np.mod(X + math.pi, TWO_PI) - math.pi, P, X


def standard_map_step_jacobian(k):
    def step(x, p):
        p1 = p + k * np.sin(x)
        return x + p1, p1

    def jac(x, p):
        c = k * np.cos(x)
        return 1.0 + c, np.ones_like(x), c, np.ones_like(x)

    return step, jac


def star_discrepancy(u):
    """Star discrepancy of points u in [0, 1) against the uniform measure (exact for a finite set)."""
    s = np.sort(np.mod(u, 1.0))
    n = s.size
    i = np.arange(1, n + 1)
    return float(max(np.max(i / n - s), np.max(s - (i - 1) / n)))


def rank_bound(u):
    """Proven bound on |rank_rotation - rotation| for an orbit whose conjugacy coordinate is u:
    the rank coordinate is within D* + 1/n of it, and only the two ends of the telescoping sum of
    advances remain (rank_rotation's docstring)."""
    n = u.size
    return 2.0 * (star_discrepancy(u) + 1.0 / n) / (n - 1)


def birkhoff_rotation(Xlifted):
    """Rotation (turns per step) of each orbit by the weighted Birkhoff average of the lifted
    advances: converges faster than any power of n on an invariant circle of a smooth map."""
    return np.array([birkhoff_average(np.diff(row) / TWO_PI) for row in Xlifted])


def covered_fraction(phi, K, K_lo, K_hi, G):
    """Brute force: the fraction of a fixed G x G grid over [-pi, pi) x [K_lo, K_hi] holding a point."""
    i = np.clip(((phi + math.pi) / TWO_PI * G).astype(int), 0, G - 1)
    j = np.clip(((K - K_lo) / (K_hi - K_lo) * G).astype(int), 0, G - 1)
    return np.unique(i * G + j).size / G**2


# ------------------------------------------------------------------------------------------------
# Order statistics on rigid rotations


@pytest.mark.parametrize("alpha", [GOLDEN, math.sqrt(2.0) - 1.0, 0.689655, 0.05, 0.97])
def test_rigid_rotation_order_and_rank_rotation(alpha):
    """A rigid rotation keeps the cyclic order exactly, and its rank rotation is within the proven
    discrepancy bound of alpha (0.689655 is close to 20/29: clustered points, a large D*)."""
    n = 3000
    u = np.mod(0.123 + alpha * np.arange(n), 1.0)
    x = TWO_PI * u - math.pi
    assert cyclic_order_violations(x) == 0
    assert abs(rank_rotation(x) - alpha) <= rank_bound(u)
    # scrambling the time order destroys it: about half the steps break the order
    rng = np.random.default_rng(1)
    assert cyclic_order_violations(rng.permutation(x)) > n // 4


def test_interval_exchange_shows_one_violation():
    """Swapping two adjacent arcs and rotating (the eps = 0 truncated map below K = 0) keeps the
    order on each arc: one violation beyond a rotation's, far below the pieces allowance."""
    a, b = 0.7, 1.9  # arcs [0, a) and [a, a + b) swap; the rest only rotates
    n = 4000
    x = np.empty(n)
    x[0] = 0.3
    for j in range(n - 1):
        y = x[j]
        y = y + b if y < a else (y - a if y < a + b else y)
        x[j + 1] = np.mod(y + TWO_PI * GOLDEN, TWO_PI)
    v = cyclic_order_violations(x)
    assert 1 <= v <= 2 * 3 + 1
    c = hovering.classify_orbits(x, np.full(n, -0.2))
    assert c.kind[0] == "circle" and c.decided_by[0] == "order+graph"
    assert hovering.classify_orbits(x, np.full(n, -0.2), pieces=1).kind[0] != "circle"


# ------------------------------------------------------------------------------------------------
# Standard map: known answers


def test_standard_map_k05_circles_and_islands():
    """k = 0.5: most starts on x = 0 lie on rotational circles; the rank rotation of each circle
    agrees with the (independent) weighted Birkhoff rotation to 1e-5 (measured: at most 6.9e-7,
    median 2e-7 at n = 4000); (0, pi + 0.1) lies in the period-2 island."""
    n = 4000
    p0 = np.linspace(0.2, TWO_PI - 0.2, 30)
    phi, K, X = standard_map_orbits(0.5, 0.0, np.append(p0, math.pi + 0.1), n)
    c = hovering.classify_orbits(phi, K, pieces=1)
    wb = birkhoff_rotation(X) % 1.0
    circ = c.kind == "circle"
    assert circ[:-1].sum() >= 20
    err = np.abs((c.rotation[circ] - wb[circ] + 0.5) % 1.0 - 0.5)
    assert np.all(err < 1e-5), err.max()
    assert np.median(err) < 1e-6
    assert c.kind[-1] == "islands" and c.period[-1] == 2 and c.rotation[-1] == 0.5
    # every island verdict: the Birkhoff rotation is the chain's p/q (to the 1/n of a plain mean)
    isl = c.kind == "islands"
    assert np.all(np.abs(wb[isl] - c.rotation[isl]) < 1e-3)
    assert np.all(c.K_min <= K.min(axis=1) + 0) and np.all(c.K_max == K.max(axis=1))


def test_standard_map_golden_circle_near_threshold():
    """k = 0.9716 (just below k_c = 0.971635): the golden circle through (0, 4.176785337765809) -
    a start found by bisection of the Birkhoff rotation on the symmetry line x = 0 - is a circle
    with rotation golden to the rank estimate's accuracy, and the cone never leaves the twist cone
    on it (a crossing there would be a false proof)."""
    n = 20_000
    phi, K, X = standard_map_orbits(0.9716, 0.0, 4.176785337765809, n)
    assert abs(birkhoff_rotation(X)[0] - GOLDEN) < 1e-9  # the start is on the golden circle
    c = hovering.classify_orbits(phi, K, pieces=1)
    assert c.kind[0] == "circle" and c.order_violations[0] == 0
    # rank error <= 2 (D* + 1/n)/(n - 1); D* of 2e4 golden-rotation points is < 1e-3: 1e-7
    assert abs(c.rotation[0] - GOLDEN) < 1e-7
    step, jac = standard_map_step_jacobian(0.9716)
    r = hovering.cone_crossing(step, jac, 0.0, 4.176785337765809, 20_000)
    assert r.status[0] == "none"


def test_standard_map_k12_no_rotational_circles():
    """k = 1.2 > 63/64 (MacKay-Percival: no rotational circle): no start is called a circle, the
    golden-mean region's orbits are chaotic or islands, and the cone crossing fires for every one
    of 400 generic starts within 1000 steps (measured: at most 77)."""
    n = 4000
    p0 = np.linspace(0.1, TWO_PI - 0.1, 24)
    phi, K, _ = standard_map_orbits(1.2, 0.0, p0, n)
    c = hovering.classify_orbits(phi, K, pieces=1)
    assert c.counts()["circle"] == 0
    golden_region = (p0 > 3.9) & (p0 < 4.6)  # the golden circle of k = 0.9716 crosses x = 0 at p = 4.18
    assert golden_region.sum() >= 3
    assert set(c.kind[golden_region]) <= {"chaotic", "islands"}
    assert c.counts()["chaotic"] >= 12
    step, jac = standard_map_step_jacobian(1.2)
    rng = np.random.default_rng(7)
    x0, y0 = rng.uniform(-math.pi, math.pi, 400), rng.uniform(0.0, TWO_PI, 400)
    r = hovering.cone_crossing(step, jac, x0, y0, 1000)
    assert np.all(r.crossed), r.status[~r.crossed]


def test_converse_kam_agrees_with_classes_at_k05():
    """Two independent methods: starts classified as circles never cross the cone (2000 steps);
    starts in islands always do (an island's tangent turns with it)."""
    n = 4000
    p0 = np.linspace(0.2, TWO_PI - 0.2, 30)
    phi, K, _ = standard_map_orbits(0.5, 0.0, p0, n)
    c = hovering.classify_orbits(phi, K, pieces=1)
    step, jac = standard_map_step_jacobian(0.5)
    r = hovering.cone_crossing(step, jac, 0.0, p0, 2000)
    assert np.all(r.status[c.kind == "circle"] == "none")
    assert (c.kind == "islands").sum() >= 4
    assert np.all(r.crossed[c.kind == "islands"])


def test_brute_force_box_counting_agrees():
    """Brute force on a fixed grid: a circle's covered fraction halves when the grid is refined
    (ratio ~1/2), a chaotic layer's does not (~1). Every circle verdict of the order test has
    ratio < 0.7, every chaotic verdict > 0.7 (measured: circles 0.50-0.51, chaotic 0.76-0.84), on the
    standard map and on eps = 0 circles of the truncated map."""
    n = 20_000
    p0 = np.linspace(0.2, TWO_PI - 0.2, 12)
    for k in (0.5, 1.2):
        phi, K, _ = standard_map_orbits(k, 0.0, p0, n)
        c = hovering.classify_orbits(phi, K, pieces=1)
        for i in range(p0.size):
            if c.kind[i] not in ("circle", "chaotic"):
                continue
            lo, hi = K[i].min(), K[i].max()
            ratio = covered_fraction(phi[i], K[i], lo, hi, 64) / covered_fraction(phi[i], K[i], lo, hi, 32)
            assert (ratio < 0.7) == (c.kind[i] == "circle"), (k, p0[i], c.kind[i], ratio)
    assert (c.kind == "chaotic").sum() >= 5  # k = 1.2 gave chaotic verdicts to check
    # eps = 0 truncated circles (impacting and not), on a fixed box K +- 0.1 around each
    m = hovering.paper.truncated_map(0.0)
    K0 = np.array([-0.3, 0.2])
    res = m.iterate(m.L1(K0), K0, n, record=("orbit",))
    c = hovering.classify_orbits(res)
    for i, k in enumerate(K0):
        ratio = covered_fraction(res.phi[i], res.K[i], k - 0.1, k + 0.1, 64) / covered_fraction(
            res.phi[i], res.K[i], k - 0.1, k + 0.1, 32
        )
        assert c.kind[i] == "circle" and ratio < 0.7, (k, c.kind[i], ratio)


# ------------------------------------------------------------------------------------------------
# The truncated map


def test_truncated_eps0_circles():
    """eps = 0: every orbit stays on its circle K. Above 0 the map is the rotation by
    Omega(K) = Omega0 + tau0 K; below 0 it swaps J_1 and J_R and rotates (an arc exchange). Both are
    circles; the rank rotation is Omega(K)/2pi mod 1 above 0, and below 0 the time mean of
    frac(omega_a / 2pi) (the advance mod one turn), each within the proven discrepancy bound."""
    m = hovering.paper.truncated_map(0.0)
    K0 = np.array([-0.5, -0.3, -0.1, 0.05, 0.2, 0.45, 0.8])
    res = m.iterate(m.L1(K0), K0, 3000, record=("orbit",))
    c = hovering.classify_orbits(res)
    assert np.all(c.kind == "circle"), c.decided_by
    assert np.all(c.K_min == K0) and np.all(c.K_max == K0)
    for i, k in enumerate(K0):
        phi = res.phi[i]
        if k > 0:
            assert c.order_violations[i] == 0
            alpha = (m.Omega0 + m.tau0 * k) / TWO_PI % 1.0
            assert abs(c.rotation[i] - alpha) <= rank_bound((phi + math.pi) / TWO_PI)
        else:
            assert 1 <= c.order_violations[i] <= 7
            f = np.mod(m.rotation(phi[:-1], res.K[i, :-1]) / TWO_PI, 1.0)
            assert abs(c.rotation[i] - f.mean()) <= rank_bound((phi + math.pi) / TWO_PI)


@pytest.mark.parametrize("p, q", [(2, 3), (4, 5)])
def test_truncated_resonance_islands(p, q):
    """eps = 0.3: the resonance Omega(K) = 2 pi p/q of the shifted standard map (K > 0) has an island
    chain of period q on L2. Starts on L2 above the resonant height: at least one island verdict,
    each with period q and rotation p/q, and the paper's rotation (mean omega_a, computed by the
    map) equals 2 pi p/q mod 2 pi to 1e-3 (a plain mean along a libration: ~amplitude/n)."""
    m = hovering.paper.truncated_map(0.3)
    K_res = TWO_PI * p / q - m.Omega0
    K0 = K_res + np.linspace(0.0, 0.3, 31)
    res = m.iterate(m.L2(K0), K0, 4000, record=("orbit", "rotation"))
    c = hovering.classify_orbits(res)
    isl = c.kind == "islands"
    assert isl.sum() >= 1
    assert np.all(c.period[isl] == q) and np.allclose(c.rotation[isl], p / q, rtol=0, atol=1e-15)
    rho = res.rotation[isl] / TWO_PI % 1.0
    assert np.all(np.abs(rho - p / q) < 1e-3)


def test_converse_kam_truncated_map():
    """TruncatedMap, eps = 0.3: on L1 above the critical curve (K_crit = -0.2747) the orbits stay in
    the no-impact set and are circles - no crossing; starts in the 2/3 island chain cross; a start
    whose orbit impacts is 'left_domain' at the first impacting point; impacting starts and maps
    without a closed-form Jacobian are refused."""
    m = hovering.paper.truncated_map(0.3)
    K_above = np.array([-0.2, 0.0, 0.3, 0.8])
    r = hovering.converse_kam(m, m.L1(K_above), K_above, 2000)
    assert np.all(r.status == "none")
    K_res = TWO_PI * 2 / 3 - m.Omega0
    K_isl = K_res + np.linspace(0.0, 0.3, 31)
    res = m.iterate(m.L2(K_isl), K_isl, 4000, record=("orbit",))
    isl = hovering.classify_orbits(res).kind == "islands"
    r = hovering.converse_kam(m, m.L2(K_isl[isl]), K_isl[isl], 2000)
    assert np.all(r.crossed)
    Kg = np.linspace(-0.5, 0.5, 11)
    family = hovering.TruncatedFamily(
        0.3,
        Kg,
        m.Omega0 + m.tau0 * Kg,
        2 * (math.pi - m.theta_w) + m.tau1 * Kg,
        2 * m.lam * np.sqrt(np.maximum(-Kg, 0.0)),
    )
    r = hovering.converse_kam(m, m.L1(-0.35), -0.35, 2000)
    assert r.status[0] == "left_domain"
    res = m.iterate(m.L1(-0.35), -0.35, r.step[0], record=("orbit", "regions"))
    # the points before it are no-impact points, the point reached at r.step impacts
    assert np.all(np.isin(res.region[0], [int(hovering.Region.BESIDE), int(hovering.Region.ABOVE)]))
    assert m.region(res.phi[0, -1], res.K[0, -1]) in (hovering.Region.UPPER, hovering.Region.RIGHT)
    with pytest.raises(ValueError, match="RIGHT|UPPER"):
        hovering.converse_kam(m, m.L2(-0.4), -0.4, 10)
    with pytest.raises(ValueError, match="TruncatedMap"):
        hovering.converse_kam(family, 0.0, 0.1, 10)
    with pytest.raises(ValueError, match="TruncatedMap"):
        hovering.converse_kam(object(), 0.0, 0.1, 10)
    with pytest.raises(ValueError, match="tau0"):
        hovering.converse_kam(hovering.TruncatedMap(eps=0.3, Omega0=1.0, theta_w=1.0, tau0=0.0), 0.0, 0.1, 10)


def test_critical_curve_is_the_lowest_circle_on_L1():
    """eps = 0.3: critical_curve() (an independent search by Birkhoff regularity in the no-impact
    regions) puts the lowest no-impact circle at K_min on L1. Starts at and above it are circles;
    starts up to 0.02 below it are not (within the 0.004 spacing of the starts)."""
    m = hovering.paper.truncated_map(0.3)
    K_min = hovering.critical_curve(m, n_steps=20_000).K_min
    K0 = K_min + 0.004 * np.arange(-5, 6)
    c = hovering.classify_orbits(m.iterate(m.L1(K0), K0, 20_000, record=("orbit",)))
    assert np.all(c.kind[5:] == "circle"), c.kind
    assert not np.any(c.kind[:5] == "circle"), c.kind


def test_flow_map_agrees_with_its_model():
    """README system at eps = -0.05 (hovers; its critical curve lies near K = -0.025): starts on L1
    well above it are circles for the flow and for its truncated model alike, and the start at
    K = -0.05 is in the period-2 island chain for both."""
    sys_ = hovering.StepSystem(
        V1=hovering.Harmonic(omega=1.0),
        V2=hovering.Tan(omega=1.4, alpha=0.7),
        coupling=hovering.Bilinear(),
        eps=-0.05,
        qw1=-1.0,
        qw2=-0.5,
        geometry="step",
    )
    fm = hovering.FlowMap(sys_, h=1.0, rtol=1e-10)
    tm = fm.truncated()
    K0 = np.array([0.01, 0.03, 0.06, -0.05])
    cf = hovering.classify_orbits(fm.iterate(fm.L1(K0), K0, 1500, record=("orbit",)))
    ct = hovering.classify_orbits(tm.iterate(tm.L1(K0), K0, 1500, record=("orbit",)))
    assert list(cf.kind) == ["circle"] * 3 + ["islands"]
    assert list(ct.kind) == list(cf.kind)
    assert cf.period[-1] == ct.period[-1] == 2
    # the model's rotation differs from the flow's by O(eps) (thm:returnmap's remainder)
    assert np.all(np.abs(cf.rotation[:3] - ct.rotation[:3]) < 0.01)


# ------------------------------------------------------------------------------------------------
# Padding, per-orbit outcomes and bad input


def test_nan_padding_and_per_orbit_outcomes():
    """A stopped orbit is used up to its first NaN; a short or empty one is 'undecided' without
    changing the others' verdicts."""
    m = hovering.paper.truncated_map(0.0)
    res = m.iterate(m.L1(np.array([0.2, 0.4])), [0.2, 0.4], 1000, record=("orbit",))
    phi = np.vstack([res.phi, res.phi[:1], np.full((1, 1001), np.nan)])
    K = np.vstack([res.K, res.K[:1], np.full((1, 1001), np.nan)])
    phi[2, 600:] = np.nan
    K[2, 100:] = np.nan  # a NaN in either array ends the orbit
    c = hovering.classify_orbits(phi, K)
    assert list(c.n_points) == [1001, 1001, 100, 0]
    assert list(c.kind) == ["circle", "circle", "undecided", "undecided"]
    assert c.decided_by[2] == "too few points" and math.isnan(c.K_min[3])
    alone = hovering.classify_orbits(res.phi[1], res.K[1])
    assert alone.rotation[0] == c.rotation[1]
    assert c.counts() == {"circle": 2, "islands": 0, "chaotic": 0, "undecided": 2}


def test_bad_input():
    x = np.zeros((2, 300))
    with pytest.raises(ValueError, match="same shape"):
        hovering.classify_orbits(x, np.zeros((2, 299)))
    with pytest.raises(ValueError, match="pieces"):
        hovering.classify_orbits(x, x, pieces=0)
    with pytest.raises(ValueError, match="tol"):
        hovering.classify_orbits(x, x, tol=-1.0)
    with pytest.raises(ValueError, match="K is required"):
        hovering.classify_orbits(x)
    with pytest.raises(ValueError, match="shape"):
        hovering.classify_orbits(np.zeros((2, 3, 4)), np.zeros((2, 3, 4)))
    step, jac = standard_map_step_jacobian(0.5)
    with pytest.raises(ValueError, match="twist"):
        hovering.cone_crossing(step, jac, 0.0, 1.0, 10, twist=0.5)
    with pytest.raises(ValueError, match="finite"):
        hovering.cone_crossing(step, jac, np.nan, 1.0, 10)
    with pytest.raises(ValueError, match="n_steps"):
        hovering.cone_crossing(step, jac, 0.0, 1.0, 0)
    with pytest.raises(ValueError, match=">= 3 points"):
        cyclic_order_violations([0.0, 1.0])


def test_not_twist_is_a_status():
    """A Jacobian whose twist entry has the wrong sign stops that orbit with 'not_twist' (the
    proof's premise fails there), and only that orbit."""
    step, jac = standard_map_step_jacobian(0.5)

    def jac_bad(x, p):
        a, b, c, d = jac(x, p)
        return a, np.where(p > 3.0, -1.0, b), c, d

    r = hovering.cone_crossing(step, jac_bad, [0.0, 0.0], [1.0, 3.5], 50)
    assert r.status[1] == "not_twist" and r.step[1] == 0
    assert r.status[0] != "not_twist"


def test_ctrl_c_keeps_what_was_found():
    """Ctrl-C (a KeyboardInterrupt from inside the step) stops cone_crossing and keeps the crossings
    found so far in .partial; classify_orbits keeps the orbits done before it."""
    step, jac = standard_map_step_jacobian(1.2)
    calls = [0]

    def step_interrupted(x, p):
        calls[0] += 1
        if calls[0] > 10:
            raise KeyboardInterrupt
        return step(x, p)

    rng = np.random.default_rng(3)
    x0, y0 = rng.uniform(-math.pi, math.pi, 50), rng.uniform(0.0, TWO_PI, 50)
    with pytest.raises(KeyboardInterrupt) as info:
        hovering.cone_crossing(step_interrupted, jac, x0, y0, 1000)
    part = info.value.partial
    assert 10 <= part.crossed.sum() < 50  # median crossing step 7 measured: about half within 10
    assert np.all(part.step[part.crossed] <= 10) and np.all(part.status[~part.crossed] == "none")
    full = hovering.cone_crossing(step, jac, x0, y0, 1000)
    assert np.array_equal(full.step[part.crossed], part.step[part.crossed])

    phi, K, _ = standard_map_orbits(0.5, 0.0, [1.0, 2.0, 3.0], 300)
    rows = [0]

    def isfinite_once(a, _real=np.isfinite):
        if np.ndim(a) == 1 and np.size(a) == 301:  # a row: classify_orbits checks phi and K of each
            rows[0] += 1
            if rows[0] > 4:  # after two orbits
                raise KeyboardInterrupt
        return _real(a)

    mp = pytest.MonkeyPatch()
    mp.setattr(np, "isfinite", isfinite_once)
    try:
        with pytest.raises(KeyboardInterrupt) as info:
            hovering.classify_orbits(phi, K, pieces=1)
    finally:
        mp.undo()
    part = info.value.partial
    i0 = int(np.argmax(part.decided_by == "interrupted"))
    assert 1 <= i0 < 3 and np.all(part.decided_by[i0:] == "interrupted")
    done = hovering.classify_orbits(phi, K, pieces=1)
    assert list(part.kind[:i0]) == list(done.kind[:i0])
