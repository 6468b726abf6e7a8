"""Potentials defined in Python (CustomPotential and Potential subclasses) in the compiled core.

The core answers every energy question of a Python-defined potential by GSL quadrature and root
finding on V and V', and the flow calls V' from its worker threads: checked against the closed
forms (Harmonic, Tan), against an independent NumPy quadrature (a quartic well), and for the
failure modes (bad callables, exceptions and NaN inside the flow, object lifetime, threads).
"""

from __future__ import annotations

import gc
import math
import subprocess
import sys
import textwrap
import weakref

import numpy as np
import pytest

import hovering
from hovering import Bilinear, CustomPotential, FlowStatus, Harmonic, Section, StepSystem, Tan, onset_parameters

W1, W2, ALPHA = 1.0, 1.4, 0.7
H = 1.0
FIELDS = ("Omega0", "tau0", "tau1", "lam", "theta_w", "I_tan")


# The same formulas, in the same order, as the compiled Harmonic::dV and Tan::dV (one tan per
# force): the flow then integrates bit-identical vector fields, and every difference below comes
# from the quadrature of period, action and angles, not from the dynamics.
def harm_V(q):
    return 0.5 * W1 * W1 * q * q


def harm_dV(q):
    return W1 * W1 * q


def tan_V(q):
    t = math.tan(ALPHA * q)
    return 0.5 * W2 * W2 / (ALPHA * ALPHA) * t * t


def tan_dV(q):
    t = math.tan(ALPHA * q)
    return W2 * W2 / ALPHA * t * (1 + t * t)


class SubHarmonic(hovering.Potential):
    """The harmonic well through the trampoline (a Python subclass) instead of callables."""

    name = "SubHarmonic"

    def V(self, q):
        return harm_V(q)

    def dV(self, q):
        return harm_dV(q)


class SubTan(hovering.Potential):
    """Tan through the trampoline, with the well's edge as a class constant."""

    q_limit = math.pi / (2 * ALPHA)

    def V(self, q):
        return tan_V(q)

    def dV(self, q):
        return tan_dV(q)


def py_harmonic(kind):
    return CustomPotential(harm_V, harm_dV, name="PyHarmonic") if kind == "callables" else SubHarmonic()


def py_tan(kind):
    if kind == "callables":
        return CustomPotential(tan_V, tan_dV, q_limit=math.pi / (2 * ALPHA), name="PyTan")
    return SubTan()


def step_system(V1, V2, qw1=-1.0, qw2=-0.5):
    return StepSystem(V1=V1, V2=V2, coupling=Bilinear(), eps=0.05, qw1=qw1, qw2=qw2, geometry="step")


def start_points(n=20):
    # Around the tangent torus (I_tan = 0.337 here): below it orbits impact (itineraries 'R' and
    # '1'), above it they do not. Shifting every start by 1e-5 in I or 1e-6 in theta changes no
    # itinerary (checked when the points were chosen), so none flips on a 1e-12 difference.
    theta = np.linspace(-3.0, 3.0, n)
    I = 0.337 * np.linspace(0.75, 1.1, n)
    return theta, I


KINDS = ("callables", "subclass")


