"""Scenes of the physical flow: schema, content of each figure, redraw from the saved result, and
bad input that fails before any computing.

The figures are checked on Agg through the artists' data and gid tags (never pixels), against
independent computations: the flow's own ``FlowMap.region`` for region colours, ``FlowMap.theory``
for the theory line, the potentials' levels for the tori.
"""

from __future__ import annotations

import copy
import resource
import subprocess
import sys
import tomllib
from pathlib import Path

import matplotlib.colors as mc
import matplotlib.pyplot as plt
import numpy as np
import pytest

import hovering
from helpers.figures import artists
from hovering import Region, pipeline, scenes
from hovering.pipeline import run_scene
from hovering.plot.style import REGION_COLORS
from hovering.scenes import parse_scene

SCENE_DIR = Path(__file__).resolve().parents[2] / "examples" / "scenes"
FLOW_FILES = ("flow_portrait", "flow_hov_vs_eps", "fig_two_tang", "fig_structure_sigma")


def _raw(name: str) -> dict:
    return tomllib.loads((SCENE_DIR / f"{name}.toml").read_text())


def _small(name: str) -> dict:
    """The scene file with sizes cut so that a quick run takes about a second."""
    d = _raw(name)
    if name == "flow_portrait":
        d.update(n_orbits=6, n_steps=3000, corner_K=5)
    elif name == "flow_hov_vs_eps":
        d.update(eps=[-0.1, 0.05], samples=3200, n_steps=5000)
    elif name == "fig_structure_sigma":
        d.update(grid=[96, 24])
    return d


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    out = tmp_path_factory.mktemp("flow_scenes")
    done = {}
    for name in FLOW_FILES:
        scene = parse_scene(_small(name), f"{name}.toml")
        done[name] = run_scene(scene, out=out / f"{name}.png", quick=True, keep_figure=True)
    yield done
    for s in done.values():
        plt.close(s["figure"])


def test_every_flow_scene_file_loads_and_names_its_effects():
    for name in FLOW_FILES:
        s = scenes.load_scene(SCENE_DIR / f"{name}.toml")
        assert s.kind in scenes.FLOW_KINDS and s.name == name
        assert s.system.V1.kind == "harmonic" and s.system.V2.kind == "tan" and s.h == 1.0
    tori = scenes.load_scene(SCENE_DIR / "fig_two_tang.toml")
    assert tori.system.eps == 0 and tori.system.geometry == "none" and tori.system.coupling == ()
    assert tori.outputs.record == ("trajectory",)


def test_flow_portrait_starts_outside_the_band_name_k0_range(tmp_path):
    # The band is the flow map's, known once it is built (a second): the refusal then names the
    # scene's key, where it named only K (an adversarial pass gave K0_range = [-1e300, 1e300]).
    d = _small("flow_portrait")
    d.update(n_orbits=3, n_steps=50, K0_range=[-1e300, 1e300])
    with pytest.raises(ValueError, match=r"K0_range = \[-1e\+300, 1e\+300\]: K = -1e\+300 .*allowed"):
        run_scene(parse_scene(d, "p.toml"), out=tmp_path / "p.png", quick=True)
    assert not (tmp_path / "p.png").exists()


@pytest.mark.e2e
@pytest.mark.parametrize("name", FLOW_FILES)
def test_redraw_gives_the_same_figure_without_computing(runs, name, tmp_path, monkeypatch):
    s = runs[name]

    # Drawing must not iterate anything: make every map's iterate fail while redrawing.
    def refuse(*a, **k):
        raise AssertionError("redraw computed")

    for cls in (hovering.FlowMap, hovering.TruncatedMap, hovering.TruncatedFamily):
        monkeypatch.setattr(cls, "iterate", refuse)
    png, result, fig = pipeline.redraw(s["npz"], out=tmp_path / "again.png", keep_figure=True)
    try:
        assert png.stat().st_size > 10_000
        a, b = artists(s["figure"]), artists(fig)
        assert a.keys() == b.keys()
        for k in a:
            if k[1] == "axes":
                assert a[k][:3] == b[k][:3]
                np.testing.assert_array_equal(a[k][3:], b[k][3:])
            else:
                for x, y in zip(a[k], b[k]):
                    np.testing.assert_array_equal(x, y)
        assert result.meta["version"] == hovering.__version__ and result.meta["quick"] is True
    finally:
        plt.close(fig)


