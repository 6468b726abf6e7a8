"""Simulate only the effects a computation calls for, shown by the work counters (res.work): no
walls, no wall search; eps = 0, no coupling term; no labels, no crossing bookkeeping; no
trajectory, no dense sample. And in each case the orbit that should not change does not."""

from __future__ import annotations

import numpy as np
import pytest

import hovering as hv
from hovering import Region, Status

KEYS = {
    "field_evaluations",
    "coupling_evaluations",
    "wall_searches",
    "section_searches",
    "label_operations",
    "dense_samples",
    "steps",
}


def system(eps=-0.05, geometry="step"):
    return hv.StepSystem(
        V1=hv.Harmonic(omega=1.0),
        V2=hv.Tan(omega=1.4, alpha=0.7),
        coupling=hv.Bilinear(),
        eps=eps,
        qw1=-1.0,
        qw2=-0.5,
        geometry=geometry,
    )


@pytest.fixture(scope="module")
def fm():
    # rk8pd by name: these counters are those of a GSL stepper (field evaluations per stage, dense
    # samples by field evaluation); the default, taylor here, evaluates no field.
    return hv.FlowMap(system(), h=1.0, rtol=1e-10, stepper="rk8pd")


@pytest.fixture(scope="module")
def points():
    rng = np.random.default_rng(11)
    return rng.uniform(-np.pi, np.pi, 16), rng.uniform(-0.1, 0.05, 16)


def test_work_is_a_dict_of_ints_on_both_results(fm, points):
    res = fm.iterate(*points, 5, record=())
    assert set(res.work) == KEYS and all(type(v) is int for v in res.work.values())
    # Every accepted step evaluates the field (rk8pd: 12 new stages per step, plus the event searches).
    assert res.work["steps"] > 0 and res.work["field_evaluations"] >= 12 * res.work["steps"]
    # One section search per trace of a return (the event is searched where p1 changes sign
    # downward): one per return unverified, one more per verifying trace.
    assert res.work["section_searches"] >= 16 * 5
    unverified = hv.FlowMap(fm.sys, h=1.0, rtol=1e-10, stepper="rk8pd", verify_steps=0).iterate(*points, 5, record=())
    assert unverified.work["section_searches"] == 16 * 5
    extra = res.work["section_searches"] - 16 * 5
    assert extra == 0 or res.work["steps"] > unverified.work["steps"]
    ret = fm.section.return_map([0.3, 1.0], [0.3, 0.32])
    assert set(ret.work) == KEYS and ret.work["section_searches"] == 2
    assert ret.work["steps"] == int(ret.steps.sum())
    assert hv.TruncatedMap(eps=0.1, Omega0=1.0, theta_w=2.0).iterate([0.0], [0.0], 3).work is None


def test_no_walls_no_wall_search():
    smooth = hv.FlowMap(system(geometry="none"), h=1.0, coordinates="section", rtol=1e-10)
    walls = hv.FlowMap(system(geometry="step"), h=1.0, coordinates="section", rtol=1e-10)
    th, I = np.linspace(-3, 3, 12), np.linspace(0.2, 0.4, 12)
    a = smooth.iterate(th, I, 5, record=())
    b = walls.iterate(th, I, 5, record=())
    assert a.work["wall_searches"] == 0 and a.work["steps"] > 0
    assert b.work["wall_searches"] > 0
    r = smooth.section.return_map(th, I)
    assert r.work["wall_searches"] == 0 and r.work["label_operations"] == 0  # the smooth flow has no labels


def test_eps0_evaluates_no_coupling(points):
    # eps = 0 selects the field without the coupling branch: not one coupling term is evaluated;
    # with eps != 0 every field evaluation has one.
    zero = hv.FlowMap(system(eps=0.0), h=1.0, rtol=1e-10).iterate(*points, 4, record=())
    some = hv.FlowMap(system(eps=-0.05), h=1.0, rtol=1e-10).iterate(*points, 4, record=())
    assert zero.work["coupling_evaluations"] == 0 and zero.work["field_evaluations"] > 0
    assert some.work["coupling_evaluations"] == some.work["field_evaluations"] > 0
    th, I = np.array([0.2, 2.0]), np.array([0.3, 0.33])
    assert hv.Section(system(eps=0.0), 1.0).return_map(th, I).work["coupling_evaluations"] == 0
    assert hv.Section(system(eps=0.05), 1.0).return_map(th, I).work["coupling_evaluations"] > 0


@pytest.mark.parametrize(
    "record, exit_regions",
    [(("regions",), None), (("visited",), None), (("itinerary",), None), (("rotation",), None), ((), ("0u", "0"))],
)
def test_labels_only_when_something_reads_them(fm, points, record, exit_regions):
    # Nothing reads a label: no crossing of q1 = qw1 tracked, no itinerary built. Something does:
    # the bookkeeping runs, on orbits that cross q1 = qw1 above the step (region ABOVE) and on
    # every labelled return. The orbit is the same bit for bit either way.
    bare = fm.iterate(*points, 8, record=("orbit",))
    assert bare.work["label_operations"] == 0
    lab = fm.iterate(*points, 8, record=("orbit",) + record, exit_regions=exit_regions)
    assert lab.work["label_operations"] > 0
    n = np.minimum(bare.steps_done, lab.steps_done)
    for i in range(points[0].size):
        assert np.array_equal(bare.phi[i, : n[i] + 1], lab.phi[i, : n[i] + 1])
        assert np.array_equal(bare.K[i, : n[i] + 1], lab.K[i, : n[i] + 1])
    # Everything else the integrator did is the same work.
    if exit_regions is None:
        for key in KEYS - {"label_operations"}:
            assert bare.work[key] == lab.work[key], key


def test_label_operations_count_the_crossings_above_the_step(fm, points):
    # Per return with labels: one operation per impact letter or per final "0" / "u" label, plus one
    # per crossing of q1 = qw1 above the step (at least one in every ABOVE return).
    res = fm.iterate(*points, 8, record=("itinerary", "regions"))
    assert np.all(res.status == Status.OK)
    letters = sum(len(s) for row in res.itinerary for s in row)
    above = int(np.count_nonzero(res.region == Region.ABOVE))
    assert above > 0
    assert res.work["label_operations"] >= letters + above


def test_no_trajectory_no_dense_sample(fm, points):
    off = fm.iterate(*points, 4, record=("orbit",))
    on = fm.iterate(*points, 4, record=("orbit", "trajectory"), trajectory_dt=0.05)
    assert off.work["dense_samples"] == 0 and on.work["dense_samples"] > 0
    # The samples cost field evaluations and nothing else: same steps, same event searches.
    assert on.work["field_evaluations"] > off.work["field_evaluations"]
    for key in ("steps", "wall_searches", "section_searches", "label_operations"):
        assert on.work[key] == off.work[key], key
    assert np.array_equal(on.phi, off.phi) and np.array_equal(on.K, off.K)


def test_counters_do_not_depend_on_threads(fm, points):
    a = fm.iterate(*points, 4, record=("regions",), n_threads=1)
    b = fm.iterate(*points, 4, record=("regions",), n_threads=2)
    assert a.work == b.work and np.array_equal(a.K_final, b.K_final)
