"""The hard-case catalogue of the flow (README "Hard cases"): grazing at every depth on both walls,
corner hits exactly and near, energies at and around the step energy, walls next to the Tan
singularity, and what a stopped orbit reports.

At eps = 0 each oscillator keeps its energy and moves on its own angle, so every case here has an
exact answer in closed form (the potentials' action-angle variables), independent of the
integrator: the time t1 = arccos(qw1 / A1) / omega1 at which q1 reaches the right wall, the angle
theta_w2 at which q2 reaches the upper wall, and the angle advance omega2(H2) t of oscillator 2.
"""

from __future__ import annotations

import numpy as np
import pytest

import hovering
from hovering import FlowStatus, Harmonic, Section, StepSystem, paper
from hovering.paper import QW1, QW2, V1, V2, H

RTOL = 1e-12


def wrap(a):
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


@pytest.fixture(scope="module")
def sec():
    return Section(StepSystem(V1=V1, V2=V2, qw1=QW1, qw2=QW2, geometry="step"), H)


def _one(sec, theta, I, **kw):
    kw = {"rtol": RTOL, "atol": RTOL, **kw}
    return sec.return_map([theta], [I], **kw)


# ------------------------------------------------------------------------------------------------
# grazing: the error of an impact at depth d is amplified by 1/sqrt(d) (the impact time of a
# parabola-like dip moves by delta / sqrt(2 |q''| d) for a position error delta), so the bound is
# C rtol / sqrt(d) with C = 10 (measured: 0.24 on the upper wall, 0.03 on the right wall).

DEPTHS = [1e-4, 1e-6, 1e-8, 1e-10, 1e-11, 1e-12, 1e-13, 1e-14]


def _unverifiable(r, d, stepper):
    """Whether a shallow impact's return was reported IMPRECISE, where that is the honest answer.

    The return is verified (its impact amplifies errors ~1/sqrt(d)); at rtol 1e-12 the tighter
    traces stop at the rounding floor: rk8pd's 1e-14 allows one trace 100x tighter, whose error
    amplified by 1/sqrt(d) >= 100 at d <= 1e-4 (measured 0.24 rtol / sqrt(d) at rtol 1e-12) stays
    above the band; taylor's 1e-15 allows two, enough down to d ~ 1e-6. IMPRECISE says so.
    """
    if r.status[0] != FlowStatus.IMPRECISE:
        return False
    assert d <= (1e-4 if stepper == "rk8pd" else 1e-8), (d, r.status[0])
    return True


@pytest.mark.parametrize("stepper", ["rk8pd", "taylor"])
@pytest.mark.parametrize("d", DEPTHS)
def test_grazing_the_right_wall_at_depth(sec, d, stepper):
    # q1's minimum is qw1 - d while q2 sits at its own minimum (below qw2: the wall is there).
    h1 = V1.V(QW1 - d)
    H2 = H - h1
    I, W = V2.action(H2), V2.frequency(H2)
    th0 = float(wrap(np.pi - W * np.pi))
    r = _one(sec, th0, I, stepper=stepper)
    if d >= 1e-11 and _unverifiable(r, d, stepper):
        return
    if d >= 1e-11:  # deeper than grazing_tol = 1e-12: a reflection, with the exact return
        assert r.status[0] == FlowStatus.OK and r.itinerary[0] == "R"
        t1 = np.arccos(QW1 / np.sqrt(2 * h1))
        assert abs(wrap(r.theta[0] - (th0 + 2 * W * t1))) <= 10 * RTOL / np.sqrt(d)
        assert abs(r.I[0] - I) <= 1e-12
    elif d <= 1e-13:  # within grazing_tol: a tangential touch, reported as such
        assert r.status[0] == FlowStatus.GRAZING
        assert abs(r.z[0, 0] - QW1) <= 2e-12 and abs(r.z[0, 1]) <= 1e-5  # at the wall, p1 ~ sqrt(d)
    else:  # d == grazing_tol: the boundary itself; either answer (or IMPRECISE), never another one
        assert r.status[0] in (FlowStatus.OK, FlowStatus.GRAZING, FlowStatus.IMPRECISE)


