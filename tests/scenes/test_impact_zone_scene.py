"""The ``impact_zone`` scene kind: the flow and its truncated model, side by side, asked whether
anything crosses the impact zone (barrier scan along L1, transits both ways).

Oracles: the scene computes what its parts compute (the model's scan and transits equal direct
calls of hovering.barrier_scan / hovering.transit on the same map and zone, bit for bit), the
figure draws what the result holds (one dashed line per barrier, one vertical range per start in
its class colour, the transit statistics as text), and the saved result redraws the same figure
without computing. The numbers of the open problem (full runs) are in docs/impact-zone.md.
"""

from __future__ import annotations

import copy
import json
import tomllib
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.colors import to_rgb

import hovering
from helpers.figures import artists
from hovering import pipeline
from hovering._style import CLASS_COLORS
from hovering.scenes import compute, load_scene, parse_scene

SCENE_DIR = Path(__file__).resolve().parents[2] / "examples" / "scenes"
FILES = ("impact_zone", "impact_zone_neg", "impact_zone_second")


def _raw(name):
    with open(SCENE_DIR / f"{name}.toml", "rb") as f:
        return tomllib.load(f)


def _small(name="impact_zone"):
    d = _raw(name)
    d.update(n_starts=6, n_steps=1500, transit_orbits=6, transit_steps=400, model_factor=3, critical_steps=2000)
    d["keep"] = 300
    return d


@pytest.fixture(scope="module")
def small():
    scene = parse_scene(_small(), SCENE_DIR / "impact_zone.toml", check_output=False)
    res = compute(scene)
    yield scene, res


def test_the_example_files_load():
    for name in FILES:
        s = load_scene(SCENE_DIR / f"{name}.toml")
        assert s.kind == "impact_zone" and s.name == name and s.system.eps != 0
        assert s.n_steps >= 20_000 and s.transit_steps >= 100_000 and s.line == "L1"
    second = load_scene(SCENE_DIR / "impact_zone_second.toml").system.build()
    assert 0 < hovering.FlowMap(second, 1.0).onset.Omega0 < 2 * np.pi  # the issue asks for Omega0 in (0, 2 pi)


@pytest.mark.parametrize(
    "key,value,text",
    [
        ("n_starts", 1, r"n_starts = 1 is out of range; allowed: \[2, 2000\]"),
        ("n_steps", 100, r"n_steps = 100 is out of range; allowed: \[256, "),
        ("model", "onset", r"model = 'onset'.*allowed"),
        ("line", "L3", r"line = 'L3'.*allowed"),
        ("transit_steps", 10**9, r"transit_steps = 1000000000 is out of range; allowed: \[1, 100000000\]"),
        ("keep", -1, r"keep = -1 is out of range; allowed: \[0, 100000\]"),
        ("bogus", 1, r"bogus"),
    ],
)
def test_schema_errors_name_the_key_and_the_allowed_values(key, value, text):
    d = _small()
    d[key] = value
    with pytest.raises(ValueError, match=text):
        parse_scene(d, SCENE_DIR / "impact_zone.toml", check_output=False)


def test_eps_zero_and_a_system_without_the_step_are_refused():
    d = _small()
    d["system"]["eps"] = 0.0
    with pytest.raises(ValueError, match=r"system.eps = 0: .*allowed: eps != 0"):
        parse_scene(d, SCENE_DIR / "impact_zone.toml", check_output=False)
    d = _small()
    d["system"]["geometry"] = "none"
    with pytest.raises(ValueError, match=r"geometry = 'none'.*allowed: 'step'"):
        parse_scene(d, SCENE_DIR / "impact_zone.toml", check_output=False)


