"""Edges of the compiled core found by an adversarial audit, checked through the Python API.

* generic turning points of a bounded well at levels above what its V reaches in double precision;
* generic angles next to the turning points (point_at raised "did not converge" near theta = +-pi,
  and with it a whole return-map batch with a quadrature V2);
* a Python potential whose q_limit / name / V returns the wrong kind of value;
* 0-d NumPy arrays as real arguments;
* section coordinates at the bottom of well 2 (H2 = 0) and of non-finite rows;
* tabulated arcs on grids with nearly coincident circles.

The C++ side of the same fixes is in cpp/tests/test_potential.cpp, test_flow.cpp and
test_tabulated.cpp.
"""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest

import hovering as hv
from hovering import Bilinear, FlowStatus, Harmonic, Numerical, Section, StepSystem, Tan

EPS = np.finfo(float).eps


# ------------------------------------------------------------------------------ turning points


@pytest.mark.parametrize("h", [1e-300, 1e-10, 1.0, 1e10, 1e33, 1e100, 1e300])
def test_generic_turning_points_of_tan_at_every_level(h):
    # Closed form q_max = atan(alpha sqrt(2h) / omega) / alpha. The generic root is the largest
    # double with V <= h (Brent to 4 eps, then stepped to that double), the closed form rounds to
    # ~1 ulp: 8 eps relative. Tan's V reaches only ~8e30 before its wall (+inf from q_limit on),
    # so for larger h the answer is the last double before q_limit (it was (-0.0, 0.0)).
    T = Tan(1.4, 0.7)
    a, b = Numerical(T).turning_points(h)
    B = T.turning_points(h)[1]
    assert abs(b - B) <= 8 * EPS * B and abs(a + B) <= 8 * EPS * B, (a, b, B)
    assert T.V(b) <= h
    if h >= 1e33:
        assert b == np.nextafter(T.q_limit, 0) and a == -b


def test_generic_action_of_tan_on_high_levels_with_steep_walls():
    # Against the closed form I = 2 h / (omega + sqrt(omega^2 + 2 alpha^2 h)) (8 eps). On a high
    # level p = sqrt(2 (h - V)) climbs to sqrt(2 h) within h / |V'| of a wall (1e-10 of the width at
    # h = 1.3e20 for Tan(2.6, 0.13)); one QAWS over the level returned 8.4e-9 off there, and 3.3e-11
    # for the onset case of tests/flow/test_onset_hard.py. Bound: the 1e-10 the onset error estimate takes
    # for a quadrature's action (measured worst 3.9e-11 over 40,000 random levels); the two named
    # cases now to 1e-12.
    for w, a, h in [
        (2.596276452619615, 0.12982146198486358, 1.2906874458886323e20),
        (8.058421877614817, 1.0, 1.3508147725979195e24),
    ]:
        T = Tan(w, a)
        assert abs(Numerical(T).action(h) / T.action(h) - 1) <= 1e-12, (w, a, h)
    rng = np.random.default_rng(5)
    worst = 0.0
    for _ in range(400):
        w, a, h = 10 ** rng.uniform(-1, 1), 10 ** rng.uniform(-6, 1), 10 ** rng.uniform(-3, 45)
        T = Tan(w, a)
        try:
            num = Numerical(T).action(h)
        except ValueError as e:  # a level above the largest double V reaches before its wall
            assert "lies above the largest value V reaches" in str(e)
            continue
        worst = max(worst, abs(num / T.action(h) - 1))
    assert worst <= 1e-10, worst


# -------------------------------------------------------------------- angles near turning points


def _thetas():
    k = 10.0 ** -np.arange(1, 17)
    t = np.concatenate([k, np.pi - k, np.linspace(-np.pi, np.pi, 101), [0.0, np.pi, -np.pi]])
    return np.concatenate([t, -t])


@pytest.mark.parametrize("base", [Harmonic(1.0), Tan(1.4, 0.7)], ids=["harmonic", "tan"])
def test_generic_point_at_and_angle_of_next_to_the_turning_points(base):
    # (q, p) to 1e-11: the generic path is QAWS quadrature asked for 1e-12 relative (measured
    # ~1e-15) and a Newton inversion stopped at 1e-14; 1e-11 is 10x the requested accuracy.
    # angle_of(q) to 1e-11 plus its conditioning: the closed form's q is a double (~1 ulp) and
    # theta ~ sqrt(q_max - q) at a turning point, dtheta/dq = omega / |p|, so 8 ulps of q move
    # theta by 8 eps q_max omega / |p| (1e-8 at theta = 1e-8, unavoidable from a double q).
    num = Numerical(base)
    for h in (1e-6, 1.0, 100.0):
        w, qm = base.frequency(h), base.turning_points(h)[1]
        for th in _thetas():
            Q, P = base.point_at(th, h)
            q, p = num.point_at(th, h)
            assert abs(q - Q) <= 1e-11 * max(1.0, qm) and abs(p - P) <= 1e-11 * max(1.0, qm * w), (h, th, q, p, Q, P)
            tol = 1e-11 + 8 * EPS * qm * w / abs(P) if P != 0 else math.inf
            assert abs(num.angle_of(Q, h) - abs(th)) <= tol, (h, th)