# ---------------------------------------------------------------------------------- closed forms


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("which", ("harmonic", "tan"))
def test_energy_questions_match_the_closed_forms(kind, which):
    # The quadrature is set to ~1e-12 relative (QAWS, epsrel 1e-12; measured 6e-15) and the roots
    # to ~1 ulp: 1e-10 leaves room for the nested ones (energy inverts action, point_at angle_of).
    py, ref = (py_harmonic(kind), Harmonic(W1)) if which == "harmonic" else (py_tan(kind), Tan(W2, ALPHA))
    assert py.q_limit == ref.q_limit
    for h in (0.05, 0.4, 1.0, 2.5):
        for f in ("period", "action", "frequency"):
            assert getattr(py, f)(h) == pytest.approx(getattr(ref, f)(h), rel=1e-10, abs=0), (f, h)
        assert py.turning_points(h) == pytest.approx(ref.turning_points(h), rel=1e-12)
        I = ref.action(h)
        assert py.energy(I) == pytest.approx(h, rel=1e-10)
        a, b = ref.turning_points(h)
        for q in np.linspace(a, b, 7)[1:-1]:
            assert abs(py.angle_of(q, h) - ref.angle_of(q, h)) < 1e-10, (q, h)
        for th in (-2.5, -0.3, 0.0, 1.2, 3.0):
            qp, rp = py.point_at(th, h), ref.point_at(th, h)
            assert np.allclose(qp, rp, rtol=0, atol=1e-10), (th, h, qp, rp)
            # The generic angle_of_point reads the angle from q alone, and theta ~ sqrt(q_max - q)
            # at a turning point: there a 1-ulp difference in q (or in the root q_max) is ~1e-8 in
            # theta. Away from the turning points dtheta/dq = omega/|p| is moderate.
            tol = 1e-10 if 1e-3 < abs(th) < math.pi - 1e-3 else 1e-7
            assert abs(py.angle_of_point(*rp, h) - th) < tol, (th, h)


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("which", ("harmonic", "tan"))
def test_return_map_matches_the_compiled_potential(kind, which):
    # Identical forces, so the orbits differ only through their start (section point from the
    # quadrature's S2^-1, ~1e-13) and the step sequence (hmax from the quadrature's period): the
    # images agree to ~rtol (measured: 7e-13 in theta, 8e-14 in I; 0 for the harmonic well, whose
    # S2 is the compiled Tan's); 1e-9 is the required agreement, ~1000x the measured one.
    V1c, V2c = Harmonic(W1), Tan(W2, ALPHA)
    V1, V2 = (py_harmonic(kind), V2c) if which == "harmonic" else (V1c, py_tan(kind))
    theta, I = start_points()
    ref = Section(step_system(V1c, V2c), H).return_map(theta, I, rtol=1e-12, n_threads=1)
    out = Section(step_system(V1, V2), H).return_map(theta, I, rtol=1e-12, n_threads=1)
    assert (ref.status == FlowStatus.OK).all() and (out.status == ref.status).all()
    assert {s for s in ref.itinerary} >= {"0", "R", "1"}  # the points exercise both walls and J_0
    assert out.itinerary == ref.itinerary
    np.testing.assert_allclose(out.theta, ref.theta, rtol=0, atol=1e-9)
    np.testing.assert_allclose(out.I, ref.I, rtol=0, atol=1e-9)
    np.testing.assert_allclose(out.time, ref.time, rtol=0, atol=1e-9)
    assert out.energy_error.max() < 1e-10


def test_onset_parameters_match_the_compiled_pair():
    # The definitions by quadrature vs closed forms: Richardson differences of ~1e-12 quantities
    # carry ~1e-9 into tau0, tau1 (the README's agreement of the three methods is 1e-7).
    ref = onset_parameters(step_system(Harmonic(W1), Tan(W2, ALPHA)), H)
    for kind in KINDS:
        sys_py = step_system(py_harmonic(kind), py_tan(kind))
        for method in ("definitions", "quadrature"):
            p = onset_parameters(sys_py, H, method=method)
            for f in FIELDS:
                assert abs(getattr(p, f) - getattr(ref, f)) <= 1e-7 * max(1.0, abs(getattr(ref, f))), (kind, method, f)
    with pytest.raises(ValueError, match="closed_form needs Harmonic or Tan"):
        onset_parameters(sys_py, H, method="closed_form")


