"""The ``corner_directions`` kind (fig:corner_directions computed): the three directions in which
trajectories reach the corner, each followed back by the smooth flow to Sigma_h and forward again
by the step system's flow to the corner, and the corner-singularity curves of Sigma_h they trace.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..._enums import FlowStatus
from ..._io.serial import saved_as
from ...flow.section import Section
from ..base import SceneResult, check_array, check_same_length, check_status, check_trajectory, fmt
from ..fields import custom, integer
from ..registry import Kind, register
from ..values import real as real_value
from ..values import text as text_value
from ..wall import DIRECTIONS, corner_energy, corner_speed, corner_states
from ._flow import FlowScene, above_corner, flowmap, needs_step, wall_flow

__all__ = [
    "CornerDirectionsScene",
    "CornerTrajectory",
    "CornerDirectionsResult",
    "compute",
    "summarize",
    "report",
    "KIND",
]


def _fractions(where: str, value, reading) -> tuple:
    """1 to 12 distinct fractions of p1w_max, each in (0, 1)."""
    if not isinstance(value, list) or not 1 <= len(value) <= 12:
        raise ValueError(f"{where} must be a list of 1 to 12 numbers in (0, 1) (p1w / p1w_max), got {value!r}")
    fr = tuple(real_value(f"{where}[{i}]", v, lo=0.0, hi=1.0, lo_open=True, hi_open=True) for i, v in enumerate(value))
    if len(set(fr)) != len(fr):
        raise ValueError(f"{where} = {value!r} lists a value twice")
    return fr


def _check(where: str, values: dict) -> None:
    needs_step(where, values)
    above_corner(where, values)


@saved_as("hovering.scenes.spec:CornerDirectionsScene")
@dataclass(frozen=True, kw_only=True)
class CornerDirectionsScene(FlowScene):
    """``corner_directions`` (fig:corner_directions): the three directions that reach the corner.

    On the energy surface h the corner is reached with momenta ``p_R0 = (-p1w, P2)``,
    ``p_01 = (p1w, -P2)``, ``p_1R = (-p1w, -P2)``, ``P2 = sqrt(2 (h - h_eps^w) - p1w^2)``
    (eq:p2corner); each is followed back by the smooth flow to its point of Sigma_h, and forward
    again by the step system's flow to the corner.

    Attributes
    ----------
    p1w_fractions : tuple of float
        The ``p1w`` of the trajectories drawn, as fractions of ``p1w_max = sqrt(2 (h - h_eps^w))``,
        each in (0, 1).
    n_curve : int
        Values of ``p1w`` on which each corner-singularity curve of Sigma_h is traced.
    """

    p1w_fractions: tuple = custom((0.3, 0.7), read=_fractions, allowed="1 to 12 distinct numbers in (0, 1)")
    n_curve: int = integer(48, lo=4, hi=2000)


@saved_as("hovering.scenes.results:CornerTrajectory")
@dataclass
class CornerTrajectory:
    """A trajectory of the step system that arrives at the corner (fig:corner_directions).

    Attributes
    ----------
    direction : {"R0", "01", "1R"}
        Its incoming direction ``p_ab``.
    p1w : float
        The horizontal speed at the corner (eq:p2corner).
    start : ndarray
        Its point of Sigma_h, ``(q1, p1 = 0, q2, p2)``, found by the time-reversed smooth flow.
    theta, I, phi, K : float
        That point in section and normal coordinates.
    flight_time : float
        Time from the start to the corner (of the reversed trace).
    trajectory : ndarray
        ``(m, 5)`` rows ``t, q1, p1, q2, p2`` of the step system's flow from the start until it
        stopped (at the corner) or returned, sampled so that a sample falls at ``flight_time``.
    status : str
        :class:`~hovering.FlowStatus` name of that forward run (``CORNER`` when it hit the corner).
    arrival : ndarray
        The state of the forward run at ``flight_time`` (where it stopped, for a corner hit).
    """

    direction: str
    p1w: float
    start: np.ndarray
    theta: float
    I: float
    phi: float
    K: float
    flight_time: float
    trajectory: np.ndarray
    status: str
    arrival: np.ndarray

    def _validate_loaded(self) -> None:
        text_value("direction", self.direction, DIRECTIONS)
        check_status("status", self.status)
        check_array("start", self.start, 1, shape=(4,))
        check_array("arrival", self.arrival, 1, shape=(4,))
        check_trajectory("trajectory", self.trajectory)


@saved_as("hovering.scenes.results:CornerDirectionsResult")
@dataclass(repr=False)
class CornerDirectionsResult(SceneResult):
    """Result of a ``corner_directions`` scene (fig:corner_directions), all from the flow.

    Attributes
    ----------
    qw1, qw2 : float
        The corner.
    step_energy : float
        ``h_eps^w`` (def:heps).
    p1w_max : float
        ``sqrt(2 (h - h_eps^w))``: the radius of the momentum circle at the corner.
    curves : dict
        Direction -> arrays ``p1w``, ``theta``, ``I``, ``phi``, ``K`` (the corner-singularity curve of
        Sigma_h traced by the reversed flow, parametrized by p1w), ``reached`` (the step system's flow
        from that point hits the corner) and ``error`` (distance of its arrival from the corner).
    trajectories : list of CornerTrajectory
        The drawn trajectories, by direction and p1w.
    """

    qw1: float = 0.0
    qw2: float = 0.0
    step_energy: float = 0.0
    p1w_max: float = 0.0
    curves: dict = field(default_factory=dict)
    trajectories: list = field(default_factory=list)

    def _validate_loaded(self) -> None:
        super()._validate_loaded()
        if set(self.curves) != set(DIRECTIONS):
            raise ValueError(f"curves must have the keys {list(DIRECTIONS)}, got {sorted(map(str, self.curves))}")
        for k, c in self.curves.items():
            check_same_length(f"curves.{k}", c, ("p1w", "theta", "I", "phi", "K", "reached", "error"))
        for i, t in enumerate(self.trajectories):
            if not isinstance(t, CornerTrajectory):
                raise ValueError(f"trajectories[{i}] must be a CornerTrajectory, got {type(t).__name__}")


def _samples_through(T: float, dt_max: float) -> float:
    """A spacing <= dt_max that puts a trajectory sample at time T (its ceil(T / dt_max)-th)."""
    return T / max(1, math.ceil(T / dt_max))


def compute(scene: CornerDirectionsScene, ctx) -> CornerDirectionsResult:
    """The three corner-singularity curves of Sigma_h traced back from the corner (each point's
    forward run checked to reach it again), and the drawn trajectories.

    Parameters
    ----------
    scene : CornerDirectionsScene
        The scene.
    ctx : hovering.scenes.base.Context
        Quick run, meta.

    Returns
    -------
    CornerDirectionsResult
    """
    meta, quick = ctx.meta, ctx.quick
    stages = ctx.stages(3)
    stages.start("setup", "flow map (tangential curve)")
    fm = flowmap(scene)  # its tangential curve gives the normal coordinates of the curves
    flow = wall_flow(scene, fm)
    sys, h = flow.sys, scene.h
    sec = Section(sys, h)
    stages.end()
    p1max = corner_speed(sys, h)
    n = max(scene.n_curve // 4, 8) if quick else scene.n_curve
    meta["n_curve"] = n
    # p1w spaced evenly in p1w^2 (K is about linear in it near the tangency, eq:cornersingbordrho).
    p1w = p1max * np.sqrt((np.arange(n) + 0.5) / n)
    stages.start("curves", f"3 directions x {n} corner states, traced back and forth")
    curves = {}
    for ab in DIRECTIONS:
        z0, T, ok = flow.preimage(corner_states(sys, h, ab, p1w))
        reached, err = np.zeros(n, dtype=bool), np.full(n, np.nan)
        if ok.any():  # the step system's flow from each point: does it hit the corner, and how close
            r = flow.returns(z0[ok])
            reached[ok] = r["status"] == int(FlowStatus.CORNER)
            err[ok] = np.where(reached[ok], np.hypot(r["z"][:, 0] - sys.qw1, r["z"][:, 2] - sys.qw2), np.nan)
        th, I = np.full(n, np.nan), np.full(n, np.nan)
        c = sec.coordinates(z0[ok])
        th[ok], I[ok] = c[:, 0], c[:, 1]
        phi, K = np.full(n, np.nan), np.full(n, np.nan)
        phi[ok], K[ok] = fm.curve.to_normal(th[ok], I[ok])
        curves[ab] = dict(p1w=p1w.copy(), theta=th, I=I, phi=phi, K=K, reached=reached, error=err)
    stages.end()
    stages.start("trajectories", f"3 directions x {len(scene.p1w_fractions)} trajectories")
    trajectories = []
    for ab in DIRECTIONS:
        pw = p1max * np.asarray(scene.p1w_fractions)
        z0, T, ok = flow.preimage(corner_states(sys, h, ab, pw))
        if not ok.all():
            raise RuntimeError(f"the smooth flow could not be traced back from the corner along p_{ab}")
        r = flow.returns(z0, trajectory_dt=[_samples_through(x, scene.outputs.trajectory_dt) for x in T])
        c = sec.coordinates(z0)
        phi, K = fm.curve.to_normal(c[:, 0], c[:, 1])
        for i in range(pw.size):
            tr = r["trajectories"][i]
            k = int(np.argmin(np.abs(tr[:, 0] - T[i])))  # the sample at T, or where the run stopped
            trajectories.append(
                CornerTrajectory(
                    direction=ab,
                    p1w=float(pw[i]),
                    start=z0[i].copy(),
                    theta=float(c[i, 0]),
                    I=float(c[i, 1]),
                    phi=float(phi[i]),
                    K=float(K[i]),
                    flight_time=float(T[i]),
                    trajectory=tr[: k + 1].copy(),
                    status=FlowStatus(int(r["status"][i])).name,
                    arrival=tr[k, 1:].copy(),
                )
            )
    stages.end()
    meta["work"] = flow.work
    return CornerDirectionsResult(
        scene=scene,
        meta=meta,
        qw1=sys.qw1,
        qw2=sys.qw2,
        step_energy=corner_energy(sys),
        p1w_max=p1max,
        curves=curves,
        trajectories=trajectories,
    )


def summarize(result: CornerDirectionsResult) -> dict:
    """The corner, its energy, each curve's points that reach the corner, each trajectory's arrival.

    Parameters
    ----------
    result : CornerDirectionsResult
        The result.

    Returns
    -------
    dict
        ``corner``, ``step_energy``, ``p1w_max``, ``curves``, ``arrivals``.
    """
    s = dict(corner=[result.qw1, result.qw2], step_energy=result.step_energy, p1w_max=result.p1w_max)
    s["curves"] = {
        k: dict(
            points=int(c["p1w"].size),
            reached=int(np.count_nonzero(c["reached"])),
            max_error=float(np.nanmax(c["error"])) if np.isfinite(c["error"]).any() else None,
            K_range=[float(np.nanmin(c["K"])), float(np.nanmax(c["K"]))] if np.isfinite(c["K"]).any() else None,
        )
        for k, c in result.curves.items()
    }
    s["arrivals"] = [
        dict(
            direction=t.direction,
            p1w=t.p1w,
            status=t.status,
            phi=t.phi,
            K=t.K,
            flight_time=t.flight_time,
            error=float(np.hypot(t.arrival[0] - result.qw1, t.arrival[2] - result.qw2)),
            momentum=[float(t.arrival[1]), float(t.arrival[3])],
        )
        for t in result.trajectories
    ]
    return s


def report(summary: dict) -> list:
    """The corner line, one line per curve, one per arrival.

    Parameters
    ----------
    summary : dict
        From :func:`summarize` (with the common numbers).

    Returns
    -------
    list of str
    """
    f, lines = fmt, []
    lines.append(
        f"  corner {summary['corner']}, h_eps^w = {f(summary['step_energy'], '.6f')}, "
        f"p1w_max = {f(summary['p1w_max'], '.6f')}"
    )
    for d, c in summary["curves"].items():
        lines.append(
            f"  sigma_{d}: {c['reached']} of {c['points']} points of Sigma_h reach the corner "
            f"(largest miss {f(c['max_error'], '.2g')})"
        )
    for a in summary["arrivals"]:
        lines.append(
            f"    p_{a['direction']}, p1w = {f(a['p1w'], '.4f')}: from (phi, K) = ({f(a['phi'], '+.4f')}, "
            f"{f(a['K'], '+.5f')}), {a['status']} after t = {f(a['flight_time'], '.4f')}, "
            f"{f(a['error'], '.2g')} from the corner, p = ({f(a['momentum'][0], '+.4f')}, "
            f"{f(a['momentum'][1], '+.4f')})"
        )
    return lines


KIND = register(
    Kind(
        "corner_directions",
        CornerDirectionsScene,
        CornerDirectionsResult,
        compute,
        summarize,
        report,
        doc="fig:corner_directions: the three directions that reach the corner",
        figsize=(12.0, 10.0),
        records=(("trajectory",), ("trajectory",)),
        check=_check,
        scene_map=flowmap,
    )
)
