"""Barriers and layers across the impact zone (hovering.barrier_scan), against known answers:
the eps = 0 truncated map (every level is invariant: every cut a barrier, margins the start
spacing), the standard map (the truncated map's J_0u region: barriers between its KAM circles at
k = 0.5, a barrier near the golden circle at k = 0.9, none at k = 1.2 > 63/64 where no rotational
circle exists), a brute-force per-cut loop for the separation margins, the executor against one
process, Ctrl-C, bad input and saving."""

from __future__ import annotations

import concurrent.futures as cf
import math
import time

import numpy as np
import pytest

import hovering
from conftest import PROMPT, CtrlCOnceStarted
from hovering import Curve, ImpactZone, paper
from hovering.analysis.barriers import _envelopes, launch_points

TWO_PI = 2.0 * math.pi


def standard_map(k):
    """The truncated map with Omega0 = 0, tau0 = 1 is Chirikov's standard map on K >= 0 (J_0u:
    phibar = phi + K, Kbar = K + k sin phibar); (phi, K) = (x, p) on the line phi = 0."""
    return hovering.TruncatedMap(eps=k, Omega0=0.0, theta_w=3 * math.pi / 4)


def band(lo, hi):
    return ImpactZone(ceiling=Curve.constant(hi), floor=Curve.constant(lo))


# ------------------------------------------------------------------------------------------------
# Known answers


def test_eps0_every_level_is_a_barrier_with_the_start_spacing_as_margin():
    """At eps = 0 the truncated map keeps K: every orbit stays on its level, so every cut is a
    barrier and its margin is exactly the spacing of the starts in s (to rounding of s)."""
    m = paper.truncated_map(0.0)
    r = hovering.barrier_scan(m, band(-0.3, 0.2), n_starts=12, n_steps=2000, line="L1")
    assert r.barrier.all() and len(r.layers) == 12
    np.testing.assert_allclose(r.margin, 1.0 / 12, rtol=0, atol=1e-12)
    np.testing.assert_allclose(r.s_min, r.s0, atol=1e-12)
    np.testing.assert_allclose(r.s_max, r.s0, atol=1e-12)
    assert set(r.kind) == {"circle"}
    # the levels below K = 0 impact (J_1, J_R), those above never do
    assert np.array_equal(r.impact_fraction > 0, r.K0 < 0)
    assert r.spanning(0.1, 0.9).size == 0


def test_standard_map_k05_circles_are_barriers():
    """k = 0.5: most starts on phi = 0 lie on KAM circles, and a cut between two circles is a
    barrier (an invariant circle separates the cylinder); no orbit spans the band."""
    r = hovering.barrier_scan(standard_map(0.5), band(TWO_PI, 2 * TWO_PI), n_starts=24, n_steps=4000, line=0.0)
    circ = r.kind == "circle"
    assert circ.sum() >= 14
    both = circ[:-1] & circ[1:]
    assert both.sum() >= 8 and np.all(r.barrier[both])
    assert r.spanning(0.2, 0.8).size == 0
    # converse KAM applies (J_0u of a TruncatedMap) and never fires on a circle
    assert set(r.cone[circ]) == {"none"}


def test_standard_map_k09_keeps_a_barrier_and_k12_has_none():
    """k = 0.9 < k_c = 0.9716: the golden circle survives and divides the band [1.4 pi, 2.6 pi]
    (it crosses phi = 0 near p = 4.18 at k = 0.9716): at least one barrier, and one orbit on each
    side of it. k = 1.2: no rotational circle exists (MacKay-Percival 63/64), and in 2e4 steps
    the orbits of the band mix across it: no barrier, one chaotic layer; the cone crossing
    certifies it for most starts."""
    zone = band(1.4 * math.pi, 2.6 * math.pi)
    r09 = hovering.barrier_scan(standard_map(0.9), zone, n_starts=24, n_steps=20_000, line=0.0)
    assert r09.barrier.any()
    golden = [b for b in r09.barriers if 0.1 < b < 0.9]  # the golden level is inside the band
    assert golden, r09.summary()
    r12 = hovering.barrier_scan(standard_map(1.2), zone, n_starts=24, n_steps=20_000, line=0.0)
    assert not r12.barrier.any(), r12.summary()
    (layer,) = r12.layers
    assert layer.kind == "chaotic" and layer.counts["circle"] == 0
    assert np.mean(r12.cone == "crossing") > 0.5
    assert r12.spanning(0.1, 0.9).size > 0


