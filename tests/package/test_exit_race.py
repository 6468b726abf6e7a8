"""A long call still running in another thread at interpreter exit parks until exit: it never aborts
the process (issue 18; README "Outcomes are values": Ctrl-C and exit).

From the moment CPython sets its finalising flag, a thread other than the finalising one that takes
the GIL is ended by a forced unwinding, which through C++ frames aborts the process (std::terminate,
"FATAL: exception not rethrown"). The bindings take every GIL through one gate
(python/src/gil.hpp) that an atexit hook closes first; pybind11's own lazy NumPy set-up, which
took the GIL on a call's first use of an array, is done at import. Each scenario below is a
separate process: a daemon thread starts a long call, the main thread waits until the call is under
way (its first progress report, its first Python call from a core thread) and exits shortly after,
at delays spread over the watcher's 100 ms cycle. Measured with these scenarios before the gate (200
runs each, a loaded 2-core VM): iterate with a progress callable 178/200 aborted (5 of them
SIGSEGV), FlowMap.iterate with progress 185/200 (7 SIGSEGV), return_map(progress=True) 200/200, a
CustomPotential on two threads 155/200 ("FATAL: exception not rethrown"), the plain call 0/200 here
but 6/600 at delay 0 (the first use of pybind11's NumPy state, which releases and re-takes the GIL).
After: 0 of each (and 0/600 plain at delay 0).

Every other entry point that runs core threads has a scenario too (hovering_area, critical_curve,
transit, barrier_scan, each also with executor=2, and work_precision), several daemon threads
making the call at once. What still failed, 200 runs each: hovering_area with executor=2 164/200
(the exit ran every queued piece, then each caller went on with its own work during the
finalisation: 2 aborts in np.unique, whose C++ in NumPy >= 2.3 takes the GIL back in a destructor;
21 SIGSEGV, hovering_estimate calling astype, whose cast took the GIL back inside the binding's
frames, whose destructors then ran without it; 141 RuntimeError tracebacks, a caller submitting
after concurrent.futures' exit hook), barrier_scan 1/200 aborted (np.unique in classify_orbits),
hovering_area 2/200 SIGSEGV, transit and barrier_scan with executor=2 3/200 and 1/200 tracebacks;
critical_curve, transit, work_precision 0/200. After (the binding fills its arrays itself, the
package's long calls use hovering._arrays.unique, a daemon caller of executor= parks at exit and
its pieces stop): 0 of each, 2600 runs.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap
from concurrent.futures import ThreadPoolExecutor

import pytest

# Interpreters exiting during a long call, in subprocesses: end to end (the 200-run loops are also slow).
pytestmark = pytest.mark.e2e

SCENARIO = textwrap.dedent(
    """
    import sys, threading, time
    import numpy as np
    import hovering as hv

    kind, delay, size, copies = sys.argv[1], float(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
    started = threading.Event()  # the long call is under way in C++ (for the executor=: a piece is done)

    def report(done, total):
        started.set()

    def system(V1):
        return hv.StepSystem(V1=V1, V2=hv.Tan(omega=1.4, alpha=0.7), coupling=hv.Bilinear(), eps=-0.05,
                             qw1=-1.0, qw2=-0.5, geometry="step")

    if kind == "iterate_progress":
        m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=2.0)
        work = lambda: m.iterate(np.zeros(size), np.full(size, 0.1), 10**6, record=(), progress=report)
    elif kind == "flowmap_progress":
        fm = hv.FlowMap(system(hv.Harmonic(omega=1.0)), 1.0, coordinates="section")
        work = lambda: fm.iterate(np.linspace(-3, 3, size), np.full(size, 0.3), 10**6, record=(), progress=report)
    elif kind == "return_map_bar":
        import tqdm
        update = tqdm.tqdm.update
        def observed(self, n=1):  # the watcher thread reports to the bar: the call is under way
            started.set()
            return update(self, n)
        tqdm.tqdm.update = observed
        sec = hv.Section(system(hv.Harmonic(omega=1.0)), 1.0)
        work = lambda: sec.return_map(np.linspace(-3, 3, size), np.full(size, 0.3), progress=True)
    elif kind == "custom_potential":
        caller = [threading.get_ident()]  # the construction's checks call V here
        def V(q):
            if threading.get_ident() != caller[0]:  # called from a core worker thread
                started.set()
            return 0.5 * q * q
        def dV(q):
            return q
        sec = hv.Section(system(hv.CustomPotential(V, dV)), 1.0)
        def work():
            caller[0] = threading.get_ident()
            sec.return_map(np.linspace(-3, 3, size), np.full(size, 0.3), n_threads=2)
    elif kind == "plain":
        m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=2.0)
        def work():
            started.set()
            m.iterate(np.zeros(size), np.full(size, 0.1), 1000, record=())
    elif kind.startswith("hovering_area"):
        # The sign of eps that does not hover: every orbit impacts within a few steps, so the call
        # is short and much of it is Python and NumPy after the core's (the estimate, the parts).
        m = hv.paper.truncated_map(eps=-0.05)
        ex = 2 if kind.endswith("_executor") else None
        work = lambda: hv.hovering_area(m, n_samples=size, n_steps=size, executor=ex, progress=report)
    elif kind == "critical_curve":
        m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=2.0)
        work = lambda: hv.critical_curve(m, n_steps=size, progress=report)
    elif kind.startswith(("transit", "barrier_scan")):
        m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=2.0)
        zone = hv.impact_zone(m, n_steps=2000)
        ex = 2 if kind.endswith("_executor") else None
        if kind.startswith("transit"):
            work = lambda: hv.transit(m, zone, n_orbits=size, n_steps=size, executor=ex, progress=report)
        else:
            work = lambda: hv.barrier_scan(m, zone, n_starts=16, n_steps=size, executor=ex, progress=report)
    elif kind == "work_precision":
        sec = hv.Section(system(hv.Harmonic(omega=1.0)), 1.0)
        # progress is reported after each setting: then the next one's return map is under way
        work = lambda: hv.work_precision(sec, quick=True, n_points=size, returns=(1,), repeat=1, n_threads=2,
                                         progress=report)
    for _ in range(copies):  # several calls at once: more of them racing the exit in one run
        threading.Thread(target=work, daemon=True).start()
    if not started.wait(120):
        sys.exit("the long call never started")
    time.sleep(delay)  # the main thread ends while the daemon thread is in C++
    """
)

_CYCLE = [0.0125 * k for k in range(8)]

#: kind -> (size of the call, delays after it is under way, daemon threads making it, runs in the
#: quick test). Every entry point that runs core threads has one: TruncatedMap.iterate
#: (iterate_progress, plain), FlowMap.iterate, Section.return_map (return_map_bar,
#: custom_potential), hovering_area, critical_curve, transit and barrier_scan (each in this process
#: and with executor=2: pieces on a pool of threads), work_precision. The progress watcher reports
#: every 100 ms: the delays cover that cycle. The plain call takes ~10-40 ms here, hovering_area's
#: ~50 ms (its first report comes at the end of its core call): their delays straddle the end,
#: where the caller's own Python and NumPy work runs into the exit. With executor=2 the exit itself
#: ran every queued piece (concurrent.futures' exit hook) and each caller then went on as the
#: interpreter finalised: 12 callers make that race in most runs. The scenarios whose race is rare
#: run 4 times in the quick test (it shows that they run and exit cleanly), 200 in the slow one.
SCENARIOS = {
    "iterate_progress": (2000, _CYCLE, 1, 10),
    "flowmap_progress": (8, _CYCLE, 1, 10),
    "return_map_bar": (100_000, _CYCLE, 1, 10),
    "custom_potential": (4000, _CYCLE, 1, 10),
    "plain": (20_000, [0.005 * k for k in range(8)], 1, 10),
    "hovering_area": (200_000, [0.002 * k for k in range(8)], 6, 4),
    "hovering_area_executor": (200_000, [0.02 * k for k in range(5)], 12, 10),
    "critical_curve": (20_000, _CYCLE, 2, 4),
    "transit": (2000, _CYCLE, 2, 4),
    "transit_executor": (2000, _CYCLE, 2, 4),
    "barrier_scan": (4000, _CYCLE, 2, 4),
    "barrier_scan_executor": (4000, _CYCLE, 2, 4),
    "work_precision": (64, _CYCLE, 2, 4),
}


def _run(kind: str, delay: float, size: int, copies: int):
    r = subprocess.run(
        [sys.executable, "-c", SCENARIO, kind, repr(delay), str(size), str(copies)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    return kind, delay, r.returncode, r.stderr


def _loop(runs: int | None) -> None:
    """Every scenario `runs` times (None: its quick count), two processes at a time."""
    jobs = []
    for kind, (size, delays, copies, quick) in SCENARIOS.items():
        for i in range(quick if runs is None else runs):
            # The plain call's length varies too (20k-60k orbits), as its end is what races.
            n = size * (1 + i % 3) if kind == "plain" else size
            jobs.append((kind, delays[i % len(delays)], n, copies))
    with ThreadPoolExecutor(2) as pool:  # two processes at a time: a loaded 2-core machine
        results = list(pool.map(lambda j: _run(*j), jobs))
    bad = [
        (kind, delay, rc, err[-300:])
        for kind, delay, rc, err in results
        if rc != 0 or any(word in err for word in ("terminate", "FATAL", "Traceback", "Segmentation"))
    ]
    counts = {kind: sum(1 for b in bad if b[0] == kind) for kind in SCENARIOS}
    assert not bad, (counts, bad[:5])


def test_exit_during_a_long_call_never_aborts_quick():
    # 10 runs of the scenarios that raced often, 4 of the others: a regression shows here already
    # (before the gate, 3 of the first 5 scenarios aborted in 30-100% of the runs; before the
    # daemon callers of executor= parked at exit, hovering_area_executor failed in 32 of 40).
    _loop(None)


@pytest.mark.stress
# 2,600 processes, two at a time: 630-945 s on an idle 2-core VM, so the suite's 900 s hang limit
# would fail it on a loaded box, and it would be most of the whole suite's time: a stress run of
# what the quick loop above already covers, run by CI as its own step (scripts/test.sh -- -m stress). Each process has its own 300 s limit (_run), which still ends a
# hang; the whole loop gets an hour.
@pytest.mark.timeout(3600)
def test_exit_during_a_long_call_never_aborts_200_runs_each():
    _loop(200)


CTRL_C_IN_JOIN = textwrap.dedent(
    """
    import _thread, threading
    import numpy as np
    import hovering as hv
    m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=2.0)
    t = threading.Thread(target=lambda: m.iterate(np.zeros(4000), np.full(4000, 0.1), 100_000, record=()))
    t.start()
    threading.Timer(0.2, _thread.interrupt_main).start()
    t.join()
    """
)


def test_ctrl_c_while_the_main_thread_waits_in_join():
    # KeyboardInterrupt in the main thread while another thread iterates: the interpreter ends with
    # the interrupt (exit 1, 130 or by SIGINT), never an abort (134).
    r = subprocess.run([sys.executable, "-c", CTRL_C_IN_JOIN], capture_output=True, text=True, timeout=300)
    assert r.returncode in (1, 130, -2), (r.returncode, r.stderr[-500:])  # -2: Python re-raises SIGINT at exit
    assert "KeyboardInterrupt" in r.stderr and "terminate called" not in r.stderr


AT_EXIT_CALL = textwrap.dedent(
    """
    import atexit, threading
    import numpy as np

    def late():  # registered before hovering is imported: runs after hovering's own atexit hook
        import hovering as hv
        V = hv.CustomPotential(lambda q: 0.5 * q * q, lambda q: q)
        sys_ = hv.StepSystem(V1=V, V2=hv.Tan(omega=1.4, alpha=0.7), coupling=hv.Bilinear(), eps=-0.05,
                             qw1=-1.0, qw2=-0.5, geometry="step")
        sec = hv.Section(sys_, 1.0)
        reports = []
        r = sec.return_map(np.linspace(-3, 3, 200), np.full(200, 0.3), n_threads=2,
                           progress=lambda d, t: reports.append((d, t)))
        print(repr(r.theta.tolist()), reports[-1] == (200, 200), flush=True)

    atexit.register(late)
    import hovering as hv
    V = hv.CustomPotential(lambda q: 0.5 * q * q, lambda q: q)
    sys_ = hv.StepSystem(V1=V, V2=hv.Tan(omega=1.4, alpha=0.7), coupling=hv.Bilinear(), eps=-0.05, qw1=-1.0,
                         qw2=-0.5, geometry="step")
    r = hv.Section(sys_, 1.0).return_map(np.linspace(-3, 3, 200), np.full(200, 0.3), n_threads=1)
    print(repr(r.theta.tolist()), flush=True)
    """
)


def test_a_call_in_a_later_atexit_callback_still_works():
    # After hovering's hook closed the gate, the finalising thread itself may still compute: its
    # core worker threads call the Python potential and its progress is reported (the gate lets
    # them pass while the finalising thread waits for them), and the answer is the one computed
    # before exit on one thread (returns do not depend on the thread that computes them).
    r = subprocess.run([sys.executable, "-c", AT_EXIT_CALL], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-500:]
    before, after = r.stdout.splitlines()
    assert after == before + " True"


FORK_CHILD = textwrap.dedent(
    """
    import os, sys, threading, time
    import numpy as np
    import hovering as hv
    started = threading.Event()
    def V(q):
        started.set()
        return 0.5 * q * q
    sys_ = hv.StepSystem(V1=hv.CustomPotential(V, lambda q: q), V2=hv.Tan(omega=1.4, alpha=0.7),
                         coupling=hv.Bilinear(), eps=-0.05, qw1=-1.0, qw2=-0.5, geometry="step")
    sec = hv.Section(sys_, 1.0)
    threading.Thread(target=lambda: sec.return_map(np.linspace(-3, 3, 4000), np.full(4000, 0.3), n_threads=2),
                     daemon=True).start()
    started.wait(120)
    pids = []
    for _ in range(20):  # fork while the workers call V (some forks land inside a call)
        pid = os.fork()
        if pid == 0:
            sys.exit(0)  # a normal exit: atexit runs hovering's hook in the child
        pids.append(pid)
        time.sleep(0.005)
    print(all(os.waitpid(p, 0)[1] == 0 for p in pids), flush=True)
    """
)


def test_a_fork_child_exits_without_waiting_for_the_parents_threads():
    # A child made by os.fork has only the forking thread: the passes of the parent's threads
    # that were calling Python at the fork must not make the child's exit wait for them forever.
    r = subprocess.run(
        [sys.executable, "-W", "ignore::DeprecationWarning", "-c", FORK_CHILD],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr[-500:]
    assert r.stdout.strip() == "True"
