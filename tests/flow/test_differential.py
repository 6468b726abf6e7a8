"""Differential layer: every stepper against an independent integrator on random systems.

Systems are drawn by Hypothesis over what a user can build: Harmonic or Tan potentials with
random frequencies (slow ones included: omega down to 0.15, where a return spans long Taylor
steps), Tan wells' widths, random polynomial couplings with eps from weak to strong, the three
geometries, and energies from low to near a Tan well's edge. Each start's first return is
compared with ``tests/helpers/scipy_flow.py`` (SciPy DOP853 at rtol 1e-13 with its own complete
event search; it imports nothing of hovering).

The claim checked is the one a user relies on: an OK return of any stepper is the reference's
return (same itinerary, time and state within the stated tolerance), or the stepper says it is
not (a non-OK status). A skipped or invented event moves the return time by a fraction of a
period (> 0.1 on these systems); accuracy differences at rtol 1e-10 are ~1e-8 (measured: the
largest time difference over the derandomised run is given in each message). So the bound is
1e-5 in time and in the state, loose for accuracy, tight for any skipped crossing.

Derandomised by default (the same examples each run); ``HOVERING_FUZZ=N`` draws N new ones (a long
search: ``HOVERING_FUZZ=200 python -m pytest tests/flow/test_differential.py``; the oracle takes
~0.1 s per return), and any failure it finds is pinned as an ``@example``.
"""

from __future__ import annotations

import math
import os

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import hovering as hv
from helpers import scipy_flow

# HOVERING_FUZZ=N: N random examples (as tests/package/test_hypothesis_api.py), else 10 fixed ones
_FUZZ = os.environ.get("HOVERING_FUZZ", "")
EXAMPLES = max(int(_FUZZ), 10) if _FUZZ.isdigit() else (200 if _FUZZ else 10)

# time and state tolerance of an OK return against the reference (see the module docstring)
TOL = 1e-5
# The same at the loose tolerance LOOSE_RTOL, where a GSL step spans a fifth of a slow period and the
# step test for two sign changes inside it matters most (it once skipped returns there: see
# test_exact_flow.py). An OK return at rtol 1e-6 is ~1e-5 off after tens of steps; a skipped or
# invented crossing > 0.1.
LOOSE_RTOL, LOOSE_TOL = 1e-6, 1e-3
COMPARED: list = []  # time differences of the OK returns compared (reported by the last test)


@st.composite
def systems(draw):
    """A random system (hovering's and the oracle's description of it), an energy, and 2 starts."""

    def potential():
        if draw(st.booleans()):
            w = draw(st.floats(0.15, 2.0))
            return hv.Harmonic(w), scipy_flow.harmonic(w), w
        w, a = draw(st.floats(0.5, 1.6)), draw(st.floats(0.2, 0.8))
        return hv.Tan(w, a), scipy_flow.tan(w, a), w

    (V1, R1, w1), (V2, R2, w2) = potential(), potential()
    terms = {(1, 1): 1.0}
    if draw(st.booleans()):
        i, j = draw(st.integers(1, 3)), draw(st.integers(1, 3))
        terms[(i, j)] = draw(st.floats(-0.5, 0.5))
    # weak to strong coupling, relative to the oscillators' stiffness (|eps| up to 0.9 w1 w2: the
    # bilinear part keeps the quadratic form positive-definite)
    eps = draw(st.sampled_from([-1, 1])) * 10 ** draw(st.floats(-3, math.log10(0.9))) * w1 * w2
    geometry = draw(st.sampled_from(["step", "wall", "none"]))
    qw1, qw2 = draw(st.floats(-1.3, -0.3)), draw(st.floats(-1.0, -0.2))
    h = 10 ** draw(st.floats(-0.7, 0.8))
    sys = hv.StepSystem(V1=V1, V2=V2, coupling=hv.Polynomial(terms), eps=eps, qw1=qw1, qw2=qw2, geometry=geometry)
    starts = [(draw(st.floats(-3.1, 3.1)), draw(st.floats(0.02, 1.0))) for _ in range(2)]
    return sys, (R1, R2, terms, eps, geometry, qw1, qw2), h, starts


