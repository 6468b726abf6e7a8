"""Files from elsewhere stay harmless: each line of docs/threat-model.md is kept here by files the
tests craft themselves (the plan and checkpoint lines hovering_sweep reads by the C++ tests test_plan, test_sweep_plan).

Every crafted file is refused with one ValueError naming the file and the field (the CLI: exit
status 2 and one ``error:`` line), and what reading it cost is bounded: the peak of the memory
tracemalloc traces (Python's and numpy's allocations) stays far below what the file declares, and
a wall-clock hang guard of 30 s holds (before these checks, the files here took up to minutes of
computation or gigabytes; see the tests' comments). No test depends on this machine's speed or
memory except through that generous guard.
"""

from __future__ import annotations

import io
import json
import os
import pickle
import re
import subprocess
import sys
import time
import tracemalloc
import zipfile
from pathlib import Path

import numpy as np
import pytest

import hovering as hv
from hovering import paper, scenes
from hovering._io import serial as _serial
from hovering._io import untrusted as _untrusted
from hovering.cli import main
from hovering.parallel.checkpoint import Checkpoint
from hovering.pipeline import redraw, run_scene
from hovering.scenes import load_result, load_scene
from hovering.scenes.schema import MAX_CANVAS_PIXELS, MAX_KEY_PARTS, MAX_SCENE_DEPTH, MAX_TEXT, check_spec, scene_table

SCENE_DIR = Path(__file__).resolve().parents[2] / "examples" / "scenes"
HANG_GUARD = 30.0  # seconds: only a guard against a hang or a long computation, never a speed test
MiB = 1 << 20

TINY_SCENE = """\
kind = "portrait"
title = "tiny"
output = "tiny.png"
n_steps = 200
n_orbits = 3
K0_range = [-0.5, 0.2]
[map]
Omega0 = "OMEGA_G"
theta_w = "3*pi/4"
[[panels]]
id = "a"
eps = 0.3
"""


# ------------------------------------------------------------------------------------------------
# Crafting files


def _npy(a: np.ndarray) -> bytes:
    b = io.BytesIO()
    np.lib.format.write_array(b, a, allow_pickle=True)
    return b.getvalue()


def _header(descr: str, shape: tuple) -> bytes:
    b = io.BytesIO()
    np.lib.format.write_array_header_1_0(b, {"descr": descr, "fortran_order": False, "shape": shape})
    return b.getvalue()


