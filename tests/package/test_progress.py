"""Progress reporting: progress=True (a tqdm bar on stderr) or a callable progress(done, total) on
every long call, fed by the core's counters; results unchanged, Ctrl-C unchanged."""

from __future__ import annotations

import threading

import numpy as np
import pytest

import hovering as hv
from conftest import CtrlCOnceStarted
from hovering import Status, paper
from hovering._progress import Progress, check_progress, progress_bar


class Recorder:
    """A progress callable that keeps every (done, total) it is given."""

    def __init__(self):
        self.calls = []

    def __call__(self, done, total):
        self.calls.append((done, total))

    def check(self, total):
        """Non-decreasing done values with a constant total, ending at it."""
        assert self.calls, "progress was never called"
        done = [d for d, _ in self.calls]
        assert all(isinstance(d, int) for d in done)
        assert done == sorted(done) and done[0] >= 0
        assert {t for _, t in self.calls} == {total}
        assert self.calls[-1] == (total, total)


def flow_system(eps=-0.05):
    return hv.StepSystem(
        V1=hv.Harmonic(omega=1.0),
        V2=hv.Tan(omega=1.4, alpha=0.7),
        coupling=hv.Bilinear(),
        eps=eps,
        qw1=-1.0,
        qw2=-0.5,
        geometry="step",
    )


@pytest.fixture(scope="module")
def fm():
    return hv.FlowMap(flow_system(), h=1.0, rtol=1e-10)


@pytest.fixture(scope="module")
def tm():
    return paper.truncated_map(0.3)


@pytest.mark.parametrize("kernel", ["simd", "scalar"])
@pytest.mark.parametrize("kind", ["map", "family"])
def test_truncated_iterate_reports_every_step(tm, kind, kernel):
    # 4000 orbits x 5000 steps, half of them leaving J_0 u J_0u early (stop_on_exit): an orbit that
    # stops credits the steps it will not take, so done ends exactly at n * n_steps.
    m = (
        tm
        if kind == "map"
        else hv.TruncatedFamily.from_map(tm, np.concatenate([-(np.linspace(1, 0, 41) ** 2), np.linspace(0.05, 1, 20)]))
    )
    rng = np.random.default_rng(2)
    phi, K = rng.uniform(-np.pi, np.pi, 4000), rng.uniform(-0.3, 0.3, 4000)
    rec = Recorder()
    kw = dict(record=("rotation",), exit_regions=("0u", "0"), stop_on_exit=True, kernel=kernel)
    res = m.iterate(phi, K, 5000, progress=rec, **kw)
    rec.check(4000 * 5000)
    assert res.count(Status.EXITED) > 0 and res.count(Status.OK) > 0
    plain = m.iterate(phi, K, 5000, **kw)
    assert np.array_equal(res.phi_final, plain.phi_final) and np.array_equal(
        res.rotation, plain.rotation, equal_nan=True
    )
    assert np.array_equal(res.steps_done, plain.steps_done)


def test_flow_iterate_and_return_map_report_every_return(fm):
    rng = np.random.default_rng(4)
    phi, K = rng.uniform(-np.pi, np.pi, 60), rng.uniform(-0.1, 0.05, 60)
    phi[0], K[0] = 0.0, 50.0  # no point of Sigma_h: OFF_SECTION at once, its returns are credited
    rec = Recorder()
    res = fm.iterate(phi, K, 40, record=("orbit",), exit_regions=("0u", "0"), stop_on_exit=True, progress=rec)
    rec.check(60 * 40)
    assert res.status[0] == Status.OFF_SECTION and res.count(Status.EXITED) > 0
    plain = fm.iterate(phi, K, 40, record=("orbit",), exit_regions=("0u", "0"), stop_on_exit=True)
    assert np.array_equal(res.phi, plain.phi, equal_nan=True) and res.work == plain.work
    rec = Recorder()
    th, I = np.linspace(-3, 3, 100), np.full(100, 0.3)
    a = fm.section.return_map(th, I, progress=rec)
    rec.check(100)
    assert np.array_equal(a.z, fm.section.return_map(th, I).z)


def test_analyses_report_one_bar_for_the_whole_call(tm, fm):
    # hovering_area: F_0 and F_eps, 2 * n * N units; critical_curve: grid, bisection, final orbit
    # (its total is corrected at the end when the bisection was shorter than its bound).
    rec = Recorder()
    area = hv.hovering_area(tm, n_steps=400, n_samples=500, progress=rec)
    rec.check(2 * area.n_samples * 400)
    assert area.area == hv.hovering_area(tm, n_steps=400, n_samples=500).area
    rec = Recorder()
    cc = hv.critical_curve(tm, n_steps=600, n_grid=16, tol=1e-3, progress=rec)
    done = rec.calls[-1][0]
    assert rec.calls[-1] == (done, done) and done % 600 == 0 and done >= 17 * 600
    assert [d for d, _ in rec.calls] == sorted(d for d, _ in rec.calls)
    assert cc.K0 == hv.critical_curve(tm, n_steps=600, n_grid=16, tol=1e-3).K0
    rec = Recorder()
    flow_area = hv.hovering_area(fm, n_steps=20, n_samples=30, progress=rec)
    rec.check(2 * flow_area.n_samples * 20)


