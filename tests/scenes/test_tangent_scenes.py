"""The tangent-dynamics scene kinds (ftle_field, periodic_manifolds, residue_vs_eps): their example
files load, run quickly, report, save and redraw, on the flow and on its model; their own keys'
errors name the key and what is allowed."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

import hovering as hv
from hovering.pipeline import redraw, run_scene
from hovering.scenes import load_scene, parse_scene

SCENE_DIR = Path(__file__).resolve().parents[2] / "examples" / "scenes"
TANGENT = ("ftle_field", "periodic_manifolds", "residue_vs_eps")


def _raw(name):
    with open(SCENE_DIR / f"{name}.toml", "rb") as f:
        return tomllib.load(f)


@pytest.mark.slow
@pytest.mark.parametrize("name", TANGENT)
def test_each_example_runs_quickly_saves_and_redraws(name, tmp_path):
    out = tmp_path / f"{name}.png"
    summary = run_scene(load_scene(SCENE_DIR / f"{name}.toml"), quick=True, out=out, keep_figure=True)
    result = summary["result"]
    assert out.exists() and out.with_suffix(".npz").exists()
    again = tmp_path / "again.png"
    redraw(out.with_suffix(".npz"), out=again)
    assert again.exists()
    if name == "ftle_field":
        assert [f.direction for f in result.fields] == ["forward", "backward"]
        assert np.nanmin(result.fields[0].ftle) > 0
    elif name == "periodic_manifolds":
        kinds = {o.stability for o in result.orbits}
        assert {"elliptic", "hyperbolic"} <= kinds and len(result.manifolds) >= 2
        assert result.owner.size == len(result.manifolds)
    else:
        assert result.start.converged and result.branch.parameter.size >= 5
        assert np.all(np.diff(result.branch.residue[:5]) > 0)


def test_the_model_runs_the_same_scene():
    d = _raw("periodic_manifolds")
    d.update(map="first_mode", manifold_length=0.0, n_orbits=0, n_seeds=0, n_line=12)
    scene = parse_scene(d, SCENE_DIR / "periodic_manifolds.toml")
    from hovering.scenes import compute as scene_compute

    result = scene_compute(scene, quick=True)
    assert result.orbits and all(o.converged for o in result.orbits)
    assert isinstance(result.scene, hv.scenes.spec.PeriodicManifoldsScene)


@pytest.mark.parametrize(
    "name,key,value,match",
    [
        ("ftle_field", "map", "exact", "map = 'exact' is not allowed; allowed: 'flow', 'measured', 'first_mode'"),
        ("ftle_field", "n_phi", 1, "n_phi = 1 is out of range"),
        ("ftle_field", "direction", "sideways", "direction = 'sideways' is not allowed"),
        ("periodic_manifolds", "period", 0, "period = 0 is out of range"),
        ("periodic_manifolds", "K_range", [0.1, -0.1], "K_range"),
        ("residue_vs_eps", "n_steps", 0, "n_steps = 0 is out of range"),
    ],
)
def test_bad_keys_are_named(name, key, value, match):
    d = _raw(name)
    d[key] = value
    with pytest.raises(ValueError, match=match.replace("(", r"\(").replace(")", r"\)")):
        parse_scene(d, SCENE_DIR / f"{name}.toml")


def test_the_examples_load():
    for name in TANGENT:
        s = load_scene(SCENE_DIR / f"{name}.toml")
        assert s.kind == name and s.map == "flow"
