"""The orbit scenes of the truncated map (sec:truncatedmapnum): ``portrait`` (a fan of orbits from
L1 or L2, per panel) and ``critical_orbits`` (the paper's four special orbits, extra orbits, the
critical curve, zoom panels). One spec, one result and one computation serve both kinds (files
name them: one class each), declared here with the panels' readers, the summary and the report.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._enums import Region, Status, wrap
from ..._io.serial import saved_as
from ..._style import SPECIAL_COLORS, orbit_color
from ...analysis import critical_curve, rotation_number
from ..base import Geometry, OrbitSet, SceneResult, fmt, fmt_pair, orbit_rows
from ..fields import OMIT, PARAM, choice, color, custom, flag, integer, integers, pair, read, real, text, write
from ..registry import Kind, register
from ..values import check_keys, tables
from ..values import pair as pair_value
from ..values import table as table_value
from ..values import text as text_value
from ._truncated import (
    MAP_KEYS,
    MapSpec,
    TruncatedScene,
    auto_ylim,
    check_band,
    leading_curve,
    map_geometry,
    resolve_map,
)

__all__ = [
    "SPECIAL_ORBITS",
    "OrbitSpec",
    "CriticalSpec",
    "ZoomSpec",
    "PanelSpec",
    "OrbitScene",
    "OrbitPanelResult",
    "ZoomPanelResult",
    "OrbitSceneResult",
    "special_starts",
    "hovering_orbits",
    "zoom_window_critical",
    "zoom_window_islands",
    "compute",
    "summarize",
    "report",
    "PORTRAIT",
    "CRITICAL_ORBITS",
]

#: The paper's four special initial conditions (sec:truncatedmapnumact), in legend order.
SPECIAL_ORBITS = ("blue", "orange", "green", "red")


def _start(where: str, line, reading) -> None:
    """An orbit starts at an angle or on a line, not both."""
    if ("phi0" in reading.table) == ("line" in reading.table):
        raise ValueError(f"{reading.where}: give exactly one of 'phi0' (an angle) or 'line' ('L1' or 'L2')")


@saved_as("hovering.scenes.spec:OrbitSpec")
@dataclass(frozen=True)
class OrbitSpec:
    """An extra orbit of a ``critical_orbits`` panel.

    Attributes
    ----------
    label : str
        Legend label (unique in the panel).
    K0 : float
        Initial height.
    phi0 : float or None
        Initial angle, or None when the orbit starts on ``line``.
    line : {"L1", "L2"} or None
        Start on this line at height K0.
    color : str or None
        Matplotlib colour (default: the next of C5, C6, ...).
    """

    label: str = text(drawn=True)
    K0: float = real()
    phi0: float | None = real(None)
    line: str | None = choice(None, ("L1", "L2"), check=_start)
    color: str | None = color()


@saved_as("hovering.scenes.spec:CriticalSpec")
@dataclass(frozen=True)
class CriticalSpec:
    """Search of the critical curve of a panel (:func:`hovering.analysis.critical_curve`).

    Attributes
    ----------
    n_steps : int
        Iterates per tested orbit (default: the scene's, so that the critical orbit drawn is
        exactly the one that passed the test).
    K_range : tuple of float or None
        Heights searched on the line (default: the analysis module's).
    line : {"L1", "L2"}
        Search line.
    color : str
        Colour of the critical orbit.
    """

    n_steps: int = integer(lo=4, hi=10_000_000, default_from="n_steps")
    K_range: tuple | None = pair()
    line: str = choice("L1", ("L1", "L2"))
    color: str = color("C4")


def _zoom_orbits(where: str, value, reading) -> tuple:
    if not isinstance(value, list) or not value:
        raise ValueError(f"{where} must be a non-empty list of orbit labels, got {value!r}")
    return tuple(text_value(where, x) for x in value)


def _zoom_orbits_value(orbits: tuple, kind) -> object:
    return list(orbits) if orbits else OMIT


@saved_as("hovering.scenes.spec:ZoomSpec")
@dataclass(frozen=True)
class ZoomSpec:
    """A zoom panel drawn from another panel's orbits (nothing is recomputed).

    Attributes
    ----------
    of : str
        Id of the panel zoomed into.
    on : {"critical", "islands", "fixed"}
        How the window is chosen: around the dip of the critical curve below K = 0, around the
        impacting points of the ``orbits`` named, or ``xlim``/``ylim`` as given.
    orbits : tuple of str
        Orbit labels for ``on = "islands"``.
    pad : float
        Margin added on each side, as a fraction of the window found.
    xlim, ylim : tuple of float or None
        The window for ``on = "fixed"``.
    """

    of: str = text()
    on: str = choice("critical", ("critical", "islands", "fixed"))
    orbits: tuple = custom((), read=_zoom_orbits, write=_zoom_orbits_value, allowed="orbit labels of the panel")
    pad: float = real(0.5, lo=0.0, hi=5.0)
    xlim: tuple | None = pair()
    ylim: tuple | None = pair()


@saved_as("hovering.scenes.spec:PanelSpec")
@dataclass(frozen=True)
class PanelSpec:
    """One panel (axes) of an orbit scene.

    Attributes
    ----------
    id : str
        Panel tag, shown in its title ("(a)").
    map : MapSpec or None
        The map (None for a zoom panel).
    special : tuple of str
        Which of :data:`SPECIAL_ORBITS` to draw (``critical_orbits`` scenes).
    orbits : tuple of OrbitSpec
        Extra orbits.
    critical : CriticalSpec or None
        Whether (and how) to search and draw the critical curve.
    zoom : ZoomSpec or None
        Set for a zoom panel.
    n_orbits : int
        Orbits started on ``line`` (``portrait`` scenes).
    K0_range : tuple of float or None
        Their initial heights (``portrait`` scenes).
    xlim, ylim : tuple of float or None
        Axes limits (default: the full circle and the range of the orbits).
    """

    id: str
    map: MapSpec | None = None
    special: tuple = ()
    orbits: tuple = ()
    critical: CriticalSpec | None = None
    zoom: ZoomSpec | None = None
    n_orbits: int = 0
    K0_range: tuple | None = None
    xlim: tuple | None = None
    ylim: tuple | None = None


# ------------------------------------------------------------------------------------------------
# Panels: each kind of panel has its own keys; maps resolved from the scene's [map] and the panel's


_PORTRAIT_PANEL_KEYS = ("id", "eps", "golden", "n_orbits", "K0_range", "xlim", "ylim") + MAP_KEYS
_CRIT_PANEL_KEYS = ("id", "eps", "golden", "special", "orbits", "critical", "xlim", "ylim") + MAP_KEYS
_ZOOM_PANEL_KEYS = ("id", "zoom")


def _limits(pw: str, pt: dict) -> dict:
    return {k: pair_value(f"{pw}.{k}", pt[k]) for k in ("xlim", "ylim") if k in pt}


def _portrait_panel(pw: str, pt: dict, reading) -> PanelSpec:
    check_keys(pw, pt, _PORTRAIT_PANEL_KEYS, ("id", "eps"))
    m = resolve_map(pw, reading.get("map"), pt)
    keys = OrbitScene._keys  # the scene's n_orbits and K0_range are the panels' defaults: one range each
    if "K0_range" in pt:
        kr = keys["K0_range"].metadata[PARAM].read(f"{pw}.K0_range", pt["K0_range"], reading)
    else:
        kr = reading.get("K0_range")
    if kr is None:
        raise ValueError(f"{pw}: missing required key 'K0_range' (in the scene or the panel)")
    check_band(f"{pw}.K0_range", m, kr)
    n = keys["n_orbits"].metadata[PARAM]
    return PanelSpec(
        id=text_value(f"{pw}.id", pt["id"]),
        map=m,
        n_orbits=n.read(f"{pw}.n_orbits", pt["n_orbits"], reading) if "n_orbits" in pt else reading.get("n_orbits"),
        K0_range=kr,
        **_limits(pw, pt),
    )


def _zoom(zw: str, zt, reading) -> ZoomSpec:
    z = read(ZoomSpec, zw, zt, reading)
    if z.on == "islands" and not z.orbits:
        raise ValueError(f"{zw}: missing required key 'orbits' (the island orbits) for on = 'islands'")
    if z.on != "islands" and z.orbits:
        raise ValueError(f"{zw}: 'orbits' is only used with on = 'islands', got on = {z.on!r}")
    lims = [k for k in ("xlim", "ylim") if getattr(z, k) is not None]
    if z.on == "fixed" and len(lims) != 2:
        raise ValueError(
            f"{zw}: missing required key(s) {[k for k in ('xlim', 'ylim') if k not in lims]} for on = 'fixed'"
        )
    if z.on != "fixed" and lims:
        raise ValueError(f"{zw}: 'xlim'/'ylim' need on = 'fixed' (the window is otherwise chosen from the data)")
    return z


def _crit_panel(pw: str, pt: dict, reading) -> PanelSpec:
    check_keys(pw, pt, _CRIT_PANEL_KEYS, ("id", "eps"))
    m = resolve_map(pw, reading.get("map"), pt)
    special = SPECIAL_ORBITS
    if "special" in pt:
        sv = pt["special"]
        if not isinstance(sv, list):
            raise ValueError(f"{pw}.special must be a list of names from {list(SPECIAL_ORBITS)}, got {sv!r}")
        for s in sv:
            text_value(f"{pw}.special", s, SPECIAL_ORBITS)
        if len(set(sv)) != len(sv):
            raise ValueError(f"{pw}.special = {sv!r} names an orbit twice")
        special = tuple(s for s in SPECIAL_ORBITS if s in sv)
    orbits = []
    if "orbits" in pt:
        ov = pt["orbits"]
        if not isinstance(ov, list):
            raise ValueError(f"{pw}.orbits must be an array of tables ([[panels.orbits]]), got {ov!r}")
        for j, ot in enumerate(ov):
            ow = f"{pw}.orbits[{j}]"
            o = read(OrbitSpec, ow, ot, reading)
            check_band(f"{ow}.K0", m, [o.K0])
            orbits.append(o)
    critical = None
    if "critical" in pt:
        cw = f"{pw}.critical"
        ct = {} if pt["critical"] is True else pt["critical"]
        if ct is not False:
            critical = read(CriticalSpec, cw, ct, reading)
            if critical.K_range is not None:
                check_band(f"{cw}.K_range", m, critical.K_range)
    labels = list(special) + [o.label for o in orbits] + (["critical"] if critical else [])
    dup = {x for x in labels if labels.count(x) > 1}
    if dup:
        raise ValueError(
            f"{pw}: orbit label(s) {sorted(dup)} used twice (labels must be unique, and "
            f"{list(SPECIAL_ORBITS) + ['critical']} are reserved)"
        )
    if not labels:
        raise ValueError(f"{pw}: the panel draws no orbit (special = [] and no orbits or critical)")
    return PanelSpec(
        id=text_value(f"{pw}.id", pt["id"]),
        map=m,
        special=special,
        orbits=tuple(orbits),
        critical=critical,
        **_limits(pw, pt),
    )


def _check_panel_refs(where: str, panels) -> None:
    ids = [p.id for p in panels]
    dup = {x for x in ids if ids.count(x) > 1}
    if dup:
        raise ValueError(f"{where}.panels: id(s) {sorted(dup)} used twice")
    by_id = {p.id: p for p in panels}
    for i, p in enumerate(panels):
        if p.zoom is None:
            continue
        zw = f"{where}.panels[{i}].zoom"
        src = by_id.get(p.zoom.of)
        if src is None or src.zoom is not None:
            ok = [q.id for q in panels if q.zoom is None]
            raise ValueError(f"{zw}.of = {p.zoom.of!r} names no orbit panel; allowed: {ok}")
        labels = list(src.special) + [o.label for o in src.orbits] + (["critical"] if src.critical else [])
        for lab in p.zoom.orbits:
            if lab not in labels:
                raise ValueError(f"{zw}.orbits: {lab!r} is no orbit of panel {src.id!r}; allowed: {labels}")


def _read_panels(where: str, value, reading) -> tuple:
    """The panels of an orbit scene, in order (at most MAX_PANELS; zooms name orbit panels)."""
    raw = tables(where, value, "panels")
    panels = []
    for i, pt in enumerate(raw):
        pw = f"{where}[{i}]"
        pt = table_value(pw, pt)
        if reading.kind.name == "portrait":
            panels.append(_portrait_panel(pw, pt, reading))
        elif "zoom" in pt:
            check_keys(pw, pt, _ZOOM_PANEL_KEYS, ("id", "zoom"))
            panels.append(PanelSpec(id=text_value(f"{pw}.id", pt["id"]), zoom=_zoom(f"{pw}.zoom", pt["zoom"], reading)))
        else:
            panels.append(_crit_panel(pw, pt, reading))
    _check_panel_refs(reading.where, panels)
    layout = reading.values.get("layout")
    if layout is not None and layout[0] * layout[1] < len(panels):
        r, c, n = layout[0], layout[1], len(panels)
        raise ValueError(
            f"{reading.where}.layout = {reading.table['layout']!r} has {r * c} cells for {n} panels; allowed: "
            f"rows * cols >= {n}"
        )
    return tuple(panels)


def _map_table(m: MapSpec) -> dict:
    t = {"eps": m.eps, "tau0": m.tau0, "tau1": m.tau1, "lam": m.lam}
    if m.golden_c is not None:
        t["golden"] = {"c": m.golden_c, "eps": m.golden_eps}
    else:
        t.update(Omega0=m.Omega0, theta_w=m.theta_w)
    return t


def _panels_value(panels: tuple, kind) -> list:
    """The panels as their tables (maps resolved, every value written)."""
    out = []
    for pn in panels:
        if pn.zoom is not None:
            out.append({"id": pn.id, "zoom": write(pn.zoom, kind)})
            continue
        t = {"id": pn.id, **_map_table(pn.map), **{k: list(getattr(pn, k)) for k in ("xlim", "ylim") if getattr(pn, k)}}
        if kind.name == "portrait":
            t.update(n_orbits=pn.n_orbits, **({"K0_range": list(pn.K0_range)} if pn.K0_range is not None else {}))
        else:
            t["special"] = list(pn.special)
            t["orbits"] = [write(o, kind) for o in pn.orbits]
            if pn.critical is not None:
                t["critical"] = write(pn.critical, kind)
        out.append(t)
    return out


@saved_as("hovering.scenes.spec:OrbitScene")
@dataclass(frozen=True, kw_only=True)
class OrbitScene(TruncatedScene):
    """``portrait`` and ``critical_orbits`` scenes of the truncated map.

    Attributes
    ----------
    n_steps : int
        Iterates per orbit.
    n_orbits, K0_range
        Portrait files only, no fields: the panels' defaults (30 orbits; heights to give).
    layout : tuple of int or None
        ``(rows, cols)`` of the panels (default: one column).
    panels : tuple of PanelSpec
        The panels.
    rotation : str
        ``"mean"`` (the paper's rho) or ``"birkhoff"`` (weighted average).
    color_by : str
        ``"orbit"`` or ``"region"`` (portrait scenes).
    marker_size : float
        Scatter marker size.
    corner_curves : bool
        Draw the corner-singularity curves (dashed black).
    leading_curve : bool
        Draw the leading-order curve ``k_{eps,1}(phi; 0)`` / ``k_{eps,2}(phi; 0)``.
    line : str
        Start line of portrait orbits.
    """

    # Keys of a portrait's file that are no field: the defaults of its panels (written resolved).
    _keys = {
        "n_orbits": integer(30, lo=1, hi=10_000, kinds=("portrait",)),
        "K0_range": pair(None, kinds=("portrait",)),
    }

    layout: tuple | None = integers(None, names=("rows", "cols"), ranges=((1, 20), (1, 20)))
    panels: tuple = custom((), read=_read_panels, write=_panels_value, required=True, allowed="1 to 36 panels")
    rotation: str = choice("mean", ("mean", "birkhoff"), kinds=("critical_orbits",))
    color_by: str = choice("orbit", ("orbit", "region"), kinds=("portrait",))
    marker_size: float = real(0.3, lo=0.0, hi=100.0, lo_open=True)
    corner_curves: bool = flag(True)
    leading_curve: bool = flag(True, kinds=("critical_orbits",))
    line: str = choice("L1", ("L1", "L2"), kinds=("portrait",))


# ------------------------------------------------------------------------------------------------
# Results


@saved_as("hovering.scenes.results:OrbitPanelResult")
@dataclass
class OrbitPanelResult:
    """One computed orbit panel of a truncated-map scene.

    Attributes
    ----------
    id : str
        Panel tag.
    params : dict
        The map's parameters (and golden-family c, eps).
    orbits : OrbitSet
        The orbits.
    geometry : Geometry
        Lines drawn under them.
    leading : tuple or None
        ``(phi, k, label)`` of the leading-order curve k_{eps,1} / k_{eps,2}, when drawn.
    K_crit, rho_crit, band_floor : float
        Predictions eq:kcrit, eq:rhocrit and the valid band's floor.
    xlim, ylim : tuple of float
        Axes limits.
    critical : dict or None
        The critical curve found (``found``, ``K0``, ``K_min``, ...), when searched.
    """

    id: str
    params: dict
    orbits: OrbitSet
    geometry: Geometry
    leading: tuple | None
    K_crit: float
    rho_crit: float
    band_floor: float
    xlim: tuple
    ylim: tuple
    critical: dict | None = None


@saved_as("hovering.scenes.results:ZoomPanelResult")
@dataclass
class ZoomPanelResult:
    """A zoom into another panel: its window and the finer lines drawn in it.

    Attributes
    ----------
    id, of, on : str
        Panel tag, the panel zoomed into, how the window was chosen.
    window : dict
        ``xlim``, ``ylim``, ``rule`` (and the orbit(s) it was chosen from).
    geometry : Geometry
        Lines, sampled finely over the window.
    leading : tuple or None
        The leading-order curve, sampled finely.
    """

    id: str
    of: str
    on: str
    window: dict
    geometry: Geometry
    leading: tuple | None = None


@saved_as("hovering.scenes.results:OrbitSceneResult")
@dataclass(repr=False)
class OrbitSceneResult(SceneResult):
    """Result of a ``portrait`` or ``critical_orbits`` scene.

    Attributes
    ----------
    panels : list of OrbitPanelResult and ZoomPanelResult
        In the scene's order.
    """

    panels: list = field(default_factory=list)

    def _validate_loaded(self) -> None:
        super()._validate_loaded()
        if len(self.panels) != len(getattr(self.scene, "panels", ())):
            raise ValueError(f"panels: {len(self.panels)} results for the scene's {len(self.scene.panels)} panels")
        ids = []
        for i, p in enumerate(self.panels):
            if not isinstance(p, (OrbitPanelResult, ZoomPanelResult)):
                raise ValueError(f"panels[{i}] must be a panel result, got {type(p).__name__}")
            ids.append(p.id)
        for i, p in enumerate(self.panels):
            if isinstance(p, ZoomPanelResult) and not any(
                q.id == p.of and isinstance(q, OrbitPanelResult) for q in self.panels
            ):
                raise ValueError(f"panels[{i}].of = {p.of!r} names no orbit panel; panels: {ids}")

    def panel(self, id: str):
        """The panel with this id.

        Parameters
        ----------
        id : str
            Panel tag.

        Returns
        -------
        OrbitPanelResult or ZoomPanelResult
        """
        for p in self.panels:
            if p.id == id:
                return p
        raise KeyError(f"no panel {id!r}; panels: {[p.id for p in self.panels]}")


# ------------------------------------------------------------------------------------------------
# Computing


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


def _orbit_panel(scene: OrbitScene, p: PanelSpec, n_steps: int, ctx) -> tuple:
    m = p.map.build()
    critical = None
    if scene.kind == "portrait":
        K0 = np.linspace(p.K0_range[0], p.K0_range[1], p.n_orbits)
        line = m.L1 if scene.line == "L1" else m.L2
        record = ("orbit", "regions") if scene.color_by == "region" else ("orbit",)
        res = m.iterate(line(K0), K0, n_steps, record=record, **ctx.progress_kw)
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
                c = critical_curve(m, n_steps=ctx.scaled(p.critical.n_steps), **kw, **ctx.progress_kw)
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
        res = m.iterate(phi0, K0, n_steps, record=record, **ctx.progress_kw)
        rho = np.asarray(rotation_number(res, method=scene.rotation), dtype=float)
        orbits = OrbitSet.of(res, labels, colors, kinds, rho)
    band_floor = m.valid_band()[0]
    ylim = tuple(p.ylim) if p.ylim else auto_ylim(orbits.K, band_floor)
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


def compute(scene: OrbitScene, ctx) -> OrbitSceneResult:
    """The orbits of each panel (and its critical curve), then each zoom's window and finer lines.

    Parameters
    ----------
    scene : OrbitScene
        The scene.
    ctx : hovering.scenes.base.Context
        Quick run, progress, meta.

    Returns
    -------
    OrbitSceneResult
    """
    meta = ctx.meta
    n_steps = ctx.scaled(scene.n_steps)
    meta["n_steps"] = n_steps
    done, maps = {}, {}
    stages = ctx.stages(sum(p.zoom is None for p in scene.panels))
    for p in scene.panels:
        if p.zoom is None:
            n = p.n_orbits if scene.kind == "portrait" else len(p.special) + len(p.orbits)
            stages.start(f"panel {p.id}", f"{n} orbits x {n_steps} steps" + (", critical curve" if p.critical else ""))
            done[p.id], maps[p.id] = _orbit_panel(scene, p, n_steps, ctx)
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
# Summary and report


def summarize(result: OrbitSceneResult) -> dict:
    """The panels' numbers: map parameters, predictions, each orbit's row, zoom windows.

    Parameters
    ----------
    result : OrbitSceneResult
        The result.

    Returns
    -------
    dict
        ``panels``.
    """
    panels = []
    for p in result.panels:
        if isinstance(p, OrbitPanelResult):
            info = dict(
                id=p.id,
                params=p.params,
                K_crit=p.K_crit,
                rho_crit=p.rho_crit,
                band_floor=p.band_floor,
                orbits=orbit_rows(p.orbits),
                n_escaped=int(np.count_nonzero(p.orbits.status == int(Status.ESCAPED))),
                xlim=list(p.xlim),
                ylim=list(p.ylim),
                n_orbits_drawn=p.orbits.n_orbits,
            )
            if p.critical is not None:
                info["critical"] = p.critical
        else:
            info = dict(id=p.id, zoom_of=p.of, window=p.window)
        panels.append(info)
    return {"panels": panels}


def report(summary: dict) -> list:
    """The lines the command line prints of a summary's panels.

    Parameters
    ----------
    summary : dict
        From :func:`summarize` (with the common numbers).

    Returns
    -------
    list of str
    """
    f, lines = fmt, []
    for p in summary.get("panels", []):
        if "zoom_of" in p:
            w = p.get("window")
            lines.append(
                f"  panel ({p['id']}): zoom of ({p['zoom_of']}), window phi {fmt_pair(w['xlim'])}, "
                f"K {fmt_pair(w['ylim'])} [{w['rule']}]"
            )
            continue
        par = p["params"]
        extra = (
            f", golden c = {f(par['golden_c'], 'g')} at eps = {f(par['golden_eps'], 'g')}" if "golden_c" in par else ""
        )
        lines.append(
            f"  panel ({p['id']}): eps = {f(par['eps'], 'g')}, Omega0 = {f(par['Omega0'], '.5f')}, "
            f"theta_w = {f(par['theta_w'], '.5f')}{extra}; predicted K~_c = {f(p['K_crit'], '.4f')}, "
            f"rho_c = {f(p['rho_crit'], '.4f')}"
        )
        if p["orbits"] and p["orbits"][0]["kind"] == "fan":
            lines.append(
                f"    {len(p['orbits'])} orbits from K0 = {f(p['orbits'][0]['K0'], '.4g')} to "
                f"{f(p['orbits'][-1]['K0'], '.4g')}, {p['n_escaped']} escaped the band"
            )
        else:
            for o in p["orbits"]:
                hov = (
                    "hovering"
                    if o.get("hovering")
                    else ("no impact" if o.get("impacts") == 0 else f"{o.get('impacts')} impacts")
                )
                lines.append(
                    f"    {o['label']:>10}: K0 = {f(o['K0'], '+.5f')}, K_min = {f(o['K_min'], '+.5f')}, "
                    f"rho = {f(o.get('rho'), '.4f')}, {hov}, {o['status']}"
                )
        c = p.get("critical")
        if c is not None:
            if c["found"]:
                lines.append(
                    f"    critical curve: K0 = {f(c['K0'], '+.5f')}, K_min = {f(c['K_min'], '+.5f')}, "
                    f"rho = {f(c['rotation_mean'], '.4f')} (Birkhoff {f(c['rotation'], '.6f')}); predicted "
                    f"K~_c = {f(c['K_pred'], '+.4f')}, rho_c = {f(c['rotation_pred'], '.4f')}"
                )
            else:
                lines.append(f"    critical curve: not found ({c['reason']})")
    return lines


def scene_map(scene: OrbitScene):
    """The map of the scene's first orbit panel.

    Parameters
    ----------
    scene : OrbitScene
        The scene.

    Returns
    -------
    TruncatedMap
    """
    for p in scene.panels:
        if p.map is not None:  # zoom panels have none
            return p.map.build()
    raise ValueError(f"scene {scene.name!r} defines no map")


PORTRAIT = register(
    Kind(
        "portrait",
        OrbitScene,
        OrbitSceneResult,
        compute,
        summarize,
        report,
        family="truncated",
        doc="orbits of the truncated map started on L1 or L2, per panel (fig:smallepsmany)",
        sets={"leading_curve": False},
        scene_map=scene_map,
    )
)
CRITICAL_ORBITS = register(
    Kind(
        "critical_orbits",
        OrbitScene,
        OrbitSceneResult,
        compute,
        summarize,
        report,
        family="truncated",
        doc="the paper's special orbits, the critical curve and zooms (fig:smalleps, fig:hoverinnc, fig:epsbig)",
        scene_map=scene_map,
    )
)
