"""FlowMap: the flow's return map as an iterable map on (phi, K), checked against exact answers,
an independent labelling of regions, time reversal, the one-return API and its own truncation."""

from __future__ import annotations

import numpy as np
import pytest

import hovering as hv
from conftest import PROMPT, CtrlCOnceStarted
from hovering import FlowStatus, Region, Status, paper


def system(eps=0.0, geometry="step", V1=None, V2=None):
    return paper.system(eps, geometry, V1=V1, V2=V2)


@pytest.fixture(scope="module")
def fm005():
    return hv.FlowMap(system(-0.05), h=1.0, rtol=1e-12)


@pytest.fixture(scope="module")
def fm0():
    return hv.FlowMap(system(0.0), h=1.0, rtol=1e-12)


def exact_advance(sys, h, I, region):
    """The eps = 0 return: I is conserved and theta advances by an exact, region-dependent angle.

    J_0u / J_0: Omega0(I) = omega2(H2) T1(h - H2) (eq:omega0ofI); J_R: omega2 times the time to the
    right wall and back, (2 / omega1) arccos(qw1 / A1) for the harmonic V1; J_1: Omega0(I) +
    2 (pi - theta_w(I)) (eq:Thetaj1).
    """
    e2 = sys.V2.energy(I)
    w2, T1 = sys.V2.frequency(e2), sys.V1.period(h - e2)
    if region == Region.RIGHT:
        return w2 * 2 * np.arccos(sys.qw1 / np.sqrt(2 * (h - e2)))
    if region == Region.UPPER:
        return w2 * T1 + 2 * (np.pi - sys.V2.angle_of(sys.qw2, e2))
    return w2 * T1


def test_eps0_is_the_exact_interval_exchange(fm0):
    # At eps = 0 the normal coordinates are (theta, I - I_tan(h)): K is conserved exactly and phi
    # advances by the exact angle of the return's region. 50 returns at rtol = atol = 1e-12: each
    # return's angle is ~3e-11 off (measured: 1.7e-9 after 50, growing linearly), so 5e-9.
    rng = np.random.default_rng(1)
    phi0, K0 = rng.uniform(-np.pi, np.pi, 40), rng.uniform(-0.08, 0.05, 40)
    res = fm0.iterate(phi0, K0, 50, record=("orbit", "regions"))
    assert np.all(res.status == Status.OK)
    I_tan = fm0.curve.I_tan0
    assert np.abs(res.K - K0[:, None]).max() < 1e-9
    seen = set()
    for i in range(40):
        I = K0[i] + I_tan
        adv = np.array([exact_advance(fm0.sys, 1.0, I, Region(r)) for r in res.region[i]])
        seen |= set(res.region[i].tolist())
        drift = hv.wrap(res.phi[i, 1:] - res.phi[i, 0] - np.cumsum(adv))
        assert np.abs(drift).max() < 5e-9
    assert {int(Region.BESIDE), int(Region.ABOVE), int(Region.RIGHT), int(Region.UPPER)} <= seen


def test_iterate_is_repeated_step_bit_for_bit(fm005):
    # Each return starts on Sigma_h solved from the image's coordinates, in iterate as in step.
    rng = np.random.default_rng(2)
    phi, K = rng.uniform(-np.pi, np.pi, 6), rng.uniform(-0.04, 0.04, 6)
    res = fm005.iterate(phi, K, 5, record=("orbit",), n_threads=2)
    p, k = phi.copy(), K.copy()
    for n in range(5):
        p, k = fm005.step(p, k)
        ok = res.status == Status.OK
        assert np.array_equal(p[ok | (res.steps_done > n)], res.phi[ok | (res.steps_done > n), n + 1])
        assert np.array_equal(k[ok | (res.steps_done > n)], res.K[ok | (res.steps_done > n), n + 1])


def test_step_is_one_return_map_in_normal_coordinates(fm005):
    # fm.step(phi, K) = Section.return_map from (phi, K + I_tan(phi)), read in normal coordinates.
    phi = np.linspace(-3.0, 3.0, 25)
    K = np.full(25, -0.02)
    p1, K1 = fm005.step(phi, K)
    th, I = fm005.curve.from_normal(phi, K)
    out = fm005.section.return_map(th, I, rtol=1e-12, atol=1e-12)
    q1, L1 = fm005.curve.to_normal(out.theta, out.I)
    assert np.abs(hv.wrap(p1 - q1)).max() < 1e-12 and np.abs(K1 - L1).max() < 1e-12
    assert np.array_equal(fm005.region(phi, K), out.region)


