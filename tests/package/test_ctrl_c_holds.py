"""Ctrl-C keeps working in a long-lived process: after hundreds of calls of every entry point that
runs core threads (interrupted, finished, stopped by their progress callback), and once the process
can no longer start a thread.

The issue: in a pytest process that had run ~450 tests under load, Ctrl-C tests hung (an
interrupt_main and a real kill -INT were ignored, progress reports stopped), while the same tests
passed in a fresh process. Hundreds of calls of every kind in one process leave nothing behind
that stops Ctrl-C (the first part of the script below passed before the fix too). What reproduces
every symptom is a process that can no longer start a thread (near its thread or address-space
limit: a long-lived process under load): the runner thread that computes while the calling thread
polls for signals was a new thread per call, and when none could be started the work ran on the
calling thread, where nothing polls for signals, until it ended. The call now hands its work to a
reserve thread started by an earlier call (python/src/signals.hpp). Measured (a SIGINT 1 s into a
~9 s call, in a process that can start no thread): before the fix honoured after 9.2 s, when the
call ended, with 0 progress reports; after, after 1.0 s with 10 reports. The long calls below are
bounded (seconds), so that a lost interrupt is a failure, not a hang.

A second way for an interrupt to be lost: a Ctrl-C landing while run_pieces was still handing out
the pieces of an executor= run left the pieces already running unstopped (they never saw the stop
event), and the executor's close() waited for each to finish in full (hours for a long run).
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import threading
import time

import pytest

import hovering
from hovering.parallel import Executor
from hovering.parallel import executor as executor_module

# Every entry point that runs core threads, small enough that a finished call takes ~10-100 ms. The
# calls are interrupted at their first progress report (by interrupt_main or by a real SIGINT),
# finish, or are stopped by a callback that raises; then a real SIGINT from another thread must stop
# a long call promptly, with progress reported, before and after the process loses the ability to
# start threads (RLIMIT_NPROC, as tests/package/test_reliability.py does).
MANY_CALLS = textwrap.dedent(
    """
    import _thread, concurrent.futures as cf, contextlib, io, os, resource, signal, sys, threading, time
    import numpy as np
    import hovering as hv
    from hovering import paper

    m = paper.truncated_map(0.3)
    zone = hv.impact_zone(m, n_steps=2000)
    fm = paper.flow_map(-0.05)
    sec = hv.Section(paper.system(0.05, "step"), 1.0)
    V = hv.CustomPotential(lambda q: 0.5 * q * q, lambda q: q)
    py_sec = hv.Section(hv.StepSystem(V1=V, V2=hv.Tan(omega=1.4, alpha=0.7), coupling=hv.Bilinear(), eps=-0.05,
                                      qw1=-1.0, qw2=-0.5, geometry="step"), 1.0)
    phi, K = np.linspace(-3, 3, 64), np.full(64, 0.03)
    pool = cf.ThreadPoolExecutor(2)
    CALLS = {
        "iterate": lambda p: m.iterate(phi, K, 20_000, record=(), progress=p),
        "iterate_scalar": lambda p: m.iterate(phi, K, 5_000, record=(), kernel="scalar", progress=p),
        "flow_iterate": lambda p: fm.iterate(phi[:8], K[:8], 20, record=(), progress=p),
        "return_map": lambda p: sec.return_map(np.linspace(-3, 3, 400), np.full(400, 0.33), progress=p),
        "python_potential": lambda p: py_sec.return_map(np.linspace(-3, 3, 64), np.full(64, 0.3), n_threads=2,
                                                        progress=p),
        "hovering_area": lambda p: hv.hovering_area(m, n_steps=5_000, n_samples=2_000, progress=p),
        "hovering_area_threads": lambda p: hv.hovering_area(m, n_steps=5_000, n_samples=2_000, progress=p,
                                                           executor=hv.parallel.Executor(workers=2, pieces=4)),
        "hovering_area_pool": lambda p: hv.hovering_area(m, n_steps=5_000, n_samples=2_000, progress=p, executor=pool),
        "critical_curve": lambda p: hv.critical_curve(m, n_steps=2_000, n_grid=16, progress=p),
        "transit": lambda p: hv.transit(m, zone, "up", n_orbits=4, n_steps=50_000, start_s=0.5, target_s=1.0,
                                        progress=p),
        "transit_threads": lambda p: hv.transit(m, zone, "up", n_orbits=8, n_steps=50_000, start_s=0.5,
                                                target_s=1.0, progress=p, executor=2),
        "barrier_scan": lambda p: hv.barrier_scan(m, zone, n_starts=4, n_steps=5_000, s_range=(0.5, 1.0), progress=p),
        "barrier_scan_threads": lambda p: hv.barrier_scan(m, zone, n_starts=8, n_steps=5_000, s_range=(0.5, 1.0),
                                                          progress=p, executor=2),
    }

    class Stop(Exception):
        pass

    def once(action):
        fired = []
        def progress(done, total):
            if done > 0 and not fired:
                fired.append(True)
                action()
        return progress

    def raise_stop():
        raise Stop

    MODES = {
        "finished": lambda: False,
        "bar": lambda: True,
        "interrupt_main": lambda: once(_thread.interrupt_main),
        "sigint": lambda: once(lambda: os.kill(os.getpid(), signal.SIGINT)),
        "callback_raises": lambda: once(raise_stop),
    }
    outcomes = {}
    with contextlib.redirect_stderr(io.StringIO()):  # the bars
        for round_ in range(int(sys.argv[1])):
            for name, call in CALLS.items():
                for mode, progress in MODES.items():
                    try:
                        call(progress())
                        got = "returned"
                    except KeyboardInterrupt:
                        got = "KeyboardInterrupt"
                    except Stop:
                        got = "Stop"
                    outcomes.setdefault((mode, got), 0)
                    outcomes[(mode, got)] += 1
    print("outcomes", sorted(outcomes.items()), flush=True)

    # A real SIGINT from another thread (started beforehand: the last phase starts none) 0.2 s after
    # the long call's first progress report; 64 orbits x 5e7 steps, ~13 s of work on one idle core
    # (a lost SIGINT ends the call in seconds: "returned").
    # Printed: the time from the signal to the KeyboardInterrupt, the reports, the steps done.
    under_way, sent = threading.Event(), []
    def sigint_once_under_way():
        while True:
            under_way.wait()
            under_way.clear()
            time.sleep(0.2)
            sent.append(time.perf_counter())
            os.kill(os.getpid(), signal.SIGINT)
    threading.Thread(target=sigint_once_under_way, daemon=True).start()

    def long_call(label):
        reports = []
        def progress(done, total):
            reports.append(done)
            if len(reports) == 1:
                under_way.set()
        try:
            m.iterate(phi, K, 5 * 10**7, record=(), progress=progress)
            print(label, "returned", len(reports), flush=True)
        except KeyboardInterrupt as e:
            print(label, "interrupted", time.perf_counter() - sent[-1], len(reports),
                  int(e.partial.steps_done.max()), flush=True)

    long_call("with_threads")
    # No new thread from here on: RLIMIT_NPROC counts threads; root ignores it, so drop to 'nobody'.
    resource.setrlimit(resource.RLIMIT_NPROC, (1, 1))
    if os.getuid() == 0:
        os.setgid(65534)
        os.setuid(65534)
    try:
        threading.Thread(target=lambda: None).start()
        print("threads allowed", flush=True)
    except RuntimeError:
        print("threads refused", flush=True)
    long_call("without_threads")
    """
)


def _run(rounds: int):
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")  # numpy must not need threads
    r = subprocess.run(
        [sys.executable, "-c", MANY_CALLS, str(rounds)], capture_output=True, text=True, timeout=600, env=env
    )
    assert r.returncode == 0, r.stderr[-2000:]
    return dict((line.split(" ", 1) + [""])[:2] for line in r.stdout.splitlines()), r.stdout


def _check_long_call(line: str, out: str):
    words = line.split()
    # "returned": no report came (the SIGINT is sent once one has), or the SIGINT was not honoured
    assert words[0] == "interrupted", out
    late, reports, steps = float(words[1]), int(words[2]), int(words[3])
    # The watcher polls every 0.1 s: stopping takes ~0.1 s on an idle machine; the generous bound
    # is a liveness check, far below the seconds the whole call takes.
    assert late < 10, out
    assert reports >= 1 and 0 < steps < 5 * 10**7, out  # progress was reported, the orbits cut short


def _check_many_calls(lines: dict, out: str, rounds: int):
    outcomes = dict(eval(lines["outcomes"]))
    n = rounds * 13  # calls of each mode
    assert sum(outcomes.values()) == 5 * n, out
    # Every interrupt landed in the call it was meant for, every raising callback stopped its call,
    # and the calls left alone finished.
    for mode, expected in [
        ("finished", "returned"),
        ("bar", "returned"),
        ("interrupt_main", "KeyboardInterrupt"),
        ("sigint", "KeyboardInterrupt"),
        ("callback_raises", "Stop"),
    ]:
        assert outcomes.get((mode, expected)) == n, (mode, out)
    _check_long_call(lines["with_threads"], out)
    assert "threads refused" in out.splitlines(), out  # the condition under test really holds
    _check_long_call(lines["without_threads"], out)


def test_ctrl_c_and_progress_still_work_after_hundreds_of_calls_and_without_new_threads():
    # 260 calls, then the two long calls: ~8 s on 2 idle cores, ~40 s with 8 busy processes on them.
    _check_many_calls(*_run(rounds=4), rounds=4)


def test_ctrl_c_while_the_pieces_are_handed_out_stops_the_running_ones(monkeypatch):
    # Ctrl-C lands once two of eight pieces were handed out and are computing (~1 s each on an idle
    # machine): those two must be stopped (their core calls end with KeyboardInterrupt), not waited
    # for until they finish (what happened before: their futures ended with a result).
    m = hovering.TruncatedMap(eps=0.3, Omega0=hovering.OMEGA_G, theta_w=2.0)
    real_submit = executor_module._Local.submit
    runs = []

    def submit(self, fn, *args):
        if len(self.submitted) == 2:
            runs.append(self)
            t0 = time.perf_counter()
            while not all(f.running() or f.done() for f in self.submitted):
                assert time.perf_counter() - t0 < 60, "the pieces never started"
                time.sleep(0.01)
            raise KeyboardInterrupt  # as if pressed here
        return real_submit(self, fn, *args)

    monkeypatch.setattr(executor_module._Local, "submit", submit)
    with pytest.raises(KeyboardInterrupt):
        hovering.hovering_area(m, n_steps=10**5, n_samples=4 * 10**4, executor=Executor(workers=2, pieces=8))
    (run,) = runs
    assert len(run.submitted) == 2 and all(f.done() for f in run.submitted)
    assert all(isinstance(f.exception(), KeyboardInterrupt) for f in run.submitted)  # stopped, not finished
    assert not [t for t in threading.enumerate() if t.name.startswith("hovering-piece")]
