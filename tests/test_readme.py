"""The README's Python examples run as written (so the documentation cannot drift from the API)."""

from __future__ import annotations

import pathlib
import re

import numpy as np

import hovering

README = pathlib.Path(__file__).resolve().parents[1] / "README.md"


def _python_blocks():
    return re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)


def test_readme_examples_run_and_agree_with_the_text():
    blocks = _python_blocks()
    assert len(blocks) >= 2, "README lost its Python examples"
    ns: dict = {}
    for code in blocks:
        exec(compile(code, str(README), "exec"), ns)
    m, res = ns["m"], ns["res"]
    # Claims made in the README's comments:
    lo, hi = m.valid_band()
    assert abs(lo + np.pi) < 1e-12 and np.isinf(hi)  # "(-3.14159..., inf)"
    assert m.region(0.3, -0.2) is hovering.Region.ABOVE
    assert abs(m.rho_crit() - 3.7694) < 1e-4  # "eq:rhocrit = 3.7694..."
    # The early-exit example: statuses are OK or EXITED, exit_step is -1 exactly for OK orbits.
    assert set(np.unique(res.status).tolist()) <= {int(hovering.Status.OK), int(hovering.Status.EXITED)}
    assert np.array_equal(res.exit_step == -1, res.status == hovering.Status.OK)
    fam = ns["fam"]
    flo, fhi = fam.valid_band()
    assert flo < 0 < fhi == 1.0