def _zeros(header: bytes, n: int, fill: bytes = b"\0"):
    """A member writer: ``header`` then n bytes of ``fill`` repeated (compresses about 1000:1)."""

    def write(f):
        f.write(header)
        chunk = fill * ((1 << 22) // len(fill))
        left = n
        while left:
            f.write(chunk[: min(left, len(chunk))])
            left -= min(left, len(chunk))

    return write


def _write(path: Path, doc, members=()) -> Path:
    """An NPZ as hovering writes one (__meta__.npy: the JSON text as a 0-d unicode array), with extra
    members: (name, bytes) or (name, writer)."""
    text = doc if isinstance(doc, str) else json.dumps(doc)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("__meta__.npy", _npy(np.array(text)))
        for name, data in members:
            if callable(data):
                with z.open(name, "w", force_zip64=True) as f:
                    data(f)
            else:
                z.writestr(name, data)
    return path


def _doc(tree) -> dict:
    return {"format": _serial.FORMAT, "version": hv.__version__, "meta": {}, "tree": tree}


def _members(path: Path) -> dict:
    with zipfile.ZipFile(path) as z:
        return {n: z.read(n) for n in z.namelist()}


def _craft(src: Path, dst: Path, edit) -> Path:
    """A copy of a genuine result with its JSON tree edited by ``edit(doc)`` (arrays kept)."""
    members = _members(src)
    doc = json.loads(str(np.load(io.BytesIO(members.pop("__meta__.npy")))))
    edit(doc)
    return _write(dst, doc, list(members.items()))


def _refused(fn, *args, match: str, mb: float = 16.0):
    """``fn(*args)`` raises one ValueError matching ``match``, with a traced peak below ``mb`` MiB
    and within the hang guard. Returns the error."""
    tracemalloc.start()
    t0 = time.perf_counter()
    try:
        with pytest.raises(ValueError, match=match) as e:
            fn(*args)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    elapsed = time.perf_counter() - t0
    assert peak < mb * MiB, f"peak {peak / MiB:.1f} MiB while refusing"
    assert elapsed < HANG_GUARD, f"{elapsed:.1f} s while refusing"
    return e.value


def _cli(capsys, *argv) -> str:
    """``python -m hovering *argv`` in this process: exit status 2 and exactly one ``error:`` line."""
    capsys.readouterr()
    t0 = time.perf_counter()
    rc = main([str(a) for a in argv])
    elapsed = time.perf_counter() - t0
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert rc == 2 and len(lines) == 1 and lines[0].startswith("error: "), (rc, captured.err)
    assert captured.out == "" and elapsed < HANG_GUARD
    return lines[0]


@pytest.fixture(scope="module")
def genuine(tmp_path_factory):
    """Genuine files to craft from: a scene result (a 3-orbit portrait) and a FlowMap record."""
    d = tmp_path_factory.mktemp("genuine")
    (d / "tiny.toml").write_text(TINY_SCENE)
    summary = run_scene(load_scene(d / "tiny.toml"), out=d / "tiny.png")
    fm = hv.save(paper.flow_map(-0.05, coordinates="section"), d / "flowmap")
    return {"result": Path(summary["npz"]), "flowmap": Path(fm), "dir": d}


def _scene_fields(doc):
    return doc["tree"]["fields"]["scene"]["fields"]


def _orbit_fields(doc):
    return doc["tree"]["fields"]["panels"]["__list__"][0]["fields"]["orbits"]["fields"]


def _flowmap_fields(doc):
    return doc["tree"]["data"]["__dict__"]


# ------------------------------------------------------------------------------------------------
# 1. No code runs: no pickle


class _Payload:
    """Unpickling this creates the directory ``marker`` (a stand-in for any code a pickle could run)."""

    def __init__(self, marker):
        self.marker = str(marker)

    def __reduce__(self):
        return (os.mkdir, (self.marker,))


def test_pickled_object_arrays_are_refused_from_their_header(tmp_path):
    marker = tmp_path / "ran"
    member = _npy(np.array([_Payload(marker)], dtype=object))
    pickle.loads(member[member.index(b"\x80") :])
    assert marker.is_dir()  # the payload works...
    marker.rmdir()
    path = _write(tmp_path / "pickle.npz", _doc({"__array__": "root", "object": False}), [("root.npy", member)])
    err = _refused(
        hv.load,
        path,
        match=r"pickle\.npz: array 'root': dtype '\|O' is refused; allowed: booleans, "
        r"integers, floats, complex numbers and text \(object arrays would need pickle\)",
    )
    assert not marker.exists() and "pickle.npz" in str(err)  # ...but is never unpickled
    # Unreferenced, the same member is not even read: the file loads as what its tree says.
    path = _write(tmp_path / "unreferenced.npz", _doc({"__list__": [1.5, "x"]}), [("root.npy", member)])
    assert hv.load(path) == [1.5, "x"] and not marker.exists()


# ------------------------------------------------------------------------------------------------
# 2. The reader never computes


def test_flowmap_record_asking_for_an_accuracy_target_is_refused_without_measuring(genuine, tmp_path, monkeypatch):
    import hovering.diagnostics.tolerance as tolerance

    calls = []
    real = tolerance.choose_setting
    monkeypatch.setattr(tolerance, "choose_setting", lambda *a, **k: calls.append(a) or real(*a, **k))
    assert (
        hv.load(genuine["flowmap"]).integrator_options["stepper"] == "taylor" and calls == []
    )  # "auto" as saved: resolved
    # Before: this 3 KB record ran a work-precision measurement for more than 300 s (it was killed).
    path = _craft(
        genuine["flowmap"],
        tmp_path / "accuracy.npz",
        lambda d: _flowmap_fields(d)["options"]["__dict__"].update(accuracy=1e-12, accuracy_returns=100000),
    )
    assert path.stat().st_size < 4096
    _refused(
        hv.load,
        path,
        match=r"accuracy\.npz: root: the FlowMap's options \['accuracy', 'accuracy_returns'\] "
        r"are not stored settings; allowed: \['atol', 'corner_tol', ",
    )
    assert calls == []


def test_flowmap_record_without_its_curve_is_refused_without_tracing(genuine, tmp_path, monkeypatch):
    traced = []
    real = hv.TangentialCurve.__init__
    monkeypatch.setattr(hv.TangentialCurve, "__init__", lambda self, *a, **k: traced.append(a) or real(self, *a, **k))
    path = _craft(
        genuine["flowmap"], tmp_path / "nocurve.npz", lambda d: _flowmap_fields(d).update(coordinates="normal")
    )
    _refused(
        hv.load,
        path,
        match=r"nocurve\.npz: root: the FlowMap is in normal coordinates but the file holds no "
        r"tangential curve",
    )
    assert traced == []


def test_redraw_draws_a_genuine_result_without_computing(genuine, tmp_path, monkeypatch):
    def refuse(*a, **k):
        raise AssertionError("redraw computed")

    monkeypatch.setattr(scenes, "compute", refuse)
    monkeypatch.setattr(hv.TruncatedMap, "iterate", refuse)
    png, result, _ = redraw(genuine["result"], out=tmp_path / "again.png")
    assert png.stat().st_size > 0 and result.panels[0].orbits.n_orbits == 3


# ------------------------------------------------------------------------------------------------
# 3. Memory and time stay within the stated limits, checked before reading


def test_zip_bomb_member_the_tree_does_not_name_is_never_read(tmp_path):
    # 256 MiB of zeros in 0.25 MiB: before, load decompressed every member (a 3.1 MB bomb took 3.1 GB).
    path = _write(
        tmp_path / "bomb.npz",
        _doc({"__dict__": {"x": 1.0, "a": {"__array__": "a"}}}),
        [("a.npy", _npy(np.arange(4.0))), ("junk.npy", _zeros(_header("|u1", (256 * MiB,)), 256 * MiB))],
    )
    assert path.stat().st_size < 2 * MiB
    tracemalloc.start()
    t0 = time.perf_counter()
    got = hv.load(path)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert got["x"] == 1.0 and np.array_equal(got["a"], np.arange(4.0))
    assert peak < 8 * MiB and time.perf_counter() - t0 < HANG_GUARD


def test_zip_bomb_member_beyond_the_memory_budget_is_refused_unread(tmp_path, monkeypatch):
    path = _write(
        tmp_path / "bomb.npz",
        _doc({"__array__": "root"}),
        [("root.npy", _zeros(_header("|u1", (256 * MiB,)), 256 * MiB))],
    )
    # The budget is half of this machine's memory; a 64 MiB budget stands in for a small machine.
    monkeypatch.setattr(_untrusted, "memory_budget", lambda: 64 * MiB)
    _refused(
        hv.load,
        path,
        match=r"bomb\.npz: its arrays and tree need 0\.25 GiB \(as its headers declare\), more "
        r"than half of this machine's memory \(0\.125 GiB\)",
    )


def test_huge_declared_shapes_are_refused_before_allocating(tmp_path):
    # Before: "Unable to allocate 7.28 TiB" (a raw MemoryError) from this 0.5 KB file.
    path = _write(
        tmp_path / "shape.npz", _doc({"__array__": "root"}), [("root.npy", _header("<f8", (10**12,)) + bytes(64))]
    )
    _refused(
        hv.load,
        path,
        match=r"shape\.npz: array 'root': the archive declares 192 bytes, its header 128 \+ "
        r"8000000000000 \(shape \(1000000000000,\), dtype <f8\)",
    )
    # A header beyond numpy's own limit is not parsed at all.
    long_header = b"\x93NUMPY\x02\x00" + (10**6).to_bytes(4, "little") + b" " * 64
    path = _write(tmp_path / "header.npz", _doc({"__array__": "root"}), [("root.npy", long_header)])
    _refused(hv.load, path, match=r"array 'root': a header of 1000000 bytes; allowed: at most 10000")


def test_json_document_limits(tmp_path):
    # Longer than MAX_TREE_CHARS: refused from the __meta__ header (256 MiB of text never decoded).
    n = _untrusted.MAX_TREE_CHARS + 1
    path = tmp_path / "long.npz"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        with z.open("__meta__.npy", "w", force_zip64=True) as f:
            _zeros(_header(f"<U{n}", ()), 4 * n, b" \0\0\0")(f)
    _refused(
        hv.load,
        path,
        match=rf"long\.npz is not a hovering result file: its __meta__ entry has {n} characters; "
        rf"allowed: at most {_untrusted.MAX_TREE_CHARS}",
    )
    # Nested 100,000 deep (before: a RecursionError from the decoder): refused by a scan before parsing.
    deep = '{"format": "hovering-npz-1", "tree": ' + '{"__list__": [' * 100_000 + "]}" * 100_000 + "}"
    _refused(
        hv.load,
        _write(tmp_path / "deep.npz", deep),
        mb=64,  # the text itself: 11 MiB as UTF-32
        match=r"deep\.npz is not a hovering result file: its __meta__ entry is nested 200001 levels deep; "
        r"allowed: at most 100",
    )
    cases = {
        "string": (_doc({"__list__": ["x" * 1_100_000]}), r"a string of 1100000 characters; allowed: at most 1048576"),
        "key": (_doc({"__dict__": {"k" * 1_100_000: 1}}), r"a key at .*: a string of 1100000 characters"),
        "nan": ('{"format": "hovering-npz-1", "tree": NaN}', r"holds NaN, which hovering never writes"),
        "infinity": ('{"format": "hovering-npz-1", "tree": -Infinity}', r"holds -Infinity"),
        "overflow": ('{"format": "hovering-npz-1", "tree": 1e400}', r"1e400 is beyond the range of a double"),
        # hovering.save refuses integers beyond 10,000 bits; a longer digit string is not converted.
        "int": (
            '{"format": "hovering-npz-1", "tree": ' + "9" * 5000 + "}",
            r"has 5000 digits; allowed: integers of at most 10000 bits",
        ),
        "int_bits": (
            '{"format": "hovering-npz-1", "tree": ' + "9" * 3011 + "}",
            rf"has {int('9' * 3011).bit_length()} bits; allowed: at most 10000",
        ),
        "float_node": (
            _doc({"__float__": "1e5"}),
            r"root: malformed result file: \{'__float__': '1e5'\}; allowed: "
            r"'nan', 'inf', '-inf'",
        ),
    }
    for name, (doc, msg) in cases.items():
        err = _refused(hv.load, _write(tmp_path / f"{name}.npz", doc), match=msg)
        assert f"{name}.npz" in str(err)


def test_archive_directory_and_member_names(tmp_path):
    good = _write(tmp_path / "good.npz", _doc({"__array__": "a"}), [("a.npy", _npy(np.arange(3)))])
    data = bytearray(good.read_bytes())
    # The end record declares a 2 GiB central directory: refused before Python's zipfile reads it.
    data[-22 + 12 : -22 + 16] = (2**31).to_bytes(4, "little")
    (tmp_path / "directory.npz").write_bytes(bytes(data))
    _refused(
        hv.load,
        tmp_path / "directory.npz",
        match=r"directory\.npz: an archive of 2 members and a directory of "
        r"2147483648 bytes; allowed: at most 100000 members",
    )
    before = sorted(os.listdir(tmp_path.parent))
    for name, member in (
        ("traversal", "../../../evil.npy"),
        ("absolute", "/tmp/evil.npy"),
        ("dotdot", "a/../../b.npy"),
    ):
        path = _write(tmp_path / f"{name}.npz", _doc({"__array__": member[:-4]}), [(member, _npy(np.arange(3.0)))])
        _refused(
            hv.load,
            path,
            match=rf"{name}\.npz: the archive has a member named '{member}'; a hovering result "
            r"file's members are relative names without '\.\.'",
        )
    with zipfile.ZipFile(tmp_path / "dup.npz", "w") as z:
        z.writestr("__meta__.npy", _npy(np.array(json.dumps(_doc({"__array__": "a"})))))
        z.writestr("a.npy", _npy(np.arange(3)))
        with pytest.warns(UserWarning, match="Duplicate name"):
            z.writestr("a.npy", _npy(np.arange(5)))
    _refused(hv.load, tmp_path / "dup.npz", match=r"dup\.npz: the archive has two members named 'a\.npy'")
    assert sorted(os.listdir(tmp_path.parent)) == before  # reading wrote nothing anywhere
    for special in ("/dev/zero", str(tmp_path)):
        _refused(hv.load, special, match=r"cannot read .*: not a regular file")


def test_every_flipped_byte_loads_or_is_one_value_error(tmp_path):
    # Before: about 380 of these ~2000 flips raised what zipfile and zlib raise for a damaged
    # member (zlib.error, NotImplementedError "zip file version 21.0", RuntimeError "... is
    # encrypted"; numpy's header parser adds tokenize.TokenError on other files), which redraw did
    # not catch. Every byte of a small result is flipped, alternately all its bits and the lowest
    # (a zip "encrypted" flag); a flip the zip leaves unchecked (a date, "version made by") may
    # still load. ~3 s.
    m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=3 * np.pi / 4)
    good = Path(hv.save(m.iterate([0.1], [-0.1], 2, record=()), tmp_path / "good")).read_bytes()
    path, refused = tmp_path / "flipped.npz", 0
    for i in range(len(good)):
        data = bytearray(good)
        data[i] ^= (0xFF, 0x01)[i % 2]
        path.write_bytes(data)
        try:
            hv.load(path)
        except ValueError as e:
            assert str(e).startswith(str(path)), (i, str(e))
            refused += 1
    # Most flips land in CRC-checked data or the zip's records (~80% here): the flips reached the reader.
    assert refused > len(good) // 2


