"""The default stepper "auto" (taylor where Taylor's method applies, else rk8pd), resolved once in the
core and visible to the user; and the error floor of one return on the linear system against its
exact solution (docs: Accuracy, "Error floor")."""

import numpy as np
import pytest

import hovering as hv
from helpers.linear_reference import QW1, QW2, LinearFlow
from hovering import _core, paper
from hovering.flow import STEPPERS

THETA, I = np.array([0.0, 1.0, 2.0, -2.5]), np.array([0.3, 0.3, 0.45, 0.2])


def custom_system():
    """The README system with V1 defined in Python: Taylor's method has no recurrences for it."""
    v1 = hv.CustomPotential(lambda q: 0.5 * q * q, lambda q: q)
    return hv.StepSystem(v1, hv.Tan(1.4, 0.7), hv.Bilinear(), eps=-0.05, qw1=-1.0, qw2=-0.5)


def test_the_default_is_auto_listed_first():
    assert _core.flow.FlowOptions().stepper == "auto" and STEPPERS[0] == "auto"
    assert hv.flow.flow_options().stepper == "auto"


def test_the_default_is_taylor_on_a_polynomial_field_and_says_so():
    sec = hv.Section(paper.system(-0.05), h=1.0)
    default, taylor = sec.return_map(THETA, I), sec.return_map(THETA, I, stepper="taylor")
    assert default.stepper == "taylor" and sec.return_map(THETA, I, stepper="rk8pd").stepper == "rk8pd"
    # The same integration, bit for bit: "auto" is a name for taylor here, nothing else.
    np.testing.assert_array_equal(default.z, taylor.z)
    np.testing.assert_array_equal(default.steps, taylor.steps)
    fm = hv.FlowMap(paper.system(-0.05), h=1.0, coordinates="section")
    assert fm.integrator_options["stepper"] == "taylor" and "stepper='taylor'" in repr(fm)
    assert _core.flow.FlowOptions().resolved_for(sec.sys.core).stepper == "taylor"


def test_the_default_is_rk8pd_where_taylor_does_not_apply():
    sys = custom_system()
    sec = hv.Section(sys, h=1.0)
    default = sec.return_map(THETA, I)
    assert default.stepper == "rk8pd"
    np.testing.assert_array_equal(default.z, sec.return_map(THETA, I, stepper="rk8pd").z)
    assert _core.flow.FlowOptions().resolved_for(sys.core).stepper == "rk8pd"
    fm = hv.FlowMap(sys, h=1.0, coordinates="section")
    assert fm.integrator_options["stepper"] == "rk8pd" and "stepper='rk8pd'" in repr(fm)
    # Naming taylor on it is still refused, naming the alternative.
    with pytest.raises(ValueError, match="stepper 'taylor' needs V1 and V2 each Harmonic or Tan.*rk8pd"):
        sec.return_map(THETA, I, stepper="taylor")


@pytest.mark.parametrize("stepper", [None, "rk8pd"])
def test_a_saved_flow_map_reloads_with_the_stepper_it_ran(tmp_path, stepper):
    # A map built with the default saves the stepper that ran (never "auto"), and one saved with an
    # explicit stepper (as every map saved before "auto" existed) reloads meaning the same.
    fm = hv.FlowMap(paper.system(-0.05), h=1.0, coordinates="section", stepper=stepper)
    back = hv.load(hv.save(fm, tmp_path / "fm"))
    assert back.integrator_options == fm.integrator_options
    assert back.integrator_options["stepper"] == (stepper or "taylor")
    np.testing.assert_array_equal(np.array(back.step(THETA, I)), np.array(fm.step(THETA, I)))


@pytest.mark.parametrize("bad", ["euler", "Taylor", "", 3])
def test_a_bad_stepper_name_names_every_choice(bad):
    sec = hv.Section(paper.system(-0.05), h=1.0)
    with pytest.raises(ValueError, match=r"stepper must be one of auto \(the default: taylor where it applies"):
        sec.return_map(THETA, I, stepper=bad)
    with pytest.raises(ValueError, match="got '"):
        hv.FlowMap(paper.system(-0.05), h=1.0, coordinates="section", stepper=bad)


@pytest.mark.parametrize("geometry", ["step", "wall"])
def test_linear_error_floor_against_the_exact_solution(geometry):
    # Harmonic x Harmonic with a bilinear coupling is linear: its exact return (normal modes, events
    # refined at 40 digits: tests/helpers/linear_reference.py) is the reference, not the core's
    # "exact" stepper, whose closed-form steps carry their own rounding (3.5e-14 over these starts).
    # Measured with taylor at rtol 1e-15 over 200 random starts: 5.5e-15 (step) / 5.8e-15 (wall),
    # at impacts (the located impact's time error times the saltation); without impact 1.6e-15.
    # Bound 1e-14 (issue 33's target): twice the measured worst, far below rk8pd's 1.6e-14 at
    # rtol 1e-16 and the 3.5e-14 of the former reference.
    sys = hv.StepSystem(
        hv.Harmonic(1.0), hv.Harmonic(1.3), hv.Bilinear(), eps=-0.05, qw1=QW1, qw2=QW2, geometry=geometry
    )
    rng = np.random.default_rng(1)
    z0, ok, _ = _core.flow.section_points(sys.core, 1.0, rng.uniform(-np.pi, np.pi, 800), rng.uniform(0.02, 0.6, 800))
    z0 = np.ascontiguousarray(z0[ok][:200])
    assert len(z0) == 200
    flow = LinearFlow(1.0, 1.3, -0.05)
    ref = [flow.ret(z, geometry) for z in z0]
    zr = np.array([[float(x) for x in r[0]] for r in ref])
    d = _core.flow.return_maps(sys.core, z0, hv.flow.flow_options(rtol=1e-15, atol=1e-15, stepper="taylor"), 1)
    assert (d["status"] == 0).all()
    assert sum(r[2] != "none" for r in ref) >= 20  # the floor covers impacts, not only smooth returns
    assert np.max(np.abs(d["z"] - zr)) <= 1e-14
    assert np.max(np.abs(d["time"] - np.array([float(r[1]) for r in ref]))) <= 1e-14