@pytest.mark.parametrize("stepper", ["rk8pd", "taylor"])
@pytest.mark.parametrize("d", DEPTHS)
def test_grazing_the_upper_wall_at_depth(sec, d, stepper):
    # q2's minimum is qw2 - d while q1 is at its minimum, left of qw1 (the upper wall is there).
    H2 = V2.V(QW2 - d)
    I, W = V2.action(H2), V2.frequency(H2)
    th0 = float(wrap(np.pi - W * np.pi))
    r = _one(sec, th0, I, stepper=stepper)
    if d >= 1e-11 and _unverifiable(r, d, stepper):
        return
    if d >= 1e-11:
        assert r.status[0] == FlowStatus.OK and r.itinerary[0] == "1"
        # the reflection maps theta_w2 to -theta_w2: the angle jumps by -2 theta_w2
        expected = th0 + 2 * np.pi * W - 2 * V2.angle_of(QW2, H2)
        assert abs(wrap(r.theta[0] - expected)) <= 10 * RTOL / np.sqrt(d)
        assert abs(r.I[0] - I) <= 1e-12
    elif d <= 1e-13:
        assert r.status[0] == FlowStatus.GRAZING
        assert abs(r.z[0, 2] - QW2) <= 2e-12
    else:
        assert r.status[0] in (FlowStatus.OK, FlowStatus.GRAZING, FlowStatus.IMPRECISE)


# ------------------------------------------------------------------------------------------------
# corners: q1 reaches qw1 at t1 while q2 = qw2 + delta. Within corner_tol (1e-10) of the corner the
# orbit stops there (CORNER); beyond it, below the corner the right wall reflects ('R'), above it
# the particle passes over the step and q2, still falling, meets the upper wall ('1').


@pytest.mark.parametrize(
    "delta", [0.0, 1e-15, -1e-15, 1e-13, -1e-13, 1e-11, -1e-11, 1e-9, -1e-9, 1e-6, -1e-6, 1e-3, -1e-3]
)
def test_corner_hits_exactly_and_near(sec, delta):
    H2 = 0.35
    I, W = V2.action(H2), V2.frequency(H2)
    t1 = np.arccos(QW1 / np.sqrt(2 * (H - H2)))
    th0 = float(wrap(V2.angle_of(QW2 + delta, H2) - W * t1))
    r = _one(sec, th0, I, rtol=1e-13, atol=1e-13)
    if abs(delta) < 1e-10:
        assert r.status[0] == FlowStatus.CORNER
        # stopped at whichever wall it met first, within corner_tol of the other
        assert max(abs(r.z[0, 0] - QW1), abs(r.z[0, 2] - QW2)) <= 1e-10
        assert r.time[0] == pytest.approx(t1, abs=1e-9)  # where it stopped, not 0
    else:
        assert r.status[0] == FlowStatus.OK
        assert r.itinerary[0] == ("R" if delta < 0 else "1")


# ------------------------------------------------------------------------------------------------
# energies at the step energy h_w = V1(qw1) + V2(qw2) (the corner's energy: the particle at rest
# in the corner) and 1e-12 around it: the section exists, returns are regular or stop with a
# status, and the energy is kept.


@pytest.mark.parametrize("dh", [-1e-12, 0.0, 1e-12])
def test_energies_at_the_step_energy(dh):
    sys = paper.system(0.0)
    h = sys.step_energy + dh
    s = Section(sys, h)
    th = np.linspace(-3.1, 3.1, 40)
    I = np.full(40, V2.action(V2.V(QW2)))  # the corner's torus of oscillator 2
    r = s.return_map(th, I, rtol=RTOL, atol=RTOL)
    assert set(np.unique(r.status)) <= {FlowStatus.OK, FlowStatus.CORNER, FlowStatus.GRAZING, FlowStatus.OFF_SECTION}
    ok = r.status == FlowStatus.OK
    assert ok.sum() >= 20
    assert np.max(r.energy_error[ok]) < 1e-12
    # eps = 0: I is conserved by every return, impacts included
    assert np.max(np.abs(r.I[ok] - I[ok])) < 1e-12
    # the FlowMap (section coordinates) is constructible there; its onset parameters are refused,
    # with the reason in onset_error (at or below h_w the tangential band does not exist; 1e-12
    # above it tau1 is not resolved: README, smallest accepted h - h_w ~7e-10), never wrong
    fm = hovering.FlowMap(sys, h, coordinates="section")
    assert fm.h == h and fm.onset is None
    assert ("must exceed the step energy" if dh <= 0 else "below the resolution of the step energy") in fm.onset_error


