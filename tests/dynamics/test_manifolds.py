"""Invariant manifolds (hovering.dynamics.manifold), their intersections and lobes.

Oracles: invariance (the images of a branch's points lie on the branch), the reversibility
(the stable branch is the reversor's image of the unstable one for an orbit on Fix(R0)), the
lobes' equal areas (consecutive lobes of one type are images of each other), and the turnstile
itself: Monte Carlo points inside a lobe are carried by the map into the next lobe of its type.
"""

from __future__ import annotations

import numpy as np
import pytest

import hovering as hv
from hovering.dynamics import intersections, lobes, manifold


def _distance_to_curve(px, py, c):
    """Distance of points to the polyline of a Manifold (lifted phi: every whole turn tried)."""
    x, y = c.phi_lift, c.K
    ok = np.isfinite(x[:-1]) & np.isfinite(x[1:])
    ok &= (x[:-1] != x[1:]) | (y[:-1] != y[1:])  # no zero-length segments
    x0, y0, x1, y1 = x[:-1][ok], y[:-1][ok], x[1:][ok], y[1:][ok]
    best = np.full(np.size(px), np.inf)
    for sh in 2 * np.pi * np.arange(-4, 5):
        X, Y = (np.asarray(px) + sh)[:, None], np.asarray(py)[:, None]
        dx, dy = x1 - x0, y1 - y0
        t = np.clip(((X - x0) * dx + (Y - y0) * dy) / (dx * dx + dy * dy), 0, 1)
        d = np.hypot(X - (x0 + t * dx), Y - (y0 + t * dy)).min(axis=1)
        best = np.minimum(best, d)
    return best


def _inside(px, py, poly_x, poly_y):
    """Even-odd point-in-polygon test (ray casting), vectorised over points."""
    px, py = np.asarray(px)[:, None], np.asarray(py)[:, None]
    x0, y0 = poly_x, poly_y
    x1, y1 = np.roll(poly_x, -1), np.roll(poly_y, -1)
    crosses = ((y0 > py) != (y1 > py)) & (px < (x1 - x0) * (py - y0) / (y1 - y0 + 1e-300) + x0)
    return np.count_nonzero(crosses, axis=1) % 2 == 1


@pytest.fixture(scope="module")
def separatrix():
    """k = 1.2: the standard map's hyperbolic fixed point, its unstable branch and the stable
    branch that crosses it (the main resonance's broken separatrix)."""
    sm = hv.TruncatedMap(eps=1.2, Omega0=0.3, theta_w=2.0)
    x = hv.periodic_orbit(sm, 0.0, 6.0, 1)
    wu = manifold(sm, x, "unstable", 1, length=8.0)
    ws = manifold(sm, x, "stable", -1, length=8.0)
    return sm, x, wu, ws


def test_the_branches_are_invariant(separatrix):
    sm, x, wu, ws = separatrix
    assert wu.status == ws.status == "complete" and wu.breaks == ws.breaks == 0
    assert wu.length >= 8.0 and abs(wu.multiplier * ws.multiplier - 1) < 1e-12
    # F(W^u) lies on W^u, F^-1(W^s) on W^s: the points whose images stay within the grown part
    # (before the last two generations, the last being cut at the length; G = F here)
    for c, step in ((wu, sm.step), (ws, sm.step_inverse)):
        sel = np.flatnonzero(c.generation < c.generation.max() - 1)[1::7]
        p, k = step(c.phi[sel], c.K[sel])
        assert np.max(_distance_to_curve(p, k, c)) < 1e-7


def test_the_stable_branch_is_the_reversors_image_of_the_unstable_one(separatrix):
    # x lies on Fix(R0) (phi = 0): R0 maps W^u(x) onto W^s(x), the branch +v to the branch -R0 v
    sm, x, wu, ws = separatrix
    rp, rk = sm.reversal(wu.phi[1::11], wu.K[1::11])
    mirrored = manifold(sm, x, "stable", 1, length=8.0)
    d = np.minimum(_distance_to_curve(rp, rk, ws), _distance_to_curve(rp, rk, mirrored))
    # the mirrored points are not the stable branch's vertices: the distance to its polyline is
    # its chords' sagitta, at most max_gap^2 kappa / 8 = (8 / 2000)^2 x 5 / 8 = 1e-5
    assert np.max(d) < 1e-5


