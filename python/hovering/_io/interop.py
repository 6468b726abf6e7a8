"""Results as xarray Datasets and pandas DataFrames (``to_xarray()``, ``to_pandas()``), for the
analysis users then do with those tools.

Both libraries are optional (``hovering[xarray]``, ``hovering[pandas]``); nothing here is imported
by ``import hovering``. Each result's method calls one function here, and every variable's units
and meaning come from the one table :data:`VARIABLES`. The map's variables are the paper's
dimensionless normal coordinates: the angle ``phi`` (radians) and the height ``K`` (the action
measured from the tangency, dimensionless); the flow's return times are in the system's time unit.
Every dataset's attrs record what made it: the result's type, its key parameters, and
``provenance`` (hovering's version and build, numpy's, the machine: JSON, as in saved results).
"""

from __future__ import annotations

import json

import numpy as np

from .._enums import FlowStatus, Region, Status
from .._extras import require
from .provenance import provenance

__all__ = [
    "VARIABLES",
    "iterate_dataset",
    "return_map_dataset",
    "hovering_area_dataset",
    "critical_curve_dataset",
    "transit_frame",
    "series_frame",
    "series_dataset",
    "flow_sweep_frame",
    "flow_sweep_dataset",
]

_ANGLE = {"units": "rad"}
_HEIGHT = {"units": "1"}
#: Units and meaning of every variable a result exports (CF-style ``units``, ``long_name``).
VARIABLES: dict[str, dict] = {
    "phi": {**_ANGLE, "long_name": "angle phi of the map's normal coordinates"},
    "K": {**_HEIGHT, "long_name": "height K of the map's normal coordinates (action from the tangency)"},
    "phi_final": {**_ANGLE, "long_name": "angle of the last state reached"},
    "K_final": {**_HEIGHT, "long_name": "height of the last state reached"},
    "phi0": {**_ANGLE, "long_name": "start angle"},
    "K0": {**_HEIGHT, "long_name": "start height"},
    "theta": {**_ANGLE, "long_name": "section angle theta (S2 of q2, p2)"},
    "I": {"units": "1", "long_name": "section action I"},
    "rotation": {"units": "rad", "long_name": "rotation number rho: mean of omega_a per step"},
    "status": {"units": "1", "long_name": "per-orbit outcome"},
    "steps_done": {"units": "1", "long_name": "steps (returns) taken"},
    "exit_step": {"units": "1", "long_name": "first step outside exit_regions (-1: never)"},
    "stop_step": {"units": "1", "long_name": "first step in the stop set (-1: never)"},
    "K_min": {**_HEIGHT, "long_name": "least K over the orbit"},
    "K_max": {**_HEIGHT, "long_name": "greatest K over the orbit"},
    "s_min": {"units": "1", "long_name": "least zone coordinate s over the recorded states"},
    "s_max": {"units": "1", "long_name": "greatest zone coordinate s over the recorded states"},
    "visited": {"units": "1", "long_name": "bit r set: a step was taken from Region r"},
    "residence": {"units": "1", "long_name": "returns taken from each region"},
    "region": {"units": "1", "long_name": "region of the point each return was taken from"},
    "time": {"units": "system time unit", "long_name": "return time"},
    "energy_error": {"units": "energy unit of the system", "long_name": "|H - h| of the image before projection"},
    "integrator_steps": {"units": "1", "long_name": "accepted integrator steps of the return"},
    "first_passage": {"units": "1", "long_name": "first step on the target level (-1: never)"},
    "area": {"units": "rad", "long_name": "area |HOV| of the hovering set (phi x K)"},
    "error": {"units": "rad", "long_name": "error bar of the area: 2 sampling_error + iteration_error"},
    "sampling_error": {"units": "rad", "long_name": "one standard deviation of the sampling"},
    "iteration_error": {"units": "rad", "long_name": "change of the area over the last doubling of N"},
    "theory": {"units": "rad", "long_name": "leading-order |HOV| (eq:hovsetsize)"},
    "area_both_sides": {"units": "rad", "long_name": "part of the area whose orbits visit both J_0 and J_0u"},
    "area_at_N": {"units": "rad", "long_name": "area estimate after N iterates"},
    "impact_fraction_F0": {"units": "1", "long_name": "fraction of the box that impacts under F_0"},
    "hovering": {"units": "1", "long_name": "sample point hovers"},
    "both_sides": {"units": "1", "long_name": "sample point's orbit visits both J_0 and J_0u"},
    "eps": {"units": "1", "long_name": "perturbation eps"},
    "K_low": {**_HEIGHT, "long_name": "floor of the sampled box"},
    "Omega0": {"units": "rad", "long_name": "rotation angle Omega0 at the tangency"},
    "theta_w": {"units": "rad", "long_name": "wall angle theta_w"},
    "floor_touched": {"units": "1", "long_name": "a hovering point lies in the lowest tenth of the box"},
    "b1": {"units": "1", "long_name": "first forcing mode b1"},
    "seconds": {"units": "s", "long_name": "wall time of the point"},
    "unresolved": {"units": "1", "long_name": "sample points whose orbit ended otherwise"},
    "step": {"units": "1", "long_name": "step index of the kept state"},
    "return_step": {"units": "1", "long_name": "step index the return was taken from"},
    "K_pred": {**_HEIGHT, "long_name": "leading-order height of the critical curve (eq:kcrit)"},
    "rotation_pred": {"units": "rad", "long_name": "leading-order rotation of the critical curve (eq:rhocrit)"},
    "rotation_mean": {"units": "rad", "long_name": "rho = <omega_a> of the critical orbit"},
    "digits": {"units": "1", "long_name": "regularity of the orbit (digits of the rotation number)"},
    "K_fail": {**_HEIGHT, "long_name": "highest failing start below K0"},
    "jacobian_q": {"units": "1", "long_name": "rotation Q of the product of the steps' Jacobians (M = Q R)"},
    "jacobian_log": {"units": "1", "long_name": "log R_11, log |R_22| of that product (/ steps: Lyapunov exponents)"},
    "jacobian_r12": {"units": "1", "long_name": "R_12 / R_11 of that product"},
    "jacobian_status": {"units": "1", "long_name": "OK, or where the product's derivative was one-sided / not finite"},
}


