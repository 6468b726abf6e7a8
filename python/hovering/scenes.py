"""Scene files: one TOML file per figure of the paper, validated, simulated and drawn.

A scene names a ``kind``, the map parameters, the iterate counts and an output path::

    kind = "critical_orbits"          # or "portrait", "hovering_area"
    title = "Critical curves for |eps| = 0.3 (fig:smalleps)"
    output = "out/fig_smalleps.png"
    n_steps = 50000

    [map]                             # shared by every panel (a panel may override any key)
    Omega0 = "OMEGA_G"                # numbers, or expressions of pi and OMEGA_G
    theta_w = "3*pi/4"

    [[panels]]
    id = "a"
    eps = 0.3

:func:`load_scene` checks every key at every level (an unknown, missing or bad key is a
``ValueError`` naming the key and what is allowed), :func:`run_scene` runs exactly the simulation
the scene asks for, draws it with :mod:`hovering.figures`, writes the PNG and an NPZ of the
computed orbits and numbers next to it, and returns a summary of the numbers shown.

The three kinds
---------------
``portrait``
    Orbits started evenly along L1 (or L2), one colour per orbit or per region (fig:smallepsmany).
``critical_orbits``
    The paper's four special orbits (blue ``K_0 = K~_c`` and orange ``K~_c + 0.05|eps|`` on L1,
    green on L1 and red on L2 at ``K = 0``) with their rotation numbers in the legend, optional
    extra orbits, the numerically found critical curve (:func:`hovering.analysis.critical_curve`),
    the leading-order curve ``k_{eps,1}(phi; K_0=0)`` (``k_{eps,2}`` for eps < 0) and zoom panels
    (fig:smalleps, fig:hoverinnc, fig:epsbig).
``hovering_area``
    ``|HOV(eps)|`` against eps with error bars and the leading-order theory eq:hovsetsize
    (:func:`hovering.analysis.hovering_area`).

The reference of every key is ``SCHEMA_DOC`` below and the files in ``examples/scenes``.
"""

from __future__ import annotations

import ast
import json
import math
import operator
import os
import time
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional

import numpy as np

from ._common import output_path
from .truncated.theory import OMEGA_G, golden_family
from .sweeps import Checkpoint
from .truncated.maps import TruncatedMap

__all__ = [
    "KINDS",
    "SPECIAL_ORBITS",
    "QUICK_FACTOR",
    "MapSpec",
    "OrbitSpec",
    "CriticalSpec",
    "ZoomSpec",
    "PanelSpec",
    "SeriesSpec",
    "Scene",
    "PanelResult",
    "load_scene",
    "parse_scene",
    "run_scene",
    "format_summary",
]

#: The kinds of scene.
KINDS = ("portrait", "critical_orbits", "hovering_area")

#: The paper's four special initial conditions (sec:truncatedmapnumact), in legend order.
SPECIAL_ORBITS = ("blue", "orange", "green", "red")

#: Iterate counts (and hovering-area samples) are divided by this in ``quick`` runs.
QUICK_FACTOR = 50

_MAP_KEYS = ("Omega0", "theta_w", "tau0", "tau1", "lam")
_MAP_DEFAULTS = {"tau0": 1.0, "tau1": 0.5, "lam": 0.5}
_COMMON_KEYS = ("kind", "title", "output", "dpi", "figsize", "map")


# ------------------------------------------------------------------------------------------------
# Validated scene objects


