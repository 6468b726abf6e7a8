"""Property-based reliability of the public API (issue 11), bounded to run in seconds.

For each public entry point and each of its parameters, Hypothesis draws values of every kind a
user can pass by mistake (NaN, inf, huge and subnormal numbers, bools, None, strings, complex
numbers, lists, 0-d and 2-d arrays of several dtypes, negative and huge counts) with the other
parameters valid, and checks the contract of the README's "Outcomes are values, bad input is an
error":

* no crash and no hang (a 20 s alarm per example turns a hang into a failure);
* a rejection is a ValueError or TypeError whose message names the parameter and says what is
  allowed (never a pybind11 signature dump, a numpy ufunc message, ZeroDivisionError, ...);
* an accepted call returns finite numbers, or NaN only together with a per-orbit status that
  says why (or, for the closed-form theory, where the quantity does not exist).

Counts are drawn below the sizes where a valid call would take long (the point is the contract,
not a stress test), so every example is fast; the whole module takes ~10 s.
The slower tests (hovering area, critical curve, the flow) take a fraction of the examples.
"""

from __future__ import annotations

import math
import os
import re
import signal

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import hovering as hv
from hovering import paper

# Derandomised by default so CI is reproducible; HOVERING_FUZZ=N runs N random examples per test
# (a deeper local search: HOVERING_FUZZ=2000 python -m pytest tests/package/test_hypothesis_api.py).
_DEEP = int(os.environ.get("HOVERING_FUZZ", "0"))
SETTINGS = settings(
    max_examples=_DEEP or 60,
    deadline=None,
    derandomize=not _DEEP,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)

M = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=2.0)
SYS = paper.system(0.05)
SEC = hv.Section(SYS, 1.0)
FM = hv.FlowMap(SYS, 1.0)

# ------------------------------------------------------------------------------------------------
# What a user can pass by mistake

SCALARS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -0.0, 5e-324, 1e-300, 1e300, -1e300, math.pi, 2 * math.pi, 1e6 + 1]),
    st.integers(min_value=-(2**80), max_value=2**80),
    st.booleans(),
    st.none(),
    st.text(max_size=4),
    st.complex_numbers(max_magnitude=10.0),
    st.just(complex("nan+1j")),
    st.builds(np.float32, st.floats(width=32)),
    st.builds(np.int64, st.integers(-(2**63), 2**63 - 1)),
)
ARRAYS = st.one_of(
    hnp.arrays(
        st.sampled_from([np.float64, np.float32]),
        hnp.array_shapes(min_dims=0, max_dims=2, max_side=3),
        elements=st.floats(allow_nan=True, allow_infinity=True, width=32),
    ),
    hnp.arrays(np.int64, hnp.array_shapes(min_dims=0, max_dims=2, max_side=3)),
    hnp.arrays(np.bool_, hnp.array_shapes(min_dims=1, max_dims=1, max_side=3)),
    hnp.arrays(np.complex128, hnp.array_shapes(min_dims=1, max_dims=1, max_side=2)),
    st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=3),
    st.lists(st.text(max_size=2), min_size=1, max_size=2),
)
ANY = st.one_of(SCALARS, ARRAYS)


def counts(small_max: int):
    """Count-like values: anything, but valid integers only up to small_max (a valid huge count
    is a legitimately long computation); invalid huge ones stay in."""
    return st.one_of(
        st.integers(min_value=-(2**70), max_value=small_max),
        st.sampled_from([2**53 + 1, 2**63 - 1, 2**64, 2**70, math.nan, math.inf, -math.inf]),
        st.floats(max_value=float(small_max)),
        st.booleans(),
        st.none(),
        st.text(max_size=3),
        st.builds(np.int64, st.integers(-5, small_max)),
    )


# ------------------------------------------------------------------------------------------------
# The contract


class Hang(Exception):
    pass


@pytest.fixture(autouse=True)
def _alarm():
    def on_alarm(*_):
        raise Hang("an example ran 20 s: a hang")

    old = signal.signal(signal.SIGALRM, on_alarm)
    yield
    signal.setitimer(signal.ITIMER_REAL, 0)
    signal.signal(signal.SIGALRM, old)