def test_tangential_curve_and_normal_coordinates_match():
    # The tangential curve is a bisection on itineraries: with identical forces every decision is
    # the same, so the curves agree to the bisection's resolution (0.4 I_tan 2^-40 ~ 2e-13).
    sc = Section(step_system(Harmonic(W1), Tan(W2, ALPHA)), H)
    sp = Section(step_system(py_harmonic("callables"), py_tan("callables")), H)
    theta = np.array([-2.0, 0.5, 2.5])
    ref = hovering.tangential_curve(sc, theta, bisections=40)
    np.testing.assert_allclose(hovering.tangential_curve(sp, theta, bisections=40), ref, rtol=0, atol=1e-9)
    phi, K = hovering.to_normal(sp, theta, np.full(3, 0.4), bisections=40)
    np.testing.assert_allclose(K, 0.4 - ref, rtol=0, atol=1e-9)
    th, I = hovering.from_normal(sp, phi, K, bisections=40)
    np.testing.assert_allclose(I, 0.4, rtol=0, atol=1e-12)


# ---------------------------------------------------------------------------------- no closed form


def quartic_V(q):
    return 0.5 * q * q + 0.25 * q**4


def quartic_dV(q):
    return q + q**3


def quartic_reference(h, n=64):
    """Period and action of V = q^2/2 + q^4/4 by NumPy alone.

    With q = q_max sin(u), h - V(q) = cos^2(u) g(u), g = q_max^2/2 + q_max^4 (1 + sin^2 u)/4: the
    square-root endpoint singularities cancel and both integrands are smooth and periodic in u, so
    the trapezoid rule converges geometrically (64 points: ~1e-16).
    """
    qm = math.sqrt(-1.0 + math.sqrt(1.0 + 4.0 * h))  # q_max^2 solves x/2 + x^2/4 = h
    u = 2 * np.pi * np.arange(n) / n
    g = 0.5 * qm**2 + 0.25 * qm**4 * (1 + np.sin(u) ** 2)
    T = np.mean(qm / np.sqrt(2 * g)) * 2 * np.pi
    I = np.mean(qm * np.cos(u) ** 2 * np.sqrt(2 * g))
    return qm, T, I


def quartic_angle(q, h, qm, T, n=40):
    """omega x time from q to q_max, Gauss-Legendre in u on [asin(q/q_max), pi/2] (smooth integrand)."""
    x, w = np.polynomial.legendre.leggauss(n)
    a, b = math.asin(q / qm), math.pi / 2
    u = 0.5 * (b - a) * x + 0.5 * (b + a)
    g = 0.5 * qm**2 + 0.25 * qm**4 * (1 + np.sin(u) ** 2)
    return 2 * np.pi / T * 0.5 * (b - a) * np.sum(w * qm / np.sqrt(2 * g))


@pytest.fixture(scope="module")
def quartic():
    return CustomPotential(quartic_V, quartic_dV, name="quartic")


def test_quartic_against_an_independent_quadrature(quartic):
    # Two spectrally converging NumPy quadratures (~1e-15) vs the core's QAWS (set to 1e-12,
    # measured 2e-15 here): 1e-9 as required, independent of how lucky QAWS is on this integrand.
    for h in (0.01, 0.3, 1.0, 4.0):
        qm, T, I = quartic_reference(h)
        assert quartic.turning_points(h) == pytest.approx((-qm, qm), rel=1e-12)
        assert quartic.period(h) == pytest.approx(T, rel=1e-9, abs=0)
        assert quartic.action(h) == pytest.approx(I, rel=1e-9, abs=0)
        assert quartic.energy(I) == pytest.approx(h, rel=1e-9)
        for q in (-0.9 * qm, -0.2 * qm, 0.0, 0.5 * qm, 0.97 * qm):
            assert abs(quartic.angle_of(q, h) - quartic_angle(q, h, qm, T)) < 1e-9, (q, h)
    # Stiffer than harmonic: the period falls with energy.
    assert quartic.period(4.0) < quartic.period(1.0) < quartic.period(0.01) < 2 * math.pi


