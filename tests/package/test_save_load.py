"""NPZ files of results, maps and systems (hovering.save / hovering.load / result.save), written
without pickle: every result type round-trips (arrays by dtype, shape and bits, scalars equal),
maps are rebuilt through their constructors and step bit for bit as the saved ones, and a file
that is not a hovering result, or names a type that is not hovering's, is refused with a
ValueError (reading never imports or calls anything else)."""

from __future__ import annotations

import dataclasses
import json
import os
import zipfile

import numpy as np
import pytest

import hovering as hv
from helpers.pickle_helpers import Cosh, issue_system, maps, quartic, results, same, same_steps
from hovering import FlowStatus, Region, Status, _serial

# ------------------------------------------------------------------ results

SAVEABLE_RESULTS = [name for name in results() if name != "iterate_custom"]


@pytest.mark.parametrize("name", SAVEABLE_RESULTS)
def test_every_result_round_trips(name, tmp_path):
    r = results()[name]
    path = r.save(tmp_path / name)
    assert path == str(tmp_path / f"{name}.npz") and os.path.isfile(path)
    back = hv.load(path)
    assert type(back) is type(r) and same(r, back)
    if getattr(r, "map", None) is not None:
        m, m2 = r.map, back.map
        assert type(m2) is type(m) and m2 is not m
        phi = np.linspace(-3.0, 3.0, 60)
        K = np.full(60, -0.02)
        assert same_steps(m, m2, phi, K)
        assert same(m.iterate(phi, K, 20), m2.iterate(phi, K, 20))


def test_result_arrays_keep_dtypes_and_enums_survive(tmp_path):
    r = results()["iterate_truncated"]
    back = hv.load(r.save(tmp_path / "r.npz"))
    for f in ("phi", "K", "region", "rotation", "status", "steps_done", "exit_step", "visited"):
        assert getattr(back, f).dtype == getattr(r, f).dtype, f
    assert back.count(Status.EXITED) == r.count(Status.EXITED) and back.n_orbits == r.n_orbits
    obj = {
        "region": Region.ABOVE,
        "status": Status.EXITED,
        "flow": FlowStatus.GRAZING,
        "many": [Region.RIGHT, Region.NONE],
        "geometry": hv.Geometry.WALL,
    }
    got = hv.load(hv.save(obj, tmp_path / "enums"))
    assert got == obj and all(got[k] is obj[k] for k in ("region", "status", "flow", "geometry"))
    assert got["many"][0] is Region.RIGHT and got["many"][1] is Region.NONE


def test_flow_result_keeps_its_itineraries_and_map(tmp_path):
    r = results()["iterate_flow"]
    back = hv.load(r.save(tmp_path / "flow"))
    assert back.itinerary == r.itinerary and isinstance(back.itinerary[0][0], str)
    fm, fm2 = r.map, back.map
    assert fm2.sys == fm.sys and fm2.curve.sec.sys is fm2.sys and fm2.integrator_options == fm.integrator_options
    assert fm2.onset == fm.onset and fm2.coordinates == fm.coordinates
    assert same(fm2.step_rotations(back, 0), fm.step_rotations(r, 0))


def test_result_on_a_custom_potential_is_refused_by_name(tmp_path):
    r = results()["iterate_custom"]
    target = tmp_path / "custom.npz"
    with pytest.raises(
        TypeError,
        match=r"^root.map@.sys@.V1: cannot save quartic \(a CustomPotential\) to NPZ: its V and V. are Python code",
    ):
        r.save(target)
    assert not target.exists() and os.listdir(tmp_path) == []
    # The hint of the message works: the result without its map.
    back = hv.load(dataclasses.replace(r, map=None).save(target))
    assert back.map is None and same(back.phi, r.phi) and back.itinerary == r.itinerary
    with pytest.raises(TypeError, match=r"Cosh\(a=0.5\) \(a Cosh, a Potential defined in Python\)"):
        hv.save(Cosh(0.5), tmp_path / "cosh")
    with pytest.raises(TypeError, match=r"^root@\.V1: cannot save quartic"):  # where it is in the tree
        hv.save(issue_system(0.0, V1=quartic()), tmp_path / "sys")


# ------------------------------------------------------------------ maps and the objects they are made of