def test_regions_match_an_independent_labelling():
    # Independent labelling: the same start in the *wall* system (the infinite wall q1 = qw1)
    # impacts ('R') exactly when the segment reaches the line, and the step system's flow is the
    # same smooth flow up to that first crossing. So a step return without impact is J_0 ('0')
    # iff the wall system impacts, J_0u ('u') iff it does not; a right-wall impact in the step
    # system is a wall impact below the corner.
    sec_step, sec_wall = hv.Section(system(0.05), 1.0), hv.Section(system(0.05, "wall"), 1.0)
    rng = np.random.default_rng(3)
    th, I = rng.uniform(-np.pi, np.pi, 400), 0.3372 + rng.uniform(-0.05, 0.05, 400)
    a = sec_step.return_map(th, I, rtol=1e-12, atol=1e-12)
    b = sec_wall.return_map(th, I, rtol=1e-12, atol=1e-12)
    ok = (a.status == FlowStatus.OK) & (b.status == FlowStatus.OK)
    assert ok.sum() > 390
    for s, w, r in zip(np.array(a.itinerary, dtype=object)[ok], np.array(b.itinerary, dtype=object)[ok], a.region[ok]):
        if s == "0":
            assert w == "R" and r == Region.ABOVE
        elif s == "u":
            assert w == "u" and r == Region.BESIDE
        elif s == "R":
            assert w == "R" and r == Region.RIGHT
        else:
            assert s[0] == "1" and w == "R"  # the upper wall is reached after crossing the line
    assert {"0", "u", "R", "1"} <= set(np.array(a.itinerary, dtype=object)[ok])


def test_time_reversal_over_many_returns(fm005):
    # F^{-1} = R2 F R2 (lem:timerevgen): 30 returns forward and 30 back bring regular orbits of
    # J_0u (quasi-periodic, K > 0.01) home. At rtol 1e-12 a return is ~1e-11 off and errors grow
    # ~linearly along a regular orbit: 1e-8 leaves a factor ~30.
    phi0 = np.linspace(-3, 3, 8)
    K0 = np.full(8, 0.03)
    res = fm005.iterate(phi0, K0, 30, record=("orbit",))
    p, k = res.phi_final, res.K_final
    for _ in range(30):
        p, k = fm005.step_inverse(p, k)
    assert np.abs(hv.wrap(p - phi0)).max() < 1e-8 and np.abs(k - K0).max() < 1e-8


def test_mixed_batch_keeps_per_orbit_statuses(fm005):
    # One orbit off the section (an action beyond H2^{-1}(h)), one on a corner-singularity curve
    # (bisected to 3e-14: the corner band |q2 - qw2| <= corner_tol = 1e-10 at the impact is ~1e-10
    # wide in phi, so the first point past the last R lies in it), the rest ordinary: each gets its
    # own status, the others are computed exactly as alone.
    phi = np.array([0.3, 0.3, -1.0, 2.0])
    K = np.array([-0.02, 5.0, 0.01, -0.03])
    # corner: bisect the itinerary change R -> 0 on the circle K = -0.02
    lo, hi = -1.2, -0.2
    reg = lambda x: fm005.region(x, -0.02)  # noqa: E731
    assert reg(lo) == Region.RIGHT and reg(hi) == Region.ABOVE
    for _ in range(45):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if reg(mid) == Region.RIGHT else (lo, mid)
    phi[0] = hi
    res = fm005.iterate(phi, K, 3, record=("orbit", "regions"))
    assert res.status[1] == Status.OFF_SECTION and res.steps_done[1] == 0
    assert res.status[0] == Status.CORNER and res.steps_done[0] == 0
    assert np.all(np.isnan(res.phi[0, 1:])) and np.all(res.region[0] == Region.NONE)
    for i in (2, 3):
        alone = fm005.iterate(phi[i : i + 1], K[i : i + 1], 3, record=("orbit",))
        assert res.status[i] == Status.OK and np.array_equal(alone.phi[0], res.phi[i])
    r = fm005.returns(phi, K)
    assert r.status[1] == FlowStatus.OFF_SECTION and np.isnan(r.phi[1]) and r.status[2] == FlowStatus.OK