def test_consecutive_lobes_have_equal_areas_and_the_map_carries_each_into_the_next(separatrix):
    sm, x, wu, ws = separatrix
    L = lobes(wu, ws)
    assert L.areas.size >= 5 and L.spread < 1e-4
    assert np.all(np.sign(L.areas[:-1]) == -np.sign(L.areas[1:]))  # they alternate sides
    # Monte Carlo: points inside lobe j land inside lobe j + 2 (the next of its type)
    pts = L.points
    rng = np.random.default_rng(0)

    def polygon(j):
        a, b = pts[j], pts[j + 1]
        from hovering.dynamics.manifolds import _piece

        ux, uy = _piece(wu, a[2], b[2])
        sx, sy = _piece(ws, min(a[3], b[3]), max(a[3], b[3]), a[4])
        if a[3] < b[3]:
            sx, sy = sx[::-1], sy[::-1]
        return np.concatenate([ux, sx]), np.concatenate([uy, sy])

    px, py = polygon(1)
    qx, qy = polygon(3)
    X = rng.uniform(px.min(), px.max(), 4000)
    Y = rng.uniform(py.min(), py.max(), 4000)
    inside = _inside(X, Y, px, py)
    assert inside.sum() > 200
    # the Monte Carlo area agrees with the shoelace area
    box = (px.max() - px.min()) * (py.max() - py.min())
    assert abs(inside.mean() * box - abs(L.areas[1])) < 4 * box * np.sqrt(inside.mean() / 4000)
    ip, ik = sm.step(np.asarray(hv.wrap(X[inside])), Y[inside])
    lifted = qx.mean() + hv.wrap(ip - qx.mean())  # on lobe 3's copy of the cylinder
    landed = _inside(lifted, ik, qx, qy)
    assert landed.mean() > 0.99


def test_intersections_are_on_both_curves(separatrix):
    sm, x, wu, ws = separatrix
    pts = intersections(wu, ws)
    assert pts.shape[0] >= 6
    assert np.max(_distance_to_curve(pts[1:, 0], pts[1:, 1], wu)) < 1e-9
    assert np.max(_distance_to_curve(pts[1:, 0], pts[1:, 1], ws)) < 1e-9


def test_corner_curves_cut_the_manifolds_of_the_impact_zone():
    # eps = -0.6: a hyperbolic period-3 orbit of the impact zone; its unstable branch crosses the
    # corner curves, where the map jumps: breaks, not a continued curve.
    m = hv.TruncatedMap(eps=-0.6, Omega0=hv.OMEGA_G, theta_w=3 * np.pi / 4)
    found = hv.periodic_orbits(m, 3, region=((-np.pi, np.pi), (-0.4, 0.0)), n_seeds=3)
    hyp = [o for o in found if o.stability == "hyperbolic"]
    assert hyp
    wu = manifold(m, hyp[0], "unstable", 1, length=3.0, max_points=50_000)
    assert wu.breaks >= 1 and np.isnan(wu.phi).sum() == wu.breaks
    # between the breaks it is still invariant
    ok = np.flatnonzero(np.isfinite(wu.phi))[1:200]
    p, k = m.step(wu.phi[ok], wu.K[ok])
    for _ in range(2):
        p, k = m.step(p, k)
    assert np.median(_distance_to_curve(p, k, wu)) < 1e-7


def test_the_flows_manifold_is_invariant():
    # The README system at eps = -0.05: the hyperbolic period-2 orbit near the floor; one branch
    # grown to length 0.3 (each return carries the integration error, ~1e-9 here).
    fm = hv.paper.flow_map(eps=-0.05, rtol=1e-12)
    found = hv.periodic_orbits(fm, 2, region=((-np.pi, np.pi), (-0.25, -0.1)), n_seeds=0, n_line=12)
    hyp = [o for o in found if o.stability == "hyperbolic"]
    assert hyp
    wu = manifold(fm, hyp[0], "unstable", 1, length=0.3, max_gap=0.01)
    assert wu.status == "complete"
    ok = np.flatnonzero(np.isfinite(wu.phi) & (wu.generation < wu.generation.max() - 1))[1::5]
    p, k = fm.step(wu.phi[ok], wu.K[ok])
    p, k = fm.step(p, k)  # G = F^2
    # vertices map onto vertices (to the returns' error) or between them: the chords' sagitta
    assert np.max(_distance_to_curve(p, k, wu)) < 1e-4