@pytest.mark.parametrize("name", ["truncated", "truncated_capped", "family", "flow_normal", "flow_section"])
def test_maps_are_rebuilt_bit_for_bit(name, tmp_path):
    m, phi, K = maps()[name]
    m2 = hv.load(hv.save(m, tmp_path / name))
    assert type(m2) is type(m) and m2.valid_band() == m.valid_band()
    assert same_steps(m, m2, phi, K)
    n = 30 if name.startswith("flow") else 400
    assert same(m.iterate(phi, K, n), m2.iterate(phi, K, n))


def test_flow_map_is_loaded_without_tracing_the_flow(tmp_path, monkeypatch):
    fm = maps()["flow_normal"][0]
    fm.forcing_coefficients(6)
    path = hv.save(fm, tmp_path / "fm")

    def refuse(*args, **kwargs):
        raise AssertionError("the tangential curve was measured again")

    monkeypatch.setattr(hv.TangentialCurve, "__init__", refuse)
    fm2 = hv.load(path)
    assert same(fm2._forcing, fm._forcing) and same(fm2.curve.values, fm.curve.values)
    assert fm2.curve.interpolation_error == fm.curve.interpolation_error


def test_systems_sections_curves_potentials_round_trip(tmp_path):
    poly = hv.Polynomial({(1, 1): 0.5, (2, 1): -0.25})
    sys = issue_system(0.1).replace(coupling=poly, V1=hv.Numerical(hv.Harmonic(1.1)))
    curve = maps()["flow_normal"][0].curve
    curve_unchecked = hv.TangentialCurve(hv.Section(issue_system(0.02), 1.0), n=16, n_check=0)
    objs = {
        "system": sys,
        "section": hv.Section(sys, 1.3),
        "bilinear": hv.Bilinear(),
        "polynomial": poly,
        "potentials": [hv.Harmonic(1.3), hv.Tan(1.4, 0.7), hv.Numerical(hv.Tan(1.4, 0.7))],
        "onset": hv.onset_parameters(sys, 1.3),
        "theory": results()["theory_family"],
    }
    got = hv.load(hv.save(objs, tmp_path / "objs"))
    assert got == objs
    assert got["system"].core is not sys.core and got["system"].core.terms == sys.core.terms
    z = hv.Section(sys, 1.3).point([0.2], [0.3])
    assert same(got["system"].core.energy(z), sys.core.energy(z))
    th = np.linspace(-np.pi, np.pi, 101)
    for c in (curve, curve_unchecked):
        c2 = hv.load(c.save(tmp_path / "curve"))
        assert c2.sec == c.sec and same(c2(th), c(th)) and same(c2.theta, c.theta) and same(c2.s, c.s)
        assert same(c2.interpolation_error, c.interpolation_error) and c2.min_slope == c.min_slope
    # A loaded curve serves a freshly built system equal to its own (potentials compare by value).
    c2 = hv.load(curve.save(tmp_path / "curve"))
    fresh = hv.FlowMap(issue_system(-0.05), h=1.0, curve=c2)
    phi, K = maps()["flow_normal"][1][:20], maps()["flow_normal"][2][:20]
    assert same_steps(fresh, maps()["flow_normal"][0], phi, K)


# ------------------------------------------------------------------ the format itself


def _write(path, doc, **arrays):
    """A hand-made file in the format (or not): the JSON document plus arrays."""
    text = doc if isinstance(doc, str) else json.dumps(doc)
    np.savez(path, __meta__=np.array(text), **arrays)
    return str(path)


def _doc(tree):
    return {"format": _serial.FORMAT, "version": hv.__version__, "meta": {}, "tree": tree}


