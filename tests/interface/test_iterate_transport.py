"""The transport options of ``iterate`` (issue 20): ``every=k``, ``stop=Above/Below``, the streamed
records ``"extrema"`` and ``"residence"``, the recorded exiting return and the padding after a stop,
on the truncated map (both kernels) and on FlowMap.

Each option is checked against an independent computation from a fully recorded run of the same
orbits (``every=1``, no stop): the kernels compute the same orbit whatever is recorded (tested
bit for bit in test_iterate.py), so the comparisons are exact (``==``, NaN = NaN), with no
tolerance: a stop is the first recorded state that :meth:`StopCondition.contains` (Python, the
core's Curve evaluation) puts in the set, extrema are ``nanmin`` / ``nanmax`` of the recorded K,
residence is a count of the recorded regions, ``every=k`` is a slice.
"""

from __future__ import annotations

import time

import numpy as np
import pytest

import hovering
from conftest import PARAM_SETS, PROMPT, CtrlCOnceStarted, band_sample, make_map
from hovering import Above, Below, Curve, Region, Status

KERNELS = ("simd", "scalar")
N_REGIONS = 5  # BESIDE, ABOVE, UPPER, RIGHT, MULTI


@pytest.fixture(scope="module", params=["TruncatedMap", "TruncatedFamily"])
def m(request):
    """The paper's map at eps = 0.3, and the same map as a TruncatedFamily (tabulated arcs; its
    band ends at the grid's floor K = -2)."""
    tm = make_map(PARAM_SETS["paper_eps+0.3"])
    if request.param == "TruncatedMap":
        return tm
    s = np.linspace(np.sqrt(2.0), 0.0, 60)  # uniform in sqrt(-K) below 0, as |J_1| is splined there
    grid = np.concatenate([-(s[:-1] ** 2), [0.0], np.linspace(0.0, 1.5, 40)[1:]])
    return hovering.TruncatedFamily.from_map(tm, grid)


@pytest.fixture(scope="module")
def starts(m):
    # K from the band floor (many escape within 100 steps) to 0.8 (above the stop curves below)
    rng = np.random.default_rng(20)
    return band_sample(m, 1500, rng, K_hi=0.8)


def wavy():
    """A stop curve crossing the orbits' range of K: 0.3 + 0.1 cos(phi) + 0.05 sin(3 phi), 64 samples."""
    return Curve.from_function(lambda p: 0.3 + 0.1 * np.cos(p) + 0.05 * np.sin(3 * p), n=64)


STOPS = {
    "above-curve": lambda: Above(wavy()),
    "below-curve": lambda: Below(wavy()),
    "above-number": lambda: Above(0.45),
    "below-number": lambda: Below(-0.2),
}


def first_in_set(stop, full):
    """Independent stop step of each orbit of an unstopped, fully recorded run: the first n <=
    steps_done with stop.contains(phi_n, K_n), -1 if none (the start counts)."""
    n_orb, n_states = full.phi.shape
    reached = np.arange(n_states)[None, :] <= full.steps_done[:, None]
    inside = stop.contains(full.phi, full.K) & reached & ~np.isnan(full.K)
    return np.where(inside.any(axis=1), np.argmax(inside, axis=1), -1)


# ------------------------------------------------------------------------------------------------
# every = k