def _xr(feature: str):
    return require("xarray", feature)


def _attrs(name: str) -> dict:
    return dict(VARIABLES.get(name, {}))


def _flags(attrs: dict, enum) -> dict:
    """CF flag attributes naming an enum's codes."""
    return {
        **attrs,
        "flag_values": np.array([int(e) for e in enum], dtype=np.int64),
        "flag_meanings": " ".join(e.name for e in enum),
    }


def _common(result_type: str, **params) -> dict:
    """The dataset's attrs: the result type, its parameters (JSON-able scalars) and provenance."""
    out = {"source": f"hovering {result_type}", "provenance": json.dumps(provenance(), default=str)}
    for k, v in params.items():
        if v is None:
            continue
        out[k] = v if isinstance(v, (int, float, str)) else str(v)
    return out


def iterate_dataset(res):
    """:meth:`hovering.IterateResult.to_xarray`."""
    xr = _xr("IterateResult.to_xarray()")
    n_states = res.n_steps // res.every + 1
    n_returns = -(-res.n_steps // res.every)
    per_state, per_return, per_orbit = ("orbit", "step"), ("orbit", "return_step"), ("orbit",)
    data = {}

    def put(name, dims, values, attrs=None):
        data[name] = (dims, np.asarray(values), attrs if attrs is not None else _attrs(name))

    for name in ("phi", "K", "theta", "I"):
        a = getattr(res, name)
        if a is not None and np.ndim(a) == 2:
            put(name, per_state, a)
    for name in ("time", "energy_error", "integrator_steps"):
        a = getattr(res, name)
        if a is not None:
            put(name, per_return, a)
    if res.region is not None:
        put("region", per_return, res.region, _flags(_attrs("region"), Region))
    if res.itinerary is not None and len({len(row) for row in res.itinerary}) <= 1:
        put(
            "itinerary",
            per_return,
            np.array(res.itinerary, dtype=str).reshape(len(res.itinerary), -1),
            {"long_name": "impacts of each return ('-': not taken)"},
        )
    for name in (
        "rotation",
        "phi_final",
        "K_final",
        "steps_done",
        "exit_step",
        "stop_step",
        "K_min",
        "K_max",
        "visited",
    ):
        a = getattr(res, name)
        if a is not None:
            put(name, per_orbit, a)
    put("status", per_orbit, res.status, _flags(_attrs("status"), Status))
    coords = {"orbit": np.arange(res.n_orbits)}
    if any(d[0] == per_state for d in data.values()):
        coords["step"] = ("step", np.arange(n_states) * res.every, _attrs("step"))
    if any(d[0] == per_return for d in data.values()):
        coords["return_step"] = ("return_step", np.arange(n_returns) * res.every, _attrs("return_step"))
    if res.residence is not None:
        put("residence", ("orbit", "region_name"), res.residence)
        coords["region_name"] = [r.name for r in Region if r.value >= 0][: res.residence.shape[1]]
    if res.jacobian_q is not None:
        put("jacobian_q", ("orbit", "row", "column"), res.jacobian_q)
        put("jacobian_log", ("orbit", "factor"), res.jacobian_log)
        put("jacobian_r12", per_orbit, res.jacobian_r12)
        put("jacobian_status", per_orbit, res.jacobian_status, _flags(_attrs("jacobian_status"), Status))
        coords["factor"] = ["R_11", "R_22"]
    attrs = _common("IterateResult", n_steps=int(res.n_steps), every=int(res.every), map=repr(res.map))
    return xr.Dataset(data, coords=coords, attrs=attrs)


def return_map_dataset(res):
    """:meth:`hovering.ReturnMapResult.to_xarray`."""
    xr = _xr("ReturnMapResult.to_xarray()")
    n = res.status.shape[0]
    data = {
        "theta": ("start", res.theta, _attrs("theta")),
        "I": ("start", res.I, _attrs("I")),
        "z": (("start", "component"), res.z, {"long_name": "image state (q1, p1, q2, p2)"}),
        "time": ("start", res.time, _attrs("time")),
        "energy_error": ("start", res.energy_error, _attrs("energy_error")),
        "integrator_steps": ("start", res.steps, _attrs("integrator_steps")),
        "status": ("start", res.status, _flags(_attrs("status"), FlowStatus)),
        "itinerary": ("start", np.array(res.itinerary, dtype=str).reshape(n), {"long_name": "impacts in order"}),
    }
    if res.region is not None:
        data["region"] = ("start", res.region, _flags(_attrs("region"), Region))
    coords = {"start": np.arange(n), "component": ["q1", "p1", "q2", "p2"]}
    attrs = _common("ReturnMapResult")
    if res.stepper is not None:  # the stepper that ran (results saved before it was recorded have none)
        attrs["stepper"] = res.stepper
    return xr.Dataset(data, coords=coords, attrs=attrs)


def hovering_area_dataset(h):
    """:meth:`hovering.HoveringArea.to_xarray`."""
    xr = _xr("HoveringArea.to_xarray()")
    data = {
        name: ((), getattr(h, name), _attrs(name))
        for name in (
            "area",
            "error",
            "sampling_error",
            "iteration_error",
            "theory",
            "area_both_sides",
            "impact_fraction_F0",
        )
    }
    steps = sorted(h.areas)
    data["area_at_N"] = ("n_steps", [h.areas[k] for k in steps], _attrs("area_at_N"))
    coords = {"n_steps": ("n_steps", np.asarray(steps, dtype=np.int64), {"long_name": "iterates N"})}
    if h.phi is not None:
        for name in ("phi", "K", "hovering", "both_sides"):
            data[name] = ("sample", getattr(h, name), _attrs(name))
    attrs = _common(
        "HoveringArea",
        n_samples=int(h.n_samples),
        unresolved=int(h.unresolved),
        floor_touched=int(bool(h.floor_touched)),
    )
    attrs["box"] = np.asarray(h.box, dtype=float)  # (phi_lo, phi_hi, K_lo, K_hi)
    return xr.Dataset(data, coords=coords, attrs=attrs)


def critical_curve_dataset(c):
    """:meth:`hovering.CriticalCurve.to_xarray`."""
    xr = _xr("CriticalCurve.to_xarray()")
    data = {
        name: ((), getattr(c, name), _attrs(name))
        for name in ("K0", "K_min", "K_max", "rotation", "rotation_mean", "digits", "K_pred", "rotation_pred", "K_fail")
    }
    data["K0"] = ((), c.K0, {**_HEIGHT, "long_name": "start height of the critical orbit on its search line"})
    data["rotation"] = ((), c.rotation, {"units": "rad", "long_name": "weighted Birkhoff rotation number"})
    data["phi"] = ("point", c.phi, _attrs("phi"))
    data["K"] = ("point", c.K, _attrs("K"))
    attrs = _common("CriticalCurve", line=c.line, hovers=int(bool(c.hovers)), note=c.note)
    return xr.Dataset(data, coords={"point": np.arange(len(c.phi))}, attrs=attrs)


def _pd(feature: str):
    return require("pandas", feature)


def transit_frame(t):
    """:meth:`hovering.TransitResult.to_pandas`."""
    pd = _pd("TransitResult.to_pandas()")
    cols = {
        name: getattr(t, name)
        for name in ("phi0", "K0", "first_passage", "steps_done", "K_min", "K_max", "s_min", "s_max")
    }
    cols["crossed"] = t.crossed
    cols["status"] = pd.Categorical([Status(int(s)).name for s in t.status], categories=[s.name for s in Status])
    for j, r in enumerate(r for r in Region if r.value >= 0):
        if j < t.residence.shape[1]:
            cols[f"residence_{r.name}"] = t.residence[:, j]
    df = pd.DataFrame(cols, index=pd.RangeIndex(len(t.phi0), name="orbit"))
    df.attrs.update(
        direction=t.direction, start_s=t.start_s, target_s=t.target_s, n_steps=int(t.n_steps), every=int(t.every)
    )
    return df


def barrier_frame(b):
    """:meth:`hovering.BarrierScan.to_pandas`: one row per start."""
    pd = _pd("BarrierScan.to_pandas()")
    cols = {
        name: getattr(b, name)
        for name in ("s0", "phi0", "K0", "kind", "period", "rotation", "decided_by", "steps_done", "s_min", "s_max")
    }
    cols["impact_fraction"] = b.impact_fraction
    cols["cone"] = b.cone
    cols["status"] = pd.Categorical([Status(int(s)).name for s in b.status], categories=[s.name for s in Status])
    # the cut above each start (none above the last)
    cols["barrier_above"] = np.append(b.barrier, False)
    cols["margin_above"] = np.append(b.margin, np.nan)
    df = pd.DataFrame(cols, index=pd.RangeIndex(len(b.s0), name="start"))
    df.attrs.update(line=b.line, n_steps=int(b.n_steps), n_bins=int(b.n_bins), complete=bool(b.complete))
    return df


_SERIES_COLUMNS = ("area", "error", "theory", "floor_touched", "K_low", "Omega0", "theta_w")


def series_frame(result):
    """:meth:`hovering.scenes.HoveringAreaResult.to_pandas`: one row per (series, eps)."""
    pd = _pd("HoveringAreaResult.to_pandas()")
    frames = []
    for s in result.series:
        cols = {"series": s.label, "eps": s.eps, **{c: getattr(s, c) for c in _SERIES_COLUMNS}}
        frames.append(pd.DataFrame(cols))
    df = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(columns=["series", "eps", *_SERIES_COLUMNS])
    df = df.set_index(["series", "eps"])
    df.attrs.update(scene=result.scene.name, kind=result.scene.kind)
    return df


def series_dataset(result):
    """:meth:`hovering.scenes.HoveringAreaResult.to_xarray`: dims ``series`` x ``eps``."""
    xr = _xr("HoveringAreaResult.to_xarray()")
    df = series_frame(result)
    ds = xr.Dataset.from_dataframe(df)
    for name in ds.data_vars:
        ds[name].attrs.update(_attrs(name))
    ds["eps"].attrs.update(_attrs("eps"))
    ds.attrs.update(_common("HoveringAreaResult", scene=result.scene.name, kind=result.scene.kind))
    return ds


def flow_sweep_frame(result):
    """:meth:`hovering.scenes.FlowHoveringResult.to_pandas`: one row per eps."""
    pd = _pd("FlowHoveringResult.to_pandas()")
    cols = {
        name: getattr(result, name)
        for name in ("flow_area", "flow_error", "flow_both_sides", "theory", "K_low", "b1", "seconds", "unresolved")
        if getattr(result, name) is not None
    }
    for model, d in result.models.items():
        for k, v in d.items():
            cols[f"{model}_{k}"] = v
    df = pd.DataFrame(cols, index=pd.Index(np.asarray(result.eps, dtype=float), name="eps"))
    df.attrs.update(scene=result.scene.name, kind=result.scene.kind)
    return df


def flow_sweep_dataset(result):
    """:meth:`hovering.scenes.FlowHoveringResult.to_xarray`: dim ``eps``, and ``model`` for the models."""
    xr = _xr("FlowHoveringResult.to_xarray()")
    eps = np.asarray(result.eps, dtype=float)
    data = {}
    for name in ("flow_area", "flow_error", "flow_both_sides", "theory", "K_low", "b1", "seconds", "unresolved"):
        a = getattr(result, name)
        if a is not None:
            base = name[5:] if name.startswith("flow_") else name
            base = {"both_sides": "area_both_sides"}.get(base, base)
            data[name] = ("eps", np.asarray(a), _attrs(base))
    models = list(result.models)
    coords = {"eps": ("eps", eps, _attrs("eps"))}
    if models:
        coords["model"] = models
        for k in result.models[models[0]]:
            data[f"model_{k}"] = (
                ("model", "eps"),
                np.stack([np.asarray(result.models[m][k]) for m in models]),
                _attrs(k) or {"long_name": f"model {k}"},
            )
    attrs = _common("FlowHoveringResult", scene=result.scene.name, kind=result.scene.kind)
    return xr.Dataset(data, coords=coords, attrs=attrs)
