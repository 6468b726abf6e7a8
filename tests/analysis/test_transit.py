"""Transport across the impact zone: transit's first passages, K extremes and crossing statistics
against a plain Python loop over m.step on a short run; the escape-rate fit against its closed
form; the executor gives the one-process answer; Ctrl-C keeps the orbits so far; bad input first."""

from __future__ import annotations

import concurrent.futures as cf
import math
import time

import numpy as np
import pytest

import hovering
from conftest import PROMPT, CtrlCOnceStarted
from hovering import Status, paper


@pytest.fixture(scope="module")
def setup():
    m = paper.truncated_map(0.3)
    return m, hovering.impact_zone(m, n_steps=5000)


def _loop(m, target, phi, K, n_steps, up=True):
    """First passage and K extremes of one orbit, by m.step, state by state (the start included)."""
    kmin = kmax = K
    for n in range(n_steps + 1):
        kmin, kmax = min(kmin, K), max(kmax, K)
        if (K >= target(phi)) if up else (K <= target(phi)):
            return n, kmin, kmax
        if n == n_steps:
            break
        phi, K = m.step(phi, K)
    return -1, kmin, kmax


def test_first_passages_and_extremes_are_the_plain_loops(setup):
    m, zone = setup
    # Near the ceiling, where a few orbits cross in a short run (measured: 2 of 200 in 2e4 steps).
    r = hovering.transit(m, zone, "up", n_orbits=40, n_steps=3000, start_s=0.97, target_s=0.975, kernel="scalar")
    assert 0 < np.count_nonzero(r.crossed) < 40  # both outcomes are exercised
    for i in range(40):
        fp, kmin, kmax = _loop(m, r.target, float(r.phi0[i]), float(r.K0[i]), 3000)
        assert r.first_passage[i] == fp, i
        assert r.K_min[i] == kmin and r.K_max[i] == kmax, i  # the scalar kernel is m.step's arithmetic
        assert r.status[i] == (Status.STOPPED if fp >= 0 else Status.OK)
        assert r.steps_done[i] == (fp if fp >= 0 else 3000)
    # starts lie on their level, the target curve on its own (to the spline's error)
    assert np.max(np.abs(zone.s(r.phi0, r.K0) - 0.97)) <= 1e-14
    phi = np.linspace(-np.pi, np.pi, 101)
    assert np.max(np.abs(zone.s(phi, r.target(phi)) - 0.975)) <= 10 * r.target.max_error / np.min(zone.height(phi))


def test_downward_transit_and_s_extremes_over_recorded_states(setup):
    m, zone = setup
    r = hovering.transit(m, zone, "down", n_orbits=20, n_steps=500, start_s=0.99, target_s=0.5, every=1)
    res = m.iterate(r.phi0, r.K0, 500, record=("orbit",))
    s = zone.s(res.phi, res.K)
    never = ~r.crossed
    assert np.array_equal(r.s_min[never], s[never].min(axis=1)) and np.array_equal(r.s_max[never], s[never].max(axis=1))


def test_crossing_statistics_are_their_definitions(setup):
    m, zone = setup
    r = hovering.transit(m, zone, "up", n_orbits=200, n_steps=5000, start_s=0.97, target_s=0.975)
    k = int(np.count_nonzero(r.crossed))
    assert r.fraction == k / 200
    assert r.fraction_error == pytest.approx(math.sqrt(r.fraction * (1 - r.fraction) / 200))
    gamma, err = r.escape_rate
    exposure = np.sum(np.where(r.crossed, r.first_passage, r.steps_done))
    assert gamma == pytest.approx(k / exposure) and err == pytest.approx(gamma / math.sqrt(k))
    none = hovering.transit(m, zone, "up", n_orbits=10, n_steps=100, start_s=0.5, target_s=1.0)
    assert none.fraction == 0 and none.escape_rate is None and none.fraction_error == 0.1


def test_an_executor_gives_the_one_process_answer(setup):
    m, zone = setup
    kw = dict(n_orbits=64, n_steps=2000, start_s=0.97, target_s=0.975, rng=3)
    one = hovering.transit(m, zone, "up", **kw)
    with cf.ThreadPoolExecutor(2) as pool:
        many = hovering.transit(m, zone, "up", executor=hovering.parallel.Executor(pool=pool, pieces=5), **kw)
    for f in ("first_passage", "K_min", "K_max", "s_min", "s_max", "residence", "status", "phi0", "K0"):
        assert np.array_equal(getattr(one, f), getattr(many, f)), f


