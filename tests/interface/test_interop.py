"""Results in a notebook and in the scientific Python stack (issue 21, items 4 and 5): short reprs
and HTML tables with the key numbers (never whole arrays), ``to_xarray()`` with named dimensions
and coordinates, units and provenance, ``to_pandas()`` for the tables. Each round trip compares
the exported values with the result's own arrays exactly (an export copies, it computes nothing)
and checks the labels against an independent count (the residence columns against the region
record), so a mislabelled axis fails.
"""

from __future__ import annotations

import json
import pathlib

import numpy as np
import pytest

import hovering
from hovering import Region, Status, paper
from hovering.scenes import load_scene
from hovering.scenes.results import FlowHoveringResult, HoveringAreaResult, SeriesResult

xr = pytest.importorskip("xarray")  # an extra: the test extra installs it (tests/package/test_extras.py)
pd = pytest.importorskip("pandas")

SCENES = pathlib.Path(__file__).resolve().parents[2] / "examples" / "scenes"


@pytest.fixture(scope="module")
def m():
    return paper.truncated_map(0.3)


@pytest.fixture(scope="module")
def res(m):
    # every=3: the coordinates must be the step indices 0, 3, 6, ..., not positions
    phi0, K0 = np.linspace(-2, 2, 40), np.full(40, -0.15)
    return m.iterate(
        phi0,
        K0,
        300,
        record=("orbit", "regions", "rotation", "extrema", "residence", "visited"),
        every=3,
        exit_regions=("0", "0u"),
    )


def _provenance_ok(attrs):
    rec = json.loads(attrs["provenance"])
    assert rec["hovering"] == hovering.__version__ and rec["numpy"] == np.__version__


def test_iterate_result_to_xarray_round_trip(res):
    ds = res.to_xarray()
    assert dict(ds.sizes) == {"orbit": 40, "step": 101, "return_step": 100, "region_name": 5}
    assert ds.phi.dims == ("orbit", "step") and ds.region.dims == ("orbit", "return_step")
    np.testing.assert_array_equal(ds.step.values, np.arange(101) * 3)
    np.testing.assert_array_equal(ds.return_step.values, np.arange(100) * 3)
    for name in ("phi", "K", "region", "rotation", "phi_final", "K_final", "status", "steps_done", "K_min", "K_max"):
        np.testing.assert_array_equal(ds[name].values, getattr(res, name), err_msg=name)
    # the state at step 30 is column 10 of the thinned orbit
    np.testing.assert_array_equal(ds.K.sel(step=30).values, res.K[:, 10])
    # residence labelled by region: its ABOVE column counts the returns taken from ABOVE, which a
    # run with every=1 records one by one (an independent count of the same thing)
    full = res.map.iterate(res.phi[:, 0], res.K[:, 0], 300, record=("regions",), exit_regions=("0", "0u"))
    for r in ("BESIDE", "ABOVE"):
        np.testing.assert_array_equal(
            ds.residence.sel(region_name=r).values, np.sum(full.region == Region[r], axis=1), err_msg=r
        )
    assert ds.phi.attrs["units"] == "rad" and "height K" in ds.K.attrs["long_name"]
    names = ds.status.attrs["flag_meanings"].split()
    assert names[list(ds.status.attrs["flag_values"]).index(int(Status.ESCAPED))] == "ESCAPED"
    assert ds.attrs["n_steps"] == 300 and ds.attrs["every"] == 3 and ds.attrs["map"] == repr(res.map)
    _provenance_ok(ds.attrs)


def test_hovering_area_to_xarray_round_trip(m):
    h = hovering.hovering_area(m, n_steps=200, n_samples=400, keep_points=True)
    ds = h.to_xarray()
    for name in ("area", "error", "sampling_error", "iteration_error", "theory", "area_both_sides"):
        assert float(ds[name]) == getattr(h, name), name
    assert list(ds.n_steps.values) == sorted(h.areas)
    assert all(float(ds.area_at_N.sel(n_steps=n)) == a for n, a in h.areas.items())
    assert ds.phi.dims == ("sample",) and ds.sizes["sample"] == h.n_samples
    np.testing.assert_array_equal(ds.hovering.values, h.hovering)
    # the stratified estimate is the hovering fraction of the box times its area
    lo, hi, K_lo, K_hi = ds.attrs["box"]
    assert (lo, hi, K_lo, K_hi) == h.box
    assert ds.attrs["n_samples"] == h.n_samples and ds.area.attrs["units"] == "rad"
    _provenance_ok(ds.attrs)


def test_critical_curve_and_return_map_to_xarray(m):
    c = hovering.critical_curve(m, n_steps=600, n_grid=16)
    ds = c.to_xarray()
    np.testing.assert_array_equal(ds.phi.values, c.phi)
    np.testing.assert_array_equal(ds.K.values, c.K)
    assert ds.phi.dims == ("point",) and float(ds.K0) == c.K0 and float(ds.K_pred) == c.K_pred
    assert float(ds.K.min()) == c.K_min  # the orbit's lowest point is the curve's K_min
    assert ds.attrs["line"] == c.line and ds.attrs["hovers"] == int(c.hovers)

    sec = paper.section(-0.1)
    rm = sec.return_map([0.1, 0.2, 0.3], [0.3, 0.3, 0.3])
    ds = rm.to_xarray()
    np.testing.assert_array_equal(ds.z.sel(component="q2").values, rm.z[:, 2])
    np.testing.assert_array_equal(ds.time.values, rm.time)
    assert list(ds.itinerary.values) == list(rm.itinerary)
    assert ds.status.attrs["flag_meanings"].split()[0] == "OK"
    _provenance_ok(ds.attrs)