def test_redraw_of_a_damaged_result_is_one_error_line(genuine, tmp_path, capsys):
    # Before: the "encrypted" flag of a member (bit 0 of its flags in the central directory) made
    # zipfile raise RuntimeError, and `hovering redraw` printed a traceback with exit status 1.
    data = bytearray(genuine["result"].read_bytes())
    data[data.index(b"PK\x01\x02") + 8] |= 0x01  # the first member's general-purpose flags
    path = tmp_path / "encrypted.npz"
    path.write_bytes(data)
    line = _cli(capsys, "redraw", path, "--out", tmp_path / "out.png")
    assert re.search(
        rf"{re.escape(str(path))}: array '[^']+': damaged or not written by hovering: .* is encrypted", line
    ), line
    assert not (tmp_path / "out.png").exists()


def test_non_utf8_and_non_unicode_text(genuine, tmp_path):
    # A lone surrogate is data in a tree (hovering.save takes any str), but not a text to show: a
    # scene's title or an orbit's label with one is refused (printing or drawing it would fail).
    surrogate = '{"format": "hovering-npz-1", "tree": {"__list__": ["ok", "\\udcff"]}}'
    assert hv.load(_write(tmp_path / "data.npz", surrogate)) == ["ok", "\udcff"]
    path = _craft(genuine["result"], tmp_path / "title.npz", lambda d: _scene_fields(d).update(title="t\ud800"))
    _refused(
        load_result,
        path,
        match=r"title\.npz: root\.scene: tiny\.toml\.title: a lone surrogate at character 1; "
        r"allowed: Unicode text",
    )
    path = _craft(
        genuine["result"],
        tmp_path / "label.npz",
        lambda d: _orbit_fields(d).update(labels={"__list__": ["a", "\udcff", "c"]}),
    )
    _refused(load_result, path, match=r"label\.npz: root\.panels\[0\]\.orbits: labels\[1\]: a lone surrogate")
    path = tmp_path / "bytes.npz"
    with zipfile.ZipFile(path, "w") as z:
        z.writestr("__meta__.npy", _npy(np.array(b'{"format": "\xff\xfe"}')))
    _refused(hv.load, path, match=r"bytes\.npz: array '__meta__': dtype '\|S16' is refused")
    scene = tmp_path / "latin1.toml"
    scene.write_bytes(TINY_SCENE.replace('"tiny"', '"t\xe9"').encode("latin-1"))
    _refused(load_scene, scene, match=r"latin1\.toml: not UTF-8 text")


