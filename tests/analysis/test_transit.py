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
    kw = dict(n_orbits=64, n_steps=2000, start_s=0.97, target_s=0.975, seed=3)
    one = hovering.transit(m, zone, "up", **kw)
    with cf.ThreadPoolExecutor(2) as pool:
        many = hovering.transit(m, zone, "up", executor=hovering.parallel.Executor(pool=pool, pieces=5), **kw)
    for f in ("first_passage", "K_min", "K_max", "s_min", "s_max", "residence", "status", "phi0", "K0"):
        assert np.array_equal(getattr(one, f), getattr(many, f)), f


def test_ctrl_c_keeps_the_orbits_so_far(setup):
    m, zone = setup
    press = CtrlCOnceStarted()
    with pytest.raises(KeyboardInterrupt) as info:
        hovering.transit(
            m, zone, "up", n_orbits=4, n_steps=10**9, start_s=0.5, target_s=1.0, every=10**6, progress=press
        )
    assert time.perf_counter() - press.fired_at < PROMPT
    part = info.value.partial
    assert part.phi0.shape == (4,) and np.all(part.steps_done < 10**9)
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