def test_bad_input(separatrix):
    sm, x, wu, ws = separatrix
    elliptic = hv.periodic_orbit(sm, 3.0, 6.0, 1)
    with pytest.raises(ValueError, match="not hyperbolic"):
        manifold(sm, elliptic)
    with pytest.raises(ValueError, match="kind must be 'unstable' or 'stable'"):
        manifold(sm, x, "both")
    with pytest.raises(ValueError, match="branch must be 1 or -1"):
        manifold(sm, x, branch=2)
    with pytest.raises(ValueError, match="length must lie in"):
        manifold(sm, x, length=-1.0)
    with pytest.raises(ValueError, match="unstable must be an unstable Manifold"):
        lobes(ws, ws)


def test_the_lobe_flux_is_the_leak_of_a_uniform_ensemble_across_the_barrier(separatrix):
    # The broken separatrix C (W^u from the fixed point to the first intersection, W^s back to the
    # next copy of the point, a closed loop round the cylinder) and its copies C + (0, 2 pi j) cut
    # the standard map's cylinder (K-periodic with period 2 pi) into layers. Each step exactly the
    # exit lobe's points cross C upward: for points uniform on the torus (an invariant measure) the
    # fraction whose layer index rises by one is A_lobe / (4 pi^2). Measured independently of the
    # lobe's polygon: the layer index of a point is the signed count of C's copies below it on its
    # vertical line.
    sm, x, wu, ws = separatrix
    L = lobes(wu, ws)
    pts = L.points
    h = pts[0]  # the first intersection along W^u (on the copy of W^s shifted by h's shift)
    from hovering.dynamics.manifolds import _piece

    ux, uy = _piece(wu, 0.0, h[2])
    sx, sy = _piece(ws, 0.0, h[3], h[4])
    # every third vertex: chords of ~0.01 move the curve by their sagitta (~1e-5), far below the
    # Monte Carlo's resolution
    cx = np.concatenate([ux[::3], ux[-1:], sx[::-1][::3], sx[:1]])
    cy = np.concatenate([uy[::3], uy[-1:], sy[::-1][::3], sy[:1]])
    span = cx[-1] - cx[0]
    assert abs(abs(span) - 2 * np.pi) < 1e-6  # once round the cylinder

    def index(p, k):
        # signed crossings of the copies of C below (p, k) on the vertical line at p (in blocks of
        # points: a block x the curve's segments at a time)
        x0, x1, y0, y1 = cx[:-1], cx[1:], cy[:-1], cy[1:]
        p = cx[0] + np.mod(p - cx[0], span)  # the copies repeat every turn: one turn of phi
        total = np.zeros(p.size)
        for lo in range(0, p.size, 1000):
            P, Kb = p[lo : lo + 1000, None], k[lo : lo + 1000, None]
            for m in (-1, 0, 1):
                X0, X1 = x0 + m * span, x1 + m * span
                straddle = (X0 <= P) != (X1 <= P)
                t = (P - X0) / np.where(X1 == X0, 1.0, X1 - X0)
                ycross = y0 + t * (y1 - y0)
                direction = np.sign(X1 - X0) * np.sign(span)
                # copies in K: C + 2 pi j lies below k for j <= floor((k - ycross) / 2 pi)
                below = np.floor((Kb - ycross) / (2 * np.pi)) + 1
                total[lo : lo + 1000] += np.sum(np.where(straddle, direction * below, 0.0), axis=1)
        return np.rint(total)

    rng = np.random.default_rng(1)
    n = 60_000
    p = rng.uniform(-np.pi, np.pi, n)
    k = x.K[0] + rng.uniform(-np.pi, np.pi, n)
    p1, k1 = sm.step(p, k)
    # the image's angle, lifted as the step moves it: phi + Omega(K), Omega = 0.3 + K (no wrap)
    lift = p + (0.3 + k) + hv.wrap(p1 - p - (0.3 + k))
    d = index(lift, k1) - index(p, k)
    up, down = np.mean(d == 1), np.mean(d == -1)
    expect = L.flux / (4 * np.pi**2)
    sigma = np.sqrt(expect / n)
    # measured (n = 60,000): 0.00123 up, 0.00147 down, against A_lobe / 4 pi^2 = 0.00147 +- 0.00016
    assert abs(up - expect) < 4 * sigma and abs(down - expect) < 4 * sigma, (up, down, expect, sigma)
    assert np.all(np.abs(d) <= 1)
