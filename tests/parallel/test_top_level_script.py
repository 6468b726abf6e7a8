"""Local parallel runs need no ``if __name__ == "__main__":`` guard (issue 21, item 3).

The README's lines pasted into a top-level script run in a fresh interpreter: before, an
``executor=2`` run started spawned worker processes that imported the script again, ran its
parallel call again and died with BrokenProcessPool. Local pieces now run on threads of the one
process; the answer must be the one-process answer bit for bit (the pieces are contiguous ranges
of one sample stream), and Ctrl-C must stop the pieces running on other threads.
"""

from __future__ import annotations

import importlib
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import hovering
from conftest import CtrlCOnceStarted
from hovering import paper
from hovering.analysis.hovering import hovering_area
from hovering.parallel import Executor

# What the README shows, as a user pastes it: no guard, no main(), the call at top level. The
# deprecated workers= spelling is in it too (it warns, and must work all the same).
SCRIPT = textwrap.dedent(
    """
    import warnings

    import numpy as np
    import hovering

    m = hovering.TruncatedMap(eps=0.3, Omega0=hovering.OMEGA_G, theta_w=3 * np.pi / 4,
                              tau0=1.0, tau1=0.5, lam=0.5)
    hp = hovering.hovering_area(m, n_steps=400, n_samples=3000, executor=2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        old = hovering.hovering_area(m, n_steps=400, n_samples=3000, workers=2)
    zone = hovering.impact_zone(m)
    tr = hovering.transit(m, zone, "up", n_orbits=40, n_steps=300, executor=2)
    print(repr(hp.area), repr(old.area), repr(hp.error), tr.first_passage.tolist())
    """
)


def test_readme_lines_in_a_top_level_script_give_the_one_process_answer(tmp_path):
    script = tmp_path / "user_script.py"
    script.write_text(SCRIPT)
    # Generous bound: the runs take ~1 s; a script that re-imported itself in workers would either
    # fail at once (BrokenProcessPool) or keep starting workers.
    run = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert "BrokenProcessPool" not in run.stderr
    area, old_area, error, first_passage = run.stdout.strip().split(" ", 3)
    m = hovering.TruncatedMap(eps=0.3, Omega0=hovering.OMEGA_G, theta_w=3 * np.pi / 4, tau0=1.0, tau1=0.5, lam=0.5)
    one = hovering_area(m, n_steps=400, n_samples=3000)
    # Exact equality: each piece draws its own contiguous range of the one sample stream and the
    # estimate only counts, so where the pieces ran cannot change a digit.
    assert float(area) == one.area and float(old_area) == one.area and float(error) == one.error
    tr = hovering.transit(m, hovering.impact_zone(m), "up", n_orbits=40, n_steps=300)
    assert eval(first_passage) == tr.first_passage.tolist()


def test_local_workers_start_no_process_and_give_the_one_process_answer():
    import multiprocessing

    m = paper.truncated_map(0.3)
    kw = dict(n_steps=600, n_samples=4000, rng=3)
    one = hovering_area(m, **kw)
    before = set(multiprocessing.active_children())
    many = hovering_area(m, **kw, executor=Executor(workers=2, pieces=5))
    assert set(multiprocessing.active_children()) == before  # threads, not processes
    assert many.area == one.area and many.areas == one.areas and many.unresolved == one.unresolved


def test_ctrl_c_stops_the_pieces_running_on_other_threads(monkeypatch):
    # Ctrl-C reaches only the main thread, which must stop the pieces on the pool's threads (the
    # run's stop event, polled by the core every ~0.1 s) and return. It is pressed (interrupt_main)
    # when the first piece is reported done, so it lands mid-run under any load: the piece that
    # took the freed worker has just started. The pieces take ~1 s each (~3 s in all on 2 idle
    # cores): a stop that never reached them ends the call in seconds, not hours, and fails below.
    area = importlib.import_module("hovering.analysis.hovering")
    real_piece, outcomes = area._piece, []

    def piece(*args):
        try:
            res = real_piece(*args)
        except KeyboardInterrupt:
            outcomes.append("stopped")
            raise
        outcomes.append("finished")
        return res

    monkeypatch.setattr(area, "_piece", piece)
    m = hovering.TruncatedMap(eps=0.3, Omega0=hovering.OMEGA_G, theta_w=2.0)
    press = CtrlCOnceStarted()
    with pytest.raises(KeyboardInterrupt):
        hovering.hovering_area(
            m, n_steps=10**5, n_samples=10**5, executor=Executor(workers=2, pieces=4), progress=press
        )
    # The bound is 30 s: generous against a loaded 2-core machine, the pieces' seconds below a lost stop.
    assert time.perf_counter() - press.fired_at < 30
    assert "stopped" in outcomes, outcomes  # a piece under way was stopped, not waited for
    # No piece is left computing once the call has returned: the pool's threads have ended.
    assert not [t for t in threading.enumerate() if t.name.startswith("hovering-piece")]
