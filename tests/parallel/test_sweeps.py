"""Checkpointed sweeps: an interrupted |HOV| sweep loses nothing and resumes without recomputing;
the checkpoint file's format (hovering.parallel.checkpoint, shared with hovering_sweep)."""

from __future__ import annotations

import json
import pathlib

import pytest

import hovering
from hovering import pipeline, scenes
from hovering.parallel.checkpoint import Checkpoint, canonical

SCENE = pathlib.Path(__file__).resolve().parents[2] / "examples" / "scenes" / "fig_hov_vs_eps.toml"


def test_checkpoint_roundtrip_and_torn_line(tmp_path):
    path = tmp_path / "c.jsonl"
    c = Checkpoint(path)
    assert c.put({"eps": 0.1, "n": 3}, {"area": 1.5, "agree": float("nan"), "top": float("-inf")})
    assert c.put({"n": 4, "eps": 0.2}, {"area": 2.5})
    assert not c.put({"eps": 0.2, "n": 4}, {"area": 9.9})  # a point is written once
    lines = path.read_text().splitlines()
    assert (
        lines[0] == '{"format":"hovering-checkpoint","version":1}'
        and json.loads(lines[1])["provenance"]["program"] == "python"
    )
    # Non-finite numbers are strings in the file (JSON has none) and floats again when read.
    assert '"agree":"NaN"' in lines[2] and '"top":"-Infinity"' in lines[2] and len(lines) == 4
    with open(path, "a") as f:
        f.write('{"key": {"eps": 0.3}, "row": {"ar')  # an interruption mid-write
    again = Checkpoint(path)
    assert len(again) == 2 and again.dropped == 1 and path.read_text().endswith("}\n")
    row = again.get({"n": 3, "eps": 0.1})  # key order does not matter
    assert row["area"] == 1.5 and row["agree"] != row["agree"] and row["top"] == float("-inf")
    assert again.get({"eps": 0.3}) is None
    # Keys are compared as values: another program's spelling of the same numbers is the same key.
    with open(path, "a") as f:
        f.write('{"row": {"area": 3.5}, "key": {"n": 5, "eps": 1e-1}}\n')
    assert Checkpoint(path).get({"eps": 0.1, "n": 5}) == {"area": 3.5}
    assert canonical({"b": [1.0, float("inf")], "a": 1}) == '{"a":1,"b":[1.0,"Infinity"]}'


@pytest.mark.parametrize(
    "text, where",
    [
        (
            '{"format":"hovering-checkpoint","version":1}\n{"key":{},"row":{}}\nnot json\n{"key":{"a":1},"row":{}}\n',
            "line 3",
        ),
        ('{"format":"hovering-checkpoint","version":1}\n{"key":{"a":NaN},"row":{}}\n', "line 2"),
        ('{"format":"hovering-checkpoint","version":1}\n{"key":{},"row":{},"more":1}\n', "line 2"),
        ('{"format":"hovering-checkpoint","version":2}\n', "line 1: a checkpoint of version 2"),
        (
            '{"key": {"eps": 0.1}, "provenance": {}, "row": {"area": 1.0}}\n',
            "line 1: a checkpoint of an older hovering",
        ),
        ("area,error\n1,2\n", "line 1: not a line of JSON"),
    ],
)
def test_damaged_or_foreign_checkpoints_are_refused_untouched(text, where, tmp_path):
    path = tmp_path / "c.jsonl"
    path.write_text(text)
    with pytest.raises(ValueError, match=rf"c\.jsonl {where}"):
        Checkpoint(path)
    assert path.read_text() == text


def test_two_writers_never_duplicate_a_point(tmp_path):
    path = tmp_path / "c.jsonl"
    a, b = Checkpoint(path), Checkpoint(path)
    assert a.put({"eps": 0.1}, {"area": 1.0})
    # b opened before a wrote: its put reads a's line first (under the lock) and writes nothing.
    assert {"eps": 0.1} not in b and not b.put({"eps": 0.1}, {"area": 2.0})
    assert {"eps": 0.1} in b and b.get({"eps": 0.1}) == {"area": 1.0}
    assert b.put({"eps": 0.2}, {"area": 3.0})
    a.refresh()
    assert a.get({"eps": 0.2}) == {"area": 3.0}
    points = [x for x in path.read_text().splitlines() if x.startswith('{"key":')]
    assert len(points) == 2 and path.read_text().count('"format"') == 1


@pytest.mark.e2e
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
    points = [x for x in ckpt.read_text().splitlines() if x.startswith('{"key":')]
    assert len(points) == 3  # the three finished points are on disk

    calls["n"] = 100  # no more interruptions; count the resumed run's measurements
    summary = pipeline.run_scene(scene, out=out, quick=True)
    total = sum(len(s["points"]) for s in summary["series"])
    assert summary["points_reused"] == 3 and calls["n"] - 100 == total - 3
    # Same numbers as a run that was never interrupted.
    monkeypatch.setattr(hovering.TruncatedMap, "hovering_area", real)
    fresh = pipeline.run_scene(scene, out=tmp_path / "fresh.png", quick=True)
    assert json.dumps(fresh["series"], sort_keys=True) == json.dumps(summary["series"], sort_keys=True)