def test_quartic_flow_conserves_energy(quartic):
    # rk8pd at rtol 1e-12 over one return (~50 steps, a few impacts): the energy error is ~1e-13;
    # 1e-10 bounds it with room for the event corrections. Three returns from 10 points, the image of
    # each return the start of the next, H evaluated in Python from the image states.
    sec = Section(step_system(quartic, Tan(W2, ALPHA), qw1=-0.8), H)
    I_tan = Tan(W2, ALPHA).action(H - quartic_V(-0.8))
    theta, I = np.linspace(-2.8, 2.8, 10), I_tan * np.linspace(0.8, 1.05, 10)
    impacts = 0
    for _ in range(3):
        out = sec.return_map(theta, I, rtol=1e-12, n_threads=1)
        assert (out.status == FlowStatus.OK).all()
        q1, p1, q2, p2 = out.z.T
        V2 = 0.5 * W2 * W2 / ALPHA**2 * np.tan(ALPHA * q2) ** 2
        energy = 0.5 * p1**2 + quartic_V(q1) + 0.5 * p2**2 + V2 + 0.05 * q1 * q2
        assert np.abs(energy - H).max() < 1e-10 and out.energy_error.max() < 1e-10
        impacts += sum(s.count("R") + s.count("1") for s in out.itinerary)
        theta, I = out.theta, out.I
    assert impacts > 0


# ---------------------------------------------------------------------------------- bad input


def test_bad_callables_are_value_errors():
    with pytest.raises(ValueError, match=r"V must be callable \(V\(q\) -> float\), got 3"):
        CustomPotential(3, harm_dV)
    with pytest.raises(ValueError, match="dV must be callable"):
        CustomPotential(harm_V, None)
    with pytest.raises(ValueError, match=r"V\(0\) must be 0 .*\|V\(0\)\| <= 1e-12\), got 1.0"):
        CustomPotential(lambda q: 0.5 * q * q + 1.0, harm_dV)
    with pytest.raises(ValueError, match=r"not a single well: q V'\(q\) must be > 0"):
        CustomPotential(lambda q: 0.25 * q**4 - 0.5 * q * q, lambda q: q**3 - q)  # double well
    with pytest.raises(ValueError, match=r"q_limit must be > 0 \(or math.inf\), got -1"):
        CustomPotential(harm_V, harm_dV, q_limit=-1)
    with pytest.raises(ValueError, match="dV is not the derivative of V"):
        CustomPotential(harm_V, lambda q: 2 * q)
    with pytest.raises(ValueError, match=r"must be finite on \|q\| <= 10"):
        CustomPotential(lambda q: 0.5 * q * q if abs(q) < 2 else math.nan, harm_dV)
    with pytest.raises(ValueError, match=r"V\(0.0\) returned 'zero', expected a float"):
        CustomPotential(lambda q: "zero", harm_dV)
    with pytest.raises(ValueError, match=r"dV\(.*\) raised ZeroDivisionError"):
        CustomPotential(harm_V, lambda q: 1 / 0)
    with pytest.raises(ValueError, match="name must be a str"):
        CustomPotential(harm_V, harm_dV, name=3)
    # Steep and singular wells pass (the derivative check refines its step where V is steep).
    CustomPotential(lambda q: math.expm1(q * q), lambda q: 2 * q * math.exp(q * q))
    CustomPotential(lambda q: -math.log1p(-q * q), lambda q: 2 * q / (1 - q * q), q_limit=1.0)


def test_check_potential_on_a_subclass():
    hovering.check_potential(SubTan())

    class DoubleWell(hovering.Potential):
        def V(self, q):
            return 0.25 * q**4 - 0.5 * q * q

        def dV(self, q):
            return q**3 - q

    with pytest.raises(ValueError, match="DoubleWell.*not a single well"):
        hovering.check_potential(DoubleWell())

    class NoForce(hovering.Potential):
        def V(self, q):
            return harm_V(q)

    with pytest.raises(TypeError, match=r"NoForce\(\) does not define dV\(self, q\)"):
        NoForce().period(1.0)


