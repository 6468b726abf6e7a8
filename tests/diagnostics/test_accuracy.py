"""Work-precision as a feature: hovering.work_precision, accuracy targets, python -m hovering accuracy.

The references are independent of the measured settings: at eps = 0 on the wall system the return
has a closed form (the angle advance omega2(H2) * 2 arccos(qw1 / A1) after a reflection), which the
reference must match; long-orbit errors must grow as m^2 (a drifting action's frequency error
accumulating in the phase), not as m; and an accuracy target must hold on points it was not
chosen on.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import hovering
from hovering import FlowMap, Section, paper
from hovering.diagnostics import accurate_flow_map, choose_setting
from hovering.diagnostics.work_precision import _reference_run
from hovering.paper import V2, system

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def wp_step():
    return hovering.work_precision(
        Section(system(0.05), 1.0),
        tolerances=(1e-6, 1e-9, 1e-12),
        steppers=("rk8pd", "rkck"),
        n_points=16,
        returns=(1, 100),
        repeat=1,
    )


def test_reference_of_the_wall_system_matches_the_closed_form():
    sec = Section(system(0.0, "wall"), 1.0)
    rng = np.random.default_rng(3)
    th, I = rng.uniform(-np.pi, np.pi, 30), rng.uniform(0.05, 0.3, 30)
    ref, info = _reference_run(sec, th, I, 1)
    h1 = 1.0 - np.array([V2.energy(i) for i in I])
    A1 = np.sqrt(2 * h1)
    T = np.where(A1 > 1.0, 2 * np.arccos(-1.0 / np.maximum(A1, 1.0)), 2 * np.pi)
    W = np.array([V2.frequency(V2.energy(i)) for i in I])
    ok = ref.status == 0
    err = np.abs(hovering.wrap(ref.theta[ok] - th[ok] - W[ok] * T[ok]))
    # the reference's own error (estimated, or 0 for the exact flow) and what it reaches: 1e-12
    assert err.max() < 1e-12
    assert info["error"] < 1e-12


def test_table_rows_and_error_ladder(wp_step):
    rows = wp_step.table
    assert len(rows) == 6 and {r["method"] for r in rows} == {"rk8pd", "rkck"}
    for r in rows:
        assert set(r) >= {"method", "tolerance", "error", "seconds", "unit"} and r["unit"] == "return"
        assert r["seconds"] > 0 and r["failed"] == 0
        # a step control at rtol tol keeps one return within ~10 tol on these O(1) variables
        # (measured: 0.4 - 3.5 tol); 100 tol leaves room for other points and machines
        assert r["error"] < 100 * r["tolerance"]
    tol, err, sec = wp_step.curve("rk8pd")
    assert np.all(np.diff(err) < 0)  # tighter tolerance, smaller error
    steps = [r["steps"] for r in rows if r["method"] == "rk8pd"]
    assert np.all(np.diff(steps) > 0)  # and it takes more steps per return (times are never asserted)


def test_long_orbit_errors_grow_as_m_squared(wp_step):
    # error after 100 returns / after 1: m^2 = 1e4 (measured 7.7e3 - 7.9e3); a linear growth would
    # give 1e2: the bounds [1e3, 1e5] tell the two apart with a margin of 10 either way
    for r in wp_step.table:
        if r["tolerance"] <= 1e-9:
            ratio = r["error_after"][100] / r["error_after"][1]
            assert 1e3 < ratio < 1e5, r
            assert 1e3 < r["reversal_after"][100] / r["reversal_after"][1] < 1e6, r


def test_fastest_and_format(wp_step):
    best = wp_step.fastest(1e-8)
    assert best is not None and best["error"] <= 1e-8
    assert all(r["seconds"] >= best["seconds"] for r in wp_step.table if r["error"] <= 1e-8)
    assert wp_step.fastest(1e-20) is None
    text = wp_step.format()
    assert "| rk8pd |" in text and "reference:" in text
    assert json.loads(json.dumps(wp_step.to_dict()))["rows"][0]["method"] == "rk8pd"


def test_plot_has_one_curve_per_method_and_the_long_orbit_panel(wp_step):
    import matplotlib

    matplotlib.use("Agg")
    fig = wp_step.plot()
    gids = {a.get_gid() for ax in fig.axes for a in ax.lines}
    assert {"method:rk8pd", "method:rkck", "long:rk8pd", "reversal:rk8pd"} <= gids
    line = next(a for a in fig.axes[0].lines if a.get_gid() == "method:rk8pd")
    np.testing.assert_allclose(line.get_xdata(), wp_step.curve("rk8pd")[2])


@pytest.mark.parametrize("accuracy", [1e-6, 1e-9, 1e-12])
def test_accuracy_target_holds_on_fresh_points(accuracy):
    sec = Section(system(0.05), 1.0)
    fm = accurate_flow_map(system(0.05), 1.0, accuracy, coordinates="section")
    opts = fm.integrator_options
    assert fm.accuracy_choice["error"] <= accuracy and fm.accuracy_choice["seconds"] > 0
    # the choice, run on 200 points it was not measured on, against the rk8pd 1e-14 reference;
    # 10x margin: the choice was measured on 16 points, and the worst of 200 may sit a bit higher
    rng = np.random.default_rng(11)
    th, I = rng.uniform(-np.pi, np.pi, 200), rng.uniform(0.1, 0.5, 200)
    ref = sec.return_map(th, I, rtol=1e-14, atol=1e-14)
    got = sec.return_map(th, I, **{k: opts[k] for k in ("stepper", "rtol", "atol")})
    ok = (ref.status == 0) & (got.status == 0)
    err = np.maximum(np.abs(hovering.wrap(got.theta - ref.theta)), np.abs(got.I - ref.I))[ok]
    assert err.max() <= 10 * accuracy


def test_looser_targets_never_cost_more():
    # On one measurement a looser target admits every row a tighter one does, so the row chosen for
    # it costs no more and is within its target. (Separate choose_setting calls would compare two
    # timings of nearly the same cost: taylor's order follows the tolerance, so its time per
    # return is nearly flat over rtol, and a loaded box once chose rtol 1e-14 for a 1e-5 target.)
    wp = hovering.work_precision(
        Section(system(0.05), 1.0),
        tolerances=[10.0**-k for k in range(3, 15)],
        steppers=["taylor", "rk8pd"],
        n_points=16,
        returns=[1],
    )
    picks = [wp.fastest(a) for a in (1e-5, 1e-8, 1e-11)]
    assert all(p is not None for p in picks)
    assert picks[0]["seconds"] <= picks[1]["seconds"] <= picks[2]["seconds"]
    for a, p in zip((1e-5, 1e-8, 1e-11), picks):
        assert p["error"] <= a
    # choose_setting takes the same rule: its pick is within the target.
    assert choose_setting(Section(system(0.05), 1.0), 1e-8)["error"] <= 1e-8


def test_unreachable_target_names_the_best_reachable():
    # The best error measured and its setting (method and tolerance).
    with pytest.raises(ValueError, match=r"not reached.*best measured is [\d.e+-]+ \(\w+ at [\d.e+-]+;"):
        accurate_flow_map(system(0.05), 1.0, 1e-17, coordinates="section")
    with pytest.raises(ValueError, match="accuracy"):
        accurate_flow_map(system(0.05), 1.0, 2.0, coordinates="section")
    with pytest.raises(ValueError, match=r"accuracy picks the stepper and tolerances itself; remove \['rtol'\]"):
        accurate_flow_map(system(0.05), 1.0, 1e-9, rtol=1e-8)


def test_the_old_form_warns_and_gives_the_builders_map():
    # FlowMap(accuracy=) is deprecated: the target is resolved above the models, by the builder;
    # the old form still measures the same setting (found by name through hovering._deprecated).
    new = accurate_flow_map(system(0.0), 1.0, 1e-9, coordinates="section")
    with pytest.warns(DeprecationWarning, match=r"FlowMap\(accuracy=\.\.\.\) is deprecated .*accurate_flow_map"):
        old = FlowMap(system(0.0), 1.0, coordinates="section", accuracy=1e-9)
    assert old.integrator_options == new.integrator_options and old.accuracy_choice["method"] == "exact"
    np.testing.assert_array_equal(old.step(0.3, 0.2), new.step(0.3, 0.2))


def test_scene_accuracy_key(tmp_path):
    from hovering.scenes import load_scene
    from hovering.scenes.compute import scene_map

    text = (ROOT / "examples/scenes/flow_portrait.toml").read_text()
    assert "[integrator]" in text
    head, tail = text.split("[integrator]", 1)
    rest = tail.split("\n[", 1)
    scene_text = head + "[integrator]\naccuracy = 1e-8\n" + ("\n[" + rest[1] if len(rest) > 1 else "")
    p = tmp_path / "s.toml"
    p.write_text(scene_text)
    sc = load_scene(p, check_output=False)
    assert sc.integrator.accuracy == 1e-8
    fm = scene_map(sc)
    assert fm.accuracy_choice["error"] <= 1e-8
    p.write_text(head + "[integrator]\naccuracy = 1e-8\nrtol = 1e-9\n" + ("\n[" + rest[1] if len(rest) > 1 else ""))
    with pytest.raises(ValueError, match="accuracy"):
        load_scene(p, check_output=False)


def test_truncated_rotation_diagram():
    m = paper.truncated_map(0.05)
    wp = hovering.work_precision(m, tolerances=(1000, 10_000), n_points=3, repeat=1)
    rows = {(r["method"], r["tolerance"]): r["error"] for r in wp.table}
    # the plain mean converges as 1/n (10x per decade, within 3x), the weighted Birkhoff average
    # super-polynomially on these invariant circles above the tangency
    ratio = rows[("mean, sin_ulp=1", 1000)] / rows[("mean, sin_ulp=1", 10_000)]
    assert 3 < ratio < 30
    assert rows[("birkhoff, sin_ulp=1", 10_000)] < 1e-10
    assert wp.reference["error"] < 1e-12


def test_bad_arguments_are_named():
    sec = Section(system(), 1.0)
    with pytest.raises(ValueError, match="stepper"):
        hovering.work_precision(sec, steppers=("rk9",))
    with pytest.raises(ValueError, match="tolerance"):
        hovering.work_precision(sec, tolerances=(0.0,))
    with pytest.raises(ValueError, match="quantity"):
        hovering.work_precision(sec, quantity="volume")
    with pytest.raises(ValueError, match="target"):
        hovering.work_precision(object())
    with pytest.raises(ValueError, match="sin_ulp"):
        hovering.work_precision(
            hovering.TruncatedMap(eps=0.1, Omega0=2.0, theta_w=2.0, tau0=1.0, tau1=0.5, lam=0.5), steppers=(2.0,)
        )


@pytest.mark.e2e
def test_cli_accuracy_writes_the_diagram_and_table(tmp_path):
    out = tmp_path / "acc.png"
    p = subprocess.run(
        [
            sys.executable,
            "-m",
            "hovering",
            "accuracy",
            str(ROOT / "examples/scenes/flow_portrait.toml"),
            "--quick",
            "--out",
            str(out),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert p.returncode == 0, p.stderr
    assert out.stat().st_size > 10_000
    table = json.loads(out.with_suffix(".json").read_text())
    assert table["kind"] == "flow"
    assert len([r for r in table["rows"] if r["method"] in ("taylor", "rk8pd")]) == 6  # quick: the two fastest
    assert len([r for r in table["rows"] if r["method"] == "scipy DOP853"]) == 3  # scipy is in the test extras
    assert "| rk8pd |" in p.stdout
    bad = subprocess.run(
        [sys.executable, "-m", "hovering", "accuracy", str(tmp_path / "missing.toml")],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert bad.returncode == 2 and bad.stderr.startswith("error:")


def test_scipy_curve_is_an_independent_implementation_that_agrees():
    # scipy's solve_ivp (DOP853 + events, the field in Python) on the step system at eps = 0: on
    # orbits whose impacts are not near-grazing it must agree with the exact flow to its tolerance
    # (1e-10 asked; 1e-7 allows DOP853's global error over a return and its event location).
    # The points are far from every hard case by construction: I = 0.2 keeps q1's turning point
    # 0.19 beyond qw1 (no grazing), and every wall-line crossing of these 12 orbits is >= 0.016 from
    # the corner (measured with DOP853 at rtol 1e-13), so no verdict may hang on the last bit of a
    # start: each start and its neighbours up to 4 ulps away must give the same answer. (It used to: the
    # reference skipped p1 events whose p1 was exactly 0.0 at the root, which scipy returns on some
    # machines; the section crossing was then missed and the next return taken, 1.4 rad away.)
    from hovering.diagnostics import scipy_return_map

    sec = Section(system(0.0, "step"), 1.0)
    th, I = np.linspace(-3.0, 3.0, 12), np.full(12, 0.2)
    ex = sec.return_map(th, I, stepper="exact")
    ok = ex.status == 0
    assert ok.sum() >= 10
    z0 = sec.point(th, I)
    rng = np.random.default_rng(1)
    for trial in range(9):  # the starts, then 8 times each component moved by up to 4 ulps
        z = z0 * (1.0 + (trial > 0) * rng.integers(-4, 5, z0.shape) * 2.0**-52)
        out = [scipy_return_map(sec.sys, zi, 1e-10) for zi in z]
        missing = [i for i in np.flatnonzero(ok) if out[i] is None]
        assert not missing, [ex.itinerary[i] for i in missing]
        c = sec.coordinates(np.array([np.full(4, np.nan) if o is None else o for o in out]))
        assert np.max(np.abs(hovering.wrap(c[ok, 0] - ex.theta[ok]))) < 1e-7
        assert np.max(np.abs(c[ok, 1] - ex.I[ok])) < 1e-7
    wp = hovering.work_precision(
        sec, tolerances=(1e-8,), steppers=("rk8pd",), n_points=8, returns=(1,), external=("scipy",), repeat=1
    )
    assert [r["method"] for r in wp.table] == ["rk8pd", "scipy DOP853"]
    with pytest.raises(ValueError, match="external"):
        hovering.work_precision(sec, external=("julia",))


def test_hovering_area_diagram_against_its_largest_setting():
    # The largest (samples, n_steps) is the reference; each smaller setting's |area - reference|
    # must lie within 4x the two stated error bars combined (each bar is ~2 sigma of the
    # stratified sampling plus the iteration-count part: a 4x margin keeps this from flaking)
    m = paper.truncated_map(0.3)
    wp = hovering.work_precision(
        m, quantity="hovering_area", tolerances=[(400, 250), (1600, 500), (6400, 1000)], repeat=1
    )
    assert wp.kind == "hovering_area" and [r["tolerance"] for r in wp.table] == ["400x250", "1600x500"]
    for r in wp.table:
        assert r["error"] <= 4 * (r["stated_error"] + wp.reference["error"]), r
        assert r["seconds"] > 0 and r["unit"] == "call"
    with pytest.raises(ValueError, match="at least two"):
        hovering.work_precision(m, quantity="hovering_area", tolerances=[(400, 250)])


def test_the_target_is_measured_with_the_maps_own_event_options():
    # The setting is measured as the map will run: with max_steps = 5 no return of system(0.05)
    # completes (13 to 157 steps measured over the ladder's steppers and tolerances), so no setting reaches
    # the target and the builder says so, instead of measuring at the default max_steps and
    # returning a map whose every return is a StepLimit. Options reach the chosen row too.
    with pytest.raises(ValueError, match=r"not reached"):
        accurate_flow_map(system(0.05), 1.0, 1e-6, coordinates="section", max_steps=5)
    fm = accurate_flow_map(system(0.05), 1.0, 1e-6, coordinates="section", verify_steps=0, grazing_tol=1e-11)
    assert fm.accuracy_choice["options"]["verify_steps"] == 0
    assert fm.accuracy_choice["options"]["grazing_tol"] == 1e-11
    assert fm.integrator_options["verify_steps"] == 0
    with pytest.raises(ValueError, match=r"max_steps"):
        choose_setting(Section(system(0.05), 1.0), 1e-6, options={"max_steps": 0})
    with pytest.raises(ValueError, match=r"unknown option.*'stepper'"):
        choose_setting(Section(system(0.05), 1.0), 1e-6, options={"stepper": "rk8pd"})
