"""Dense output: FlowMap.iterate(record=("trajectory",)) and Section.return_map(trajectory_dt=...)
against the closed-form flow of two harmonic oscillators, the walls, the energy, and the orbit
computed without a trajectory (bit for bit)."""

from __future__ import annotations

import numpy as np
import pytest

import hovering as hv
from hovering import Status, TrajectoryPoint

W1, W2 = 1.0, 1.4


def harmonic(geometry="none"):
    return hv.StepSystem(
        V1=hv.Harmonic(W1), V2=hv.Harmonic(W2), coupling=hv.Bilinear(), eps=0.0, qw1=-1.0, qw2=-0.5, geometry=geometry
    )


def example():
    return hv.StepSystem(
        V1=hv.Harmonic(omega=1.0),
        V2=hv.Tan(omega=1.4, alpha=0.7),
        coupling=hv.Bilinear(),
        eps=-0.05,
        qw1=-1.0,
        qw2=-0.5,
        geometry="step",
    )


def closed_form(z, t):
    """The eps = 0 flow of two harmonic oscillators from z = (q1, p1, q2, p2) after times t."""
    q1, p1, q2, p2 = z
    c1, s1, c2, s2 = np.cos(W1 * t), np.sin(W1 * t), np.cos(W2 * t), np.sin(W2 * t)
    return np.stack(
        [q1 * c1 + p1 / W1 * s1, -q1 * W1 * s1 + p1 * c1, q2 * c2 + p2 / W2 * s2, -q2 * W2 * s2 + p2 * c2], axis=-1
    )


def rows(res, i):
    a, b = res.trajectory_index[i], res.trajectory_index[i + 1]
    return res.trajectory[a:b], res.trajectory_kind[a:b]


@pytest.mark.parametrize("rtol", [1e-8, 1e-10, 1e-12])
def test_smooth_harmonic_trajectory_is_the_closed_form(rtol):
    # geometry "none", eps = 0: the flow is two uncoupled harmonic oscillators, known exactly. Each
    # sample is one exact rk8pd step from the start of its accepted step, so it carries the
    # step control's accuracy: measured <= 0.9 rtol (at 1e-8, 1e-10, 1e-12) against the closed form
    # from the return's start; 20 rtol leaves room. (A cubic Hermite interpolant of the ~0.25-long
    # steps would be ~1e-5 off.) The energy along the whole trajectory stays within the same 20 rtol.
    fm = hv.FlowMap(harmonic(), h=1.0, coordinates="section", rtol=rtol)
    rng = np.random.default_rng(0)
    th, I = rng.uniform(-np.pi, np.pi, 6), rng.uniform(0.05, 0.6, 6)
    dt, ns = 0.037, 5
    res = fm.iterate(th, I, ns, record=("trajectory", "states", "times", "orbit"), trajectory_dt=dt)
    assert np.all(res.status == Status.OK) and not res.trajectory_truncated.any()
    assert res.trajectory.shape == (res.trajectory_index[-1], 5) and res.trajectory_index.shape == (7,)
    assert res.trajectory.dtype == np.float64 and res.trajectory_index.dtype == np.int64
    for i in range(6):
        tr, kind = rows(res, i)
        assert np.array_equal(tr, res.trajectory_of(i)) and np.array_equal(res.trajectory_of(i - 6), tr)
        t = tr[:, 0]
        assert np.all(np.diff(t) >= 0)
        T = np.concatenate([[0.0], np.cumsum(res.time[i])])  # the clock runs on across returns
        # Samples at exactly t = k dt, k = 0, 1, ... up to the end of the last return, none missing.
        s = t[kind == TrajectoryPoint.SAMPLE]
        k_last = int(np.ceil(T[-1] / dt)) - 1
        assert np.array_equal(s, np.arange(k_last + 1) * dt)
        # No walls: only samples and the ns return points, at the return times.
        assert np.array_equal(
            np.flatnonzero(kind != TrajectoryPoint.SAMPLE), np.flatnonzero(kind == TrajectoryPoint.RETURN)
        )
        assert np.allclose(t[kind == TrajectoryPoint.RETURN], T[1:], rtol=0, atol=1e-12)
        # Each return's samples are the closed-form flow from the point of Sigma_h it started from.
        for j in range(ns):
            m = (kind == TrajectoryPoint.SAMPLE) & (t >= T[j]) & (t < T[j + 1])
            assert np.abs(closed_form(res.z[i, j], t[m] - T[j]) - tr[m, 1:]).max() <= 20 * rtol
        assert np.abs(fm.sys.core.energy(np.ascontiguousarray(tr[:, 1:])) - 1.0).max() <= 20 * rtol
        # The return points are the images: their section coordinates are the next orbit points.
        c = fm.section.coordinates(tr[kind == TrajectoryPoint.RETURN, 1:])
        assert np.array_equal(c[:, 0], res.phi[i, 1:]) and np.array_equal(c[:, 1], res.K[i, 1:])


