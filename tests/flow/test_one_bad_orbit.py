"""One bad orbit never loses the batch (issue 18, README "Numerical outcomes are per-orbit statuses").

A runaway orbit (status NON_FINITE, its last state ~1e307) among good ones used to make
Section.return_map raise for the whole batch: the Python side computed the section coordinates of
every row, and the runaway's H2 overflows (``action(inf)``). Every entry point of both models gets
one bad orbit among good ones here; the good ones must equal what they give alone (bit for bit:
each orbit is computed independently of the batch) and the bad one keeps its status, with NaN
records.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import hovering as hv
from hovering import FlowStatus, Status

#: An indefinite quadratic potential (eps = -0.5 > the oscillators' 0.04): orbits that do not
#: reflect off the wall quickly run away (NON_FINITE once the kinetic energy passes 1e4 (1 + h),
#: t ~ 6).
RUNAWAY = hv.StepSystem(
    V1=hv.Harmonic(0.2), V2=hv.Harmonic(0.2), coupling=hv.Bilinear(), eps=-0.5, qw1=-1, qw2=-2, geometry="wall"
)
H = 0.3
THETA = np.linspace(-math.pi, math.pi, 41)[[0, 1, 2, 12, 33, 34]]
I0 = np.full(6, 0.5)
BAD = 3


def same(a, b) -> bool:
    return np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True)


@pytest.fixture(scope="module")
def sec():
    return hv.Section(RUNAWAY, H)


def test_return_map_keeps_the_good_returns_beside_a_runaway(sec):
    r = sec.return_map(THETA, I0, trajectory_dt=0.5)
    assert r.status[BAD] == FlowStatus.NON_FINITE
    assert all(r.status[i] == FlowStatus.OK for i in range(6) if i != BAD)
    for i in range(6):
        alone = sec.return_map(THETA[i : i + 1], I0[i : i + 1], trajectory_dt=0.5)
        assert alone.status[0] == r.status[i]
        for f in ("theta", "I", "z", "time", "energy_error", "steps", "region"):
            assert same(getattr(alone, f)[0], getattr(r, f)[i]), (i, f)
        assert alone.itinerary[0] == r.itinerary[i]
        assert same(alone.trajectory_of(0), r.trajectory_of(i))
    # The runaway: its last state and time (finite, kinetic energy past 1e4 (1 + h)), no image
    # coordinates, H kept to the integrator's accuracy.
    assert np.isnan(r.theta[BAD]) and np.isnan(r.I[BAD])
    kinetic = 0.5 * (r.z[BAD, 1] ** 2 + r.z[BAD, 3] ** 2)
    assert np.isfinite(r.z[BAD]).all() and kinetic > 1e4 * (1 + H) and r.time[BAD] > 4
    assert r.energy_error[BAD] < 1e-12 * kinetic  # measured 8e-14 (rk8pd at rtol 1e-10)
    assert r.count(FlowStatus.NON_FINITE) == 1


def test_section_coordinates_of_a_runaway_state_are_nan(sec):
    # A state whose H2 overflows (where a runaway would end without the kinetic-energy stop) has
    # no action in double precision, as a state with a non-finite entry.
    r = sec.return_map(THETA, I0)
    r.z[BAD] = [1e300, 1e300, 1e300, 1e300]
    c = sec.coordinates(r.z)
    assert np.isnan(c[BAD]).all()
    ok = r.status == FlowStatus.OK
    assert same(c[ok, 0], r.theta[ok]) and same(c[ok, 1], r.I[ok])
    assert same(sec.coordinates(r.z[ok]), c[ok])


def test_flow_map_keeps_the_good_orbits_beside_a_runaway():
    fm = hv.FlowMap(RUNAWAY, H, coordinates="section")
    r = fm.returns(THETA, I0)
    assert r.status[BAD] == FlowStatus.NON_FINITE and np.isnan([r.phi[BAD], r.K[BAD]]).all()
    phi1, K1 = fm.step(THETA, I0)
    reg = fm.region(THETA, I0)
    back = fm.returns(THETA, I0, inverse=True)
    record = [k for k in hv.normal.FLOW_RECORD_KEYS if k != "trajectory"]
    it = fm.iterate(THETA, I0, 3, record=record)
    rot = hv.rotation_number(it)
    assert it.status[BAD] == Status.NON_FINITE and it.steps_done[BAD] == 0 and np.isnan(rot[BAD])
    for i in range(6):
        one = fm.returns(THETA[i : i + 1], I0[i : i + 1])
        assert one.status[0] == r.status[i] and same(one.phi[0], phi1[i]) and same(one.K[0], K1[i])
        assert one.region[0] == reg[i] and same(one.z[0], r.z[i]) and same(one.time[0], r.time[i])
        assert same(fm.returns(THETA[i : i + 1], I0[i : i + 1], inverse=True).phi[0], back.phi[i])
        alone = fm.iterate(THETA[i : i + 1], I0[i : i + 1], 3, record=record)
        assert alone.status[0] == it.status[i] and alone.steps_done[0] == it.steps_done[i]
        for f in (
            "phi",
            "K",
            "region",
            "rotation",
            "theta",
            "I",
            "z",
            "time",
            "energy_error",
            "integrator_steps",
            "phi_final",
            "K_final",
            "visited",
        ):
            assert same(getattr(alone, f)[0], getattr(it, f)[i]), (i, f)
        assert alone.itinerary[0] == it.itinerary[i]
        assert same(hv.rotation_number(alone)[0], rot[i])


def test_results_with_a_runaway_save_and_load(sec, tmp_path):
    r = sec.return_map(THETA, I0)
    hv.save(r, tmp_path / "r.npz")
    back = hv.load(tmp_path / "r.npz")
    for f in ("theta", "I", "z", "time", "status"):
        assert same(getattr(back, f), getattr(r, f))
    it = hv.FlowMap(RUNAWAY, H, coordinates="section").iterate(THETA, I0, 3, record=("orbit", "section", "states"))
    hv.save(it, tmp_path / "it.npz")
    back = hv.load(tmp_path / "it.npz")
    for f in ("phi", "K", "theta", "I", "z", "status", "steps_done"):
        assert same(getattr(back, f), getattr(it, f))


def test_flow_analyses_keep_the_good_orbits_beside_a_stopped_one():
    # Normal coordinates (the rotation analyses need them): a start below the band is OFF_SECTION.
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
    phi, K = np.array([0.5, 1.0, 1.5]), np.array([-0.1, fm.valid_band()[0] - 0.2, 0.1])
    res = fm.iterate(phi, K, 40, record=("orbit", "regions", "rotation"))
    assert list(res.status) == [Status.OK, Status.OFF_SECTION, Status.OK] and res.steps_done[1] == 0
    rho, wb, reg = hv.rotation_number(res), hv.rotation_number(res, "birkhoff"), hv.regularity(res)
    assert np.isnan([rho[1], wb[1], reg[1]]).all() and fm.step_rotations(res, 1).size == 0
    for i in (0, 2):
        alone = fm.iterate(phi[i : i + 1], K[i : i + 1], 40, record=("orbit", "regions", "rotation"))
        assert same(alone.phi[0], res.phi[i]) and same(fm.step_rotations(alone, 0), fm.step_rotations(res, i))
        assert rho[i] == hv.rotation_number(alone)[0] and wb[i] == hv.rotation_number(alone, "birkhoff")[0]
        assert reg[i] == hv.regularity(alone)[0]


@pytest.mark.parametrize("which", ["map", "family"])
def test_truncated_analyses_keep_the_good_orbits_beside_an_escaped_one(which):
    m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=2.0)
    if which == "family":
        m = hv.TruncatedFamily.from_map(
            m, np.concatenate([np.linspace(-2.0, 0.0, 41), np.linspace(0.05, 1.0, 20)]), forcing=(1.0, 0.2)
        )
    lo = m.valid_band()[0]
    phi, K = np.array([0.5, 0.5, 1.5]), np.array([-0.1, lo + 1e-9, 0.3])  # the second leaves the band
    record = ("orbit", "regions", "rotation", "visited")
    res = m.iterate(phi, K, 200, record=record)
    assert res.status[1] == Status.ESCAPED and res.status[0] == res.status[2] == Status.OK
    rho, wb, reg = hv.rotation_number(res), hv.rotation_number(res, "birkhoff"), hv.regularity(res)
    assert np.isnan(res.phi[1, res.steps_done[1] + 1 :]).all()
    for i in (0, 2):
        alone = m.iterate(phi[i : i + 1], K[i : i + 1], 200, record=record)
        for f in ("phi", "K", "region", "rotation", "visited", "phi_final", "K_final"):
            assert same(getattr(alone, f)[0], getattr(res, f)[i]), (i, f)
        assert rho[i] == hv.rotation_number(alone)[0] and wb[i] == hv.rotation_number(alone, "birkhoff")[0]
        assert reg[i] == hv.regularity(alone)[0]
