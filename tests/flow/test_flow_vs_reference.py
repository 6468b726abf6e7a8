"""Cross-check of hovering's flow return map against an independent pure-NumPy reference.

The reference (``tests/helpers/flow_reference.py``) was written from the problem statement alone: fixed-
step RK4 (DT = 1e-3) with bisection-located events.  It is validated here on its own (angle-action
conversion, exact answers at eps = 0, step halving, detection of wall dips inside one step) and
then compared with ``hovering.Section.return_map`` and ``hovering.FlowMap.iterate`` at h = 1,
eps = 0.05 and eps = -0.1, for V1 = Harmonic(1), V2 = Tan(1.4, 0.7), step qw = (-1, -0.5).

Tolerance.  Measured accuracy of the reference (DT vs DT/2 from the same start, the 96 test
points and their images): |d theta| <= 9e-13, |d I| <= 6e-14, |d time| <= 1.5e-12 per return,
|d H| <= 5e-14 (RK4: the DT/2 error is 16x smaller, so these differences are the DT errors).
Measured agreement with hovering at rtol = atol = 1e-12: one return |d theta| <= 1.8e-12,
|d I| <= 2.3e-13, |d time| <= 7.1e-13; three returns (FlowMap.iterate vs the reference applied
3 times) |d theta| <= 1.1e-11, |d I| <= 6.2e-13: per-return differences grow by the map's
stretching (finite differences of the reference: an I-perturbation grows by up to ~90x, a
theta-perturbation by up to ~5x over three returns).
One return: TOL = 1e-10 (about 50x the measured differences: room for other compilers / CPUs,
but far below what a mislocated event or a wrong reflection gives; hovering at rtol = 1e-7
already differs by ~1.5e-7).  Three returns: ITER_TOL = 1e-9 (bound ~90 * 2.3e-13 +
5 * 1.8e-12 ~ 3e-11 on the propagated one-return differences, with 30x room).  Both are
multiplied by the square-root (grazing) amplification factor 1 + sqrt(1e-4 / margin) of an impact
at distance ``margin`` from tangency or the corner (all kept test points have margin > 3.5e-4,
where this factor is < 1.6).  Points whose reference trajectory comes within 1e-6 of a wall or
the corner at an event are dropped (their itinerary is ill-conditioned); the selection uses the
reference only.
"""

from __future__ import annotations

import math
from collections import Counter

import numpy as np
import pytest

import hovering as hv
from helpers import flow_reference as ref
from hovering import paper

# Independent scipy solutions of the same flow (seconds each): slow; CI runs them, at the oldest dependencies too.
pytestmark = pytest.mark.slow

H = 1.0
EPS_VALUES = (0.05, -0.1)
N_RETURNS = 3
#: Reference orbits passing this close to a wall or the corner at an event are not compared.
MARGIN_MIN = 1e-6
#: Base tolerances on theta, I and the return time for one / three returns (module docstring).
TOL = 1e-10
ITER_TOL = 1e-9
GRAZING_SCALE = 1e-4
KINDS = {"u", "0", "R", "1"}


def _tolerance(margin, base=TOL):
    return base * (1.0 + np.sqrt(GRAZING_SCALE / margin))


def _angle_diff(a, b):
    return np.abs((np.asarray(a) - np.asarray(b) + np.pi) % (2.0 * np.pi) - np.pi)


def _points():
    """96 points of Sigma_1: 80 around the tangency (I in [0.29, 0.38]; q1's minimum touches
    qw1 near I = 0.337), and 16 with I in [0.15, 0.26]: at eps = -0.1 an upper-wall impact ('1')
    in the first return needs I < ~0.26."""
    rng = np.random.default_rng(20240611)
    theta = rng.uniform(-np.pi, np.pi, 96)
    I = np.concatenate([rng.uniform(0.29, 0.38, 80), rng.uniform(0.15, 0.26, 16)])
    return theta, I


def _system(eps):
    return paper.system(eps)


@pytest.fixture(scope="module", params=EPS_VALUES, ids=lambda e: f"eps={e:+g}")
def reference(request):
    """The reference applied N_RETURNS times to the test points (for one eps)."""
    eps = request.param
    theta, I = _points()
    th, ac, times, margins, its = [theta], [I], [], [], []
    ok = np.ones(theta.size, bool)
    for _ in range(N_RETURNS):
        d = ref.return_map_details(th[-1], ac[-1], eps, h=H)
        th.append(d["theta"])
        ac.append(d["I"])
        times.append(d["time"])
        margins.append(d["margin"])
        its.append(d["itinerary"])
        ok &= d["ok"]
    assert ok.all(), "the reference failed on a test point"
    return {
        "eps": eps,
        "theta": np.stack(th, axis=1),  # (n, N_RETURNS + 1)
        "I": np.stack(ac, axis=1),
        "time": np.stack(times, axis=1),  # (n, N_RETURNS)
        "margin": np.stack(margins, axis=1),
        "itinerary": [list(x) for x in zip(*its)],  # n lists of N_RETURNS strings
    }