# ------------------------------------------------------------------------------------------------
# 4. Anything else is one ValueError naming the file and the field


CRAFTED = {
    # name: (edit of the genuine scene result's tree, what the error names)
    "dpi_text": (
        lambda d: _scene_fields(d).update(dpi="high"),
        r"root\.scene\.dpi must be of type int \(the type of OrbitScene\.dpi\), got str",
    ),
    "dpi_nan": (lambda d: _scene_fields(d).update(dpi={"__float__": "nan"}), r"root\.scene\.dpi must be of type int"),
    "eps_inf": (
        lambda d: _scene_fields(d)["panels"]["__tuple__"][0]["fields"]["map"]["fields"].update(
            eps={"__float__": "inf"}
        ),
        r"root\.scene: tiny\.toml\.panels\[0\]\.eps must be finite, got inf",
    ),
    "eps_expression": (
        lambda d: _scene_fields(d)["panels"]["__tuple__"][0]["fields"]["map"]["fields"].update(eps="2*pi"),
        r"root\.scene\.panels\[0\]\.map\.eps must be of type float",
    ),
    "kind": (
        lambda d: _scene_fields(d).update(rotation="birkhoff"),
        r"root\.scene: scene\.rotation = 'birkhoff' is not what a scene file can give \(its other values give "
        r"'mean'\)",
    ),
    "name": (
        lambda d: _scene_fields(d).update(name="other"),
        r"scene\.name = 'other' is not what a scene file can give",
    ),
    "title_long": (
        lambda d: _scene_fields(d).update(title="T" * (MAX_TEXT + 1)),
        rf"root\.scene: tiny\.toml\.title: a string of {MAX_TEXT + 1} characters; allowed: at most {MAX_TEXT}",
    ),
    "phi_text": (
        lambda d: _orbit_fields(d).update(phi="not an array"),
        r"root\.panels\[0\]\.orbits\.phi must be of type ndarray",
    ),
    "phi_shape": (
        lambda d: _orbit_fields(d).update(K=_orbit_fields(d)["status"]),
        r"root\.panels\[0\]\.orbits: K must be a 2-D array of numbers, got shape \(3,\)",
    ),
    "labels_int": (
        lambda d: _orbit_fields(d).update(labels={"__list__": [1, 2, 3]}),
        r"root\.panels\[0\]\.orbits: labels\[0\] must be a non-empty string, got 1",
    ),
    "labels_count": (
        lambda d: _orbit_fields(d).update(labels={"__list__": ["a"]}),
        r"root\.panels\[0\]\.orbits: labels must be a list of 3 strings, got a list of 1",
    ),
    "label_long": (
        lambda d: _orbit_fields(d).update(labels={"__list__": ["x" * 300, "b", "c"]}),
        rf"labels\[0\]: a string of 300 characters; allowed: at most {MAX_TEXT}",
    ),
    "colour": (
        lambda d: _orbit_fields(d).update(colors={"__list__": ["nocolour", "C1", "C2"]}),
        r"root\.panels\[0\]\.orbits: colors\[0\] = 'nocolour' is not a matplotlib colour",
    ),
    "panels_dict": (
        lambda d: d["tree"]["fields"].update(panels={"__dict__": {"a": 1}}),
        r"root\.panels must be of type list \(the type of OrbitSceneResult\.panels\), got dict",
    ),
    "panels_text": (
        lambda d: d["tree"]["fields"]["panels"]["__list__"].__setitem__(0, "a"),
        r"root: panels\[0\] must be a panel result, got str",
    ),
    "meta_steps": (
        lambda d: d["tree"]["fields"]["meta"]["__dict__"].update(n_steps="x" * 60_000),
        r"root: meta\.n_steps must be of type int, got str",
    ),
    "enum": (
        lambda d: d["tree"]["fields"].update(meta={"__enum__": _serial._type_name(hv.Region), "value": 99}),
        r"root\.meta: 99 is not a Region",
    ),
}


@pytest.mark.parametrize("name", sorted(CRAFTED))
def test_wrong_types_and_values_in_a_result_name_the_file_and_field(name, genuine, tmp_path):
    edit, msg = CRAFTED[name]
    path = _craft(genuine["result"], tmp_path / f"{name}.npz", edit)
    err = _refused(load_result, path, match=msg)
    assert str(err).startswith(f"{path}: ")


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """Genuine result files: an IterateResult (2 orbits, 10 steps, every 2nd state kept, several
    records) and a HoveringArea."""
    d = tmp_path_factory.mktemp("results")
    m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=3 * np.pi / 4)
    res = m.iterate([0.1, 0.5], [-0.1, 0.1], 10, record=("orbit", "regions", "rotation", "jacobian"), every=2)
    return {
        "iterate": Path(hv.save(res, d / "iterate")),
        "area": Path(hv.save(hv.hovering_area(m, 40, 50), d / "area")),
    }


def _with_arrays(src: Path, dst: Path, arrays: dict) -> Path:
    """A copy of a genuine result with array members replaced (member name without ``.npy`` -> array)."""
    members = _members(src)
    members.update({f"{k}.npy": _npy(a) for k, a in arrays.items()})
    with zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as z:
        for name, data in members.items():
            z.writestr(name, data)
    return dst


_STATUSES = re.escape(", ".join(f"{s.name} ({int(s)})" for s in hv.Status))  # what the enum has, not a copy
_REGIONS = re.escape(", ".join(f"{r.name} ({int(r)})" for r in hv.Region))

