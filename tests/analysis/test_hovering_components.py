"""HoveringArea.components (the band, island chains by period, the region under the floor), the
default box that deepens itself, and compare_hovering (the flow's verdicts against its models').

Every check is against an independent computation: a plain Python loop over ``m.step`` /
``m.region``, each model's own ``hovering_area`` on the same points, an explicit deeper K_low, the
eps = 0 tori of the flow (K = const in its normal coordinates) and the theory (0 for the sign of
eps that does not hover).
"""

from __future__ import annotations

import numpy as np
import pytest

import hovering
from hovering import Region, paper
from hovering.analysis import hovering as hovering_module
from hovering.analysis import hovering_compare
from hovering.analysis.hovering import COMPONENTS, _clusters

BAND, ISLANDS, UNDER = (COMPONENTS.index(k) for k in ("band", "islands", "under_floor"))
NO_IMPACT = (int(Region.BESIDE), int(Region.ABOVE))


def plain_verdict(m, phi, K, n_steps):
    """(hovers, regions visited) of one point by its definition, one scalar step at a time: it
    impacts under F_0 within n_steps, and never under F_eps (the region of each step from x_n)."""
    m0 = m.with_eps(0.0)
    p, k = float(phi), float(K)
    impacts0 = False
    for _ in range(n_steps):
        if int(m0.region(p, k)) not in NO_IMPACT:
            impacts0 = True
            break
        p, k = m0.step(p, k)
    p, k, seen = float(phi), float(K), set()
    for _ in range(n_steps):
        r = int(m.region(p, k))
        if r not in NO_IMPACT:
            return False, seen
        seen.add(r)
        p, k = m.step(p, k)
    return impacts0, seen


def interior(hv, samples, code, count):
    """Up to ``count`` samples of part ``code`` whose 8 grid neighbours are in the same part (far
    from the part's edge, where the scalar and the SIMD kernel may round an orbit differently);
    ``samples`` as asked of hovering_area (the grid it makes of them)."""
    n_phi, n_K = hovering._core.analysis.sample_grid(samples, hv.box[2])
    grid = hv.component.reshape(n_phi, n_K) == code
    inner = grid.copy()
    for dc in (-1, 0, 1):
        for dr in (-1, 0, 1):
            shifted = np.roll(grid, dc, axis=0)
            shifted = np.roll(shifted, dr, axis=1)
            if dr:  # rows do not wrap
                shifted[:, 0 if dr > 0 else -1] = False
            inner &= shifted
    idx = np.flatnonzero(inner.ravel())
    return idx[np.linspace(0, idx.size - 1, min(count, idx.size)).astype(int)] if idx.size else idx


@pytest.fixture(scope="module")
def negative_eps():
    # The paper's map at eps = -0.3: eq:hovsetsize gives 0 (sin(Omega0/2) > 0), yet points hover
    # in a period-2 island chain inside J_0 below the default box (the box deepens once to reach it).
    m = paper.truncated_map(-0.3)
    return m, hovering.hovering_area(m, n_steps=2000, n_samples=20_000, keep_points=True)


def test_parts_sum_to_area_and_negative_eps_is_islands(negative_eps):
    m, hv = negative_eps
    c = hv.components
    assert m.theory().area == 0.0
    # Every hovering sample is in exactly one part: the areas add up to the area (to rounding:
    # three products box * count / n against one).
    assert c.band + c.islands + c.under_floor == pytest.approx(hv.area, rel=1e-12)
    assert sum(c.counts.values()) == int(hv.hovering.sum())
    assert sum(c.periods.values()) == pytest.approx(c.islands, rel=1e-12)
    # Theory 0 for the band: it is 0 within its error; the islands carry the rest (many sigmas).
    assert c.band <= c.band_error
    assert c.islands > 10 * c.islands_error
    # The truncated map has no floor: nothing is under it.
    assert c.floor == "none" and c.under_floor == 0.0 and c.counts["under_floor"] == 0
    # The chain of Omega0 + tau0 K = pi (mod 2 pi) has period 2: it carries (nearly) all of it.
    assert c.periods.get(2, 0.0) >= 0.95 * c.islands
    # Per-sample codes agree with the core's membership.
    assert np.array_equal(hv.component != 0, hv.hovering)
    assert np.array_equal(hv.component == BAND, hv.both_sides)
    assert np.all(hv.period[hv.component != ISLANDS] == 0)


def test_positive_eps_splits_band_and_islands():
    # At eps = 0.3 the deepened box holds the band (eq:hovsetsize) and a period-2 chain below it.
    m = paper.truncated_map(0.3)
    hv = hovering.hovering_area(m, n_steps=2000, n_samples=20_000)
    c = hv.components
    assert c.band + c.islands + c.under_floor == pytest.approx(hv.area, rel=1e-12)
    # eq:hovsetsize is the band's leading order (0.764 at 0.3; measured C ~ 0.3 eps^2 below it).
    assert abs(c.band - hv.theory) <= 1.0 * 0.3**2 + c.band_error
    assert c.islands > 10 * c.islands_error