RANGE_WORDS = re.compile(r"must|allowed|one of|expected|outside|needs|cannot|got", re.I)
FOREIGN = (
    "incompatible function arguments",
    "arg0",
    "ufunc",
    "object of type",
    "has no attribute",
    "unsupported operand",
    "division by zero",
    "Traceback",
)


def outcome(call, *names):
    """Run call(); return its result, or None after checking that a rejection names a parameter."""
    signal.setitimer(signal.ITIMER_REAL, 20.0)
    try:
        return call()
    except (ValueError, TypeError) as e:
        msg = str(e)
        assert any(n in msg for n in names), f"message does not name {names}: {msg!r}"
        assert RANGE_WORDS.search(msg), f"message does not say what is allowed: {msg!r}"
        assert not any(f in msg for f in FOREIGN), f"internal message leaked: {msg!r}"
        return None
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)


def huge(value) -> bool:
    """An input beyond 1e150, whose results may honestly overflow to inf (IEEE, not garbage)."""
    try:
        a = np.abs(np.asarray(value, dtype=float))
    except (TypeError, ValueError):
        return False
    return bool(np.any(a[np.isfinite(a)] > 1e150))


def finite_or_explained(values, status, ok):
    """Every non-finite entry belongs to an orbit whose status says why (not ok)."""
    v = np.asarray(values, dtype=float)
    s = np.asarray(status)
    bad = ~np.isfinite(v.reshape(len(s), -1)).all(axis=1)
    assert not np.any(bad & (s == ok)), "non-finite values with status OK"


def check_iterate(res, ok=int(hv.Status.OK)):
    for name in ("phi", "K"):
        a = getattr(res, name, None)
        if a is None:
            continue
        a = np.asarray(a, dtype=float)
        assert not np.any(np.isinf(a)), name
        fin = a[np.isfinite(a)]
        if name == "phi":
            assert np.all((fin >= -np.pi) & (fin < np.pi)), "phi outside [-pi, pi)"
    finite_or_explained(res.phi_final, res.status, ok)
    finite_or_explained(res.K_final, res.status, ok)


# ------------------------------------------------------------------------------------------------
# Truncated map


MAP_ARGS = dict(eps=0.3, Omega0=hv.OMEGA_G, theta_w=2.0, tau0=1.0, tau1=0.5, lam=0.5)


@pytest.mark.parametrize("param", list(MAP_ARGS) + ["K_max"])
@SETTINGS
@given(value=ANY)
def test_truncated_map_parameters(param, value):
    m = outcome(lambda: hv.TruncatedMap(**{**MAP_ARGS, param: value}), param)
    if m is not None:
        check_iterate(m.iterate([0.1, -2.0, 3.0], [-0.1, -0.3, 0.05], 20))


ITERATE = dict(
    phi0=ANY,
    K0=ANY,
    n_steps=counts(50),
    record=ANY,
    exit_regions=ANY,
    stop_on_exit=ANY,
    n_threads=counts(4),
    kernel=ANY,
    sin_ulp=ANY,
)


@pytest.mark.parametrize("param", list(ITERATE))
@SETTINGS
@given(data=st.data())
def test_truncated_iterate_parameters(param, data):
    value = data.draw(ITERATE[param])
    kw = dict(phi0=[0.1, 2.0], K0=[-0.1, -0.2], n_steps=20)
    kw[param] = value
    res = outcome(lambda: M.iterate(**kw), param, param.rstrip("0"))
    if res is not None:
        check_iterate(res)


@pytest.mark.parametrize("method", ["step", "step_inverse", "reversal"])
@SETTINGS
@given(phi=ANY, K=ANY)
def test_truncated_pointwise(method, phi, K):
    r = outcome(lambda: getattr(M, method)(phi, K), "phi", "K")
    if r is not None:
        p, k = (np.asarray(x, dtype=float) for x in r)
        assert np.all(np.isfinite(p)) and np.all(np.isfinite(k))
        assert np.all((p >= -np.pi) & (p < np.pi))


