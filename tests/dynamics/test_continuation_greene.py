"""Continuation of periodic orbits in a parameter (hovering.continue_orbit) and Greene's residue
criterion (hovering.dynamics.greene_residues, greene_critical).

Oracles: the standard map's elliptic fixed point (residue k / 4 along its branch, period doubling
at k = 4 exactly), an algebraic fold (x^2 + p = 0), Greene's critical k = 0.971635406 of the golden
circle, and the critical curve of ``critical_curve``.
"""

from __future__ import annotations

import numpy as np
import pytest

import hovering as hv
from hovering.dynamics import GOLDEN, convergents, greene_critical, greene_residues, pseudo_arclength


def test_the_elliptic_fixed_point_doubles_its_period_at_k_4():
    sm = hv.TruncatedMap(eps=1.0, Omega0=0.3, theta_w=2.0)
    fixed = hv.periodic_orbit(sm, 3.0, 6.0, 1)
    branch = hv.continue_orbit(sm, fixed, 5.0)
    assert branch.status == "complete" and branch.parameter[-1] >= 5.0
    # along the branch: residue k / 4 (the fixed point does not move: phi = pi, Omega(K) = 2 pi)
    assert np.allclose(branch.residue, branch.parameter / 4, atol=1e-10)
    assert np.allclose(branch.K, 2 * np.pi - 0.3, atol=1e-10)
    assert [e["kind"] for e in branch.events] == ["period doubling"]
    assert abs(branch.events[0]["parameter"] - 4.0) < 1e-9  # the residue is linear in k: exact
    assert branch.stability[0] == "elliptic" and branch.stability[-1] == "inverse hyperbolic"


def test_pseudo_arclength_turns_round_a_fold():
    # x^2 + p = 0 from (1, -1) towards p = 0: the branch turns at (0, 0) and comes back (x < 0);
    # natural continuation in p would stop at the fold.
    G = lambda y: np.array([y[0] ** 2 + y[1]])  # noqa: E731
    J = lambda y: np.array([[2 * y[0], 1.0]])  # noqa: E731
    pts, tans, status = pseudo_arclength(G, J, np.array([1.0, -1.0]), np.array([-0.5, 1.0]), 0.1, 40)
    assert status == "complete"
    assert np.max(np.abs(pts[:, 0] ** 2 + pts[:, 1])) < 1e-10
    assert pts[:, 1].max() < 1e-3 and pts[-1, 0] < -1  # it went round the fold
    turn = np.flatnonzero(tans[:-1, 1] * tans[1:, 1] < 0)
    assert turn.size == 1  # dp/ds changes sign once: the fold


def test_continuation_on_the_flow_follows_the_orbit():
    # The README system's elliptic period-2 orbit (the 3/2 resonance), eps from -0.05 to -0.07: each
    # point of the branch is the orbit periodic_orbit finds at that eps.
    fm = hv.paper.flow_map(eps=-0.05)
    found = hv.periodic_orbits(fm, 2, region=((-np.pi, np.pi), (-0.1, 0.05)), n_seeds=0, n_line=12)
    ell = [o for o in found if o.stability == "elliptic"][0]
    branch = hv.continue_orbit(fm, ell, -0.07, ds=0.005, n_steps=10)
    assert branch.status == "complete" and branch.parameter.min() <= -0.07
    assert np.all(np.diff(branch.residue) > 0)  # the resonance widens with |eps|
    check = hv.periodic_orbit(fm.with_eps(float(branch.parameter[3])), branch.phi[3] + 1e-3, branch.K[3], 2)
    assert check.converged and abs(check.residue - branch.residue[3]) < 1e-6
    # both to the flow's default tolerance (1e3 rtol = 1e-7 in the residual)
    assert min(np.hypot((check.phi - branch.phi[3] + np.pi) % (2 * np.pi) - np.pi, check.K - branch.K[3])) < 1e-6


def test_convergents():
    assert convergents(GOLDEN, 8) == [(0, 1), (1, 1), (1, 2), (2, 3), (3, 5), (5, 8), (8, 13), (13, 21)]
    assert convergents(np.pi, 4) == [(3, 1), (22, 7), (333, 106), (355, 113)]


def test_greene_verdicts_on_both_sides_of_the_standard_maps_critical_k():
    for k, verdict in ((0.9, "exists"), (1.05, "destroyed")):
        m = hv.TruncatedMap(eps=k, Omega0=0.0, theta_w=2.0)
        g = greene_residues(m, GOLDEN, (2.5, 5.5), min_period=13, max_period=233)
        assert g.verdict == verdict, (k, g.residues)


def test_greenes_critical_k_of_the_golden_circle():
    # The parameter where the elliptic orbits of the convergents 89/144 .. 233/377 reach residue 1/4
    # converges to k_c = 0.971635406 (Greene 1979; MacKay 1983: 0.9716354061).
    sm = hv.TruncatedMap(eps=1.0, Omega0=0.0, theta_w=2.0)
    gc = greene_critical(sm, GOLDEN, (0.95, 1.0), (2.5, 5.5), min_period=89, max_period=377)
    assert gc.q.tolist() == [89, 144, 233, 377]
    err = np.abs(gc.parameter - 0.971635406)
    assert err[-1] < 1e-5 and err[-1] < err[0]  # 2e-6 at q = 377 (2e-5 at 89)
    assert gc.error < 1e-5


def test_the_critical_curve_of_critical_curve_is_a_robust_circle():
    # The paper's map at eps = 0.3: critical_curve finds the lowest circle that never impacts, with
    # rotation rho_c. The orbits of rho_c's convergents on L1 (the curve's minimum) lie on it, with
    # residues -> 0: it is a KAM circle far from breaking up; what makes it the lowest is the impact
    # region below it (orbits started under it impact), not the loss of its own stability.
    m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=3 * np.pi / 4)
    cc = hv.critical_curve(m, n_steps=20_000)
    g = greene_residues(m, cc.rotation / (2 * np.pi), (cc.K_min - 0.02, cc.K_min + 0.02), max_period=700, lines=("L1",))
    found = np.isfinite(g.residues[:, 0])
    assert found.sum() >= 3 and g.verdict == "exists"
    long = g.q >= 600
    assert np.all(np.abs(g.residues[long & found, 0]) < 1e-6)
    assert np.all(np.abs(g.K[long & found, 0] - cc.K_min) < 1e-3)  # they sit on the curve


def test_bad_input():
    sm = hv.TruncatedMap(eps=1.0, Omega0=0.3, theta_w=2.0)
    fixed = hv.periodic_orbit(sm, 3.0, 6.0, 1)
    with pytest.raises(ValueError, match="stop must differ"):
        hv.continue_orbit(sm, fixed, 1.0)
    with pytest.raises(ValueError, match="parameter .* is required with a family"):
        hv.continue_orbit(sm, fixed, 2.0, family=lambda p: sm.with_eps(p))
    with pytest.raises(ValueError, match="bracket must be"):
        greene_critical(sm, GOLDEN, (1.0, 0.9), (2.5, 5.5))
    with pytest.raises(ValueError, match="lines: each must be one of"):
        greene_residues(sm, GOLDEN, (2.5, 5.5), lines=("x",))
