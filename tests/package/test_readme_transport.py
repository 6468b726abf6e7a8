"""The user guide's page "Iterating for transport" runs as written and its comments are true."""

from __future__ import annotations

import pathlib
import re

import numpy as np

import hovering

PAGE = pathlib.Path(__file__).resolve().parents[2] / "docs" / "guide" / "transport.md"


def test_transport_section_runs_and_agrees_with_its_comments():
    blocks = re.findall(r"```python\n(.*?)```", PAGE.read_text(), flags=re.S)
    assert len(blocks) == 1, "the transport page lost its example"
    ns: dict = {}
    exec(compile(blocks[0], str(PAGE), "exec"), ns)
    barrier, tr, up, K0 = ns["barrier"], ns["tr"], ns["up"], ns["K0"]
    # "(~3e-8)": the orbit lies on the curve to the spline's error, i.e. it is a circle
    assert 1e-9 < barrier.max_error < 1e-7
    assert tr.phi.shape == (1000, 101) and tr.every == 100
    # "-1 for all ... a barrier": every orbit ran its 10_000 steps without reaching the circle
    assert np.all(tr.stop_step == -1) and np.all(tr.steps_done == 10_000)
    # "the highest K reached is 0.33, below its lowest point 0.60"
    assert abs(tr.K_max.max() - 0.33) < 0.005 and abs(barrier.K.min() - 0.60) < 0.005
    assert tr.K_max.max() < barrier.K.min()
    assert tr.residence.shape == (1000, 5) and np.all(tr.residence.sum(axis=1) == 10_000)
    # "first n with K_n >= wave(phi_n)"; "status STOPPED there"
    hit = up.stop_step >= 0
    assert 0 < np.count_nonzero(hit) < K0.size
    assert np.all(up.status[hit] == hovering.Status.STOPPED) and np.all(up.status[~hit] == hovering.Status.OK)
    assert np.all(up.K_final[hit] >= ns["wave"](up.phi_final[hit]))