RESULTS_CRAFTED = {
    # name: (the file, edit of its tree, arrays replaced, what the error names). Before, each loaded:
    # later a 0-d status was an IndexError in repr, map=5 an AttributeError, a rotation of 7 values
    # for 2 orbits made rotation_number return 7 numbers.
    "status_code": (
        "iterate",
        None,
        {"root.status": np.array([0, 99], np.int8)},
        rf"root: status\[1\] = 99 is not a Status; allowed: {_STATUSES}$",
    ),
    "status_float": (
        "iterate",
        None,
        {"root.status": np.array([0.0, 0.5])},
        r"root: status must be an array of integers of shape \(any,\), got shape \(2,\), dtype float64",
    ),
    "status_0d": ("iterate", None, {"root.status": np.array(0, np.int8)}, r"root: status must be .* got shape \(\)"),
    "phi_columns": (
        "iterate",
        None,
        {"root.phi": np.zeros((2, 5))},
        r"root: phi must be an array of floats of shape \(2, 6\), got shape \(2, 5\)",
    ),
    "phi_1d": ("iterate", None, {"root.phi": np.zeros(6)}, r"root: phi must be .* \(2, 6\), got shape \(6,\)"),
    "rotation_length": (
        "iterate",
        None,
        {"root.rotation": np.zeros(7)},
        r"root: rotation must be an array of floats of shape \(2,\), got shape \(7,\)",
    ),
    "region_code": (
        "iterate",
        None,
        {"root.region": np.full((2, 5), 99, np.int8)},
        rf"root: region\[0, 0\] = 99 is not a Region; allowed: {_REGIONS}$",
    ),
    "steps_done": (
        "iterate",
        None,
        {"root.steps_done": np.array([10, 11])},
        r"root: steps_done\[1\] = 11 is out of range; allowed: \[0, 10\]",
    ),
    "n_steps": (
        "iterate",
        lambda d: d["tree"]["fields"].update(n_steps=-5),
        {},
        r"root: n_steps must be an integer in \[0, \d+\], got -5",
    ),
    "map": (
        "iterate",
        lambda d: d["tree"]["fields"].update(map=5),
        {},
        r"root: map must be a map \(hovering\.TruncatedMap, TruncatedFamily or FlowMap\), got 5",
    ),
    "jacobian_part": (
        "iterate",
        lambda d: d["tree"]["fields"].update(jacobian_log=None),
        {},
        r"root: jacobian_q, jacobian_log, jacobian_r12, jacobian_status are recorded together; the file has only "
        r"jacobian_q, jacobian_r12, jacobian_status",
    ),
    # The box is [-pi, pi) x [K_lo, 0): every area lies in [0, 2 pi |K_lo|] (4.045 for this map's default
    # K_lo = -0.6438), the error in [0, 3 times that]; the stratified grid of 50 samples has 66 points.
    "area_negative": (
        "area",
        lambda d: d["tree"]["fields"].update(area=-5.0),
        {},
        r"root: area must lie in \[0\.0, 4\.04\d*\], got -5\.0",
    ),
    "area_huge": (
        "area",
        lambda d: d["tree"]["fields"].update(area=1e300),
        {},
        r"root: area must lie in \[0\.0, 4\.04\d*\], got 1e\+300",
    ),
    "error_negative": (
        "area",
        lambda d: d["tree"]["fields"].update(error=-1.0),
        {},
        r"root: error must lie in \[0\.0, 12\.13\d*\], got -1\.0",
    ),
    "n_samples": (
        "area",
        lambda d: d["tree"]["fields"].update(n_samples=-1),
        {},
        r"root: n_samples must be an integer in \[1, \d+\], got -1",
    ),
    "unresolved": (
        "area",
        lambda d: d["tree"]["fields"].update(unresolved=67),
        {},
        r"root: unresolved must be an integer in \[0, 66\], got 67",
    ),
    "impact_fraction": (
        "area",
        lambda d: d["tree"]["fields"].update(impact_fraction_F0=5.0),
        {},
        r"root: impact_fraction_F0 must lie in \[0\.0, 1\.0\], got 5\.0",
    ),
    "areas": (
        "area",
        lambda d: d["tree"]["fields"]["areas"]["__items__"][0].__setitem__(1, -0.5),
        {},
        r"root: areas\[10\] must lie in \[0\.0, 4\.04\d*\], got -0\.5",
    ),
}


@pytest.mark.parametrize("name", sorted(RESULTS_CRAFTED))
def test_results_are_checked_against_what_their_computation_returns(name, results, tmp_path):
    which, edit, arrays, msg = RESULTS_CRAFTED[name]
    src = results[which]
    assert hv.load(src) is not None  # the genuine file passes the checks
    path = _craft(src, tmp_path / f"{name}.npz", edit or (lambda d: None))
    path = _with_arrays(path, path, arrays) if arrays else path
    err = _refused(hv.load, path, match=msg)
    assert str(err).startswith(f"{path}: ")


@pytest.mark.parametrize("what", ["rtol", "max_steps", "h", "sys", "forcing"])
def test_wrong_types_and_values_in_a_flowmap_record(what, genuine, tmp_path):
    edit, msg = {
        "rtol": (
            lambda d: _flowmap_fields(d)["options"]["__dict__"].update(rtol="tiny"),
            r"root: rtol must be a real number, got 'tiny'",
        ),
        "max_steps": (
            lambda d: _flowmap_fields(d)["options"]["__dict__"].update(max_steps=[1, 2]),
            r"a bare list in the tree at root@\.options\.max_steps",
        ),
        "h": (lambda d: _flowmap_fields(d).update(h={"__float__": "nan"}), r"root: h must be finite, got nan"),
        "sys": (lambda d: _flowmap_fields(d).update(sys=3), r"root: the FlowMap's sys must be a StepSystem, got int"),
        "forcing": (
            lambda d: _flowmap_fields(d).update(forcing={"__list__": [{"__float__": "inf"}]}),
            r"root: forcing\[0\] must be finite, got inf",
        ),
    }[what]
    _refused(hv.load, _craft(genuine["flowmap"], tmp_path / f"{what}.npz", edit), match=msg)


def test_a_polynomial_record_with_a_repeated_power_is_refused(tmp_path):
    # Before: {(i, j): c for ...} kept the last coefficient of a repeated power and dropped the
    # first without a word (the system loaded with another coupling than the file lists).
    sys_ = hv.StepSystem(
        hv.Harmonic(1.0), hv.Tan(1.4, 0.7), coupling=hv.Polynomial({(1, 1): 1.0, (2, 0): 0.5}), eps=0.1
    )
    src = Path(hv.save(sys_, tmp_path / "sys"))

    def terms(d):
        return d["tree"]["data"]["__dict__"]["coupling"]["data"]["__dict__"]["terms"]["__list__"]

    dup = _craft(src, tmp_path / "dup.npz", lambda d: terms(d).append({"__list__": [1, 1, 2.0]}))
    err = _refused(hv.load, dup, match=r"root@\.coupling: terms\[2\] = \[1, 1, 2\.0\] repeats the power q1\^1 q2\^1")
    assert str(err).startswith(f"{dup}: ")
    short = _craft(src, tmp_path / "short.npz", lambda d: terms(d).__setitem__(0, {"__list__": [1, 1]}))
    _refused(hv.load, short, match=r"root@\.coupling: terms\[0\] must be a term \[i, j, c\]")
    assert hv.load(src).coupling == sys_.coupling