def _region_colls(ax):
    return {c.get_gid(): c for c in ax.collections if (c.get_gid() or "").startswith("region:")}


@pytest.mark.e2e
def test_flow_portrait_side_by_side_same_starts_region_colours(runs):
    s = runs["flow_portrait"]
    res, fig = s["result"], s["figure"]
    assert len(fig.axes) == 2
    for ax in fig.axes:
        assert ax.get_xlabel() == r"$\phi$" and ax.get_ylabel() == r"$K$"
        colls = _region_colls(ax)
        assert colls  # coloured by region (recorded: outputs.record = ["regions"])
        for gid, c in colls.items():
            want = mc.to_rgba(REGION_COLORS[Region.parse(gid.split(":")[1])])
            np.testing.assert_allclose(c.get_facecolor()[0], want)
        labels = {ln.get_label() for ln in ax.lines}
        assert {"phi_01", "phi_1R", "phi_R0", "L1", "L2"} <= labels
        assert any(np.all(np.asarray(ln.get_ydata()) == 0) for ln in ax.lines)  # K = 0
    assert "full return map" in fig.axes[0].get_title() and "truncated model" in fig.axes[1].get_title()
    # the same initial conditions for both models, on the flow's L1
    assert res.flow.n_orbits == res.model.n_orbits == 6
    np.testing.assert_array_equal(res.flow.phi[:, 0], res.model.phi[:, 0])
    np.testing.assert_array_equal(res.flow.K[:, 0], res.model.K[:, 0])
    # every flow point is drawn in the colour of its region, as the flow itself labels it: check
    # a sample of points against FlowMap.region (an independent one-return call per point)
    scene = res.scene
    fm = hovering.FlowMap(scene.system.build(), h=scene.h, **scene.integrator.options())
    phi, K, reg = res.flow.phi[:, :-1].ravel(), res.flow.K[:, :-1].ravel(), res.flow.region.ravel()
    pick = np.linspace(0, phi.size - 1, 40).astype(int)
    assert [int(r) for r in fm.region(phi[pick], K[pick])] == [int(r) for r in reg[pick]]
    drawn = {gid: c.get_offsets() for gid, c in _region_colls(fig.axes[0]).items()}
    for r in np.unique(reg):
        pts = np.column_stack([phi[reg == r], K[reg == r]])
        got = np.asarray(drawn[f"region:{Region(int(r)).label}"])
        assert got.shape == pts.shape and np.allclose(np.sort(got, axis=0), np.sort(pts, axis=0))
    # measured corner curves: on the flow panel they are the measured ones, on the model's closed forms
    assert res.flow_geometry.measured and not res.model_geometry.measured
    assert s["flow"]["statuses"] == {"OK": 6}


def test_flow_portrait_without_regions_records_none_and_colours_by_orbit(tmp_path):
    d = _small("flow_portrait")
    d.update(n_orbits=3, n_steps=200, corner_K=0)
    d["outputs"] = {"record": []}
    s = run_scene(parse_scene(d, "p.toml"), out=tmp_path / "p.png", quick=True, keep_figure=True)
    try:
        res = s["result"]
        assert res.flow.region is None and res.model.region is None  # not asked, not computed
        ax = s["figure"].axes[0]
        assert [c.get_gid() for c in ax.collections] == ["orbit:K0=-0.08", "orbit:K0=-0.02", "orbit:K0=0.04"]
        assert res.flow_geometry.corners == {}
    finally:
        plt.close(s["figure"])


