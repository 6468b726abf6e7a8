"""Checkpointed sweeps: an interrupted |HOV| sweep loses nothing and resumes without recomputing."""

from __future__ import annotations

import json
import pathlib

import pytest

import hovering
from hovering import pipeline, scenes
from hovering.sweeps import Checkpoint

SCENE = pathlib.Path(__file__).resolve().parents[1] / "examples" / "scenes" / "fig_hov_vs_eps.toml"


def test_checkpoint_roundtrip_and_torn_line(tmp_path):
    path = tmp_path / "c.jsonl"
    c = Checkpoint(path)
    c.put({"eps": 0.1, "n": 3}, {"area": 1.5})
    c.put({"n": 4, "eps": 0.2}, {"area": 2.5})
    with open(path, "a") as f:
        f.write('{"key": {"eps": 0.3}, "row": {"ar')  # an interruption mid-write
    again = Checkpoint(path)
    assert len(again) == 2
    assert again.get({"n": 3, "eps": 0.1}) == {"area": 1.5}  # key order does not matter
    assert again.get({"eps": 0.3}) is None


def test_interrupted_sweep_resumes(tmp_path, monkeypatch):
    scene = scenes.load_scene(SCENE)
    out = tmp_path / "hov.png"
    real = hovering.TruncatedMap.hovering_area
    calls = {"n": 0}

    def flaky(self, *a, **kw):
        calls["n"] += 1
        if calls["n"] == 4:
            raise KeyboardInterrupt
        return real(self, *a, **kw)

    monkeypatch.setattr(hovering.TruncatedMap, "hovering_area", flaky)
    with pytest.raises(KeyboardInterrupt):
        pipeline.run_scene(scene, out=out, quick=True)
    ckpt = out.with_suffix(".sweep.jsonl")
    assert len(ckpt.read_text().splitlines()) == 3  # the three finished points are on disk

    calls["n"] = 100  # no more interruptions; count the resumed run's measurements
    summary = pipeline.run_scene(scene, out=out, quick=True)
    total = sum(len(s["points"]) for s in summary["series"])
    assert summary["points_reused"] == 3 and calls["n"] - 100 == total - 3
    # Same numbers as a run that was never interrupted.
    monkeypatch.setattr(hovering.TruncatedMap, "hovering_area", real)
    fresh = pipeline.run_scene(scene, out=tmp_path / "fresh.png", quick=True)
    assert json.dumps(fresh["series"], sort_keys=True) == json.dumps(summary["series"], sort_keys=True)