@pytest.mark.parametrize("case", ["dpi", "figsize", "layout", "title"])
def test_redraw_refuses_what_the_scene_schema_refuses(case, genuine, tmp_path, capsys):
    edit, msg = {
        # Before: dpi 8000 asked for a 51200 x 38400 canvas (7.8 GB; MemoryError under an 8 GB limit).
        "dpi": (
            lambda d: _scene_fields(d).update(dpi=8000),
            r"root\.scene: tiny\.toml\.dpi = 8000 is out of range; allowed: \[30, 1200\]",
        ),
        "figsize": (
            lambda d: _scene_fields(d).update(dpi=1200, figsize={"__tuple__": [60.0, 60.0]}),
            r"dpi = 1200 and figsize make a figure of 60 x 60 inches, a canvas of 5184 million pixels; "
            r"allowed: at most 150 million",
        ),
        # Before: 24 s and 890 MB (a 121 x 92.6 inch canvas of 400 axes).
        "layout": (
            lambda d: _scene_fields(d).update(layout={"__tuple__": [20, 20]}),
            r"dpi = 130 and layout make a figure of 121 x 92\.6 inches, a canvas of 189 million pixels",
        ),
        # Before: 97 s and 360 MB of savefig.
        "title": (
            lambda d: _scene_fields(d).update(title="T" * 500_000),
            r"root\.scene: tiny\.toml\.title: a string of 500000 characters; allowed: at most 65536",
        ),
    }[case]
    path = _craft(genuine["result"], tmp_path / f"{case}.npz", edit)
    tracemalloc.start()
    try:
        line = _cli(capsys, "redraw", path, "--out", tmp_path / "out.png")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert str(path) in line and re.search(msg, line), line
    assert peak < 32 * MiB and not (tmp_path / "out.png").exists()


@pytest.mark.e2e
def test_redraw_command_line_is_one_error_line_and_bounded(genuine, tmp_path):
    path = _craft(genuine["result"], tmp_path / "dpi.npz", lambda d: _scene_fields(d).update(dpi=8000))
    # `python -m hovering redraw`, which writes its own peak RSS (VmHWM: this process image's, from
    # its exec) at exit. Not the rusage of wait4: Linux carries the parent's high-water RSS across
    # fork + exec into the child's ru_maxrss, so it read 650 MB inside a grown test session.
    hwm = tmp_path / "hwm"
    run = (
        "import atexit, runpy, sys\n"
        "def peak():\n"
        "    with open('/proc/self/status') as f:\n"
        "        line = next(x for x in f if x.startswith('VmHWM:'))\n"
        f"    open({str(hwm)!r}, 'w').write(line.split()[1])\n"
        "atexit.register(peak)\n"
        "sys.argv = ['hovering'] + sys.argv[1:]\n"
        "runpy.run_module('hovering', run_name='__main__', alter_sys=True)\n"
    )
    with open(tmp_path / "out", "w+") as out, open(tmp_path / "err", "w+") as err:
        proc = subprocess.Popen([sys.executable, "-c", run, "redraw", str(path)], stdout=out, stderr=err)
        try:
            proc.wait(timeout=120)
        except subprocess.TimeoutExpired:
            proc.kill()
            pytest.fail("python -m hovering redraw did not finish in 120 s")
    text = (tmp_path / "err").read_text()
    assert proc.returncode == 2 and (tmp_path / "out").read_text() == "" and text.count("\n") == 1, text
    assert text.startswith(f"error: {path}: root.scene: tiny.toml.dpi = 8000 is out of range")
    # The whole process (Python, numpy, matplotlib) stays below 512 MB: the canvas asked for is 7.8 GB.
    assert int(hwm.read_text()) < 512 * 1024 and not path.with_suffix(".png").exists()


# ------------------------------------------------------------------------------------------------
# Scene files (TOML)


def _scene(tmp_path, name, text) -> Path:
    p = tmp_path / f"{name}.toml"
    p.write_text(text)
    return p


TOML_CASES = {
    # Before: RecursionError tracebacks.
    "deep_array": (
        TINY_SCENE.replace("K0_range = [-0.5, 0.2]", "K0_range = " + "[" * 5000 + "]" * 5000),
        rf"line 6: 'K0_range' nests arrays or tables more than {MAX_SCENE_DEPTH} deep",
    ),
    "deep_table": (
        TINY_SCENE + "figsize = " + "{a=" * 5000 + "1" + "}" * 5000 + "\n",
        r"line 13: 'figsize' nests arrays or tables more than 16 deep",
    ),
    # Before: 97 s and 8 GB (MemoryError) inside Python's TOML reader.
    "dotted_key": (
        TINY_SCENE.replace('title = "tiny"', "title." + "a." * 100_000 + "b = 1"),
        rf"line 2: the key 'title\.a\.a.*has more than {MAX_KEY_PARTS} dotted parts",
    ),
    "nested_dotted": (
        TINY_SCENE + "[panels.zoom]\n" + "".join(f"k{i} = {{" for i in range(20)) + "x=1" + "}" * 20,
        r"line 14: 'k0' nests arrays or tables more than 16 deep",
    ),
    # Before: OverflowError tracebacks.
    "int_eps": (
        TINY_SCENE.replace("eps = 0.3", "eps = " + "9" * 350),
        rf"int_eps\.toml\.panels\[0\]\.eps = \(an integer of {int('9' * 350).bit_length()} bits\) is out of "
        r"range; allowed: integers",
    ),
    # Before: Python's "Exceeds the limit (4300 digits) for integer string conversion", naming nothing.
    "int_marker": (
        TINY_SCENE.replace("n_orbits = 3", "n_orbits = 3\nmarker_size = " + "9" * 5000),
        r"int_marker\.toml: line 6: 'marker_size' has a number of 5000 digits; allowed: numbers within the "
        r"range of a double",
    ),
    "int_real": (
        TINY_SCENE.replace("eps = 0.3", "eps = " + str(2**1024 - 1)),
        r"int_real\.toml\.panels\[0\]\.eps is an integer of 1024 bits, beyond the range of a double",
    ),
    # Before: 129 s of savefig and 390 MB.
    "title_500k": (
        TINY_SCENE.replace('title = "tiny"', 'title = "' + "x" * 500_000 + '"'),
        r"title_500k\.toml\.title: a string of 500000 characters; allowed: at most 65536",
    ),
    "title_long": (
        TINY_SCENE.replace('title = "tiny"', 'title = "' + "x" * 201 + '"'),
        rf"title_long\.toml\.title: a string of 201 characters; allowed: at most {MAX_TEXT}",
    ),
    "panel_id": (
        TINY_SCENE.replace('id = "a"', 'id = "' + "a" * 1000 + '"'),
        r"panels\[0\]\.id: a string of 1000 characters; allowed: at most 200",
    ),
    # Before: 25 s and 890 MB for a 121 x 92.6 inch figure.
    "layout": (
        TINY_SCENE.replace("n_orbits = 3", "n_orbits = 3\nlayout = [20, 20]"),
        r"dpi = 130 and layout make a figure of 121 x 92\.6 inches, a canvas of 189 million pixels",
    ),
    "dpi_figsize": (
        TINY_SCENE.replace("n_orbits = 3", "n_orbits = 3\ndpi = 1200\nfigsize = [12, 12]"),
        r"dpi = 1200 and figsize make a figure of 12 x 12 inches, a canvas of 207 million pixels",
    ),
}


