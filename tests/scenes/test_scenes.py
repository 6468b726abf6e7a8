"""Scene files (examples/scenes/*.toml): validation, quick runs and the content of each figure.

Oracles: the scene files themselves (every one must load), the paper's construction of each figure
(sec:truncatedmapnumact: which initial conditions, which curves, how many panels), closed forms of
the geometry module (K~_c, L1, L2, k_eps1, k_eps2, eq:hovsetsize), and the paper's statement that
for an orbit staying in J_0 u J_0u the rotation number is Omega0 + tau0 <K>. Figures are checked by
content (axes, labels, artists, legend text), never by pixels.
"""

from __future__ import annotations

import json
import re
import tomllib
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import hovering
from hovering import Region, Status, scenes
from hovering.pipeline import run_scene
from hovering.scenes import load_scene, parse_scene
from hovering.scenes.compute import zoom_window_critical, zoom_window_islands

SCENE_DIR = Path(__file__).resolve().parents[2] / "examples" / "scenes"
EXPECTED = {"fig_smallepsmany", "fig_smalleps", "fig_hoverinnc", "fig_epsbig", "fig_hov_vs_eps"}
FLOW = {"flow_portrait", "flow_hov_vs_eps", "fig_two_tang", "fig_structure_sigma"}  # tests/scenes/test_flow_scenes.py
PAPER_FIGURES = {"fig_corner_directions", "fig_sigma0_wall", "fig_wallsection"}  # tests/scenes/test_paper_figures.py
ZONE = {"impact_zone", "impact_zone_neg", "impact_zone_second"}  # tests/scenes/test_impact_zone_scene.py
TANGENT = {"ftle_field", "periodic_manifolds", "residue_vs_eps"}  # tests/scenes/test_tangent_scenes.py
SCENE_FILES = [SCENE_DIR / f"{n}.toml" for n in sorted(EXPECTED)]


def _raw(name):
    with open(SCENE_DIR / f"{name}.toml", "rb") as f:
        return tomllib.load(f)


# ------------------------------------------------------------------------------------------------
# Loading and validation


def test_one_scene_file_per_figure():
    assert {p.stem for p in SCENE_DIR.glob("*.toml")} == EXPECTED | FLOW | PAPER_FIGURES | ZONE | TANGENT


@pytest.mark.parametrize("path", SCENE_FILES, ids=[p.stem for p in SCENE_FILES])
def test_every_scene_file_loads_and_validates(path):
    s = load_scene(path)
    assert s.kind in scenes.KINDS
    assert s.name == path.stem
    assert s.output.suffix == ".png"
    assert s.n_steps > 0
    if s.kind == "hovering_area":
        assert s.eps and s.series
    else:
        assert s.panels
        for p in s.panels:
            assert (p.map is None) == (p.zoom is not None)


def test_paper_parameters_and_golden_family_are_resolved():
    s = load_scene(SCENE_DIR / "fig_smalleps.toml")
    a, b = s.panels
    assert (a.map.eps, b.map.eps) == (0.3, -0.3)
    # "OMEGA_G" and "3*pi/4" are expressions in the file
    assert a.map.Omega0 == pytest.approx(2 * np.pi * (np.sqrt(5) - 1) / 2, rel=1e-15)
    assert a.map.theta_w == pytest.approx(3 * np.pi / 4, rel=1e-15)
    assert (a.map.tau0, a.map.tau1, a.map.lam) == (1.0, 0.5, 0.5)
    e = load_scene(SCENE_DIR / "fig_epsbig.toml")
    by_id = {p.id: p for p in e.panels}
    # (d): eps = -0.92 with the (Omega0, theta_w) of (b), eps = 0.92; (e): its own
    assert (by_id["d"].map.Omega0, by_id["d"].map.theta_w) == (by_id["b"].map.Omega0, by_id["b"].map.theta_w)
    assert by_id["d"].map.eps == -0.92 and by_id["e"].map.eps == -0.92
    O, tw = hovering.golden_family(-0.92, -0.9)
    assert (by_id["e"].map.Omega0, by_id["e"].map.theta_w) == (O, tw)
    assert by_id["c"].zoom.of == "b" and by_id["c"].zoom.on == "islands"