class Boom(RuntimeError):
    """Raised by a V' on purpose."""


def boom_system(dV):
    # V1's force is broken on -0.5 < q1 < -0.3, which only the flow visits: the section points
    # (q1 > 0), the turning points and the quadrature of the period (V only, V' at the ends) do not.
    V1 = CustomPotential(harm_V, dV, name="broken", check_extent=0.25)
    return Section(step_system(V1, Tan(W2, ALPHA)), H)


def test_exceptions_and_bad_values_inside_the_flow():
    theta, I = start_points(6)

    def raising(q):
        if -0.5 < q < -0.3:
            raise Boom(f"at q = {q}")
        return harm_dV(q)

    with pytest.raises(Boom, match="at q = -0.3"):
        boom_system(raising).return_map(theta, I, n_threads=1)
    with pytest.raises(ValueError, match=r"broken.dV\(-0.3.*\) = nan: V and V' must be finite inside the well"):
        boom_system(lambda q: math.nan if -0.5 < q < -0.3 else harm_dV(q)).return_map(theta, I, n_threads=1)
    with pytest.raises(TypeError, match=r"broken.dV\(-0.3.*\) returned None of type NoneType"):
        boom_system(lambda q: None if -0.5 < q < -0.3 else harm_dV(q)).return_map(theta, I, n_threads=1)
    # An exception inside the quadrature (onset parameters) reaches Python as well.
    flaky = {"n": 0, "armed": False}

    def V_flaky(q):  # fails on the 50th call once armed, deep inside a quadrature or root search
        flaky["n"] += flaky["armed"]
        if flaky["n"] > 50:
            raise Boom("late")
        return harm_V(q)

    V1 = CustomPotential(V_flaky, harm_dV)
    flaky["armed"] = True
    with pytest.raises(Boom, match="late"):
        onset_parameters(step_system(V1, Tan(W2, ALPHA)), H)


def test_python_objects_live_as_long_as_the_core_holds_them():
    # Numerical(base) stores the potential in C++: the holder must keep the Python subclass (whose
    # V and V' live on the Python side) alive with all Python references dropped, and let it go
    # with the Numerical (no reference cycle hidden from the garbage collector).
    sub = SubHarmonic()
    ref = weakref.ref(sub)
    num = hovering.Numerical(sub)
    del sub
    gc.collect()
    assert ref() is not None
    theta, I = start_points(5)
    expect = Section(step_system(Harmonic(W1), Tan(W2, ALPHA)), H).return_map(theta, I, rtol=1e-12, n_threads=1)
    out = Section(step_system(num, Tan(W2, ALPHA)), H).return_map(theta, I, rtol=1e-12, n_threads=1)
    np.testing.assert_allclose(out.I, expect.I, rtol=0, atol=1e-9)
    del num, out
    gc.collect()
    assert ref() is None
    # CustomPotential owns its callables.
    f = lambda q: harm_dV(q)  # noqa: E731
    fref = weakref.ref(f)
    pot = CustomPotential(harm_V, f)
    del f
    gc.collect()
    assert fref() is not None and pot.dV_callable is fref()
    del pot
    gc.collect()
    assert fref() is None