def test_impacts_lie_on_the_walls_and_samples_follow_the_reflected_flow():
    # eps = 0 with the step: between events the flow is still the closed form, restarted from the
    # post-impact state; impacts are recorded twice (before and after the reflection, same time).
    rtol = 1e-10
    fm = hv.FlowMap(harmonic("step"), h=1.0, coordinates="section", rtol=rtol)
    rng = np.random.default_rng(3)
    th, I = rng.uniform(-np.pi, np.pi, 20), rng.uniform(0.02, 0.45, 20)
    res = fm.iterate(th, I, 4, record=("trajectory", "states", "times", "itinerary"), trajectory_dt=0.05)
    n_right = n_upper = 0
    for i in np.flatnonzero(res.status == Status.OK):
        tr, kind = rows(res, i)
        t, z = tr[:, 0], tr[:, 1:]
        inn, out = np.flatnonzero(kind == TrajectoryPoint.IMPACT_IN), np.flatnonzero(kind == TrajectoryPoint.IMPACT_OUT)
        assert np.array_equal(out, inn + 1) and np.array_equal(t[inn], t[out])
        assert len(inn) == sum(len(s) for s in res.itinerary[i] if s not in ("0", "u"))
        for a, b in zip(inn, out):
            right = abs(z[a, 0] - -1.0) <= 1e-12
            upper = abs(z[a, 2] - -0.5) <= 1e-12
            assert right != upper  # exactly one wall, to 1e-12 (a corner hit would have stopped the orbit)
            w = 0 if right else 2
            assert z[b, w] == (-1.0 if right else -0.5)  # placed exactly on the wall
            assert z[b, w + 1] == -z[a, w + 1] and z[b, 2 - w] == z[a, 2 - w] and z[b, 3 - w] == z[a, 3 - w]
            n_right, n_upper = n_right + right, n_upper + upper
        # Samples between events: the closed form from the last event (return start or reflection).
        T = np.concatenate([[0.0], np.cumsum(res.time[i])])
        anchors = [(T[j], res.z[i, j]) for j in range(4)] + [(t[b], z[b]) for b in out]
        anchors.sort(key=lambda a: a[0])
        at = np.array([a[0] for a in anchors])
        for r in np.flatnonzero(kind == TrajectoryPoint.SAMPLE):
            j = np.searchsorted(at, t[r], side="right") - 1
            # Post-impact states are located events (~rtol), then the flow adds its own ~rtol.
            assert np.abs(closed_form(anchors[j][1], t[r] - anchors[j][0]) - z[r]).max() <= 20 * rtol
    assert n_right > 0 and n_upper > 0  # both walls were exercised


