"""Ctrl-C during a long iterate(): KeyboardInterrupt carries every orbit's state, nothing is lost."""

from __future__ import annotations

import time

import numpy as np
import pytest

from conftest import PROMPT, CtrlCOnceStarted
from hovering import Status, paper


def test_interrupt_keeps_every_orbit_state():
    m = paper.truncated_map(0.3)
    rng = np.random.default_rng(5)
    n = 20_000
    phi0, K0 = rng.uniform(-np.pi, np.pi, n), rng.uniform(-0.5, 0.5, n)
    # 2e9 orbit-steps, ~4 s on 2 idle cores; Ctrl-C is pressed once the work has begun
    # (CtrlCOnceStarted), so it always lands mid-run, on any machine and under any load; a lost
    # interrupt makes the call return within seconds and fail here.
    press = CtrlCOnceStarted()
    with pytest.raises(KeyboardInterrupt) as info:
        m.iterate(phi0, K0, 100_000, record=("rotation",), n_threads=2, progress=press)
    assert time.perf_counter() - press.fired_at < PROMPT
    res = info.value.partial
    assert res.n_orbits == n
    done, st = res.steps_done, res.status
    # Workers run a few lanes of orbits to the end before taking new ones, so at the interrupt
    # some orbits are finished (OK, all steps), some are under way and most have not started
    # (both INTERRUPTED, with their state so far). No orbit escapes from this band in 1e5 steps.
    assert set(np.unique(st).tolist()) <= {int(Status.OK), int(Status.INTERRUPTED)}
    assert np.all(done[st == Status.OK] == 100_000)
    interrupted = st == Status.INTERRUPTED
    assert interrupted.sum() > 0 and np.all(done[interrupted] < 100_000)
    under_way = np.flatnonzero(interrupted & (done > 0))
    assert under_way.size > 0
    # Every orbit's reported state is exactly where a fresh run of its own steps_done steps ends
    # (one orbit at a time, so bit-identical: the kernel's arithmetic is per lane). The sample
    # covers finished, interrupted-under-way and never-started orbits.
    finished = np.flatnonzero(st == Status.OK)
    sample = np.concatenate([finished[:5], under_way[:40], rng.choice(np.flatnonzero(interrupted), 40)])
    for i in sample:
        again = m.iterate(phi0[i : i + 1], K0[i : i + 1], int(done[i]), record=("rotation",), n_threads=1)
        assert again.phi_final[0] == res.phi_final[i] and again.K_final[0] == res.K_final[i]
        if done[i] > 0:
            assert again.rotation[0] == res.rotation[i]


def test_interrupt_reports_unstarted_out_of_band_orbits_as_escaped():
    # Orbits that start outside the band are ESCAPED after 0 steps, interrupted run or not.
    m = paper.truncated_map(0.3, K_max=1.0)
    n = 20_000
    phi0 = np.linspace(-3, 3, n)
    K0 = np.where(np.arange(n) % 2 == 0, 0.1, 5.0)
    for kernel in ("simd", "scalar"):
        # 5e8 orbit-steps: ~1 s (simd) and ~8 s (scalar) on 2 idle cores, Ctrl-C at ~0.1 s
        with pytest.raises(KeyboardInterrupt) as info:
            m.iterate(phi0, K0, 50_000, record=(), n_threads=2, kernel=kernel, progress=CtrlCOnceStarted())
        res = info.value.partial
        outside = K0 > 1.0
        assert np.all(res.status[outside] == Status.ESCAPED) and np.all(res.steps_done[outside] == 0)
        assert np.all(res.status[~outside] != Status.ESCAPED)


# The test owns SIGALRM and the real-time timer, which pytest-timeout's "signal" method (pyproject)
# also uses; 0 turns that off for this test only (its work is bounded by the alarm it sets).
@pytest.mark.timeout(0)
def test_exception_from_a_signal_handler_propagates_unchanged():
    # Only Ctrl-C becomes KeyboardInterrupt-with-partial; what another handler raises passes through.
    import signal

    m = paper.truncated_map(0.3)

    def on_alarm(signum, frame):
        raise TimeoutError("budget exceeded")

    def arm(done, total):  # the alarm is set once the work has begun, to ring 50 ms later, in C++
        if done > 0 and not rang:
            rang.append(True)
            signal.setitimer(signal.ITIMER_REAL, 0.05)

    rang = []
    # The run's own alarm (pytest-timeout's per-test timeout, also SIGALRM) is put aside for the
    # test and given back with what was left of it.
    outer, t0 = signal.getitimer(signal.ITIMER_REAL)[0], time.monotonic()
    old = signal.signal(signal.SIGALRM, on_alarm)
    try:
        with pytest.raises(TimeoutError, match="budget exceeded"):  # ~4 s of work were it not raised
            m.iterate(np.zeros(20_000), np.full(20_000, 0.1), 100_000, record=(), n_threads=2, progress=arm)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
        if outer > 0:
            signal.setitimer(signal.ITIMER_REAL, max(outer - (time.monotonic() - t0), 1e-3))