def test_foreign_types_are_refused(tmp_path):
    marker = tmp_path / "pwned"
    attacks = {
        "record os:system": {"__record__": "os:system", "data": {"__dict__": {}}},
        "enum os:system": {"__enum__": "os:system", "value": f"touch {marker}"},
        # A hovering module imports os: the name must lead to a class defined in hovering, not
        # through the module's attributes to os.system.
        "enum through a hovering module": {"__enum__": "hovering._checks:os.system", "value": f"touch {marker}"},
        "dataclass through a hovering module": {"__dataclass__": "hovering._io.serial:json.JSONDecoder", "fields": {}},
        "dunder": {"__record__": "hovering:__builtins__.eval", "data": {"__dict__": {}}},
        "not a dataclass": {"__dataclass__": "hovering.truncated.maps:TruncatedMap", "fields": {}},
        "not an enum": {"__enum__": "hovering.truncated.maps:TruncatedMap", "value": 1},
        "no record": {"__record__": "hovering.truncated.maps:IterateResult", "data": {"__dict__": {}}},
        "unknown class": {"__record__": "hovering:NoSuchThing", "data": {"__dict__": {}}},
        "malformed name": {"__record__": "hovering.TruncatedMap", "data": {"__dict__": {}}},
    }
    for what, tree in attacks.items():
        path = _write(tmp_path / "a.npz", _doc(tree))
        with pytest.raises(ValueError, match=r"refusing to rebuild|cannot rebuild|malformed"):
            hv.load(path)
        assert not marker.exists(), what
    path = _write(tmp_path / "os.npz", _doc({"__record__": "os:system", "data": {"__dict__": {}}}))
    with pytest.raises(ValueError, match=r"refusing to rebuild type 'os:system': only hovering's own types"):
        hv.load(path)


def test_files_that_are_not_results_are_value_errors(tmp_path):
    cases = {}
    (tmp_path / "garbage.npz").write_bytes(os.urandom(256))
    cases["garbage"] = r"is not a hovering result file|cannot read"
    (tmp_path / "text.npz").write_text("hello, world\n")
    cases["text"] = r"is not a hovering result file"
    (tmp_path / "empty.npz").write_bytes(b"")
    cases["empty"] = r"is not a hovering result file|cannot read"
    np.save(tmp_path / "array.npy", np.arange(3))
    cases["array.npy"] = r"a single .npy array"
    np.savez(tmp_path / "plain.npz", x=np.arange(3))
    cases["plain"] = r"no __meta__ entry"
    np.savez(tmp_path / "meta_array.npz", __meta__=np.arange(3))
    cases["meta_array"] = r"not a string"
    _write(tmp_path / "badjson.npz", "{not json")
    cases["badjson"] = r"is not a hovering result file"
    _write(tmp_path / "format.npz", {"format": "something-else", "tree": None})
    cases["format"] = r"unknown result format 'something-else'"
    _write(tmp_path / "list.npz", [1, 2, 3])
    cases["list"] = r"unknown result format None"
    _write(tmp_path / "notree.npz", {"format": _serial.FORMAT})
    cases["notree"] = r"no tree"
    _write(tmp_path / "bare.npz", _doc([1, 2]))
    cases["bare"] = r"a bare list"
    _write(tmp_path / "node.npz", _doc({"__what__": 1}))
    cases["node"] = r"unknown node"
    _write(tmp_path / "array.npz", _doc({"__array__": "root.x"}))
    cases["array"] = r"the array 'root.x' is missing"
    _write(tmp_path / "fields.npz", _doc({"__dataclass__": "hovering.truncated.theory:Theory", "fields": {"eps": 1.0}}))
    cases["fields"] = r"Theory lacks the field 'Omega0'"
    _write(tmp_path / "extra.npz", _doc({"__dataclass__": "hovering.normal.flowmap:FlowSteps", "fields": {"bogus": 1}}))
    cases["extra"] = r"FlowSteps has fields \['bogus'\] this version does not know"
    _write(
        tmp_path / "record.npz",
        _doc({"__record__": "hovering.truncated.maps:TruncatedMap", "data": {"__dict__": {"eps": 0.3}}}),
    )
    cases["record"] = r"malformed result file \(TypeError: .*missing 2 required"
    _write(
        tmp_path / "values.npz",
        _doc(
            {
                "__record__": "hovering.truncated.maps:TruncatedMap",
                "data": {"__dict__": dict(eps=0.3, Omega0=1.0, theta_w=4.0, tau0=1.0, tau1=0.5, lam=0.5, K_max=1.0)},
            }
        ),
    )
    cases["values"] = r"theta_w"  # the constructor's own check
    with zipfile.ZipFile(tmp_path / "zip.npz", "w") as z:
        z.writestr("readme.txt", "not an array")
    cases["zip"] = r"no __meta__ entry"
    cases["missing"] = r"cannot read"
    cases["directory"] = r"cannot read"
    for name, msg in cases.items():
        path = tmp_path if name == "directory" else tmp_path / (name if name.endswith(".npy") else f"{name}.npz")
        with pytest.raises(ValueError, match=msg):
            hv.load(path)
    for bad in (None, 3, "", "a\0b"):
        with pytest.raises(ValueError, match="path must be a file path"):
            hv.load(bad)


