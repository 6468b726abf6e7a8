"""Periodic orbits (hovering.periodic_orbit, periodic_orbits) on both models.

Oracles: the standard map's orbits in closed form (the truncated map above K = 0 is the shifted
standard map, k = eps tau0: fixed points with residue -k cos(phi) / 4, the 1/2 orbit with k^2 / 4);
closure checked with ``step`` (not the iterate the search uses) and the monodromy with the explicit
product of ``jacobian`` along the orbit; the flow's orbits with an independent SciPy integration
(tests/helpers/scipy_flow.py) chained over the period, returning to the start.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import hovering as hv
from helpers import scipy_flow


def _closes(m, o, tol):
    """The orbit's points map onto each other under step(), and its monodromy is the product of
    jacobian() along it."""
    p, k = m.step(o.phi, o.K)
    dphi = (p - np.roll(o.phi, -1) + np.pi) % (2 * np.pi) - np.pi
    assert np.max(np.abs(dphi)) < tol and np.max(np.abs(k - np.roll(o.K, -1))) < tol
    M = np.eye(2)
    for i in range(o.period):
        M = m.jacobian(o.phi[i], o.K[i]).J @ M
    assert np.allclose(M, o.monodromy, rtol=1e-6, atol=1e-6 * np.abs(M).max())


@settings(max_examples=20, deadline=None)
@given(st.floats(0.05, 1.2), st.floats(0.5, 2.0), st.floats(-3.0, 3.0))
@example(eps=1.0, tau0=2.0, Omega0=0.0)  # k = 2: the half orbit's R = 1 exactly (parabolic)
@example(eps=1.2, tau0=2.0, Omega0=0.5)  # k = 2.4: R = 1.44, inverse hyperbolic
def test_the_standard_maps_fixed_points_and_half_orbit(eps, tau0, Omega0):
    # Fixed points: Omega(K) = 2 pi j, phi in {0, pi}: residue -k cos(phi) / 4 (k = eps tau0).
    m = hv.TruncatedMap(eps=eps, Omega0=Omega0, theta_w=2.0, tau0=tau0)
    k = eps * tau0
    K_fix = (4 * np.pi - Omega0) / tau0  # Omega = 4 pi: K > 0 for these parameters
    for phi, sign in ((0.05, -1.0), (np.pi - 0.05, 1.0)):
        o = hv.periodic_orbit(m, phi, K_fix + 0.01, 1)
        assert o.converged and o.minimal_period == 1
        assert abs(o.K[0] - K_fix) < 1e-12 and abs(math.cos(o.phi[0]) + sign) < 1e-12
        assert abs(o.residue - sign * k / 4) < 1e-13
        assert o.stability == ("elliptic" if sign > 0 else "hyperbolic")
        assert o.det_error < 1e-13
        _closes(m, o, 1e-12)
    # The symmetric 1/2 orbit {(0, K), (pi, K)} with Omega(K) = 3 pi: residue k^2 / 4, elliptic for
    # k < 2, parabolic at k = 2, inverse hyperbolic beyond (k reaches 2.4 here).
    K_half = (3 * np.pi - Omega0) / tau0
    o = hv.periodic_orbit(m, 0.0, K_half + 0.01, 2, symmetric=True, line="0")
    assert o.converged and o.line == "0" and o.winding == int(round((Omega0 + tau0 * K_half) * 2 / (2 * np.pi)))
    assert np.allclose(o.K, K_half, atol=1e-12)
    R = k**2 / 4
    assert abs(o.residue - R) < 1e-12
    # the classification's parabolic band is ~1e-13 wide (100 x the map's rounding x the period)
    if abs(R - 1) <= 1e-14:
        assert o.stability == "parabolic"
    elif abs(R - 1) > 1e-11:
        assert o.stability == ("elliptic" if R < 1 else "inverse hyperbolic")
    _closes(m, o, 1e-12)


def test_newton_converges_quadratically():
    # a start 3e-3 from the period-5 orbit: residuals 1e-2, 1e-4, 1e-8, 1e-16
    m = hv.TruncatedMap(eps=0.7, Omega0=0.3, theta_w=2.0)
    exact = hv.periodic_orbit(m, 2.5, 1.2, 5, tol=1e-14)
    assert exact.converged
    o = hv.periodic_orbit(m, exact.phi[0] + 3e-3, exact.K[0] - 3e-3, 5, tol=1e-14)
    assert o.converged and o.newton_steps >= 3 and o.same_orbit(exact)
    orders = o.convergence_orders()
    assert orders.size >= 1 and np.all(orders > 1.7), (o.residuals, orders)


def test_multiple_shooting_gives_the_same_long_orbit_as_fewer_segments():
    # k = 0.9: a period-55 orbit near the golden circle (rotation 34/55), found with 55, 11 and 5
    # segments; the residues agree, the orbit closes under step().
    m = hv.TruncatedMap(eps=0.9, Omega0=0.0, theta_w=2.0)
    K = 2 * np.pi * 34 / 55
    orbits = [hv.periodic_orbit(m, 0.0, K, 55, symmetric=True, line="0", winding=34, segment=s) for s in (1, 5, 11)]
    assert all(o.converged for o in orbits)
    assert all(o.same_orbit(orbits[0]) for o in orbits[1:])
    assert max(abs(o.residue - orbits[0].residue) for o in orbits) < 1e-9
    assert orbits[0].winding == 34
    _closes(m, orbits[0], 1e-10)


def test_the_symmetric_and_general_searches_find_the_same_orbits():
    m = hv.TruncatedMap(eps=0.5, Omega0=0.3, theta_w=2.0)
    found = hv.periodic_orbits(m, 3, region=((-np.pi, np.pi), (0.5, 7.0)), n_seeds=4)
    # rotations 1/3 and 2/3 in this K range: an elliptic and a hyperbolic orbit each (3/3 is the
    # fixed points', of minimal period 1, which periodic_orbits leaves out)
    assert len(found) == 4
    assert sorted(o.winding for o in found) == [1, 1, 2, 2]
    for o in found:
        _closes(m, o, 1e-12)
        assert o.minimal_period == 3
        g = hv.periodic_orbit(m, o.phi[1] + 1e-3, o.K[1] - 1e-3, 3)
        assert g.converged and g.same_orbit(o)
    # Poincare-Birkhoff: each resonance has one elliptic and one hyperbolic orbit, and the
    # residues of a pair have opposite signs
    for w in (1, 2):
        pair = [o for o in found if o.winding == w]
        assert {o.stability for o in pair} == {"elliptic", "hyperbolic"}


def test_even_periods_need_the_second_family_of_lines():
    # The hyperbolic 1/2 orbit of the standard map lies on Fix(R1) (L1, L2), not on phi = 0 or pi.
    m = hv.TruncatedMap(eps=0.5, Omega0=0.3, theta_w=2.0)
    box = ((-np.pi, np.pi), (2.0, 3.5))
    both = hv.periodic_orbits(m, 2, region=box, n_seeds=0)
    only_r0 = hv.periodic_orbits(m, 2, region=box, n_seeds=0, lines=("0", "pi"))
    assert sorted(o.stability for o in both) == ["elliptic", "hyperbolic"]
    assert [o.stability for o in only_r0] == ["elliptic"]
    hyp = [o for o in both if o.stability == "hyperbolic"][0]
    assert hyp.line in ("L1", "L2")


def test_orbits_in_the_impact_zone_cross_the_corner_curves():
    # eps = -0.6, the paper's map: period-2 island chains of the impact zone; every orbit found
    # closes under step() whatever the arcs it visits.
    m = hv.TruncatedMap(eps=-0.6, Omega0=hv.OMEGA_G, theta_w=3 * np.pi / 4)
    found = hv.periodic_orbits(m, 3, region=((-np.pi, np.pi), (-0.4, 0.0)), n_seeds=3)
    assert len(found) >= 2
    impacting = [o for o in found if np.any(np.isin(o.regions, [hv.Region.UPPER, hv.Region.RIGHT]))]
    assert impacting
    for o in found:
        _closes(m, o, 1e-10)


def test_a_failed_search_is_a_status_not_an_exception():
    m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=3 * np.pi / 4, K_max=0.5)
    o = hv.periodic_orbit(m, 0.0, 0.45, 50)  # escapes above K_max within the period
    assert o.status == "step_failed" and o.step_status == hv.Status.ESCAPED and np.all(np.isnan(o.phi))
    o = hv.periodic_orbit(m, 0.0, 0.1, 3, symmetric=True, line="0", K_bracket=(0.1, 0.11))
    assert o.status == "no_root"


@pytest.mark.parametrize(
    "kw,match",
    [
        (dict(period=0), r"period must be an integer in \[1, 100000\]"),
        (dict(period=2.5), r"period must be an integer"),
        (dict(phi=np.nan), r"phi must be finite"),
        (dict(tol=-1.0), r"tol must lie in"),
        (dict(line="L3", symmetric=True), r"line must be one of \['0', 'pi', 'L1', 'L2'\]"),
        (dict(line="0"), r"line, K_bracket and winding are for a symmetric search"),
        (dict(segment=3, period=4), r"segment = 3 must divide the period 4"),
        (dict(max_iter=0), r"max_iter must be an integer in \[1, 1000\]"),
        # a flag, like every other: 'yes' (truthy) used to run a symmetric search
        (dict(symmetric="yes"), r"symmetric must be True or False, got 'yes'"),
        (dict(symmetric=1), r"symmetric must be True or False, got 1"),
    ],
)
def test_bad_input(kw, match):
    m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=3 * np.pi / 4)
    args = dict(phi=0.0, K=0.1, period=2)
    args.update(kw)
    with pytest.raises(ValueError, match=match):
        hv.periodic_orbit(m, **args)
    with pytest.raises(ValueError, match="m must be a map"):
        hv.periodic_orbit("map", 0.0, 0.1, 1)
    with pytest.raises(ValueError, match="region must have"):
        hv.periodic_orbits(m, 1, region=((1.0, 0.0), (0.0, 1.0)))
    with pytest.raises(ValueError, match="lines: each must be one of"):
        hv.periodic_orbits(m, 1, lines=("x",))


# -------------------------------------------------------------------------------------- the flow


def test_the_flows_periodic_orbits_close_under_an_independent_integration():
    # The README system at eps = -0.05: the period-2 orbits of the 3/2 resonance near K = -0.1
    # (one of them impacts the upper wall). Each point's state is integrated by SciPy's DOP853
    # (its own event search) return after return; after the period it is back at the start.
    fm = hv.paper.flow_map(eps=-0.05, rtol=1e-12)
    found = hv.periodic_orbits(fm, 2, region=((-np.pi, np.pi), (-0.25, 0.05)), n_seeds=2, n_line=16)
    assert {o.stability for o in found} >= {"elliptic", "hyperbolic"}
    R1, R2 = scipy_flow.harmonic(1.0), scipy_flow.tan(1.4, 0.7)
    sys = fm.sys
    for o in found:
        assert o.converged and o.det_error < 1e-7
        z0 = fm.section.point(*fm.curve.from_normal(o.phi[:1], o.K[:1]))[0]
        z = z0
        for _ in range(o.period):
            ref = scipy_flow.reference_return(R1, R2, "bilinear", sys.eps, "step", sys.qw1, sys.qw2, z)
            assert ref["status"] == "ok"
            z = ref["z"]
        assert np.max(np.abs(z - z0)) < 1e-8, (o, z - z0)
        # the monodromy against central differences of the period's map (h = 1e-5)
        h = 1e-5
        D = np.empty((2, 2))
        for j, (dp, dk) in enumerate(((h, 0.0), (0.0, h))):
            a, b = (o.phi[0] + dp, o.K[0] + dk), (o.phi[0] - dp, o.K[0] - dk)
            for _ in range(o.period):
                a, b = fm.step(*a), fm.step(*b)
            D[0, j] = ((a[0] - b[0] + np.pi) % (2 * np.pi) - np.pi) / (2 * h)
            D[1, j] = (a[1] - b[1]) / (2 * h)
        assert np.allclose(D, o.monodromy, atol=1e-6 * (1 + np.abs(D).max())), (D, o.monodromy)


# ------------------------------------------------------------------------------ island chains


def test_island_chains_are_linked_to_the_elliptic_orbit_at_their_centre():
    m = hv.TruncatedMap(eps=0.5, Omega0=0.3, theta_w=2.0)
    res = m.iterate(np.pi, [1.3, 1.29, 2.0], 4000, record=("orbit",))
    found = hv.dynamics.island_centres(m, res)
    assert found.index.tolist() == [0, 1] and found.period.tolist() == [5, 5]
    a, b = found.orbits
    assert a.converged and a.stability == "elliptic" and a.same_orbit(b)
    # the orbit lies inside its chain: each island's points surround one of its points
    pts = res.phi[0, ::5], res.K[0, ::5]
    assert np.min(np.hypot((pts[0] - a.phi[:, None] + np.pi) % (2 * np.pi) - np.pi, pts[1] - a.K[:, None])) < 0.2


def test_the_impact_zones_island_chains_from_a_barrier_scan():
    # The zone of docs/impact-zone.md's positive case: every island chain the scan classified has an
    # elliptic periodic orbit of the chain's period at its centre, most of them impacting.
    tm = hv.TruncatedMap(eps=0.0914, Omega0=7.6696, theta_w=2.2117, tau0=3.0788, tau1=1.2223, lam=1.9072)
    zone = hv.impact_zone(tm, floor=-0.2)
    scan = hv.barrier_scan(tm, zone, n_starts=24, n_steps=3000)
    found = hv.dynamics.island_centres(tm, scan)
    assert len(found) >= 4
    for o, q in zip(found.orbits, found.period):
        assert o.converged and o.period == q and o.minimal_period == q and o.stability == "elliptic"
        _closes(tm, o, 1e-10)  # the default tolerance, 1e-11, times the step's stretch
    assert any(np.isin(o.regions, [hv.Region.UPPER, hv.Region.RIGHT]).any() for o in found.orbits)
    with pytest.raises(ValueError, match="orbits must be an IterateResult"):
        hv.dynamics.island_centres(tm, "scan")


def test_a_nearly_parabolic_start_is_not_called_converged():
    # An adversarial pass: near a nearly parabolic fixed point of the flow's map (R ~ -1.4e-7,
    # Newton's matrix M - I nearly singular) the damped correction let the residual grow
    # 4.79e-6 -> 4.99e-6 -> 5.19e-6, and "two iterations without halving it, within 1e3 tol"
    # called that the rounding floor: "converged", 520x tol, where the flow's floor at rtol 1e-11
    # is ~1e-10. A floor now needs Newton's correction as small as the residual (here it is
    # large); a converged orbit closes to within 1e3 tol under the map itself.
    s = hv.StepSystem(
        hv.Harmonic(0.2883501599780604),
        hv.Tan(0.3904664669129242, 0.3437536550974594),
        hv.Polynomial({(1, 3): 0.55, (0, 3): 1.151}),
        eps=-0.0007,
        qw1=-3.338674907363699,
        qw2=-2.6224194265302465,
        geometry="step",
    )
    fm = hv.FlowMap(s, 2.788777826091436, rtol=1e-11)
    po = hv.periodic_orbit(fm, 1.32246813, 0.23130818, 1)
    x1 = fm.step(float(po.phi[0]), float(po.K[0]))
    gap = max(abs(float(hv.wrap(x1[0] - po.phi[0]))), abs(x1[1] - po.K[0]))
    assert po.status != "converged" and gap > 100 * po.tol, (po.status, gap, po.residuals)
