"""The sweep executable's C++ runner (hovering._core.scene.run_point, the code of hovering_sweep)
against Python's scene points: the same numbers for the truncated map (the same samples, drawn
from numpy's stream reproduced in C++, and the same compiled map: bit for bit) and agreement
within the error bars for the flow (whose measured forcing is a least-squares fit in Python and the
equivalent discrete sine transform in C++: the box moves by ulps, the chaotic orbits differ)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from hovering import _core
from hovering.analysis.hovering import _stratified
from hovering.scenes.compute import _flow_point, _truncated_point, scaled
from hovering.scenes.schema import load_scene
from hovering.scenes.spec import QUICK_FACTOR

ROOT = Path(__file__).resolve().parents[1]
TRUNC = ROOT / "examples/scenes/fig_hov_vs_eps.toml"
FLOW = ROOT / "examples/scenes/flow_hov_vs_eps.toml"


def test_truncated_points_are_pythons_bit_for_bit():
    text = TRUNC.read_text()
    sc = load_scene(TRUNC, check_output=False)
    n, samples = scaled(sc.n_steps, True), max(sc.samples // QUICK_FACTOR, 400)
    k = 0
    for s in sc.series:
        for e in sc.eps:
            c = _core.scene.run_point(text, TRUNC.name, k, True, 0)
            kw = {} if s.K_low is None else {"K_low": s.K_low}
            p = _truncated_point(s.map_at(e), n, samples, sc.seed, kw)
            for name in ("area", "error", "theory", "K_low"):
                assert c[name] == p[name], (s.label, e, name, c[name], p[name])
            assert bool(c["floor_touched"]) == p["floor_touched"]
            assert c["key"]["Omega0"] == repr(p["Omega0"]) and c["key"]["theta_w"] == repr(p["theta_w"])
            assert c["key"]["n_steps"] == str(n) and c["key"]["samples"] == str(samples)
            k += 1
    assert k == len(sc.series) * len(sc.eps) == 44


@pytest.mark.parametrize("seed", [0, 3, 2**40 + 1, 2**63 - 1])
def test_samples_are_numpys(seed):
    # The runner's box and samples are Python's: a one-point scene with K_low given, whose area
    # (count of hovering samples x box / n) can only match if every sample matches.
    text = f"""
kind = "hovering_area"
output = "x.png"
n_steps = 300
samples = 1500
seed = {seed}
eps = [0.25]
[[series]]
label = "a"
Omega0 = 2.1
theta_w = 2.0
K_low = -0.37
"""
    c = _core.scene.run_point(text, "x.toml", 0, False, 1)
    from hovering.scenes.schema import parse_scene
    import tomllib

    sc = parse_scene(tomllib.loads(text), Path("x.toml"), check_output=False)
    h = sc.series[0].map_at(0.25).build().hovering_area(n_steps=300, samples=1500, K_low=-0.37, seed=seed)
    assert c["n_samples"] == h.n_samples == _stratified(1500, -0.37, np.random.default_rng(seed))[0].size
    assert (c["area"], c["area_N2"], c["area_N4"], c["area_both_sides"]) == (
        h.area, h.areas[150], h.areas[75], h.area_both_sides)
    assert c["impact_fraction_F0"] == h.impact_fraction_F0 and c["sampling_error"] == h.sampling_error


def test_flow_points_agree_within_error_bars():
    text = FLOW.read_text().replace("eps = [-0.2, -0.1, -0.05, 0.05, 0.1, 0.2]", "eps = [-0.1, 0.1]")
    text = text.replace("samples = 2000", "samples = 800").replace("n_steps = 2000", "n_steps = 300")
    sc = load_scene(FLOW, check_output=False)
    from dataclasses import replace

    sc = replace(sc, eps=(-0.1, 0.1))
    for i, e in enumerate(sc.eps):
        c = _core.scene.run_point(text, FLOW.name, i, False, 0)
        p = _flow_point(sc, e, 300, 800)
        # The box: the same default depth up to the rounding of the forcing fit (1e-12 relative).
        assert c["K_low"] == pytest.approx(p["K_low"], rel=1e-12)
        assert c["b1"] == pytest.approx(p["b1"], rel=1e-12)
        assert c["theory"] == pytest.approx(p["theory"], rel=1e-9, abs=1e-15)
        assert c["unresolved"] == p["unresolved"]
        # Two estimates of one area from (almost) the same samples: within the sum of the bars.
        assert abs(c["area"] - p["flow"]) <= c["error"] + p["flow_err"], (e, c["area"], p["flow"])
        o = p["models"]["onset"]
        assert abs(c["onset_area"] - o["area"]) <= c["onset_error"] + o["error"]
        assert c["onset_K_low"] == pytest.approx(o["K_low"], rel=1e-12)
        assert abs(c["onset_agree"] - o["agree"]) <= 0.05
    # The sign of eps that hovers: this system's b_1 sin(Omega0 / 2) < 0, so eps = -0.1 has theory > 0.
    assert _core.scene.run_point(text, FLOW.name, 0, True, 0)["theory"] > 0.1


def test_run_point_errors():
    text = TRUNC.read_text()
    with pytest.raises(IndexError):
        _core.scene.run_point(text, TRUNC.name, 10**6, True, 0)
    acc = FLOW.read_text().replace("rtol = 1e-10", "accuracy = 1e-9")
    with pytest.raises(ValueError, match="give stepper and rtol instead"):
        _core.scene.run_point(acc, FLOW.name, 0, True, 0)