def _set(d, path, value):
    """Set d[path] where path is a tuple of keys/indices; value _DEL deletes."""
    for k in path[:-1]:
        d = d[k]
    if value is _DEL:
        del d[path[-1]]
    else:
        d[path[-1]] = value


_DEL = object()

# (scene, path to change, new value, text the message must contain)
UNKNOWN = [
    ("fig_smalleps", ("colour",), "red", "colour"),
    ("fig_smalleps", ("map", "omega0"), 1.0, "omega0"),
    ("fig_smalleps", ("panels", 0, "epsilon"), 0.1, "epsilon"),
    ("fig_hoverinnc", ("panels", 0, "golden", "C"), 0.5, "'C'"),
    ("fig_hoverinnc", ("panels", 2, "zoom", "padding"), 0.5, "padding"),
    ("fig_epsbig", ("panels", 1, "critical", "Krange"), [0, 1], "Krange"),
    ("fig_epsbig", ("panels", 1, "orbits", 0, "k0"), 0.1, "k0"),
    ("fig_smallepsmany", ("panels", 0, "special"), ["blue"], "special"),  # not a portrait key
    ("fig_hov_vs_eps", ("series", 0, "c"), 0.5, "'c'"),
    ("fig_hov_vs_eps", ("panels",), [], "panels"),
]


@pytest.mark.parametrize("name,path,value,text", UNKNOWN, ids=[".".join(map(str, u[1])) for u in UNKNOWN])
def test_unknown_keys_are_named(name, path, value, text):
    d = _raw(name)
    _set(d, path, value)
    with pytest.raises(ValueError, match="unknown key") as e:
        parse_scene(d, SCENE_DIR / f"{name}.toml")
    msg = str(e.value)
    assert text in msg and "allowed keys" in msg


MISSING = [
    ("fig_smalleps", ("kind",), "kind"),
    ("fig_smalleps", ("output",), "output"),
    ("fig_smalleps", ("n_steps",), "n_steps"),
    ("fig_smalleps", ("panels",), "panels"),
    ("fig_smalleps", ("panels", 1, "eps"), "eps"),
    ("fig_smalleps", ("panels", 0, "id"), "id"),
    ("fig_smalleps", ("map", "theta_w"), "theta_w"),
    ("fig_hoverinnc", ("panels", 0, "golden", "c"), "'c'"),
    ("fig_hoverinnc", ("panels", 2, "zoom", "of"), "'of'"),
    ("fig_epsbig", ("panels", 1, "orbits", 2, "K0"), "K0"),
    ("fig_epsbig", ("panels", 2, "zoom", "orbits"), "orbits"),
    ("fig_smallepsmany", ("K0_range",), "K0_range"),
    ("fig_hov_vs_eps", ("eps",), "eps"),
    ("fig_hov_vs_eps", ("series", 0, "label"), "label"),
]


@pytest.mark.parametrize("name,path,text", MISSING, ids=[".".join(map(str, m[1])) for m in MISSING])
def test_missing_required_keys_are_named(name, path, text):
    d = _raw(name)
    _set(d, path, _DEL)
    with pytest.raises(ValueError, match="missing required key") as e:
        parse_scene(d, SCENE_DIR / f"{name}.toml")
    assert text in str(e.value)