def test_section_return_map_keeps_per_orbit_outcomes():
    # A point with no point of Sigma_h used to raise for the whole batch; now it is OFF_SECTION.
    sec = hv.Section(system(0.05), 1.0)
    out = sec.return_map([0.1, 0.2, 0.3], [0.3, 50.0, 0.31])
    assert list(out.status) == [FlowStatus.OK, FlowStatus.OFF_SECTION, FlowStatus.OK]
    assert np.isnan(out.theta[1]) and np.isfinite(out.theta[[0, 2]]).all()
    with pytest.raises(ValueError, match="no point of Sigma_h"):
        sec.point([0.2], [50.0])  # the coordinate conversion itself still names the point


def test_early_exit_and_exit_step(fm005):
    # exit_regions {0u, 0}: the first impact stops the orbit; exit_step is where a full orbit's
    # regions first leave the set.
    rng = np.random.default_rng(4)
    phi, K = rng.uniform(-np.pi, np.pi, 30), rng.uniform(-0.05, 0.0, 30)
    full = fm005.iterate(phi, K, 20, record=("regions",))
    early = fm005.iterate(phi, K, 20, record=("regions",), exit_regions={"0u", "0"}, stop_on_exit=True)
    out = ~np.isin(full.region, [int(Region.BESIDE), int(Region.ABOVE)])
    first = np.where(out.any(1), out.argmax(1), -1)
    assert np.array_equal(early.exit_step, first)
    assert np.array_equal(early.status == Status.EXITED, first >= 0)
    assert np.array_equal(early.steps_done, np.where(first >= 0, first, 20))


def test_records_are_only_what_is_asked(fm005):
    res = fm005.iterate(
        [0.1], [0.01], 4, record=("times", "energy_error", "steps", "itinerary", "section", "states", "visited")
    )
    assert res.phi is None and res.region is None and res.rotation is None
    assert res.time.shape == (1, 4) and np.all(res.time > 5) and np.all(res.energy_error < 1e-10)
    assert res.integrator_steps.shape == (1, 4) and np.all(res.integrator_steps > 10)
    assert res.itinerary == [["u"] * 4] and res.visited[0] == 1 << int(Region.BESIDE)
    H = fm005.sys.core.energy(res.z[0])
    assert np.abs(H - 1.0).max() < 1e-14  # every point is put on Sigma_h at energy h exactly
    assert res.theta.shape == (1, 5) and abs(res.theta[0, 0] - 0.1) < 1e-15
    assert abs(res.I[0, 0] - fm005.curve.from_normal(0.1, 0.01)[1]) < 1e-15
    with pytest.raises(ValueError, match="record: unknown key"):
        fm005.iterate([0.1], [0.01], 4, record=("everything",))


def test_interrupt_keeps_partial_results(fm005):
    # Ctrl-C during a long iterate is honoured promptly and keeps every orbit's state so far.
    rng = np.random.default_rng(5)
    n = 8
    phi, K = rng.uniform(-np.pi, np.pi, n), rng.uniform(0.01, 0.05, n)
    # ~0.7 s per orbit, ~3 s in all on 2 idle cores; Ctrl-C once it has begun (~0.1 s), when no
    # orbit can have ended: a lost interrupt makes the call return within seconds and fail here
    with pytest.raises(KeyboardInterrupt) as info:
        fm005.iterate(phi, K, 20_000, record=("rotation",), n_threads=2, progress=CtrlCOnceStarted())
    res = info.value.partial
    assert res.n_orbits == n and np.all(res.status == Status.INTERRUPTED)
    assert res.steps_done.max() > 0 and res.steps_done.max() < 20_000
    i = int(np.argmax(res.steps_done))
    again = fm005.iterate(phi[i : i + 1], K[i : i + 1], int(res.steps_done[i]), record=())
    assert again.phi_final[0] == res.phi_final[i] and again.K_final[0] == res.K_final[i]


