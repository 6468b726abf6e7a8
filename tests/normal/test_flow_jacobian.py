"""The flow map's Jacobian (``FlowMap.jacobian``, ``iterate(record=("jacobian",))``): variational
equations with the state, saltation at impacts, the section's projection and the charts.

Oracles, each independent of the core's tangent code:
* central differences of the return with their own error bound (tests/helpers/tangent.py), on
  random systems drawn by Hypothesis (Harmonic or Tan, slow frequencies, weak to strong polynomial
  couplings, step and wall geometries), every stepper that applies, both coordinate systems;
* the linear flow's Jacobian in closed form: expm(A T) (SciPy) between the harmonic charts,
  differentiated by hand;
* one impact by hand: uncoupled harmonic oscillators, whose return map is theta' = theta +
  omega2 T(I) with T from the wall's angle, so J = [[1, omega2 T'(I)], [0, 1]];
* det J = 1 (the return map preserves area), the returns of step() bit for bit.

The noise of a central difference of the flow is the integration error of a return, which varies
from point to point by up to ``delta = 100 rtol`` (the per-return error band the differential tests
measure: ~1e-8 at rtol 1e-10); with h = sqrt(rtol) the bound is ``|D(h) - D(2h)| / 3 + delta / h``,
~1e-4 at rtol 1e-12, and the tests accept twice it.
"""

from __future__ import annotations

import math
import os

import numpy as np
import pytest
import scipy.linalg
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import hovering as hv
from helpers import tangent as fd

_FUZZ = os.environ.get("HOVERING_FUZZ", "")
EXAMPLES = max(int(_FUZZ), 8) if _FUZZ.isdigit() else (100 if _FUZZ else 8)

RTOL = 1e-12


def _check_points(fm, phi, K, checked, rtol=RTOL):
    """Compare fm.jacobian with central differences at the points whose stencil stays on the
    centre's itinerary (fm integrates at ``rtol``); appends the relative errors to ``checked``."""
    h, delta = math.sqrt(rtol), 100 * rtol
    t = fm.jacobian(phi, K)
    base = fm.returns(phi, K)
    for i in range(np.size(phi)):
        if t.status[i] != hv.Status.OK:
            assert np.all(np.isnan(t.J[i]))  # a status, not a number
            continue
        P, Q = fd.stencil(phi[i], K[i], h)
        st_ = fm.returns(P, Q)
        if not (np.all(st_.status == hv.FlowStatus.OK) and all(it == base.itinerary[i] for it in st_.itinerary)):
            continue  # the stencil crosses a change of itinerary (a corner or grazing curve)
        Dh, D2h = fd.differences(st_.phi, st_.K, h)
        err = np.abs(Dh - t.J[i])
        assert np.all(err <= 2 * fd.bound(Dh, D2h, delta * (1 + np.abs(t.J[i]).max()), h)), (
            fm,
            phi[i],
            K[i],
            base.itinerary[i],
            t.J[i],
            Dh,
        )
        # area preservation: det J = 1 to the entries' error (delta relative) times their size
        assert abs(np.linalg.det(t.J[i]) - 1) <= 4 * delta * (1 + np.abs(t.J[i]).max()) ** 2
        checked.append(err.max() / (1 + np.abs(t.J[i]).max()))


