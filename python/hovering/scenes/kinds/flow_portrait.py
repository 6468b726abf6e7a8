"""The ``flow_portrait`` kind: the full return map of the flow and its truncated model side by side,
from the same starts on the flow's L1, coloured by region, with the measured corner-singularity
curves of the flow and the model's closed forms.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._enums import Status
from ..._io.serial import saved_as
from ..._style import orbit_color
from ...diagnostics.work_precision import _reverse
from ..base import Geometry, OrbitSet, SceneResult, fmt, orbit_rows, region_counts
from ..fields import choice, integer, pair, real
from ..registry import Kind, register
from ._flow import FlowScene, flow_geometry, flowmap, needs_step, work
from ._truncated import auto_ylim, map_geometry

__all__ = ["FlowPortraitScene", "FlowPortraitResult", "compute", "summarize", "report", "KIND"]


@saved_as("hovering.scenes.spec:FlowPortraitScene")
@dataclass(frozen=True, kw_only=True)
class FlowPortraitScene(FlowScene):
    """``flow_portrait``: the full return map and its truncated model side by side.

    Attributes
    ----------
    n_steps : int
        Returns per orbit (the same count of truncated-map steps).
    n_orbits : int
        Orbits started on the flow's L1.
    K0_range : tuple of float
        Their initial heights.
    model : {"measured", "first_mode"}
        The truncated model: onset arcs with the measured forcing, or its first mode (F_eps).
    corner_K : int
        Circles on which the flow's corner-singularity curves are measured (0: not drawn).
    marker_size : float
        Scatter marker size.
    """

    n_steps: int = integer(lo=1, hi=1_000_000)
    n_orbits: int = integer(12, lo=1, hi=1000)
    K0_range: tuple = pair((-0.1, 0.05))
    model: str = choice("measured", ("measured", "first_mode"))
    corner_K: int = integer(12, lo=0, hi=200)
    marker_size: float = real(0.5, lo=0.0, hi=100.0, lo_open=True)


@saved_as("hovering.scenes.results:FlowPortraitResult")
@dataclass(repr=False)
class FlowPortraitResult(SceneResult):
    """Result of a ``flow_portrait`` scene: the same starts under the flow and its model.

    Attributes
    ----------
    flow, model : OrbitSet
        The flow's orbits (FlowMap) and the truncated model's.
    flow_geometry, model_geometry : Geometry
        Measured corner curves and lines of the flow; closed forms of the model.
    onset : dict
        The onset parameters (Omega0, theta_w, tau0, tau1, lam).
    forcing : ndarray
        Sine coefficients of the measured forcing f.
    model_name : str
        ``"measured"`` or ``"first_mode"``.
    work : dict
        The flow's work counters, when the core reports them.
    """

    flow: OrbitSet = None
    model: OrbitSet = None
    flow_geometry: Geometry = None
    model_geometry: Geometry = None
    onset: dict = field(default_factory=dict)
    forcing: np.ndarray = None
    model_name: str = "measured"
    work: dict = field(default_factory=dict)


def compute(scene: FlowPortraitScene, ctx) -> FlowPortraitResult:
    """The flow's orbits, a time-reversal check of their accuracy, the model's orbits from the same
    starts, and the lines of both.

    Parameters
    ----------
    scene : FlowPortraitScene
        The scene.
    ctx : hovering.scenes.base.Context
        Quick run, progress, meta.

    Returns
    -------
    FlowPortraitResult
    """
    meta = ctx.meta
    n = ctx.scaled(scene.n_steps, floor=50)
    meta["n_steps"] = n
    stages = ctx.stages(5)
    stages.start("setup", f"flow map (tangential curve, forcing) and its {scene.model} model")
    fm = flowmap(scene)
    tm = fm.truncated(forcing=scene.model)
    stages.end()
    K0 = np.linspace(scene.K0_range[0], scene.K0_range[1], scene.n_orbits)
    try:  # the band is the flow map's (known once it is built): name the scene's key in the refusal
        phi0 = np.asarray(fm.L1(K0), dtype=float)
    except ValueError as e:
        raise ValueError(f"K0_range = {list(scene.K0_range)}: {e}") from None
    regions = "regions" in scene.outputs.record
    record = ("orbit", "regions") if regions else ("orbit",)
    labels = [f"K0={k:.4g}" for k in K0]
    colors = [orbit_color(i) for i in range(scene.n_orbits)]
    stages.start("flow", f"{scene.n_orbits} orbits x {n} returns")
    fres = fm.iterate(phi0, K0, n, record=record, **ctx.progress_kw)
    stages.end()
    stages.start("reversal check", f"2 orbits x {min(n, 1000)} returns back")
    meta["accuracy"] = _reversal_check(fm, fres, min(n, 1000))
    stages.end()
    stages.start("model", f"{scene.n_orbits} orbits x {n} steps")
    mres = tm.iterate(phi0, K0, n, record=record)
    stages.end()
    flow = OrbitSet.of(fres, labels, colors, ["fan"] * len(labels))
    model = OrbitSet.of(mres, labels, colors, ["fan"] * len(labels))
    floor = max(fm.valid_band()[0], tm.valid_band()[0])
    lo = min(auto_ylim(flow.K, floor)[0], auto_ylim(model.K, floor)[0])
    hi = max(auto_ylim(flow.K, floor)[1], auto_ylim(model.K, floor)[1])
    stages.start("corner curves", f"{scene.corner_K} circles")
    fg = flow_geometry(fm, (lo, hi), scene.corner_K, fm.integrator_options["rtol"])
    stages.end()
    mg = map_geometry(tm, (lo, hi), corner_curves=scene.corner_K > 0)
    p = fm.onset
    onset = dict(Omega0=p.Omega0, theta_w=p.theta_w, tau0=p.tau0, tau1=p.tau1, lam=p.lam)
    return FlowPortraitResult(
        scene=scene,
        meta=meta,
        flow=flow,
        model=model,
        flow_geometry=fg,
        model_geometry=mg,
        onset=onset,
        forcing=np.asarray(fm.forcing_coefficients()),
        model_name=scene.model,
        work=work(fres),
    )


def _reversal_check(fm, res, m: int, n_orbits: int = 2) -> dict:
    """How far the integration carried the portrait's orbits: the first ``n_orbits`` that ran m
    returns are run m returns back by time reversal from their m-th point; the distance to their
    start (phi, K) is the reversal error. It needs no reference, and like the error it grows as
    m^2 with the number of returns (``hovering.work_precision``)."""
    ok = np.flatnonzero(res.steps_done >= m)[:n_orbits]
    out = {
        "integrator": {k: v for k, v in fm.integrator_options.items()},
        "reversal_returns": int(m),
        "reversal_orbits": int(ok.size),
        "reversal_error": float("nan"),
    }
    if ok.size and m > 0:
        bt, bk, alive = _reverse(fm, res.phi[ok, m], res.K[ok, m], m, 0)
        d = np.maximum(np.abs((bt - res.phi[ok, 0] + np.pi) % (2 * np.pi) - np.pi), np.abs(bk - res.K[ok, 0]))
        out["reversal_error"] = float(np.max(d[alive])) if alive.any() else float("nan")
    if fm.accuracy_choice is not None:
        out["accuracy_target"] = {k: fm.accuracy_choice[k] for k in ("error", "seconds", "returns")}
    return out


def summarize(result: FlowPortraitResult) -> dict:
    """The onset parameters, the forcing's first modes, and each map's orbits, regions and statuses.

    Parameters
    ----------
    result : FlowPortraitResult
        The result.

    Returns
    -------
    dict
        ``onset``, ``forcing``, ``model_name``, ``work``, ``flow``, ``model``.
    """
    s = dict(onset=result.onset, forcing=result.forcing[:3], model_name=result.model_name, work=result.work)
    for name, o in (("flow", result.flow), ("model", result.model)):
        s[name] = dict(
            orbits=orbit_rows(o),
            regions=region_counts(o.region),
            statuses={Status(int(v)).name: int(np.count_nonzero(o.status == v)) for v in np.unique(o.status)},
        )
    return s


def report(summary: dict) -> list:
    """The onset line, then one line per map: orbits, hovering ones, regions, statuses.

    Parameters
    ----------
    summary : dict
        From :func:`summarize` (with the common numbers).

    Returns
    -------
    list of str
    """
    f, o = fmt, summary["onset"]
    lines = [
        f"  onset: Omega0 = {f(o['Omega0'], '.5f')}, theta_w = {f(o['theta_w'], '.5f')}, "
        f"tau0 = {f(o['tau0'], '.4f')}, tau1 = {f(o['tau1'], '.4f')}, lam = {f(o['lam'], '.4f')}; "
        f"model: {summary['model_name']} forcing"
    ]
    for name in ("flow", "model"):
        d = summary[name]
        hov = sum(1 for x in d["orbits"] if x.get("hovering"))
        lines.append(
            f"  {name:>5}: {len(d['orbits'])} orbits, {hov} hovering, regions {d['regions']}, statuses {d['statuses']}"
        )
    return lines


KIND = register(
    Kind(
        "flow_portrait",
        FlowPortraitScene,
        FlowPortraitResult,
        compute,
        summarize,
        report,
        doc="the flow's return map beside its truncated model, from the same starts",
        figsize=(13.0, 5.6),
        records=(("regions",), ()),
        check=needs_step,
        scene_map=flowmap,
    )
)