def test_tangential_curve_matches_bisection_and_is_the_tangency():
    # The curve traced back from the wall agrees with the bisection oracle (whose 55 halvings of a
    # 0.2-wide bracket resolve ~1e-17 relative, but each decision is a return at rtol 1e-12:
    # ~1e-12), and the flow itself confirms it: 1e-9 below the curve the wall system impacts,
    # 1e-9 above it it does not.
    sec = hv.Section(system(0.1), 1.0)
    c = hv.TangentialCurve(sec)
    th = np.linspace(-3.0, 3.0, 9)
    assert np.abs(c(th) - hv.tangential_curve(sec, th)).max() < 1e-11
    assert c.is_graph and c.interpolation_error < 1e-12
    wall = hv.Section(system(0.1, "wall"), 1.0)
    below = wall.return_map(th, c(th) - 1e-9, rtol=1e-13, atol=1e-15).itinerary
    above = wall.return_map(th, c(th) + 1e-9, rtol=1e-13, atol=1e-15).itinerary
    assert below == ["R"] * 9 and above == ["u"] * 9


def test_tangential_curve_says_when_it_is_not_a_graph():
    # The system: a graph up to eps ~ 0.5; at 0.6 theta(s) turns back (one theta, several
    # tangency actions); at 0.8 the curve no longer winds once around the cylinder; at eps = 1 the
    # points of q1 = qw1 with p1 = 0 are not all minima of q1.
    c = hv.TangentialCurve(hv.Section(system(0.6), 1.0))
    assert not c.is_graph and c.min_slope < 0 and "not a graph" in c.not_graph_reason
    with pytest.raises(ValueError, match="not a graph over theta"):
        c(0.0)
    with pytest.raises(ValueError, match="not a graph over theta"):
        hv.FlowMap(system(0.6), h=1.0)
    with pytest.raises(ValueError, match="winds"):
        hv.TangentialCurve(hv.Section(system(0.8), 1.0))
    with pytest.raises(ValueError, match="not a minimum of q1"):
        hv.TangentialCurve(hv.Section(system(1.0), 1.0))
    fs = hv.FlowMap(system(0.6), h=1.0, coordinates="section")
    assert fs.step(0.1, 0.2)[1] > 0  # theta, I still work
    # ... but not every return lands on Sigma_h's chart: from (0.1, 0.3) the next maximum of q1
    # lies at q1 = -0.23 < 0, which no (theta, I) describes; it is OFF_SECTION, not a misnamed point
    r = hv.Section(system(0.6), 1.0).return_map([0.1], [0.3])
    assert r.status[0] == hv.FlowStatus.OFF_SECTION and r.z[0, 0] < 0 and np.isnan(r.I[0])
    assert np.isnan(fs.step(0.1, 0.3)[1])


def test_a_curve_that_cannot_be_traced_names_the_status_and_the_energy():
    # h = 1e6 (an adversarial pass): the tangential curve's first trace back ends IMPRECISE; the
    # message said "(integration status 9)". It names the status as hovering.FlowStatus does, what
    # that means, the energy and the tolerance of the trace.
    sys = hv.StepSystem(hv.Harmonic(1.0), hv.Tan(1.4, 0.7), hv.Bilinear(), eps=0.05)
    with pytest.raises(ValueError) as e:
        hv.FlowMap(sys, 1e6)
    msg = str(e.value)
    assert "h = 1e+06" in msg and "rtol = " in msg, msg
    assert f"ended {FlowStatus.IMPRECISE.name} ({FlowStatus.IMPRECISE.__doc__})" in msg, msg


def test_truncated_model_of_the_system_needs_no_hand_scaling(fm005):
    # fm.truncated(): onset-parameter arcs and the measured forcing. Its first sine coefficient is
    # b1 = 0.564 here: passing eps instead of eps b1 to TruncatedMap would overstate the forcing.
    tm = fm005.truncated()
    p = fm005.onset
    b = fm005.forcing_coefficients()
    assert 0.55 < b[0] < 0.58 and abs(b[1]) < 0.05
    assert tm.eps == fm005.eps and np.allclose(tm.forcing, b)
    first = fm005.truncated(forcing="first_mode")
    assert first.eps == pytest.approx(-0.05 * b[0]) and first.Omega0 == p.Omega0 and first.lam == p.lam
    # Same map on a regular point of J_0u: the model is the flow to O(eps K, eps^2) (thm:returnmap).
    pf, Kf = fm005.step(0.3, 0.01)
    pt, Kt = tm.step(0.3, 0.01)
    assert abs(hv.wrap(pf - pt)) < 0.05 and abs(Kf - Kt) < 2e-3


