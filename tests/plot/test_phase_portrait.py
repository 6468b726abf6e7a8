"""The matplotlib front end of the truncated map (headless, Agg): phase portraits coloured by region
and by orbit, checked through the artists' data against the orbit result they draw.
"""

from __future__ import annotations

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pytest

import hovering
from conftest import PARAM_SETS, make_map
from hovering import pipeline as plotting
from hovering.plot import primitives


def test_backend_is_headless():
    assert matplotlib.get_backend().lower() == "agg"


@pytest.mark.parametrize("eps", [0.3, -0.3])
def test_phase_portrait_region_colouring(eps):
    m = make_map(dict(PARAM_SETS["paper_eps+0.3"], eps=eps))
    ax, res = plotting.phase_portrait(m, n_orbits=6, n_steps=300)
    try:
        assert "phi" in ax.get_xlabel() and "K" in ax.get_ylabel()
        assert ax.get_xlim() == pytest.approx((-np.pi, np.pi))
        visited = set(np.unique(res.region[res.region >= 0]).tolist())
        assert len(ax.collections) == len(visited) >= 2
        # each region's scatter holds exactly the points recorded in that region
        labels = {c.get_label(): c for c in ax.collections}
        for r in visited:
            lab = f"J_{hovering.Region(r).label}"
            assert labels[lab].get_offsets().shape[0] == np.count_nonzero(res.region == r)
        assert ax.get_legend() is not None
        # the geometry is drawn: K = 0, L1, L2 and three corner curves
        names = [ln.get_label() for ln in ax.get_lines()]
        for n in ("L1", "L2", "phi_01", "phi_1R", "phi_R0"):
            assert n in names
    finally:
        plt.close(ax.figure)


def test_phase_portrait_orbit_colouring():
    m = make_map(PARAM_SETS["paper_eps+0.3"])
    fig, ax = plt.subplots()
    try:
        ax2, res = plotting.phase_portrait(m, n_orbits=5, n_steps=200, ax=ax, color_by="orbit", title="T")
        assert ax2 is ax and ax.get_title() == "T"
        assert len(ax.collections) == 5 == res.n_orbits
        for i, c in enumerate(ax.collections):
            assert c.get_offsets().shape[0] == np.count_nonzero(np.isfinite(res.phi[i]))
    finally:
        plt.close(fig)


def test_plot_orbits_rejects_missing_records_and_bad_colouring():
    m = make_map(PARAM_SETS["paper_eps+0.3"])
    fig, ax = plt.subplots()
    try:
        r = m.iterate([0.0], [0.1], 5, record=("rotation",))
        with pytest.raises(ValueError, match=r"needs a result with record='orbit'"):
            primitives.plot_orbits(ax, r)
        r = m.iterate([0.0], [0.1], 5, record=("orbit",))
        with pytest.raises(ValueError, match=r"color_by='region' needs a result with record='regions'"):
            primitives.plot_orbits(ax, r)
        with pytest.raises(ValueError, match=r"color_by must be 'region' or 'orbit', got 'x'"):
            primitives.plot_orbits(ax, r, color_by="x")
    finally:
        plt.close(fig)
