"""The ``wall_section`` kind (fig:wallsection computed): the corner-singularity curves of the wall
section, measured by bisection of the flow's labels on circles ``rho_w = const``, one circle's arcs
J_R, J_0, J_1, and trajectory segments through it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..._enums import FlowStatus, wrap
from ..._io.serial import saved_as
from ..base import SceneResult, check_array, check_same_length, check_status, check_trajectory, fmt, region_counts
from ..fields import integer, real
from ..registry import Kind, register
from ..values import MAX_TEXT
from ..values import text as text_value
from ..wall import DIRECTIONS, WallFlow, rho_w_max, wall_states, wall_tangency_action
from ._flow import FlowScene, above_corner, flowmap, needs_step, wall_flow

__all__ = ["WallSectionScene", "WallSegment", "WallSectionResult", "compute", "summarize", "report", "KIND"]


def _check(where: str, values: dict) -> None:
    needs_step(where, values)
    above_corner(where, values)
    # The wall coordinates need the tangency line I_tan^{eps,-}(theta) near the unperturbed one.
    system = values["system"]
    try:
        wall_tangency_action(system.build(), values["h"], [-3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0])
    except ValueError as e:
        raise ValueError(f"{where}.system.eps = {system.eps!r}: {e}") from None


@saved_as("hovering.scenes.spec:WallSectionScene")
@dataclass(frozen=True, kw_only=True)
class WallSectionScene(FlowScene):
    """``wall_section`` (fig:wallsection): the wall section's corner-singularity curves and a fixed circle.

    In the wall coordinates ``(theta, rho_w)`` of ``Sigma_h^{w,-}`` (eq:rhow): the curves
    ``sigma_R0^-, sigma_01^-, sigma_1R^-`` measured on circles ``rho_w = const`` by bisection of the
    flow's region labels, one circle's arcs J_R, J_0, J_1, and trajectory segments from it.

    Attributes
    ----------
    rho_w_fraction : float
        The drawn circle's ``rho_w`` as a fraction of ``rho_max(h)`` (eq:rhomaxh), in (0, 1].
    n_theta : int
        Angles labelled on that circle.
    n_circles : int
        Circles on which the corner-singularity curves are measured.
    bisections : int
        Bisection steps per boundary (resolution ``2 pi / n / 2^bisections``).
    segments : int
        Trajectory segments drawn per region of the circle.
    """

    rho_w_fraction: float = real(0.5, lo=0.0, hi=1.0, lo_open=True)
    n_theta: int = integer(720, lo=32, hi=20_000)
    n_circles: int = integer(16, lo=2, hi=200)
    bisections: int = integer(30, lo=1, hi=50)
    segments: int = integer(2, lo=0, hi=10)


@saved_as("hovering.scenes.results:WallSegment")
@dataclass
class WallSegment:
    """A trajectory segment through a point of the wall section's fixed circle (fig:wallsection).

    Attributes
    ----------
    kind : str
        The region of the arc it starts on (``"R"``, ``"0"``, ``"1"``) or the corner-singularity
        curve it starts at (``"R0"``, ``"01"``, ``"1R"``).
    theta : float
        Its wall angle.
    wall : ndarray
        Its state on the wall section ``(qw1, p1, q2, p2)``.
    trajectory : ndarray
        ``(m, 5)`` rows of the step system's flow from its point of Sigma_h until it returned or
        stopped.
    status : str
        :class:`~hovering.FlowStatus` name of that return.
    itinerary : str
        Its itinerary.
    """

    kind: str
    theta: float
    wall: np.ndarray
    trajectory: np.ndarray
    status: str
    itinerary: str

    def _validate_loaded(self) -> None:
        text_value("kind", self.kind, ("R", "0", "1") + DIRECTIONS)
        check_status("status", self.status)
        check_array("wall", self.wall, 1, shape=(4,))
        check_trajectory("trajectory", self.trajectory)
        if len(self.itinerary) > MAX_TEXT:
            raise ValueError(f"itinerary: a string of {len(self.itinerary)} characters; allowed: at most {MAX_TEXT}")


@saved_as("hovering.scenes.results:WallSectionResult")
@dataclass(repr=False)
class WallSectionResult(SceneResult):
    """Result of a ``wall_section`` scene (fig:wallsection), all from the flow.

    Attributes
    ----------
    qw1, qw2 : float
        The corner.
    rho_w, rho_max : float
        The drawn circle and eq:rhomaxh.
    tangency : dict
        The tangency line ``rho_w = 0``: arrays ``theta``, ``q2``, ``p2``.
    circle : dict
        The circle's samples: arrays ``theta``, ``q2``, ``p2``, ``p1`` and ``region`` (the flow's
        label of the return through each).
    boundaries : dict
        ``"R0"``, ``"01"``, ``"1R"`` -> the bisected wall angle where the circle's label changes
        (R to 0, 0 to 1, 1 to R with increasing theta; NaN if not found).
    curves : dict
        The corner-singularity curves of the wall section: arrays ``rho_w`` (circles) and
        ``theta_R0``, ``theta_01``, ``theta_1R``, ``q2_R0``, ..., ``p2_1R`` (NaN where not found).
    segments : list of WallSegment
        The drawn trajectory segments.
    resolution : float
        Bracket width left by the bisections (radians).
    """

    qw1: float = 0.0
    qw2: float = 0.0
    rho_w: float = 0.0
    rho_max: float = 0.0
    tangency: dict = field(default_factory=dict)
    circle: dict = field(default_factory=dict)
    boundaries: dict = field(default_factory=dict)
    curves: dict = field(default_factory=dict)
    segments: list = field(default_factory=list)
    resolution: float = 0.0

    def _validate_loaded(self) -> None:
        super()._validate_loaded()
        check_same_length("tangency", self.tangency, ("theta", "q2", "p2"))
        check_same_length("circle", self.circle, ("theta", "q2", "p2", "p1", "region"))
        if set(self.boundaries) != set(DIRECTIONS) or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in self.boundaries.values()
        ):
            raise ValueError(f"boundaries must map {list(DIRECTIONS)} to numbers")
        check_same_length(
            "curves", self.curves, ("rho_w",) + tuple(f"{c}_{d}" for c in ("theta", "q2", "p2") for d in DIRECTIONS)
        )
        for i, p in enumerate(self.segments):
            if not isinstance(p, WallSegment):
                raise ValueError(f"segments[{i}] must be a WallSegment, got {type(p).__name__}")


#: Label changes with increasing wall angle and the corner-singularity curve each one is (lemma:border).
_CHANGES = {("R", "0"): "R0", ("0", "1"): "01", ("1", "R"): "1R"}


def _circle_boundaries(flow: WallFlow, h: float, rho: np.ndarray, n_theta: int, bisections: int) -> tuple:
    """The corner-singularity angles on circles ``rho_w = rho[k]`` of the wall section.

    Each circle is labelled by the flow at ``n_theta`` angles; every change R -> 0, 0 -> 1, 1 -> R
    between neighbours is then bisected (all circles' brackets at once) ``bisections`` times.
    Returns ``(theta, other)``: ``theta[ab]`` one angle per circle (NaN where that change is not
    found once) and the number of other label changes per circle."""
    sys = flow.sys
    th = -np.pi + 2 * np.pi * (np.arange(n_theta) + 0.5) / n_theta
    TH = np.tile(th, rho.size)
    R = np.repeat(rho, n_theta)
    It = wall_tangency_action(sys, h, th)
    lab, _, _ = flow.labels(wall_states(sys, h, TH, R, I_tan=np.tile(It, rho.size)))
    lab = lab.reshape(rho.size, n_theta)
    nxt = np.roll(lab, -1, axis=1)
    found = {ab: np.full(rho.size, np.nan) for ab in DIRECTIONS}
    other = np.zeros(rho.size, dtype=int)
    brackets = []
    for k in range(rho.size):
        for i in np.flatnonzero(lab[k] != nxt[k]):
            ab = _CHANGES.get((lab[k, i], nxt[k, i]))
            if ab is None or np.isfinite(found[ab][k]):
                other[k] += 1
                continue
            found[ab][k] = 0.0
            brackets.append((k, ab, th[i], th[i] + 2 * np.pi / n_theta, lab[k, i]))
    if brackets:
        lo = np.array([b[2] for b in brackets])
        hi = np.array([b[3] for b in brackets])
        rr = rho[[b[0] for b in brackets]]
        left = np.array([b[4] for b in brackets], dtype=object)
        for _ in range(bisections):
            mid = 0.5 * (lo + hi)
            m = wrap(mid)
            lm, _, _ = flow.labels(wall_states(sys, h, m, rr))
            same = lm == left
            lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
        for (k, ab, *_), x in zip(brackets, wrap(0.5 * (lo + hi))):
            found[ab][k] = x
    return found, other


def compute(scene: WallSectionScene, ctx) -> WallSectionResult:
    """The circle's labels, the corner-singularity curves bisected on circles (the circle's own
    boundaries with them), and trajectory segments through the circle.

    Parameters
    ----------
    scene : WallSectionScene
        The scene.
    ctx : hovering.scenes.base.Context
        Quick run, meta.

    Returns
    -------
    WallSectionResult
    """
    meta, quick = ctx.meta, ctx.quick
    flow = wall_flow(scene)
    sys, h = flow.sys, scene.h
    rmax = rho_w_max(sys, h)
    rho = scene.rho_w_fraction * rmax
    n_theta = max(scene.n_theta // 4, 90) if quick else scene.n_theta
    n_circles = max(scene.n_circles // 2, 4) if quick else scene.n_circles
    meta.update(n_theta=n_theta, n_circles=n_circles)
    stages = ctx.stages(3)
    stages.start("circle", f"{n_theta} angles labelled")
    th = -np.pi + 2 * np.pi * (np.arange(n_theta) + 0.5) / n_theta
    It = wall_tangency_action(sys, h, th)
    tangency = wall_states(sys, h, th, 0.0, I_tan=It)  # p1 = 0: the tangency line rho_w = 0
    zc = wall_states(sys, h, th, rho, I_tan=It)
    _, region, _ = flow.labels(zc)
    stages.end()
    stages.start(
        "corner curves", f"{n_circles + 1} circles x {max(n_theta // 4, 64)} angles, {scene.bisections} bisections"
    )
    # The circle's own boundaries and the curves' circles, bisected together (rho^2 spacing: the
    # curve sigma_01 goes as sqrt(rho_w) near the tangency line, Lemma lemma:border).
    rhos = np.concatenate([[rho], rmax * ((np.arange(n_circles) + 1.0) / n_circles) ** 2])
    found, other = _circle_boundaries(flow, h, rhos, max(n_theta // 4, 64), scene.bisections)
    meta["other_changes"] = [int(x) for x in other]
    stages.end()
    boundaries = {ab: float(found[ab][0]) for ab in DIRECTIONS}
    curves = {"rho_w": rhos[1:]}
    for ab in DIRECTIONS:
        z = wall_states(sys, h, np.nan_to_num(found[ab][1:]), rhos[1:])
        bad = ~np.isfinite(found[ab][1:])
        z[bad] = np.nan
        curves[f"theta_{ab}"] = found[ab][1:]
        curves[f"q2_{ab}"], curves[f"p2_{ab}"] = z[:, 2], z[:, 3]
    stages.start("segments", f"up to {3 * scene.segments + 3} trajectory segments")
    # Segments: `segments` per arc, evenly inside it, and one at each of the circle's boundaries.
    picks = []
    for a, (lo_ab, hi_ab) in (("R", ("1R", "R0")), ("0", ("R0", "01")), ("1", ("01", "1R"))):
        lo, hi = boundaries[lo_ab], boundaries[hi_ab]
        if np.isfinite(lo) and np.isfinite(hi):
            width = (hi - lo) % (2 * np.pi)
            picks += [(a, lo + width * (j + 1) / (scene.segments + 1)) for j in range(scene.segments)]
    picks += [(ab, boundaries[ab]) for ab in DIRECTIONS if np.isfinite(boundaries[ab])]
    segments = []
    if picks:
        angles = wrap(np.array([p[1] for p in picks]))
        zw = wall_states(sys, h, angles, rho)
        z0, _, ok = flow.preimage(zw)
        keep = np.flatnonzero(ok)
        r = flow.returns(z0[keep], trajectory_dt=scene.outputs.trajectory_dt)
        for j, i in enumerate(keep):
            segments.append(
                WallSegment(
                    kind=picks[i][0],
                    theta=float(angles[i]),
                    wall=zw[i].copy(),
                    trajectory=r["trajectories"][j],
                    status=FlowStatus(int(r["status"][j])).name,
                    itinerary=r["itinerary"][j],
                )
            )
    stages.end()
    meta["work"] = flow.work
    return WallSectionResult(
        scene=scene,
        meta=meta,
        qw1=sys.qw1,
        qw2=sys.qw2,
        rho_w=rho,
        rho_max=rmax,
        tangency=dict(theta=th, q2=tangency[:, 2], p2=tangency[:, 3]),
        circle=dict(theta=th, q2=zc[:, 2], p2=zc[:, 3], p1=zc[:, 1], region=region),
        boundaries=boundaries,
        curves=curves,
        segments=segments,
        resolution=2 * np.pi / max(n_theta // 4, 64) / 2**scene.bisections,
    )


def summarize(result: WallSectionResult) -> dict:
    """The circle's boundaries and arcs, the curves' points, the segments' itineraries.

    Parameters
    ----------
    result : WallSectionResult
        The result.

    Returns
    -------
    dict
        ``rho_w``, ``rho_max``, ``boundaries``, ``resolution``, ``arcs``, ``circle_regions``,
        ``curve_points``, ``segments``.
    """
    b = result.boundaries
    two_pi = 2 * math.pi
    return dict(
        rho_w=result.rho_w,
        rho_max=result.rho_max,
        boundaries=b,
        resolution=result.resolution,
        arcs={
            "R": (b["R0"] - b["1R"]) % two_pi,
            "0": (b["01"] - b["R0"]) % two_pi,
            "1": (b["1R"] - b["01"]) % two_pi,
        },
        circle_regions=region_counts(result.circle["region"]),
        curve_points={k: int(np.count_nonzero(np.isfinite(result.curves[f"theta_{k}"]))) for k in DIRECTIONS},
        segments=[dict(kind=g.kind, theta=g.theta, status=g.status, itinerary=g.itinerary) for g in result.segments],
    )


def report(summary: dict) -> list:
    """The circle's boundaries and arcs; the curves and the segments.

    Parameters
    ----------
    summary : dict
        From :func:`summarize` (with the common numbers).

    Returns
    -------
    list of str
    """
    f, lines = fmt, []
    b, a = summary["boundaries"], summary["arcs"]
    lines.append(
        f"  circle rho_w = {f(summary['rho_w'], '.5f')} (rho_max {f(summary['rho_max'], '.5f')}): "
        f"theta_R0 = {f(b['R0'], '+.6f')}, theta_01 = {f(b['01'], '+.6f')}, theta_1R = {f(b['1R'], '+.6f')} "
        f"(+- {f(summary['resolution'], '.1g')}); |J_R| = {f(a['R'], '.4f')}, |J_0| = {f(a['0'], '.4f')}, "
        f"|J_1| = {f(a['1'], '.4f')}"
    )
    lines.append(
        f"  corner curves measured on {summary['curve_points']} circles; segments "
        + ", ".join(f"{g['kind']}: {g['status']} {g['itinerary']!r}" for g in summary["segments"])
    )
    return lines


KIND = register(
    Kind(
        "wall_section",
        WallSectionScene,
        WallSectionResult,
        compute,
        summarize,
        report,
        doc="fig:wallsection: the wall section's corner-singularity curves and the arcs of a circle",
        figsize=(12.0, 10.0),
        records=(("regions", "trajectory"), ("regions", "trajectory")),
        check=_check,
        scene_map=flowmap,
    )
)
