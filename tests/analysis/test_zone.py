"""The impact zone as two curves and its coordinate s: s and K_at are each other's inverse, the
boundaries sit at s = 0 and 1, and the orbits the boundaries were measured from lie on them within
the curves' own error estimates."""

from __future__ import annotations

import numpy as np
import pytest

import hovering
from hovering import paper

PHI = np.linspace(-np.pi, np.pi, 257)


def test_constant_curves_give_the_affine_coordinate_exactly():
    z = hovering.ImpactZone(ceiling=hovering.Curve.constant(0.25), floor=hovering.Curve.constant(-0.75))
    K = np.linspace(-1, 1, 9)
    # (K + 0.75) / 1.0 in binary: exact for these K (multiples of 1/4)
    assert np.array_equal(z.s(0.3, K), K + 0.75)
    assert np.array_equal(z.K_at(0.3, K + 0.75), K)
    assert z.s(2.0, 0.25) == 1.0 and z.s(-2.0, -0.75) == 0.0 and z.height(0.1) == 1.0


def test_s_and_K_at_are_inverse_and_the_boundaries_are_0_and_1_on_spline_curves():
    c = hovering.Curve.from_function(lambda p: 0.1 + 0.05 * np.cos(p) + 0.02 * np.sin(3 * p), n=64)
    f = hovering.Curve.from_function(lambda p: -0.3 + 0.04 * np.sin(p), n=32)
    z = hovering.ImpactZone(ceiling=c, floor=f)
    assert np.array_equal(z.s(PHI, c(PHI)), np.ones_like(PHI))  # the same evaluation, divided by itself
    assert np.array_equal(z.s(PHI, f(PHI)), np.zeros_like(PHI))
    s = np.linspace(-0.5, 1.5, 41)[:, None]
    K = z.K_at(PHI[None, :], s)
    # Rounding only: a few ulps of the values involved (|K| <= 0.5, height ~0.4).
    assert np.max(np.abs(z.s(PHI[None, :], K) - s)) <= 1e-14
    assert np.isnan(z.s(0.0, np.nan))  # the padding of a stopped orbit stays missing


def test_a_ceiling_below_the_floor_is_refused_naming_where():
    c = hovering.Curve.from_function(lambda p: 0.1 * np.cos(p), n=32)
    with pytest.raises(ValueError, match=r"ceiling must lie above the floor .* at phi = "):
        hovering.ImpactZone(ceiling=c, floor=hovering.Curve.constant(0.05))
    with pytest.raises(ValueError, match="ceiling must be a hovering.Curve, got float"):
        hovering.ImpactZone(ceiling=0.1, floor=hovering.Curve.constant(0.0))
    with pytest.raises(ValueError, match="ceiling must lie above the floor"):
        hovering.impact_zone(paper.truncated_map(0.3), ceiling=-1.0, floor=-0.5)


def test_truncated_zone_ceiling_is_the_critical_curve_and_the_floor_the_band_edge():
    m = paper.truncated_map(0.3)
    z = hovering.impact_zone(m, n_steps=5000)
    assert z.floor_kind == "band" and z.floor.n == 1 and z.floor(0.0) == m.valid_band()[0]
    cc = hovering.critical_curve(m, 5000)  # the same search, run again: an orbit the curve was built from
    ok = np.isfinite(cc.K)
    s = z.s(cc.phi[ok], cc.K[ok])
    # The orbit lies on the ceiling within the curve's own scatter estimate (max_error, in K)
    # divided by the zone's least height.
    tol = z.ceiling.max_error / np.min(z.height(PHI))
    assert np.max(np.abs(s - 1)) <= tol and tol < 1e-6
    # The curve passes through the critical orbit's start on L1 (its height K0 there).
    assert z.ceiling(m.L1(cc.K0)) == pytest.approx(cc.K0, abs=2 * z.ceiling.max_error + 1e-9)


def test_flow_zone_floor_is_the_flows_own_and_its_orbit_lies_at_s_0():
    fm = paper.flow_map(0.05)
    z = hovering.impact_zone(fm, n_steps=1000)
    assert z.floor_kind == "flow"
    fl = hovering.impact_zone_floor(fm, n_steps=1000)
    ok = np.isfinite(fl.K)
    tol = z.floor.max_error / np.min(z.height(PHI))
    assert np.max(np.abs(z.s(fl.phi[ok], fl.K[ok]))) <= tol and tol < 1e-5
    # The floor lies below the flow's upper-tangent torus height +- the search window, and the
    # ceiling above it: the zone is the band the paper's Discussion asks about.
    assert np.all(z.floor(PHI) < 0) and np.all(z.height(PHI) > 0)


def test_a_zone_saves_and_loads(tmp_path):
    c = hovering.Curve.from_function(lambda p: 0.1 + 0.05 * np.cos(p), n=16)
    z = hovering.ImpactZone(ceiling=c, floor=hovering.Curve.constant(-0.2), floor_kind="band")
    hovering.save(z, tmp_path / "z.npz")
    back = hovering.load(tmp_path / "z.npz")
    assert back.floor_kind == "band" and np.array_equal(back.s(PHI, 0.0), z.s(PHI, 0.0))


