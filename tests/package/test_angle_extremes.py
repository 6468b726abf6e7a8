"""Valid input never raises: every angle of [-pi, pi) works in every entry point of both models,
the extremes and their neighbours in ulps included, and so does every finite angle where the API
documents wrapping (issue 18, README "Values are in range").

It used to fail at phi = nextafter(pi, 0): the flow map's conversion to the section wrapped it to one
ulp below -pi ((phi + pi) rounds up to 2 pi; the wrap had no correction for that side), and
FlowMap.step / region / iterate raised "theta must lie in [-pi, pi]" at every K, losing the batch.
Each check compares with an independent value: a wrapped input gives what the wrapped angle gives
(bit for bit), and across the seam at +-pi the maps are continuous, so the image of pi - k ulps
lies within 1e-9 of the image of -pi (a few ulps times the map's derivative, plus the flow's
integration noise of ~1e-12 for two starts 1e-15 apart; 1e-9 is far below any real jump: the
seam is chosen away from every corner curve).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import hovering as hv
from hovering import FlowStatus, Status, wrap

PI = math.pi


def ulps_from(x: float, k: int, toward: float) -> float:
    for _ in range(k):
        x = float(np.nextafter(x, toward))
    return x


#: [-pi, pi): -pi and the next 3 doubles above it, the 4 doubles below pi.
LOW = [ulps_from(-PI, k, 0.0) for k in range(4)]
HIGH = [ulps_from(PI, k, 0.0) for k in range(1, 5)]
IN_RANGE = LOW + HIGH
#: Outside [-pi, pi), for the entry points that document wrapping.
WRAPPED = [PI, ulps_from(PI, 1, 4.0), ulps_from(-PI, 1, -4.0), ulps_from(3 * PI, 1, 0.0), -3 * PI, 2 * PI, 1e6]


def in_circle(x) -> bool:
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    return bool(np.all((x >= -PI) & (x < PI)))


def seam_gap(a, b) -> float:
    """Largest distance on the circle between two arrays of angles."""
    return float(np.max(np.abs(wrap(np.asarray(a, float) - np.asarray(b, float)))))


# ------------------------------------------------------------------ the truncated models


@pytest.fixture(scope="module")
def truncated_maps():
    m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=2.0)
    fam = hv.TruncatedFamily.from_map(
        m, np.concatenate([np.linspace(-1.5, 0.0, 31), np.linspace(0.05, 1.0, 20)]), forcing=(1.0, 0.2)
    )
    return {"TruncatedMap": m, "TruncatedFamily": fam}


#: Heights where no arc boundary lies near phi = +-pi (checked below), and one above the band's
#: arcs (K > 0: the whole circle is J_0).
TRUNCATED_K = (-0.3, 0.2)


@pytest.mark.parametrize("name", ["TruncatedMap", "TruncatedFamily"])
def test_truncated_entry_points_take_every_angle(truncated_maps, name):
    m = truncated_maps[name]
    for K in TRUNCATED_K:
        starts = m.arcs(K) if K < 0 else None
        if starts is not None:  # the seam is inside one arc, far from its ends
            ends = np.asarray([v for k, v in starts.items() if k.startswith("start")], float).ravel()
            assert np.min(np.abs(wrap(ends - PI))) > 1e-3, ends
        ref_step = m.step(-PI, K)
        ref_inv = m.step_inverse(-PI, K)
        for a in IN_RANGE:
            p1, K1 = m.step(a, K)
            q1, L1 = m.step_inverse(a, K)
            assert in_circle([p1, q1])
            assert seam_gap(p1, ref_step[0]) < 1e-9 and abs(K1 - ref_step[1]) < 1e-9
            assert seam_gap(q1, ref_inv[0]) < 1e-9 and abs(L1 - ref_inv[1]) < 1e-9
            assert m.region(a, K) == m.region(-PI, K)
            assert abs(m.rotation(a, K) - m.rotation(-PI, K)) < 1e-9
            r = m.iterate([a, 0.5], [K, K], 5, record=("orbit",))
            assert (r.status == Status.OK).all() and in_circle(r.phi) and in_circle(r.phi_final)
            pr, _ = m.reversal(a, K)
            assert in_circle(pr)
            assert np.isfinite(m.forcing_at(a))
        for a in WRAPPED:  # wrapped first, so exactly as the wrapped angle
            w = wrap(a)
            assert m.step(a, K) == m.step(w, K)
            assert m.step_inverse(a, K) == m.step_inverse(w, K)
            assert m.region(a, K) == m.region(w, K) and m.rotation(a, K) == m.rotation(w, K)
            r, rw = m.iterate([a], [K], 5, record=("orbit",)), m.iterate([w], [K], 5, record=("orbit",))
            assert np.array_equal(r.phi, rw.phi) and np.array_equal(r.K, rw.K)
            # sin(phi) of the raw angle: |phi| <= 1e6 wraps to within 1e-9 (README), as sin does
            assert m.forcing_at(a) == pytest.approx(m.forcing_at(w), abs=1e-9)
    assert in_circle(m.L1(np.linspace(-1, 1, 41))) and in_circle(m.L2(np.linspace(-1, 1, 41)))


def test_critical_curve_on_a_vertical_line_at_the_seam(truncated_maps):
    # line = phi is an angle input: -pi and its wrapped twin pi search the same line, and pi - 1 ulp
    # finds the same curve (continuity; the grid and bisection are the same).
    m = truncated_maps["TruncatedMap"]
    kw = dict(n_steps=512, n_grid=8, K_range=(-0.6, 0.4), tol=1e-3, n_threads=1)
    a = hv.critical_curve(m, line=-PI, **kw)
    assert hv.critical_curve(m, line=PI, **kw).K0 == a.K0
    assert abs(hv.critical_curve(m, line=HIGH[0], **kw).K0 - a.K0) <= 2e-3


# ------------------------------------------------------------------ the flow


@pytest.fixture(scope="module")
def flow():
    s = hv.StepSystem(
        V1=hv.Harmonic(omega=1.0),
        V2=hv.Tan(omega=1.4, alpha=0.7),
        coupling=hv.Bilinear(),
        eps=-0.05,
        qw1=-1.0,
        qw2=-0.5,
        geometry="step",
    )
    fm = hv.FlowMap(s, 1.0)
    return {
        "sys": s,
        "sec": hv.Section(s, 1.0),
        "normal": fm,
        "section": hv.FlowMap(s, 1.0, coordinates="section", curve=None),
    }


#: (coordinates, heights): K in normal coordinates, I in section coordinates; orbits that return
#: regularly from the whole seam (asserted: status OK).
FLOW_K = {"normal": (-0.2, 0.05), "section": (0.3, 0.6)}


@pytest.mark.parametrize("coords", ["normal", "section"])
def test_flow_map_entry_points_take_every_angle(flow, coords):
    fm = flow[coords]
    for K in FLOW_K[coords]:
        ref = fm.returns([-PI], [K])
        ref_inv = fm.returns([-PI], [K], inverse=True)
        assert ref.status[0] == FlowStatus.OK and ref_inv.status[0] == FlowStatus.OK
        for a in IN_RANGE:
            r = fm.returns([a, 0.1], [K, K])
            assert (r.status == FlowStatus.OK).all() and in_circle(r.phi)
            assert seam_gap(r.phi[0], ref.phi[0]) < 1e-9 and abs(r.K[0] - ref.K[0]) < 1e-9
            assert r.region[0] == ref.region[0] and r.itinerary[0] == ref.itinerary[0]
            p1, _ = fm.step(a, K)
            q1, L1 = fm.step_inverse(a, K)
            assert in_circle([p1, q1]) and seam_gap(q1, ref_inv.phi[0]) < 1e-9 and abs(L1 - ref_inv.K[0]) < 1e-9
            assert fm.region(a, K) == ref.region[0]
            it = fm.iterate([a, 0.1], [K, K], 2, record=("orbit", "section"))
            assert (it.status == Status.OK).all() and in_circle(it.phi) and in_circle(it.theta)
        for a in WRAPPED:  # "phi any finite angle, wrapped"
            w = wrap(a)
            r, rw = fm.returns([a], [K]), fm.returns([w], [K])
            assert r.phi[0] == rw.phi[0] and r.K[0] == rw.K[0] and r.status[0] == FlowStatus.OK
            assert fm.step(a, K) == fm.step(w, K) and fm.region(a, K) == fm.region(w, K)
            assert fm.step_inverse(a, K) == fm.step_inverse(w, K)
            it, itw = fm.iterate([a], [K], 2, record=("orbit",)), fm.iterate([w], [K], 2, record=("orbit",))
            assert np.array_equal(it.phi, itw.phi) and np.array_equal(it.K, itw.K)


def test_section_entry_points_take_every_angle(flow):
    # Section coordinates take theta in [-pi, pi] (closed: pi is -pi's twin there).
    sec = flow["sec"]
    for I in (0.3, 0.6):
        z_ref = sec.point(-PI, I)
        ref = sec.return_map([-PI], [I])
        assert ref.status[0] == FlowStatus.OK
        for a in IN_RANGE + [PI]:
            z = sec.point(a, I)
            assert np.max(np.abs(z - z_ref)) < 1e-9
            c = sec.coordinates(z)
            assert in_circle(c[:, 0]) and seam_gap(c[0, 0], a) < 1e-12 and abs(c[0, 1] - I) < 1e-12
            r = sec.return_map([a, 0.0], [I, I])
            assert (r.status == FlowStatus.OK).all() and in_circle(r.theta)
            assert seam_gap(r.theta[0], ref.theta[0]) < 1e-9 and abs(r.I[0] - ref.I[0]) < 1e-9


def test_normal_coordinates_take_every_angle(flow):
    sec, curve = flow["sec"], flow["normal"].curve
    ref = curve(-PI)
    for a in IN_RANGE + [PI]:
        assert abs(curve(a) - ref) < 1e-9
        th, K = curve.to_normal(a, 0.5)
        assert in_circle(th) and abs(K - (0.5 - ref)) < 1e-9
        ph, I = curve.from_normal(a, -0.1)
        assert in_circle(ph) and abs(I - (ref - 0.1)) < 1e-9
        assert np.isfinite(curve.forcing(a)).all()
        # The bisection functions (the curve point by point, measured on the flow): to 1e-9 of
        # the interpolated curve (whose error is below 1e-12, README) at the seam as elsewhere.
        t = hv.tangential_curve(sec, a)
        assert abs(float(np.ravel(t)[0]) - ref) < 1e-9
        p, k = hv.to_normal(sec, a, 0.5)
        assert in_circle(p) and abs(float(np.ravel(k)[0]) - (0.5 - ref)) < 1e-9
        p, i = hv.from_normal(sec, a, -0.1)
        assert in_circle(p) and abs(float(np.ravel(i)[0]) - (ref - 0.1)) < 1e-9
        assert np.isfinite(hv.forcing_function(sec, a)).all()
    for a in WRAPPED:  # from_normal wraps phi
        assert curve.from_normal(a, -0.1) == curve.from_normal(wrap(a), -0.1)


def test_potential_angles_take_every_angle(flow):
    V2 = flow["sys"].V2
    q_ref, p_ref = V2.point_at(-PI, 0.5)
    for a in IN_RANGE + [PI]:
        q, p = V2.point_at(a, 0.5)
        assert abs(q - q_ref) < 1e-9 and abs(p - p_ref) < 1e-9
        assert seam_gap(V2.angle_of_point(q, p, 0.5), a) < 1e-9