@dataclass(frozen=True)
class MapSpec:
    """Parameters of one truncated map F_eps.

    Attributes
    ----------
    eps : float
        Perturbation amplitude.
    Omega0, theta_w, tau0, tau1, lam : float
        Map parameters (``Omega0, theta_w`` from the golden family when ``golden_c`` is set).
    golden_c : float or None
        Family parameter c of thm:hoveringc, if the panel uses the golden family.
    golden_eps : float or None
        The eps at which the golden-family ``(Omega0, theta_w)`` were computed (may differ from
        ``eps``: fig:epsbig d uses the eps = 0.92 parameters at eps = -0.92).
    """

    eps: float
    Omega0: float
    theta_w: float
    tau0: float = 1.0
    tau1: float = 0.5
    lam: float = 0.5
    golden_c: Optional[float] = None
    golden_eps: Optional[float] = None

    def build(self) -> TruncatedMap:
        """The :class:`~hovering.TruncatedMap` with these parameters.

        Returns
        -------
        TruncatedMap
        """
        return TruncatedMap(self.eps, self.Omega0, self.theta_w, self.tau0, self.tau1, self.lam)

    def as_dict(self) -> dict:
        """Parameters as a plain dict (for summaries and NPZ files).

        Returns
        -------
        dict
        """
        d = dict(eps=self.eps, Omega0=self.Omega0, theta_w=self.theta_w, tau0=self.tau0, tau1=self.tau1, lam=self.lam)
        if self.golden_c is not None:
            d.update(golden_c=self.golden_c, golden_eps=self.golden_eps)
        return d


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
        Matplotlib colour (default: the next of C4, C5, ...).
    """

    label: str
    K0: float
    phi0: Optional[float] = None
    line: Optional[str] = None
    color: Optional[str] = None


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

    n_steps: int
    K_range: Optional[tuple] = None
    line: str = "L1"
    color: str = "C4"


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

    of: str
    on: str = "critical"
    orbits: tuple = ()
    pad: float = 0.5
    xlim: Optional[tuple] = None
    ylim: Optional[tuple] = None


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
    map: Optional[MapSpec] = None
    special: tuple = ()
    orbits: tuple = ()
    critical: Optional[CriticalSpec] = None
    zoom: Optional[ZoomSpec] = None
    n_orbits: int = 0
    K0_range: Optional[tuple] = None
    xlim: Optional[tuple] = None
    ylim: Optional[tuple] = None


@dataclass(frozen=True)
class SeriesSpec:
    """One curve of a ``hovering_area`` scene: a map family over the scene's eps values.

    Attributes
    ----------
    label : str
        Legend label.
    Omega0, theta_w, tau0, tau1, lam : float or None
        Fixed parameters (``Omega0, theta_w`` None when ``golden_c`` is set).
    golden_c : float or None
        Use the golden family of thm:hoveringc: ``(Omega0, theta_w)`` recomputed at each eps.
    color : str or None
        Matplotlib colour.
    K_low : float or None
        Bottom of the sampled box ``[-pi, pi) x [K_low, 0)`` (default: the analysis module's,
        ``-2|eps|/|sin(Omega0/2)|``, which holds the critical band of eq:hovsetsize); set it near
        the band floor to measure HOV by its definition over the whole band.
    """

    label: str
    Omega0: Optional[float]
    theta_w: Optional[float]
    tau0: float = 1.0
    tau1: float = 0.5
    lam: float = 0.5
    golden_c: Optional[float] = None
    color: Optional[str] = None
    K_low: Optional[float] = None

    def map_at(self, eps: float) -> MapSpec:
        """The map of this series at one eps.

        Parameters
        ----------
        eps : float
            Perturbation amplitude.

        Returns
        -------
        MapSpec
        """
        if self.golden_c is not None:
            O, tw = golden_family(eps, self.golden_c, self.tau0)
            return MapSpec(eps, O, tw, self.tau0, self.tau1, self.lam, self.golden_c, eps)
        return MapSpec(eps, self.Omega0, self.theta_w, self.tau0, self.tau1, self.lam)


@dataclass(frozen=True)
class Scene:
    """A validated scene file (see :func:`load_scene` and the module docstring).

    Attributes
    ----------
    path : Path or None
        The file it was read from.
    name : str
        The file's stem (or ``"scene"``).
    kind : str
        One of :data:`KINDS`.
    title : str
        Figure title.
    output : Path
        PNG path (relative paths are relative to the working directory).
    n_steps : int
        Iterates per orbit (hovering_area: the N of "never impacts").
    dpi : int
        PNG resolution.
    figsize : tuple of float or None
        Figure size in inches (default from the layout).
    layout : tuple of int or None
        ``(rows, cols)`` of the panels (default: one column).
    panels : tuple of PanelSpec
        Orbit scenes.
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
    eps : tuple of float
        hovering_area: the eps values.
    samples : int
        hovering_area: sample points per eps.
    seed : int
        hovering_area: sampling seed.
    series : tuple of SeriesSpec
        hovering_area: the curves.
    """

    path: Optional[Path]
    name: str
    kind: str
    title: str
    output: Path
    n_steps: int
    dpi: int = 130
    figsize: Optional[tuple] = None
    layout: Optional[tuple] = None
    panels: tuple = ()
    rotation: str = "mean"
    color_by: str = "orbit"
    marker_size: float = 0.3
    corner_curves: bool = True
    leading_curve: bool = True
    line: str = "L1"
    eps: tuple = ()
    samples: int = 0
    seed: int = 0
    series: tuple = ()


# ------------------------------------------------------------------------------------------------
# Value checking: every failure is a ValueError naming the key, the value and what is allowed


_NAMES = {"pi": math.pi, "OMEGA_G": OMEGA_G}
_BINOPS = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
           ast.Pow: operator.pow}
_UNOPS = {ast.USub: operator.neg, ast.UAdd: operator.pos}
_FUNCS = {"sqrt": math.sqrt, "sin": math.sin, "cos": math.cos, "acos": math.acos}


def _eval_expr(node):
    if isinstance(node, ast.Expression):
        return _eval_expr(node.body)
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) and not isinstance(node.value, bool):
        return float(node.value)
    if isinstance(node, ast.Name) and node.id in _NAMES:
        return _NAMES[node.id]
    if isinstance(node, ast.BinOp) and type(node.op) in _BINOPS:
        return _BINOPS[type(node.op)](_eval_expr(node.left), _eval_expr(node.right))
    if isinstance(node, ast.UnaryOp) and type(node.op) in _UNOPS:
        return _UNOPS[type(node.op)](_eval_expr(node.operand))
    if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in _FUNCS
            and len(node.args) == 1 and not node.keywords):
        return _FUNCS[node.func.id](_eval_expr(node.args[0]))
    raise ValueError("unsupported expression")


#: Most panels (or hovering-area series) in one figure: a scene is a figure, not a sweep; 200
#: panels took 4 minutes and 300 MB.
MAX_PANELS = 36
#: Most eps values of one hovering-area scene.
MAX_SERIES_POINTS = 200
#: Largest scene file read (a scene is a few hundred bytes; /dev/zero must not be read forever).
MAX_SCENE_BYTES = 1 << 20

#: Longest expression string accepted: a parameter is a formula like "2 * pi * (sqrt(5) - 1) / 2",
#: never a program; a 50,000-deep one exhausted the parser's memory.
_MAX_EXPR = 200


def _real(where: str, value, lo=None, hi=None, lo_open=False, hi_open=False) -> float:
    """A finite real number (or an expression string of numbers, pi, OMEGA_G) inside a range."""
    if isinstance(value, bool):
        raise ValueError(f"{where} must be a number, got {value!r}")
    if isinstance(value, str):
        if len(value) > _MAX_EXPR:
            raise ValueError(f"{where}: expression of {len(value)} characters; allowed: at most {_MAX_EXPR}")
        try:
            v = float(_eval_expr(ast.parse(value, mode="eval")))
        except (SyntaxError, ValueError, ZeroDivisionError, OverflowError, TypeError, RecursionError, MemoryError):
            raise ValueError(
                f"{where}: cannot evaluate {value!r}; allowed: a number or an expression of numbers, "
                f"pi, OMEGA_G, + - * / ** and sqrt, sin, cos, acos") from None
    elif isinstance(value, (int, float)):
        v = float(value)
    else:
        raise ValueError(f"{where} must be a number, got {value!r}")
    if not math.isfinite(v):
        raise ValueError(f"{where} must be finite, got {value!r}")
    bad_lo = lo is not None and (v <= lo if lo_open else v < lo)
    bad_hi = hi is not None and (v >= hi if hi_open else v > hi)
    if bad_lo or bad_hi:
        left = "(" if lo_open or lo is None else "["
        right = ")" if hi_open or hi is None else "]"
        rng = f"{left}{'-inf' if lo is None else lo}, {'inf' if hi is None else hi}{right}"
        raise ValueError(f"{where} = {value!r} is out of range; allowed: {rng}")
    return v


def _int(where: str, value, lo=None, hi=None) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"{where} must be an integer, got {value!r}")
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        raise ValueError(f"{where} = {value!r} is out of range; allowed: [{lo}, {'inf' if hi is None else hi}]")
    return int(value)


def _bool(where: str, value) -> bool:
    if not isinstance(value, bool):
        raise ValueError(f"{where} must be true or false, got {value!r}")
    return value


def _str(where: str, value, choices=None) -> str:
    if not isinstance(value, str) or not value.strip():
        raise ValueError(f"{where} must be a non-empty string, got {value!r}")
    if choices is not None and value not in choices:
        raise ValueError(f"{where} = {value!r} is not allowed; allowed: {', '.join(repr(c) for c in choices)}")
    return value


def _color(where: str, value) -> str:
    """A colour matplotlib understands, checked when the scene is read (not at savefig time)."""
    from matplotlib.colors import is_color_like

    v = _str(where, value)
    if not is_color_like(v):
        raise ValueError(f"{where} = {value!r} is not a matplotlib colour; allowed: a name ('red'), 'C0'..'C9', "
                         f"or hex '#rrggbb'")
    return v


def _pair(where: str, value, increasing=True) -> tuple:
    if not isinstance(value, list) or len(value) != 2:
        raise ValueError(f"{where} must be a list of two numbers [low, high], got {value!r}")
    a, b = _real(f"{where}[0]", value[0]), _real(f"{where}[1]", value[1])
    if increasing and not a < b:
        raise ValueError(f"{where} = {value!r} must be increasing (low < high)")
    return (a, b)


def _table(where: str, value) -> dict:
    if not isinstance(value, dict):
        raise ValueError(f"{where} must be a table, got {value!r}")
    return value


def _check_keys(where: str, table: dict, allowed, required=()) -> None:
    unknown = [k for k in table if k not in allowed]
    if unknown:
        raise ValueError(f"{where}: unknown key(s) {', '.join(repr(k) for k in unknown)}; "
                         f"allowed keys: {', '.join(allowed)}")
    for k in required:
        if k not in table:
            raise ValueError(f"{where}: missing required key {k!r}; allowed keys: {', '.join(allowed)}")


def _map_params(where: str, table: dict) -> dict:
    """The map keys present in a table, checked (theta_w in (0, pi), lam > 0)."""
    out = {}
    ranges = {"Omega0": {}, "tau0": {}, "tau1": {}, "theta_w": dict(lo=0.0, hi=math.pi, lo_open=True, hi_open=True),
              "lam": dict(lo=0.0, lo_open=True)}
    for k in _MAP_KEYS:
        if k in table:
            out[k] = _real(f"{where}.{k}", table[k], **ranges[k])
    return out


def _golden(where: str, value, eps_default: float, tau0: float) -> tuple:
    t = _table(where, value)
    _check_keys(where, t, ("c", "eps"), required=("c",))
    c = _real(f"{where}.c", t["c"])
    if not abs(c) < abs(tau0):
        raise ValueError(f"{where}.c = {t['c']!r} is out of range; allowed: |c| < |tau0| = {abs(tau0)}")
    ge = _real(f"{where}.eps", t["eps"]) if "eps" in t else eps_default
    O, tw = golden_family(ge, c, tau0)
    if not 0 < tw < math.pi:
        raise ValueError(f"{where}: the golden family gives theta_w = {tw} outside (0, pi) for c = {c}, eps = {ge}")
    return c, ge, O, tw


def _resolve_map(where: str, scene_map: dict, panel: dict) -> MapSpec:
    """Scene [map] values overridden by the panel's; golden family when the panel has ``golden``."""
    vals = {**_MAP_DEFAULTS, **scene_map, **_map_params(where, panel)}
    eps = _real(f"{where}.eps", panel["eps"])
    if "golden" in panel:
        for k in ("Omega0", "theta_w"):
            if k in panel:
                raise ValueError(f"{where}: give either 'golden' or {k!r}, not both "
                                 f"(the golden family sets Omega0 and theta_w)")
        c, ge, O, tw = _golden(f"{where}.golden", panel["golden"], eps, vals["tau0"])
        vals.update(Omega0=O, theta_w=tw)
        spec = MapSpec(eps=eps, **{k: vals[k] for k in _MAP_KEYS}, golden_c=c, golden_eps=ge)
    else:
        for k in ("Omega0", "theta_w"):
            if k not in vals:
                raise ValueError(f"{where}: missing required key {k!r} (in [map] or the panel), "
                                 f"or a 'golden' table; allowed keys: {', '.join(_MAP_KEYS)}, golden")
        spec = MapSpec(eps=eps, **{k: vals[k] for k in _MAP_KEYS})
    try:
        spec.build()
    except ValueError as e:
        raise ValueError(f"{where}: {e}") from None
    return spec