@pytest.mark.e2e
def test_flow_hovering_area_scene_both_signs_models_and_theory(runs):
    s = runs["flow_hov_vs_eps"]
    res, fig = s["result"], s["figure"]
    ax = fig.axes[0]
    assert ax.get_xlabel() == r"$\varepsilon$" and "HOV" in ax.get_ylabel()
    gids = {c[0].get_gid() for c in ax.containers}
    assert gids == {"measured:flow", "measured:onset", "measured:measured"}
    flow = [c for c in ax.containers if c[0].get_gid() == "measured:flow"][0]
    order = np.argsort(res.eps)
    np.testing.assert_array_equal(flow[0].get_ydata(), res.flow_area[order])
    # the theory line is FlowMap.theory() at each eps (an independent call): eq:hovsetsize with the
    # measured b1, 0 on the sign that does not hover (here sin(Omega0/2) < 0: eps > 0)
    (theory,) = [ln for ln in ax.lines if ln.get_gid() == "theory:eq:hovsetsize"]
    scene = res.scene
    for e, t in zip(res.eps, res.theory):
        fm = hovering.FlowMap(scene.system.build(eps=e), h=scene.h, **scene.integrator.options())
        assert t == pytest.approx(fm.theory().area, rel=1e-12)
    assert res.theory[res.eps > 0].max() == 0.0 and res.theory[res.eps < 0].min() > 0.1
    # eps = -0.1 hovers, +0.05 does not (thm:hovering with sin(Omega0/2) < 0), for flow and models;
    # error bars cover the difference to eq:hovsetsize at -0.1 (flow_vs_model: 0.1417 vs 0.1508)
    i_neg, i_pos = int(np.flatnonzero(res.eps < 0)[0]), int(np.flatnonzero(res.eps > 0)[0])
    assert res.flow_area[i_neg] == pytest.approx(res.theory[i_neg], abs=res.flow_error[i_neg] + 0.02)
    assert res.flow_area[i_pos] == 0.0
    for m in ("onset", "measured"):
        assert res.models[m]["area"][i_pos] == 0.0 and res.models[m]["agree"][i_neg] > 0.95
    assert len(fig.axes[1].lines) == 2  # agreement curves of both models


@pytest.mark.e2e
def test_sigma_structure_regions_and_images(runs):
    s = runs["fig_structure_sigma"]
    res, fig = s["result"], s["figure"]
    assert len(fig.axes) == 6
    xl = [ax.get_xlabel() for ax in fig.axes]
    assert xl[0] == r"$q_2$" and xl[2] == r"$\theta$" and xl[4] == r"$\phi$"
    assert xl[1].startswith(r"$\bar") and xl[5].startswith(r"$\bar")
    # the band holds all four regions of thm:regionsJdyn (J_0u above the tangency)
    counts = s["regions"]
    assert all(counts[k] > 0 for k in ("0u", "0", "1", "R"))
    assert set(np.unique(res.region[res.K > 0])) == {int(Region.BESIDE)}  # K > 0: J_0u
    # the regions are the flow's own labels of these points (an independent one-return call)
    scene = res.scene
    fm = hovering.FlowMap(scene.system.build(), h=scene.h, **scene.integrator.options())
    pick = np.linspace(0, res.phi.size - 1, 60).astype(int)
    assert [int(r) for r in fm.region(res.phi[pick], res.K[pick])] == [int(r) for r in res.region[pick]]
    phi1, K1 = fm.step(res.phi[pick], res.K[pick])
    np.testing.assert_allclose(phi1, res.phi1[pick], atol=1e-12)
    np.testing.assert_allclose(K1, res.K1[pick], atol=1e-12)
    # every panel coloured by region with the shared colours; corner curves on the (phi, K) panel
    for ax in fig.axes:
        for gid, c in _region_colls(ax).items():
            np.testing.assert_allclose(c.get_facecolor()[0], mc.to_rgba(REGION_COLORS[Region.parse(gid[7:])]))
    assert {"phi_01", "phi_1R", "phi_R0"} <= {ln.get_label() for ln in fig.axes[4].lines}
    # the time-reversal picture (thm:reverseJs): the images of the regions are their reflections
    # theta -> -theta in (theta, I) up to the O(eps) deformation; here: each image region's mean
    # theta has the opposite sign of the region's own for J_1 and J_R
    for r in (Region.UPPER, Region.RIGHT):
        sel = res.region == int(r)
        m0 = np.angle(np.mean(np.exp(1j * res.theta[sel])))
        m1 = np.angle(np.nanmean(np.exp(1j * res.theta1[sel])))
        assert np.sign(m0) == -np.sign(m1)