# ---------------------------------------------------------------------------------------------
# The reference on its own
# ---------------------------------------------------------------------------------------------


def test_reference_coordinates():
    rng = np.random.default_rng(1)
    theta = rng.uniform(-np.pi, np.pi, 40)
    I = rng.uniform(0.05, 1.0, 40)
    q2, p2 = ref.oscillator2(theta, I)
    th2, I2 = ref.coordinates(q2, p2)
    assert np.max(_angle_diff(th2, theta)) < 1e-14 and np.max(np.abs(I2 - I)) < 1e-14
    # Conventions: theta = 0 at the right turning point, sign(theta) = -sign(p2).
    q2max, p20 = ref.oscillator2(0.0, 0.3)
    assert p20 == 0.0 and q2max > 0 and np.all(np.sign(p2) == -np.sign(theta))
    # I is the action (1/2pi) \oint p dq (quadrature with q = q2max cos(phi)).
    for J in (0.1, 0.337, 0.8):
        E = ref.energy2(J)
        qm = math.asin(ref.ALPHA * math.sqrt(2 * E) / ref.frequency2(E)) / ref.ALPHA
        phi = np.linspace(0.0, np.pi, 20001)
        V = 0.5 * (ref.OMEGA2 / ref.ALPHA) ** 2 * np.tan(ref.ALPHA * qm * np.cos(phi)) ** 2
        f = np.sqrt(np.maximum(2 * (E - V), 0.0)) * qm * np.sin(phi)
        integral = np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(phi))  # trapezoid rule (np.trapezoid needs numpy 2)
        assert abs(integral / np.pi - J) < 1e-10
    # Under the free oscillator 2, theta advances by Omega(E) t and I stays.
    y = (np.zeros(40), np.zeros(40), q2, p2)
    t, n = 3.7, 3700
    for _ in range(n):
        y = ref._rk4(y, t / n, 0.0)
    th3, I3 = ref.coordinates(y[2], y[3])
    Om = ref.frequency2(ref.energy2(I))
    assert np.max(_angle_diff(th3, theta + Om * t)) < 1e-11
    assert np.max(np.abs(I3 - I)) < 1e-12


def test_reference_exact_at_eps0():
    """At eps = 0: I is conserved; without impact the return time is 2 pi and theta advances by
    Omega2 * 2 pi; with one right-wall impact q1 = a cos t hits qw1 at t* = arccos(qw1 / a), the
    return time is 2 t* and theta advances by Omega2 * 2 t*."""
    theta, I = _points()
    d = ref.return_map_details(theta, I, 0.0, h=H)
    its = np.array(d["itinerary"])
    assert {"u", "0", "R", "1"} <= set(its)
    assert np.max(np.abs(d["I"] - I)) < 1e-12
    Om = ref.frequency2(ref.energy2(I))
    a = np.sqrt(2 * (H - ref.energy2(I)))
    free = (its == "u") | (its == "0")
    wall = its == "R"
    T = np.where(wall, 2 * np.arccos(ref.QW1 / np.where(wall, a, 2.0)), 2 * np.pi)
    sel = free | wall
    assert np.max(np.abs(d["time"][sel] - T[sel])) < 1e-11
    assert np.max(_angle_diff(d["theta"][sel], theta[sel] + Om[sel] * T[sel])) < 1e-10
    assert np.max(d["energy_error"]) < 1e-11


@pytest.mark.parametrize("eps", EPS_VALUES)
def test_reference_step_halving(eps):
    theta, I = _points()
    theta, I = theta[::4], I[::4]
    a = ref.return_map_details(theta, I, eps, h=H)
    b = ref.return_map_details(theta, I, eps, h=H, dt=ref.DT / 2)
    keep = a["margin"] > MARGIN_MIN
    assert keep.sum() >= 20 and a["itinerary"] == b["itinerary"]
    # Measured: 1.1e-12 (theta), 1e-13 (I), 1e-12 (time).
    assert np.max(_angle_diff(a["theta"], b["theta"])[keep]) < 1e-11
    assert np.max(np.abs(a["I"] - b["I"])[keep]) < 1e-12
    assert np.max(np.abs(a["time"] - b["time"])[keep]) < 1e-11
    assert np.max(a["energy_error"]) < 1e-11


