"""Pickling (protocols 2-5, copy, deepcopy, multiprocessing, cloudpickle) of every object of the package.

The standard: an unpickled map steps bit for bit as the original (step, step_inverse, region,
iterate on a few hundred points, NaN-aware), an unpickled potential answers every energy question
identically, and an unpickled result has the same arrays (dtype, shape, bits) and scalars. An
object that cannot be pickled (a CustomPotential of lambdas) says which callable is at fault.
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import multiprocessing
import pickle

import numpy as np
import pytest

import hovering as hv
from helpers.pickle_helpers import (
    Cosh,
    issue_system,
    maps,
    quartic,
    quartic_dV,
    quartic_V,
    results,
    same,
    same_steps,
    scaled,
)
from hovering import _core

PROTOCOLS = list(range(2, pickle.HIGHEST_PROTOCOL + 1))
COPIES = {
    **{f"pickle{p}": functools.partial(lambda o, p: pickle.loads(pickle.dumps(o, p)), p=p) for p in PROTOCOLS},
    "copy": copy.copy,
    "deepcopy": copy.deepcopy,
}


# ------------------------------------------------------------------ potentials

POTENTIALS = {
    "harmonic": lambda: hv.Harmonic(1.3),
    "tan": lambda: hv.Tan(1.4, 0.7),
    "numerical_tan": lambda: hv.Numerical(hv.Tan(1.4, 0.7)),
    "custom": quartic,
    "custom_partial": scaled,
    "numerical_custom": lambda: hv.Numerical(quartic()),
    "python_subclass": lambda: Cosh(0.8),
}


def potential_answers(p) -> list:
    """Everything a potential answers, at a few positions and levels."""
    out = [type(p), p.name, p.q_limit]
    lim = min(p.q_limit, 3.0)
    for q in np.linspace(-0.9 * lim, 0.9 * lim, 7):
        out += [p.V(q), p.dV(q)]
    for h in (0.05, 0.7, 2.5):
        qmin, qmax = p.turning_points(h)
        q, pp = p.point_at(0.7, h)
        out += [
            qmin,
            qmax,
            p.period(h),
            p.frequency(h),
            p.action(h),
            p.energy(p.action(h)),
            p.angle_of(0.3 * qmax, h),
            q,
            pp,
            p.angle_of_point(q, pp, h),
        ]
    return out


@pytest.mark.parametrize("how", COPIES)
@pytest.mark.parametrize("name", POTENTIALS)
def test_potentials_round_trip_with_identical_answers(name, how):
    p = POTENTIALS[name]()
    q = COPIES[how](p)
    assert q is not p and type(q) is type(p)
    a, b = potential_answers(p), potential_answers(q)
    assert all(x == y for x, y in zip(a, b)), (name, how)
    # The compiled potentials compare by value, a CustomPotential by its callables (a new
    # functools.partial is another callable), a Potential subclass by identity.
    if name not in ("python_subclass", "custom_partial") or (name == "custom_partial" and how == "copy"):
        assert q == p and hash(q) == hash(p)


def test_potential_pickles_keep_what_makes_them():
    c = pickle.loads(pickle.dumps(quartic()))
    assert isinstance(c, hv.CustomPotential) and c.V_callable is quartic_V and c.dV_callable is quartic_dV
    n = pickle.loads(pickle.dumps(hv.Numerical(hv.Tan(1.4, 0.7))))
    assert n.base == hv.Tan(1.4, 0.7) and n.name == "Numerical(Tan(omega=1.4, alpha=0.7))"
    cosh = Cosh(0.8)
    cosh.note = "kept"
    back = pickle.loads(pickle.dumps(cosh))
    assert back.a == 0.8 and back.note == "kept" and back.V(1.0) == cosh.V(1.0)
    # Equality by value (the compiled potentials): what lets a loaded curve serve an equal system.
    assert hv.Harmonic(1.0) == hv.Harmonic(1.0) != hv.Harmonic(2.0) and hv.Harmonic(1.0) != hv.Tan(1.0, 0.5)
    assert hv.Numerical(hv.Harmonic(1.0)) == hv.Numerical(hv.Harmonic(1.0)) != hv.Harmonic(1.0)
    assert len({hv.Tan(1.4, 0.7), hv.Tan(1.4, 0.7)}) == 1


def test_custom_potential_of_a_lambda_names_the_callable():
    def local_dV(q):
        return q + q**3

    p = hv.CustomPotential(lambda q: 0.5 * q * q + 0.25 * q**4, quartic_dV, name="lam")
    with pytest.raises(pickle.PicklingError, match=r"cannot pickle lam: its V = <function .*<lambda>.* module level"):
        pickle.dumps(p)
    p2 = hv.CustomPotential(quartic_V, local_dV, name="local")
    with pytest.raises(pickle.PicklingError, match=r"cannot pickle local: its dV = <function .*local_dV"):
        pickle.dumps(p2)
    # Inside a system, a map and a result it is still the callable that is named.
    fm = hv.FlowMap(issue_system(-0.05, V1=p2), h=1.0)
    res = fm.iterate([0.1], [-0.02], 1)
    for obj in (fm.sys, fm, res):
        with pytest.raises(pickle.PicklingError, match="its dV = <function .*local_dV"):
            pickle.dumps(obj)
    # Copies do not pickle: any callable copies.
    for c in (copy.copy(p), copy.deepcopy(p)):
        assert c.V_callable is p.V_callable and c.V(0.7) == p.V(0.7)


def test_cloudpickle_stores_lambdas():
    import cloudpickle  # a test dependency (pyproject [test])

    p = hv.CustomPotential(lambda q: 0.5 * q * q + 0.25 * q**4, lambda q: q + q**3, name="lam")
    q = cloudpickle.loads(cloudpickle.dumps(p))
    assert type(q) is hv.CustomPotential and potential_answers(q) == potential_answers(p)
    fm = hv.FlowMap(issue_system(-0.05, V1=p), h=1.0)
    fm2 = cloudpickle.loads(cloudpickle.dumps(fm))
    phi, K = np.linspace(-3, 3, 12), np.full(12, -0.02)
    assert same_steps(fm, fm2, phi, K)


def test_compiled_states_are_checked():
    # A corrupted or foreign state is a ValueError naming the entry, never a crash.
    cases = [
        (_core.flow.Harmonic, ("x",), r"Harmonic: omega must be a real number"),
        (_core.flow.Harmonic, (0.0,), r"omega must lie in \[1e-100, 1e100\]"),
        (_core.flow.Tan, (1.0,), r"Tan.__setstate__: expected the tuple \(omega, alpha\)"),
        (_core.flow.OnsetParameters, (1.0,) * 5, r"expected the tuple \(Omega0, tau0"),
        (_core.truncated.TruncatedMap, (0.3, 1.0, 4.0, 1.0, 0.5, 0.5, 1.0), r"theta_w"),
        (
            _core.truncated.TruncatedFamily,
            (0.1, [0.0, 1.0], [1.0, 1.0], [1.0, 1.0], [0.0, 0.0], [1.0], 1.0),
            r"K grid needs at least 3 points|at least 3",
        ),
        (_core.flow.FlowOptions, ("rk8pd", 0.0, 1e-12, 1e-15, 100, 10, 1e-12, 1e-10), r"rtol"),
        (
            _core.normal.TangentialCurve,
            (1.0, 0.0, 0.3, np.zeros(7), np.ones(7), 0.0, 0.0),
            r"even number in \[8, 4096\] of samples, got 7",
        ),
    ]
    for cls, state, msg in cases:
        obj = cls.__new__(cls)
        with pytest.raises(ValueError, match=msg):
            obj.__setstate__(state)


# ------------------------------------------------------------------ couplings, systems, sections, curves


def test_couplings_systems_and_sections_round_trip():
    poly = hv.Polynomial({(1, 1): 0.5, (2, 1): -0.25})
    sys = issue_system(0.1).replace(coupling=poly)
    sec = hv.Section(sys, 1.2)
    onset = hv.onset_parameters(sys, 1.2)
    for f in COPIES.values():
        assert f(hv.Bilinear()) == hv.Bilinear() and f(poly) == poly
        s2 = f(sys)
        assert s2 == sys and s2.core is not sys.core and s2.core.terms == sys.core.terms
        z = sec.point([0.3, -1.0], [0.4, 0.35])
        assert same(s2.core.energy(z), sys.core.energy(z))
        sec2 = f(sec)
        assert sec2 == sec and same(sec2.point([0.3], [0.4]), sec.point([0.3], [0.4]))
        o2 = f(onset)
        assert o2 == onset and [getattr(o2, k) for k in ("Omega0", "tau0", "tau1", "lam", "theta_w", "I_tan")] == [
            getattr(onset, k) for k in ("Omega0", "tau0", "tau1", "lam", "theta_w", "I_tan")
        ]
        opts = hv.flow.flow_options(rtol=1e-9, stepper="rkck", max_impacts=7)
        o3 = f(opts)
        assert (o3.rtol, o3.stepper, o3.max_impacts, o3.max_steps) == (1e-9, "rkck", 7, opts.max_steps)


def test_tangential_curve_round_trips_without_tracing(monkeypatch):
    fm = maps()["flow_normal"][0]
    curve = fm.curve
    blob = pickle.dumps(curve)
    deep = copy.deepcopy(curve)

    def refuse(*args, **kwargs):
        raise AssertionError("the curve was measured again")

    monkeypatch.setattr(hv.TangentialCurve, "__init__", refuse)  # the only way to measure one
    back = pickle.loads(blob)
    th = np.linspace(-np.pi, np.pi, 257)
    for c in (back, deep):
        assert c.sec == curve.sec and c.is_graph and c.min_slope == curve.min_slope
        for k in ("s", "theta", "values"):
            assert same(getattr(c, k), getattr(curve, k))
        assert c.interpolation_error == curve.interpolation_error and c.I_tan0 == curve.I_tan0
        assert same(c(th), curve(th)) and same(c.at(th)[1], curve.at(th)[1])
        assert same(c.forcing_coefficients(4), curve.forcing_coefficients(4))
    pickle.loads(pickle.dumps(fm))  # the flow map does not measure it either


# ------------------------------------------------------------------ maps


@pytest.mark.parametrize("how", ["pickle2", f"pickle{pickle.HIGHEST_PROTOCOL}", "copy", "deepcopy"])
@pytest.mark.parametrize(
    "name", ["truncated", "truncated_capped", "family", "flow_normal", "flow_section", "flow_custom"]
)
def test_maps_step_bit_for_bit_after_a_round_trip(name, how):
    m, phi, K = maps()[name]
    m2 = COPIES[how](m)
    assert type(m2) is type(m) and m2 is not m
    assert m2.valid_band() == m.valid_band() and m2.eps == m.eps
    assert same_steps(m, m2, phi, K)
    n = 50 if name.startswith("flow") else 500
    r1, r2 = m.iterate(phi, K, n if name != "flow_custom" else 4), m2.iterate(phi, K, n if name != "flow_custom" else 4)
    assert same(r1, r2) and r2.map is m2


def test_map_attributes_survive():
    m = hv.TruncatedMap(eps=0.2, Omega0=1.1, theta_w=2.2)
    m.label = "mine"
    fam = maps()["family"][0]
    fm = maps()["flow_normal"][0]
    fm.forcing_coefficients(5)  # the cache: kept, not measured again
    m2, fam2, fm2 = pickle.loads(pickle.dumps((m, fam, fm)))
    assert m2.label == "mine" and repr(m2) == repr(m)
    assert all(same(a, b) for a, b in zip(fam2._tables, fam._tables)) and fam2._K_max == fam._K_max
    assert tuple(fam2.forcing) == tuple(fam.forcing) and fam2.onset() == fam.onset()
    assert same(fam2.with_eps(0.1).step(0.3, -0.2), fam.with_eps(0.1).step(0.3, -0.2))
    assert same(fm2._forcing, fm._forcing) and fm2.integrator_options == fm.integrator_options
    assert fm2.onset == fm.onset and fm2.curve.sec.sys is fm2.sys and fm2.coordinates == fm.coordinates
    assert fm2.theory() == fm.theory()


def test_a_map_subclass_keeps_its_class():
    m = SubMap(eps=0.3, Omega0=1.1, theta_w=2.2)
    m2 = pickle.loads(pickle.dumps(m))
    assert type(m2) is SubMap and m2.extra == 7 and same(m2.step(0.4, -0.1), m.step(0.4, -0.1))


class SubMap(hv.TruncatedMap):
    """A subclass with its own attribute and constructor signature (module level: it pickles by name)."""

    def __init__(self, *, extra=7, **params):
        super().__init__(**params)
        self.extra = extra


# ------------------------------------------------------------------ results


@pytest.mark.parametrize("how", ["pickle2", f"pickle{pickle.HIGHEST_PROTOCOL}", "deepcopy"])
@pytest.mark.parametrize("name", list(results()))
def test_results_round_trip(name, how):
    r = results()[name]
    r2 = COPIES[how](r)
    assert same(r, r2), name
    for f in dataclasses.fields(r):
        a = getattr(r, f.name)
        if isinstance(a, np.ndarray):
            assert getattr(r2, f.name) is not a
    if getattr(r, "map", None) is not None:
        m = r.map
        phi = np.linspace(-3, 3, 40)
        K = np.full(40, -0.02)
        assert same_steps(m, r2.map, phi, K)


# ------------------------------------------------------------------ processes


def test_spawned_pool_steps_like_the_direct_call():
    # Each task pickles the map (bound method m.step and its arguments) into a fresh interpreter.
    names = ["truncated", "family", "flow_normal", "flow_custom"]
    tasks, expected = [], []
    for name in names:
        m, phi, K = maps()[name]
        for i in range(3):
            tasks.append((m.step, phi[i::3], K[i::3]))
            expected.append(m.step(phi[i::3], K[i::3]))
    ctx = multiprocessing.get_context("spawn")
    with ctx.Pool(2) as pool:
        got = pool.starmap(_call, tasks)
        res = pool.map(_iterate_truncated, [maps()["truncated"][0]])[0]
    assert all(same(a, b) for a, b in zip(got, expected))
    m, phi, K = maps()["truncated"]
    assert same(res, m.iterate(phi, K, 100)) and type(res.map) is hv.TruncatedMap


def _call(f, *args):
    return f(*args)


def _iterate_truncated(m):
    _, phi, K = maps()["truncated"]
    return m.iterate(phi, K, 100)