BAD = [
    ("fig_smalleps", ("kind",), "movie", ["kind", "'movie'", "portrait"]),
    ("fig_smalleps", ("map", "theta_w"), 4.0, ["theta_w", "4.0", "(0.0, 3.14159"]),
    ("fig_smalleps", ("map", "lam"), 0, ["lam", "(0.0, inf)"]),
    ("fig_smalleps", ("n_steps",), -5, ["n_steps", "-5", "[1, "]),
    ("fig_smalleps", ("n_steps",), "many", ["n_steps", "integer", "'many'"]),
    ("fig_smalleps", ("n_steps",), True, ["n_steps", "integer"]),
    ("fig_smalleps", ("panels", 0, "eps"), "pi/0", ["eps", "'pi/0'", "expression"]),
    ("fig_smalleps", ("panels", 0, "eps"), "__import__('os')", ["eps", "cannot evaluate"]),
    ("fig_smalleps", ("panels", 0, "eps"), float("nan"), ["eps", "finite"]),
    ("fig_smalleps", ("rotation",), "median", ["rotation", "'median'", "'birkhoff'"]),
    ("fig_smalleps", ("panels", 0, "special"), ["purple"], ["special", "'purple'", "'blue'"]),
    ("fig_smalleps", ("panels", 1, "id"), "a", ["id", "'a'", "twice"]),
    ("fig_smalleps", ("layout",), [1, 1], ["layout", "rows * cols >= 2"]),
    ("fig_smalleps", ("panels", 0, "ylim"), [1.0, -1.0], ["ylim", "increasing"]),
    ("fig_smallepsmany", ("color_by",), "rainbow", ["color_by", "'rainbow'", "'region'"]),
    ("fig_smallepsmany", ("K0_range",), [-5.0, 0.5], ["K0_range", "band floor"]),
    ("fig_hoverinnc", ("panels", 0, "golden", "c"), 1.2, ["golden.c", "|c| < |tau0|"]),
    ("fig_hoverinnc", ("panels", 2, "zoom", "of"), "zz", ["zoom.of", "'zz'", "allowed"]),
    ("fig_hoverinnc", ("panels", 2, "zoom", "on"), "middle", ["zoom.on", "'middle'", "'islands'"]),
    ("fig_epsbig", ("panels", 2, "zoom", "orbits"), ["nope"], ["zoom.orbits", "'nope'", "allowed"]),
    ("fig_epsbig", ("panels", 1, "orbits", 0, "K0"), -9.0, ["orbits[0].K0", "band floor"]),
    ("fig_epsbig", ("panels", 1, "orbits", 0, "line"), "L1", ["orbits[0]", "exactly one of 'phi0'"]),
    ("fig_epsbig", ("panels", 1, "orbits", 1, "label"), "island A, period 5", ["used twice"]),
    ("fig_hov_vs_eps", ("eps",), [0.1, "x"], ["eps[1]", "'x'"]),
    ("fig_hov_vs_eps", ("series", 3, "K_low"), -10.0, ["K_low", "band floor"]),
    ("fig_hov_vs_eps", ("samples",), 0, ["samples", "out of range"]),
    # Checked at load, not at savefig after the simulation (issue 11):
    ("fig_hov_vs_eps", ("series", 0, "color"), "C99x", ["series[0].color", "'C99x'", "not a matplotlib colour"]),
    ("fig_epsbig", ("panels", 1, "orbits", 0, "color"), "bluish", ["orbits[0].color", "'bluish'"]),
    # Text the figure draws: its math parses at load (a bad title once failed after 89 s of work)
    ("fig_hov_vs_eps", ("title",), "$\\frac{1}{$ of eps", ["title", "does not parse", "mathtext"]),
    ("fig_epsbig", ("panels", 1, "orbits", 0, "label"), "island $x^$", ["orbits[0].label", "does not parse"]),
    ("fig_smalleps", ("output",), "out/fig.xyz", ["output", "'.xyz'", ".png", ".pdf"]),
    ("fig_smalleps", ("output",), str(SCENE_DIR / "fig_smalleps.toml" / "x.png"), ["output", "is not a directory"]),
    ("fig_smalleps", ("output",), "out/" + "f" * 300 + ".png", ["output", "304 bytes", "at most 255 bytes"]),
    ("fig_smalleps", ("panels", 0, "eps"), "1/0", ["eps", "'1/0'", "division by zero"]),
    ("fig_smalleps", ("panels", 0, "eps"), "10**400", ["eps", "too large for a double"]),
    ("fig_smalleps", ("panels", 0, "eps"), "sqrt(-1)", ["eps", "math domain error"]),
    ("fig_smalleps", ("panels",), [{"id": f"p{i}"} for i in range(37)], ["panels", "37 panels", "at most 36"]),
    ("fig_hov_vs_eps", ("seed",), 2**70, ["seed", "out of range"]),
    ("fig_smalleps", ("panels", 0, "eps"), "(" * 30000 + "1" + ")" * 30000, ["eps", "60001 characters", "at most 200"]),
]