@pytest.mark.parametrize("name", sorted(TOML_CASES))
def test_scene_files_are_read_as_untrusted(name, tmp_path, capsys):
    text, msg = TOML_CASES[name]
    path = _scene(tmp_path, name, text)
    _refused(load_scene, path, match=msg, mb=64)  # the file itself is up to 1 MB; its text is copied a few times
    line = _cli(capsys, "scene", path, "--out", tmp_path / "out.png")
    assert re.search(msg, line) and not list(tmp_path.glob("out.*"))


def test_canvas_limit_is_what_the_figure_would_need():
    # The largest example figure is far inside the limit; the limit is the figure's own size in pixels.
    from hovering.plot.figures import figure_inches

    for p in SCENE_DIR.glob("*.toml"):
        s = load_scene(p, check_output=False)
        w, h = figure_inches(s, len(getattr(s, "panels", ())))
        assert (s.dpi * w) * (s.dpi * h) < MAX_CANVAS_PIXELS / 10, p.name


# ------------------------------------------------------------------------------------------------
# Checkpoints


HOV_SCENE = SCENE_DIR / "fig_hov_vs_eps.toml"


@pytest.fixture(scope="module")
def checkpoint(tmp_path_factory):
    """A genuine checkpoint of a quick |HOV| sweep and the summary of the run that wrote it."""
    d = tmp_path_factory.mktemp("ckpt")
    summary = run_scene(load_scene(HOV_SCENE), out=d / "hov.png", quick=True)
    return d / "hov.sweep.jsonl", summary


def _edited(src: Path, dst_dir: Path, edit) -> Path:
    """The sweep's output path whose checkpoint is ``src`` with its first point's row edited (line 3,
    after the header and the provenance line)."""
    lines = src.read_text().splitlines()
    rec = json.loads(lines[2])
    edit(rec["row"])
    lines[2] = json.dumps(rec)
    (dst_dir / "hov.sweep.jsonl").write_text("\n".join(lines) + "\n")
    return dst_dir / "hov.png"


@pytest.mark.parametrize(
    "case",
    [
        "area_text",
        "area_missing",
        "flag_number",
        "box_other",
        "row_list",
        "count_float",
        "area_negative",
        "area_huge",
        "error_negative",
        "samples_negative",
        "unresolved_huge",
        "impact_fraction",
    ],
)
def test_checkpoint_rows_are_checked_before_use(case, checkpoint, tmp_path, monkeypatch):
    # The last six loaded before and were drawn as they were; error = -1 ended the run at the
    # plot ("'yerr' must not contain negative values"), naming neither file nor line, saving nothing.
    # An area lies in [0, 2 pi |K_low|] of the point's box, the error in [0, 3 times that].
    edit, msg = {
        "area_text": (
            lambda r: r.update(area="x"),
            r"row\.area must be a number \(within the range of a double\), got 'x'",
        ),
        "area_missing": (lambda r: r.pop("area"), r"row\.area is missing"),
        "flag_number": (lambda r: r.update(floor_touched=0), r"row\.floor_touched must be true or false, got 0"),
        "box_other": (lambda r: r.update(K_low=-0.5), r"row\.K_low = -0\.5 is not the point's K_low = -?0\.\d+"),
        "row_list": (
            lambda r: (r.clear(), r.update(area=[1.0] * 10)),
            r"row\.area must be a number .*, got \[1\.0, .*\]",
        ),
        "count_float": (lambda r: r.update(n_samples=2.5), r"row\.n_samples must be an integer, got 2\.5"),
        "area_negative": (lambda r: r.update(area=-5.0), r"row\.area must lie in \[0\.0, [\d.]+\], got -5\.0"),
        "area_huge": (lambda r: r.update(area=1e300), r"row\.area must lie in \[0\.0, [\d.]+\], got 1e\+300"),
        "error_negative": (lambda r: r.update(error=-1.0), r"row\.error must lie in \[0\.0, [\d.]+\], got -1\.0"),
        "samples_negative": (
            lambda r: r.update(n_samples=-3),
            r"row\.n_samples must be an integer in \[1, \d+\], got -3",
        ),
        "unresolved_huge": (
            lambda r: r.update(unresolved=10**18),
            r"row\.unresolved must be an integer in \[0, \d+\], got 1000000000000000000",
        ),
        "impact_fraction": (
            lambda r: r.update(impact_fraction_F0=5.0),
            r"row\.impact_fraction_F0 must lie in \[0\.0, 1\.0\], got 5\.0",
        ),
    }[case]
    out = _edited(checkpoint[0], tmp_path, edit)
    computed = []
    from hovering.scenes.kinds import _sweep  # the function each sweep point calls

    monkeypatch.setattr(_sweep, "hovering_area", lambda *a, **k: computed.append(a))
    _refused(
        run_scene,
        load_scene(HOV_SCENE),
        out,
        True,
        match=rf"hov\.sweep\.jsonl line 3: {msg} \(the file was "
        r"edited or damaged",
    )
    assert computed == [] and not out.exists()


