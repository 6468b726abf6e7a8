"""Scene spec -> typed result: the only place a scene simulates anything.

Each kind computes exactly what its figure and report show: orbits with the records the figure
colours by, the lines drawn under them (L1, L2, corner curves, the leading-order curve), zoom
windows, theory curves. Drawing (:mod:`hovering.plot`) never computes. Flow scenes build their
system from the scene's own ``[system]``, ``[section]``, ``[integrator]`` and ``[outputs]``
tables, so what a scene does not name is not simulated: geometry "none" has no wall events,
eps = 0 no coupling, no "regions" no crossing bookkeeping, no "trajectory" no dense output.
"""

from __future__ import annotations

import logging
import math
import os
import time
from collections.abc import Callable

import numpy as np

from .._enums import FlowStatus, Region, Status, wrap
from .._progress import check_progress, progress_bar
from .._style import SPECIAL_COLORS, orbit_color
from .._version import __version__
from ..analysis import rotation_number
from ..analysis.barriers import barrier_scan
from ..analysis.transit import transit
from ..analysis.zone import impact_zone
from ..diagnostics.work_precision import _reverse
from ..flow.section import Section
from ..normal.coordinates import TangentialCurve
from ..normal.corners import corner_curves
from ..normal.flowmap import FlowMap
from ..parallel.checkpoint import Checkpoint, check_row
from ..parallel.executor import Executor, from_old_arguments, run_pieces
from ..parallel.executor import executor as open_executor
from ..truncated.maps import TruncatedFamily, TruncatedMap
from ..truncated.theory import golden_family, hovering_area_theory
from .plan import build_system, plan_points, point_key
from .results import (
    CornerDirectionsResult,
    CornerTrajectory,
    FlowHoveringResult,
    FlowPortraitResult,
    Geometry,
    HoveringAreaResult,
    ImpactZoneResult,
    OrbitPanelResult,
    OrbitSceneResult,
    OrbitSet,
    SceneResult,
    SeriesResult,
    SigmaStructureResult,
    TangentToriResult,
    TorusResult,
    WallPoint,
    WallSectionResult,
    WallSegment,
    WallTangencyResult,
    ZoneStudy,
    ZoomPanelResult,
)
from .spec import (
    QUICK_FACTOR,
    CornerDirectionsScene,
    FlowHoveringScene,
    FlowPortraitScene,
    HoveringAreaScene,
    ImpactZoneScene,
    OrbitScene,
    PanelSpec,
    SceneSpec,
    SigmaStructureScene,
    TangentToriScene,
    WallSectionScene,
    WallTangencyScene,
)
from .wall import (
    DIRECTIONS,
    WallFlow,
    corner_energy,
    corner_speed,
    corner_states,
    rho_w_max,
    tangent_action,
    wall_states,
    wall_tangency_action,
)

__all__ = [
    "compute",
    "map_geometry",
    "flow_geometry",
    "zoom_window_critical",
    "zoom_window_islands",
    "leading_curve",
    "special_starts",
    "hovering_orbits",
    "scaled",
    "scene_map",
]

_log = logging.getLogger(__name__)


class _Stages:
    """The stages of one scene's computation: each timed into ``meta["timings"]`` and logged at INFO
    (what ``hovering -v`` shows) when it starts, with what it computes and how much, and when it
    ends, with its time: ``scene impact-zone: stage 2/3 flow: barrier scan 480 orbits x 10000
    returns, transits 2 x 64 orbits x 10000 returns`` ... ``scene impact-zone: stage 2/3 flow done,
    12.3 s``. The library only logs; the command line decides what is shown."""

    def __init__(self, meta: dict, total: int):
        self.meta, self.total, self.number = meta, total, 0
        self.name, self.t = "", 0.0

    def start(self, name: str, what: str = "") -> None:
        self.number, self.name, self.t = self.number + 1, name, time.perf_counter()
        _log.info(
            "scene %s: stage %d/%d %s%s", self.meta["name"], self.number, self.total, name, f": {what}" if what else ""
        )

    def end(self) -> float:
        dt = time.perf_counter() - self.t
        self.meta["timings"][self.name] = dt
        _log.info("scene %s: stage %d/%d %s done, %.1f s", self.meta["name"], self.number, self.total, self.name, dt)
        return dt