def test_transit_to_pandas_is_one_row_per_orbit(m):
    zone = hovering.impact_zone(m)
    t = hovering.transit(m, zone, "up", n_orbits=30, n_steps=300)
    df = t.to_pandas()
    assert len(df) == 30 and df.index.name == "orbit"
    np.testing.assert_array_equal(df.first_passage.values, t.first_passage)
    np.testing.assert_array_equal(df.crossed.values, t.first_passage >= 0)
    assert list(df.status.astype(str)) == [Status(int(s)).name for s in t.status]
    np.testing.assert_array_equal(df.residence_ABOVE.values, t.residence[:, int(Region.ABOVE)])
    assert df.attrs["direction"] == "up" and df.attrs["n_steps"] == 300


def _series(label, eps, offset):
    eps = np.asarray(eps, dtype=float)
    z = np.zeros_like(eps)
    return SeriesResult(
        label=label,
        color="C0",
        eps=eps,
        area=eps + offset,
        error=0.01 + z,
        theory=eps * 2,
        floor_touched=z > 1,
        K_low=-1 + z,
        Omega0=3.0 + z,
        theta_w=2.0 + z,
        theory_eps=eps,
        theory_curve=eps * 2,
    )


def test_hovering_sweep_to_pandas_and_to_xarray():
    scene = load_scene(SCENES / "fig_hov_vs_eps.toml", check_output=False)
    # two series on different eps grids: the dataset is NaN where a series has no point
    r = HoveringAreaResult(
        scene=scene, meta={"version": "x"}, series=[_series("a", [0.1, 0.2], 1.0), _series("b", [0.2, 0.3], 2.0)]
    )
    df = r.to_pandas()
    assert df.index.names == ["series", "eps"] and len(df) == 4
    assert df.loc[("b", 0.3), "area"] == 2.3 and df.loc[("a", 0.1), "theory"] == 0.2
    ds = r.to_xarray()
    assert ds.area.dims == ("series", "eps") and list(ds.eps.values) == [0.1, 0.2, 0.3]
    assert float(ds.area.sel(series="a", eps=0.2)) == 1.2 and np.isnan(float(ds.area.sel(series="a", eps=0.3)))
    assert ds.area.attrs["units"] == "rad" and ds.attrs["scene"] == scene.name
    _provenance_ok(ds.attrs)
    assert scene.name in repr(r) and "points=4" in repr(r)


def test_flow_sweep_to_pandas_and_to_xarray():
    scene = load_scene(SCENES / "flow_hov_vs_eps.toml", check_output=False)
    eps = np.array([-0.1, 0.1, 0.2])
    models = {
        "measured": {"area": eps + 1, "error": eps * 0 + 0.1, "agree": eps * 0 + 0.9},
        "first_mode": {"area": eps + 2, "error": eps * 0 + 0.2, "agree": eps * 0 + 0.8},
    }
    r = FlowHoveringResult(
        scene=scene,
        meta={},
        eps=eps,
        flow_area=eps * 3,
        flow_error=eps * 0 + 0.05,
        flow_both_sides=eps,
        models=models,
        theory=eps * 4,
        K_low=eps - 1,
        b1=eps * 0 + 0.5,
        seconds=eps * 0 + 1,
        unresolved=np.zeros(3, dtype=int),
    )
    df = r.to_pandas()
    assert df.index.name == "eps" and list(df.index) == list(eps)
    np.testing.assert_array_equal(df.first_mode_area.values, eps + 2)
    ds = r.to_xarray()
    assert ds.model_area.dims == ("model", "eps") and list(ds.model.values) == ["measured", "first_mode"]
    np.testing.assert_array_equal(ds.model_agree.sel(model="first_mode").values, models["first_mode"]["agree"])
    np.testing.assert_array_equal(ds.flow_area.values, eps * 3)
    assert ds.eps.attrs["long_name"] == "perturbation eps"
    _provenance_ok(ds.attrs)


def test_reprs_are_short_and_name_the_key_numbers(m):
    big = m.iterate(np.linspace(-3, 3, 100_000), np.full(100_000, -0.2), 20, record=("orbit",))
    text = repr(big)
    assert len(text) < 400 and "n_orbits=100000" in text and "n_steps=20" in text
    counts = {s.name: big.count(s) for s in Status if big.count(s)}
    assert "status={" + ", ".join(f"{k}: {v}" for k, v in counts.items()) + "}" in text
    html = big._repr_html_()
    assert html.startswith("<table>") and "IterateResult" in html and len(html) < 2000
    h = hovering.hovering_area(m, n_steps=100, n_samples=200)
    assert f"area={h.area:.6g}" in repr(h) and "n_samples=" in repr(h) and "<td" in h._repr_html_()
    c = hovering.critical_curve(m, n_steps=400, n_grid=8)
    assert f"K0={c.K0:.6g}" in repr(c) and len(repr(c)) < 400
