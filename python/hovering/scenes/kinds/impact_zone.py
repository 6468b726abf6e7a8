"""The ``impact_zone`` kind: does anything cross the impact zone? For the flow's return map and its
truncated model side by side: the zone between the critical curve and the floor, a barrier scan
along a symmetry line and transits up from near the floor and down from near the ceiling.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..._io.serial import saved_as
from ...analysis.barriers import BarrierScan, barrier_scan
from ...analysis.transit import TransitResult, transit
from ...analysis.zone import ImpactZone, impact_zone
from ..base import SceneResult, fmt
from ..fields import choice, integer
from ..registry import Kind, register
from ..values import MAX_TEXT
from ._flow import FlowScene, flowmap, needs_step

__all__ = ["ImpactZoneScene", "ZoneStudy", "ImpactZoneResult", "compute", "summarize", "report", "KIND"]


def _check(where: str, values: dict) -> None:
    needs_step(where, values)
    if values["system"].eps == 0:
        raise ValueError(
            f"{where}.system.eps = 0: at eps = 0 every level K is invariant and the zone has no critical "
            "curve; allowed: eps != 0"
        )


@saved_as("hovering.scenes.spec:ImpactZoneScene")
@dataclass(frozen=True, kw_only=True)
class ImpactZoneScene(FlowScene):
    """``impact_zone``: does anything cross the impact zone? The flow and its model side by side.

    For each map (the flow's return map and its truncated model): the zone between the critical
    curve and the floor (:func:`hovering.impact_zone`), a :func:`hovering.barrier_scan` along a
    symmetry line (layers by class, two-sided barriers) and :func:`hovering.transit` up from near
    the floor and down from near the ceiling.

    Attributes
    ----------
    n_starts : int
        Starts of the barrier scan.
    n_steps : int
        Returns per orbit of the scan (steps of the model).
    transit_orbits : int
        Orbits per transit direction.
    transit_steps : int
        Returns per transit orbit (the model gets ``model_factor`` times more steps).
    model_factor : int
        How many more steps the model's orbits get than the flow's (it is ~1000x cheaper per step).
    model : {"measured", "first_mode"}
        The truncated model.
    line : {"L1", "L2"}
        Where the scan's starts lie.
    critical_steps : int
        Iterates per tested orbit of the critical-curve search (the zone's ceiling).
    keep : int
        Points of each scan orbit drawn.
    """

    # Counts bounded so that a scene from elsewhere cannot ask for days.
    n_starts: int = integer(40, lo=2, hi=2000)
    n_steps: int = integer(20_000, lo=256, hi=10_000_000)
    transit_orbits: int = integer(40, lo=1, hi=100_000)
    transit_steps: int = integer(100_000, lo=1, hi=100_000_000)
    model_factor: int = integer(20, lo=1, hi=1000)
    model: str = choice("measured", ("measured", "first_mode"))
    line: str = choice("L1", ("L1", "L2"))
    critical_steps: int = integer(20_000, lo=500, hi=10_000_000)
    keep: int = integer(2000, lo=0, hi=100_000)


@saved_as("hovering.scenes.results:ZoneStudy")
@dataclass
class ZoneStudy:
    """One map's answer to "does anything cross the impact zone?" (an ``impact_zone`` scene).

    Attributes
    ----------
    name : str
        ``"flow"`` or the model's name.
    zone : ImpactZone
        Its floor and ceiling.
    scan : BarrierScan
        Layers and barriers along the scene's line (with ``keep`` points of each orbit).
    up, down : TransitResult
        Orbits from s = 0.05 towards the ceiling and from s = 0.95 towards the floor.
    seconds : dict
        Seconds per stage (``zone``, ``scan``, ``transit``).
    """

    name: str = ""
    zone: ImpactZone = None
    scan: BarrierScan = None
    up: TransitResult = None
    down: TransitResult = None
    seconds: dict = field(default_factory=dict)

    def _validate_loaded(self) -> None:
        for k in ("zone", "scan", "up", "down"):
            want = ImpactZone if k == "zone" else BarrierScan if k == "scan" else TransitResult
            if not isinstance(getattr(self, k), want):
                raise ValueError(f"{k} must be a {want.__name__}, got {type(getattr(self, k)).__name__}")
        if len(self.name) > MAX_TEXT:
            raise ValueError(f"name: a string of {len(self.name)} characters; allowed: at most {MAX_TEXT}")

    def summary(self) -> dict:
        """The numbers of the study, JSON-able: layers, barriers, transit fractions and extremes.

        Returns
        -------
        dict
        """
        sc = self.scan
        out = dict(
            name=self.name,
            floor=self.zone.floor_kind,
            starts=len(sc),
            n_steps=sc.n_steps,
            classes={k: int(np.count_nonzero(sc.kind == k)) for k in ("circle", "islands", "chaotic", "undecided")},
            barriers=[float(b) for b in sc.barriers],
            layers=[
                dict(
                    s_start=list(ly.s_start),
                    s=[ly.s_min, ly.s_max],
                    kind=ly.kind,
                    periods=list(ly.periods),
                    impacting=ly.impacting,
                )
                for ly in sc.layers
            ],
            spanning=int(sc.spanning(0.1, 0.9).size),
            seconds=self.seconds,
        )
        for d in ("up", "down"):
            t = getattr(self, d)
            rate = t.escape_rate
            out[d] = dict(
                orbits=int(t.crossed.size),
                n_steps=t.n_steps,
                start_s=t.start_s,
                target_s=t.target_s,
                crossed=int(np.count_nonzero(t.crossed)),
                fraction=t.fraction,
                fraction_error=t.fraction_error,
                s_reached=float(np.nanmax(t.s_max) if d == "up" else np.nanmin(t.s_min)),
                escape_rate=list(rate) if rate is not None else None,
            )
        return out


@saved_as("hovering.scenes.results:ImpactZoneResult")
@dataclass
class ImpactZoneResult(SceneResult):
    """Result of an ``impact_zone`` scene: the flow's and its model's :class:`ZoneStudy`.

    Attributes
    ----------
    flow, model : ZoneStudy
        The two studies.
    model_name : str
        ``"measured"`` or ``"first_mode"``.
    onset : dict
        The onset parameters (Omega0, theta_w, tau0, tau1, lam).
    b1 : float
        First mode of the measured forcing: the model acts with eps b1.
    """

    flow: ZoneStudy = None
    model: ZoneStudy = None
    model_name: str = "measured"
    onset: dict = field(default_factory=dict)
    b1: float = float("nan")

    def _validate_loaded(self) -> None:
        super()._validate_loaded()
        for k in ("flow", "model"):
            if not isinstance(getattr(self, k), ZoneStudy):
                raise ValueError(f"{k} must be a ZoneStudy, got {type(getattr(self, k)).__name__}")


def _zone_study(name, m, zone, scene: ImpactZoneScene, n_scan: int, n_transit: int, ctx) -> ZoneStudy:
    """The scan and both transits of one map in its zone."""
    sec = {}
    t = time.perf_counter()
    scan = barrier_scan(
        m,
        zone,
        n_starts=scene.n_starts,
        n_steps=n_scan,
        line=scene.line,
        keep=min(scene.keep, n_scan + 1),
        **ctx.progress_kw,
    )
    sec["scan"] = time.perf_counter() - t
    t = time.perf_counter()
    kw = dict(n_orbits=scene.transit_orbits, n_steps=n_transit, **ctx.progress_kw)
    # transit's default targets lie inside the zone (1 - margin, margin): its boundaries are
    # invariant curves that no orbit reaches, so targets on them could never count a crossing
    up = transit(m, zone, "up", start_s=0.05, **kw)
    down = transit(m, zone, "down", start_s=0.95, **kw)
    sec["transit"] = time.perf_counter() - t
    return ZoneStudy(name=name, zone=zone, scan=scan, up=up, down=down, seconds=sec)


def _study_size(scene: ImpactZoneScene, n_scan: int, n_transit: int, unit: str) -> str:
    return (
        f"barrier scan {scene.n_starts} orbits x {n_scan} {unit}, "
        f"transits 2 x {scene.transit_orbits} orbits x {n_transit} {unit}"
    )


def compute(scene: ImpactZoneScene, ctx) -> ImpactZoneResult:
    """Both maps' zones (the model's measured in the flow's zone coordinate), then each one's scan
    and transits.

    Parameters
    ----------
    scene : ImpactZoneScene
        The scene.
    ctx : hovering.scenes.base.Context
        Quick run, progress, meta.

    Returns
    -------
    ImpactZoneResult
    """
    meta = ctx.meta
    n_scan, n_transit = ctx.scaled(scene.n_steps, floor=1000), ctx.scaled(scene.transit_steps, floor=200)
    n_crit = ctx.scaled(scene.critical_steps, floor=2000)
    f = scene.model_factor
    meta.update(n_steps=n_scan, transit_steps=n_transit, critical_steps=n_crit)
    stages = ctx.stages(3)
    stages.start(
        "zones", f"flow map, its {scene.model} model, their ceilings and floors ({n_crit} steps per tested orbit)"
    )
    fm = flowmap(scene)
    tm = fm.truncated(forcing=scene.model)
    fzone = impact_zone(fm, n_steps=n_crit)
    # The model has no floor of its own: it is measured in the flow's zone coordinate, between its
    # own critical curve and the flow's floor (the torus tangent to the upper wall).
    mzone = impact_zone(tm, n_steps=n_crit, floor=fzone.floor)
    stages.end()
    stages.start("flow", _study_size(scene, n_scan, n_transit, "returns"))
    flow = _zone_study("flow", fm, fzone, scene, n_scan, n_transit, ctx)
    stages.end()
    stages.start("model", _study_size(scene, n_scan * f, n_transit * f, "steps"))
    model = _zone_study(scene.model, tm, mzone, scene, n_scan * f, n_transit * f, ctx)
    stages.end()
    p = fm.onset
    return ImpactZoneResult(
        scene=scene,
        meta=meta,
        flow=flow,
        model=model,
        model_name=scene.model,
        onset=dict(Omega0=p.Omega0, theta_w=p.theta_w, tau0=p.tau0, tau1=p.tau1, lam=p.lam),
        b1=float(fm.forcing_coefficients()[0]),
    )


def summarize(result: ImpactZoneResult) -> dict:
    """The onset parameters, b1, and each map's study (:meth:`ZoneStudy.summary`).

    Parameters
    ----------
    result : ImpactZoneResult
        The result.

    Returns
    -------
    dict
        ``onset``, ``b1``, ``model_name``, ``flow``, ``model``.
    """
    s = dict(onset=result.onset, b1=result.b1, model_name=result.model_name)
    s["flow"], s["model"] = result.flow.summary(), result.model.summary()
    return s


def report(summary: dict) -> list:
    """The model's eps b1, then per map: classes, barriers, spanning orbits, transits.

    Parameters
    ----------
    summary : dict
        From :func:`summarize` (with the common numbers).

    Returns
    -------
    list of str
    """
    f, lines = fmt, []
    lines.append(f"  the model ({summary['model_name']} forcing) acts with eps b1, b1 = {f(summary['b1'], '.4f')}")
    for name in ("flow", "model"):
        d = summary[name]
        lines.append(
            f"  {name:>5}: {d['starts']} starts x {d['n_steps']} returns: classes {d['classes']}, "
            f"{len(d['barriers'])} barrier(s) at s = {', '.join(f(b, '.3f') for b in d['barriers']) or '-'}; "
            f"{d['spanning']} orbit(s) span s 0.1..0.9"
        )
        for direction in ("up", "down"):
            t = d[direction]
            rate = t["escape_rate"]
            lines.append(
                f"         {direction}: {t['crossed']}/{t['orbits']} crossed s {f(t['start_s'], 'g')} -> "
                f"{f(t['target_s'], 'g')} in {t['n_steps']} returns, s reached {f(t['s_reached'], '.3f')}"
                + (f", rate {f(rate[0], '.2g')} +- {f(rate[1], '.1g')}" if rate else "")
            )
    return lines


KIND = register(
    Kind(
        "impact_zone",
        ImpactZoneScene,
        ImpactZoneResult,
        compute,
        summarize,
        report,
        doc="does anything cross the impact zone? The flow and its model side by side",
        figsize=(14.0, 10.0),
        check=_check,
    )
)