# ------------------------------------------------------------------------------------------------
# Parsing


_PORTRAIT_KEYS = _COMMON_KEYS + ("n_steps", "n_orbits", "K0_range", "line", "color_by", "marker_size",
                                 "corner_curves", "layout", "panels")
_PORTRAIT_PANEL_KEYS = ("id", "eps", "golden", "n_orbits", "K0_range", "xlim", "ylim") + _MAP_KEYS
_CRIT_KEYS = _COMMON_KEYS + ("n_steps", "rotation", "marker_size", "corner_curves", "leading_curve", "layout",
                             "panels")
_CRIT_PANEL_KEYS = ("id", "eps", "golden", "special", "orbits", "critical", "xlim", "ylim") + _MAP_KEYS
_ZOOM_PANEL_KEYS = ("id", "zoom")
_ZOOM_KEYS = ("of", "on", "orbits", "pad", "xlim", "ylim")
_ORBIT_KEYS = ("label", "K0", "phi0", "line", "color")
_CRITICAL_KEYS = ("n_steps", "K_range", "line", "color")
_HOV_KEYS = _COMMON_KEYS + ("n_steps", "samples", "seed", "eps", "series")
_SERIES_KEYS = ("label", "golden_c", "color", "K_low") + _MAP_KEYS


def parse_scene(data: dict, path: Optional[os.PathLike] = None) -> Scene:
    """Validate a scene given as a dict (the parsed TOML) and build the :class:`Scene`.

    Parameters
    ----------
    data : dict
        The parsed TOML document.
    path : path-like, optional
        Where it came from (used in messages and as the scene name).

    Returns
    -------
    Scene

    Raises
    ------
    ValueError
        For an unknown key (at any level), a missing required key or a bad value; the message
        names the key (as ``panels[1].zoom.of``), the value and the allowed keys or range.
    """
    p = Path(path) if path is not None else None
    name = p.stem if p is not None else "scene"
    where = p.name if p is not None else "scene"
    data = _table(where, data)
    if "kind" not in data:
        raise ValueError(f"{where}: missing required key 'kind'; allowed: {', '.join(repr(k) for k in KINDS)}")
    kind = _str(f"{where}.kind", data["kind"], KINDS)
    allowed = {"portrait": _PORTRAIT_KEYS, "critical_orbits": _CRIT_KEYS, "hovering_area": _HOV_KEYS}[kind]
    required = ("kind", "output", "n_steps") + (("panels",) if kind != "hovering_area" else ("eps", "series"))
    _check_keys(where, data, allowed, required)

    scene_map = {}
    if "map" in data:
        mt = _table(f"{where}.map", data["map"])
        _check_keys(f"{where}.map", mt, _MAP_KEYS)
        scene_map = _map_params(f"{where}.map", mt)
    common = dict(
        path=p,
        name=name,
        kind=kind,
        title=_str(f"{where}.title", data["title"]) if "title" in data else name,
        output=output_path(f"{where}.output", _str(f"{where}.output", data["output"])),
        n_steps=_int(f"{where}.n_steps", data["n_steps"], 1, 10_000_000),
        dpi=_int(f"{where}.dpi", data["dpi"], 30, 1200) if "dpi" in data else 130,
        figsize=_size(f"{where}.figsize", data["figsize"]) if "figsize" in data else None,
    )
    if kind == "hovering_area":
        return _parse_hovering_area(where, data, scene_map, common)
    return _parse_orbit_scene(where, kind, data, scene_map, common)