def test_the_critical_curve_is_a_barrier_between_impacting_layers_and_circles():
    """The ceiling s = 1 is the critical invariant curve (the lowest circle that never impacts):
    the cut across it is a barrier, every start above it lies on a non-impacting circle where the
    converse-KAM test finds no crossing, and every start below it impacts (eps = 0.3, measured:
    margin 0.0047 at the cut, starts spaced 0.01)."""
    m = paper.truncated_map(0.3)
    zone = hovering.impact_zone(m, n_steps=20_000)
    r = hovering.barrier_scan(m, zone, n_starts=20, n_steps=20_000, s_range=(0.9, 1.1))
    above = r.s0 > 1.0
    cut = int(np.argmax(above)) - 1
    assert r.barrier[cut] and r.s0[cut] < 1.0 < r.s0[cut + 1]
    assert np.all(r.kind[above] == "circle") and np.all(r.impact_fraction[above] == 0)
    assert np.all(r.cone[above] == "none")
    assert np.all(r.impact_fraction[~above] > 0) and np.all(r.cone[~above] == "left_domain")
    assert np.all(r.s_max[~above] <= 1.0 + 1e-6)  # nothing below rose through the critical curve


def test_margins_are_the_brute_force_per_cut_loop():
    """The vectorised margins against a plain loop over cuts and bins on the points themselves
    (the same definition, computed independently from the recorded orbits)."""
    m = paper.truncated_map(0.3)
    zone = hovering.impact_zone(m, n_steps=5000)
    r = hovering.barrier_scan(m, zone, n_starts=10, n_steps=1024, n_bins=16, s_range=(0.5, 1.0))
    res = m.iterate(r.phi0, r.K0, 1024, record=("orbit",))
    s = zone.s(res.phi, res.K)
    hi, lo = _envelopes(res.phi, s, 16)
    for c in range(9):
        worst = math.inf
        for b in range(16):
            below = max(hi[j, b] for j in range(c + 1))
            above = [min(lo[j, bb % 16] for j in range(c + 1, 10)) for bb in (b - 1, b, b + 1)]
            above = [a if math.isfinite(a) else above[1] for a in above]
            gap = max(above) - below
            if not math.isnan(gap):
                worst = min(worst, gap)
        assert r.margin[c] == pytest.approx(worst, abs=0, rel=0) or (math.isinf(worst) and np.isnan(r.margin[c]))
        assert r.barrier[c] == (worst >= 0)
    # the extremes of s are those of the recorded orbits
    np.testing.assert_array_equal(r.s_min, np.nanmin(s, axis=1))
    np.testing.assert_array_equal(r.s_max, np.nanmax(s, axis=1))


def test_launch_points_lie_on_the_line_at_their_level():
    m = paper.truncated_map(0.3)
    zone = hovering.impact_zone(m, n_steps=5000)
    s = np.linspace(0.05, 0.95, 7)
    for line in ("L1", "L2", 1.0):
        phi, K = launch_points(m, zone, s, line)
        want = m.L1(K) if line == "L1" else m.L2(K) if line == "L2" else np.full_like(K, 1.0)
        np.testing.assert_allclose(phi, want, atol=1e-12)
        np.testing.assert_allclose(zone.s(phi, K), s, atol=1e-9)


# ------------------------------------------------------------------------------------------------
# Execution: executor, Ctrl-C, saving, bad input


def test_an_executor_and_any_thread_count_give_the_one_process_answer():
    m = paper.truncated_map(0.3)
    zone = hovering.impact_zone(m, n_steps=5000)
    kw = dict(n_starts=12, n_steps=2000, s_range=(0.6, 1.0))
    one = hovering.barrier_scan(m, zone, **kw)
    with cf.ThreadPoolExecutor(2) as pool:
        many = hovering.barrier_scan(m, zone, executor=hovering.parallel.Executor(pool=pool, pieces=3), **kw)
    threads = hovering.barrier_scan(m, zone, n_threads=1, **kw)
    for f in ("kind", "period", "s_min", "s_max", "margin", "barrier", "impact_fraction", "cone", "status"):
        assert np.array_equal(getattr(one, f), getattr(many, f), equal_nan=f in ("margin",)), f
        assert np.array_equal(getattr(one, f), getattr(threads, f), equal_nan=f in ("margin",)), f


#: Classification options of the Ctrl-C scans: island chains up to period 2 only. The orbits cut
#: short are never classified; were the interrupt lost, the full classification of 4 x 2e6 points
#: (~18 s, mostly the island tests of periods up to 64) would be what the test waits for.
_SHORT = dict(max_period=2)