@pytest.mark.parametrize("case", ["status", "steps", "visited"])
def test_checkpoint_pieces_are_checked_before_use(case, tmp_path):
    # Before: any int8 status and int64 step count was taken: status 99 counted as "unresolved",
    # steps beyond n_steps as having survived them. Now each names the file, the line and the entry.
    from hovering.parallel import Executor

    m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=3 * np.pi / 4)
    ck = tmp_path / "pieces.jsonl"
    kw = dict(n_steps=40, n_samples=50, executor=Executor(workers=1, pieces=2, checkpoint=ck))
    hv.hovering_area(m, **kw)
    lines = ck.read_text().splitlines()
    rec = json.loads(lines[2])  # the first piece, after the header and the provenance line
    column, value, msg = {
        "status": (1, 99, rf"row\.outcomes\.status\[0\] = 99 is not a Status; allowed: {_STATUSES}"),
        "steps": (2, 41, r"row\.outcomes\.steps_done\[0\] = 41 is out of range; allowed: \[0, 40\]"),
        "visited": (3, -1, r"row\.outcomes\.visited\[0\] = -1 is out of range; allowed: \[0, 31\]"),
    }[case]
    rec["row"]["outcomes"][column][0] = value
    lines[2] = json.dumps(rec)
    ck.write_text("\n".join(lines) + "\n")
    _refused(lambda: hv.hovering_area(m, **kw), match=rf"pieces\.jsonl line 3: {msg} \(the file was edited or damaged")


def test_checkpoint_genuine_rows_are_reused(checkpoint, tmp_path, monkeypatch):
    path, first = checkpoint
    (tmp_path / "hov.sweep.jsonl").write_bytes(path.read_bytes())
    from hovering.scenes.kinds import _sweep

    monkeypatch.setattr(_sweep, "hovering_area", lambda *a, **k: pytest.fail("recomputed a stored point"))
    again = run_scene(load_scene(HOV_SCENE), out=tmp_path / "hov.png", quick=True)
    assert again["points_reused"] == first["points_reused"] + sum(len(s["points"]) for s in first["series"])
    assert json.dumps(again["series"], sort_keys=True) == json.dumps(first["series"], sort_keys=True)


def test_checkpoint_files_within_limits(tmp_path, monkeypatch):
    head = '{"format":"hovering-checkpoint","version":1}\n'
    good = '{"key":{"eps":0.1},"row":{"area":1.0}}\n'
    # A line nested 100,000 deep (before: a RecursionError traceback) is a damaged line, refused
    # without recursing; so is a line of invalid UTF-8. Memory stays bounded while reading.
    path = tmp_path / "c.jsonl"
    for bad in ('{"key": ' + "[" * 100_000 + "]" * 100_000 + ', "row": {}}\n', '{"key": {"eps": "\xff"}}\n'):
        data = (head + good).encode() + (bad.encode("latin-1") if "\xff" in bad else bad.encode())
        path.write_bytes(data)
        tracemalloc.start()
        with pytest.raises(ValueError, match=r"c\.jsonl line 3: not a line of JSON"):
            Checkpoint(path)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        assert peak < 16 * MiB and path.read_bytes() == data
    path.write_text(head + good)
    assert Checkpoint(path).get({"eps": 0.1}) == {"area": 1.0}
    os.mkfifo(tmp_path / "fifo.jsonl")
    _refused(Checkpoint, tmp_path / "fifo.jsonl", match=r"fifo\.jsonl: not a regular file")
    # 10,000 rows of empty lists: ~2 MB of text, ~50 MB of Python objects by the estimate.
    (tmp_path / "big.jsonl").write_text(head + (json.dumps({"key": {"a": 1}, "row": {"r": [[]] * 10_000}}) + "\n") * 10)
    monkeypatch.setattr(_untrusted, "memory_budget", lambda: 4 * MiB)
    _refused(
        Checkpoint,
        tmp_path / "big.jsonl",
        match=r"big\.jsonl: a checkpoint of \d+ bytes, whose rows would take "
        r"up to [\d.e-]+ GiB, more than half of this machine's memory",
    )


# ------------------------------------------------------------------------------------------------
# What is genuine still loads


def test_genuine_large_and_compressible_results_load(tmp_path):
    # A 64 MB orbit array that is all NaN (orbits that stopped: compresses ~1000:1) is a legitimate
    # result, not a bomb: within the budget it loads, bit for bit.
    phi = np.full((2000, 4000), np.nan)
    phi[:, 0] = np.linspace(-3, 3, 2000)
    path = hv.save({"phi": phi, "labels": [f"K0={k:.4g}" for k in range(2000)]}, tmp_path / "big")
    assert os.path.getsize(path) < 2 * MiB
    back = hv.load(path)
    assert np.array_equal(back["phi"], phi, equal_nan=True) and back["labels"][1999] == "K0=1999"


@pytest.mark.parametrize("path", sorted(SCENE_DIR.glob("*.toml")), ids=lambda p: p.stem)
def test_every_example_scene_passes_its_recheck(path):
    # A genuine spec, written out as its scene file and read again, is itself (golden-family
    # parameters recomputed, expressions as their values): check_spec never refuses what a scene
    # file gave.
    spec = load_scene(path, check_output=False)
    assert check_spec(spec) is spec
    again = scenes.parse_scene(scene_table(spec), spec.path, check_output=False)
    assert again == spec or not _differs(again, spec)


def _differs(a, b) -> bool:
    from hovering.scenes.schema import _first_difference

    return _first_difference(a, b, "scene") is not None


def test_every_result_type_round_trips_its_checks(tmp_path):
    # The field-type checks accept everything hovering writes (results of every type, maps).
    from helpers.pickle_helpers import maps, results

    for name, r in {
        **{k: v for k, v in results().items() if k != "iterate_custom"},
        **{f"map_{k}": v[0] for k, v in maps().items() if k != "flow_custom"},
    }.items():
        back = hv.load(hv.save(r, tmp_path / name))
        assert type(back) is type(r), name


def test_what_save_writes_load_reads(tmp_path):
    # The reading limits are also save's: nothing is written that load would refuse.
    key = "a/../b"  # a dict key that, as a member name, would have a '..' component
    back = hv.load(hv.save({key: np.arange(3.0), "t": "x" * 1000}, tmp_path / "names"))
    assert np.array_equal(back[key], np.arange(3.0)) and back["t"] == "x" * 1000
    with zipfile.ZipFile(tmp_path / "names.npz") as z:
        assert all(_untrusted.safe_member_name(n) for n in z.namelist())
    with pytest.raises(
        ValueError,
        match=r"cannot save: the file would not read back: .*a string of 1100000 "
        r"characters; allowed: at most 1048576",
    ):
        hv.save({"note": "x" * 1_100_000}, tmp_path / "long")
    deep = 1.0
    for _ in range(60):
        deep = [deep]
    with pytest.raises(
        ValueError,
        match=r"cannot save: the file would not read back: the tree is nested 121 levels "
        r"deep; allowed: at most 100",
    ):
        hv.save(deep, tmp_path / "deep")
    with pytest.raises(TypeError, match=r"root: arrays of dtype datetime64\[D\] cannot be saved"):
        hv.save(np.array(["2020-01-01"], dtype="M8[D]"), tmp_path / "dates")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["names.npz"]