@pytest.mark.e2e
def test_tangent_tori_figure(runs):
    s = runs["fig_two_tang"]
    res, fig = s["result"], s["figure"]
    assert len(fig.axes) == 4
    sys = res.scene.system.build()
    h1w, h2w = sys.V1.V(sys.qw1), sys.V2.V(sys.qw2)
    right, upper = res.tori
    assert right.name == "right" and upper.name == "upper"
    assert right.h1 == pytest.approx(h1w, rel=1e-15) and upper.h2 == pytest.approx(h2w, rel=1e-12)
    for t in res.tori:
        # circles: the levels H1 = h1, H2 = h2 (1e-12: the potentials' own point_at accuracy)
        np.testing.assert_allclose(0.5 * t.p1**2 + np.array([sys.V1.V(q) for q in t.q1]), t.h1, atol=1e-12)
        np.testing.assert_allclose(0.5 * t.p2**2 + np.array([sys.V2.V(q) for q in t.q2]), t.h2, atol=1e-12)
        tr = t.trajectory
        assert tr.shape[1] == 5 and tr.shape[0] > 100
        # the trajectory lies on its torus: both partial energies conserved (eps = 0) to 1e-9
        np.testing.assert_allclose(0.5 * tr[:, 2] ** 2 + np.array([sys.V1.V(q) for q in tr[:, 1]]), t.h1, atol=1e-9)
        np.testing.assert_allclose(0.5 * tr[:, 4] ** 2 + np.array([sys.V2.V(q) for q in tr[:, 3]]), t.h2, atol=1e-9)
    # tangency: the right torus's q1 reaches qw1 (its minimum), the upper torus's q2 reaches qw2
    assert min(right.q1) == pytest.approx(sys.qw1, abs=1e-9) and min(upper.q2) == pytest.approx(sys.qw2, abs=1e-9)
    gids = {ln.get_gid() for ax in fig.axes for ln in ax.lines}
    assert {"trajectory:right", "trajectory:upper", "torus:right", "torus:upper"} <= gids
    assert [ax.get_xlabel() for ax in fig.axes] == [r"$q_1$", r"$q_1$", r"$q_1$", r"$q_2$"]
    # the effects the scene names and no others: no walls (geometry none) -> no wall-event search, no
    # coupling (eps = 0) -> none evaluated, a trajectory asked -> dense samples; no labels asked
    for w in s["work"].values():
        assert w["wall_searches"] == 0 and w["coupling_evaluations"] == 0 and w["label_operations"] == 0
        assert w["dense_samples"] > 100 and w["field_evaluations"] > 0


# ------------------------------------------------------------------------------------------------
# Schema: every flow kind's errors name the key