def test_trajectory_changes_nothing_and_conserves_energy():
    # The example system (Tan potential, coupling, the step): the orbit with a trajectory is the
    # orbit without, bit for bit; the energy along the trajectory is that of Sigma_h to the
    # integrator's accuracy (each return's |H - h| is <= energy_error of the record; measured 1e-10
    # at rtol 1e-10, 20 rtol allowed).
    rtol = 1e-10
    fm = hv.FlowMap(example(), h=1.0, rtol=rtol)
    rng = np.random.default_rng(7)
    phi, K = rng.uniform(-np.pi, np.pi, 12), rng.uniform(-0.1, 0.05, 12)
    off = fm.iterate(phi, K, 6, record=("orbit", "regions", "itinerary"))
    on = fm.iterate(phi, K, 6, record=("orbit", "regions", "itinerary", "trajectory"), trajectory_dt=0.02)
    assert np.array_equal(off.phi, on.phi, equal_nan=True) and np.array_equal(off.K, on.K, equal_nan=True)
    assert np.array_equal(off.region, on.region) and off.itinerary == on.itinerary
    assert off.trajectory is None and off.work["dense_samples"] == 0
    # Every sample computed is counted: those kept, and those of a verified return's first trace,
    # which the kept trace's replace (unverified, the two are equal).
    kept = np.count_nonzero(on.trajectory_kind == TrajectoryPoint.SAMPLE)
    assert on.work["dense_samples"] >= kept
    plain = hv.FlowMap(example(), h=1.0, rtol=rtol, verify_steps=0)
    once = plain.iterate(phi, K, 6, record=("trajectory",), trajectory_dt=0.02)
    assert once.work["dense_samples"] == np.count_nonzero(once.trajectory_kind == TrajectoryPoint.SAMPLE)
    H = fm.sys.core.energy(np.ascontiguousarray(on.trajectory[:, 1:]))
    assert np.abs(H - 1.0).max() <= 20 * rtol
    impacts = np.isin(on.trajectory_kind, [TrajectoryPoint.IMPACT_IN, TrajectoryPoint.IMPACT_OUT])
    assert impacts.any()
    q = on.trajectory[impacts]
    assert np.all(np.minimum(np.abs(q[:, 1] + 1.0), np.abs(q[:, 3] + 0.5)) <= 1e-12)


def test_return_map_trajectory_and_the_flow_map_agree():
    # One return of Section.return_map records the same rows as one return of FlowMap.iterate
    # from the same point of Sigma_h (same tracer, same clock origin).
    sys = example()
    fm = hv.FlowMap(sys, h=1.0, coordinates="section", rtol=1e-10)
    th, I = np.array([0.4, -2.0, 2.9]), np.array([0.3, 0.35, 0.32])
    a = fm.iterate(th, I, 1, record=("trajectory",), trajectory_dt=0.03)
    b = fm.section.return_map(th, I, rtol=1e-10, atol=1e-10, trajectory_dt=0.03)
    assert np.array_equal(a.trajectory, b.trajectory) and np.array_equal(a.trajectory_index, b.trajectory_index)
    assert np.array_equal(a.trajectory_kind, b.trajectory_kind)
    for i in range(3):
        assert b.trajectory_of(i)[-1, 0] == b.time[i] and np.array_equal(b.trajectory_of(i)[-1, 1:], b.z[i])
    assert b.work["dense_samples"] > 0
    c = fm.section.return_map(th, I, rtol=1e-10, atol=1e-10)
    assert c.trajectory is None and c.work["dense_samples"] == 0 and np.array_equal(c.z, b.z)
    with pytest.raises(ValueError, match="no trajectory was recorded"):
        c.trajectory_of(0)