# ------------------------------------------------------------------------------------------------
# walls next to the Tan singularity, loose tolerances, high energy: the stepper must never report a
# state outside the well (|q2| >= pi / (2 alpha)); an orbit that cannot stay inside says so.


@pytest.mark.parametrize("gap", [None, 1e-6, 1e-8])
@pytest.mark.parametrize("stepper", ["rkck", "rkf45", "rk8pd", "taylor"])
def test_states_outside_the_tan_well_are_never_reported(gap, stepper):
    qlim = np.pi / (2 * V2.alpha)
    qw2 = QW2 if gap is None else -(1 - gap) * qlim
    sys = StepSystem(V1=V1, V2=V2, qw1=QW1, qw2=qw2, geometry="step")
    h = 1000.0
    s = Section(sys, h)
    th = np.linspace(-3, 3, 40)
    I = np.array([V2.action(e) for e in np.linspace(0.01 * h, 0.999 * h, 40)])
    r = s.return_map(th, I, rtol=1e-2, atol=1e-2, stepper=stepper, max_steps=100_000)
    assert np.all(np.abs(r.z[:, 2]) < qlim) and np.all(np.isfinite(r.z))
    assert set(np.unique(r.status)) <= {
        FlowStatus.OK,
        FlowStatus.OUTSIDE_WELL,
        FlowStatus.CORNER,
        FlowStatus.GRAZING,
        FlowStatus.IMPACT_LIMIT,
        # rtol 1e-2 leaves energy errors up to ~11 on h = 1000 near the chart's edge (H2 -> h):
        # a return whose (theta, I) then names no point, or another one, says so
        FlowStatus.OFF_SECTION,
        # and a verified return (long, or a shallow impact) whose error stays far above rtol 1e-2
        # at 1e-4 and 1e-6 says so
        FlowStatus.IMPRECISE,
        # rkf45's loose steps next to the singularity can gain energy without bound (8e11 on
        # h = 1000, measured): a runaway, stopped once its kinetic energy passes 1e4 (1 + h)
        FlowStatus.NON_FINITE,
    }
    stopped = r.status != FlowStatus.OK
    assert np.all(r.time[stopped] > 0)  # where it stopped, in time
    if stepper == "rkf45":  # the loose tolerance does leave the well here (measured: 11-17 of 40)
        assert np.count_nonzero(r.status == FlowStatus.OUTSIDE_WELL) > 0
    # and at a sane tolerance the same orbits return regularly (the status was the tolerance's doing)
    good = s.return_map(th, I, rtol=1e-10, atol=1e-10, stepper=stepper)
    assert np.count_nonzero(good.status == FlowStatus.OUTSIDE_WELL) == 0
    assert np.count_nonzero(good.status == FlowStatus.OFF_SECTION) == 0


def test_outside_well_status_names():
    assert hovering.Status.OUTSIDE_WELL.name == "OUTSIDE_WELL"
    assert FlowStatus.OUTSIDE_WELL != FlowStatus.NON_FINITE


# ------------------------------------------------------------------------------------------------
# a stopped orbit reports where and when it stopped