BAD = [
    ("flow_portrait", ("system", "V1", "kind"), "cubic", "system.V1.kind = 'cubic' is not allowed"),
    ("flow_portrait", ("system", "V2", "alpha"), None, "system.V2: missing required key 'alpha'"),
    ("flow_portrait", ("system", "bogus"), 1, "system: unknown key(s) 'bogus'"),
    ("flow_portrait", ("system", "qw1"), 0.5, "system.qw1 = 0.5 is out of range"),
    ("flow_portrait", ("system", "geometry"), "wall", "system.geometry = 'wall'"),
    ("flow_portrait", ("system", "coupling"), [[1.0, 1]], "system.coupling[0] must be a term [c, i, j]"),
    # A repeated power: before, the last coefficient silently replaced the first (Polynomial's dict).
    (
        "flow_portrait",
        ("system", "coupling"),
        [[1.0, 1, 1], [0.5, 2, 0], [2.0, 1, 1]],
        "flow_portrait.toml.system.coupling[2] = [2.0, 1, 1] repeats the term q1^1 q2^1 of "
        "flow_portrait.toml.system.coupling[0]; allowed: each power (i, j) once",
    ),
    ("flow_portrait", ("section", "h"), 0.1, "section.h = 0.1 is out of range; allowed: above the step energy"),
    ("flow_portrait", ("integrator", "rtol"), 1.0, "integrator.rtol = 1.0 is out of range"),
    ("flow_portrait", ("integrator", "stepper"), "euler", "integrator.stepper = 'euler' is not allowed"),
    ("flow_portrait", ("outputs", "record"), ["trajectory"], "outputs.record = 'trajectory' is not allowed"),
    ("flow_portrait", ("model",), "third", "model = 'third' is not allowed"),
    ("flow_portrait", ("n_steps",), 0, "n_steps = 0 is out of range"),
    ("flow_hov_vs_eps", ("eps",), [0.1, 0.1], "eps = [0.1, 0.1] lists a value twice"),
    ("flow_hov_vs_eps", ("models",), ["onset", "other"], "models = 'other' is not allowed"),
    ("flow_hov_vs_eps", ("samples",), 3, "samples = 3 is out of range"),
    ("fig_two_tang", ("outputs", "record"), [], "outputs.record = [] lacks ['trajectory']"),
    ("fig_two_tang", ("system", "geometry"), "step", "the tangent tori are those of the unperturbed smooth flow"),
    ("fig_two_tang", ("system", "eps"), 0.1, "eps != 0 needs a coupling"),
    ("fig_two_tang", ("outputs", "trajectory_dt"), 0.0, "outputs.trajectory_dt = 0.0 is out of range"),
    ("fig_structure_sigma", ("grid",), [10], "grid must be [n_phi, n_K]"),
    ("fig_structure_sigma", ("outputs", "record"), ["regions"], "lacks ['section', 'states']"),
]


@pytest.mark.parametrize("name,path,value,text", BAD)
def test_flow_schema_errors_name_the_key(name, path, value, text):
    d = copy.deepcopy(_raw(name))
    t = d
    for k in path[:-1]:
        t = t[k]
    if value is None:
        del t[path[-1]]
    else:
        t[path[-1]] = value
    with pytest.raises(ValueError) as e:
        parse_scene(d, f"{name}.toml")
    assert text in str(e.value), str(e.value)


@pytest.mark.e2e
@pytest.mark.parametrize(
    "case,text",
    [
        ("unwritable", "is not a directory"),
        ("format", "matplotlib cannot write '.xyz' files"),
        ("expression", "expression of 359 characters; allowed: at most 200"),
        ("deep", "expression of 303 characters; allowed: at most 200"),
        ("code", "cannot evaluate"),
        ("colour", "is not a matplotlib colour"),
    ],
)
def test_bad_flow_scene_fails_in_the_cli_before_computing(tmp_path, case, text):
    src = (SCENE_DIR / "flow_portrait.toml").read_text()
    if case == "unwritable":
        # a regular file where the directory should be: not writable for anyone, root included
        blocker = tmp_path / "blocker"
        blocker.write_text("x")
        src = src.replace('output = "out/flow_portrait.png"', f'output = "{blocker}/sub/x.png"')
    elif case == "format":
        src = src.replace("out/flow_portrait.png", "out/flow_portrait.xyz")
    elif case == "expression":
        src = src.replace("\neps = -0.05", '\neps = "' + "+".join(["0.001"] * 60) + '"')
    elif case == "deep":  # 150 nested parentheses: refused by length before the parser sees them
        src = src.replace("\neps = -0.05", '\neps = "' + "(" * 150 + "0.1" + ")" * 150 + '"')
    elif case == "code":
        src = src.replace("\neps = -0.05", "\neps = \"__import__('os').getcwd()\"")
    else:  # the flow's hovering scene has no colour key; the truncated ones do
        src = (SCENE_DIR / "fig_hov_vs_eps.toml").read_text()
        src = src.replace("output = ", 'output = "x.png"\n#', 1)
        src = src.replace("[[series]]", '[[series]]\ncolor = "no-such-colour"', 1)
    p = tmp_path / "bad.toml"
    p.write_text(src)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run(
        [sys.executable, "-m", "hovering", "scene", str(p)], capture_output=True, text=True, cwd=tmp_path, timeout=120
    )
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    assert r.returncode == 2 and r.stderr.startswith("error: ") and "Traceback" not in r.stderr
    assert text in r.stderr, r.stderr
    # CPU seconds of the child (load-proof): interpreter start-up included (~0.5 s); the check
    # itself is well under a second, the scene's computation would be many seconds.
    assert cpu < 5.0
    assert not list(tmp_path.glob("**/*.npz"))


