"""Resolved sweep plans: `python -m hovering plan` writes them, `hovering_sweep --plan` runs them,
and `python -m hovering scene` on the same scene gives the same rows bit for bit (both models:
the truncated map and the flow with its truncated models), because both programs call the same
core functions on the same numbers. The two programs share one checkpoint format: a sweep begun
by either is finished by the other, without recomputing or duplicating a point."""

from __future__ import annotations

import dataclasses
import json
import math
import re
import subprocess
import tomllib
from pathlib import Path

import pytest

import hovering
from hovering.parallel.checkpoint import Checkpoint, canonical
from hovering.scenes import load_scene
from hovering.scenes.compute import compute, run_point
from hovering.scenes.plan import FORMAT, VERSION, plan_points, plan_text, point_key, sweep_counts, write_plan

ROOT = Path(__file__).resolve().parents[2]
TRUNC = ROOT / "examples" / "scenes" / "fig_hov_vs_eps.toml"
FLOW = ROOT / "examples" / "scenes" / "flow_hov_vs_eps.toml"


def flow_scene():
    """The flow sweep at two eps, one of each sign (one hovers, one does not), with both models."""
    return dataclasses.replace(load_scene(FLOW, check_output=False), eps=(-0.1, 0.2))


def run_exe(exe, plan: Path, out: Path, *extra) -> subprocess.CompletedProcess:
    r = subprocess.run(
        [exe, "--plan", str(plan), "--out", str(out), *extra], capture_output=True, text=True, timeout=600
    )
    assert r.returncode == 0, r.stderr
    return r


def rows_by_key(path: Path) -> dict:
    """canonical key -> row of a checkpoint, without the timing (the one field that may differ)."""
    c = Checkpoint(path)
    return {k: {f: v for f, v in c.get(json.loads(k)).items() if f != "seconds"} for k in c._rows}


def same(a, b) -> bool:
    """Rows equal field by field, floats bit for bit (NaN equal to NaN)."""
    if isinstance(a, dict):
        return isinstance(b, dict) and a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, float) and isinstance(b, float):
        return a == b or (math.isnan(a) and math.isnan(b))
    return type(a) is type(b) and a == b


@pytest.mark.parametrize("which", ["truncated", "flow"])
def test_executable_rows_are_the_python_scenes_bit_for_bit(which, sweep_exe, tmp_path):
    scene = load_scene(TRUNC, check_output=False) if which == "truncated" else flow_scene()
    plan = tmp_path / "p.toml"
    write_plan(scene, plan, quick=True)
    run_exe(sweep_exe, plan, tmp_path / "exe.jsonl")
    compute(scene, quick=True, checkpoint=tmp_path / "py.jsonl")
    exe, py = rows_by_key(tmp_path / "exe.jsonl"), rows_by_key(tmp_path / "py.jsonl")
    n = 44 if which == "truncated" else 2
    assert len(exe) == len(py) == n and exe.keys() == py.keys()  # keys written by each program match
    for k in py:
        assert same(exe[k], py[k]), (k, exe[k], py[k])
    if which == "flow":
        # Not a comparison of zeros: the hovering sign has area > 0 and both models measured, with
        # their verdicts compared where they sample the flow's box.
        rows = list(py.values())
        assert max(r["area"] for r in rows) > 0.05
        assert all(set(r["models"]) == {"onset", "measured"} for r in rows)
        assert any(0.5 < r["models"]["onset"]["agree"] <= 1 for r in rows)


def test_a_sweep_begun_by_the_executable_is_finished_by_python(sweep_exe, tmp_path):
    scene = load_scene(TRUNC, check_output=False)
    points = plan_points(scene, quick=True)
    plan = tmp_path / "half.toml"
    plan.write_text(plan_text(scene, True, points=points[:17]))  # the first 17 of 44 points
    ck = tmp_path / "c.jsonl"
    run_exe(sweep_exe, plan, ck)
    res = compute(scene, quick=True, checkpoint=ck)
    assert res.meta["points_reused"] == 17
    lines = ck.read_text().splitlines()
    assert sum(line.startswith('{"key":') for line in lines) == 44
    assert lines[0] == '{"format":"hovering-checkpoint","version":1}'
    programs = [json.loads(x)["provenance"]["program"] for x in lines if x.startswith('{"provenance":')]
    assert programs == ["hovering_sweep", "python"]
    fresh = compute(scene, quick=True, checkpoint=tmp_path / "fresh.jsonl")
    for a, b in zip(res.series, fresh.series):
        for f in ("eps", "area", "error", "theory", "K_low", "floor_touched"):
            assert (getattr(a, f) == getattr(b, f)).all(), f


