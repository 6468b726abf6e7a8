"""One representation of a map's parameters: each class's ``_to_record`` / ``_from_record`` is what
pickle, NPZ files and checkpoint keys use; files written before (tests/data/legacy, written by
main at 22d49ca with tests/data/legacy/make_legacy.py) still load, and step as the objects that
wrote them did: bit for bit for the truncated maps, within the tolerance for the flow maps (whose
numerics change between versions; bit for bit as the same constructor call builds them now)."""

from __future__ import annotations

import copy
import io
import pickle
from pathlib import Path

import numpy as np
import pytest

import hovering as hv
from hovering import paper
from hovering._io import records as _pickle
from hovering._io import serial as _serial
from hovering.parallel.checkpoint import canonical

LEGACY = Path(__file__).resolve().parents[1] / "data" / "legacy"
MAPS = ("truncated", "truncated_capped", "family", "flow_normal", "flow_section")


def objects() -> dict:
    """One object of each class with a record."""
    sys = paper.system(-0.05)
    fm = hv.FlowMap(sys, h=1.0)
    m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=2.0)
    return {
        "truncated": m,
        "family": hv.TruncatedFamily.from_map(
            m, np.concatenate([-(np.linspace(1, 0, 20) ** 2), [0.5, 1.0]]), forcing=(1.0, 0.2)
        ),
        "harmonic": hv.Harmonic(1.3),
        "tan": hv.Tan(1.4, 0.7),
        "numerical": hv.Numerical(hv.Tan(1.1, 0.3)),
        "bilinear": hv.Bilinear(),
        "polynomial": hv.Polynomial({(1, 1): 1.0, (2, 0): -0.5}),
        "system": sys,
        "section": fm.section,
        "curve": fm.curve,
        "flowmap": fm,
        "onset": hv.onset_parameters(sys, 1.0),
    }


@pytest.mark.parametrize("name", list(objects()))
def test_pickle_is_the_record(name):
    obj = objects()[name]
    fn, args = obj.__reduce__()
    assert fn is _pickle.restore_record and args[0] is type(obj)
    assert _serial.record_key(args[1]) == _serial.record_key(obj._to_record())
    back = pickle.loads(pickle.dumps(obj))
    assert type(back) is type(obj) and _serial.record_key(back) == _serial.record_key(obj)
    assert canonical(_serial.record_key(copy.deepcopy(obj))) == canonical(_serial.record_key(obj))


def test_record_keys_name_parameters_not_caches():
    fm = objects()["flowmap"]
    before = _serial.record_key(fm)
    fm.forcing_coefficients()  # fills the forcing cache, which the record carries
    assert _serial.record_key(fm) == before and fm._to_record()["forcing"] is not None
    other = hv.FlowMap(fm.sys, h=1.0, rtol=1e-9)
    assert _serial.record_key(other) != before
    m = objects()["truncated"]
    assert _serial.record_key(m) == _serial.record_key(hv.TruncatedMap(**m.params))
    assert _serial.record_key(m) != _serial.record_key(m.with_eps(0.31))


def _unpickle(data: bytes):
    """pickle.loads of a legacy file. The files were written under numpy 2, whose array pickles
    name ``numpy._core``; numpy < 2 calls that module ``numpy.core`` and cannot read them (numpy's
    own limit across its majors, not the records'), so there the names are read as numpy 1's."""
    if np.lib.NumpyVersion(np.__version__) >= "2.0.0":
        return pickle.loads(data)

    class Numpy1(pickle.Unpickler):
        def find_class(self, module, name):
            if module == "numpy._core" or module.startswith("numpy._core."):
                module = "numpy.core" + module[len("numpy._core") :]
            return super().find_class(module, name)

    return Numpy1(io.BytesIO(data)).load()


@pytest.mark.parametrize("name", MAPS)
@pytest.mark.parametrize("suffix", [".pkl", ".npz"])
def test_files_written_before_load_and_step_as_they_did(name, suffix):
    expected = np.load(LEGACY / "expected.npz")
    path = LEGACY / f"{name}{suffix}"
    m = _unpickle(path.read_bytes()) if suffix == ".pkl" else hv.load(path)
    phi, K = expected["phi"], expected[f"{name}.K"]
    p1, K1 = m.step(phi, K)
    if isinstance(m, hv.FlowMap):
        # The flow's numerics move on between versions (0.3.0: verified returns, Sigma_h's point
        # from another Newton start), so a loaded flow map steps within its rtol of what it did,
        # and bit for bit as the map built now from what the file holds: the system, the energy,
        # the coordinates, the tangential curve (of the normal coordinates, as computed then) and
        # the integrator options it was written with (rk8pd, the default then; "auto" now).
        rtol = m.integrator_options["rtol"]
        assert np.allclose(p1, expected[f"{name}.phi1"], rtol=0, atol=100 * rtol, equal_nan=True)
        assert np.allclose(K1, expected[f"{name}.K1"], rtol=0, atol=100 * rtol, equal_nan=True)
        eps, coordinates = {"flow_normal": (-0.05, "normal"), "flow_section": (0.05, "section")}[name]
        system = hv.StepSystem(
            V1=hv.Harmonic(1.0),
            V2=hv.Tan(1.4, 0.7),
            coupling=hv.Bilinear(),
            eps=eps,
            qw1=-1.0,
            qw2=-0.5,
            geometry="step",
        )
        assert m.integrator_options["stepper"] == ("rk8pd" if name == "flow_normal" else "rkck")
        built = hv.FlowMap(system, h=1.0, coordinates=coordinates, curve=m.curve, **m.integrator_options)
        p2, K2 = built.step(phi, K)
        assert np.array_equal(p1, p2, equal_nan=True) and np.array_equal(K1, K2, equal_nan=True)
    else:
        # The truncated maps' numbers have not changed: bit for bit as the objects that wrote them.
        assert np.array_equal(p1, expected[f"{name}.phi1"], equal_nan=True)
        assert np.array_equal(K1, expected[f"{name}.K1"], equal_nan=True)
    # And a loaded map pickles by its record now, and round-trips.
    assert type(m).__reduce__(m)[0] is _pickle.restore_record
    again = pickle.loads(pickle.dumps(m))
    assert np.array_equal(again.step(phi, K)[1], K1, equal_nan=True)


@pytest.mark.parametrize("name", ["curve", "section", "system_poly", "hovering_area"])
def test_other_files_written_before_load(name):
    a = _unpickle((LEGACY / f"{name}.pkl").read_bytes())
    b = hv.load(LEGACY / f"{name}.npz")
    assert type(a) is type(b)
    if name == "hovering_area":
        assert a.area == b.area > 0 and np.array_equal(a.hovering, b.hovering)
    elif name == "curve":
        assert np.array_equal(a.values, b.values) and a(0.3) == b(0.3)
    else:
        assert a == b