def test_the_scene_computes_what_its_parts_compute(small):
    scene, res = small
    fm = hovering.FlowMap(scene.system.build(), scene.h, rtol=scene.integrator.rtol)
    tm = fm.truncated(forcing="measured")
    # the model is measured in the flow's zone coordinate: its own ceiling, the flow's floor
    assert res.model.zone.floor == res.flow.zone.floor and res.flow.zone.floor_kind == "flow"
    zone = res.model.zone
    scan = hovering.barrier_scan(tm, zone, n_starts=6, n_steps=1500 * 3, keep=300)
    for f in ("s0", "kind", "period", "s_min", "s_max", "margin", "barrier", "phi", "K"):
        a, b = getattr(scan, f), getattr(res.model.scan, f)
        assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f"), f
    up = hovering.transit(tm, zone, "up", n_orbits=6, n_steps=400 * 3, start_s=0.05)
    assert np.array_equal(up.first_passage, res.model.up.first_passage)
    assert np.array_equal(up.s_max, res.model.up.s_max)
    # the summary reads the same numbers
    s = res.summary()
    assert s["model"]["barriers"] == pytest.approx(list(scan.barriers))
    assert s["model"]["up"]["crossed"] == int(np.count_nonzero(up.crossed))
    assert s["flow"]["starts"] == 6 and s["b1"] == pytest.approx(float(fm.forcing_coefficients()[0]))


def test_the_figure_draws_what_the_result_holds(small):
    _, res = small
    fig = hovering.plot.render(res)
    try:
        assert len(fig.axes) == 4
        for col, study in enumerate((res.flow, res.model)):
            top, bottom = fig.axes[col], fig.axes[2 + col]
            n_bar = len(study.scan.barriers)
            assert sum(1 for ln in top.lines if ln.get_gid() == "barrier") == n_bar
            assert sum(1 for ln in bottom.lines if ln.get_gid() == "barrier") == n_bar
            ranges = {c.get_gid(): c for c in bottom.collections if (c.get_gid() or "").startswith("range:")}
            drawn = sum(len(c.get_segments()) for c in ranges.values())
            assert drawn == len(study.scan)
            for gid, c in ranges.items():
                kind = gid.split(":")[1]
                assert np.allclose(c.get_color()[0][:3], to_rgb(CLASS_COLORS[kind]))
                segs = c.get_segments()
                rows = np.flatnonzero(study.scan.kind == kind)
                np.testing.assert_allclose([sg[:, 1].min() for sg in segs], study.scan.s_min[rows])
                np.testing.assert_allclose([sg[:, 1].max() for sg in segs], study.scan.s_max[rows])
            text = next(t.get_text() for t in bottom.texts if t.get_gid() == "transit")
            up = study.up
            assert f"up: {int(np.count_nonzero(up.crossed))}/{up.crossed.size} crossed" in text
    finally:
        plt.close(fig)


def test_a_loaded_result_is_the_result(small, tmp_path):
    _, res = small
    npz, js = res.save(tmp_path / "iz.npz")
    back = hovering.scenes.load_result(npz)
    assert back.summary() == res.summary()
    assert json.loads(Path(js).read_text())["summary"]["flow"]["layers"] == res.summary()["flow"]["layers"]
    a, b = artists(hovering.plot.render(res)), artists(hovering.plot.render(back))
    assert a.keys() == b.keys()
    plt.close("all")


@pytest.mark.e2e
def test_a_quick_run_of_the_example_writes_png_npz_json_and_redraws(tmp_path, monkeypatch):
    s = pipeline.run_scene(load_scene(SCENE_DIR / "impact_zone.toml", check_output=False),
                           out=tmp_path / "iz.png", quick=True)  # fmt: skip
    assert Path(s["output"]).stat().st_size > 20_000
    doc = json.loads(Path(s["json"]).read_text())
    assert doc["summary"]["kind"] == "impact_zone" and doc["meta"]["quick"] is True

    def refuse(*a, **k):
        raise AssertionError("redraw computed")

    monkeypatch.setattr(hovering.FlowMap, "iterate", refuse)
    png, result, _ = pipeline.redraw(s["npz"], out=tmp_path / "again.png")
    assert png.stat().st_size > 20_000 and result.summary()["flow"] == copy.deepcopy(doc["summary"]["flow"])
