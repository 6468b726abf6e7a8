"""Checkpointed sweeps: an interrupted |HOV| sweep loses nothing and resumes without recomputing;
the checkpoint file's format (hovering.parallel.checkpoint, shared with hovering_sweep)."""

from __future__ import annotations

import json
import pathlib
import re

import pytest

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


HEAD = b'{"format":"hovering-checkpoint","version":1}\n'


@pytest.mark.parametrize(
    "line, message",
    [
        # Before: read as Infinity (a key equal to {"x": "Infinity"}, a row's area -inf), silently.
        (b'{"key":{"x":1e999},"row":{}}', r"line 3: key\.x: a number beyond the range of a double \(it reads as inf\)"),
        (
            b'{"key":{"x":1},"row":{"area":-1e999}}',
            r"line 3: row\.area: a number beyond the range of a double \(it reads as -inf\)",
        ),
        # Before: accepted (hovering_sweep read it as another number).
        (
            b'{"key":{"n":123456789012345678901234567890},"row":{}}',
            r"line 3: key\.n: the integer 1234\d+ is beyond 64 bits",
        ),
        # Before: the last "key" won, silently.
        (b'{"key":{"x":1},"key":{"x":2},"row":{}}', r"line 3: key: the name 'key' twice in one object"),
        (b'{"key":{"m":{"a":1,"a":2}},"row":{}}', r"line 3: key\.m\.a: the name 'a' twice in one object"),
        # Before: accepted (a string no UTF-8 file can hold; hovering_sweep refused the line).
        (b'{"key":{"s":"\\ud800"},"row":{}}', r"line 3: key\.s: a lone surrogate \\ud800"),
        # Before: the message named the parser's column, or nothing, but never the field.
        (b'{"key":{"x":NaN},"row":{}}', r"line 3: key\.x: the token NaN is not a JSON number"),
        (
            b'{"key":{"eps":0.1,"n":},"row":{}}',
            r"line 3: not a line of JSON: Expecting value at character 23, in key\.n",
        ),
        (b'{"key":{"s":"\xff"},"row":{}}', r"line 3: not a line of JSON: invalid UTF-8 at byte 14, in key\.s"),
        (
            b'{"key":{"a":[0,1,' + b"[" * 200 + b"]" * 200 + b']},"row":{}}',
            r"line 3: not a line of JSON: nested deeper than 100 levels, at character \d+, in key\.a\[2\]",
        ),
        (
            b'{"key":{"a":[1,2,"x\x01"]},"row":{}}',
            r"line 3: not a line of JSON: Invalid control character at character 20, in key\.a\[2\]",
        ),
        (b'{"key":1,"row":{}}', r"line 3: key must be an object, got a number 1"),
        (b'{"key":{}}', r"line 3: a point without its 'row' field"),
        (b'{"key":{},"row":{},"extra":1}', r"line 3: a point with other fields: 'extra'"),
        (b'{"provenance":[1]}', r"line 3: provenance must be an object, got an array"),
        (b'{"other":1}', r"line 3: neither a point .* fields 'other'"),
        (b"[1, 2]", r"line 3: not a JSON object: the line is an array"),
    ],
)
def test_every_refused_checkpoint_line_names_the_file_line_and_field(line, message, tmp_path):
    path = tmp_path / "c.jsonl"
    data = HEAD + b'{"key":{"a":1},"row":{}}\n' + line + b"\n"
    path.write_bytes(data)
    with pytest.raises(ValueError, match=rf"^{re.escape(str(path))} {message}"):
        Checkpoint(path)
    assert path.read_bytes() == data


def test_a_refused_header_names_its_field_in_a_bounded_message(tmp_path):
    path = tmp_path / "c.jsonl"
    for head, message in [
        (
            b'{"format":"hovering-checkpoint","version":"' + b"x" * 100_000 + b'"}',
            r"line 1: a checkpoint of version 'xxx",
        ),
        (
            b'{"format":"hovering-checkpoint","version":' + b"9" * 4000 + b"}",
            r"line 1: version: an integer of 13288 bits is",
        ),
        (
            b'{"format":"hovering-checkpoint","version":' + b"9" * 5000 + b"}",
            r"line 1: version: an integer of 5000 digits",
        ),
        (b'{"format":"other","version":1}', r"line 1: the first line is not the header .*format = 'other'"),
    ]:
        path.write_bytes(head + b"\n")
        with pytest.raises(ValueError, match=rf"^{re.escape(str(path))} {message}") as e:
            Checkpoint(path)
        assert len(str(e.value)) < 500


def test_a_file_of_one_line_without_its_newline_is_refused_untouched_not_cut(tmp_path):
    # Before: taken for a torn line and cut to nothing (then written over by the first put).
    path = tmp_path / "notes.txt"
    path.write_bytes(b"my notes, one line")
    with pytest.raises(
        ValueError, match=r"notes\.txt line 1: the first line is not the header .*\(one line of 18 bytes"
    ):
        Checkpoint(path)
    assert path.read_bytes() == b"my notes, one line"
    # A piece of the header is a torn first write: cut off, and the file starts again.
    path.write_bytes(HEAD[:20])
    c = Checkpoint(path)
    assert c.dropped == 1 and path.read_bytes() == b"" and c.put({"a": 1}, {"r": 2})
    assert path.read_bytes().startswith(HEAD)


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
    from hovering.scenes.kinds import _sweep

    scene = scenes.load_scene(SCENE)
    out = tmp_path / "hov.png"
    real = _sweep.hovering_area  # the function each sweep point calls (analyses are free functions)
    calls = {"n": 0}

    def flaky(m, *a, **kw):
        calls["n"] += 1
        if calls["n"] == 4:
            raise KeyboardInterrupt
        return real(m, *a, **kw)

    monkeypatch.setattr(_sweep, "hovering_area", flaky)
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
    monkeypatch.setattr(_sweep, "hovering_area", real)
    fresh = pipeline.run_scene(scene, out=tmp_path / "fresh.png", quick=True)
    assert json.dumps(fresh["series"], sort_keys=True) == json.dumps(summary["series"], sort_keys=True)