@st.composite
def systems(draw):
    def potential():
        if draw(st.booleans()):
            w = draw(st.floats(0.15, 2.0))
            return hv.Harmonic(w), w
        w, a = draw(st.floats(0.5, 1.6)), draw(st.floats(0.2, 0.8))
        return hv.Tan(w, a), w

    (V1, w1), (V2, w2) = potential(), potential()
    terms = {(1, 1): 1.0}
    if draw(st.booleans()):
        terms[(draw(st.integers(1, 3)), draw(st.integers(1, 3)))] = draw(st.floats(-0.5, 0.5))
    eps = draw(st.sampled_from([-1, 1])) * 10 ** draw(st.floats(-3, math.log10(0.5))) * w1 * w2
    geometry = draw(st.sampled_from(["step", "wall"]))
    sys = hv.StepSystem(
        V1=V1,
        V2=V2,
        coupling=hv.Polynomial(terms),
        eps=eps,
        qw1=draw(st.floats(-1.3, -0.3)),
        qw2=draw(st.floats(-1.0, -0.2)),
        geometry=geometry,
    )
    h = 10 ** draw(st.floats(-0.5, 0.6))
    starts = [(draw(st.floats(-3.1, 3.1)), draw(st.floats(0.05, 0.95))) for _ in range(3)]
    return sys, h, starts


CHECKED: list = []


@settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(systems())
def test_the_jacobian_is_the_derivative_of_the_return_on_random_systems(drawn):
    sys, h, starts = drawn
    I_top = sys.V2.action(0.95 * h)
    th = np.array([s[0] for s in starts])
    I = np.array([s[1] * I_top for s in starts])
    for stepper in ("rk8pd", "taylor"):
        fm = hv.FlowMap(sys, h, coordinates="section", stepper=stepper, rtol=RTOL, max_steps=100_000)
        _check_points(fm, th, I, CHECKED)


def test_the_random_systems_were_compared():
    if not CHECKED:
        test_the_jacobian_is_the_derivative_of_the_return_on_random_systems()
    assert len(CHECKED) >= 15, len(CHECKED)
    print(f"{len(CHECKED)} Jacobians compared, largest relative difference {max(CHECKED):.2e}")


@pytest.mark.parametrize("stepper", ["rk8pd", "taylor", "rkck", "rk4imp", "msadams"])
@pytest.mark.parametrize("eps", [-0.05, 0.1])
def test_normal_coordinates_of_the_readme_system(stepper, eps):
    # msadams and the implicit steppers cannot meet rtol 1e-12 here (IMPRECISE): 1e-10
    rtol = RTOL if stepper in ("rk8pd", "taylor", "rkck") else 1e-10
    fm = hv.paper.flow_map(eps=eps, stepper=stepper, rtol=rtol)
    rng = np.random.default_rng(4)
    phi, K = rng.uniform(-np.pi, np.pi, 10), rng.uniform(-0.25, 0.2, 10)
    checked: list = []
    _check_points(fm, phi, K, checked, rtol)
    assert len(checked) >= 6
    t = fm.jacobian(phi, K)
    if stepper in ("rk8pd", "taylor", "rkck"):  # the step control reads the state only
        p1, k1 = fm.step(phi, K)
        assert np.array_equal(t.phi, p1, equal_nan=True) and np.array_equal(t.K, k1, equal_nan=True)


# ---------------------------------------------------------------------------------- closed forms


def _harmonic_chart(w, theta, I):
    """(q, p) of a harmonic oscillator at (theta, I) and its tangents d/dtheta, d/dI (by hand)."""
    A = math.sqrt(2 * w * I) / w
    q, p = A * math.cos(theta), -A * w * math.sin(theta)
    return np.array([q, p]), np.array([p / w, -w * q]), np.array([q, p]) / (2 * I)