def _steppers(sys, terms):
    """(stepper, rtol, tolerance) of every stepper that applies to the system: the GSL ones checked
    here at the default and a loose tolerance, Taylor, the closed form."""
    out = [("rk8pd", 1e-10, TOL), ("rkck", 1e-10, TOL), ("taylor", 1e-10, TOL)]
    out += [("rk8pd", LOOSE_RTOL, LOOSE_TOL), ("rkck", LOOSE_RTOL, LOOSE_TOL)]
    linear = all(isinstance(v, hv.Harmonic) for v in (sys.V1, sys.V2)) and set(terms) <= {(1, 1)}
    if linear:
        out.append(("exact", 1e-10, TOL))
    return out


@settings(
    max_examples=EXAMPLES,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
@given(systems())
def test_every_stepper_returns_the_references_crossing_or_says_it_cannot(drawn):
    sys, (R1, R2, terms, eps, geometry, qw1, qw2), h, starts = drawn
    sec = hv.Section(sys, h)
    # starts as fractions of the action range that has points of Sigma_h at this energy
    I_top = sys.V2.action(0.95 * h) if np.isfinite(sys.V2.action(0.95 * h)) else 1.0
    th = np.array([s[0] for s in starts])
    I = np.array([s[1] * I_top for s in starts])
    z0, ok, _ = sec._points(th, I)
    if not ok.any():
        return
    th, I, z0 = th[ok], I[ok], z0[ok]
    refs = []
    for z in z0:
        # t_max bounds the oracle's work on a runaway (a coupling unbounded below); step_fraction
        # 64 keeps its dense output at ~1e-13, far below TOL, at half the cost of the default
        refs.append(
            scipy_flow.reference_return(R1, R2, terms, eps, geometry, qw1, qw2, z, t_max=300.0, step_fraction=64)
        )
    for stepper, rtol, tol in _steppers(sys, terms):
        r = sec.return_map(th, I, stepper=stepper, rtol=rtol, atol=rtol, max_steps=200_000, n_threads=1)
        for k, ref in enumerate(refs):
            if r.status[k] != hv.FlowStatus.OK:
                continue  # the stepper says it is not a return: allowed (the reference may disagree)
            where = f"{stepper} at rtol {rtol} on {sys!r}, h = {h}, start ({th[k]!r}, {I[k]!r}): {r.time[k]} vs {ref}"
            if ref["status"] in ("failed", "limit"):
                continue  # DOP853 gave up (a runaway on a coupling unbounded below): no verdict
            assert ref["status"] == "ok", where
            # the reference knows no chart: an OK return must be the reference's crossing
            assert abs(r.time[k] - ref["time"]) < tol, where
            if rtol == 1e-10:
                COMPARED.append(abs(r.time[k] - ref["time"]))
            assert np.max(np.abs(r.z[k] - ref["z"])) < tol * max(1.0, np.max(np.abs(ref["z"]))), where
            if geometry != "none":
                assert r.itinerary[k].replace("0", "").replace("u", "") == ref["itinerary"], where


@pytest.mark.parametrize("eps", [0.035, -0.035])
def test_the_issues_beat_system_skips_no_return_in_the_wall_geometry(eps):
    # Harmonic(0.2) x Harmonic(0.2), bilinear, wall at qw1 = -1, h = 0.3 (an issue's report: taylor
    # returned a later crossing for 65 of 2,000 starts at eps = 0.035, 48 at -0.035). The closed
    # form is checked against the oracle on 12 starts, then every stepper against it on 2,000.
    sys = hv.StepSystem(
        V1=hv.Harmonic(0.2), V2=hv.Harmonic(0.2), coupling=hv.Bilinear(), eps=eps, qw1=-1.0, qw2=-0.5, geometry="wall"
    )
    sec = hv.Section(sys, 0.3)
    rng = np.random.default_rng(3)
    th, I = rng.uniform(-3.1, 3.1, 3000), rng.uniform(0.01, 1.4, 3000)
    _, ok, _ = sec._points(th, I)
    th, I = th[ok][:2000], I[ok][:2000]
    exact = sec.return_map(th, I, stepper="exact")
    R = scipy_flow.harmonic(0.2)
    z0 = sec.point(th[:12], I[:12])
    for k in range(12):
        ref = scipy_flow.reference_return(R, R, "bilinear", eps, "wall", -1.0, -0.5, z0[k])
        assert abs(exact.time[k] - ref["time"]) < 1e-9, (k, exact.time[k], ref)
    for stepper in ("taylor", "rk8pd", "rkck"):
        for rtol in (1e-6, 1e-10, 1e-14):
            r = sec.return_map(th, I, stepper=stepper, rtol=rtol, atol=rtol)
            assert np.array_equal(r.status, exact.status), (stepper, rtol)
            both = r.status == hv.FlowStatus.OK
            # accuracy at rtol 1e-6 over returns ~30 long: ~1e-5; a skipped dip: > 1
            assert np.max(np.abs(r.time - exact.time)[both]) < 1e-3, (stepper, rtol)


def test_the_issues_strong_coupling_start_returns_at_the_first_maximum():
    # eps = -0.5 on the same system, start (-3, 0.5): exact, rk8pd and rkck return at t = 2.988;
    # taylor at rtol 1e-6 reported OK at t = 5.971 before its steps held one event velocity root.
    sys = hv.StepSystem(
        V1=hv.Harmonic(0.2), V2=hv.Harmonic(0.2), coupling=hv.Bilinear(), eps=-0.5, qw1=-1.0, qw2=-0.5, geometry="wall"
    )
    sec = hv.Section(sys, 0.3)
    R = scipy_flow.harmonic(0.2)
    ref = scipy_flow.reference_return(R, R, "bilinear", -0.5, "wall", -1.0, -0.5, sec.point([-3.0], [0.5])[0])
    assert ref["status"] == "ok" and abs(ref["time"] - 2.988) < 1e-3
    for stepper in ("exact", "rk8pd", "rkck", "taylor"):
        r = sec.return_map([-3.0], [0.5], stepper=stepper, rtol=1e-6, atol=1e-6)
        # OK at the reference's crossing, or not OK at all (never a later crossing)
        assert r.status[0] != hv.FlowStatus.OK or abs(r.time[0] - ref["time"]) < 1e-4, (stepper, r.time[0])


def test_the_oracle_gives_up_within_its_budget_of_evaluations():
    # An orbit whose steps shrink without bound (toward a Tan well's edge, off along a coupling
    # unbounded below) once ran the oracle for more than 15 minutes and GBs under HOVERING_FUZZ=40.
    # It now stops with "limit" (no verdict) once its budget is spent: checked here with a budget
    # below what an ordinary return needs (3,900-6,000 evaluations; the default is 1e7, and 2e5
    # per chunk of about a period).
    R = scipy_flow.harmonic(1.0)
    sec = hv.Section(
        hv.StepSystem(V1=hv.Harmonic(1.0), V2=hv.Harmonic(1.0), coupling=hv.Bilinear(), eps=0.05, geometry="wall"), 1.0
    )
    z0 = sec.point([0.3], [0.2])[0]
    full = scipy_flow.reference_return(R, R, "bilinear", 0.05, "wall", -1.0, -0.5, z0, step_fraction=64)
    assert full["status"] == "ok" and full["evaluations"] > 1000, full
    cut = scipy_flow.reference_return(
        R, R, "bilinear", 0.05, "wall", -1.0, -0.5, z0, step_fraction=64, max_evaluations=500
    )
    assert cut["status"] == "limit" and cut["evaluations"] == 501 and cut["time"] < full["time"], cut


def test_an_ok_return_is_the_point_its_coordinates_name():
    # paper.system(eps=-0.3): some returns end at a maximum of q1 that Sigma_h's chart does not
    # hold (q1 < 0); they are OFF_SECTION, and every OK return maps back onto its own state.
    sec = hv.Section(hv.paper.system(eps=-0.3), 1.0)
    rng = np.random.default_rng(0)
    th, I = rng.uniform(-3, 3, 3000), rng.uniform(0.01, 1.2, 3000)
    _, ok, _ = sec._points(th, I)
    th, I = th[ok], I[ok]
    for stepper in ("rk8pd", "taylor"):
        r = sec.return_map(th, I, stepper=stepper)
        off = r.status == hv.FlowStatus.OFF_SECTION
        assert off.sum() > 5  # the case exists (measured: 22 of 2,119)
        assert np.all(np.isfinite(r.z[off]))  # where it stopped is kept
        good = r.status == hv.FlowStatus.OK
        back = sec.point(r.theta[good], r.I[good])
        # the chart's point is the return's state: the same root, to the return's energy error
        assert np.max(np.abs(back[:, 0] - r.z[good, 0])) < 1e-7


def test_the_random_systems_were_compared():
    # Runs after the property test in file order; alone (-k), it runs that test's examples first.
    if not COMPARED:
        test_every_stepper_returns_the_references_crossing_or_says_it_cannot()
    # the derandomised draw compares dozens of OK returns (a draw that compared none tested nothing)
    assert len(COMPARED) >= 20, len(COMPARED)
    print(f"{len(COMPARED)} OK returns compared, largest time difference {max(COMPARED):.2e}")