def test_progress_true_draws_a_tqdm_bar_on_stderr(tm, fm, capsys):
    rng = np.random.default_rng(0)
    tm.iterate(rng.uniform(-3, 3, 2000), rng.uniform(0, 0.3, 2000), 20_000, record=(), progress=True)
    err = capsys.readouterr().err
    assert "TruncatedMap.iterate" in err and "100%" in err and "step" in err
    fm.iterate([0.1, 0.2], [0.01, -0.02], 30, record=(), progress=True)
    err = capsys.readouterr().err
    assert "FlowMap.iterate" in err and "100%" in err and "return" in err
    hv.hovering_area(tm, n_steps=100, n_samples=200, progress=True)
    err = capsys.readouterr().err
    assert err.count("hovering_area") >= 1 and "100%" in err and "iterate" not in err  # one bar, not three


def test_progress_runs_off_the_main_thread(tm):
    # No signals there, but the watcher still reports.
    rec, out = Recorder(), {}

    def run():
        out["res"] = tm.iterate(np.zeros(100), np.linspace(0.01, 0.3, 100), 10_000, record=(), progress=rec)

    t = threading.Thread(target=run)
    t.start()
    t.join()
    rec.check(100 * 10_000)
    assert np.all(out["res"].status == Status.OK)


@pytest.mark.parametrize("bad", ["yes", 1, None, 0.5, [print]])
def test_bad_progress_is_a_named_value_error(tm, fm, bad):
    for call in (
        lambda: tm.iterate([0.0], [0.1], 10, progress=bad),
        lambda: fm.iterate([0.0], [0.01], 2, progress=bad),
        lambda: fm.section.return_map([0.0], [0.3], progress=bad),
        lambda: hv.hovering_area(tm, n_steps=8, n_samples=4, progress=bad),
        lambda: hv.critical_curve(tm, n_steps=16, progress=bad),
    ):
        with pytest.raises(ValueError, match="progress must be True .* False .* or a callable progress"):
            call()


def test_an_exception_in_the_callable_stops_the_work_and_propagates(tm):
    def boom(done, total):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        tm.iterate(np.zeros(1000), np.linspace(0.01, 0.3, 1000), 100_000, record=(), progress=boom)


def test_keyboard_interrupt_in_the_callable_is_ctrl_c(tm):
    # Ctrl-C that lands while the callable runs: the usual KeyboardInterrupt with the partial result.
    def ctrl_c(done, total):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt) as info:
        tm.iterate(np.zeros(1000), np.linspace(0.01, 0.3, 1000), 1000, record=(), progress=ctrl_c)
    assert info.value.partial.n_orbits == 1000


def test_ctrl_c_with_a_bar_keeps_the_partial_result_and_closes_the_bar(tm, capsys, monkeypatch):
    from tqdm import std as tqdm_std
    from tqdm import tqdm

    rng = np.random.default_rng(5)
    phi0, K0 = rng.uniform(-np.pi, np.pi, 20_000), rng.uniform(-0.5, 0.5, 20_000)
    # 2e9 steps, ~4 s on 2 idle cores (a lost interrupt fails in seconds). Ctrl-C is pressed once
    # the work has begun (whatever the load): by the bar's own first update (progress=True), or by
    # the callable (progress=rec).
    press = CtrlCOnceStarted()
    update = tqdm_std.tqdm.update

    def pressing_update(self, n=1):
        press(self.n + n, self.total)
        return update(self, n)

    monkeypatch.setattr(tqdm_std.tqdm, "update", pressing_update)
    rec = Recorder()

    def pressing_rec(done, total):
        rec(done, total)
        press(done, total)

    for progress in (True, pressing_rec):
        press.fired_at = None
        with pytest.raises(KeyboardInterrupt) as info:
            tm.iterate(phi0, K0, 100_000, record=(), n_threads=2, progress=progress)
        res = info.value.partial
        assert res.n_orbits == 20_000 and res.count(Status.INTERRUPTED) > 0
    assert len(tqdm._instances) == 0  # the bar was closed
    assert rec.calls and rec.calls[-1][0] < rec.calls[-1][1] == 20_000 * 100_000
    assert "TruncatedMap.iterate" in capsys.readouterr().err


def test_progress_module_parts_totals_and_the_disabled_reporter():
    seen = []
    with progress_bar(lambda d, t: seen.append((d, t)), 100) as bar:
        first, second = bar.part(0), bar.part(60)
        first(30, 60)
        first(20, 60)  # not monotone: ignored
        second(40, 40)
        bar.advance(5)  # beyond the total: the total grows with it
    assert seen == [(30, 100), (100, 100), (105, 105)]
    seen.clear()
    with progress_bar(lambda d, t: seen.append((d, t)), 100) as bar:
        bar(10)
        bar.set_total(50)
        bar(50)
    assert seen == [(10, 100), (10, 50), (50, 50)]
    with progress_bar(False, 100) as bar:
        assert not bar.enabled and bar.part(10) is False
        bar(50)
    assert check_progress(np.bool_(True)) is True and isinstance(Progress(None, 3), Progress)


def test_progress_bar_closes_on_keyboard_interrupt(capsys):
    from tqdm import tqdm

    with pytest.raises(KeyboardInterrupt), progress_bar(True, 10, desc="closing", unit="step") as bar:
        bar(3)
        raise KeyboardInterrupt
    assert len(tqdm._instances) == 0
    assert "closing" in capsys.readouterr().err