def test_audit_case_point_at_near_pi():
    # Raised "quadrature ... did not converge" for |theta| in ~(pi - 5e-6, pi - 5e-7).
    q, p = Numerical(Harmonic(1.0)).point_at(3.14159, 1.0)
    Q, P = Harmonic(1.0).point_at(3.14159, 1.0)
    assert abs(q - Q) < 1e-12 and abs(p - P) < 1e-12


def test_return_map_batch_with_a_quadrature_V2_near_the_turning_points():
    # One failing start used to raise for the whole batch. With V2 = Numerical(Tan) the images
    # match the compiled Tan's: identical forces, starts equal to ~1e-13 (point_at, energy), so
    # the images agree to ~rtol x the orbit's sensitivity; 1e-8 leaves a wide margin.
    th = np.array([np.pi - 2e-6, np.pi - 1e-6, -np.pi + 3e-7, 2e-6, -1e-7, 1.0, -2.5])
    I = np.full(th.size, 0.3)

    def sec(V2):
        return Section(
            StepSystem(V1=Harmonic(1.0), V2=V2, coupling=Bilinear(), eps=0.05, qw1=-1.0, qw2=-0.5, geometry="step"), 1.0
        )

    ref = sec(Tan(1.4, 0.7)).return_map(th, I, rtol=1e-12, n_threads=1)
    out = sec(Numerical(Tan(1.4, 0.7))).return_map(th, I, rtol=1e-12, n_threads=1)
    assert np.all(out.status == FlowStatus.OK) and list(out.itinerary) == list(ref.itinerary)
    assert np.abs(hv.wrap(out.theta - ref.theta)).max() < 1e-8 and np.abs(out.I - ref.I).max() < 1e-8


# -------------------------------------------------------------- Python potentials: wrong returns


def _sub(**attrs):
    ns = dict(V=lambda self, q: 0.5 * q * q, dV=lambda self, q: q)
    ns.update(attrs)
    return type("Sub", (hv.Potential,), ns)()


@pytest.mark.parametrize(
    "attrs,match",
    [
        (dict(q_limit="a"), r"Sub\(\): q_limit must be a real number > 0 or inf, got 'a'"),
        (dict(q_limit=lambda self: "a"), r"Sub\(\): q_limit\(\) must return a real number > 0 or inf, got 'a'"),
        (dict(q_limit=lambda self: None), r"q_limit\(\) must return a real number > 0 or inf, got None"),
        (dict(q_limit=lambda self: 1 + 2j), r"q_limit\(\) must return a real number > 0 or inf, got \(1\+2j\)"),
        (dict(q_limit=lambda self: True), r"q_limit\(\) must return a real number > 0 or inf, got True"),
        (dict(q_limit=-1.0), r"q_limit must be a real number > 0 or inf, got -1.0"),
        (dict(q_limit=math.nan), r"q_limit must be a real number > 0 or inf, got nan"),
    ],
)
def test_wrong_q_limit_is_a_named_value_error(attrs, match):
    # It was RuntimeError "Unable to cast Python instance of type <class 'str'> to C++ type '?'".
    # (Python itself answers pot.q_limit from the subclass; the core reads it through the
    # trampoline, here in the turning points' bracket.)
    with pytest.raises(ValueError, match=match):
        _sub(**attrs).turning_points(1.0)


def test_good_q_limits_pass():
    # A float32, a 0-d array from a method: read as 2 (V = q^2 / 2 reaches only 2 at the wall).
    for lim in (np.float32(2.0), lambda self: np.array(2.0)):
        pot = _sub(q_limit=lim)
        assert pot.turning_points(1.0)[1] == pytest.approx(math.sqrt(2), rel=1e-15)
        with pytest.raises(ValueError, match=r"V never reaches the energy 3 \(V\(-2\) = 2 at the wall q_limit"):
            pot.turning_points(3.0)
    assert _sub(q_limit=math.inf).turning_points(1e300)[1] == pytest.approx(math.sqrt(2e300), rel=1e-15)