@pytest.mark.e2e
def test_cli_redraw(tmp_path, runs, capsys):
    from hovering.cli import main

    out = tmp_path / "re.png"
    assert main(["redraw", runs["flow_portrait"]["npz"], "--out", str(out)]) == 0
    assert out.stat().st_size > 10_000 and "without computing" in capsys.readouterr().out
    bad = tmp_path / "junk.npz"
    bad.write_bytes(b"not a zip")
    assert main(["redraw", str(bad)]) == 2
    np.savez(tmp_path / "plain.npz", x=np.zeros(3))
    assert main(["redraw", str(tmp_path / "plain.npz")]) == 2
    err = capsys.readouterr().err
    assert "error: " in err and "not a hovering result file" in err and "Traceback" not in err


def test_scene_progress_reaches_its_total(tmp_path):
    # a sweep scene reports its points; an orbit scene the iterations of its core calls
    calls = []
    d = _small("flow_hov_vs_eps")
    d.update(eps=[-0.1, 0.05], samples=100, n_steps=100, models=["onset"])
    scenes.compute(
        parse_scene(d, "h.toml"),
        quick=True,
        progress=lambda done, total: calls.append((done, total)),
        checkpoint=tmp_path / "h.jsonl",
    )
    assert calls and calls[-1] == (2, 2) and all(a <= b for (a, _), (b, _) in zip(calls, calls[1:]))
    calls.clear()
    d = _small("flow_portrait")
    d.update(n_orbits=2, n_steps=100, corner_K=0)
    scenes.compute(parse_scene(d, "p.toml"), quick=True, progress=lambda done, total: calls.append((done, total)))
    assert calls and calls[-1][0] == calls[-1][1] == 2 * 50  # 2 orbits x 50 returns (quick: 100 / 50, floor 50)
    with pytest.raises(ValueError, match="progress"):
        scenes.compute(parse_scene(d, "p.toml"), progress="yes")


def test_cli_explore_is_wired(capsys):
    from hovering.cli import main

    # on Agg there is no window: the scene and its map are checked and built, nothing is shown
    assert main(["explore", str(SCENE_DIR / "flow_portrait.toml"), "--n-steps", "10"]) == 0
    assert "cannot open a window" in capsys.readouterr().err
    assert main(["explore", str(SCENE_DIR / "absent.toml")]) == 2
    assert "error:" in capsys.readouterr().err


def test_a_repeated_coupling_power_is_refused_in_a_file_and_in_a_spec(tmp_path):
    # Read from a file: the error names the file, the entry and the term it repeats.
    text = (SCENE_DIR / "flow_portrait.toml").read_text()
    assert 'coupling = "bilinear"' in text
    path = tmp_path / "dup.toml"
    path.write_text(text.replace('coupling = "bilinear"', "coupling = [[1.0, 1, 1], [2.0, 1, 1]]"))
    with pytest.raises(ValueError, match=r"^dup\.toml\.system\.coupling\[1\] = \[2\.0, 1, 1\] repeats the term"):
        scenes.load_scene(path, check_output=False)
    # A spec built in Python: its system is not built with one of the two coefficients dropped.
    from hovering.scenes.spec import PotentialSpec, SystemSpec

    spec = SystemSpec(
        PotentialSpec("harmonic", 1.0), PotentialSpec("harmonic", 1.4), coupling=((1.0, 1, 1), (2.0, 1, 1))
    )
    with pytest.raises(
        ValueError, match=r"coupling\[1\] = \(2\.0, 1, 1\) repeats the power q1\^1 q2\^1 of coupling\[0\]"
    ):
        spec.build()


