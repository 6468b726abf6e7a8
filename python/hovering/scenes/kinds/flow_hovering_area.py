"""The ``flow_hovering_area`` kind: |HOV| against eps for the flow, its truncated models (onset arcs;
arcs measured on the flow) and eq:hovsetsize, both signs of eps, with error bars. A sweep: each eps
a point of the plan, checkpointed, resumable, runnable by ``hovering_sweep``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from ..._core.analysis import box_floor
from ..._io.serial import saved_as
from ..._progress import progress_bar
from ...analysis.hovering import default_K_low
from ...normal.compare import truncated_from_flow
from ...normal.corners import corner_curves
from ...parallel.checkpoint import Checkpoint
from ..base import SceneResult, fmt
from ..fields import choice_list, distinct_reals, integer
from ..plan import build_system, sweep_counts, system_record
from ..registry import Kind, register
from ._flow import FlowScene, flowmap, needs_step
from ._sweep import sweep, sweep_size

__all__ = ["FlowHoveringScene", "FlowHoveringResult", "plan", "compute", "summarize", "report", "KIND"]


@saved_as("hovering.scenes.spec:FlowHoveringScene")
@dataclass(frozen=True, kw_only=True)
class FlowHoveringScene(FlowScene):
    """``flow_hovering_area``: |HOV| against eps for the flow, its models and eq:hovsetsize.

    Attributes
    ----------
    n_steps : int
        Returns (and model steps) of "never impacts".
    eps : tuple of float
        The eps values (``system.eps`` is replaced by each).
    samples : int
        Sample points per eps (the same points for the flow and the models).
    seed : int
        Sampling seed.
    models : tuple of str
        Truncated models drawn: ``"onset"`` (onset arcs, measured forcing: ``FlowMap.truncated()``)
        and ``"measured"`` (arcs measured on the flow's corner curves,
        :func:`hovering.truncated_from_flow`).
    """

    n_steps: int = integer(lo=1, hi=1_000_000)
    eps: tuple = distinct_reals((), lo=-1.0, hi=1.0, required=True)
    samples: int = integer(1000, lo=16, hi=10_000_000)
    seed: int = integer(0, lo=0, hi=2**63 - 1)
    models: tuple = choice_list(("onset", "measured"), ("onset", "measured"))


@saved_as("hovering.scenes.results:FlowHoveringResult")
@dataclass(repr=False)
class FlowHoveringResult(SceneResult):
    """Result of a ``flow_hovering_area`` scene (one row per eps).

    Attributes
    ----------
    eps : ndarray
        The eps values.
    flow_area, flow_error, flow_both_sides : ndarray
        |HOV| of the flow, its error bar, and the part whose orbits visit both J_0 and J_0u.
    models : dict
        Model name -> ``{"area": ndarray, "error": ndarray, "agree": ndarray}`` (agree: fraction
        of the sample points with the flow's verdict).
    theory : ndarray
        eq:hovsetsize with the measured first forcing mode (0 on the sign that does not hover).
    K_low, b1, seconds, unresolved : ndarray
        Box floor, first forcing mode, the flow's seconds, its unresolved points.
    """

    eps: np.ndarray = None
    flow_area: np.ndarray = None
    flow_error: np.ndarray = None
    flow_both_sides: np.ndarray = None
    models: dict = field(default_factory=dict)
    theory: np.ndarray = None
    K_low: np.ndarray = None
    b1: np.ndarray = None
    seconds: np.ndarray = None
    unresolved: np.ndarray = None
    reused: int = 0

    def _summary(self) -> list:
        out = super()._summary() + [("eps", self.eps), ("models", list(self.models))]
        if self.flow_area is not None and len(self.flow_area):
            out.append(("flow_area", f"{np.nanmin(self.flow_area):.4g}..{np.nanmax(self.flow_area):.4g}"))
        return out

    def to_pandas(self):
        """The sweep as a :class:`pandas.DataFrame` (needs ``hovering[pandas]``): one row per eps
        (the index); the flow's columns (``flow_area``, ``flow_error``, ``flow_both_sides``,
        ``theory``, ``K_low``, ``b1``, ``seconds``, ``unresolved``) and ``{model}_{area, error,
        agree}`` for each model.

        Returns
        -------
        pandas.DataFrame

        Raises
        ------
        ImportError
            Without pandas, naming ``pip install pandas`` and the extra ``.[pandas]``.
        """
        from ..._io.interop import flow_sweep_frame

        return flow_sweep_frame(self)

    def to_xarray(self):
        """The sweep as an :class:`xarray.Dataset` (needs ``hovering[xarray]``): the flow's
        columns over dimension ``eps``, each model's ``area``, ``error``, ``agree`` as
        ``model_area`` ... over (``model``, ``eps``); units, the scene and provenance in attrs.

        Returns
        -------
        xarray.Dataset

        Raises
        ------
        ImportError
            Without xarray, naming ``pip install xarray`` and the extra ``.[xarray]``.
        """
        from ..._io.interop import flow_sweep_dataset

        return flow_sweep_dataset(self)


# ------------------------------------------------------------------------------------------------
# The plan: each eps a point, with the flow's box and the models as tables


def _model(name: str, tm, K_low: float) -> dict:
    rec = tm._to_record()
    out = {"name": name, "K_low": float(K_low), "eps": float(rec["eps"])}
    for k in ("K", "Omega", "JR", "J1", "forcing"):
        out[k] = [float(x) for x in np.asarray(rec[k], dtype=float)]
    out["K_max"] = float(rec["K_max"])
    return out


def _measured_model(fm, K_low: float):
    """The truncated family with arcs measured on the flow's corner curves (and measured forcing).

    Circles below the flow's impact zone (eps > 0: under the deformed torus tangent to the upper
    wall, :func:`hovering.impact_zone_floor`) hold no J_1 / J_R arcs: the family then stops at the
    lowest circle that has them, and its band is shallower than the box asked for.
    """
    depth = min(-1.05 * K_low, -0.95 * fm.valid_band()[0])  # circles with a point of Sigma_h only
    s = np.linspace(math.sqrt(depth), 0.0, 17)[:-1]
    K = np.concatenate([-(s**2), [0.01, 0.03, 0.05]])
    cc = corner_curves(fm.section, K, fm.curve, n_phi=256, bisections=30, rtol=1e-12)
    ok = (K > 0) | (np.isfinite(cc.JR) & np.isfinite(cc.J1) & np.isfinite(cc.Omega))
    first = int(np.argmax(np.cumprod(ok[::-1])[::-1])) if not ok.all() else 0
    keep = np.zeros(K.size, bool)
    keep[first:] = True
    keep &= ok
    if not keep.all():
        cc = dataclasses.replace(
            cc,
            **{
                f: getattr(cc, f)[keep]
                for f in ("K", "phi_R0", "phi_01", "phi_1R", "JR", "J0", "J1", "Omega", "Omega_spread", "other")
            },
        )
    return truncated_from_flow(cc, fm.eps, forcing=tuple(fm.forcing_coefficients()))


def _flow_point(scene: FlowHoveringScene, e: float, n_steps: int, samples: int) -> dict:
    system = system_record(scene.system, e)
    fm = scene.integrator.flow_map(build_system(system), scene.h)
    o = fm.integrator_options  # what an accuracy target chose, or the scene's setting
    integrator = {"stepper": o["stepper"], "rtol": float(o["rtol"]), "atol": float(o["atol"])}
    # Every other option explicit too (a plan holds no default): the map's own (the scene's).
    integrator.update(scene.integrator.events())
    # One box for flow and models, so the same points are classified by each: the default depth
    # (the critical band of eq:hovsetsize), cut to the band every model is defined on.
    deep = default_K_low(fm, -math.inf)  # hovering_area's default box, before a band cuts it
    tms = {name: (fm.truncated() if name == "onset" else _measured_model(fm, deep)) for name in scene.models}
    K_low = default_K_low(fm)
    if "onset" in tms:
        K_low = max(K_low, box_floor(tms["onset"].valid_band()[0]))
    # A model whose band is shallower than the box (measured arcs stop at the impact zone's floor)
    # samples its own box: its points are not the flow's.
    models = [_model(name, tm, max(K_low, box_floor(tm.valid_band()[0]))) for name, tm in tms.items()]
    th = fm.theory()
    return {
        "n_steps": int(n_steps),
        "samples": int(samples),
        "seed": int(scene.seed),
        "K_low": float(K_low),
        "theory": float(th.area),
        "b1": float(th.forcing[0]),
        "h": float(scene.h),
        "system": system,
        "integrator": integrator,
        "models": models,
    }


def plan(scene: FlowHoveringScene, quick: bool = False) -> list:
    """The resolved points of the sweep: one per eps, with the integrator an accuracy target picks,
    the box shared by flow and models, the models' tables and the theory (:mod:`hovering.scenes.plan`).

    Parameters
    ----------
    scene : FlowHoveringScene
        The scene.
    quick : bool, optional
        A quick run's counts.

    Returns
    -------
    list of dict
    """
    n_steps, samples = sweep_counts(scene, quick)
    return [_flow_point(scene, e, n_steps, samples) for e in scene.eps]


def compute(scene: FlowHoveringScene, ctx) -> FlowHoveringResult:
    """Measure every eps of the plan (or read it from the checkpoint): the flow and each model on
    the same points.

    Parameters
    ----------
    scene : FlowHoveringScene
        The scene.
    ctx : hovering.scenes.base.Context
        Quick run, progress, meta, checkpoint and executor.

    Returns
    -------
    FlowHoveringResult
    """
    meta, progress, where = ctx.meta, ctx.progress, ctx.executor
    points = plan(scene, ctx.quick)
    meta.update(n_steps=points[0]["n_steps"], samples=points[0]["samples"])
    ckpt = Checkpoint(ctx.checkpoint)
    meta["checkpoint"] = str(ckpt.path)
    stages = ctx.stages(1)
    stages.start("sweep", sweep_size(points, where))
    with progress_bar(progress, total=len(points), desc=scene.name, unit="eps") as bar:
        rows, from_ckpt = sweep(scene.kind, points, ckpt, bar, where, scene.name)
    stages.end()
    reused = sum(from_ckpt)
    col = lambda c: np.array([r[c] for r in rows], dtype=float)  # noqa: E731
    models = {
        name: {
            k: np.array([r["models"][name][k] for r in rows], dtype=float) for k in ("area", "error", "agree", "K_low")
        }
        for name in scene.models
    }
    meta["points_reused"] = reused
    return FlowHoveringResult(
        scene=scene,
        meta=meta,
        eps=np.array([p["system"]["eps"] for p in points], dtype=float),
        flow_area=col("area"),
        flow_error=col("error"),
        flow_both_sides=col("area_both_sides"),
        models=models,
        theory=col("theory"),
        K_low=col("K_low"),
        b1=col("b1"),
        seconds=col("seconds"),
        unresolved=col("unresolved"),
        reused=reused,
    )


def summarize(result: FlowHoveringResult) -> dict:
    """One row per eps: the flow's area, error, both-sides part, theory, box, b1, time, and each model's.

    Parameters
    ----------
    result : FlowHoveringResult
        The result.

    Returns
    -------
    dict
        ``points``.
    """
    pts = []
    for i, e in enumerate(result.eps):
        d = dict(
            eps=float(e),
            flow=float(result.flow_area[i]),
            flow_error=float(result.flow_error[i]),
            flow_both_sides=float(result.flow_both_sides[i]),
            theory=float(result.theory[i]),
            K_low=float(result.K_low[i]),
            b1=float(result.b1[i]),
            seconds=float(result.seconds[i]),
            unresolved=int(result.unresolved[i]),
        )
        d["models"] = {m: {k: float(v[i]) for k, v in cols.items()} for m, cols in result.models.items()}
        pts.append(d)
    return {"points": pts}


def report(summary: dict) -> list:
    """One line per eps: the flow's |HOV|, each model's and the theory.

    Parameters
    ----------
    summary : dict
        From :func:`summarize` (with the common numbers).

    Returns
    -------
    list of str
    """
    f, lines = fmt, []
    for r in summary["points"]:
        mod = ", ".join(
            f"{m} {f(v['area'], '.4f')} +- {f(v['error'], '.4f')} "
            + (
                f"(agree {f(100 * v['agree'], '.1f')}%)"
                if v.get("agree") is not None
                else f"(own box from K = {f(v.get('K_low'), '.4f')}: its band ends there)"
            )
            for m, v in r["models"].items()
        )
        lines.append(
            f"  eps = {f(r['eps'], '+.3f')}: flow |HOV| = {f(r['flow'], '.4f')} "
            f"+- {f(r['flow_error'], '.4f')} "
            f"[both sides {f(r['flow_both_sides'], '.4f')}], {mod}, eq:hovsetsize {f(r['theory'], '.4f')} "
            f"({f(r['seconds'], '.1f')} s)"
        )
    return lines


KIND = register(
    Kind(
        "flow_hovering_area",
        FlowHoveringScene,
        FlowHoveringResult,
        compute,
        summarize,
        report,
        doc="|HOV| against eps for the flow, its truncated models and eq:hovsetsize",
        figsize=(13.0, 5.2),
        records=(("regions",), ("regions",)),
        check=needs_step,
        scene_map=lambda scene: flowmap(scene, eps=scene.eps[0]),
        plan=plan,
        quick_floor=(50, 100),
    )
)