def test_the_linear_flows_jacobian_in_closed_form():
    # H = p^2/2 + w1^2 q1^2/2 + w2^2 q2^2/2 + eps q1 q2, no walls: z(T) = expm(A T) z0. The return map's
    # Jacobian is D2 P expm(A T) V0: V0 the chart's tangents at the start (q1 from the energy), P the
    # projection along the flow onto p1 = 0, D2 the inverse harmonic chart at the end.
    w1, w2, eps, h = 1.0, 1.3, 0.2, 1.0
    sys = hv.StepSystem(hv.Harmonic(w1), hv.Harmonic(w2), hv.Bilinear(), eps=eps, geometry="none")
    A = np.array([[0, 1, 0, 0], [-(w1**2), 0, -eps, 0], [0, 0, 0, 1], [-eps, 0, -(w2**2), 0]], dtype=float)
    for stepper, tol in (("exact", 1e-10), ("taylor", 1e-8), ("rk8pd", 1e-8)):
        fm = hv.FlowMap(sys, h, coordinates="section", stepper=stepper, rtol=RTOL)
        for theta, I in ((0.4, 0.3), (-2.0, 0.5), (2.9, 0.1)):
            (q2, p2), d2th, d2I = _harmonic_chart(w2, theta, I)
            rest = h - w2 * I  # w1^2 q1^2 / 2 + eps q1 q2 = rest, q1 > 0
            q1 = (-eps * q2 + math.sqrt((eps * q2) ** 2 + 2 * w1**2 * rest)) / w1**2
            F1 = w1**2 * q1 + eps * q2
            V0 = np.zeros((4, 2))
            V0[2:, 0], V0[2:, 1] = d2th, d2I
            V0[0, 0] = -eps * q1 * d2th[0] / F1
            V0[0, 1] = -(eps * q1 * d2I[0] + w2) / F1
            r = fm.returns(theta, I)
            T = float(r.time[0])
            z1 = scipy.linalg.expm(A * T) @ np.array([q1, 0.0, q2, p2])
            f = A @ z1
            P = np.eye(4) - np.outer(f, np.eye(4)[1]) / f[1]
            dz = P @ scipy.linalg.expm(A * T) @ V0
            Q2, P2 = z1[2], z1[3]
            E2 = 0.5 * P2**2 + 0.5 * w2**2 * Q2**2
            # theta = atan2(-p / w, q), I = E / w
            D2 = np.array([[w2 * P2 / (2 * E2), -w2 * Q2 / (2 * E2)], [w2 * Q2, P2 / w2]])
            J = D2 @ dz[2:]
            t = fm.jacobian(theta, I)
            assert np.allclose(t.J, J, rtol=0, atol=tol * (1 + np.abs(J).max())), (stepper, theta, I, t.J, J)


def _uncoupled(geometry="step"):
    return hv.StepSystem(
        hv.Harmonic(1.0), hv.Harmonic(1.3), hv.Bilinear(), eps=0.0, qw1=-0.8, qw2=-0.5, geometry=geometry
    )


@pytest.mark.parametrize("stepper", ["rk8pd", "taylor", "exact"])
def test_one_right_wall_impact_by_hand(stepper):
    # eps = 0: oscillator 1 runs from its maximum A1 to the wall q1 = qw1 and back, T = 2 acos(qw1 / A1)
    # / w1 with A1 = sqrt(2 (h - w2 I)) / w1; oscillator 2 turns by w2 T. So theta' = theta + w2 T(I),
    # I' = I, and J = [[1, w2 T'(I)], [0, 1]]: T' comes from the impact alone (without the saltation
    # matrix the variational equations would give a different J, and without the section's
    # projection too).
    w1, w2, qw1, h = 1.0, 1.3, -0.8, 1.0
    fm = hv.FlowMap(_uncoupled(), h, coordinates="section", stepper=stepper, rtol=RTOL)
    found = 0
    for theta in np.linspace(-3, 3, 13):
        for I in (0.1, 0.2, 0.3):
            t = fm.jacobian(theta, I)
            r = fm.returns(theta, I)
            if r.itinerary[0] != "R":
                continue
            found += 1
            h1 = h - w2 * I
            A1 = math.sqrt(2 * h1) / w1
            dA1 = -w2 / (w1 * math.sqrt(2 * h1))
            dT = (2 / w1) * (qw1 / A1**2) * dA1 / math.sqrt(1 - (qw1 / A1) ** 2)
            J = np.array([[1.0, w2 * dT], [0.0, 1.0]])
            assert np.allclose(t.J, J, rtol=0, atol=1e-9), (stepper, theta, I, t.J, J)
    assert found >= 5