@pytest.mark.parametrize("name,path,value,texts", BAD, ids=[f"{'.'.join(map(str, b[1]))}={b[2]!r}" for b in BAD])
def test_bad_values_name_key_value_and_range(name, path, value, texts):
    d = _raw(name)
    _set(d, path, value)
    with pytest.raises(ValueError) as e:
        parse_scene(d, SCENE_DIR / f"{name}.toml")
    for t in texts:
        assert t in str(e.value), (t, str(e.value))


def test_golden_and_explicit_theta_w_conflict():
    d = _raw("fig_hoverinnc")
    d["panels"][0]["theta_w"] = 1.0
    with pytest.raises(ValueError, match="either 'golden' or 'theta_w'"):
        parse_scene(d)


def test_load_scene_reports_toml_syntax_errors(tmp_path):
    p = tmp_path / "broken.toml"
    p.write_text('kind = "portrait"\nn_steps = = 3\n')
    with pytest.raises(ValueError, match="broken.toml: not valid TOML"):
        load_scene(p)
    with pytest.raises(FileNotFoundError):
        load_scene(tmp_path / "absent.toml")


# ------------------------------------------------------------------------------------------------
# Quick runs of every scene (once per module) and the content of the figures


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    import matplotlib.pyplot as plt

    out = tmp_path_factory.mktemp("scenes")
    done = {}
    for path in SCENE_FILES:
        s = load_scene(path)
        done[path.stem] = run_scene(s, out=out / f"{path.stem}.png", quick=True, keep_figure=True)
    yield done
    for summary in done.values():
        plt.close(summary["figure"])