def test_a_floor_below_the_band_is_raised_just_inside_it():
    """A given floor that dips below the map's band (the flow's floor torus given to its truncated
    model, whose band is narrower) is raised to 1% of the zone's height above the band's edge
    where it dips, and kept where it does not (to the spline's accuracy on a smooth stretch, 1e-6
    of the floor's size here). The zone's height runs from the band's edge to the ceiling's top
    (0.5 here; the band's own top, 1.0, is no scale: a truncated map's band reaches up to K ~ 1e6)."""
    m = hovering.TruncatedMap(eps=0.3, Omega0=hovering.OMEGA_G, theta_w=3 * np.pi / 4, K_max=1.0)
    lo, hi = m.valid_band()
    floor = hovering.Curve.from_function(lambda p: lo + 0.05 * np.cos(p), n=64)
    zone = hovering.impact_zone(m, ceiling=0.5, floor=floor)
    assert zone.raised and not hovering.impact_zone(m, ceiling=0.5, floor=lo + 0.1).raised
    p = np.linspace(-np.pi, np.pi, 2001)
    edge = lo + 0.01 * (0.5 - lo)
    assert np.all(zone.floor(p) > lo)
    away = np.abs(floor(p) - edge) > 0.01  # off the kinks, where the spline is smooth
    np.testing.assert_allclose(zone.floor(p)[away], np.maximum(floor(p), edge)[away], atol=1e-6)


# ------------------------------------------------------------------------------------------------
# The searches at both signs of eps and at large |eps|; a ValueError that says why where they fail


def test_a_given_floor_on_a_truncated_map_is_kept():
    """The paper's map has a band up to K ~ 1e6 (|Omega| = 1e6): a margin of 1% of the band's
    height put a given floor at K ~ 1e4, above the ceiling, and the zone failed. Now a floor inside
    the band is kept as given, and the ceiling is the critical curve as without it."""
    m = paper.truncated_map(0.3)
    zone = hovering.impact_zone(m, n_steps=5000, floor=-1.0)
    assert zone.floor_kind == "given" and not zone.raised and zone.floor(0.3) == -1.0
    assert zone.ceiling == hovering.impact_zone(m, n_steps=5000).ceiling


@pytest.mark.parametrize("eps", [0.3, -0.3, 0.9, -0.9])
def test_truncated_zones_at_both_signs_and_large_eps(eps):
    """The ceiling is a circle that never impacts (checked on its own orbit, 20,000 steps, from
    where it crosses the search line) above the band's floor. eps = -0.9 (the sign that does not
    hover): no curve in the leading-order range (the circles near K = 0 dip into J_R or are
    destroyed, k = |eps| tau0 = 0.9), which raised RuntimeError; the search now widens and finds
    the lowest one above (K ~ 4.3-5.2, rotation near 1 - golden)."""
    m = paper.truncated_map(eps)
    zone = hovering.impact_zone(m, n_steps=5000)
    assert zone.floor_kind == "band"
    line = m.L1 if m.theory().hovers else m.L2
    K = float(np.mean(zone.ceiling.K))
    for _ in range(100):  # where the ceiling crosses its search line
        K = float(zone.ceiling(float(line(K))))
    res = m.iterate([float(line(K))], [K + 2 * zone.ceiling.max_error], 20_000, record=("residence",))
    impacts = res.residence[0, [int(hovering.Region.UPPER), int(hovering.Region.RIGHT)]].sum()
    assert res.status[0] == hovering.Status.OK and impacts == 0


def test_the_ceiling_is_searched_above_the_floor():
    """A floor at or above the critical curve leaves no zone: the lowest start above it already
    lies on a non-impacting curve. The old search returned that curve as the ceiling (a sliver
    zone, dipping to the floor at K = -0.299 against a critical curve at -0.47); now it says so."""
    m = paper.truncated_map(0.5)
    with pytest.raises(ValueError, match=r"the impact zone is empty on L1: the lowest start above the floor"):
        hovering.impact_zone(m, n_steps=5000, floor=-0.3)
    # below the critical curve (K = -0.47 on L1) the zone is there, its ceiling the critical curve
    # (the grid starts higher, so the bisection ends on another start of the critical curve's
    # fractal edge: measured 3e-5 apart in K; the band-floored zone's own ceiling is the reference)
    zone = hovering.impact_zone(m, n_steps=5000, floor=-0.6)
    ref = hovering.impact_zone(m, n_steps=5000).ceiling
    assert zone.ceiling.K.min() == pytest.approx(ref.K.min(), abs=1e-4) and zone.ceiling.K.min() < -0.46


def test_flow_searches_fail_with_a_reason_and_what_to_pass():
    """README system: at eps = -0.3 the eps = 0 torus tangent to the upper wall (K = -0.153) lies
    below the band of the normal coordinates (from -0.117): no floor (the search raised
    RuntimeError); its measured truncated model at eps = +0.3 has no invariant curve in its band
    (the leading-order range, 3 K_crit = +0.56 > the band's top, was refused by critical_curve)."""
    fm = hovering.FlowMap(paper.system(eps=-0.3), 1.0)
    with pytest.raises(ValueError, match=r"^no invariant curve .* that torus lies below the band .* floor="):
        hovering.impact_zone(fm, n_steps=1000)
    model = hovering.FlowMap(paper.system(eps=0.3), 1.0).truncated()
    with pytest.raises(ValueError, match=r"no ceiling found for the impact zone: .* Pass K_range=.* ceiling="):
        hovering.impact_zone(model, n_steps=2000)


def test_flow_at_the_sign_that_does_not_hover_is_refused_not_inverted():
    """README system at eps = +0.2 (does not hover): the flow's floor torus reaches K = 0, and the
    orbits just above it never impact. The old ceiling search went below the floor and returned an
    invariant curve of J_0 (K0 at the band's edge) under it, and the zone failed with "ceiling
    below the floor"; the search now starts above the floor and says the zone is empty there."""
    fm = hovering.FlowMap(paper.system(eps=0.2), 1.0)
    with pytest.raises(ValueError, match="the impact zone is empty on L2"):
        hovering.impact_zone(fm, n_steps=1000)