def test_hovering_verdicts_of_flow_and_model_agree():
    # |eps| = 0.05 on the system (Omega0 = 9.83, sin(Omega0/2) < 0: it hovers for eps < 0).
    # The same stratified points classified by the flow and by fm.truncated(): measured 99.7%
    # (eps = -0.05) and 100% (eps = +0.05) with 2000 x 2000; here 400 points x 600 returns.
    for eps, hovers in ((-0.05, True), (0.05, False)):
        fm = hv.FlowMap(system(eps), h=1.0)
        flow = hv.hovering_area(fm, n_steps=600, n_samples=400, keep_points=True)
        model = hv.hovering_area(fm.truncated(), n_steps=600, n_samples=400, K_low=flow.box[2], keep_points=True)
        assert np.mean(flow.hovering == model.hovering) >= 0.98
        assert (flow.area > 0.05) == hovers and (model.area > 0.05) == hovers
        assert fm.theory().hovers == hovers and flow.theory == pytest.approx(fm.theory().area)
        assert flow.unresolved == 0 and flow.impact_fraction_F0 == 1.0


def test_impact_zone_floor_is_the_deformed_upper_tangent_torus():
    # Below the torus tangent to the upper wall (K_u = -0.153 at eps = 0) orbits pass above the
    # step without impact; the highest invariant curve there bounds the impact zone from below.
    fm = hv.FlowMap(system(0.05), h=1.0)
    f = hv.impact_zone_floor(fm, n_steps=800, n_grid=24, tol=1e-4)
    assert -0.16 < fm.upper_tangent_K() < -0.15
    assert -0.15 < f.K_min < f.K0 < f.K_max < -0.09  # measured -0.137 < -0.121 < -0.109 at 2000 returns
    above = fm.iterate([0.0], [f.K_fail + 0.01], 800, record=(), exit_regions=("0",), stop_on_exit=True)
    assert above.status[0] == Status.EXITED  # just above it orbits impact (or pass beside the step)


def test_section_return_map_interrupt_keeps_finished_returns():
    # The issue: Ctrl-C during return_map was honoured only when the batch ended (10.6 s after the
    # press) and kept nothing. Now: promptly, with every finished return kept. Ctrl-C is pressed
    # once returns are done (so it lands mid-run on any machine and under any load).
    import time

    sec = hv.Section(system(0.05), 1.0)
    n = 400_000  # ~6 s of returns on 2 cores
    th, I = np.linspace(-3, 3, n), np.full(n, 0.33)
    press = CtrlCOnceStarted()
    with pytest.raises(KeyboardInterrupt) as info:
        sec.return_map(th, I, n_threads=2, progress=press)
    assert time.perf_counter() - press.fired_at < PROMPT
    out = info.value.partial
    done = out.status == FlowStatus.OK
    assert 0 < done.sum() < n and np.all(out.status[~done] == FlowStatus.INTERRUPTED)
    i = int(np.flatnonzero(done)[0])
    again = sec.return_map(th[i : i + 1], I[i : i + 1])
    assert again.theta[0] == out.theta[i] and again.I[0] == out.I[i]


def test_repr_says_the_effective_eps_and_the_band_and_still_evaluates():
    # The truncated model of the flow sees eps b1, not eps (b1 = 0.56 here); the repr says so, with
    # the band, in a comment, so eval(repr) is still the map.
    from hovering import Bilinear, FlowMap, Harmonic, StepSystem, Tan  # noqa: F401  (names eval needs)

    fm = paper.flow_map(0.05)
    text = repr(fm)
    b1 = float(fm.forcing_coefficients()[0])
    lo, hi = fm.valid_band()
    assert f"effective eps = eps b1 = {0.05 * b1:.4g} (b1 = {b1:.4g})" in text
    assert f"band K in [{lo:.4g}, {hi:.4g}]" in text
    again = eval(text)
    assert again.sys == fm.sys and again.h == fm.h and again.step(0.3, -0.02) == fm.step(0.3, -0.02)