@pytest.mark.parametrize("stepper", ["rk8pd", "taylor", "exact"])
def test_one_upper_wall_impact_by_hand(stepper):
    # eps = 0: oscillator 2 reflects off q2 = qw2 (while q1 < qw1) at its wall angle
    # theta_w2 = acos(qw2 / A2): its angle jumps from theta_w2 to -theta_w2, so after one period of
    # oscillator 1 (T = 2 pi / w1, no right-wall impact) theta' = theta + w2 T - 2 theta_w2(I):
    # J = [[1, -2 theta_w2'(I)], [0, 1]], theta_w2' = (qw2 / A2^2) A2' / sqrt(1 - (qw2 / A2)^2).
    w2, qw2, h = 1.3, -0.5, 1.0
    fm = hv.FlowMap(_uncoupled(), h, coordinates="section", stepper=stepper, rtol=RTOL)
    found = 0
    for theta in np.linspace(-3, 3, 25):
        for I in (0.45, 0.55, 0.65):
            r = fm.returns(theta, I)
            if r.itinerary[0] != "1":
                continue
            found += 1
            A2 = math.sqrt(2 * w2 * I) / w2
            dA2 = A2 / (2 * I)
            dthw = (qw2 / A2**2) * dA2 / math.sqrt(1 - (qw2 / A2) ** 2)
            J = np.array([[1.0, -2 * dthw], [0.0, 1.0]])
            t = fm.jacobian(theta, I)
            assert np.allclose(t.J, J, rtol=0, atol=1e-9), (stepper, theta, I, t.J, J)
    assert found >= 5


def test_the_closed_forms_jacobian_follows_the_orbit_it_differentiates():
    # With tangents the closed form takes fixed T/8 steps (no event-driven return), and a turn of
    # q inside a step was settled by a parabola through the ends' q'': near Tan(0.15, 0.9)'s steep
    # wall q'' at q1's minimum is many times its value at the ends, so the step "stayed above"
    # qw1 = -1.5 and the impact was skipped, status OK (an adversarial pass: 94-234 of 300 points;
    # image 1.572 against 1.257, J[0, 1] 3.771 against 3.689). The Jacobian's image must be the
    # return's (without tangents the closed form is event-driven) and its J taylor's (1e-6: both
    # agree to ~3e-14 in the image and ~3e-11 in J; a skipped impact is > 0.1 off in the image).
    sys = hv.StepSystem(hv.Tan(0.15, 0.9), hv.Harmonic(1.0), None, eps=0.0, qw1=-1.5, qw2=-0.75, geometry="wall")
    fe = hv.FlowMap(sys, 1.0, coordinates="section", stepper="exact")
    ft = hv.FlowMap(sys, 1.0, coordinates="section", stepper="taylor", rtol=1e-13, atol=1e-13)
    rng = np.random.default_rng(1)
    th = np.concatenate([[2.17], rng.uniform(-np.pi, np.pi, 300)])
    I = np.concatenate([[0.26], rng.uniform(0.02, 0.5, 300)])
    je, re, jt = fe.jacobian(th, I), fe.returns(th, I), ft.jacobian(th, I)
    ok = (je.status == 0) & (re.status == 0) & (jt.status == 0)
    assert ok[0] and ok.sum() > 250, ok.sum()
    d = np.abs(hv.wrap(je.phi - re.phi)) + np.abs(je.K - re.K)
    assert np.all(d[ok] < 1e-6), (np.flatnonzero(ok & (d >= 1e-6))[:5], d[ok].max())
    dJ = np.abs(je.J - jt.J).max(axis=(1, 2))
    assert np.all(dJ[ok] < 1e-6 * np.maximum(1.0, np.abs(jt.J).max(axis=(1, 2)))[ok]), dJ[ok].max()
    assert abs(je.J[0, 0, 1] - 3.689386817727) < 1e-8