def _size(where: str, value) -> tuple:
    if not isinstance(value, list) or len(value) != 2:
        raise ValueError(f"{where} must be [width, height] in inches, got {value!r}")
    return tuple(_real(f"{where}[{i}]", v, lo=0.5, hi=60.0) for i, v in enumerate(value))


def _parse_orbit_scene(where: str, kind: str, data: dict, scene_map: dict, common: dict) -> Scene:
    portrait = kind == "portrait"
    opts = {}
    if "marker_size" in data:
        opts["marker_size"] = _real(f"{where}.marker_size", data["marker_size"], lo=0.0, hi=100.0, lo_open=True)
    if "corner_curves" in data:
        opts["corner_curves"] = _bool(f"{where}.corner_curves", data["corner_curves"])
    if portrait:
        opts["leading_curve"] = False
        if "color_by" in data:
            opts["color_by"] = _str(f"{where}.color_by", data["color_by"], ("orbit", "region"))
        if "line" in data:
            opts["line"] = _str(f"{where}.line", data["line"], ("L1", "L2"))
        n_orbits = _int(f"{where}.n_orbits", data["n_orbits"], 1, 10_000) if "n_orbits" in data else 30
        K0_range = _pair(f"{where}.K0_range", data["K0_range"]) if "K0_range" in data else None
    else:
        if "rotation" in data:
            opts["rotation"] = _str(f"{where}.rotation", data["rotation"], ("mean", "birkhoff"))
        if "leading_curve" in data:
            opts["leading_curve"] = _bool(f"{where}.leading_curve", data["leading_curve"])

    raw = data["panels"]
    if not isinstance(raw, list) or not raw:
        raise ValueError(f"{where}.panels must be a non-empty array of tables ([[panels]]), got {raw!r}")
    if len(raw) > MAX_PANELS:
        raise ValueError(f"{where}.panels: {len(raw)} panels; allowed: at most {MAX_PANELS} (one figure)")
    panels = []
    for i, pt in enumerate(raw):
        pw = f"{where}.panels[{i}]"
        pt = _table(pw, pt)
        if portrait:
            _check_keys(pw, pt, _PORTRAIT_PANEL_KEYS, ("id", "eps"))
            m = _resolve_map(pw, scene_map, pt)
            kr = _pair(f"{pw}.K0_range", pt["K0_range"]) if "K0_range" in pt else K0_range
            if kr is None:
                raise ValueError(f"{pw}: missing required key 'K0_range' (in the scene or the panel)")
            _check_band(f"{pw}.K0_range", m, kr)
            panels.append(PanelSpec(
                id=_str(f"{pw}.id", pt["id"]), map=m,
                n_orbits=_int(f"{pw}.n_orbits", pt["n_orbits"], 1, 10_000) if "n_orbits" in pt else n_orbits,
                K0_range=kr, **_limits(pw, pt)))
        elif "zoom" in pt:
            _check_keys(pw, pt, _ZOOM_PANEL_KEYS, ("id", "zoom"))
            panels.append(PanelSpec(id=_str(f"{pw}.id", pt["id"]), zoom=_parse_zoom(f"{pw}.zoom", pt["zoom"])))
        else:
            _check_keys(pw, pt, _CRIT_PANEL_KEYS, ("id", "eps"))
            panels.append(_parse_crit_panel(pw, pt, scene_map, common["n_steps"]))
    _check_panel_refs(where, panels)
    layout = _layout(f"{where}.layout", data["layout"], len(panels)) if "layout" in data else None
    return Scene(panels=tuple(panels), layout=layout, **opts, **common)