def test_a_flow_figure_names_the_stepper_that_ran():
    # The line under a flow figure's title names the integrator as it ran: "auto" resolved on the
    # system (what FlowMap resolves it to), an explicit stepper as given, an accuracy target as a
    # target, and a result that records its setting (flow_portrait) by that record.
    from hovering.plot.common import system_text

    def scene(**integrator):
        d = _raw("flow_hov_vs_eps")
        d["integrator"] = integrator
        return parse_scene(d, "flow_hov_vs_eps.toml", check_output=False)

    auto = scene(rtol=1e-9)
    ran = hovering.FlowMap(auto.system.build(), auto.h, rtol=1e-9).integrator_options["stepper"]
    assert ran == "taylor" and system_text(auto).endswith("taylor rtol 1e-09")
    assert system_text(scene(stepper="rk8pd", rtol=1e-8)).endswith("rk8pd rtol 1e-08")
    assert system_text(scene(accuracy=1e-9)).endswith("accuracy target 1e-09")

    class Recorded:
        meta = {"accuracy": {"integrator": {"stepper": "rkf45", "rtol": 3e-7, "atol": 3e-7}}}

    assert system_text(auto, Recorded()).endswith("rkf45 rtol 3e-07")
    Recorded.meta = {"accuracy": {"integrator": {"stepper": "exact", "rtol": 1e-10, "atol": 1e-10}}}
    assert system_text(auto, Recorded()).endswith("exact (closed form)")  # it ignores rtol


def test_a_flow_scene_sets_every_integrator_option():
    # [integrator] takes every option FlowMap takes (the core's defaults where absent), checked
    # against the core's ranges when the scene is read, before anything is computed.
    d = _raw("flow_hov_vs_eps")
    d["integrator"] = {"rtol": 1e-9, "verify_steps": 0, "max_impacts": 7, "corner_tol": 1e-6, "event_tol": 1e-13}
    s = parse_scene(d, "flow_hov_vs_eps.toml", check_output=False)
    o = s.integrator.flow_map(s.system.build(), s.h).integrator_options
    assert (o["verify_steps"], o["max_impacts"], o["corner_tol"], o["event_tol"]) == (0, 7, 1e-6, 1e-13)
    core = hovering._core.flow.FlowOptions()
    assert (o["max_steps"], o["grazing_tol"]) == (core.max_steps, core.grazing_tol)
    # The wall-section kinds trace with the same options (WallFlow took only the tolerances).
    from hovering.scenes.kinds._flow import wall_flow

    w = _raw("fig_wallsection")
    w["integrator"] = dict(d["integrator"])
    wo = wall_flow(parse_scene(w, "fig_wallsection.toml", check_output=False)).options
    assert (wo.verify_steps, wo.max_impacts, wo.corner_tol, wo.event_tol, wo.rtol) == (0, 7, 1e-6, 1e-13, 1e-9)
    for key, value, needle in (
        ("verify_steps", -2, r"integrator\.verify_steps.*-2.*\[-1, "),
        ("max_impacts", 0, r"integrator\.max_impacts.*0.*\[1, 1000000\]"),
        ("max_steps", 2.5, r"integrator\.max_steps"),
        ("event_tol", 0.0, r"integrator\.event_tol"),
        ("grazing_tol", -1e-12, r"integrator\.grazing_tol"),
    ):
        bad = copy.deepcopy(d)
        bad["integrator"][key] = value
        with pytest.raises(ValueError, match=needle):
            parse_scene(bad, "flow_hov_vs_eps.toml", check_output=False)