@pytest.mark.parametrize("max_steps", [1, 3, 10])
def test_step_limit_reports_the_time_and_state_reached(sec, max_steps):
    I = 0.5 * V2.action(H - V1.V(QW1))
    full = _one(sec, 0.3, I)
    r = _one(sec, 0.3, I, max_steps=max_steps)
    assert r.status[0] == FlowStatus.STEP_LIMIT
    assert 0 < r.time[0] < full.time[0]
    # the state is the flow's at that time: energy kept, and the exact uncoupled motion of q1
    assert r.energy_error[0] < 1e-12
    A1 = sec.point([0.3], [I])[0, 0]
    assert r.z[0, 0] == pytest.approx(A1 * np.cos(r.time[0]), abs=1e-10)


def test_non_finite_reports_the_time_and_state_reached():
    # A runaway (an indefinite coupled potential): NON_FINITE once its kinetic energy passes
    # 1e4 (1 + |h|), with that last state and its time: the unstable mode grows as e^(0.68 t)
    # (0.68 = sqrt(0.5 - 0.04)), kinetic energy ~1e4 after t ~ 6. H is kept to the end (to the
    # integrator's accuracy relative to terms of size ~1e4); the state's own coordinates are NaN (it is not on Sigma_h).
    s = Section(
        StepSystem(
            V1=Harmonic(0.2), V2=Harmonic(0.2), coupling=hovering.Bilinear(), eps=-0.5, qw1=-1, qw2=-2, geometry="wall"
        ),
        0.3,
    )
    for stepper in ("rk8pd", "taylor"):
        r = s.return_map([np.linspace(-np.pi, np.pi, 41)[12]], [0.5], stepper=stepper)
        assert r.status[0] == FlowStatus.NON_FINITE
        kinetic = 0.5 * (r.z[0, 1] ** 2 + r.z[0, 3] ** 2)
        assert np.isfinite(r.z[0]).all() and 1e4 * 1.3 < kinetic < 1e6
        assert 4 < r.time[0] < 10 and np.isnan([r.theta[0], r.I[0]]).all()
        assert r.energy_error[0] < 1e-12 * kinetic  # measured 8e-14 (rk8pd, rtol 1e-10), 1e-16 (taylor)


# ------------------------------------------------------------------------------------------------
# the implicit Gauss-Legendre steppers (with the flow's Jacobian: V'' in closed form for Harmonic /
# Tan, the coupling's Hessian) converge to the exact flow and to rk8pd on the coupled system


@pytest.mark.parametrize("stepper,order", [("rk4imp", 4), ("rk2imp", 2)])
def test_implicit_gauss_steppers_converge(stepper, order):
    sys0 = StepSystem(V1=V1, V2=V2, coupling=hovering.Bilinear(), eps=0.0, qw1=QW1, qw2=QW2, geometry="step")
    s0 = Section(sys0, H)
    th, I = np.linspace(-3, 3, 16), np.full(16, 0.2)
    ex = s0.return_map(th, I, stepper="exact")
    errs = []
    for tol in (1e-6, 1e-9):
        # the method's own convergence: unverified (a verified return is a tighter trace's)
        r = s0.return_map(th, I, rtol=tol, atol=tol, stepper=stepper, verify_steps=0)
        ok = (r.status == 0) & (ex.status == 0)
        assert ok.sum() >= 14 and list(np.array(r.itinerary)[ok]) == list(np.array(ex.itinerary)[ok])
        errs.append(np.max(np.abs(wrap(r.theta[ok] - ex.theta[ok]))))
    # 1000x tighter tolerance: the error must drop by more than 10x (measured ~40x for rk4imp, 20-40x rk2imp;
    # an order-2 or -4 method whose Jacobian were wrong would not converge, or not at this rate)
    assert errs[1] < errs[0] / 10 and errs[1] < 1e-4
    # coupled (the Jacobian's coupling terms): agrees with rk8pd to the implicit stepper's accuracy
    s1 = Section(sys0.replace(eps=0.05), H)
    a = s1.return_map(th, I, rtol=1e-10, atol=1e-10, stepper=stepper, verify_steps=0)
    b = s1.return_map(th, I, rtol=1e-12, atol=1e-12)
    ok = (a.status == 0) & (b.status == 0)
    assert np.max(np.abs(wrap(a.theta[ok] - b.theta[ok]))) < (1e-6 if order == 4 else 1e-3)