def _limits(pw: str, pt: dict) -> dict:
    return {k: _pair(f"{pw}.{k}", pt[k]) for k in ("xlim", "ylim") if k in pt}


def _check_band(where: str, m: MapSpec, K) -> None:
    lo = m.build().valid_band()[0]
    Kmin = min(K)
    if not Kmin > lo:
        raise ValueError(f"{where}: K0 = {Kmin} lies below the band floor {lo:.6g} of this panel's map; "
                         f"allowed: K0 > {lo:.6g}")


def _parse_crit_panel(pw: str, pt: dict, scene_map: dict, n_steps: int) -> PanelSpec:
    m = _resolve_map(pw, scene_map, pt)
    special = SPECIAL_ORBITS
    if "special" in pt:
        sv = pt["special"]
        if not isinstance(sv, list):
            raise ValueError(f"{pw}.special must be a list of names from {list(SPECIAL_ORBITS)}, got {sv!r}")
        for s in sv:
            _str(f"{pw}.special", s, SPECIAL_ORBITS)
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
            ot = _table(ow, ot)
            _check_keys(ow, ot, _ORBIT_KEYS, ("label", "K0"))
            if ("phi0" in ot) == ("line" in ot):
                raise ValueError(f"{ow}: give exactly one of 'phi0' (an angle) or 'line' ('L1' or 'L2')")
            o = OrbitSpec(
                label=_str(f"{ow}.label", ot["label"]),
                K0=_real(f"{ow}.K0", ot["K0"]),
                phi0=_real(f"{ow}.phi0", ot["phi0"]) if "phi0" in ot else None,
                line=_str(f"{ow}.line", ot["line"], ("L1", "L2")) if "line" in ot else None,
                color=_color(f"{ow}.color", ot["color"]) if "color" in ot else None,
            )
            _check_band(f"{ow}.K0", m, [o.K0])
            orbits.append(o)
    critical = None
    if "critical" in pt:
        cw = f"{pw}.critical"
        ct = pt["critical"]
        if ct is True:
            ct = {}
        ct = _table(cw, ct) if ct is not False else None
        if ct is not None:
            _check_keys(cw, ct, _CRITICAL_KEYS)
            kr = _pair(f"{cw}.K_range", ct["K_range"]) if "K_range" in ct else None
            if kr is not None:
                _check_band(f"{cw}.K_range", m, kr)
            critical = CriticalSpec(
                n_steps=_int(f"{cw}.n_steps", ct["n_steps"], 4, 10_000_000) if "n_steps" in ct else n_steps,
                K_range=kr,
                line=_str(f"{cw}.line", ct["line"], ("L1", "L2")) if "line" in ct else "L1",
                color=_color(f"{cw}.color", ct["color"]) if "color" in ct else "C4",
            )
    labels = list(special) + [o.label for o in orbits] + (["critical"] if critical else [])
    dup = {x for x in labels if labels.count(x) > 1}
    if dup:
        raise ValueError(f"{pw}: orbit label(s) {sorted(dup)} used twice (labels must be unique, and "
                         f"{list(SPECIAL_ORBITS) + ['critical']} are reserved)")
    if not labels:
        raise ValueError(f"{pw}: the panel draws no orbit (special = [] and no orbits or critical)")
    return PanelSpec(id=_str(f"{pw}.id", pt["id"]), map=m, special=special, orbits=tuple(orbits),
                     critical=critical, **_limits(pw, pt))


def _parse_zoom(zw: str, zt) -> ZoomSpec:
    zt = _table(zw, zt)
    _check_keys(zw, zt, _ZOOM_KEYS, ("of",))
    on = _str(f"{zw}.on", zt["on"], ("critical", "islands", "fixed")) if "on" in zt else "critical"
    orbits = ()
    if "orbits" in zt:
        if not isinstance(zt["orbits"], list) or not zt["orbits"]:
            raise ValueError(f"{zw}.orbits must be a non-empty list of orbit labels, got {zt['orbits']!r}")
        orbits = tuple(_str(f"{zw}.orbits", s) for s in zt["orbits"])
    if on == "islands" and not orbits:
        raise ValueError(f"{zw}: missing required key 'orbits' (the island orbits) for on = 'islands'")
    if on != "islands" and orbits:
        raise ValueError(f"{zw}: 'orbits' is only used with on = 'islands', got on = {on!r}")
    lims = {k: _pair(f"{zw}.{k}", zt[k]) for k in ("xlim", "ylim") if k in zt}
    if on == "fixed" and len(lims) != 2:
        raise ValueError(f"{zw}: missing required key(s) {[k for k in ('xlim', 'ylim') if k not in lims]} "
                         f"for on = 'fixed'")
    if on != "fixed" and lims:
        raise ValueError(f"{zw}: 'xlim'/'ylim' need on = 'fixed' (the window is otherwise chosen from the data)")
    return ZoomSpec(of=_str(f"{zw}.of", zt["of"]), on=on, orbits=orbits,
                    pad=_real(f"{zw}.pad", zt["pad"], lo=0.0, hi=5.0) if "pad" in zt else 0.5, **lims)


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


def _layout(where: str, value, n: int) -> tuple:
    if not isinstance(value, list) or len(value) != 2:
        raise ValueError(f"{where} must be [rows, cols], got {value!r}")
    r, c = _int(f"{where}[0]", value[0], 1, 20), _int(f"{where}[1]", value[1], 1, 20)
    if r * c < n:
        raise ValueError(f"{where} = {value!r} has {r * c} cells for {n} panels; allowed: rows * cols >= {n}")
    return (r, c)