def test_save_writes_whole_files_or_nothing(tmp_path):
    target = tmp_path / "r.npz"
    r = results()["iterate_truncated"]
    r.save(target)
    before = target.read_bytes()
    with pytest.raises(TypeError, match=r"root.x: cannot save a object"):
        hv.save({"x": object()}, target)
    with pytest.raises(ValueError, match="meta must be JSON-able"):
        r.save(target, meta={"when": object()})
    with pytest.raises(ValueError, match="meta must be a dict"):
        r.save(target, meta=[1, 2])
    assert target.read_bytes() == before and os.listdir(tmp_path) == ["r.npz"]
    with pytest.raises(ValueError, match=r"cannot write .*no_such_dir"):
        r.save(tmp_path / "no_such_dir" / "r.npz")
    (tmp_path / "d.npz").mkdir()
    with pytest.raises(ValueError, match="is a directory"):
        r.save(tmp_path / "d")
    for bad in (None, 1.5, "", " ", "x\0y"):
        with pytest.raises(ValueError, match="path must be a file path"):
            r.save(bad)
    obj, meta = hv.load(r.save(target, meta={"run": 3, "note": "paper figure"}), meta=True)
    assert meta == {"run": 3, "note": "paper figure"} and same(obj, r)


def test_tree_corner_cases(tmp_path):
    # NumPy scalars of every kind, non-finite floats, nested containers, non-string keys, and dict
    # keys that look like another entry's path (each array still comes back as itself).
    obj = {
        "flag": np.bool_(True),
        "i": np.int64(-3),
        "f": np.float32(0.5),
        "inf": -np.inf,
        "nan": float("nan"),
        "a.b": np.arange(3),
        "a": {"b": np.arange(5.0)},
        "t": (1, (2.5, "x"), [None, True]),
        "keys": {1: "one", (2, 3): np.zeros(2, dtype=np.int8), Region.UPPER: "enum key"},
        "strings": np.array(["0", "u", "R1"], dtype=object),
        "empty": np.zeros((0, 4)),
    }
    got = hv.load(hv.save(obj, tmp_path / "tree"))
    assert got["flag"] is True and got["i"] == -3 and got["f"] == 0.5 and got["inf"] == -np.inf and np.isnan(got["nan"])
    assert same(got["a.b"], np.arange(3)) and same(got["a"]["b"], np.arange(5.0))
    assert got["t"] == (1, (2.5, "x"), [None, True])
    assert got["keys"][1] == "one" and same(got["keys"][(2, 3)], np.zeros(2, dtype=np.int8))
    assert got["keys"][Region.UPPER] == "enum key"
    assert got["strings"].dtype == object and list(got["strings"]) == ["0", "u", "R1"]
    assert got["empty"].shape == (0, 4)


def test_only_hovering_types_are_written(tmp_path):
    @dataclasses.dataclass
    class Mine:
        x: int = 1

    class MyHarmonic(hv.Harmonic):
        pass

    for obj, msg in (
        (Mine(), r"cannot save a .*Mine to NPZ: only hovering's own classes"),
        (MyHarmonic(1.0), r"cannot save a .*MyHarmonic to NPZ"),
        (np.array([object()]), r"arrays of Python objects"),
        ({"c": 1j}, r"root.c: cannot save a complex"),
    ):
        with pytest.raises(TypeError, match=msg):
            hv.save(obj, tmp_path / "x")
    assert os.listdir(tmp_path) == []


def test_public_api():
    assert hv.save is _serial.save and hv.load is _serial.load and {"save", "load"} <= set(hv.__all__)
    for cls in (
        hv.IterateResult,
        hv.ReturnMapResult,
        hv.FlowSteps,
        hv.HoveringArea,
        hv.CriticalCurve,
        hv.CornerCurves,
        hv.MapComparison,
        hv.Theory,
        hv.TangentialCurve,
    ):
        assert issubclass(cls, _serial.Saveable) and cls.save.__doc__