def test_ctrl_c_keeps_the_orbits_so_far(setup):
    m, zone = setup
    press = CtrlCOnceStarted()
    # ~3 s of work on an idle core (4 orbits x 1e7 steps), Ctrl-C pressed at its first progress
    # report (~0.1 s): if the interrupt were lost, the call would return in seconds and fail here
    # instead of hanging (1e9 steps per orbit sat over 10 minutes under load).
    with pytest.raises(KeyboardInterrupt) as info:
        hovering.transit(
            m, zone, "up", n_orbits=4, n_steps=10**7, start_s=0.5, target_s=1.0, every=10**5, progress=press
        )
    assert time.perf_counter() - press.fired_at < PROMPT
    part = info.value.partial
    assert part.phi0.shape == (4,) and np.all(part.steps_done < 10**7)
    assert np.all(part.status == Status.INTERRUPTED)


@pytest.mark.parametrize(
    "kw, match",
    [
        (dict(direction="sideways"), "direction must be 'up' or 'down', got 'sideways'"),
        (dict(start_s=1.0, target_s=0.5), "start_s must lie below target_s"),
        (dict(direction="down", start_s=0.1, target_s=0.5), "start_s must lie above target_s"),
        (dict(n_orbits=0), r"n_orbits must be an integer in \[1, "),
        (dict(start_s=float("nan")), "start_s"),
        (dict(every=0), "every must be an integer"),
        (dict(executor="x" * 0), "scheduler must be an address"),
    ],
)
def test_bad_input_is_named_before_any_work(setup, kw, match):
    m, zone = setup
    t = time.process_time()
    with pytest.raises(ValueError, match=match):
        hovering.transit(m, zone, **{"n_steps": 10**12, **kw})
    assert time.process_time() - t < 5  # refused, not computed (1e12 steps would take hours)


def test_zone_type_is_checked_and_results_save(setup, tmp_path):
    m, zone = setup
    with pytest.raises(ValueError, match="zone must be a hovering.ImpactZone"):
        hovering.transit(m, (0, 1))
    r = hovering.transit(m, zone, "up", n_orbits=8, n_steps=200)
    hovering.save(r, tmp_path / "t.npz")
    back = hovering.load(tmp_path / "t.npz")
    assert np.array_equal(back.first_passage, r.first_passage) and back.target == r.target


# ------------------------------------------------------------------------------------------------
# Crossings that can happen: targets inside the zone (the defect: targets on its invariant edges)

#: The first-mode truncated model of the system of docs/impact-zone.md's positive case (the README
#: system with V2 = Tan(1, 0.7), eps = +0.05: onset parameters and eps b_1 = 0.05 x 1.828, rounded
#: to 5 digits): its zone has no barrier, its orbits cross it both ways in 1e4-1e5 steps.
TAN = dict(eps=0.0914, Omega0=7.6696, theta_w=2.2117, tau0=3.0788, tau1=1.2223, lam=1.9072)


@pytest.fixture(scope="module")
def chaotic():
    """TAN's map in the zone from K = -0.2 (about the middle height of its flow's floor torus,
    -0.34 .. -0.09; the model has no floor of its own) to its critical curve."""
    m = hovering.TruncatedMap(**TAN)
    return m, hovering.impact_zone(m, n_steps=20_000, floor=-0.2)


def test_default_targets_lie_inside_the_zone_at_the_margin():
    m = paper.truncated_map(0.3)
    zone = hovering.ImpactZone(ceiling=hovering.Curve.constant(0.1), floor=hovering.Curve.constant(-0.3))
    up = hovering.transit(m, zone, "up", n_orbits=4, n_steps=10)
    down = hovering.transit(m, zone, "down", n_orbits=4, n_steps=10)
    assert (up.start_s, up.target_s) == (0.05, 0.98) and (down.start_s, down.target_s) == (0.95, 0.02)
    assert hovering.transit(m, zone, "up", n_orbits=4, n_steps=10, margin=0.1).target_s == 0.9
    assert hovering.transit(m, zone, "down", n_orbits=4, n_steps=10, margin=0.1).target_s == 0.1
    for bad in (0.0, 0.5, -0.1, float("nan")):
        with pytest.raises(ValueError, match="margin"):
            hovering.transit(m, zone, "up", n_orbits=4, n_steps=10, margin=bad)


def test_a_chaotic_zone_is_crossed_both_ways_with_the_defaults(chaotic):
    """The positive case: with the default targets (s = 0.98 up, 0.02 down) most orbits cross
    (measured 17 of 24 up, 24 of 24 down in 1e5 steps); aimed at the invariant ceiling itself
    (s = 1, the old default) none does, although the same orbits come within 0.01 of it."""
    m, zone = chaotic
    up = hovering.transit(m, zone, "up", n_orbits=24, n_steps=100_000)
    down = hovering.transit(m, zone, "down", n_orbits=24, n_steps=100_000)
    # Thresholds well under the measured counts: the chaotic orbits' details depend on the last
    # bit of sin (SLEEF on this machine), the fractions do not.
    assert np.count_nonzero(up.crossed) >= 10 and np.count_nonzero(down.crossed) >= 20
    assert up.escape_rate is not None and down.escape_rate is not None
    on_edge = hovering.transit(m, zone, "up", n_orbits=24, n_steps=100_000, target_s=1.0)
    assert not on_edge.crossed.any()
    assert np.max(on_edge.s_max) > 0.99  # ... while they approach it