def scaled(n: int, quick: bool, floor: int = 100) -> int:
    """An iterate count divided by :data:`QUICK_FACTOR` in quick runs (at least ``floor``).

    Parameters
    ----------
    n : int
        The scene's count.
    quick : bool
        Quick run.
    floor : int, optional
        Smallest count of a quick run.

    Returns
    -------
    int
    """
    return max(n // QUICK_FACTOR, min(floor, n)) if quick else n


def _progress_kw(progress) -> dict:
    # Only passed when asked, so a map without a progress argument still runs silently.
    return {"progress": progress} if progress else {}


# ------------------------------------------------------------------------------------------------
# Lines drawn under orbits


def map_geometry(m, K_range, n: int = 400, corner_curves: bool = True, lines: bool = True) -> Geometry:
    """K = 0, L1, L2 and the corner curves of a truncated map (closed forms) over ``K_range``.

    Parameters
    ----------
    m : TruncatedMap or TruncatedFamily
        The map.
    K_range : (float, float)
        Heights drawn (clipped to the map's band).
    n : int, optional
        Samples per line.
    corner_curves, lines : bool, optional
        What is drawn.

    Returns
    -------
    Geometry
    """
    lo = m.valid_band()[0]
    K = np.linspace(max(K_range[0], lo * (1 - 1e-9)), K_range[1], n)
    Kn = K[K < 0]
    corners = {}
    if corner_curves and Kn.size:
        cc = m.corner_curves(Kn)
        corners = {k: np.asarray(cc[k], dtype=float) for k in ("01", "1R", "R0")}
    return Geometry(
        K=K,
        L1=np.asarray(m.L1(K), dtype=float) if lines else None,
        L2=np.asarray(m.L2(K), dtype=float) if lines else None,
        K_corner=Kn,
        corners=corners,
    )


def flow_geometry(fm, K_range, n_circles: int, rtol: float, n: int = 200) -> Geometry:
    """K = 0, L1, L2 of a FlowMap and its corner curves measured on ``n_circles`` circles K < 0.

    Parameters
    ----------
    fm : FlowMap
        The flow's map (normal coordinates, geometry "step").
    K_range : (float, float)
        Heights drawn.
    n_circles : int
        Circles on which the corner curves are bisected (0: none).
    rtol : float
        Integration tolerance of the measurement.
    n : int, optional
        Samples of L1, L2.

    Returns
    -------
    Geometry
    """
    lo = fm.valid_band()[0]
    K = np.linspace(max(K_range[0], 0.95 * lo), K_range[1], n)
    corners, Kc = {}, np.zeros(0)
    if n_circles > 0 and K_range[0] < 0:
        top = min(K_range[1], 0.0)
        Kc = np.linspace(max(K_range[0], 0.95 * lo), top, n_circles + 1)[:-1] if top > K_range[0] else Kc
        if Kc.size:
            cc = corner_curves(fm.section, Kc, fm.curve, n_phi=256, bisections=30, rtol=max(rtol, 1e-13))
            corners = {"01": cc.phi_01, "1R": cc.phi_1R, "R0": cc.phi_R0}
    return Geometry(
        K=K,
        L1=np.asarray(fm.L1(K), dtype=float),
        L2=np.asarray(fm.L2(K), dtype=float),
        K_corner=Kc,
        corners=corners,
        measured=True,
    )


def leading_curve(m, n: int = 721, window: tuple | None = None) -> tuple:
    """The leading-order upper critical curve: ``k_{eps,1}(phi; 0)`` (eps >= 0) or ``k_{eps,2}`` (eps < 0).

    Parameters
    ----------
    m : TruncatedMap
        The map.
    n : int, optional
        Samples.
    window : (float, float), optional
        Angles sampled (default the whole circle).

    Returns
    -------
    tuple
        ``(phi, k, label)``.
    """
    lo, hi = window if window is not None else (-np.pi, np.pi)
    phi = np.linspace(lo, hi, n)
    if m.eps >= 0:
        return phi, np.asarray(m.k_eps1(phi, 0.0)), r"$k_{\varepsilon,1}(\phi;K_0=0)$ (leading order)"
    return phi, np.asarray(m.k_eps2(phi, 0.0)), r"$k_{\varepsilon,2}(\phi;K_0=0)$ (leading order)"


# ------------------------------------------------------------------------------------------------
# Truncated-map orbit scenes


def special_starts(m, names) -> list:
    """Initial points of the paper's special orbits (sec:truncatedmapnumact).

    Parameters
    ----------
    m : TruncatedMap
        The map.
    names : sequence of str
        From :data:`~hovering.scenes.SPECIAL_ORBITS`.

    Returns
    -------
    list of (float, float)
    """
    Kc = m.K_crit()
    K = {"blue": Kc, "orange": Kc + 0.05 * abs(m.eps), "green": 0.0, "red": 0.0}
    return [(m.L2(0.0) if n == "red" else m.L1(K[n]), K[n]) for n in names]


def hovering_orbits(orbits: OrbitSet) -> np.ndarray:
    """Per orbit: all steps taken, never in J_1, J_R (or 2+ impacts), and some point below K = 0.

    Parameters
    ----------
    orbits : OrbitSet
        Orbits recorded with regions.

    Returns
    -------
    ndarray of bool
    """
    reg = orbits.region
    imp = np.any((reg == int(Region.UPPER)) | (reg == int(Region.RIGHT)) | (reg == int(Region.MULTI)), axis=1)
    return (orbits.status == int(Status.OK)) & ~imp & (np.nanmin(orbits.K, axis=1) < 0)


def _auto_ylim(K, band_floor: float, pad: float = 0.05) -> tuple:
    """Heights of all finite orbit points (and K = 0), widened by ``pad``, inside the band."""
    K = np.asarray(K)
    lo = min(float(np.nanmin(K)), 0.0)
    hi = max(float(np.nanmax(K)), 0.0)
    d = pad * (hi - lo) if hi > lo else 0.1
    return (max(lo - d, band_floor), hi + d)


def _clip_x(lo: float, hi: float) -> list:
    return [max(lo, -np.pi), min(hi, np.pi)]


def zoom_window_critical(orbits: OrbitSet, m, pad: float = 0.5) -> dict:
    """Window around the dip of the critical curve below K = 0 (the hovering set).

    The critical orbit is the panel's numerically found critical curve if it hovers, else the
    hovering orbit with the lowest minimum. The window spans the angles where that orbit lies
    below K = 0 and the heights ``[K_min, 0]``, each widened by ``pad`` times its size on both
    sides; with no hovering orbit, the predicted dip at ``K~_c``, ``phi = L1(0) +- theta_w``.

    Parameters
    ----------
    orbits : OrbitSet
        The zoomed panel's orbits (recorded with regions).
    m : TruncatedMap
        Its map.
    pad : float, optional
        Margin on each side as a fraction of the dip's width and depth.

    Returns
    -------
    dict
        ``xlim``, ``ylim``, ``rule`` and ``orbit`` (the label used, or None).
    """
    hov = hovering_orbits(orbits)
    kinds = np.array(orbits.kinds)
    Kmin = np.nanmin(orbits.K, axis=1)
    if np.any(hov & (kinds == "critical")):
        i = int(np.flatnonzero(hov & (kinds == "critical"))[0])
    elif hov.any():
        i = int(np.flatnonzero(hov)[np.argmin(Kmin[hov])])
    else:
        c, Kc = m.L1(0.0), min(m.K_crit(), -0.05 * abs(m.eps))
        w, h = 2 * m.theta_w, -Kc
        return dict(
            xlim=_clip_x(c - m.theta_w - pad * w, c + m.theta_w + pad * w),
            ylim=[Kc - pad * h, pad * h],
            rule="predicted dip (no hovering orbit)",
            orbit=None,
        )
    phi, K = orbits.phi[i], orbits.K[i]
    ok = np.isfinite(K)
    phi, K = phi[ok], K[ok]
    j = int(np.argmin(K))
    d = wrap(phi - phi[j])
    below = K < 0
    a, b = float(d[below].min()), float(d[below].max())
    w, h = b - a, -float(K[j])
    x0 = float(phi[j])
    return dict(
        xlim=_clip_x(x0 + a - pad * w, x0 + b + pad * w),
        ylim=[-h - pad * h, pad * h],
        rule=f"dip of orbit '{orbits.labels[i]}' below K=0, pad {pad:g}",
        orbit=orbits.labels[i],
    )


def zoom_window_islands(orbits: OrbitSet, names, pad: float = 0.3) -> dict:
    """Bounding box of the impacting points (J_1, J_R) of the named island orbits.

    Parameters
    ----------
    orbits : OrbitSet
        The zoomed panel's orbits (recorded with regions).
    names : sequence of str
        Labels of the island orbits.
    pad : float, optional
        Margin on each side as a fraction of the box size.

    Returns
    -------
    dict
        ``xlim``, ``ylim``, ``rule`` and ``orbits``.
    """
    idx = [orbits.labels.index(o) for o in names]
    phis, Ks = [], []
    for i in idx:
        n = int(orbits.steps_done[i])
        reg = orbits.region[i, :n]
        sel = (reg == int(Region.UPPER)) | (reg == int(Region.RIGHT))
        phis.append(orbits.phi[i, :n][sel])
        Ks.append(orbits.K[i, :n][sel])
    phi, K = np.concatenate(phis), np.concatenate(Ks)
    rule = f"impacting points of {list(names)}, pad {pad:g}"
    if phi.size == 0:
        phi = np.concatenate([orbits.phi[i][np.isfinite(orbits.phi[i])] for i in idx])
        K = np.concatenate([orbits.K[i][np.isfinite(orbits.K[i])] for i in idx])
        rule = f"all points of {list(names)} (none impacts), pad {pad:g}"
    c = float(np.angle(np.mean(np.exp(1j * phi))))
    d = wrap(phi - c)
    a, b = c + float(d.min()), c + float(d.max())
    w, h = b - a, float(K.max() - K.min())
    return dict(
        xlim=_clip_x(a - pad * w, b + pad * w),
        ylim=[float(K.min()) - pad * h, float(K.max()) + pad * h],
        rule=rule,
        orbits=list(names),
    )


def _orbit_panel(scene: OrbitScene, p: PanelSpec, n_steps: int, quick: bool, progress) -> tuple:
    m = p.map.build()
    critical = None
    if scene.kind == "portrait":
        K0 = np.linspace(p.K0_range[0], p.K0_range[1], p.n_orbits)
        line = m.L1 if scene.line == "L1" else m.L2
        record = ("orbit", "regions") if scene.color_by == "region" else ("orbit",)
        res = m.iterate(line(K0), K0, n_steps, record=record, **_progress_kw(progress))
        orbits = OrbitSet.of(
            res, [f"K0={k:.4g}" for k in K0], [orbit_color(i) for i in range(p.n_orbits)], ["fan"] * p.n_orbits
        )
    else:
        starts = special_starts(m, p.special)
        labels, colors, kinds = list(p.special), [SPECIAL_COLORS[n] for n in p.special], list(p.special)
        for j, o in enumerate(p.orbits):
            phi0 = o.phi0 if o.phi0 is not None else (m.L1(o.K0) if o.line == "L1" else m.L2(o.K0))
            starts.append((phi0, o.K0))
            labels.append(o.label)
            colors.append(o.color or orbit_color(j, 5))
            kinds.append("extra")
        if p.critical is not None:
            kw = {"line": p.critical.line}
            if p.critical.K_range is not None:
                kw["K_range"] = p.critical.K_range
            try:
                c = m.critical_curve(n_steps=scaled(p.critical.n_steps, quick), **kw, **_progress_kw(progress))
            except RuntimeError as e:
                critical = dict(found=False, reason=str(e))
            else:
                critical = dict(
                    found=True,
                    K0=c.K0,
                    K_min=c.K_min,
                    rotation=c.rotation,
                    rotation_mean=c.rotation_mean,
                    K_pred=c.K_pred,
                    rotation_pred=c.rotation_pred,
                    digits=c.digits,
                )
                line = m.L1 if p.critical.line == "L1" else m.L2
                starts.append((line(c.K0), c.K0))
                labels.append("critical")
                colors.append(p.critical.color)
                kinds.append("critical")
        phi0 = np.array([s[0] for s in starts], dtype=float)
        K0 = np.array([s[1] for s in starts], dtype=float)
        record = ("orbit", "regions", "rotation") if scene.rotation == "mean" else ("orbit", "regions")
        res = m.iterate(phi0, K0, n_steps, record=record, **_progress_kw(progress))
        rho = np.asarray(rotation_number(res, method=scene.rotation), dtype=float)
        orbits = OrbitSet.of(res, labels, colors, kinds, rho)
    band_floor = m.valid_band()[0]
    ylim = tuple(p.ylim) if p.ylim else _auto_ylim(orbits.K, band_floor)
    xlim = tuple(p.xlim) if p.xlim else (-np.pi, np.pi)
    geom = map_geometry(m, ylim, corner_curves=scene.corner_curves)
    lead = leading_curve(m) if scene.leading_curve else None
    panel = OrbitPanelResult(
        id=p.id,
        params=p.map.as_dict(),
        orbits=orbits,
        geometry=geom,
        leading=lead,
        K_crit=float(m.K_crit()),
        rho_crit=float(m.rho_crit()),
        band_floor=float(band_floor),
        xlim=xlim,
        ylim=ylim,
        critical=critical,
    )
    return panel, m


def _orbit_scene(scene: OrbitScene, quick: bool, progress, meta: dict) -> OrbitSceneResult:
    n_steps = scaled(scene.n_steps, quick)
    meta["n_steps"] = n_steps
    done, maps = {}, {}
    stages = _Stages(meta, sum(p.zoom is None for p in scene.panels))
    for p in scene.panels:
        if p.zoom is None:
            n = p.n_orbits if scene.kind == "portrait" else len(p.special) + len(p.orbits)
            stages.start(f"panel {p.id}", f"{n} orbits x {n_steps} steps" + (", critical curve" if p.critical else ""))
            done[p.id], maps[p.id] = _orbit_panel(scene, p, n_steps, quick, progress)
            stages.end()
    panels = []
    for p in scene.panels:
        if p.zoom is None:
            panels.append(done[p.id])
            continue
        src, m, z = done[p.zoom.of], maps[p.zoom.of], p.zoom
        if z.on == "critical":
            w = zoom_window_critical(src.orbits, m, z.pad)
        elif z.on == "islands":
            w = zoom_window_islands(src.orbits, z.orbits, z.pad)
        else:
            w = dict(xlim=list(z.xlim), ylim=list(z.ylim), rule="fixed")
        geom = map_geometry(m, tuple(w["ylim"]), n=1200, corner_curves=scene.corner_curves)
        lead = leading_curve(m, n=2001) if scene.leading_curve else None
        panels.append(ZoomPanelResult(id=p.id, of=z.of, on=z.on, window=w, geometry=geom, leading=lead))
    return OrbitSceneResult(scene=scene, meta=meta, panels=panels)


# ------------------------------------------------------------------------------------------------
# Truncated-map |HOV| against eps


def _theory_line(spec, eps_all: np.ndarray) -> tuple:
    e_hi = max(float(eps_all.max()), 0.0)
    e_lo = min(float(eps_all.min()), 0.0)
    eg = np.linspace(0.0, e_hi, 200)[1:]
    if spec.golden_c is not None:
        tg = np.array(
            [hovering_area_theory(x, tw, O) for x in eg for O, tw in [golden_family(x, spec.golden_c, spec.tau0)]]
        )
    else:
        tg = np.asarray(hovering_area_theory(eg, spec.theta_w, spec.Omega0), dtype=float)
    return np.concatenate([[e_lo, 0.0], eg]), np.concatenate([[0.0, 0.0], tg])


def run_point(kind: str, point: dict, n_threads: int = 0) -> dict:
    """Measure one point of a resolved sweep plan (:func:`hovering.scenes.plan.plan_points`).

    The same core functions, on the same numbers, as ``hovering_sweep`` (cpp/src/hovering/sweep/
    run.cpp): the rows of the two programs are the same doubles (but ``seconds``), and each
    resumes the other's checkpoint. A piece: it runs in any process.

    Parameters
    ----------
    kind : {"hovering_area", "flow_hovering_area"}
        The plan's kind.
    point : dict
        A plan point.
    n_threads : int, optional
        Core threads (0 = all cores).

    Returns
    -------
    dict
        The row: the estimate's fields (``area``, ``error``, ``sampling_error``,
        ``iteration_error``, ``area_N4``, ``area_N2``, ``area_both_sides``, ``impact_fraction_F0``,
        ``floor_touched``, ``unresolved``, ``n_samples``, ``K_low``), ``theory`` (carried),
        ``seconds``; a flow point also ``b1`` (carried) and ``models`` (per model: ``area``,
        ``error``, ``agree``, ``K_low``).
    """
    t = time.perf_counter()
    # A row holds the estimate, not its split: the split's orbit classes and the flow's floor search
    # would cost a sweep point up to 1.5 s for nothing it shows.
    kw = dict(
        n_steps=point["n_steps"], n_samples=point["samples"], rng=point["seed"], n_threads=n_threads, components=False
    )
    if kind == "hovering_area":
        h = TruncatedMap(**point["map"]).hovering_area(K_low=point["K_low"], **kw)
        row = _area_row(h)
    else:
        fm = FlowMap(build_system(point["system"]), h=point["h"], **point["integrator"])
        h = fm.hovering_area(K_low=point["K_low"], keep_points=bool(point["models"]), **kw)
        row = _area_row(h)
        row["b1"] = point["b1"]
        row["models"] = {}
        for m in point["models"]:
            tm = TruncatedFamily._from_record({k: m[k] for k in ("eps", "K", "Omega", "JR", "J1", "forcing", "K_max")})
            mh = tm.hovering_area(K_low=m["K_low"], keep_points=True, **kw)
            # A model sampling another box (its band is shallower) classifies other points: no agreement.
            agree = float(np.mean(mh.hovering == h.hovering)) if m["K_low"] == point["K_low"] else float("nan")
            row["models"][m["name"]] = dict(area=mh.area, error=mh.error, agree=agree, K_low=m["K_low"])
    row["theory"] = point["theory"]
    row["seconds"] = time.perf_counter() - t
    return row


def _area_row(h) -> dict:
    N = sorted(h.areas)
    return dict(
        area=h.area,
        error=h.error,
        sampling_error=h.sampling_error,
        iteration_error=h.iteration_error,
        area_N4=h.areas[N[0]],
        area_N2=h.areas[N[1]],
        area_both_sides=h.area_both_sides,
        impact_fraction_F0=h.impact_fraction_F0,
        floor_touched=bool(h.floor_touched),
        unresolved=int(h.unresolved),
        n_samples=int(h.n_samples),
        K_low=float(h.box[2]),
    )


#: The fields of a point's row that the sweeps read (what a checkpointed row must have).
_ROW = dict(
    area=float,
    error=float,
    sampling_error=float,
    iteration_error=float,
    area_N4=float,
    area_N2=float,
    area_both_sides=float,
    impact_fraction_F0=float,
    floor_touched=bool,
    unresolved=int,
    n_samples=int,
    K_low=float,
    theory=float,
    seconds=float,
)
_MODEL_ROW = dict(area=float, error=float, agree=float, K_low=float)


def _row_check(kind: str, point: dict) -> Callable:
    """A check of a checkpointed row (untrusted): the fields its reader takes, and the point's own box."""
    fields = dict(_ROW)
    if kind == "flow_hovering_area":
        fields.update(b1=float, models=(tuple(m["name"] for m in point["models"]), _MODEL_ROW))

    def check(row):
        check_row(row, fields)
        if row["K_low"] != point["K_low"]:
            raise ValueError(f"row.K_low = {row['K_low']!r} is not the point's K_low = {point['K_low']!r}")

    return check


def _sweep_size(points: list, where) -> str:
    """What a sweep computes, for its log line: points, samples x steps per point, where."""
    p = points[0]
    models = f" + {len(p['models'])} model(s)" if p.get("models") else ""
    if where is None:
        place = "in this process"
    elif where.scheduler is not None:
        place = f"on the Dask scheduler at {where.scheduler}"
    elif where.client is not None:
        place = "on a Dask client"
    elif where.pool is not None:
        place = "on the caller's pool"
    else:
        place = f"{where.workers} at a time on {'a Dask LocalCluster' if where.dask else 'threads'}"
    return f"{len(points)} points of {p['samples']} samples x {p['n_steps']} steps{models}, {place}"


def _point_label(point: dict) -> str:
    eps = point["map"]["eps"] if "map" in point else point["system"]["eps"]
    return f"eps = {eps:g}"


def _sweep(kind: str, points: list, ckpt, bar, where: Executor | None, name: str = "") -> tuple:
    """Rows of a plan's points in order: from the checkpoint (each row checked first: the file is
    untrusted), or computed (here, or as pieces on the executor ``where``) and
    checkpointed as each arrives (a point another process wrote meanwhile is not written again).
    Returns (rows, reused: one bool per point, True where the checkpoint had it). Each point is
    logged at INFO as it arrives (``name``: the scene's, for the line)."""
    keys = [point_key(kind, p) for p in points]
    rows = [ckpt.get(k, _row_check(kind, p)) for k, p in zip(keys, points)]
    reused = [r is not None for r in rows]
    bar.advance(sum(reused))
    todo = [i for i, r in enumerate(rows) if r is None]
    _log.info(
        "scene %s: %d of %d points from the checkpoint %s, %d to compute", name, sum(reused), len(points),
        ckpt.path, len(todo),
    )  # fmt: skip

    def done(j, row):
        i = todo[j]
        ckpt.put(keys[i], row)
        rows[i] = ckpt.get(keys[i]) if keys[i] in ckpt else row  # another process's row, if it was first
        bar.advance(1)
        _log.info(
            "scene %s: point %d/%d (%s) area %.4g +- %.2g, %.1f s", name, i + 1, len(points),
            _point_label(points[i]), rows[i]["area"], rows[i]["error"], rows[i]["seconds"],
        )  # fmt: skip

    if where is not None:
        with open_executor(**where.where()) as ex:
            # Each point keeps the core's threads (all cores): sweep points differ in cost (1-25 s per
            # eps of the flow scene), and one thread per point on a shared machine left the costliest
            # point alone at the end (66 s vs 50 s for flow_hov_vs_eps on 2 workers here).
            for _ in run_pieces(ex, _call, [(run_point, (kind, points[i])) for i in todo], on_result=done):
                pass
    else:
        for j, i in enumerate(todo):
            ckpt.refresh()
            if keys[i] in ckpt:  # finished by another process meanwhile (hovering_sweep on the same file)
                rows[i] = ckpt.get(keys[i], _row_check(kind, points[i]))
                reused[i] = True
                bar.advance(1)
                continue
            done(j, run_point(kind, points[i]))
    return rows, reused


def _call(fn, args):
    return fn(*args)


def _hovering_scene(
    scene: HoveringAreaScene, quick: bool, progress, meta: dict, checkpoint, where=None
) -> HoveringAreaResult:
    points = plan_points(scene, quick)
    meta.update(n_steps=points[0]["n_steps"], samples=points[0]["samples"])
    # Each measured point is on disk at once; a rerun resumes where an interrupted one stopped and
    # recomputes nothing already measured (keys hold every parameter that changes a point).
    ckpt = Checkpoint(checkpoint)
    meta["checkpoint"] = str(ckpt.path)
    eps_all = np.array(scene.eps)
    stages = _Stages(meta, 1)
    stages.start("sweep", _sweep_size(points, where))
    with progress_bar(progress, total=len(points), desc=scene.name, unit="point") as bar:
        all_rows, from_ckpt = _sweep(scene.kind, points, ckpt, bar, where, scene.name)
    stages.end()
    drawn = set()
    out = []
    ne = len(scene.eps)
    for k, s in enumerate(scene.series):
        rows = all_rows[k * ne : (k + 1) * ne]
        pts = points[k * ne : (k + 1) * ne]
        reused = sum(from_ckpt[k * ne : (k + 1) * ne])
        fam = (s.golden_c, s.Omega0, s.theta_w, s.tau0)
        te, tc = _theory_line(s, eps_all) if fam not in drawn else (np.zeros(0), np.zeros(0))
        drawn.add(fam)
        col = lambda c, dt=float: np.array([r[c] for r in rows], dtype=dt)  # noqa: E731
        par = lambda c: np.array([p["map"][c] for p in pts], dtype=float)  # noqa: E731
        out.append(
            SeriesResult(
                label=s.label,
                color=s.color or orbit_color(k),
                eps=par("eps"),
                area=col("area"),
                error=col("error"),
                theory=col("theory"),
                floor_touched=col("floor_touched", bool),
                K_low=col("K_low"),
                Omega0=par("Omega0"),
                theta_w=par("theta_w"),
                theory_eps=te,
                theory_curve=tc,
                golden_c=s.golden_c,
                reused=reused,
            )
        )
    meta["points_reused"] = sum(from_ckpt)
    return HoveringAreaResult(scene=scene, meta=meta, series=out)


# ------------------------------------------------------------------------------------------------
# The physical flow


def _flowmap(scene, eps: float | None = None, coordinates: str = "normal"):
    return FlowMap(scene.system.build(eps=eps), h=scene.h, coordinates=coordinates, **scene.integrator.options())


def _work(res) -> dict:
    w = getattr(res, "work", None)
    return {} if w is None else {k: int(v) for k, v in dict(w).items()}


def _flow_portrait(scene: FlowPortraitScene, quick: bool, progress, meta: dict) -> FlowPortraitResult:
    n = scaled(scene.n_steps, quick, floor=50)
    meta["n_steps"] = n
    stages = _Stages(meta, 5)
    stages.start("setup", f"flow map (tangential curve, forcing) and its {scene.model} model")
    fm = _flowmap(scene)
    tm = fm.truncated(forcing=scene.model)
    stages.end()
    K0 = np.linspace(scene.K0_range[0], scene.K0_range[1], scene.n_orbits)
    phi0 = np.asarray(fm.L1(K0), dtype=float)
    regions = "regions" in scene.outputs.record
    record = ("orbit", "regions") if regions else ("orbit",)
    labels = [f"K0={k:.4g}" for k in K0]
    colors = [orbit_color(i) for i in range(scene.n_orbits)]
    stages.start("flow", f"{scene.n_orbits} orbits x {n} returns")
    fres = fm.iterate(phi0, K0, n, record=record, **_progress_kw(progress))
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
    lo = min(_auto_ylim(flow.K, floor)[0], _auto_ylim(model.K, floor)[0])
    hi = max(_auto_ylim(flow.K, floor)[1], _auto_ylim(model.K, floor)[1])
    stages.start("corner curves", f"{scene.corner_K} circles")
    fg = flow_geometry(fm, (lo, hi), scene.corner_K, fm.integrator_options.get("rtol", 1e-10))
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
        work=_work(fres),
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


def _flow_hovering(
    scene: FlowHoveringScene, quick: bool, progress, meta: dict, checkpoint, where=None
) -> FlowHoveringResult:
    points = plan_points(scene, quick)
    meta.update(n_steps=points[0]["n_steps"], samples=points[0]["samples"])
    ckpt = Checkpoint(checkpoint)
    meta["checkpoint"] = str(ckpt.path)
    stages = _Stages(meta, 1)
    stages.start("sweep", _sweep_size(points, where))
    with progress_bar(progress, total=len(points), desc=scene.name, unit="eps") as bar:
        rows, from_ckpt = _sweep(scene.kind, points, ckpt, bar, where, scene.name)
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


def _circle(V, e: float, n: int) -> tuple:
    """The level ``V(q) + p^2/2 = e`` as a closed curve, by the potential's own angle variable."""
    th = np.linspace(-np.pi, np.pi, n)
    qp = np.array([V.point_at(float(t), e) for t in th])
    return qp[:, 0], qp[:, 1]


def _tangent_tori(scene: TangentToriScene, quick: bool, progress, meta: dict) -> TangentToriResult:
    sys = scene.system.build()
    h = scene.h
    h1w, h2w = float(sys.V1.V(sys.qw1)), float(sys.V2.V(sys.qw2))
    fm = _flowmap(scene, coordinates="section")
    tori = []
    stages = _Stages(meta, 2)
    for name, h1, color in (("right", h1w, "C0"), ("upper", h - h2w, "C3")):
        stages.start(f"torus {name}", f"1 orbit x {scene.n_returns} returns with its trajectory")
        h2 = h - h1
        q1, p1 = _circle(sys.V1, h1, scene.n_points)
        q2, p2 = _circle(sys.V2, h2, scene.n_points)
        # A point of Sigma_h on this torus: (theta, I) with H2(I) = h2; theta = 0 (p2 = 0, q2 at
        # its maximum) starts the segment at a clean corner of the configuration-space box.
        I = float(sys.V2.action(h2))
        res = fm.iterate(
            [0.0],
            [I],
            scene.n_returns,
            record=("trajectory",),
            trajectory_dt=scene.outputs.trajectory_dt,
            **_progress_kw(progress),
        )
        meta.setdefault("status", {})[name] = Status(int(res.status[0])).name
        meta.setdefault("work", {})[name] = _work(res)
        stages.end()
        tori.append(
            TorusResult(
                name=name,
                h1=h1,
                h2=h2,
                q1=q1,
                p1=p1,
                q2=q2,
                p2=p2,
                trajectory=np.asarray(res.trajectory_of(0)),
                color=color,
            )
        )
    return TangentToriResult(scene=scene, meta=meta, tori=tori, qw1=sys.qw1, qw2=sys.qw2)


def _sigma_structure(scene: SigmaStructureScene, quick: bool, progress, meta: dict) -> SigmaStructureResult:
    fm = _flowmap(scene)
    nphi, nK = scene.grid
    if quick:
        nphi, nK = max(nphi // 4, 16), max(nK // 4, 4)
    meta["grid"] = [nphi, nK]
    lo = max(scene.K_range[0], 0.95 * fm.valid_band()[0])
    P, KK = np.meshgrid(-np.pi + 2 * np.pi * (np.arange(nphi) + 0.5) / nphi, np.linspace(lo, scene.K_range[1], nK))
    stages = _Stages(meta, 2)
    stages.start("returns", f"{nphi} x {nK} points, 1 return each")
    res = fm.iterate(
        P.ravel(), KK.ravel(), 1, record=("orbit", "regions", "section", "states"), **_progress_kw(progress)
    )
    stages.end()
    ok = np.isfinite(res.theta[:, 0])  # points with a point of Sigma_h
    z = res.z
    # The tangency circle K = 0 and its image (K = eps f(phi) to leading order).
    ph = np.linspace(-np.pi, np.pi, 721, endpoint=False)
    tg = fm.iterate(ph, np.zeros_like(ph), 1, record=("orbit", "section", "states"))
    tangency = dict(
        phi=ph,
        theta=tg.theta[:, 0],
        I=tg.I[:, 0],
        q2=tg.z[:, 0, 2],
        p2=tg.z[:, 0, 3],
        phi1=tg.phi[:, 1],
        K1=tg.K[:, 1],
        theta1=tg.theta[:, 1],
        I1=tg.I[:, 1],
        q21=tg.z[:, 1, 2],
        p21=tg.z[:, 1, 3],
    )
    stages.start("corner curves", f"{10 if quick else 24} circles")
    corners = flow_geometry(
        fm, (lo, min(scene.K_range[1], 0.0)), 10 if quick else 24, fm.integrator_options.get("rtol", 1e-10)
    )
    stages.end()
    return SigmaStructureResult(
        scene=scene,
        meta=meta,
        phi=res.phi[ok, 0],
        K=res.K[ok, 0],
        region=res.region[ok, 0],
        theta=res.theta[ok, 0],
        I=res.I[ok, 0],
        q2=z[ok, 0, 2],
        p2=z[ok, 0, 3],
        phi1=res.phi[ok, 1],
        K1=res.K[ok, 1],
        theta1=res.theta[ok, 1],
        I1=res.I[ok, 1],
        q21=z[ok, 1, 2],
        p21=z[ok, 1, 3],
        tangency=tangency,
        corners=corners,
    )


# ------------------------------------------------------------------------------------------------
# The corner and the wall section (fig:corner_directions, fig:Sigma_0_wall, fig:wallsection)


def _wall_flow(scene, fm=None) -> WallFlow:
    """The scene's step system and integrator settings (an accuracy target resolved by its FlowMap)."""
    if scene.integrator.accuracy is not None:
        opts = (fm if fm is not None else _flowmap(scene)).integrator_options
    else:
        opts = scene.integrator.options()
    return WallFlow(scene.system.build(), opts)


def _samples_through(T: float, dt_max: float) -> float:
    """A spacing <= dt_max that puts a trajectory sample at time T (its ceil(T / dt_max)-th)."""
    return T / max(1, math.ceil(T / dt_max))


def _corner_directions(scene: CornerDirectionsScene, quick: bool, progress, meta: dict) -> CornerDirectionsResult:
    stages = _Stages(meta, 3)
    stages.start("setup", "flow map (tangential curve)")
    fm = _flowmap(scene)  # its tangential curve gives the normal coordinates of the curves
    flow = _wall_flow(scene, fm)
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


def _wall_tangency(scene: WallTangencyScene, quick: bool, progress, meta: dict) -> WallTangencyResult:
    flow = _wall_flow(scene)
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
    stages = _Stages(meta, 2)
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


def _wall_section(scene: WallSectionScene, quick: bool, progress, meta: dict) -> WallSectionResult:
    flow = _wall_flow(scene)
    sys, h = flow.sys, scene.h
    rmax = rho_w_max(sys, h)
    rho = scene.rho_w_fraction * rmax
    n_theta = max(scene.n_theta // 4, 90) if quick else scene.n_theta
    n_circles = max(scene.n_circles // 2, 4) if quick else scene.n_circles
    meta.update(n_theta=n_theta, n_circles=n_circles)
    stages = _Stages(meta, 3)
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


def _zone_study(name, m, zone, scene: ImpactZoneScene, n_scan: int, n_transit: int, progress) -> ZoneStudy:
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
        **_progress_kw(progress),
    )
    sec["scan"] = time.perf_counter() - t
    t = time.perf_counter()
    kw = dict(n_orbits=scene.transit_orbits, n_steps=n_transit, **_progress_kw(progress))
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


def _impact_zone(scene: ImpactZoneScene, quick: bool, progress, meta: dict) -> ImpactZoneResult:
    n_scan, n_transit = scaled(scene.n_steps, quick, floor=1000), scaled(scene.transit_steps, quick, floor=200)
    n_crit = scaled(scene.critical_steps, quick, floor=2000)
    f = scene.model_factor
    meta.update(n_steps=n_scan, transit_steps=n_transit, critical_steps=n_crit)
    stages = _Stages(meta, 3)
    stages.start(
        "zones", f"flow map, its {scene.model} model, their ceilings and floors ({n_crit} steps per tested orbit)"
    )
    fm = _flowmap(scene)
    tm = fm.truncated(forcing=scene.model)
    fzone = impact_zone(fm, n_steps=n_crit)
    # The model has no floor of its own: it is measured in the flow's zone coordinate, between its
    # own critical curve and the flow's floor (the torus tangent to the upper wall).
    mzone = impact_zone(tm, n_steps=n_crit, floor=fzone.floor)
    stages.end()
    stages.start("flow", _study_size(scene, n_scan, n_transit, "returns"))
    flow = _zone_study("flow", fm, fzone, scene, n_scan, n_transit, progress)
    stages.end()
    stages.start("model", _study_size(scene, n_scan * f, n_transit * f, "steps"))
    model = _zone_study(scene.model, tm, mzone, scene, n_scan * f, n_transit * f, progress)
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


def scene_map(scene: SceneSpec):
    """The map a scene is about: an orbit scene's first panel's, a hovering-area scene's first
    series at its first eps, a flow scene's :class:`~hovering.FlowMap` (its system, section and
    integrator; a ``tangent_tori`` scene's in section coordinates).

    Parameters
    ----------
    scene : SceneSpec
        A validated scene.

    Returns
    -------
    TruncatedMap or FlowMap
    """
    if isinstance(scene, OrbitScene):
        for p in scene.panels:
            if p.map is not None:  # zoom panels have none
                return p.map.build()
    if isinstance(scene, HoveringAreaScene):
        return scene.series[0].map_at(scene.eps[0]).build()
    if isinstance(scene, FlowHoveringScene):
        return _flowmap(scene, eps=scene.eps[0])
    if isinstance(scene, TangentToriScene):
        return _flowmap(scene, coordinates="section")
    if isinstance(
        scene, (FlowPortraitScene, SigmaStructureScene, CornerDirectionsScene, WallTangencyScene, WallSectionScene)
    ):
        return _flowmap(scene)
    raise ValueError(f"scene {scene.name!r} defines no map")


# ------------------------------------------------------------------------------------------------


def compute(
    scene: SceneSpec,
    quick: bool = False,
    progress=False,
    checkpoint: os.PathLike | None = None,
    workers: int | None = None,
    client=None,
    scheduler: str | None = None,
    dask: bool = False,
    *,
    executor=None,
) -> SceneResult:
    """Run a scene's simulation and return its typed result (nothing is drawn or written).

    Parameters
    ----------
    scene : SceneSpec
        From :func:`hovering.scenes.load_scene`.
    quick : bool, optional
        Divide iterate counts (and samples) by :data:`QUICK_FACTOR` for a fast check.
    progress : bool or callable, optional
        Progress bars on stderr for the long computations (see :mod:`hovering._progress`).
    checkpoint : path-like, optional
        Sweep scenes (``hovering_area``, ``flow_hovering_area``): the JSON-lines file every
        finished point is written to at once (default: next to the scene's output).
    workers, client, scheduler, dask : optional
        Deprecated (removed in 0.4.0): the fields of ``executor=Executor(...)``; each warns.
    executor : None, int, str, distributed.Client or hovering.parallel.Executor, optional
        Sweep scenes: run the points as pieces on local worker threads (``int``), a Dask
        scheduler (address), a Dask client, or as a :class:`~hovering.parallel.Executor` says (a Dask
        LocalCluster); each point is checkpointed as it arrives and the result is the one-process
        result. Other scenes: ignored (they are one computation). A scene's pieces are its points and
        its checkpoint is ``checkpoint``: an Executor's ``pieces`` and ``checkpoint`` are refused.

    Returns
    -------
    SceneResult
        The kind's result type, with ``meta`` (version, quick, timings).
    """

    if not isinstance(scene, SceneSpec):
        raise ValueError(f"scene must be a scene spec from hovering.scenes.load_scene, got {type(scene).__name__}")
    progress = check_progress(progress)
    meta = dict(version=__version__, quick=bool(quick), kind=scene.kind, name=scene.name, timings={})
    t0 = time.perf_counter()
    _log.info("scene %s: %s%s", scene.name, scene.kind, f" (quick: counts / {QUICK_FACTOR})" if quick else "")
    ck = checkpoint if checkpoint is not None else scene.output.with_suffix(".sweep.jsonl")
    where = from_old_arguments(
        "compute",
        executor,
        dict(workers=workers, client=client, scheduler=scheduler, dask=dask),
        allowed=("workers", "client", "scheduler", "dask"),
    )
    if where is not None and (where.pieces is not None or where.checkpoint is not None):
        raise ValueError(
            "compute: a scene's points are its pieces and checkpoint= its checkpoint; give an Executor "
            "without pieces and checkpoint"
        )
    if isinstance(scene, OrbitScene):
        out = _orbit_scene(scene, quick, progress, meta)
    elif isinstance(scene, HoveringAreaScene):
        out = _hovering_scene(scene, quick, progress, meta, ck, where)
    elif isinstance(scene, FlowPortraitScene):
        out = _flow_portrait(scene, quick, progress, meta)
    elif isinstance(scene, FlowHoveringScene):
        out = _flow_hovering(scene, quick, progress, meta, ck, where)
    elif isinstance(scene, TangentToriScene):
        out = _tangent_tori(scene, quick, progress, meta)
    elif isinstance(scene, SigmaStructureScene):
        out = _sigma_structure(scene, quick, progress, meta)
    elif isinstance(scene, CornerDirectionsScene):
        out = _corner_directions(scene, quick, progress, meta)
    elif isinstance(scene, WallTangencyScene):
        out = _wall_tangency(scene, quick, progress, meta)
    elif isinstance(scene, WallSectionScene):
        out = _wall_section(scene, quick, progress, meta)
    elif isinstance(scene, ImpactZoneScene):
        out = _impact_zone(scene, quick, progress, meta)
    else:
        raise ValueError(f"no computation for scene kind {scene.kind!r}")
    meta["timings"]["total"] = time.perf_counter() - t0
    _log.info("scene %s: computed in %.1f s", scene.name, meta["timings"]["total"])
    return out