def test_ctrl_c_keeps_the_orbits_so_far():
    m = paper.truncated_map(0.3)
    zone = hovering.impact_zone(m, n_steps=5000)
    press = CtrlCOnceStarted()
    with pytest.raises(KeyboardInterrupt) as info:
        # starts that stay in the band, so that the press lands inside a long orbit (an orbit that
        # leaves the band early still returns its padded record). 2e6 steps: one start per piece,
        # ~0.5 s each, the press at the first one's first report (~0.1 s); were it lost, the scan
        # would end within seconds (its classification kept short by max_period) and fail here.
        hovering.barrier_scan(
            m, zone, n_starts=4, n_steps=2 * 10**6, s_range=(0.5, 1.0), classify=_SHORT, progress=press
        )
    assert time.perf_counter() - press.fired_at < PROMPT
    part = info.value.partial
    assert not part.complete and len(part) == 4
    cut_short = part.status == hovering.Status.INTERRUPTED
    assert cut_short.all() and not part.barrier.any()
    assert np.all(part.decided_by == "interrupted") and np.all(part.kind == "undecided")


def test_an_orbit_that_ends_on_its_own_keeps_its_verdict_when_the_rest_is_interrupted():
    m = paper.truncated_map(0.3)
    zone = hovering.impact_zone(m, n_steps=5000)
    with pytest.raises(KeyboardInterrupt) as info:
        # the lowest start leaves the band after 1160 steps; the second one is cut short. Three
        # starts share the first piece (the most that fit 1.3e6 steps), ~0.35 s of work, Ctrl-C at
        # its first report (~0.1 s); the whole scan takes seconds, so a lost interrupt fails here.
        hovering.barrier_scan(m, zone, n_starts=4, n_steps=1_300_000, progress=CtrlCOnceStarted(after=1))
    part = info.value.partial
    cut_short = part.status == hovering.Status.INTERRUPTED
    assert part.status[0] == hovering.Status.ESCAPED and part.decided_by[0] != "interrupted"
    assert cut_short[1:].all() and np.all((part.decided_by == "interrupted") == cut_short)


def test_results_save_and_load(tmp_path):
    m = paper.truncated_map(0.3)
    zone = hovering.impact_zone(m, n_steps=5000)
    r = hovering.barrier_scan(m, zone, n_starts=6, n_steps=600, keep=7)
    full = m.iterate(r.phi0, r.K0, 600, record=("orbit",))
    take = [0, 100, 200, 300, 400, 500, 600]  # keep=7 over 600 returns: evenly strided, ends included
    assert np.array_equal(r.phi, full.phi[:, take], equal_nan=True)
    assert np.array_equal(r.K, full.K[:, take], equal_nan=True)
    # a short repr, and a table with one row per start (pandas is in the test extra)
    assert len(repr(r)) < 400 and "barriers=" in repr(r) and "<table>" in r._repr_html_()
    df = r.to_pandas()
    assert list(df.index) == list(range(6)) and np.array_equal(df["s_max"].to_numpy(), r.s_max)
    assert np.array_equal(df["barrier_above"].to_numpy()[:-1], r.barrier) and not df["barrier_above"].iloc[-1]
    assert df.attrs["line"] == "L1" and list(df["kind"]) == list(r.kind)
    back = hovering.load(hovering.save(r, tmp_path / "scan.npz"))
    assert back.summary() == r.summary()
    assert np.array_equal(back.margin, r.margin, equal_nan=True)


@pytest.mark.parametrize(
    "kw, match",
    [
        (dict(n_starts=1), r"n_starts must be an integer in \[2, 100000\], got 1"),
        (dict(n_steps=10), r"n_steps must be an integer in \[256, "),
        (dict(s_range=(0.8, 0.2)), r"s_range must rise: got \(0.8, 0.2\)"),
        (dict(s_range="ab"), "s_range must be two zone levels"),
        (dict(line="L3"), "line must be 'L1', 'L2' or an angle, got 'L3'"),
        (dict(line=4.0), r"line must lie in \[-3.14159.*got 4"),
        (dict(s_range=(-50.0, 1.0)), r"lies outside the map's band"),
        (dict(n_bins=2), r"n_bins must be an integer in \[4, "),
        (dict(keep=-1), r"keep must be an integer in \[0, "),
    ],
)
def test_bad_input_is_named_before_any_work(kw, match):
    m = paper.truncated_map(0.3)
    zone = ImpactZone(ceiling=Curve.constant(0.3), floor=Curve.constant(-0.3))
    t = time.process_time()
    with pytest.raises(ValueError, match=match):
        hovering.barrier_scan(m, zone, **{"n_steps": 10**9, **kw})
    assert time.process_time() - t < 5  # refused, not computed
    with pytest.raises(ValueError, match="zone must be a hovering.ImpactZone"):
        hovering.barrier_scan(m, (0, 1))