@pytest.mark.e2e
@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_quick_run_writes_png_and_npz(runs, name):
    s = runs[name]
    png, npz = Path(s["output"]), Path(s["npz"])
    assert png.stat().st_size > 10_000
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert s["quick"] is True
    full = load_scene(SCENE_DIR / f"{name}.toml").n_steps
    assert s["n_steps"] == max(full // scenes.QUICK_FACTOR, 100)
    # the typed result on disk: NPZ (arrays + tree) and a sidecar JSON (scene, meta, summary)
    res = scenes.load_result(npz)
    assert res.meta["n_steps"] == s["n_steps"] and res.scene.name == name and res.meta["quick"] is True
    side = json.loads(Path(s["json"]).read_text())
    assert side["summary"]["n_steps"] == s["n_steps"] and side["summary"]["scene"] == name
    assert side["meta"]["version"] == hovering.__version__ and side["meta"]["timings"]["total"] > 0


def _orbit_colls(ax):
    return [c for c in ax.collections if (c.get_gid() or "").startswith("orbit:")]


def _labels(ax):
    return {ln.get_label() for ln in ax.lines}


def _orbit_axes(fig):
    return [ax for ax in fig.axes if ax.get_xlabel() == r"$\phi$"]


@pytest.mark.e2e
def test_smallepsmany_two_panels_of_thirty_orbits(runs):
    s = runs["fig_smallepsmany"]
    fig = s["figure"]
    assert len(fig.axes) == 2
    for ax, eps, p in zip(fig.axes, (0.3, -0.3), s["panels"]):
        assert ax.get_xlabel() == r"$\phi$" and ax.get_ylabel() == r"$K$"
        assert len(_orbit_colls(ax)) == 30
        assert rf"\varepsilon={eps:g}" in ax.get_title()
        assert {"phi_01", "phi_1R", "phi_R0", "L1", "L2"} <= _labels(ax)
        # evenly spaced on L1 from the scene's K0_range
        K0 = np.array([o["K0"] for o in p["orbits"]])
        np.testing.assert_allclose(K0, np.linspace(-1.0, 0.5, 30), atol=1e-12)
        m = hovering.TruncatedMap(eps, hovering.OMEGA_G, 3 * np.pi / 4)
        phi0 = np.array([o["phi0"] for o in p["orbits"]])
        np.testing.assert_allclose(phi0, m.L1(K0), atol=1e-12)


@pytest.mark.e2e
def test_smalleps_special_orbits_legends_and_curves(runs):
    s = runs["fig_smalleps"]
    fig = s["figure"]
    assert len(fig.axes) == 2
    result = s["result"]
    for ax, p in zip(fig.axes, s["panels"]):
        eps = p["params"]["eps"]
        m = hovering.TruncatedMap(**p["params"])
        assert ax.get_xlabel() == r"$\phi$" and ax.get_ylabel() == r"$K$"
        colls = _orbit_colls(ax)
        assert [c.get_gid() for c in colls] == ["orbit:blue", "orbit:orange", "orbit:green", "orbit:red"]
        # the paper's colours: blue, orange, green, red = C0..C3
        import matplotlib.colors as mc

        for c, col in zip(colls, ("C0", "C1", "C2", "C3")):
            np.testing.assert_allclose(c.get_facecolor()[0], mc.to_rgba(col))
        # initial conditions of sec:truncatedmapnumact
        o = {x["label"]: x for x in p["orbits"]}
        Kc = hovering.K_crit(eps, 3 * np.pi / 4, hovering.OMEGA_G)
        assert o["blue"]["K0"] == pytest.approx(Kc, abs=1e-15)
        assert o["orange"]["K0"] == pytest.approx(Kc + 0.05 * abs(eps), abs=1e-15)
        assert o["green"]["K0"] == 0.0 and o["red"]["K0"] == 0.0
        assert o["green"]["phi0"] == pytest.approx(hovering.wrap(-hovering.OMEGA_G / 2), abs=1e-14)
        assert o["red"]["phi0"] == pytest.approx(hovering.wrap(np.pi - hovering.OMEGA_G / 2), abs=1e-14)
        # legend: one entry per orbit with its rho (3 decimals), plus the black leading curve
        texts = [t.get_text() for t in ax.get_legend().get_texts()]
        assert len(texts) == 5
        for lab in ("blue", "orange", "green", "red"):
            assert any(f"{o[lab]['rho']:.3f}" in t and r"\rho" in t for t in texts), (lab, texts)
        # rho is <omega_a>; an orbit that never impacts has rho = Omega0 + tau0 <K> (paper, after
        # fig:smalleps); 1e-12 covers the summation order of the two means.
        free = [x for x in p["orbits"] if x["impacts"] == 0 and x["status"] == "OK"]
        assert free  # green for eps > 0, red for eps < 0 (the curve k^{u0})
        orbits = result.panel(p["id"]).orbits
        for x in free:
            i = orbits.labels.index(x["label"])
            K = orbits.K[i]
            assert x["rho"] == pytest.approx(m.Omega0 + m.tau0 * K[:-1].mean(), abs=1e-12)
        # the leading-order curve: k_{eps,1}(phi; 0) for eps > 0, k_{eps,2}(phi; 0) for eps < 0
        (lead,) = [ln for ln in ax.lines if ln.get_gid() == "leading_curve"]
        x, y = lead.get_data()
        want = m.k_eps1(x, 0.0) if eps > 0 else m.k_eps2(x, 0.0)
        np.testing.assert_allclose(y, want, atol=1e-15)
        assert lead.get_color() == "k"
        # corner-singularity curves in dashed black, K = 0 / L1 / L2 in light grey
        corner = [ln for ln in ax.lines if ln.get_label() in ("phi_01", "phi_1R", "phi_R0")]
        assert len(corner) == 3 and all(ln.get_color() == "k" for ln in corner)
        assert any(ln.get_linestyle() == "--" for ln in corner)
        grey = [ln for ln in ax.lines if ln.get_label() in ("L1", "L2")]
        assert len(grey) == 2 and all(ln.get_color() == "0.55" for ln in grey)
        assert any(np.all(np.asarray(ln.get_ydata()) == 0) for ln in ax.lines)  # K = 0


@pytest.mark.e2e
def test_smalleps_hovering_only_for_positive_eps(runs):
    # fig:smalleps a: blue and orange lie on invariant curves in J_0 u J_0u dipping below K = 0;
    # b: no L1 orbit hovers (the hovering set is destroyed); red stays on K >= 0 curve.
    pa, pb = runs["fig_smalleps"]["panels"]
    oa = {o["label"]: o for o in pa["orbits"]}
    ob = {o["label"]: o for o in pb["orbits"]}
    assert oa["blue"]["hovering"] and oa["orange"]["hovering"]
    assert not any(ob[k]["hovering"] for k in ("blue", "orange", "green"))
    assert ob["red"]["impacts"] == 0 and ob["red"]["K_min"] >= -1e-12


@pytest.mark.e2e
def test_hoverinnc_zoom_shows_the_dip_of_the_critical_curve(runs):
    s = runs["fig_hoverinnc"]
    fig = s["figure"]
    assert len(fig.axes) == 3
    pa, pb, pc = s["panels"]
    for ax, p in zip(fig.axes[:2], (pa, pb)):
        assert len(_orbit_colls(ax)) == len(p["orbits"]) >= 4
        assert "golden family $c=" in ax.get_title()
    assert pa["params"]["golden_c"] == -0.9 and pb["params"]["golden_c"] == 0.9
    zax = fig.axes[2]
    w = pc["window"]
    assert pc["zoom_of"] == "b"
    np.testing.assert_allclose(zax.get_xlim(), w["xlim"])
    np.testing.assert_allclose(zax.get_ylim(), w["ylim"])
    # the window holds K = 0 and the minimum of the orbit it was built from, and is a real zoom
    o = {x["label"]: x for x in pb["orbits"]}[w["orbit"]]
    assert o["hovering"]
    assert w["ylim"][0] < o["K_min"] < 0 < w["ylim"][1]
    assert w["ylim"][1] - w["ylim"][0] < 0.25 * (fig.axes[1].get_ylim()[1] - fig.axes[1].get_ylim()[0])
    assert zax.get_xlabel() == r"$\phi$" and "zoom of (b)" in zax.get_title()


@pytest.mark.e2e
def test_epsbig_panels_islands_zoom_and_flipped_eps(runs):
    s = runs["fig_epsbig"]
    fig = s["figure"]
    assert len(fig.axes) == 5
    by_id = {p["id"]: p for p in s["panels"]}
    eps = [by_id[k]["params"]["eps"] for k in "abde"]
    assert eps == [0.6, 0.92, -0.92, -0.92]
    labels_b = [o["label"] for o in by_id["b"]["orbits"]]
    assert labels_b[:4] == ["blue", "orange", "green", "red"]
    assert sum(lab.startswith("island") for lab in labels_b) == 4
    axb = fig.axes[1]
    assert len(_orbit_colls(axb)) == len(labels_b)
    # zoom (c): inside the circle, and it contains the impacting points of the island orbits
    w = by_id["c"]["window"]
    assert -np.pi <= w["xlim"][0] < w["xlim"][1] <= np.pi
    ob = s["result"].panel("b").orbits
    lab, phi, K, reg = ob.labels, ob.phi, ob.K, ob.region
    for name in w["orbits"]:
        i = lab.index(name)
        sel = (reg[i] == int(Region.UPPER)) | (reg[i] == int(Region.RIGHT))
        assert sel.any()
        p, k = phi[i, :-1][sel], K[i, :-1][sel]
        assert np.all((p >= w["xlim"][0]) & (p <= w["xlim"][1]) & (k >= w["ylim"][0]) & (k <= w["ylim"][1]))
    np.testing.assert_allclose(fig.axes[2].get_xlim(), w["xlim"])
    # leading curve k_{eps,2} on the negative-eps panels
    for ax, _panel in ((fig.axes[3], "d"), (fig.axes[4], "e")):
        (lead,) = [ln for ln in ax.lines if ln.get_gid() == "leading_curve"]
        assert r"k_{\varepsilon,2}" in lead.get_label()


@pytest.mark.e2e
def test_hov_vs_eps_errorbars_and_theory(runs):
    s = runs["fig_hov_vs_eps"]
    fig = s["figure"]
    assert len(fig.axes) == 2
    ax = fig.axes[0]
    assert ax.get_xlabel() == r"$\varepsilon$" and "HOV" in ax.get_ylabel()
    scene = load_scene(SCENE_DIR / "fig_hov_vs_eps.toml")
    assert len(s["series"]) == len(scene.series)
    measured = [c for c in ax.containers if (c[0].get_gid() or "").startswith("measured:")]
    assert len(measured) == len(scene.series)
    # one theory line per distinct map family (the whole-band series shares the first's)
    theory = [ln for ln in ax.lines if (ln.get_gid() or "").startswith("theory:")]
    assert len(theory) == 3
    for ser, spec, cont in zip(s["series"], scene.series, measured):
        eps = np.array([r["eps"] for r in ser["points"]])
        area = np.array([r["area"] for r in ser["points"]])
        assert list(eps) == list(scene.eps)
        np.testing.assert_allclose(cont[0].get_ydata(), area)
        for r in ser["points"]:
            ms = spec.map_at(r["eps"])
            want = hovering.hovering_area_theory(r["eps"], ms.theta_w, ms.Omega0) if r["eps"] > 0 else 0.0
            assert r["theory"] == pytest.approx(want, rel=1e-12)
            assert r["error"] > 0 or r["area"] == 0
    # thm:hovering at small eps: in the default box the hovering set is empty for eps < 0 and
    # near the leading order for small eps > 0 (loose: this is a quick run)
    first = {r["eps"]: r for r in s["series"][0]["points"]}
    assert first[-0.1]["area"] == 0.0
    assert first[0.05]["area"] == pytest.approx(first[0.05]["theory"], rel=0.25)


def test_zoom_window_rules_on_synthetic_orbits():
    # critical rule: the orbit K = -0.1 cos(phi - 1) dips below 0 on (1 - pi/2, 1 + pi/2)
    phi = np.linspace(-np.pi, np.pi, 20001)[:-1]
    K = -0.1 * np.cos(phi - 1.0)
    orbits = SimpleNamespace(
        phi=phi[None, :],
        K=K[None, :],
        region=np.full((1, phi.size - 1), int(Region.ABOVE)),
        status=np.array([int(Status.OK)]),
        steps_done=np.array([phi.size - 1]),
        labels=["x"],
        kinds=["extra"],
    )
    w = zoom_window_critical(orbits, None, pad=0.1)
    np.testing.assert_allclose(w["xlim"], [1 - np.pi / 2 - 0.1 * np.pi, 1 + np.pi / 2 + 0.1 * np.pi], atol=1e-3)
    np.testing.assert_allclose(w["ylim"], [-0.11, 0.01], atol=1e-8)
    assert w["orbit"] == "x"
    # islands rule: only the J_1 / J_R points count, across the seam phi = +-pi
    reg = np.full((1, 9), int(Region.ABOVE))
    reg[0, [2, 5]] = int(Region.RIGHT)
    p = np.array([[0.0, 0.5, 3.1, 1.0, 2.0, -3.1, 0.3, 0.2, 0.1, 0.0]])
    k = np.array([[-0.5, -0.4, -0.2, -0.9, -0.8, -0.1, -0.3, -0.3, -0.3, -0.3]])
    orbits = SimpleNamespace(
        phi=p, K=k, region=reg, status=np.array([0]), steps_done=np.array([9]), labels=["isl"], kinds=["extra"]
    )
    w = zoom_window_islands(orbits, ["isl"], pad=0.0)
    np.testing.assert_allclose(w["ylim"], [-0.2, -0.1])
    assert w["xlim"] == [pytest.approx(3.1), np.pi]  # the box (3.1, 3.1 + 0.083) is clipped at pi


@pytest.mark.e2e
def test_cli_scene_prints_summary_and_path(tmp_path, capsys):
    from hovering.__main__ import main

    out = tmp_path / "fig.png"
    rc = main(["scene", str(SCENE_DIR / "fig_smalleps.toml"), "--quick", "--out", str(out)])
    text = capsys.readouterr().out
    assert rc == 0 and out.stat().st_size > 0 and out.with_suffix(".npz").exists()
    assert str(out) in text and "[quick]" in text
    assert re.search(r"blue: K0 = -0\.27474, K_min = [-+]\d\.\d+, rho = 3\.77\d\d", text), text


def test_cli_scene_bad_file_is_a_clean_error(tmp_path, capsys):
    from hovering.__main__ import main

    p = tmp_path / "bad.toml"
    p.write_text('kind = "portrait"\noutput = "x.png"\nn_steps = 10\nbogus = 1\n')
    rc = main(["scene", str(p)])
    err = capsys.readouterr().err
    assert rc == 2 and "unknown key(s) 'bogus'" in err and "allowed keys" in err
    assert not (tmp_path / "x.png").exists()


def test_portrait_coloured_by_region(tmp_path):
    import matplotlib.pyplot as plt

    d = _raw("fig_smallepsmany")
    d.update(color_by="region", n_orbits=6, n_steps=5000)
    d["panels"] = d["panels"][:1]
    s = run_scene(parse_scene(d, "region.toml"), out=tmp_path / "r.png", quick=True, keep_figure=True)
    try:
        (ax,) = s["figure"].axes
        labels = {c.get_label() for c in ax.collections}
        # orbits from K0 = -1 to 0.5 visit every region: beside, above, upper wall, right wall
        assert labels == {"J_0u", "J_0", "J_1", "J_R"}
        assert [t.get_text() for t in ax.get_legend().get_texts()] == ["J_0u", "J_0", "J_1", "J_R"]
        assert s["result"].panel("a").orbits.region.shape == (6, 100)  # recorded because they are drawn
    finally:
        plt.close(s["figure"])
    o = scenes.load_result(tmp_path / "r.npz").panel("a").orbits
    assert o.phi.shape == (6, 101) and o.region.shape == (6, 100)


def test_drawn_text_takes_mathtext_that_parses_and_a_literal_dollar():
    # The other side of the check above: matplotlib's own mathtext decides (what it parses here
    # it draws), and text with a lone (or escaped) dollar is plain text to it.
    for title in ("$|HOV|$ against $\\varepsilon$", "costs $5", "price \\$3 and \\$4"):
        d = _raw("fig_hov_vs_eps")
        d["title"] = title
        assert parse_scene(d, SCENE_DIR / "fig_hov_vs_eps.toml").title == title