def test_grazing_and_corner_returns_get_a_status_not_a_number():
    # eps = 0, right wall at qw1 = -0.8: a return whose q1 minimum is the wall grazes (A1 = |qw1|); one
    # whose q2 sits at qw2 when q1 reaches qw1 hits the corner.
    w1, w2, qw1, qw2, h = 1.0, 1.3, -0.8, -0.5, 1.0
    wall = hv.FlowMap(_uncoupled("wall"), h, coordinates="section", rtol=RTOL, grazing_tol=1e-9)
    I_graze = (h - 0.5 * w1**2 * qw1**2) / w2
    t = wall.jacobian(2.0, I_graze)
    assert t.status == hv.Status.GRAZING and np.all(np.isnan(t.J))
    fm = hv.FlowMap(_uncoupled(), h, coordinates="section", rtol=RTOL)
    I = 0.2
    A1, A2 = math.sqrt(2 * (h - w2 * I)) / w1, math.sqrt(2 * w2 * I) / w2
    t_w = math.acos(qw1 / A1) / w1  # q1 reaches the wall
    theta = -math.acos(qw2 / A2) - w2 * t_w  # q2 = qw2 then, rising (p2 > 0: theta < 0)
    t = fm.jacobian(theta, I)
    assert t.status == hv.Status.CORNER and np.all(np.isnan(t.J))


def test_the_recorded_product_and_the_orbit():
    fm = hv.paper.flow_map(eps=-0.05)
    K0 = np.array([-0.15, -0.05, 0.1])
    r = fm.iterate(fm.L1(K0), K0, 25, record=("orbit", "jacobian"))
    plain = fm.iterate(fm.L1(K0), K0, 25, record=("orbit",))
    assert np.array_equal(r.phi, plain.phi) and np.array_equal(r.K, plain.K)
    Js = [fm.jacobian(r.phi[:, n], r.K[:, n]).J for n in range(25)]
    M = np.broadcast_to(np.eye(2), (3, 2, 2)).copy()
    partial = []  # M_k = J_{k-1} ... J_0
    for J in Js:
        partial.append(M)
        M = J @ M
    # Same factors, two ways of multiplying them (QR-renormalised vs direct): they differ by
    # rounding only. The product J_k M_k rounds by ~2u |J_k| |M_k|, carried to the end by the later
    # factors: a first-order bound 4u sum_k |J_{n-1} .. J_{k+1}| |J_k| |M_k| (2-norms) for the
    # two products together. Relative to |M| it is no bound: the factors shear (|J_k| up to ~1e3)
    # and the partial products grow and cancel.
    bound = np.zeros(3)
    later = np.broadcast_to(np.eye(2), (3, 2, 2)).copy()
    norm = lambda A: np.linalg.norm(A, 2, axis=(1, 2))  # noqa: E731
    for J, Mk in zip(reversed(Js), reversed(partial)):
        bound += norm(later) * norm(J) * norm(Mk)
        later = later @ J
    bound *= 4 * np.finfo(float).eps
    assert np.all(np.abs(r.jacobian() - M).max(axis=(1, 2)) <= bound)
    assert np.all(r.jacobian_status == hv.Status.OK)
    # L1 + L2 = sum log det J: the integration's departure from area preservation, ~25 x 1e-10
    assert np.all(np.abs(r.jacobian_log.sum(axis=1)) < 1e-7)


def test_bad_input_and_interrupt_shape():
    fm = hv.paper.flow_map(eps=-0.05)
    with pytest.raises(ValueError, match="jacobian: phi"):
        fm.jacobian(np.inf, 0.0)
    t = fm.jacobian(np.zeros((2, 3)), -0.1)
    assert t.J.shape == (2, 3, 2, 2) and t.status.shape == (2, 3)
    off = fm.jacobian(0.0, 5.0)  # no point of Sigma_h there
    assert off.status == hv.Status.OFF_SECTION and np.all(np.isnan(off.J))