def test_a_sweep_begun_by_python_is_finished_by_the_executable(sweep_exe, tmp_path):
    scene = load_scene(TRUNC, check_output=False)
    ck = tmp_path / "c.jsonl"
    # Python measures the scene at three of its eps: those points are points of the whole scene.
    part = dataclasses.replace(scene, eps=scene.eps[:3])
    compute(part, quick=True, checkpoint=ck)
    plan = tmp_path / "p.toml"
    write_plan(scene, plan, quick=True)
    r = run_exe(sweep_exe, plan, ck)
    assert "44 points, 12 already in" in r.stderr  # 4 series x 3 eps
    assert sum(line.startswith('{"key":') for line in ck.read_text().splitlines()) == 44
    run_exe(sweep_exe, plan, tmp_path / "alone.jsonl")
    assert rows_by_key(ck) == rows_by_key(tmp_path / "alone.jsonl")


def test_the_plan_file_holds_the_points_python_runs(tmp_path):
    scene = flow_scene()
    plan = tmp_path / "p.toml"
    write_plan(scene, plan, quick=True)
    data = tomllib.loads(plan.read_text())
    pts = plan_points(scene, quick=True)
    assert data["format"] == FORMAT and data["version"] == VERSION and data["kind"] == "flow_hovering_area"
    # Every number is written so that it reads back as the same double (repr; TOML's inf).
    assert data["points"] == pts
    n, samples = sweep_counts(scene, quick=True)
    assert [p["n_steps"] for p in pts] == [n, n] and samples == max(scene.samples // 50, 100)
    # The default checkpoint is the scene run's own, seen from the plan's folder.
    assert Path(tmp_path / data["checkpoint"]).resolve() == (Path.cwd() / scene.output.with_suffix(".sweep.jsonl"))
    # The key holds every parameter: a different box, seed or model table is another point.
    k = point_key("flow_hovering_area", pts[0])
    assert "theory" not in k and "b1" not in k and k["kind"] == "flow_hovering_area"
    for change in (dict(K_low=pts[0]["K_low"] * 0.5), dict(seed=1)):
        assert point_key("flow_hovering_area", {**pts[0], **change}) != k
    models = [dict(pts[0]["models"][0], K=[x * 1.001 for x in pts[0]["models"][0]["K"]])] + pts[0]["models"][1:]
    assert point_key("flow_hovering_area", {**pts[0], "models": models}) != k


def test_the_hand_written_plan_of_the_docs_runs(sweep_exe, tmp_path):
    # docs/sweep-plan.md's example: read by the executable, and the same rows as Python's run of
    # the same points (the docs' K_low is hovering_area's default box for eps = 0.1, written out).
    text = (ROOT / "docs" / "sweep-plan.md").read_text()
    toml = re.search(r"```toml\n(.*?)```", text, re.S).group(1)
    plan = tmp_path / "hand.toml"
    plan.write_text(toml)
    data = tomllib.loads(toml)
    r = run_exe(sweep_exe, plan, tmp_path / "hand.jsonl")
    assert "2 points, 0 already in" in r.stderr

    m = hovering.TruncatedMap(**data["points"][0]["map"])
    assert -hovering.hovering_area(m, n_steps=4, n_samples=1).box[2] == -data["points"][0]["K_low"]
    exe = rows_by_key(tmp_path / "hand.jsonl")
    for p in data["points"]:
        p = {**p, "theory": p.get("theory", math.nan)}
        row = {f: v for f, v in run_point("hovering_area", p).items() if f != "seconds"}
        key = canonical(point_key("hovering_area", p))
        assert same(exe[key], row), (exe[key], row)


def test_plan_command(tmp_path, capsys, monkeypatch):
    from hovering.cli import main

    monkeypatch.chdir(tmp_path)
    assert main(["plan", str(TRUNC), "--quick"]) == 0
    out = capsys.readouterr().out
    assert "wrote fig_hov_vs_eps.plan.toml (hovering_area, 44 points)" in out
    assert "hovering_sweep --plan fig_hov_vs_eps.plan.toml" in out
    assert len(tomllib.loads((tmp_path / "fig_hov_vs_eps.plan.toml").read_text())["points"]) == 44
    # Not a sweep scene, a bad output name, another program's file in the way: one error line, exit 2.
    assert main(["plan", str(ROOT / "examples" / "scenes" / "fig_smalleps.toml")]) == 2
    assert "a plan is made of the sweep kinds 'hovering_area' and 'flow_hovering_area'" in capsys.readouterr().err
    assert main(["plan", str(TRUNC), "-o", "p.txt"]) == 2
    assert "a plan is a TOML file" in capsys.readouterr().err
    (tmp_path / "mine.toml").write_text("x = 1\n")
    assert main(["plan", str(TRUNC), "-o", "mine.toml"]) == 2
    assert (
        "was not written by hovering" in capsys.readouterr().err and (tmp_path / "mine.toml").read_text() == "x = 1\n"
    )
    # A plan hovering wrote is replaced (a new plan of the full counts).
    assert main(["plan", str(TRUNC), "-o", "fig_hov_vs_eps.plan.toml"]) == 0
    assert tomllib.loads((tmp_path / "fig_hov_vs_eps.plan.toml").read_text())["points"][0]["n_steps"] == 20000


def test_a_flow_scenes_integrator_options_reach_both_programs(sweep_exe, tmp_path):
    # Every FlowOptions field a scene's [integrator] sets is written into the plan and the point's
    # key, and both programs integrate with it: with corner_tol = 0.05 (and max_impacts = 1,
    # verify_steps = 0), orbits that pass within 0.05 of the corner stop there, the rows
    # differ from the default options' (the options act), and the executable's rows are still
    # Python's bit for bit under keys both programs agree on.
    base = flow_scene()
    ig = dataclasses.replace(base.integrator, max_impacts=1, verify_steps=0, corner_tol=0.05)
    scene = dataclasses.replace(base, integrator=ig)
    plan = tmp_path / "p.toml"
    write_plan(scene, plan, quick=True)
    for p in tomllib.loads(plan.read_text())["points"]:
        assert p["integrator"] == {**ig.events(), "stepper": "taylor", "rtol": ig.rtol, "atol": ig.atol}
    run_exe(sweep_exe, plan, tmp_path / "exe.jsonl")
    compute(scene, quick=True, checkpoint=tmp_path / "py.jsonl")
    compute(base, quick=True, checkpoint=tmp_path / "default.jsonl")
    exe, py, default = (rows_by_key(tmp_path / f"{n}.jsonl") for n in ("exe", "py", "default"))
    assert len(py) == 2 and exe.keys() == py.keys() and not (py.keys() & default.keys())
    for k in py:
        assert same(exe[k], py[k]), (k, exe[k], py[k])
    assert not same(sorted(py.values(), key=str), sorted(default.values(), key=str))


def test_a_plans_integrator_has_the_readers_types_whatever_a_spec_holds(tmp_path):
    # A spec built in code may hold an int tolerance or NumPy scalars; the plan (and so both
    # programs' checkpoint keys) holds floats for tolerances and ints for counts, as TOML the C++
    # reader takes (an int 0 became the key's 0 in Python and 0.0 in the executable).
    import numpy as np

    base = flow_scene()
    ig = dataclasses.replace(base.integrator, corner_tol=0, max_impacts=np.int64(3), event_tol=np.float64(1e-14))
    plan = tmp_path / "p.toml"
    write_plan(dataclasses.replace(base, integrator=ig), plan, quick=True)
    it = tomllib.loads(plan.read_text())["points"][0]["integrator"]
    assert (it["corner_tol"], it["max_impacts"], it["event_tol"]) == (0.0, 3, 1e-14)
    assert [type(it[k]) for k in ("corner_tol", "max_impacts", "event_tol")] == [float, int, float]