def test_membership_matches_a_plain_loop(negative_eps):
    n_steps = 2000
    m, hv = negative_eps
    pos = paper.truncated_map(0.3)
    hp = hovering.hovering_area(pos, n_steps=n_steps, n_samples=20_000, K_low=-0.7, keep_points=True)
    checked = 0
    for mm, h, code in ((m, hv, ISLANDS), (pos, hp, BAND), (pos, hp, 0)):
        for i in interior(h, 20_000, code, 3):
            hovers, seen = plain_verdict(mm, h.phi[i], h.K[i], n_steps)
            assert hovers == (code != 0), (code, h.phi[i], h.K[i])
            if code:
                # band: the orbit visits both J_0 and J_0u; islands: only one of them.
                assert (len(seen) == 2) == (code == BAND), (code, seen)
            checked += 1
    assert checked == 9


def test_default_box_deepens_like_an_explicit_K_low():
    m = paper.truncated_map(-0.3)
    kw = dict(n_steps=1000, n_samples=5000, components=False)
    first = hovering.hovering_area(m, deepen=0, **kw)
    assert first.floor_touched and first.deepened == 0
    deep = hovering.hovering_area(m, **kw)
    assert deep.deepened == 1 and not deep.floor_touched and not deep.band_edge
    assert deep.box[2] == 2 * first.box[2]
    explicit = hovering.hovering_area(m, K_low=2 * first.box[2], **kw)
    assert (deep.area, deep.error, deep.n_samples) == (explicit.area, explicit.error, explicit.n_samples)
    # A given K_low is the user's: kept even when the floor is touched.
    given = hovering.hovering_area(m, K_low=first.box[2], **kw)
    assert given.floor_touched and given.deepened == 0 and given.box == first.box


def test_deepening_stops_at_the_band_edge():
    # Islands reach the lower edge of this map's band (K = -pi): the box deepens twice, is clipped
    # to the band, and says the band ended first (51 hovering samples in its lowest tenth).
    m = hovering.TruncatedMap(eps=-0.3, Omega0=1.0, theta_w=3 * np.pi / 4, tau0=5.0, lam=0.5)
    hv = hovering.hovering_area(m, n_steps=500, n_samples=2000, components=False)
    lo = m.valid_band()[0]
    assert hv.band_edge and hv.floor_touched and hv.deepened == 2
    assert lo < hv.box[2] and hv.box[2] == pytest.approx(lo, rel=1e-8)


def test_clusters_join_neighbours_and_wrap_in_phi():
    # A 6 x 5 grid (columns = phi cells, rows = K cells); sample i = column * 5 + row.
    g = np.zeros((6, 5), bool)
    g[0, 0] = g[5, 1] = True  # diagonal across the phi seam: one cluster
    g[2, 3] = g[3, 4] = True  # diagonal: one cluster
    g[0, 4] = True  # alone: rows do not wrap (else it would touch g[0, 0])
    g[3, 1] = True  # alone: two cells from every other point
    got = sorted(tuple(c.tolist()) for c in _clusters(g.ravel(), 5))
    assert got == sorted([(0, 26), (13, 19), (4,), (16,)])
    assert _clusters(np.zeros(30, bool), 5) == []


@pytest.fixture(scope="module")
def flow_comparison():
    fm = hovering.FlowMap(paper.system(-0.05), 1.0)
    return fm, hovering.compare_hovering(fm, n_samples=300, n_steps=200)


def test_compare_hovering_counts_match_each_models_own_run(flow_comparison):
    fm, cmp = flow_comparison
    flow = cmp.flow
    assert [v.model for v in cmp.models] == ["onset", "measured"]
    for v, forcing in ((cmp["onset"], "first_mode"), (cmp["measured"], "measured")):
        # The model's own hovering_area on the flow's box and seed draws the same points.
        own = hovering.hovering_area(
            fm.truncated(forcing), n_steps=200, n_samples=300, K_low=flow.box[2], keep_points=True, components=False
        )
        assert np.array_equal(own.phi, flow.phi) and np.array_equal(own.K, flow.K)
        f, mh = flow.hovering, own.hovering
        expected = [[np.sum(~f & ~mh), np.sum(~f & mh)], [np.sum(f & ~mh), np.sum(f & mh)]]
        assert v.confusion.tolist() == expected and v.confusion.sum() == flow.n_samples
        assert v.agreement == pytest.approx(np.mean(f == mh), abs=1e-15)
        assert v.area == own.area
        differ = f != mh
        assert np.array_equal(v.phi, flow.phi[differ]) and np.array_equal(v.flow_hovers, f[differ])
    # The models are models of this flow: they agree on most points (measured 0.99 at 5152 samples).
    assert min(v.agreement for v in cmp.models) > 0.9
    text = repr(cmp)
    assert "onset: agree" in text and "measured: agree" in text and len(text) < 400