# ------------------------------------------------------------------------------------------------
# The zone tools on truncated maps at eps < 0, on a flow's floor below its band, and Ctrl-C


def test_a_scan_at_eps_below_0_runs_where_cone_orbits_leave_the_band():
    """eps = -0.3 (the sign that does not hover): the zone reaches down to the band's floor
    K = -pi, and the converse-KAM orbit of the lowest start (in J_0, smooth) leaves the band; its
    region lookup raised and the whole scan was lost. Now that start is "left_domain" (it left
    the map's domain: no circle of the smooth region passes through it) and the rest stands."""
    m = paper.truncated_map(-0.3)
    zone = hovering.impact_zone(m, n_steps=5000)
    r = hovering.barrier_scan(m, zone, n_starts=16, n_steps=2000)
    assert r.complete and set(r.cone) <= {"n/a", "none", "crossing", "left_domain", "not_twist"}
    smooth = np.isin(np.asarray(m.region(r.phi0, r.K0)), (int(hovering.Region.BESIDE), int(hovering.Region.ABOVE)))
    assert np.all(r.cone[~smooth] == "n/a") and r.cone[0] == "left_domain" and smooth[0]
    # the verdicts of the starts whose cone orbits stay in the band are converse_kam's own
    from hovering.analysis.orbits import converse_kam

    ok = np.flatnonzero(smooth)[1:]
    want = [converse_kam(m, r.phi0[i : i + 1], r.K0[i : i + 1], 2000).status[0] for i in ok[-3:]]
    assert list(r.cone[ok[-3:]]) == want


def test_interrupted_orbits_are_not_classified(monkeypatch):
    """After Ctrl-C the orbits cut short get no verdict ("interrupted"); classifying and reducing
    their partial orbits (millions of points) delayed the return by seconds (3.2 s measured for
    one orbit of a 1e7-step scan, 0.1-0.25 s now). Now classify_orbits sees only the orbits that
    ended on their own, and the cut-short ones have no s extremes (NaN)."""
    import hovering.analysis.barriers as barriers

    rows = []
    real = barriers.classify_orbits

    def spy(phi, K, **kw):
        rows.append(phi.shape[0])
        return real(phi, K, **kw)

    monkeypatch.setattr(barriers, "classify_orbits", spy)
    m = paper.truncated_map(0.3)
    zone = hovering.impact_zone(m, n_steps=5000)
    press = CtrlCOnceStarted()
    with pytest.raises(KeyboardInterrupt) as info:  # bounded as in test_ctrl_c_keeps_the_orbits_so_far
        hovering.barrier_scan(
            m, zone, n_starts=4, n_steps=2 * 10**6, s_range=(0.5, 1.0), classify=_SHORT, progress=press
        )
    part = info.value.partial
    assert np.all(part.status == hovering.Status.INTERRUPTED) and np.all(part.decided_by == "interrupted")
    assert rows and all(n == 0 for n in rows)
    assert np.all(np.isnan(part.s_min)) and np.all(np.isnan(part.s_max))


def test_a_flow_zone_keeps_its_floor_torus_below_the_band_and_scans_from_it():
    """README system at eps = -0.1: the flow's floor torus dips to K = -0.261, below the band its
    normal coordinates are guaranteed on (from -0.257). It is an orbit of the flow, so the zone
    keeps it (it was raised to a level orbits cross: s down to -0.037 measured on orbits started
    at s = 0.05), and the scan starts orbits just above it (they were refused as out of band)."""
    fm = hovering.FlowMap(paper.system(eps=-0.1), 1.0)
    zone = hovering.impact_zone(fm, n_steps=1000)
    lo = fm.valid_band()[0]
    assert zone.floor_kind == "flow" and not zone.raised and zone.floor.K.min() < lo
    assert zone.floor == hovering.impact_zone_floor(fm, n_steps=1000).curve
    phi_low = float(zone.floor.phi[np.argmin(zone.floor.K)])
    r = hovering.barrier_scan(fm, zone, n_starts=4, n_steps=300, line=phi_low, s_range=(0.0, 0.02))
    assert r.K0[0] < lo and np.all(r.status == hovering.Status.OK)
    # nothing started above the floor went below it (to the floor curve's own scatter, in s)
    assert np.nanmin(r.s_min) >= -10 * zone.floor.max_error / np.min(zone.height(zone.floor.phi))