def test_reference_detects_dips_inside_a_step():
    """A wall dip shorter than one step (both step ends outside) is an impact, located first."""
    dt, eps = 0.1, -0.1
    # q1 dips below qw1 (by ~1e-4) and comes back within the step, with q2 < qw2: right wall.
    y0 = (ref.QW1 + 1e-4, -0.02, -0.8, 0.0)
    y1 = ref._substep(y0, dt, eps)
    assert y1[0] > ref.QW1
    ev = sorted(ref._events(y0, y1, dt, eps, False))
    assert [e[1] for e in ev] == ["x1down", "min1"] and 0 < ev[0][0] < ev[1][0]
    # q2 dips below qw2 within the step while q1 < qw1: upper wall.
    y0 = (-1.2, 0.0, ref.QW2 + 1e-4, -0.02)
    y1 = ref._substep(y0, dt, eps)
    assert y1[2] > ref.QW2
    ev = sorted(ref._events(y0, y1, dt, eps, True))
    assert [e[1] for e in ev] == ["x2down", "min2"] and 0 < ev[0][0] < ev[1][0]


# ---------------------------------------------------------------------------------------------
# hovering against the reference
# ---------------------------------------------------------------------------------------------


def test_return_map_vs_reference(reference):
    eps = reference["eps"]
    theta, I = _points()
    sec = hv.Section(_system(eps), H)
    out = sec.return_map(theta, I, rtol=1e-12, atol=1e-12)

    margin = reference["margin"][:, 0]
    keep = margin > MARGIN_MIN
    assert keep.sum() >= 0.9 * keep.size
    ref_its = [its[0] for its in reference["itinerary"]]
    kept_its = [ref_its[k] for k in np.flatnonzero(keep)]
    assert KINDS <= {s for s in kept_its if len(s) == 1}, Counter(kept_its)

    assert np.all(np.asarray(out.status)[keep] == 0)
    bad = [(k, ref_its[k], out.itinerary[k]) for k in np.flatnonzero(keep) if out.itinerary[k] != ref_its[k]]
    assert not bad, f"itineraries differ (index, reference, hovering): {bad}"

    tol = _tolerance(margin[keep])
    d_theta = _angle_diff(out.theta, reference["theta"][:, 1])[keep]
    d_I = np.abs(np.asarray(out.I) - reference["I"][:, 1])[keep]
    d_t = np.abs(np.asarray(out.time) - reference["time"][:, 0])[keep]
    assert np.all(d_theta < tol), (d_theta.max(), np.flatnonzero(keep)[np.argmax(d_theta / tol)])
    assert np.all(d_I < tol), (d_I.max(), np.flatnonzero(keep)[np.argmax(d_I / tol)])
    assert np.all(d_t < tol), (d_t.max(), np.flatnonzero(keep)[np.argmax(d_t / tol)])


def test_flowmap_iterate_vs_reference(reference):
    eps = reference["eps"]
    theta, I = _points()
    fm = hv.FlowMap(_system(eps), h=H, rtol=1e-12, coordinates="section")
    res = fm.iterate(theta, I, N_RETURNS, record=("orbit", "itinerary"))
    phi, K = np.asarray(res.phi), np.asarray(res.K)
    assert phi.shape == K.shape == (theta.size, N_RETURNS + 1)

    margin = np.min(reference["margin"], axis=1)
    keep = margin > MARGIN_MIN
    assert keep.sum() >= 0.9 * keep.size
    kept_its = [s for k in np.flatnonzero(keep) for s in reference["itinerary"][k]]
    assert KINDS <= set(kept_its), Counter(kept_its)

    bad = [
        (k, reference["itinerary"][k], list(res.itinerary[k]))
        for k in np.flatnonzero(keep)
        if list(res.itinerary[k]) != reference["itinerary"][k]
    ]
    assert not bad, f"itineraries differ (index, reference, hovering): {bad}"

    assert np.max(_angle_diff(phi[:, 0], theta)) < 1e-15 and np.max(np.abs(K[:, 0] - I)) < 1e-15
    tol = _tolerance(margin[keep], ITER_TOL)[:, None]
    d_theta = _angle_diff(phi, reference["theta"])[keep]
    d_I = np.abs(K - reference["I"])[keep]
    assert np.all(d_theta < tol), d_theta.max(axis=0)
    assert np.all(d_I < tol), d_I.max(axis=0)
