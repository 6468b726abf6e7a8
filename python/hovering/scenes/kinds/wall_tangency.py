"""The ``wall_tangency`` kind (fig:Sigma_0_wall computed): the tangency line of the unperturbed wall
section, its seven points of the paper's caption with their trajectories, and the regions of its
interior labelled by the flow.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..._enums import FlowStatus, wrap
from ..._io.serial import saved_as
from ...flow.section import Section
from ...normal.coordinates import TangentialCurve
from ..base import SceneResult, check_same_length, check_status, check_trajectory, fmt, region_counts
from ..fields import integer, integers, real
from ..registry import Kind, register
from ..values import MAX_TEXT
from ..wall import tangent_action, wall_states
from ._flow import FlowScene, above_corner, flowmap, needs_step, wall_flow

__all__ = ["WallTangencyScene", "WallPoint", "WallTangencyResult", "compute", "summarize", "report", "KIND"]


def _check(where: str, values: dict) -> None:
    needs_step(where, values)
    above_corner(where, values)
    system = values["system"]
    if system.eps != 0:
        raise ValueError(
            f"{where}.system.eps = {system.eps!r}: fig:Sigma_0_wall draws the unperturbed tangency "
            f"line; allowed: eps = 0 (the wall_section kind takes eps != 0)"
        )


@saved_as("hovering.scenes.spec:WallTangencyScene")
@dataclass(frozen=True, kw_only=True)
class WallTangencyScene(FlowScene):
    """``wall_tangency`` (fig:Sigma_0_wall): the tangency line of the wall section and its trajectories.

    The unperturbed wall section ``Sigma_h^{*,-}`` in the (q2, p2) plane: the tangency line
    ``Xi^0_wall`` (trajectories that touch q1 = qw1), its seven points of the paper's caption and
    their trajectories, and the regions of its interior ``Sigma_h^{w,-}`` labelled by the flow.

    Attributes
    ----------
    grid : tuple of int
        ``(n_theta, n_rho)`` points of the interior labelled by the flow (wall coordinates).
    n_points : int
        Samples of the tangency line.
    marker_size : float
        Scatter marker size of the labelled points.
    """

    grid: tuple = integers((180, 40), names=("n_theta", "n_rho"), ranges=((8, 2000), (2, 1000)))
    n_points: int = integer(400, lo=16, hi=100_000)
    marker_size: float = real(2.0, lo=0.0, hi=100.0, lo_open=True)


@saved_as("hovering.scenes.results:WallPoint")
@dataclass
class WallPoint:
    """A numbered point of the wall's tangency line and its trajectory (fig:Sigma_0_wall).

    Attributes
    ----------
    number : int
        The caption's number (1 and 7: above the corner; 2 and 6: at the corner; 3-5: below it).
    theta, q2, p2 : float
        The point (wall angle and its (q2, p2); p1 = 0 at q1 = qw1).
    trajectory : ndarray
        ``(m, 5)`` rows of the smooth flow through it, from Sigma_h to Sigma_h.
    status : str
        :class:`~hovering.FlowStatus` name of the step system's return from the same start.
    itinerary : str
        That return's itinerary.
    """

    number: int
    theta: float
    q2: float
    p2: float
    trajectory: np.ndarray
    status: str
    itinerary: str

    def _validate_loaded(self) -> None:
        if not 1 <= self.number <= 7:
            raise ValueError(f"number = {self.number!r} is out of range; allowed: 1 to 7")
        check_status("status", self.status)
        check_trajectory("trajectory", self.trajectory)
        if len(self.itinerary) > MAX_TEXT:
            raise ValueError(f"itinerary: a string of {len(self.itinerary)} characters; allowed: at most {MAX_TEXT}")


@saved_as("hovering.scenes.results:WallTangencyResult")
@dataclass(repr=False)
class WallTangencyResult(SceneResult):
    """Result of a ``wall_tangency`` scene (fig:Sigma_0_wall).

    Attributes
    ----------
    qw1, qw2 : float
        The corner.
    line : dict
        The tangency line ``Xi^0_wall``: arrays ``theta``, ``q2``, ``p2``.
    outer : dict
        The level ``H2 = h`` (outer edge of ``Sigma_h^>``): arrays ``q2``, ``p2``.
    points : list of WallPoint
        The seven numbered points.
    grid : dict
        Interior points in wall coordinates: arrays ``theta``, ``rho_w``, ``q2``, ``p2`` and
        ``region`` (the flow's label of the return through each).
    """

    qw1: float = 0.0
    qw2: float = 0.0
    line: dict = field(default_factory=dict)
    outer: dict = field(default_factory=dict)
    points: list = field(default_factory=list)
    grid: dict = field(default_factory=dict)

    def _validate_loaded(self) -> None:
        super()._validate_loaded()
        check_same_length("line", self.line, ("theta", "q2", "p2"))
        check_same_length("outer", self.outer, ("q2", "p2"))
        check_same_length("grid", self.grid, ("theta", "rho_w", "q2", "p2", "region"))
        for i, p in enumerate(self.points):
            if not isinstance(p, WallPoint):
                raise ValueError(f"points[{i}] must be a WallPoint, got {type(p).__name__}")


def compute(scene: WallTangencyScene, ctx) -> WallTangencyResult:
    """The tangency line, the caption's seven points with their trajectories (smooth flow) and the
    step system's verdict on each, and the interior's grid labelled by the flow.

    Parameters
    ----------
    scene : WallTangencyScene
        The scene.
    ctx : hovering.scenes.base.Context
        Quick run, meta.

    Returns
    -------
    WallTangencyResult
    """
    meta, quick = ctx.meta, ctx.quick
    flow = wall_flow(scene)
    sys, h = flow.sys, scene.h
    E2 = h - sys.V1.V(sys.qw1)  # H2 on the unperturbed tangency line
    line_theta = np.linspace(-np.pi, np.pi, scene.n_points)
    line = np.array([sys.V2.point_at(float(x), E2) for x in line_theta])
    outer = np.array([sys.V2.point_at(float(x), h) for x in line_theta])
    # The seven points of the caption, in increasing wall angle (the sense oscillator 2 turns):
    # 1 above the corner, 2 at it (p2 < 0), 3-5 below it on the right wall, 6 at it (p2 > 0), 7 above.
    P = math.sqrt(2.0 * (E2 - sys.V2.V(sys.qw2)))
    t_1R, t_R0 = sys.V2.angle_of_point(sys.qw2, -P, E2), sys.V2.angle_of_point(sys.qw2, P, E2)
    up = t_1R - t_R0  # the arc above the step, through theta = 0
    low = 2 * np.pi - up
    thetas = wrap(
        np.array([t_1R - up / 4, t_1R, t_1R + low / 4, t_1R + low / 2, t_1R + 3 * low / 4, t_R0, t_R0 + up / 4])
    )
    stages = ctx.stages(2)
    stages.start("points", f"{thetas.size} wall points and their trajectories")
    # Each point's segment starts where the tangential curve (traced back from the wall by the core)
    # puts it on Sigma_h; the smooth flow draws it (it only touches the walls), the step system says
    # what the touch is: grazing the right wall, hitting the corner, or passing above it.
    curve = TangentialCurve(Section(sys, h))
    th0, I0 = curve.at(thetas)
    z0 = Section(sys, h).point(th0, I0)
    sm = flow.returns(z0, trajectory_dt=scene.outputs.trajectory_dt, smooth=True)
    st = flow.returns(z0)
    points = [
        WallPoint(
            number=i + 1,
            theta=float(thetas[i]),
            q2=float(q2),
            p2=float(p2),
            trajectory=sm["trajectories"][i],
            status=FlowStatus(int(st["status"][i])).name,
            itinerary=st["itinerary"][i],
        )
        for i, (q2, p2) in enumerate(sys.V2.point_at(float(x), E2) for x in thetas)
    ]
    stages.end()
    n_th, n_rho = scene.grid
    if quick:
        n_th, n_rho = max(n_th // 4, 24), max(n_rho // 4, 6)
    stages.start("regions", f"{n_th} x {n_rho} wall states labelled")
    meta["grid"] = [n_th, n_rho]
    It = tangent_action(sys, h)
    TH, RHO = np.meshgrid(-np.pi + 2 * np.pi * (np.arange(n_th) + 0.5) / n_th, It * (np.arange(n_rho) + 0.5) / n_rho)
    zw = wall_states(sys, h, TH.ravel(), RHO.ravel(), I_tan=It)
    _, region, _ = flow.labels(zw)
    stages.end()
    meta["work"] = flow.work
    return WallTangencyResult(
        scene=scene,
        meta=meta,
        qw1=sys.qw1,
        qw2=sys.qw2,
        line=dict(theta=line_theta, q2=line[:, 0], p2=line[:, 1]),
        outer=dict(q2=outer[:, 0], p2=outer[:, 1]),
        points=points,
        grid=dict(theta=TH.ravel(), rho_w=RHO.ravel(), q2=zw[:, 2], p2=zw[:, 3], region=region),
    )


def summarize(result: WallTangencyResult) -> dict:
    """The seven points (where, and what the step system does from each) and the interior's regions.

    Parameters
    ----------
    result : WallTangencyResult
        The result.

    Returns
    -------
    dict
        ``tangency_points``, ``regions``.
    """
    return {
        "tangency_points": [
            dict(number=p.number, theta=p.theta, q2=p.q2, p2=p.p2, status=p.status, itinerary=p.itinerary)
            for p in result.points
        ],
        "regions": region_counts(result.grid["region"]),
    }


def report(summary: dict) -> list:
    """One line per point, one for the interior.

    Parameters
    ----------
    summary : dict
        From :func:`summarize` (with the common numbers).

    Returns
    -------
    list of str
    """
    f, lines = fmt, []
    for p in summary["tangency_points"]:
        lines.append(
            f"  point {p['number']}: theta = {f(p['theta'], '+.4f')}, q2 = {f(p['q2'], '+.4f')}, "
            f"p2 = {f(p['p2'], '+.4f')}: step system {p['status']} {p['itinerary']!r}"
        )
    lines.append(f"  interior regions {summary['regions']}")
    return lines


KIND = register(
    Kind(
        "wall_tangency",
        WallTangencyScene,
        WallTangencyResult,
        compute,
        summarize,
        report,
        doc="fig:Sigma_0_wall: the wall section's tangency line, points 1-7 and their trajectories",
        figsize=(18.0, 6.2),
        records=(("regions", "trajectory"), ("regions", "trajectory")),
        check=_check,
        scene_map=flowmap,
    )
)