def test_max_trajectory_points_truncates_per_orbit_and_is_checked_first():
    fm = hv.FlowMap(example(), h=1.0, rtol=1e-10)
    phi, K = np.array([0.1, 1.2, -2.0]), np.array([-0.02, 0.01, -0.05])
    full = fm.iterate(phi, K, 3, record=("trajectory",), trajectory_dt=0.01)
    per_orbit = np.diff(full.trajectory_index)
    cap = 3 * (int(per_orbit.min()) // 2)  # half of the shortest orbit's points per orbit
    cut = fm.iterate(phi, K, 3, record=("trajectory",), trajectory_dt=0.01, max_trajectory_points=cap)
    assert np.all(cut.trajectory_truncated) and not full.trajectory_truncated.any()
    assert np.all(np.diff(cut.trajectory_index) == cap // 3)
    for i in range(3):  # the kept points are the first ones; the orbit itself is unchanged
        assert np.array_equal(cut.trajectory_of(i), full.trajectory_of(i)[: cap // 3])
    assert np.array_equal(cut.phi_final, full.phi_final) and np.array_equal(cut.K_final, full.K_final)
    assert cut.work["dense_samples"] < full.work["dense_samples"]  # no dense work once an orbit is full
    with pytest.raises(ValueError, match=r"max_trajectory_points .* must be an integer in \[6, "):
        fm.iterate(phi, K, 3, record=("trajectory",), trajectory_dt=0.01, max_trajectory_points=5)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (
            dict(record=("trajectory",)),
            r"trajectory_dt \(the sample spacing\) must be a number in \(0, inf\) .*got None",
        ),
        (dict(record=("orbit",), trajectory_dt=0.1), "only used with record 'trajectory'"),
        (dict(record=("trajectory",), trajectory_dt=0.0), r"trajectory_dt must lie in \(0.0, inf\), got 0.0"),
        (dict(record=("trajectory",), trajectory_dt=float("nan")), "trajectory_dt must be finite"),
        (dict(record=("trajectory",), trajectory_dt="0.1"), "trajectory_dt must be a real number"),
        (dict(record=("trajectory",), trajectory_dt=0.1, max_trajectory_points=2.5), "max_trajectory_points"),
        (dict(record=("trajectories",)), "unknown key"),
    ],
)
def test_bad_trajectory_arguments_are_named(kwargs, match):
    fm = hv.FlowMap(harmonic(), h=1.0, coordinates="section")
    with pytest.raises(ValueError, match=match):
        fm.iterate([0.1], [0.3], 2, **kwargs)
    if "trajectory_dt" in kwargs and "record" in kwargs and kwargs["record"] == ("trajectory",):
        with pytest.raises(ValueError, match=match):
            fm.section.return_map([0.1], [0.3], **{k: v for k, v in kwargs.items() if k != "record"})


@pytest.mark.parametrize("stepper", ["rk8pd", "rkf45", "rk4", "msadams", "taylor"])
def test_every_stepper_records_without_changing_the_orbit(stepper):
    # The samples are extra stepper steps from the accepted steps' starts (msadams: its rk8pd
    # extension); none of them touches the state the integration goes on from. Each orbit is
    # also what it is alone (msadams' clock restarts with every return), whatever the thread count.
    fm = hv.FlowMap(example(), h=1.0, coordinates="section", stepper=stepper, rtol=1e-9)
    th, I = np.linspace(-3, 3, 6), np.full(6, 0.31)
    off = fm.iterate(th, I, 3, record=("orbit",), n_threads=1)
    on = fm.iterate(th, I, 3, record=("orbit", "trajectory", "energy_error"), trajectory_dt=0.05, n_threads=2)
    alone = fm.iterate(th[2:3], I[2:3], 3, record=("orbit",), n_threads=1)
    assert np.array_equal(off.phi, on.phi) and np.array_equal(off.K, on.K)
    assert np.array_equal(off.phi[2], alone.phi[0]) and np.array_equal(off.K[2], alone.K[0])
    # Energy along the trajectory: the samples have the integrator's own accuracy, i.e. the energy
    # error of the returns themselves (measured: at most 1.8x the largest |H(image) - h|, from
    # 3e-10 for rk8pd to 2e-7 for msadams at rtol 1e-9; the error oscillates along a return, so a
    # sample inside it may exceed its end's).
    H = fm.sys.core.energy(np.ascontiguousarray(on.trajectory[:, 1:]))
    assert np.abs(H - 1.0).max() <= 3 * np.nanmax(on.energy_error) + 1e-12