def test_the_positive_case_is_the_raw_orbits(chaotic):
    """Cross-check by the raw orbits (m.iterate without a stop, the same kernel): each orbit's
    first passage is the first state with K >= target(phi) (resp. <=) of its raw orbit, and the
    orbits that crossed up pass the down target too, later on the same raw orbit: one orbit
    visits both ends of the zone."""
    m, zone = chaotic
    n = 40_000
    up = hovering.transit(m, zone, "up", n_orbits=12, n_steps=n)
    down = hovering.transit(m, zone, "down", n_orbits=12, n_steps=n)
    for r, above in ((up, True), (down, False)):
        raw = m.iterate(r.phi0, r.K0, n, record=("orbit",))
        hit = raw.K >= r.target(raw.phi) if above else raw.K <= r.target(raw.phi)
        first = np.where(hit.any(axis=1), np.argmax(hit, axis=1), -1)
        assert np.array_equal(first, r.first_passage)
        assert np.count_nonzero(first >= 0) >= 6
        s = zone.s(raw.phi, raw.K)
        crossed = np.flatnonzero(first >= 0)
        # the level reached: the zone coordinate at the first passage is past the target level, to
        # the target curve's error (a spline through the level: estimated 1e-16 here; 1e-6 bounds
        # it with room, far below the 0.003 by which the orbits overshoot the level in one step)
        s_hit = s[crossed, first[crossed]]
        assert np.all(s_hit >= r.target_s - 1e-6) if above else np.all(s_hit <= r.target_s + 1e-6)
        if above:  # after reaching s = 0.98 they come back down past s = 0.02 (measured: 9 of 9)
            later = [np.any(s[i, first[i] :] <= down.target_s) for i in crossed]
            assert np.count_nonzero(later) >= len(crossed) // 2


def test_an_orbit_escaping_past_the_target_has_crossed():
    """A truncated map's band floor is the edge of its domain: an orbit that jumps below it ends
    ESCAPED with its image out of the band, before the stop is tested. An image past the target
    has passed the target (the old transit counted it as not crossed). eps = 0.7, the band floor
    K = -pi: measured 9 stopped and 7 escaped past the target of 24."""
    m = paper.truncated_map(0.7)
    zone = hovering.impact_zone(m, n_steps=5000)
    r = hovering.transit(m, zone, "down", n_orbits=24, n_steps=20_000)
    esc = r.status == Status.ESCAPED
    assert esc.any() and np.all(r.crossed[esc])
    assert np.array_equal(r.first_passage[esc], r.steps_done[esc])
    raw = m.iterate(r.phi0[esc], r.K0[esc], 20_000, record=())
    assert np.array_equal(raw.steps_done, r.steps_done[esc]) and np.all(raw.status == Status.ESCAPED)
    assert np.all(raw.K_final <= r.target(raw.phi_final))
    assert np.all(r.crossed == ((r.status == Status.STOPPED) | esc))


def test_a_flow_zone_without_barrier_is_crossed():
    """The flow of the positive case (README system with V2 = Tan(1, 0.7), eps = +0.05): both
    boundaries are the flow's invariant curves, and its orbits cross the zone (measured here 6 of 6
    down to s = 0.02 within 1,791 returns; docs/impact-zone.md: 40 of 40 down, 39 of 40 up within
    20,000, the up direction too slow for this test). Checked on the raw flow orbits of two of
    them: the first state at or below the target is the transit's first passage (tolerance 1e-6
    in s: the target spline's error estimate is 2e-16, the flow's orbits are deterministic)."""
    from hovering.flow.system import Tan

    fm = hovering.FlowMap(paper.system(eps=0.05, V2=Tan(1.0, 0.7)), 1.0)
    zone = hovering.impact_zone(fm, n_steps=1000)
    assert zone.floor_kind == "flow"
    down = hovering.transit(fm, zone, "down", n_orbits=6, n_steps=3000)
    assert np.count_nonzero(down.crossed) >= 4
    i = np.flatnonzero(down.crossed)[:2]
    raw = fm.iterate(down.phi0[i], down.K0[i], int(down.first_passage[i].max()), record=("orbit",))
    for j, k in enumerate(i):
        fp = int(down.first_passage[k])
        s = zone.s(raw.phi[j, : fp + 1], raw.K[j, : fp + 1])
        assert s[-1] <= down.target_s + 1e-6 and np.all(s[:-1] > down.target_s - 1e-6)