@pytest.mark.parametrize("kernel", KERNELS)
@pytest.mark.parametrize("k", [1, 2, 7, 100, 101, 250])
def test_every_k_is_a_slice_of_the_full_record(m, starts, kernel, k):
    phi0, K0 = starts
    n = 100  # k = 7: n not a multiple of k; k = 100: two states; k > n: the start alone
    rec = ("orbit", "regions", "rotation", "visited")
    full = m.iterate(phi0, K0, n, record=rec, kernel=kernel, exit_regions={"0u", "0"})
    assert full.count(Status.ESCAPED) > 50  # orbits that stop mid-way (NaN padding is sliced too)
    thin = m.iterate(phi0, K0, n, record=rec, kernel=kernel, exit_regions={"0u", "0"}, every=k)
    assert thin.every == k
    assert thin.phi.shape == (phi0.size, n // k + 1) and thin.region.shape == (phi0.size, -(-n // k))
    assert np.array_equal(thin.phi, full.phi[:, ::k], equal_nan=True)
    assert np.array_equal(thin.K, full.K[:, ::k], equal_nan=True)
    assert np.array_equal(thin.region, full.region[:, ::k])
    # what is not a per-state record is not thinned
    for attr in ("phi_final", "K_final", "rotation", "status", "steps_done", "exit_step", "visited"):
        assert np.array_equal(getattr(thin, attr), getattr(full, attr), equal_nan=True), attr


def test_every_k_thins_what_the_memory_check_counts(m):
    # 1e12 steps of one orbit: every state would need 16 TB and is refused before any work. A run
    # of 3e6 steps thinned to every 3e5-th state (11 states; ~1 s, the family's ~7 s) starts, and
    # Ctrl-C, pressed once work is under way, ends it: the partial result has the thinned shape.
    with pytest.raises(ValueError, match=r"for 1 orbits x 1000000000000 steps needs .* GiB, more than half"):
        m.iterate([0.1], [0.1], 10**12, record=("orbit",))
    with pytest.raises(ValueError, match=r"for 1 orbits x 1000000000000 steps \(every 2\) needs .* GiB"):
        m.iterate([0.1], [0.1], 10**12, record=("orbit",), every=2)
    press = CtrlCOnceStarted()
    with pytest.raises(KeyboardInterrupt) as info:
        m.iterate([0.1], [0.1], 3 * 10**6, record=("orbit",), every=3 * 10**5, progress=press)
    assert time.perf_counter() - press.fired_at < PROMPT
    part = info.value.partial
    assert part.phi.shape == (1, 11) and part.status[0] == Status.INTERRUPTED and part.phi[0, 0] == 0.1


# ------------------------------------------------------------------------------------------------
# stop


@pytest.mark.parametrize("kernel", KERNELS)
@pytest.mark.parametrize("which", list(STOPS))
def test_stop_is_the_first_state_in_the_set(m, starts, kernel, which):
    phi0, K0 = starts
    n = 100
    stop = STOPS[which]()
    full = m.iterate(phi0, K0, n, record=("orbit", "regions"), kernel=kernel)
    expected = first_in_set(stop, full)
    # the test set covers a start in the set, a later first visit and orbits that never reach it
    assert np.any(expected == 0) and np.any(expected > 0) and np.any(expected == -1), which
    res = m.iterate(phi0, K0, n, record=("orbit", "regions"), kernel=kernel, stop=stop)
    assert np.array_equal(res.stop_step, expected)
    hit = expected >= 0
    assert np.all(res.status[hit] == Status.STOPPED)
    assert np.array_equal(res.status[~hit], full.status[~hit])  # OK or ESCAPED as without the stop
    assert np.array_equal(res.steps_done[hit], expected[hit])
    rows = np.flatnonzero(hit)
    # the final state is the first state in the set, bit for bit
    assert np.array_equal(res.phi_final[hit], full.phi[rows, expected[hit]])
    assert np.array_equal(res.K_final[hit], full.K[rows, expected[hit]])
    assert np.all(stop.contains(res.phi_final[hit], res.K_final[hit]))
    for i in rows[:: max(1, rows.size // 200)]:
        s = expected[i]
        assert np.array_equal(res.phi[i, : s + 1], full.phi[i, : s + 1])
        assert np.all(np.isnan(res.phi[i, s + 1 :])) and np.all(np.isnan(res.K[i, s + 1 :]))
        assert np.array_equal(res.region[i, :s], full.region[i, :s])
        assert np.all(res.region[i, s:] == Region.NONE)  # no return is taken from x_{stop_step}
    # orbits that never reach the set are untouched
    assert np.array_equal(res.phi[~hit], full.phi[~hit], equal_nan=True)
    assert np.array_equal(res.region[~hit], full.region[~hit])


@pytest.mark.parametrize("kernel", KERNELS)
def test_stop_tests_the_curve_with_its_own_arithmetic(kernel):
    # K0 exactly on the curve (as Curve.__call__ computes it) is in both closed sets; one ulp off is
    # out of one of them. A kernel that evaluated the spline differently from Curve.__call__ (other
    # cell, other order of operations, fused multiply-adds) would disagree at some of these points.
    m = make_map(PARAM_SETS["paper_eps+0.3"])
    c = wavy()
    rng = np.random.default_rng(3)
    phi0 = np.concatenate(
        [
            rng.uniform(-np.pi, np.pi, 4000),
            c.phi,
            np.nextafter(c.phi, np.inf),
            np.nextafter(c.phi, -np.inf)[1:],
            [-np.pi, np.nextafter(np.pi, 0)],
        ]
    )
    on = c(phi0)
    for stop, off in ((Above(c), np.nextafter(on, -np.inf)), (Below(c), np.nextafter(on, np.inf))):
        a = m.iterate(phi0, on, 0, record=(), kernel=kernel, stop=stop)
        assert np.all(a.stop_step == 0) and np.all(a.status == Status.STOPPED)
        b = m.iterate(phi0, off, 0, record=(), kernel=kernel, stop=stop)
        assert np.all(b.stop_step == -1) and np.all(b.status == Status.OK)


@pytest.mark.parametrize("kernel", KERNELS)
@pytest.mark.parametrize("side", ["Below", "Above"])
def test_stop_just_inside_the_extreme_of_a_curve(kernel, side):
    # The SIMD kernel skips the spline for packets beyond the curve's range (its lower / upper
    # bound); a state just inside the extreme must still stop. Curve [0.2, 0.35, 0.35] has its
    # maximum 0.3875 at phi = 0, inside a cell whose end curvatures are equal (d = 0 up to
    # rounding), where the bound was once computed as 0.38719 and the SIMD kernel never stopped
    # these orbits. At eps = 0, K stays K0 and phi rotates, so each orbit eventually passes phi ~ 0.
    m0 = make_map(dict(PARAM_SETS["paper_eps+0.3"], eps=0.0))
    sign = 1.0 if side == "Below" else -1.0
    c = Curve(sign * np.array([0.2, 0.35, 0.35]))
    top = c(0.0)
    assert top == pytest.approx(sign * 0.3875, abs=1e-15)
    K0 = top - sign * np.geomspace(3e-4, 1e-6, 40)
    phi0 = np.full(40, -3.0)
    stop = Below(c) if side == "Below" else Above(c)
    full = m0.iterate(phi0, K0, 20_000, record=("orbit",), kernel=kernel)
    expected = first_in_set(stop, full)
    assert np.all(expected > 0)  # every orbit gets there, none starts there
    res = m0.iterate(phi0, K0, 20_000, record=(), kernel=kernel, stop=stop)
    assert np.array_equal(res.stop_step, expected)


@pytest.mark.parametrize("kernel", KERNELS)
def test_stop_comes_before_an_exit_at_the_same_state(m, starts, kernel):
    # A state in the stop set ends the orbit before its return is looked at: with stop_on_exit
    # too, an orbit whose first state in the set is also its first outside exit_regions is STOPPED.
    phi0, K0 = starts
    stop = Above(wavy())
    plain = m.iterate(phi0, K0, 100, record=("regions",), kernel=kernel, stop=stop)
    both = m.iterate(
        phi0, K0, 100, record=("regions",), kernel=kernel, stop=stop, exit_regions={"0u", "0"}, stop_on_exit=True
    )
    first_out = np.array(
        [
            np.argmax(~np.isin(r, [Region.BESIDE, Region.ABOVE]) & (r != Region.NONE))
            if np.any(~np.isin(r, [Region.BESIDE, Region.ABOVE]) & (r != Region.NONE))
            else -1
            for r in plain.region
        ]
    )
    stopped_first = (plain.stop_step >= 0) & ((first_out == -1) | (plain.stop_step <= first_out))
    exited_first = (first_out >= 0) & ((plain.stop_step == -1) | (first_out < plain.stop_step))
    assert np.any(stopped_first) and np.any(exited_first)
    assert np.all(both.status[stopped_first] == Status.STOPPED)
    assert np.array_equal(both.steps_done[stopped_first], plain.stop_step[stopped_first])
    assert np.all(both.status[exited_first] == Status.EXITED)
    assert np.array_equal(both.exit_step[exited_first], first_out[exited_first])
    assert np.all(both.stop_step[exited_first] == -1)


# ------------------------------------------------------------------------------------------------
# extrema and residence


@pytest.mark.parametrize("kernel", KERNELS)
@pytest.mark.parametrize("stop", [None, "above-curve", "below-number"])
def test_extrema_are_those_of_the_states_visited(m, starts, kernel, stop):
    phi0, K0 = starts
    s = None if stop is None else STOPS[stop]()
    full = m.iterate(phi0, K0, 100, record=("orbit",), kernel=kernel, stop=s)
    for every in (1, 9):  # streamed over every state, not the kept ones
        ext = m.iterate(phi0, K0, 100, record=("extrema",), kernel=kernel, stop=s, every=every)
        assert ext.phi is None and ext.K is None
        # states x_0 .. x_{steps_done}: the start, the final state (also an escaped image) and
        # nothing after a stop (the padding is NaN, which nanmin skips)
        assert np.array_equal(ext.K_min, np.nanmin(full.K, axis=1))
        assert np.array_equal(ext.K_max, np.nanmax(full.K, axis=1))
    assert np.all(ext.K_min <= np.minimum(K0, ext.K_final)) and np.all(ext.K_max >= np.maximum(K0, ext.K_final))


@pytest.mark.parametrize("kernel", KERNELS)
@pytest.mark.parametrize("exit_kw", [{}, dict(exit_regions={"0u", "0"}, stop_on_exit=True)])
def test_residence_counts_the_recorded_returns(m, starts, kernel, exit_kw):
    phi0, K0 = starts
    full = m.iterate(phi0, K0, 100, record=("regions", "visited"), kernel=kernel, **exit_kw)
    res = m.iterate(phi0, K0, 100, record=("residence",), kernel=kernel, every=13, **exit_kw)
    assert res.residence.shape == (phi0.size, N_REGIONS) and res.residence.dtype == np.int64
    expected = np.stack([np.count_nonzero(full.region == r, axis=1) for r in range(N_REGIONS)], axis=1)
    assert np.array_equal(res.residence, expected)
    # steps_done returns, plus the exiting one (recorded, not taken) with stop_on_exit
    exited = full.status == Status.EXITED
    assert np.array_equal(res.residence.sum(axis=1), full.steps_done + exited)
    if exit_kw:
        assert np.any(exited)
    bits = (full.visited[:, None].astype(np.int64) >> np.arange(N_REGIONS)) & 1
    assert np.array_equal(res.residence > 0, bits == 1)


# ------------------------------------------------------------------------------------------------
# threads, kernels, interrupt


ALL = dict(record=("orbit", "regions", "rotation", "visited", "extrema", "residence"), every=3)
ATTRS = (
    "phi",
    "K",
    "region",
    "rotation",
    "visited",
    "phi_final",
    "K_final",
    "status",
    "steps_done",
    "exit_step",
    "stop_step",
    "K_min",
    "K_max",
    "residence",
)


def _same(a, b):
    for attr in ATTRS:
        x, y = getattr(a, attr), getattr(b, attr)
        assert (x is None) == (y is None), attr
        if x is not None:
            assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), attr


@pytest.mark.parametrize("kernel", KERNELS)
def test_results_do_not_depend_on_the_thread_count(kernel):
    m = make_map(PARAM_SETS["paper_eps+0.92"])
    phi0, K0 = band_sample(m, 3000, np.random.default_rng(8), K_hi=1.0)
    kw = dict(ALL, kernel=kernel, stop=Above(wavy()), exit_regions={"0u", "0", "1"})
    r1 = m.iterate(phi0, K0, 150, n_threads=1, **kw)
    assert {Status.OK, Status.ESCAPED, Status.STOPPED} <= set(r1.status.tolist())  # chunks of unequal work
    _same(r1, m.iterate(phi0, K0, 150, n_threads=2, **kw))
    _same(r1, m.iterate(phi0, K0, 150, n_threads=0, **kw))


def test_kernels_are_bit_identical_at_eps_0():
    # At eps = 0 neither kernel calls sin's result into K (K_{n+1} = K_n + 0 sin(...)), so the two
    # kernels compute the same numbers (today; with eps != 0 they differ by SLEEF vs libm sin, see
    # test_iterate.py); with every option on they must still agree bit for bit.
    m = make_map(dict(PARAM_SETS["paper_eps+0.3"], eps=0.0))
    phi0, K0 = band_sample(m, 2000, np.random.default_rng(9), K_hi=0.8)
    for stop in (Above(wavy()), Below(wavy())):
        a = m.iterate(phi0, K0, 200, kernel="simd", stop=stop, **ALL)
        b = m.iterate(phi0, K0, 200, kernel="scalar", stop=stop, **ALL)
        assert np.any(a.stop_step > 0)
        _same(a, b)


@pytest.mark.parametrize("kernel", KERNELS)
def test_interrupt_keeps_the_transport_records(kernel):
    m = make_map(PARAM_SETS["paper_eps+0.3"])
    n = 20_000
    phi0, K0 = band_sample(m, n, np.random.default_rng(5), K_hi=0.8, margin=0.5)
    press = CtrlCOnceStarted()
    with pytest.raises(KeyboardInterrupt) as info:  # ~1 s (simd), ~6 s (scalar) of work; Ctrl-C at ~0.1 s
        m.iterate(
            phi0,
            K0,
            20_000,
            record=("extrema", "residence"),
            n_threads=2,
            kernel=kernel,
            stop=Above(wavy()),
            progress=press,
        )
    assert time.perf_counter() - press.fired_at < PROMPT
    res = info.value.partial
    st = res.status
    assert np.any(st == Status.INTERRUPTED) and np.any(st == Status.STOPPED)
    # the partial records are those of the states reached: redo a few orbits to where they were
    idx = np.flatnonzero(st == Status.INTERRUPTED)[:5].tolist() + np.flatnonzero(st == Status.STOPPED)[:5].tolist()
    for i in idx:
        again = m.iterate(
            phi0[i : i + 1],
            K0[i : i + 1],
            int(res.steps_done[i]),
            record=("extrema", "residence"),
            kernel=kernel,
            stop=Above(wavy()),
        )
        assert again.K_min[0] == res.K_min[i] and again.K_max[0] == res.K_max[i]
        assert np.array_equal(again.residence[0], res.residence[i])
        assert again.stop_step[0] == res.stop_step[i]


# ------------------------------------------------------------------------------------------------
# save and load


def test_a_result_with_the_transport_records_saves_and_loads(m, starts, tmp_path):
    phi0, K0 = starts
    res = m.iterate(
        phi0[:50], K0[:50], 30, stop=Below(wavy()), every=4, **{k: v for k, v in ALL.items() if k != "every"}
    )
    path = hovering.save(res, tmp_path / "r.npz")
    back = hovering.load(path)
    assert back.every == 4
    _same(res, back)


# ------------------------------------------------------------------------------------------------
# FlowMap


@pytest.fixture(scope="module")
def fm():
    sys = hovering.StepSystem(
        V1=hovering.Harmonic(1.0),
        V2=hovering.Tan(1.4, 0.7),
        coupling=hovering.Bilinear(),
        eps=-0.05,
        qw1=-1.0,
        qw2=-0.5,
        geometry="step",
    )
    return hovering.FlowMap(sys, h=1.0, rtol=1e-10)


@pytest.fixture(scope="module")
def flow_run(fm):
    """Twelve orbits of 24 returns, fully recorded, and their starts."""
    phi0 = np.linspace(-3.0, 3.0, 12)
    K0 = np.tile([-0.06, -0.02, 0.01, 0.04], 3)
    full = fm.iterate(phi0, K0, 24, record=("orbit", "regions", "itinerary", "times", "steps", "visited"))
    return phi0, K0, full


def test_flow_every_k_is_a_slice_of_the_full_record(fm, flow_run):
    phi0, K0, full = flow_run
    thin = fm.iterate(phi0, K0, 24, record=("orbit", "regions", "itinerary", "times", "steps", "visited"), every=5)
    assert thin.phi.shape == (12, 24 // 5 + 1) and thin.region.shape == thin.time.shape == (12, 5)
    assert np.array_equal(thin.phi, full.phi[:, ::5], equal_nan=True)
    assert np.array_equal(thin.K, full.K[:, ::5], equal_nan=True)
    assert np.array_equal(thin.region, full.region[:, ::5])
    assert np.array_equal(thin.time, full.time[:, ::5], equal_nan=True)
    assert np.array_equal(thin.integrator_steps, full.integrator_steps[:, ::5])
    assert thin.itinerary == [row[::5] for row in full.itinerary]
    for attr in ("phi_final", "K_final", "status", "steps_done", "visited"):
        assert np.array_equal(getattr(thin, attr), getattr(full, attr)), attr


@pytest.mark.parametrize("stop", [Above(0.03), Below(Curve.from_function(lambda p: -0.03 + 0.01 * np.sin(p), n=32))])
def test_flow_stop_extrema_and_residence_against_the_full_record(fm, flow_run, stop):
    phi0, K0, full = flow_run
    expected = first_in_set(stop, full)
    assert np.any(expected == 0) and np.any(expected > 0)
    res = fm.iterate(phi0, K0, 24, record=("orbit", "regions", "itinerary", "extrema", "residence"), stop=stop)
    assert np.array_equal(res.stop_step, expected)
    hit = expected >= 0
    assert np.all(res.status[hit] == Status.STOPPED) and np.array_equal(res.steps_done[hit], expected[hit])
    rows = np.flatnonzero(hit)
    assert np.array_equal(res.phi_final[hit], full.phi[rows, expected[hit]])
    assert np.array_equal(res.K_final[hit], full.K[rows, expected[hit]])
    for i in rows:
        s = expected[i]
        assert np.array_equal(res.K[i, : s + 1], full.K[i, : s + 1]) and np.all(np.isnan(res.K[i, s + 1 :]))
        assert res.itinerary[i][:s] == full.itinerary[i][:s] and res.itinerary[i][s:] == ["-"] * (24 - s)
        assert np.all(res.region[i, s:] == Region.NONE)
    # streamed records vs the states and returns recorded
    assert np.array_equal(res.K_min, np.nanmin(res.K, axis=1)) and np.array_equal(res.K_max, np.nanmax(res.K, axis=1))
    counts = np.stack([np.count_nonzero(res.region == r, axis=1) for r in range(N_REGIONS)], axis=1)
    assert np.array_equal(res.residence, counts)
    assert np.array_equal(res.residence.sum(axis=1), res.steps_done)


def test_flow_stop_on_exit_records_the_exiting_return(fm, flow_run):
    # The return that leaves exit_regions is computed; it is recorded (region, itinerary, time)
    # though not taken, and the returns after it are padding: Region.NONE, '-', NaN, -1 - never
    # the smooth flow's label ''.
    phi0, K0, full = flow_run
    allowed = {int(Region.BESIDE), int(Region.ABOVE)}
    first = np.array([next((j for j, r in enumerate(row) if int(r) not in allowed), -1) for row in full.region])
    assert np.any(first >= 0)
    res = fm.iterate(
        phi0,
        K0,
        24,
        record=("orbit", "regions", "itinerary", "times", "steps", "residence"),
        exit_regions={"0u", "0"},
        stop_on_exit=True,
    )
    for i in np.flatnonzero(first >= 0):
        k = first[i]
        assert res.status[i] == Status.EXITED and res.exit_step[i] == k and res.steps_done[i] == k
        assert res.itinerary[i][: k + 1] == full.itinerary[i][: k + 1]
        assert res.itinerary[i][k] not in ("", "-")
        assert res.itinerary[i][k + 1 :] == ["-"] * (24 - k - 1)
        assert np.array_equal(res.region[i, : k + 1], full.region[i, : k + 1])
        assert np.all(res.region[i, k + 1 :] == Region.NONE)
        assert np.array_equal(res.time[i, : k + 1], full.time[i, : k + 1]) and np.all(np.isnan(res.time[i, k + 1 :]))
        assert np.all(res.integrator_steps[i, k + 1 :] == -1)
        assert np.all(np.isnan(res.phi[i, k + 1 :]))
        assert res.residence[i].sum() == k + 1


def test_flow_results_do_not_depend_on_the_thread_count(fm, flow_run):
    phi0, K0, _ = flow_run
    kw = dict(record=("orbit", "regions", "extrema", "residence"), every=2, stop=Above(0.03))
    a = fm.iterate(phi0, K0, 12, n_threads=1, **kw)
    b = fm.iterate(phi0, K0, 12, n_threads=2, **kw)
    for attr in (
        "phi",
        "K",
        "region",
        "phi_final",
        "K_final",
        "status",
        "steps_done",
        "stop_step",
        "K_min",
        "K_max",
        "residence",
    ):
        assert np.array_equal(getattr(a, attr), getattr(b, attr), equal_nan=getattr(a, attr).dtype.kind == "f"), attr


def test_flow_interrupt_keeps_the_transport_records(fm):
    # Ctrl-C (once work has begun) keeps each orbit's extrema, residence and stop so far: redoing
    # the most advanced orbit for its steps_done returns gives the same numbers, bit for bit.
    rng = np.random.default_rng(5)
    phi, K = rng.uniform(-np.pi, np.pi, 100), rng.uniform(-0.06, 0.05, 100)
    press = CtrlCOnceStarted()
    kw = dict(record=("extrema", "residence"), stop=Above(0.045))
    with pytest.raises(KeyboardInterrupt) as info:  # ~2 s of work on 2 idle cores; Ctrl-C at ~0.1 s
        fm.iterate(phi, K, 2000, n_threads=2, progress=press, **kw)
    assert time.perf_counter() - press.fired_at < PROMPT
    res = info.value.partial
    assert np.any(res.status == Status.INTERRUPTED)
    for i in [
        int(np.argmax(np.where(res.status == Status.INTERRUPTED, res.steps_done, -1))),
        *np.flatnonzero(res.status == Status.STOPPED)[:2].tolist(),
    ]:
        again = fm.iterate(phi[i : i + 1], K[i : i + 1], int(res.steps_done[i]), **kw)
        assert again.K_min[0] == res.K_min[i] and again.K_max[0] == res.K_max[i]
        assert np.array_equal(again.residence[0], res.residence[i]) and again.stop_step[0] == res.stop_step[i]


# ------------------------------------------------------------------------------------------------
# bad input: a ValueError naming it, before any work (10**15 steps would never finish)


BAD = [
    (dict(every=0), r"every must be an integer in \[1, 2\*\*53\] \(record every k-th state\), got 0"),
    (dict(every=-3), r"every must be an integer in \[1, 2\*\*53\]"),
    (dict(every=2.5), r"every must be an integer >= 1 \(record every k-th state\), got 2\.5"),
    (dict(every=True), r"every must be an integer >= 1"),
    (dict(every="2"), r"every must be an integer >= 1"),
    (
        dict(stop=0.5),
        r"stop must be hovering\.Above\(curve_or_K\) or hovering\.Below\(curve_or_K\) \(or None\), got 0\.5",
    ),
    (dict(stop="above"), r"stop must be hovering\.Above"),
    (dict(stop=wavy), r"stop must be hovering\.Above"),
]


@pytest.mark.parametrize("kw,match", BAD)
def test_bad_transport_arguments_truncated(m, kw, match):
    for kernel in KERNELS:
        with pytest.raises(ValueError, match=match):
            m.iterate([0.1], [0.1], 10**15, record=(), kernel=kernel, **kw)


@pytest.mark.parametrize("kw,match", BAD)
def test_bad_transport_arguments_flow(fm, kw, match):
    with pytest.raises(ValueError, match=match):
        fm.iterate([0.1], [0.01], 10**15, record=(), **kw)


@pytest.mark.parametrize(
    "bad,match",
    [
        (float("nan"), r"Above: K must be finite, got nan"),
        (float("inf"), r"Above: K must be finite, got inf"),
        ("0.3", r"Above takes a hovering\.Curve or a number K \(a constant curve\), got '0\.3'"),
        (True, r"Above takes a hovering\.Curve or a number K"),
        ([0.1, 0.2, 0.3], r"Above takes a hovering\.Curve or a number K"),
    ],
)
def test_bad_stop_conditions(bad, match):
    with pytest.raises(ValueError, match=match):
        Above(bad)
    with pytest.raises(ValueError, match=match.replace("Above", "Below")):
        Below(bad)