# The threaded cases run in a child process with a timeout, so that a deadlock (a callback waiting
# for a GIL its caller holds) fails the test instead of hanging the suite.
THREADED = textwrap.dedent(
    """
    import gc, math, threading
    import numpy as np
    import hovering
    from test_custom_potential import (Boom, SubHarmonic, boom_system, harm_dV, py_harmonic, py_tan,
                                       start_points, step_system, H)
    theta, I = start_points()
    main = threading.get_ident()
    for kind in ("callables", "subclass"):
        sec = hovering.Section(step_system(py_harmonic(kind), py_tan(kind)), H)
        one = sec.return_map(theta, I, rtol=1e-10, n_threads=1)
        two = sec.return_map(theta, I, rtol=1e-10, n_threads=2)
        assert np.array_equal(one.z, two.z) and one.itinerary == two.itinerary, kind
        print("same", kind)

    def worker_only(q):  # raises on worker threads only, never on the calling thread
        if threading.get_ident() != main and -0.5 < q < -0.3:
            raise Boom("from a worker")
        return harm_dV(q)

    # 64 points or more run on worker threads only (the calling thread watches for Ctrl-C), so
    # the exception surely comes from a worker whatever the scheduling.
    theta64, I64 = start_points(64)
    try:
        boom_system(worker_only).return_map(theta64, I64, n_threads=2)
    except Boom as e:
        print("Boom", e)
    try:
        boom_system(lambda q: math.nan if -0.5 < q < -0.3 else harm_dV(q)).return_map(theta, I, n_threads=2)
    except ValueError as e:
        print("ValueError", "= nan" in str(e))
    # The subclass's Python object, referenced by the core only, on two threads.
    num = hovering.Numerical(SubHarmonic())
    gc.collect()
    out = hovering.Section(step_system(num, py_tan("subclass")), H).return_map(theta, I, rtol=1e-10, n_threads=2)
    print("alive", bool((out.status == 0).all()))
    """
)


def test_threads_no_deadlock_and_errors_from_workers():
    import pathlib

    r = subprocess.run(
        [sys.executable, "-c", THREADED], capture_output=True, text=True, timeout=120, cwd=pathlib.Path(__file__).parent
    )
    assert r.returncode == 0, r.stderr
    assert r.stdout.split("\n") == [
        "same callables",
        "same subclass",
        "Boom from a worker",
        "ValueError True",
        "alive True",
        "",
    ], r.stdout


def test_default_threads_fall_back_to_one_for_python_potentials():
    # n_threads=0 means all cores for compiled potentials but one thread when a potential calls
    # back into Python (the GIL serialises the calls: two threads were measured 3.4x slower). The
    # detection must hold for both ways of defining one and not fire for compiled ones.
    def _python_defined(sys):
        return sys.python_defined

    class Sub(hovering.Potential):
        def V(self, q):
            return 0.5 * q * q

        def dV(self, q):
            return q

    cp = hovering.CustomPotential(lambda q: 0.5 * q * q, lambda q: q)
    tan = hovering.Tan(1.4, 0.7)
    assert _python_defined(hovering.StepSystem(V1=cp, V2=tan))
    assert _python_defined(hovering.StepSystem(V1=Sub(), V2=tan))
    assert not _python_defined(hovering.StepSystem(V1=hovering.Harmonic(1.0), V2=tan))
    sec = hovering.Section(hovering.StepSystem(V1=cp, V2=tan, coupling=hovering.Bilinear(), eps=0.05), 1.0)
    th, I = np.linspace(-3, 3, 6), np.full(6, 0.3)
    a, b = sec.return_map(th, I), sec.return_map(th, I, n_threads=2)
    np.testing.assert_array_equal(a.theta, b.theta)  # threads never change results


def test_overriding_a_compiled_potential_is_refused():
    # The flow evaluates Harmonic/Tan forces from their parameters (no virtual call), so a Python
    # subclass overriding V or dV would be ignored silently: StepSystem must refuse it by name.
    class Stiffer(hovering.Harmonic):
        def dV(self, q):
            return 2.0 * q

    class Plain(hovering.Tan):  # no override: still fine
        pass

    with pytest.raises(ValueError, match="overrides V/dV of the compiled Harmonic"):
        hovering.StepSystem(V1=Stiffer(1.0), V2=hovering.Tan(1.4, 0.7))
    hovering.StepSystem(V1=hovering.Harmonic(1.0), V2=Plain(1.4, 0.7))