def test_flow_under_the_floor():
    # eps = 0.1 on the README system does not hover by eq:hovsetsize (0 for this sign); what hovers
    # lies under the flow's floor: above the eps = 0 torus tangent to the upper wall (F_0 impacts
    # there and only there: K = const at eps = 0) and below the floor curve, never beside the step.
    fm = hovering.FlowMap(paper.system(0.1), 1.0)
    hv = hovering.hovering_area(fm, n_steps=100, n_samples=200, K_low=-0.2, keep_points=True)
    c = hv.components
    assert hv.theory == 0.0 and c.floor == "flow"
    assert c.band + c.islands + c.under_floor == pytest.approx(hv.area, rel=1e-12)
    under = hv.component == UNDER
    assert c.counts["under_floor"] == under.sum() > 10
    assert np.all(hv.K[under] > fm.upper_tangent_K())
    # The floor is searched within 0.05 + 2 |eps| above that torus (FlowMap.impact_zone_floor).
    assert np.max(hv.K[under]) - fm.upper_tangent_K() < 0.05 + 2 * 0.1
    for i in np.flatnonzero(under)[[0, -1]]:  # the lowest and the highest column's first
        hovers, seen = plain_verdict(fm, hv.phi[i], hv.K[i], 100)
        assert hovers and seen == {int(Region.ABOVE)}


def test_a_floor_that_is_not_found_loses_nothing():
    # 50 returns per tested orbit find no floor on this flow (the search raises): the area stands,
    # the one-sided points stay in `islands`, and `floor` says why.
    fm = hovering.FlowMap(paper.system(0.1), 1.0)
    hv = hovering.hovering_area(fm, n_steps=50, n_samples=60, K_low=-0.2)
    c = hv.components
    assert c.floor.startswith("not found: no invariant curve") and c.under_floor == 0.0
    assert hv.area > 0 and c.band + c.islands == pytest.approx(hv.area, rel=1e-12)


def test_save_and_load_keep_the_components(tmp_path, negative_eps):
    _, hv = negative_eps
    hovering.save(hv, tmp_path / "hv")
    back = hovering.load(tmp_path / "hv.npz")
    assert back.components == hv.components and back.deepened == hv.deepened
    assert np.array_equal(back.component, hv.component) and np.array_equal(back.period, hv.period)
    # A file written before the components existed still loads, without them.
    from pathlib import Path

    old = hovering.load(Path(__file__).resolve().parents[1] / "data" / "legacy" / "hovering_area.npz")
    assert old.area > 0 and old.components is None and old.deepened == 0 and old.component is None


def test_save_and_load_a_comparison(tmp_path, flow_comparison):
    _, cmp = flow_comparison
    cmp.save(tmp_path / "cmp")
    back = hovering.load(tmp_path / "cmp.npz")
    assert repr(back) == repr(cmp)
    for a, b in zip(back.models, cmp.models):
        assert np.array_equal(a.confusion, b.confusion) and np.array_equal(a.K, b.K)


def test_bad_input_is_refused_before_any_work(monkeypatch):
    def no_work(*args, **kwargs):
        raise AssertionError("computed before checking the arguments")

    monkeypatch.setattr(hovering_module, "_outcomes", no_work)
    monkeypatch.setattr(hovering_compare, "_outcomes", no_work)
    m = paper.truncated_map(0.2)
    with pytest.raises(ValueError, match="components must be True or False, got 'yes'"):
        hovering.hovering_area(m, components="yes")
    with pytest.raises(ValueError, match=r"deepen must be an integer in \[0, 64\], got -1"):
        hovering.hovering_area(m, deepen=-1)
    fm = hovering.FlowMap(paper.system(-0.05), 1.0)
    with pytest.raises(ValueError, match="flow_map must be a hovering.FlowMap, got TruncatedMap"):
        hovering.compare_hovering(m)
    with pytest.raises(ValueError, match="unknown model 'bogus'; allowed: 'onset', 'measured'"):
        hovering.compare_hovering(fm, models=("onset", "bogus"))
    with pytest.raises(ValueError, match="models must be a sequence"):
        hovering.compare_hovering(fm, models="onset")
    with pytest.raises(ValueError, match="must not repeat"):
        hovering.compare_hovering(fm, models=("onset", "onset"))
    with pytest.raises(ValueError, match=r"n_samples must be an integer in \[1, "):
        hovering.compare_hovering(fm, n_samples=0)
    with pytest.raises(ValueError, match=r"n_steps must be an integer in \[4, "):
        hovering.compare_hovering(fm, n_steps=2)
    section = hovering.FlowMap(paper.system(-0.05), 1.0, coordinates="section")
    with pytest.raises(ValueError, match="coordinates='normal'"):
        hovering.compare_hovering(section)


def test_exported():
    for name in ("compare_hovering", "HoveringComparison", "HoveringComponents", "ModelVerdicts"):
        assert name in hovering.__all__ and name in hovering.analysis.__all__
        assert getattr(hovering, name) is getattr(hovering.analysis, name)