@pytest.mark.parametrize("method", ["L1", "L2", "arcs", "corner_curves"])
@SETTINGS
@given(K=ANY)
def test_truncated_curves(method, K):
    r = outcome(lambda: getattr(M, method)(K), "K")
    if r is not None:
        for x in r.values() if isinstance(r, dict) else r if isinstance(r, tuple) else (r,):
            assert not np.any(np.isinf(np.asarray(x, dtype=float)))


HOV = dict(n_steps=counts(64), n_samples=counts(200), K_low=ANY, rng=st.one_of(counts(10**6), ANY), n_threads=counts(4))


@pytest.mark.parametrize("param", list(HOV))
@settings(SETTINGS, max_examples=max(8, SETTINGS.max_examples // 5))
@given(data=st.data())
def test_hovering_area_parameters(param, data):
    kw = dict(n_steps=32, n_samples=100)
    kw[param] = data.draw(HOV[param])
    a = outcome(lambda: hv.hovering_area(M, **kw), param)
    if a is not None:
        assert math.isfinite(a.area) and a.area >= 0 and math.isfinite(a.error) and a.error >= 0


CRIT = dict(n_steps=counts(64), K_range=ANY, n_grid=counts(8), digits=ANY, tol=ANY, search=ANY, regions=ANY)


@pytest.mark.parametrize("param", list(CRIT))
@settings(SETTINGS, max_examples=max(8, SETTINGS.max_examples // 8))
@given(data=st.data())
def test_critical_curve_parameters(param, data):
    kw = dict(n_steps=64, n_grid=4, tol=1e-3)
    kw[param] = data.draw(CRIT[param])
    try:
        c = outcome(lambda: hv.critical_curve(M, **kw), param)
    except RuntimeError as e:
        # "no invariant curve found": an answer about the map at these settings, not bad input.
        assert "no invariant curve" in str(e)
        return
    if c is not None:
        assert math.isfinite(c.K0) and math.isfinite(c.rotation)


THEORY = {
    "K_crit": (hv.K_crit, ("eps", "theta_w", "Omega0"), (0.1, 2.0, 1.0)),
    "rho_crit": (hv.rho_crit, ("eps", "theta_w", "Omega0", "tau0"), (0.1, 2.0, 1.0, 1.0)),
    "hovering_area_theory": (hv.hovering_area_theory, ("eps", "theta_w", "Omega0"), (0.1, 2.0, 1.0)),
    "golden_family": (hv.golden_family, ("eps", "c", "tau0"), (0.1, 0.2, 1.0)),
    "rho1": (hv.rho1, ("K0", "eps", "Omega0", "tau0"), (-0.1, 0.1, 1.0, 1.0)),
    "L1": (hv.L1, ("K", "Omega0", "tau0"), (-0.1, 1.0, 1.0)),
    "wrap": (hv.wrap, ("x",), (1.0,)),
}


@pytest.mark.parametrize(
    "case",
    [(f, i) for f, (_, names, _) in THEORY.items() for i in range(len(names))],
    ids=lambda c: f"{c[0]}:{THEORY[c[0]][1][c[1]]}",
)
@SETTINGS
@given(value=ANY)
def test_theory_functions(case, value):
    f, i = case
    fn, names, valid = THEORY[f]
    args = list(valid)
    args[i] = value
    r = outcome(lambda: fn(*args), names[i], "angle")
    if r is not None:
        # NaN where the quantity does not exist (resonance sin(Omega0 / 2) = 0); inf only by overflow.
        assert huge(value) or not np.any(np.isinf(np.asarray(r, dtype=float)))


# ------------------------------------------------------------------------------------------------
# Potentials and the flow


@pytest.mark.parametrize(
    "make,param",
    [(lambda v: hv.Harmonic(v), "omega"), (lambda v: hv.Tan(v, 0.7), "omega"), (lambda v: hv.Tan(1.4, v), "alpha")],
    ids=["Harmonic", "Tan-omega", "Tan-alpha"],
)
@SETTINGS
@given(value=ANY)
def test_potential_parameters(make, param, value):
    p = outcome(lambda: make(value), param, "incompatible")  # pybind11 type errors: see below
    if p is not None:
        assert math.isfinite(p.period(1.0)) and p.period(1.0) > 0 and math.isfinite(p.action(1.0))


@pytest.mark.parametrize("pot", [hv.Harmonic(1.0), hv.Tan(1.4, 0.7), hv.Numerical(hv.Tan(1.4, 0.7))], ids=repr)
@pytest.mark.parametrize("method", ["period", "action", "turning_points", "energy"])
@SETTINGS
@given(h=st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.sampled_from([5e-324, 1e-300, 1e300])))
def test_potential_energy_questions(pot, method, h):
    r = outcome(lambda: getattr(pot, method)(h), "energy", "action", "h =")
    if r is not None:
        assert huge(h) or np.all(np.isfinite(np.asarray(r, dtype=float)))  # inf only by overflow


@pytest.mark.parametrize("pot", [hv.Harmonic(1.0), hv.Tan(1.4, 0.7), hv.Numerical(hv.Harmonic(1.0))], ids=repr)
@SETTINGS
@given(
    q=st.floats(allow_nan=True, allow_infinity=True),
    p=st.floats(allow_nan=True, allow_infinity=True),
    h=st.one_of(st.floats(min_value=-1.0, max_value=10.0), st.just(math.nan)),
)
def test_angle_of_point(pot, q, p, h):
    th = outcome(lambda: pot.angle_of_point(q, p, h), "q and p", "energy", "level")
    if th is not None:
        assert -math.pi <= th <= math.pi


SYSTEM = dict(eps=ANY, qw1=ANY, qw2=ANY, geometry=ANY, coupling=ANY)


@pytest.mark.parametrize("param", list(SYSTEM))
@SETTINGS
@given(data=st.data())
def test_step_system_parameters(param, data):
    kw = dict(V1=paper.V1, V2=paper.V2, coupling=hv.Bilinear(), eps=0.05, qw1=paper.QW1, qw2=paper.QW2)
    kw[param] = data.draw(SYSTEM[param])
    s = outcome(lambda: hv.StepSystem(**kw), param)
    if s is not None:
        sec = outcome(lambda: hv.Section(s, 1.0), "h")
        if sec is not None:
            r = sec.return_map([0.1], [0.3])
            finite_or_explained(r.theta, r.status, int(hv.FlowStatus.OK))


RETURN_MAP = dict(
    theta=ANY,
    I=ANY,
    rtol=ANY,
    atol=ANY,
    stepper=ANY,
    event_tol=ANY,
    max_steps=counts(10**5),
    max_impacts=counts(100),
    grazing_tol=ANY,
    corner_tol=ANY,
    n_threads=counts(4),
)


@pytest.mark.parametrize("param", list(RETURN_MAP))
@settings(SETTINGS, max_examples=max(8, SETTINGS.max_examples // 3))
@given(data=st.data())
def test_return_map_parameters(param, data):
    kw = dict(theta=[0.1, 2.0], I=[0.3, 0.1])
    kw[param] = data.draw(RETURN_MAP[param])
    if param in ("rtol", "atol") and isinstance(kw[param], float) and 0 < kw[param] < 1e-15:
        kw[param] = 1e-15  # valid but slow tolerances are a benchmark's business
    r = outcome(lambda: SEC.return_map(**kw), param)
    if r is not None:
        finite_or_explained(r.theta, r.status, int(hv.FlowStatus.OK))
        finite_or_explained(r.I, r.status, int(hv.FlowStatus.OK))


@SETTINGS
@given(h=ANY)
def test_section_energy(h):
    s = outcome(lambda: hv.Section(SYS, h), "h")
    if s is not None:
        r = s.return_map([0.1], [s.I_range[0] * 0.5 + s.I_range[1] * 0.5] if hasattr(s, "I_range") else [0.1])
        finite_or_explained(r.theta, r.status, int(hv.FlowStatus.OK))


FLOW_ITERATE = dict(
    phi0=ANY, K0=ANY, n_steps=counts(3), record=ANY, exit_regions=ANY, stop_on_exit=ANY, n_threads=counts(2)
)


@pytest.mark.parametrize("param", list(FLOW_ITERATE))
@settings(SETTINGS, max_examples=max(8, SETTINGS.max_examples // 4))
@given(data=st.data())
def test_flowmap_iterate_parameters(param, data):
    kw = dict(phi0=[0.1, 2.0], K0=[-0.05, -0.1], n_steps=2)
    kw[param] = data.draw(FLOW_ITERATE[param])
    res = outcome(lambda: FM.iterate(**kw), param, param.rstrip("0"))
    if res is not None:
        check_iterate(res, ok=int(hv.Status.OK))


@pytest.mark.parametrize(
    "fn,names", [(hv.to_normal, ("theta", "I")), (hv.from_normal, ("phi", "K"))], ids=["to_normal", "from_normal"]
)
@SETTINGS
@given(a=ANY, b=ANY)
def test_normal_coordinates(fn, names, a, b):
    r = outcome(lambda: fn(SEC, a, b), *names, "shape", "length")
    if r is not None:
        for x in r:
            x = np.asarray(x, dtype=float)
            assert np.all(np.isfinite(x))


# ------------------------------------------------------------------------------------------------
# Everything else with arguments: one valid call each, every parameter fuzzed in turn


_RES = M.iterate([0.1, 2.0], [-0.1, -0.2], 40, record=("orbit", "rotation"))
_FAM = hv.TruncatedFamily(0.3, [-2.0, -1.0, -0.5, 0.0, 1.0], [3.9] * 5, [1.6] * 5, [1.0, 0.8, 0.5, 0.0, 0.0])
OTHER = {
    "birkhoff_average": (hv.birkhoff_average, dict(values=[[1.0, 2.0, 3.0], [3.0, 4.0, 5.0]], axis=-1)),
    "rotation_number": (hv.rotation_number, dict(res=_RES, method="mean")),
    "regularity": (hv.regularity, dict(res=_RES)),
    "theory": (hv.theory, dict(eps=0.3, Omega0=hv.OMEGA_G, theta_w=2.0, tau0=1.0, forcing=(1.0, 0.2), n_grid=1001)),
    "TruncatedFamily": (
        hv.TruncatedFamily,
        dict(
            eps=0.3,
            K=[-2.0, -1.0, -0.5, 0.0, 1.0],
            Omega=[3.9] * 5,
            JR=[1.6] * 5,
            J1=[1.0, 0.8, 0.5, 0.0, 0.0],
            forcing=(1.0,),
        ),
    ),
    "family.step": (_FAM.step, dict(phi=0.1, K=-0.1)),
    "forcing_at": (M.forcing_at, dict(phi=0.3)),
    "k_eps2": (M.k_eps2, dict(phi=[0.1, 0.2], K0=-0.1)),
    "count": (_RES.count, dict(status="OK")),
    "region_mask": (hv.region_mask, dict(regions=("0u", "0"))),
}
_OTHER_CASES = [(k, p) for k, (_, kw) in OTHER.items() for p in kw]


@pytest.mark.parametrize("case", _OTHER_CASES, ids=[f"{k}:{p}" for k, p in _OTHER_CASES])
@SETTINGS
@given(value=ANY)
def test_other_entry_points(case, value):
    name, param = case
    fn, kw = OTHER[name]
    r = outcome(lambda: fn(**{**kw, param: value}), param, param.rstrip("0"), "status", "region")
    if r is not None and not isinstance(r, (hv.Theory, hv.TruncatedFamily)):
        for x in r if isinstance(r, tuple) else (r,):
            if isinstance(x, (int, float, np.ndarray)):
                a = np.asarray(x, dtype=float)
                # NaN only where documented (an orbit that took no step / a stopped tail); never inf.
                assert huge(value) or not np.any(np.isinf(a))
