"""The ``residue_vs_eps`` kind: a periodic orbit followed in eps by pseudo-arclength continuation,
its residue against eps with the stability bands, folds and period doublings marked.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..._io.serial import saved_as
from ...dynamics import Branch, PeriodicOrbit, continue_orbit, periodic_orbit
from ..base import SceneResult, fmt
from ..fields import integer, real
from ..registry import Kind, register
from ._flow import FlowScene
from ._tangent import map_field, scene_model

__all__ = ["ResidueScene", "ResidueResult", "compute", "summarize", "report", "KIND"]


@saved_as("hovering.scenes.spec:ResidueScene")
@dataclass(frozen=True, kw_only=True)
class ResidueScene(FlowScene):
    """``residue_vs_eps``: an orbit's residue along its branch in eps.

    Attributes
    ----------
    map : {"flow", "measured", "first_mode"}
        The flow's return map or one of its truncated models.
    period : int
        The orbit's period.
    phi0, K0 : float
        A point near the orbit at the scene's eps (Newton's start).
    eps_stop : float
        The eps the branch is followed to.
    n_steps : int
        Continuation steps at most.
    """

    map: str = map_field()
    period: int = integer(2, lo=1, hi=10_000)
    phi0: float = real(0.0)
    K0: float = real(0.0)
    eps_stop: float = real(-0.1)
    n_steps: int = integer(50, lo=1, hi=10_000)


@saved_as("hovering.scenes.results:ResidueResult")
@dataclass(repr=False)
class ResidueResult(SceneResult):
    """Result of a ``residue_vs_eps`` scene.

    Attributes
    ----------
    start : PeriodicOrbit
        The orbit at the scene's eps.
    branch : Branch or None
        Its continuation (None if Newton did not find the orbit).
    """

    start: PeriodicOrbit | None = None
    branch: Branch | None = None


def compute(scene: ResidueScene, ctx) -> ResidueResult:
    """Newton's orbit at the scene's eps, then its branch to ``eps_stop``.

    Parameters
    ----------
    scene : ResidueScene
        The scene.
    ctx : hovering.scenes.base.Context
        Quick run, stages, meta.

    Returns
    -------
    ResidueResult
    """
    meta = ctx.meta
    m = scene_model(scene)
    stages = ctx.stages(2)
    stages.start("orbit", f"period {scene.period} near ({scene.phi0}, {scene.K0})")
    start = periodic_orbit(m, scene.phi0, scene.K0, scene.period)
    stages.end()
    branch = None
    if start.converged and scene.eps_stop != m.eps:
        steps = max(5, scene.n_steps // 5) if ctx.quick else scene.n_steps
        ds = abs(scene.eps_stop - m.eps) / max(steps - 5, 1)

        def family(e):
            return scene_model(scene, eps=e)

        stages.start("continuation", f"eps {m.eps:g} -> {scene.eps_stop:g}, {steps} steps at most")
        branch = continue_orbit(m, start, scene.eps_stop, family=family, parameter=m.eps, ds=ds, n_steps=steps)
        stages.end()
    meta.update(map=scene.map, start_status=start.status)
    return ResidueResult(scene=scene, meta=meta, start=start, branch=branch)


def summarize(result: ResidueResult) -> dict:
    """The start's residue, the branch's range and its events.

    Parameters
    ----------
    result : ResidueResult
        The result.

    Returns
    -------
    dict
    """
    b = result.branch
    return {
        "start_status": result.start.status,
        "start_residue": float(result.start.residue) if result.start.converged else None,
        "points": 0 if b is None else int(b.parameter.size),
        "eps": None if b is None else [float(b.parameter.min()), float(b.parameter.max())],
        "events": [] if b is None else [dict(kind=e["kind"], eps=float(e["parameter"])) for e in b.events],
        "branch_status": None if b is None else b.status,
    }


def report(summary: dict) -> list:
    """The start and the events.

    Parameters
    ----------
    summary : dict
        From :func:`summarize`.

    Returns
    -------
    list of str
    """
    lines = [f"  start: {summary['start_status']}, residue {fmt(summary['start_residue'], '.5g')}"]
    if summary["points"]:
        lines.append(
            f"  branch: {summary['points']} points, eps {fmt(summary['eps'][0], '.5g')} .. "
            f"{fmt(summary['eps'][1], '.5g')} ({summary['branch_status']})"
        )
    for e in summary["events"]:
        lines.append(f"  {e['kind']} at eps = {fmt(e['eps'], '.6g')}")
    return lines


KIND = register(
    Kind(
        "residue_vs_eps",
        ResidueScene,
        ResidueResult,
        compute,
        summarize,
        report,
        doc="a periodic orbit's residue along its continuation in eps, folds and period doublings marked",
        figsize=(8.0, 5.0),
        scene_map=scene_model,
    )
)