def _parse_hovering_area(where: str, data: dict, scene_map: dict, common: dict) -> Scene:
    ev = data["eps"]
    if not isinstance(ev, list) or not ev:
        raise ValueError(f"{where}.eps must be a non-empty list of numbers, got {ev!r}")
    if len(ev) > MAX_SERIES_POINTS:
        raise ValueError(f"{where}.eps: {len(ev)} values; allowed: at most {MAX_SERIES_POINTS} (use a sweep for more)")
    eps = tuple(_real(f"{where}.eps[{i}]", e) for i, e in enumerate(ev))
    if len(set(eps)) != len(eps):
        raise ValueError(f"{where}.eps = {ev!r} lists a value twice")
    sv = data["series"]
    if not isinstance(sv, list) or not sv:
        raise ValueError(f"{where}.series must be a non-empty array of tables ([[series]]), got {sv!r}")
    if len(sv) > MAX_PANELS:
        raise ValueError(f"{where}.series: {len(sv)} series; allowed: at most {MAX_PANELS}")
    series = []
    for i, st in enumerate(sv):
        sw = f"{where}.series[{i}]"
        st = _table(sw, st)
        _check_keys(sw, st, _SERIES_KEYS, ("label",))
        vals = {**_MAP_DEFAULTS, **scene_map, **_map_params(sw, st)}
        c = None
        if "golden_c" in st:
            for k in ("Omega0", "theta_w"):
                if k in st:
                    raise ValueError(f"{sw}: give either 'golden_c' or {k!r}, not both")
            c = _real(f"{sw}.golden_c", st["golden_c"])
            if not abs(c) < abs(vals["tau0"]):
                raise ValueError(f"{sw}.golden_c = {st['golden_c']!r} is out of range; "
                                 f"allowed: |c| < |tau0| = {abs(vals['tau0'])}")
            vals["Omega0"] = vals["theta_w"] = None
        else:
            for k in ("Omega0", "theta_w"):
                if k not in vals:
                    raise ValueError(f"{sw}: missing required key {k!r} (in [map] or the series), or 'golden_c'")
        s = SeriesSpec(label=_str(f"{sw}.label", st["label"]), golden_c=c,
                       color=_color(f"{sw}.color", st["color"]) if "color" in st else None,
                       K_low=_real(f"{sw}.K_low", st["K_low"], hi=0.0, hi_open=True) if "K_low" in st else None,
                       **{k: vals[k] for k in _MAP_KEYS})
        for e in eps:
            try:
                m = s.map_at(e).build()
            except ValueError as err:
                raise ValueError(f"{sw} at eps = {e}: {err}") from None
            if s.K_low is not None and not s.K_low > m.valid_band()[0]:
                raise ValueError(f"{sw}.K_low = {st['K_low']!r} lies below the band floor {m.valid_band()[0]:.6g} "
                                 f"of the map at eps = {e}; allowed: ({m.valid_band()[0]:.6g}, 0)")
        series.append(s)
    return Scene(
        eps=eps,
        samples=_int(f"{where}.samples", data["samples"], 1, 100_000_000) if "samples" in data else 100_000,
        seed=_int(f"{where}.seed", data["seed"], 0, 2**63 - 1) if "seed" in data else 0,
        series=tuple(series),
        **common,
    )


def load_scene(path: os.PathLike) -> Scene:
    """Read and validate a scene file (TOML).

    Parameters
    ----------
    path : path-like
        The ``.toml`` file.

    Returns
    -------
    Scene

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    ValueError
        For a TOML syntax error, an unknown key (at any level), a missing required key or a bad
        value: the message names the key, the value and the allowed keys or range.
    """
    p = Path(path)
    if p.exists() and not p.is_file():
        raise ValueError(f"{p}: not a regular file (a scene is a .toml file)")
    with open(p, "rb") as f:
        raw = f.read(MAX_SCENE_BYTES + 1)
    if len(raw) > MAX_SCENE_BYTES:
        raise ValueError(f"{p.name}: larger than {MAX_SCENE_BYTES} bytes; a scene file is a few hundred")
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except UnicodeDecodeError as e:
        raise ValueError(f"{p.name}: not UTF-8 text (TOML files are UTF-8): byte {e.start}") from None
    except tomllib.TOMLDecodeError as e:
        raise ValueError(f"{p.name}: not valid TOML: {e}") from None
    return parse_scene(data, p)


# ------------------------------------------------------------------------------------------------
# Running


@dataclass
class PanelResult:
    """What one orbit panel computed (input of the figure makers in :mod:`hovering.figures`).

    Attributes
    ----------
    spec : PanelSpec
        The panel.
    map : TruncatedMap
        Its map.
    res : IterateResult
        The orbits (recorded as the panel needs).
    labels, colors : list of str
        Per-orbit legend label key and colour.
    kinds : list of str
        Per orbit: one of :data:`SPECIAL_ORBITS`, ``"extra"``, ``"critical"`` or ``"fan"``.
    rho : ndarray or None
        Rotation numbers (``critical_orbits`` scenes).
    critical : object or None
        The :class:`~hovering.analysis.CriticalCurve` found, when asked for.
    critical_error : str or None
        Why the critical-curve search failed, when it did.
    """

    spec: PanelSpec
    map: TruncatedMap
    res: Any
    labels: list
    colors: list
    kinds: list
    rho: Optional[np.ndarray] = None
    critical: Any = None
    critical_error: Optional[str] = None


