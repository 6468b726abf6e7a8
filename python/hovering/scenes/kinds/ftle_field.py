"""The ``ftle_field`` kind: the finite-time Lyapunov exponent over a box of (phi, K), forward and
backward: the ridges are the stable and unstable manifolds of the hyperbolic sets, the skeleton of
the transport across the impact zone.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._io.serial import saved_as
from ...dynamics import FTLEField, ftle_field
from ..base import SceneResult, fmt
from ..fields import choice, integer, pair
from ..registry import Kind, register
from ._flow import FlowScene
from ._tangent import map_field, scene_model

__all__ = ["FTLEScene", "FTLEResult", "compute", "summarize", "report", "KIND"]


@saved_as("hovering.scenes.spec:FTLEScene")
@dataclass(frozen=True, kw_only=True)
class FTLEScene(FlowScene):
    """``ftle_field``: the finite-time Lyapunov exponent over a box.

    Attributes
    ----------
    map : {"flow", "measured", "first_mode"}
        The flow's return map or one of its truncated models.
    n_steps : int
        The finite time n (returns).
    phi_range, K_range : tuple of float
        The box.
    n_phi, n_K : int
        Starts per side of the grid.
    direction : {"both", "forward", "backward"}
        Which fields (forward ridges: stable manifolds; backward: unstable ones).
    """

    map: str = map_field()
    n_steps: int = integer(20, lo=1, hi=100_000)
    phi_range: tuple = pair((-3.141592653589793, 3.141592653589793))
    K_range: tuple = pair((-0.2, 0.05))
    n_phi: int = integer(200, lo=2, hi=4000)
    n_K: int = integer(150, lo=2, hi=4000)
    direction: str = choice("both", ("both", "forward", "backward"))


@saved_as("hovering.scenes.results:FTLEResult")
@dataclass(repr=False)
class FTLEResult(SceneResult):
    """Result of an ``ftle_field`` scene.

    Attributes
    ----------
    fields : list of FTLEField
        The forward and/or backward fields (:class:`hovering.FTLEField`).
    """

    fields: list = field(default_factory=list)

    def _validate_loaded(self) -> None:
        super()._validate_loaded()
        for i, f in enumerate(self.fields):
            if not isinstance(f, FTLEField):
                raise ValueError(f"fields[{i}] must be an FTLEField, got {type(f).__name__}")


def compute(scene: FTLEScene, ctx) -> FTLEResult:
    """The field(s) over the scene's grid, one batched iteration each.

    Parameters
    ----------
    scene : FTLEScene
        The scene.
    ctx : hovering.scenes.base.Context
        Quick run, stages, meta.

    Returns
    -------
    FTLEResult
    """
    meta = ctx.meta
    m = scene_model(scene)
    n_phi, n_K = scene.n_phi, scene.n_K
    if ctx.quick:
        n_phi, n_K = max(8, n_phi // 5), max(6, n_K // 5)
    phi = np.linspace(*scene.phi_range, n_phi)
    K = np.linspace(*scene.K_range, n_K)
    dirs = ("forward", "backward") if scene.direction == "both" else (scene.direction,)
    stages = ctx.stages(len(dirs))
    out = []
    for d in dirs:
        stages.start(d, f"{n_phi} x {n_K} starts x {scene.n_steps} returns")
        out.append(ftle_field(m, phi, K, scene.n_steps, direction=d))
        stages.end()
    meta.update(grid=[n_phi, n_K], map=scene.map)
    return FTLEResult(scene=scene, meta=meta, fields=out)


def summarize(result: FTLEResult) -> dict:
    """Each field's range, median and the share of its starts whose orbit stopped.

    Parameters
    ----------
    result : FTLEResult
        The result.

    Returns
    -------
    dict
    """
    rows = []
    for f in result.fields:
        v = f.ftle[np.isfinite(f.ftle)]
        rows.append(
            dict(
                direction=f.direction,
                n_steps=f.n_steps,
                min=float(v.min()) if v.size else None,
                median=float(np.median(v)) if v.size else None,
                max=float(v.max()) if v.size else None,
                stopped=float(1 - v.size / f.ftle.size),
            )
        )
    return {"fields": rows}


def report(summary: dict) -> list:
    """One line per field.

    Parameters
    ----------
    summary : dict
        From :func:`summarize`.

    Returns
    -------
    list of str
    """
    return [
        f"  {r['direction']} FTLE over {r['n_steps']} returns: {fmt(r['min'], '.3g')} .. {fmt(r['max'], '.3g')}, "
        f"median {fmt(r['median'], '.3g')}; stopped before n: {fmt(100 * r['stopped'], '.1f')}%"
        for r in summary.get("fields", [])
    ]


KIND = register(
    Kind(
        "ftle_field",
        FTLEScene,
        FTLEResult,
        compute,
        summarize,
        report,
        doc="the finite-time Lyapunov exponent over a box, forward and backward (the manifolds' ridges)",
        figsize=(13.0, 5.5),
        scene_map=scene_model,
    )
)
