"""One point per call (issue 33): the fast paths of FlowMap.step / step_inverse / region,
Section.return_map and TruncatedMap.step give what the array paths give, bit for bit; bad input is
still refused with a message naming it; the tracers a map keeps between calls change nothing.

No timing here (benchmarks/bench_per_call.py measures the costs)."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

import hovering as hv
from hovering import paper
from hovering.flow.system import Bilinear, Harmonic, StepSystem, Tan

H = paper.H


def _random_system(rng, geometry):
    """A random system of the kinds taylor and rk8pd both take: Harmonic or Tan potentials, a bilinear coupling."""
    V1 = Harmonic(rng.uniform(0.8, 1.3))
    V2 = Tan(rng.uniform(1.1, 1.6), rng.uniform(0.5, 0.8)) if rng.random() < 0.7 else Harmonic(rng.uniform(1.2, 1.6))
    return StepSystem(V1, V2, Bilinear(), eps=rng.uniform(-0.08, 0.08), qw1=-1.0, qw2=-0.5, geometry=geometry)


def _same(a, b):
    return np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True)


@pytest.mark.parametrize("geometry", ["step", "wall"])
@pytest.mark.parametrize("stepper", ["taylor", "rk8pd"])
def test_one_point_fast_paths_equal_the_array_paths_bit_for_bit(geometry, stepper):
    rng = np.random.default_rng(33 + (geometry == "wall") + 2 * (stepper == "taylor"))
    for _ in range(2):
        sys_ = _random_system(rng, geometry)
        sec = hv.Section(sys_, H)
        fm = hv.FlowMap(sys_, H, coordinates="section", stepper=stepper, rtol=1e-9)
        I_tan = sys_.V2.action(H - sys_.V1.V(sys_.qw1))
        th = rng.uniform(-np.pi, np.pi, 12)
        I = I_tan * rng.uniform(0.3, 1.3, 12)
        I[-1] = 50.0  # no point of Sigma_h: OFF_SECTION / NaN on both paths
        batch = sec.return_map(th, I, stepper=stepper, rtol=1e-9, n_threads=1)
        steps = fm.returns(th, I, n_threads=1)
        back = fm.returns(th, I, inverse=True, n_threads=1)
        assert np.count_nonzero(batch.status == hv.FlowStatus.OK) >= 6
        for i in range(th.size):
            t, k = float(th[i]), float(I[i])
            one = sec.return_map(t, k, stepper=stepper, rtol=1e-9, n_threads=1)
            arr = sec.return_map(th[i : i + 1], I[i : i + 1], stepper=stepper, rtol=1e-9, n_threads=1)
            for name in ("theta", "I", "z", "time", "status", "energy_error", "steps", "region"):
                a, b = getattr(one, name), getattr(arr, name)
                assert _same(a, b) and a.dtype == b.dtype and a.shape == b.shape, (name, a, b)
                assert _same(a, getattr(batch, name)[i : i + 1]), name
            assert one.itinerary == arr.itinerary == batch.itinerary[i : i + 1]
            assert one.work == arr.work
            assert one.trajectory is None and arr.trajectory is None
            assert _same(fm.step(t, k), (steps.phi[i], steps.K[i]))
            assert _same(fm.step_inverse(t, k), (back.phi[i], back.K[i]))
            assert int(fm.region(t, k)) == int(steps.region[i])
            assert isinstance(fm.step(t, k)[0], float) and isinstance(fm.region(t, k), hv.Region)


@pytest.mark.parametrize("geometry", ["step", "wall"])
@pytest.mark.parametrize("stepper", ["taylor", "rk8pd"])
def test_an_orbit_is_its_one_return_steps_chained(geometry, stepper):
    # iterate starts each return (but an orbit's first) from the point of Sigma_h that the last
    # return's chart check solved, instead of solving it again: the orbit must be, bit for bit,
    # the chain of one-return steps, each solving its start afresh; with a polynomial coupling
    # too (its section point takes the coupling's terms), and in normal coordinates (where the
    # coordinates' round trip need not give the same start, so nothing may be reused wrongly).
    rng = np.random.default_rng(7 + (geometry == "wall") + 2 * (stepper == "taylor"))
    base = _random_system(rng, geometry)
    poly = StepSystem(
        base.V1, base.V2, hv.Polynomial({(2, 1): 1.0, (1, 3): 1.0}), eps=0.05, qw1=-1.0, qw2=-0.5, geometry=geometry
    )
    for sys_ in (base, poly):
        for coords in ("section", "normal"):
            fm = hv.FlowMap(sys_, H, coordinates=coords, stepper=stepper, rtol=1e-9)
            I_tan = sys_.V2.action(H - sys_.V1.V(sys_.qw1))
            th = rng.uniform(-np.pi, np.pi, 5)
            I = I_tan * rng.uniform(0.4, 1.2, 5)
            if coords == "normal":  # K is measured from the tangential curve (near I_tan)
                I = I - I_tan
            orbit = fm.iterate(th, I, 15, record=("orbit",), n_threads=1)
            assert np.count_nonzero(orbit.status == 0) >= 3
            for i in range(th.size):
                x, y = float(th[i]), float(I[i])
                for k in range(15):
                    if not np.isfinite(orbit.phi[i, k + 1]):
                        break
                    x, y = fm.step(x, y)
                    assert _same((x, y), (orbit.phi[i, k + 1], orbit.K[i, k + 1])), (coords, i, k)


def test_normal_coordinates_and_other_scalar_types_take_the_same_path():
    fm = paper.flow_map(eps=-0.05)
    phi, K = np.linspace(-3, 3, 7), np.linspace(-0.1, 0.1, 7)
    ref = fm.returns(phi, K, n_threads=1)
    for i in range(phi.size):
        for p, k in ((float(phi[i]), float(K[i])), (phi[i], K[i]), (np.float32(phi[i]), K[i])):
            assert _same(fm.step(p, k), (ref.phi[i], ref.K[i]))
    a, b = fm.step(np.array([1.0]), np.array([0.0]))
    assert _same(fm.step(1, 0), (a[0], b[0]))  # ints: the fast path too


def test_truncated_step_fast_path_equals_the_array_path():
    rng = np.random.default_rng(3)
    tm = paper.truncated_map(-0.05)
    lo, hi = tm.valid_band()
    phi, K = rng.uniform(-10, 10, 50), rng.uniform(lo, hi, 50)
    a, b = tm.step(phi, K)
    ai, bi = tm.step_inverse(phi, K)
    for i in range(phi.size):
        assert tm.step(float(phi[i]), float(K[i])) == (a[i], b[i])
        assert tm.step_inverse(float(phi[i]), float(K[i])) == (ai[i], bi[i])


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda fm, sec, tm: fm.step(float("nan"), 0.1), r"step: phi must be finite, got nan"),
        (lambda fm, sec, tm: fm.step(0.1, float("inf")), r"step: K must be finite, got inf"),
        (lambda fm, sec, tm: fm.step(2e6, 0.1), r"step: phi must be an angle in \[-1e6, 1e6\]"),
        (lambda fm, sec, tm: fm.step(10**400, 0.1), r"step: phi must be"),
        (lambda fm, sec, tm: fm.step(0.1, 10**400), r"K must be"),
        (lambda fm, sec, tm: fm.step(True, 0.1), r"step: phi must be real numbers"),
        (lambda fm, sec, tm: fm.step_inverse(0.1, float("nan")), r"step_inverse: K must be finite"),
        (lambda fm, sec, tm: fm.region(float("nan"), 0.0), r"region: phi must be finite"),
        (lambda fm, sec, tm: sec.return_map(5.0, 0.3), r"theta must lie in \[-pi, pi\], got 5"),
        (lambda fm, sec, tm: sec.return_map(0.3, float("nan")), r"I must be finite"),
        (lambda fm, sec, tm: sec.return_map(0.3, 0.3, rtol=True), r"rtol"),
        (lambda fm, sec, tm: sec.return_map(0.3, 0.3, max_steps=True), r"max_steps"),
        # Equal to a validated option (2000 == 2000.0, hash equal) but not an integer.
        (lambda fm, sec, tm: sec.return_map(0.3, 0.3, max_steps=2000.0), r"max_steps must be an integer"),
        (lambda fm, sec, tm: sec.return_map(0.3, 0.3, max_impacts=50.0), r"max_impacts must be an integer"),
        (lambda fm, sec, tm: sec.return_map(0.3, 0.3, rtol=[1e-9]), r"rtol"),
        (lambda fm, sec, tm: sec.return_map(0.3, 0.3, stepper="nope"), r"nope"),
        (lambda fm, sec, tm: sec.return_map(0.3, 0.3, n_threads=-1), r"n_threads must be an integer"),
        (lambda fm, sec, tm: tm.step(0.1, -5.0), r"step: K = -5 is outside the band"),
        (lambda fm, sec, tm: tm.step(float("nan"), 0.0), r"step: phi must be finite"),
    ],
)
def test_bad_one_point_input_is_still_refused_by_name(call, match):
    fm = paper.flow_map(eps=-0.05)
    sec = fm.section
    tm = paper.truncated_map(-0.05)
    # The good calls first: the options and tracers they leave behind must not let bad input through.
    fm.step(0.1, 0.0)
    sec.return_map(0.3, 0.3)
    sec.return_map(0.3, 0.3, max_steps=1)  # then max_steps=True (== 1) must still be refused
    sec.return_map(0.3, 0.3, max_steps=2000)  # and 2000.0
    sec.return_map(0.3, 0.3, max_impacts=50)
    sec.return_map(0.3, 0.3, rtol=1e-9)
    with pytest.raises(ValueError, match=match):
        call(fm, sec, tm)


def test_an_option_changed_in_place_is_validated_again():
    # Section.return_map takes the last call's mapper when every option is the same object; a 0-d
    # array is the same object after it is changed in place, so it must never be taken that way:
    # the call after the change integrates at the new tolerance (what a fresh section gives).
    sec = paper.section(-0.05)
    r = np.array(1e-10)
    first = sec.return_map(0.3, 0.3, rtol=r, atol=r)
    r[...] = 1e-4
    changed = sec.return_map(0.3, 0.3, rtol=r, atol=r)
    fresh = paper.section(-0.05).return_map(0.3, 0.3, rtol=1e-4, atol=1e-4)
    assert _same(changed.z, fresh.z) and not _same(changed.z, first.z)


def test_a_sections_system_and_energy_cannot_be_reassigned():
    # Its kept mappers integrate the system it was made with: a reassigned sys returned the old
    # system's images. Both are fixed; other attributes are free.
    sec = paper.section(-0.05)
    before = sec.return_map(0.5, 0.3)
    for name, value in (("sys", paper.system(0.0)), ("h", 1.1)):
        with pytest.raises(AttributeError, match=rf"Section\.{name} is fixed at construction"):
            setattr(sec, name, value)
    sec.note = "mine"
    assert sec.note == "mine" and _same(sec.return_map(0.5, 0.3).z, before.z)
    assert _same(copy.copy(sec).return_map(0.5, 0.3).z, before.z)


def test_kept_tracers_change_no_result_and_no_work_count():
    # A map keeps its tracers from call to call; a fresh map must give the same numbers, and each
    # call's work counters must count that call only.
    sys_ = paper.system(-0.05)
    th = np.linspace(-3, 3, 21)
    I = np.full(21, 0.3)
    for stepper in ("taylor", "rk8pd"):
        kw = dict(stepper=stepper, rtol=1e-10, n_threads=1)
        used = hv.Section(sys_, H)
        for t in th[:5]:
            used.return_map(float(t), 0.3, **kw)
        used.return_map(th, I, trajectory_dt=0.3, **kw)
        a = used.return_map(th, I, **kw)
        b = hv.Section(sys_, H).return_map(th, I, **kw)
        assert _same(a.z, b.z) and a.itinerary == b.itinerary and a.work == b.work
        assert a.trajectory is None
        fm = hv.FlowMap(sys_, H, coordinates="section", stepper=stepper)
        fm.iterate(th, I, 3, record=("orbit", "trajectory"), trajectory_dt=0.2, n_threads=2)
        fm.jacobian(th, I, n_threads=1)
        r1 = fm.iterate(th, I, 5, record=("orbit", "regions"), n_threads=1)
        fresh = hv.FlowMap(sys_, H, coordinates="section", stepper=stepper)
        r2 = fresh.iterate(th, I, 5, record=("orbit", "regions"), n_threads=1)
        assert _same(r1.phi, r2.phi) and _same(r1.region, r2.region) and r1.work == r2.work


def test_a_used_section_pickles_without_its_kept_mappers():
    sec = paper.section(-0.05)
    sec.return_map(0.3, 0.3)
    back = pickle.loads(pickle.dumps(sec))
    assert back == sec and "_mappers" not in back.__dict__ and "_last_mapper" not in back.__dict__
    assert "_last_mapper" not in copy.deepcopy(sec).__dict__
    assert _same(back.return_map(0.3, 0.3).z, sec.return_map(0.3, 0.3).z)