def test_wrong_name_and_V_are_named_value_errors():
    # The core reads the name for repr and its messages.
    with pytest.raises(ValueError, match=r"Sub\(\): name must be a str, got 5 of type int"):
        repr(_sub(name=5))
    with pytest.raises(ValueError, match=r"Sub\(\): name\(\) must return a str, got None"):
        _sub(name=lambda self: None).period(-1.0)
    assert repr(_sub(name=lambda self: "mine")) == "mine"

    # A name that raises does not replace the core's message: the class name stands in.
    def boom(self):
        raise RuntimeError("no name")

    assert repr(_sub(name=property(boom))) == "Sub()"
    # V and V' returning a non-number: a ValueError, and still the TypeError it was before.
    bad_V = _sub(V=lambda self, q: "x")
    for exc in (ValueError, TypeError, hv.Potential.ReturnError):
        with pytest.raises(exc, match=r"Sub\(\).V\(.*\) returned 'x' of type str: V and V' must return a real number"):
            bad_V.period(1.0)
    # It pickles (a process pool sends a worker's exception back that way).
    with pytest.raises(hv.Potential.ReturnError) as info:
        bad_V.period(1.0)
    again = pickle.loads(pickle.dumps(info.value))
    assert type(again) is hv.Potential.ReturnError and str(again) == str(info.value)


# ------------------------------------------------------------------------- 0-d arrays as reals


def test_zero_dimensional_arrays_are_real_arguments():
    assert Harmonic(np.array(2.0)).omega == 2.0
    assert Harmonic(np.array(2)).omega == 2.0
    assert Tan(np.array(1.4, dtype=np.float32), np.array(0.7)).alpha == 0.7
    assert Harmonic(1.0).period(np.array(0.5)) == 2 * np.pi
    assert Harmonic(np.uint8(3)).omega == 3.0
    for bad in (
        np.array([2.0]),
        np.array([[2.0]]),
        np.array(True),
        np.array(1 + 2j),
        np.array("2"),
        np.array(2.0, dtype=object),
        True,
        1 + 2j,
        "2",
        None,
    ):
        with pytest.raises(ValueError, match="Harmonic: omega must be a real number"):
            Harmonic(bad)


# ------------------------------------------------------------------ section coordinates, H2 = 0


@pytest.mark.parametrize(
    "V2", [Tan(1.4, 0.7), Harmonic(1.3), Numerical(Tan(1.4, 0.7))], ids=["tan", "harmonic", "numerical"]
)
def test_coordinates_at_the_bottom_of_well_2(V2):
    # H2 = 0 is the centre of the polar-like (theta, I): I = 0 exactly, theta = 0 by convention
    # (it raised "Tan.action: energy must be finite and > 0, got 0"). Non-finite rows stay NaN.
    sec = Section(StepSystem(V1=Harmonic(1.0), V2=V2, coupling=Bilinear(), eps=0.05, qw1=-1.0, qw2=-0.5), 1.0)
    assert np.array_equal(sec.coordinates(np.zeros(4)), [[0.0, 0.0]])
    z = np.array([[1.2, 0.0, 0.0, 0.0], [np.nan, 0.0, 0.1, 0.2], [1.0, 0.0, 0.0, np.inf], [0.0, 0.0, 0.0, -0.0]])
    c = sec.coordinates(z)
    assert np.array_equal(c[0], [0.0, 0.0]) and np.array_equal(c[3], [0.0, 0.0])
    assert np.isnan(c[1]).all() and np.isnan(c[2]).all()
    # A state just off the bottom still has its ordinary coordinates.
    th, I = sec.coordinates(np.array([1.2, 0.0, 0.0, -1e-3]))[0]
    assert th == pytest.approx(np.pi / 2, abs=1e-9) and I > 0


# --------------------------------------------------------------------- nearly coincident circles


def test_nearly_coincident_circles_are_rejected():
    # K = 1e-14 next to K = 0: a natural cubic spline through them amplified the tables' rounding
    # by range / spacing = 2e14 (the family's Omega'(0) moved from 3.1 to 3.1086 on exact linear
    # tables, to -8e11 on measured ones).
    def fam(K):
        K = np.asarray(K)
        return hv.TruncatedFamily(
            0.3, K, 2.0 + 3.1 * K, np.where(K <= 0, 1.5 + 0.5 * K, 0.0), np.sqrt(np.maximum(-K, 0.0))
        )

    with pytest.raises(
        ValueError,
        match=r"the K grid's points must be at least 1e-9 of its range \(2\) apart, but "
        r"K\[4\] = 0 and K\[5\] = 1e-14 are 1e-14 apart",
    ):
        fam([-1.0, -0.5, -0.2, -0.04, 0.0, 1e-14, 0.05, 0.5, 1.0])
    f = fam([-1.0, -0.5, -0.2, -0.04, 0.0, 4e-9, 0.05, 0.5, 1.0])  # 2e-9 of the range: kept
    assert f.onset()[2] == pytest.approx(3.1, abs=1e-6)