def _scaled(scene: Scene, quick: bool) -> int:
    return max(scene.n_steps // QUICK_FACTOR, 100) if quick else scene.n_steps


def _special_starts(m: TruncatedMap, names) -> list:
    """Initial points of the paper's special orbits (sec:truncatedmapnumact)."""
    Kc = m.K_crit()
    K = {"blue": Kc, "orange": Kc + 0.05 * abs(m.eps), "green": 0.0, "red": 0.0}
    return [(m.L2(0.0) if n == "red" else m.L1(K[n]), K[n]) for n in names]


def _run_orbit_panel(scene: Scene, p: PanelSpec, n_steps: int, quick: bool) -> PanelResult:
    m = p.map.build()
    if scene.kind == "portrait":
        K0 = np.linspace(p.K0_range[0], p.K0_range[1], p.n_orbits)
        line = m.L1 if scene.line == "L1" else m.L2
        record = ("orbit", "regions") if scene.color_by == "region" else ("orbit",)
        res = m.iterate(line(K0), K0, n_steps, record=record)
        labels = [f"K0={k:.4g}" for k in K0]
        return PanelResult(p, m, res, labels, [f"C{i % 10}" for i in range(p.n_orbits)], ["fan"] * p.n_orbits)

    from . import figures
    from .analysis import rotation_number

    starts = _special_starts(m, p.special)
    labels = list(p.special)
    colors = [figures.SPECIAL_COLORS[n] for n in p.special]
    kinds = list(p.special)
    for j, o in enumerate(p.orbits):
        phi0 = o.phi0 if o.phi0 is not None else (m.L1(o.K0) if o.line == "L1" else m.L2(o.K0))
        starts.append((phi0, o.K0))
        labels.append(o.label)
        colors.append(o.color or f"C{(5 + j) % 10}")
        kinds.append("extra")
    crit, crit_err = None, None
    if p.critical is not None:
        kw = {"line": p.critical.line}
        if p.critical.K_range is not None:
            kw["K_range"] = p.critical.K_range
        cn = max(p.critical.n_steps // QUICK_FACTOR, 100) if quick else p.critical.n_steps
        try:
            crit = m.critical_curve(n_steps=cn, **kw)
        except RuntimeError as e:
            crit_err = str(e)
        if crit is not None:
            line = m.L1 if p.critical.line == "L1" else m.L2
            starts.append((line(crit.K0), crit.K0))
            labels.append("critical")
            colors.append(p.critical.color)
            kinds.append("critical")
    phi0 = np.array([s[0] for s in starts], dtype=float)
    K0 = np.array([s[1] for s in starts], dtype=float)
    record = ("orbit", "regions", "rotation") if scene.rotation == "mean" else ("orbit", "regions")
    res = m.iterate(phi0, K0, n_steps, record=record)
    rho = np.asarray(rotation_number(res, method=scene.rotation), dtype=float)
    return PanelResult(p, m, res, labels, colors, kinds, rho=rho, critical=crit, critical_error=crit_err)


def _orbit_summary(pr: PanelResult) -> list:
    from ._common import Region, Status

    res = pr.res
    out = []
    for i, lab in enumerate(pr.labels):
        K = res.K[i]
        d = dict(label=lab, kind=pr.kinds[i], phi0=float(res.phi[i, 0]), K0=float(K[0]),
                 K_min=float(np.nanmin(K)), K_max=float(np.nanmax(K)), status=Status(int(res.status[i])).name,
                 steps=int(res.steps_done[i]))
        if pr.rho is not None:
            d["rho"] = float(pr.rho[i])
        if res.region is not None:
            reg = res.region[i]
            d["impacts"] = int(np.count_nonzero((reg == int(Region.UPPER)) | (reg == int(Region.RIGHT))))
            d["hovering"] = bool(d["impacts"] == 0 and d["K_min"] < 0 and res.status[i] == int(Status.OK))
        out.append(d)
    return out


def run_scene(scene: Scene, out: Optional[os.PathLike] = None, quick: bool = False, keep_figure: bool = False) -> dict:
    """Simulate a scene, draw its figure, write the PNG and an NPZ next to it.

    Parameters
    ----------
    scene : Scene
        From :func:`load_scene`.
    out : path-like, optional
        PNG path (default ``scene.output``); the NPZ gets the same name with ``.npz``.
    quick : bool, optional
        Divide iterate counts (and hovering-area samples) by :data:`QUICK_FACTOR` (at least 100
        iterates) for a fast check; the figure title says so.
    keep_figure : bool, optional
        Return the matplotlib figure in the summary (key ``"figure"``) instead of closing it.

    Returns
    -------
    dict
        ``scene, kind, output, npz, quick, n_steps, runtime_s`` and the numbers shown: for orbit
        scenes ``panels``, a list of per-panel dicts (``id``, ``params``, predictions ``K_crit``
        and ``rho_crit``, ``orbits`` with ``label, K0, K_min, rho, impacts, hovering, status``,
        ``critical`` and the zoom ``window``); for ``hovering_area`` ``series`` with ``eps``,
        ``area``, ``error``, ``theory``.
    """
    from . import figures

    t0 = time.perf_counter()
    png = output_path("out", out) if out is not None else scene.output
    png.parent.mkdir(parents=True, exist_ok=True)
    npz = png.with_suffix(".npz")
    n_steps = _scaled(scene, quick)
    summary: dict = dict(scene=scene.name, kind=scene.kind, title=scene.title, output=str(png), npz=str(npz),
                         quick=bool(quick), n_steps=n_steps)
    arrays: dict = {}
    if scene.kind == "hovering_area":
        samples = max(scene.samples // QUICK_FACTOR, 400) if quick else scene.samples
        summary["samples"] = samples
        series_out = []
        # Each measured point is on disk at once (png.sweep.jsonl); a rerun resumes where an
        # interrupted one stopped and recomputes nothing already measured.
        ckpt = Checkpoint(png.with_suffix(".sweep.jsonl"))
        summary["checkpoint"] = str(ckpt.path)
        reused = 0
        for s in scene.series:
            rows = []
            for e in scene.eps:
                ms = s.map_at(e)
                kw = {} if s.K_low is None else {"K_low": s.K_low}
                key = dict(map=ms.as_dict(), n_steps=n_steps, samples=samples, seed=scene.seed, **kw)
                row = ckpt.get(key)
                if row is None:
                    h = ms.build().hovering_area(n_steps=n_steps, samples=samples, seed=scene.seed, **kw)
                    row = dict(eps=e, area=float(h.area), error=float(h.error), theory=float(h.theory),
                               floor_touched=bool(h.floor_touched), K_low=float(h.box[2]), Omega0=ms.Omega0,
                               theta_w=ms.theta_w)
                    ckpt.put(key, row)
                else:
                    reused += 1
                rows.append(row)
            series_out.append(dict(label=s.label, golden_c=s.golden_c, K_low=s.K_low, points=rows))
            key = f"s{len(series_out) - 1}"
            for col in ("eps", "area", "error", "theory", "K_low", "Omega0", "theta_w"):
                arrays[f"{key}_{col}"] = np.array([r[col] for r in rows])
        summary["series"] = series_out
        summary["points_reused"] = reused
        fig = figures.hovering_area_figure(scene, series_out, n_steps=n_steps)
    else:
        results = {}
        for p in scene.panels:
            if p.zoom is None:
                results[p.id] = _run_orbit_panel(scene, p, n_steps, quick)
        fig, panel_info = figures.orbit_figure(scene, results, quick=quick)
        panels_out = []
        for p in scene.panels:
            info = dict(id=p.id, **panel_info.get(p.id, {}))
            if p.zoom is None:
                pr = results[p.id]
                m = pr.map
                info.update(params=p.map.as_dict(), K_crit=m.K_crit(), rho_crit=m.rho_crit(),
                            band_floor=m.valid_band()[0], orbits=_orbit_summary(pr),
                            n_escaped=int(np.count_nonzero(pr.res.status == 1)))
                if p.critical is not None:
                    c = pr.critical
                    info["critical"] = (dict(found=True, K0=c.K0, K_min=c.K_min, rotation=c.rotation,
                                             rotation_mean=c.rotation_mean, K_pred=c.K_pred,
                                             rotation_pred=c.rotation_pred, digits=c.digits)
                                        if c is not None else dict(found=False, reason=pr.critical_error))
                arrays[f"{p.id}_phi"] = pr.res.phi.astype(np.float32)
                arrays[f"{p.id}_K"] = pr.res.K.astype(np.float32)
                arrays[f"{p.id}_labels"] = np.array(pr.labels)
                arrays[f"{p.id}_status"] = pr.res.status
                if pr.res.region is not None:
                    arrays[f"{p.id}_region"] = pr.res.region
                if pr.rho is not None:
                    arrays[f"{p.id}_rho"] = pr.rho
            else:
                info["zoom_of"] = p.zoom.of
            panels_out.append(info)
        summary["panels"] = panels_out
    fig.savefig(png, dpi=scene.dpi)
    summary["runtime_s"] = time.perf_counter() - t0
    arrays["summary_json"] = np.array(json.dumps(_jsonable(summary)))
    np.savez_compressed(npz, **arrays)
    if keep_figure:
        summary["figure"] = fig
    else:
        import matplotlib.pyplot as plt

        plt.close(fig)
    return summary


def _jsonable(x):
    if isinstance(x, dict):
        return {k: _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, (np.floating, float)):
        return None if not math.isfinite(float(x)) else float(x)
    if isinstance(x, (np.integer,)):
        return int(x)
    if isinstance(x, np.bool_):
        return bool(x)
    return x


def format_summary(summary: dict) -> str:
    """Human-readable text of a :func:`run_scene` summary (what the CLI prints).

    Parameters
    ----------
    summary : dict
        The summary.

    Returns
    -------
    str
    """
    lines = [f"scene {summary['scene']} ({summary['kind']}), {summary['n_steps']} iterates"
             + (" [quick]" if summary["quick"] else "")]
    for p in summary.get("panels", []):
        if "zoom_of" in p:
            w = p.get("window")
            lines.append(f"  panel ({p['id']}): zoom of ({p['zoom_of']}), window phi {_fmt_pair(w['xlim'])}, "
                         f"K {_fmt_pair(w['ylim'])} [{w['rule']}]")
            continue
        par = p["params"]
        extra = f", golden c = {par['golden_c']:g} at eps = {par['golden_eps']:g}" if "golden_c" in par else ""
        lines.append(f"  panel ({p['id']}): eps = {par['eps']:g}, Omega0 = {par['Omega0']:.5f}, "
                     f"theta_w = {par['theta_w']:.5f}{extra}; predicted K~_c = {p['K_crit']:.4f}, "
                     f"rho_c = {p['rho_crit']:.4f}")
        if p["orbits"] and p["orbits"][0]["kind"] == "fan":
            lines.append(f"    {len(p['orbits'])} orbits from K0 = {p['orbits'][0]['K0']:.4g} to "
                         f"{p['orbits'][-1]['K0']:.4g}, {p['n_escaped']} escaped the band")
        else:
            for o in p["orbits"]:
                hov = ("hovering" if o.get("hovering") else
                       ("no impact" if o.get("impacts") == 0 else f"{o.get('impacts')} impacts"))
                lines.append(f"    {o['label']:>10}: K0 = {o['K0']:+.5f}, K_min = {o['K_min']:+.5f}, "
                             f"rho = {o['rho']:.4f}, {hov}, {o['status']}")
        c = p.get("critical")
        if c is not None:
            if c["found"]:
                lines.append(f"    critical curve: K0 = {c['K0']:+.5f}, K_min = {c['K_min']:+.5f}, "
                             f"rho = {c['rotation_mean']:.4f} (Birkhoff {c['rotation']:.6f}); predicted "
                             f"K~_c = {c['K_pred']:+.4f}, rho_c = {c['rotation_pred']:.4f}")
            else:
                lines.append(f"    critical curve: not found ({c['reason']})")
    for s in summary.get("series", []):
        lines.append(f"  {s['label']}:")
        for r in s["points"]:
            flag = "  (box floor touched)" if r["floor_touched"] else ""
            lines.append(f"    eps = {r['eps']:+.3f}: |HOV| = {r['area']:.4f} +- {r['error']:.4f}, "
                         f"theory {r['theory']:.4f}{flag}")
    lines.append(f"wrote {summary['output']} and {summary['npz']} in {summary['runtime_s']:.2f} s")
    return "\n".join(lines)


def _fmt_pair(p) -> str:
    return f"[{p[0]:.3f}, {p[1]:.3f}]"
