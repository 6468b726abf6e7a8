"""TOML -> validated spec: every key at every level checked, before anything is computed.

An unknown, missing or out-of-range key is a ``ValueError`` naming it (as ``panels[1].zoom.of``),
the value and what is allowed. Values may be expressions of numbers, ``pi`` and ``OMEGA_G`` (a
whitelisted arithmetic evaluator over the parsed syntax tree, never ``eval``). Output paths are
checked here too (format, writable directory), so a scene that cannot be written fails in a
second, not after its simulation.
"""

from __future__ import annotations

import dataclasses
import math
import os
import re
import tomllib
from pathlib import Path

from .._output import output_path
from ..flow.section import STEPPERS
from ..interface import register
from ..truncated.theory import golden_family
from .spec import (
    FLOW_KINDS,
    KINDS,
    SPECIAL_ORBITS,
    CornerDirectionsScene,
    CriticalSpec,
    FlowHoveringScene,
    FlowPortraitScene,
    HoveringAreaScene,
    ImpactZoneScene,
    IntegratorSpec,
    MapSpec,
    OrbitScene,
    OrbitSpec,
    OutputsSpec,
    PanelSpec,
    PotentialSpec,
    SceneSpec,
    SeriesSpec,
    SigmaStructureScene,
    SystemSpec,
    TangentToriScene,
    WallSectionScene,
    WallTangencyScene,
    ZoomSpec,
    figure_inches,
)
from .values import (  # noqa: F401 (re-exported: the limits and checks were defined here)
    _MAX_INT_BITS,
    MAX_CANVAS_PIXELS,
    MAX_KEY_PARTS,
    MAX_PANELS,
    MAX_PATH_CHARS,
    MAX_SCENE_BYTES,
    MAX_SCENE_DEPTH,
    MAX_SCENE_STRING,
    MAX_SERIES_POINTS,
    MAX_TEXT,
    boolean,
    check_keys,
    color,
    distinct_reals,
    evaluate,
    integer,
    pair,
    real,
    size,
    table,
    tables,
    text,
)
from .wall import corner_energy, wall_tangency_action

__all__ = [
    "load_scene",
    "parse_scene",
    "check_spec",
    "scene_table",
    "MAX_PANELS",
    "MAX_SERIES_POINTS",
    "MAX_SCENE_BYTES",
    "MAX_TEXT",
    "MAX_PATH_CHARS",
    "MAX_SCENE_STRING",
    "MAX_SCENE_DEPTH",
    "MAX_KEY_PARTS",
    "MAX_CANVAS_PIXELS",
]

_MAP_KEYS = ("Omega0", "theta_w", "tau0", "tau1", "lam")
_MAP_DEFAULTS = {"tau0": 1.0, "tau1": 0.5, "lam": 0.5}
_COMMON_KEYS = ("kind", "title", "output", "dpi", "figsize")

# One value's checks live in .values (the kinds call them too); the old private names stay here.
_eval_expr, _real, _int, _bool, _str, _color, _pair, _table, _tables, _eps_list, _check_keys, _size = (
    evaluate,
    real,
    integer,
    boolean,
    text,
    color,
    pair,
    table,
    tables,
    distinct_reals,
    check_keys,
    size,
)


def _map_params(where: str, table: dict) -> dict:
    """The map keys present in a table, checked (theta_w in (0, pi), lam > 0)."""
    out = {}
    ranges = {
        "Omega0": {},
        "tau0": {},
        "tau1": {},
        "theta_w": dict(lo=0.0, hi=math.pi, lo_open=True, hi_open=True),
        "lam": dict(lo=0.0, lo_open=True),
    }
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
                raise ValueError(
                    f"{where}: give either 'golden' or {k!r}, not both (the golden family sets Omega0 and theta_w)"
                )
        c, ge, O, tw = _golden(f"{where}.golden", panel["golden"], eps, vals["tau0"])
        vals.update(Omega0=O, theta_w=tw)
        spec = MapSpec(eps=eps, **{k: vals[k] for k in _MAP_KEYS}, golden_c=c, golden_eps=ge)
    else:
        for k in ("Omega0", "theta_w"):
            if k not in vals:
                raise ValueError(
                    f"{where}: missing required key {k!r} (in [map] or the panel), "
                    f"or a 'golden' table; allowed keys: {', '.join(_MAP_KEYS)}, golden"
                )
        spec = MapSpec(eps=eps, **{k: vals[k] for k in _MAP_KEYS})
    try:
        spec.build()
    except ValueError as e:
        raise ValueError(f"{where}: {e}") from None
    return spec


# ------------------------------------------------------------------------------------------------
# Parsing


_PORTRAIT_KEYS = _COMMON_KEYS + (
    "map",
    "n_steps",
    "n_orbits",
    "K0_range",
    "line",
    "color_by",
    "marker_size",
    "corner_curves",
    "layout",
    "panels",
)
_PORTRAIT_PANEL_KEYS = ("id", "eps", "golden", "n_orbits", "K0_range", "xlim", "ylim") + _MAP_KEYS
_CRIT_KEYS = _COMMON_KEYS + (
    "map",
    "n_steps",
    "rotation",
    "marker_size",
    "corner_curves",
    "leading_curve",
    "layout",
    "panels",
)
_CRIT_PANEL_KEYS = ("id", "eps", "golden", "special", "orbits", "critical", "xlim", "ylim") + _MAP_KEYS
_ZOOM_PANEL_KEYS = ("id", "zoom")
_ZOOM_KEYS = ("of", "on", "orbits", "pad", "xlim", "ylim")
_ORBIT_KEYS = ("label", "K0", "phi0", "line", "color")
_CRITICAL_KEYS = ("n_steps", "K_range", "line", "color")
_HOV_KEYS = _COMMON_KEYS + ("map", "n_steps", "samples", "seed", "eps", "series")
_SERIES_KEYS = ("label", "golden_c", "color", "K_low") + _MAP_KEYS

_ZONE_KEYS = (
    "n_starts",
    "n_steps",
    "transit_orbits",
    "transit_steps",
    "model_factor",
    "model",
    "line",
    "critical_steps",
    "keep",
)
# The physical flow: the tables that name a scene's effects.
_FLOW_COMMON = _COMMON_KEYS + ("system", "section", "integrator", "outputs")
_FLOW_KEYS = {
    "flow_portrait": _FLOW_COMMON + ("n_steps", "n_orbits", "K0_range", "model", "corner_K", "marker_size"),
    "flow_hovering_area": _FLOW_COMMON + ("n_steps", "eps", "samples", "seed", "models"),
    "tangent_tori": _FLOW_COMMON + ("n_returns", "n_points"),
    "sigma_structure": _FLOW_COMMON + ("grid", "K_range", "marker_size"),
    "corner_directions": _FLOW_COMMON + ("p1w_fractions", "n_curve"),
    "wall_tangency": _FLOW_COMMON + ("grid", "n_points", "marker_size"),
    "wall_section": _FLOW_COMMON + ("rho_w_fraction", "n_theta", "n_circles", "bisections", "segments"),
    "impact_zone": _FLOW_COMMON + _ZONE_KEYS,
}
_FLOW_REQUIRED = {
    "flow_portrait": ("n_steps",),
    "flow_hovering_area": ("n_steps", "eps"),
    "tangent_tori": (),
    "sigma_structure": (),
    "corner_directions": (),
    "wall_tangency": (),
    "wall_section": (),
    "impact_zone": (),
}
#: The scene's own keys of each kind, as ``scene_table`` writes them back (after the common ones).
_KIND_KEYS = {
    "flow_portrait": ("n_steps", "n_orbits", "K0_range", "model", "corner_K", "marker_size"),
    "flow_hovering_area": ("n_steps", "eps", "samples", "seed", "models"),
    "tangent_tori": ("n_returns", "n_points"),
    "sigma_structure": ("grid", "K_range", "marker_size"),
    "corner_directions": ("p1w_fractions", "n_curve"),
    "wall_tangency": ("grid", "n_points", "marker_size"),
    "wall_section": ("rho_w_fraction", "n_theta", "n_circles", "bisections", "segments"),
    "impact_zone": _ZONE_KEYS,
}
# (allowed, required) records per kind: a figure's own needs are required, the rest optional.
_FLOW_RECORDS = {
    "flow_portrait": (("regions",), ()),
    "flow_hovering_area": (("regions",), ("regions",)),
    "tangent_tori": (("trajectory",), ("trajectory",)),
    "sigma_structure": (("regions", "section", "states"), ("regions", "section", "states")),
    "corner_directions": (("trajectory",), ("trajectory",)),
    "wall_tangency": (("regions", "trajectory"), ("regions", "trajectory")),
    "wall_section": (("regions", "trajectory"), ("regions", "trajectory")),
    "impact_zone": ((), ()),
}
_SYSTEM_KEYS = ("V1", "V2", "coupling", "eps", "qw1", "qw2", "geometry")
_POTENTIAL_KEYS = ("kind", "omega", "alpha")
_SECTION_KEYS = ("h",)
_INTEGRATOR_KEYS = ("stepper", "rtol", "atol", "accuracy")
_OUTPUTS_KEYS = ("record", "trajectory_dt")
_STEPPERS = STEPPERS


def output_dirs(path: os.PathLike | None) -> tuple:
    """Where a scene's own ``output`` may lie: under the scene file's folder or the working
    directory (a scene from elsewhere cannot make hovering write anywhere else; ``--out`` can).

    Parameters
    ----------
    path : path-like or None
        The scene file (None: a scene without a file, the working directory only).

    Returns
    -------
    tuple of Path
    """
    return (Path.cwd(),) + ((Path(path).parent,) if path is not None else ())


def parse_scene(data: dict, path: os.PathLike | None = None, check_output: bool = True) -> SceneSpec:
    """Validate a scene given as a dict (the parsed TOML) and build its spec.

    Parameters
    ----------
    data : dict
        The parsed TOML document.
    path : path-like, optional
        Where it came from (used in messages and as the scene name).
    check_output : bool, optional
        Check that ``output`` can be written (format, writable directory, under the scene's
        folder or the working directory: :func:`output_dirs`); off for uses that write nothing
        (the explorer) or write elsewhere (``--out``).

    Returns
    -------
    SceneSpec
        An :class:`OrbitScene`, :class:`HoveringAreaScene`, :class:`FlowPortraitScene`,
        :class:`FlowHoveringScene`, :class:`TangentToriScene`, :class:`SigmaStructureScene`,
        :class:`CornerDirectionsScene`, :class:`WallTangencyScene` or :class:`WallSectionScene`.

    Raises
    ------
    ValueError
        For an unknown key (at any level), a missing required key or a bad value; the message
        names the key (as ``panels[1].zoom.of``), the value and the allowed keys or range.
    """
    p = Path(path) if path is not None else None
    where = p.name if p is not None else "scene"
    _check_document(where, data)
    spec = _parse_scene(data, p, where, check_output)
    _check_canvas(where, spec)
    return spec


def _check_document(where: str, data) -> None:
    """Limits of the parsed document as a whole, before any field: nesting depth, string and key
    lengths, integers of 64 bits (TOML's). Iterative, so a deep document cannot exhaust the stack."""
    stack = [(data, where, 0)]
    while stack:
        node, at, depth = stack.pop()
        if isinstance(node, (dict, list)):
            if depth > MAX_SCENE_DEPTH:
                raise ValueError(
                    f"{at}: tables and arrays nested more than {MAX_SCENE_DEPTH} deep; allowed: at most "
                    f"{MAX_SCENE_DEPTH} levels"
                )
            items = node.items() if isinstance(node, dict) else enumerate(node)
            for k, v in items:
                if isinstance(k, str) and len(k) > MAX_SCENE_STRING:
                    raise ValueError(f"{at}: a key of {len(k)} characters; allowed: at most {MAX_SCENE_STRING}")
                stack.append((v, f"{at}.{k}" if isinstance(node, dict) else f"{at}[{k}]", depth + 1))
        elif isinstance(node, str) and len(node) > MAX_SCENE_STRING:
            raise ValueError(f"{at}: a string of {len(node)} characters; allowed: at most {MAX_SCENE_STRING}")
        elif isinstance(node, int) and not isinstance(node, bool) and node.bit_length() > _MAX_INT_BITS:
            raise ValueError(
                f"{at} = (an integer of {node.bit_length()} bits) is out of range; allowed: integers in "
                f"[-2**63, 2**63 - 1] (TOML's 64-bit integers)"
            )


def _check_canvas(where: str, spec: SceneSpec) -> None:
    """The figure's canvas (dpi and its size in inches, given or its kind's default) within MAX_CANVAS_PIXELS."""

    w, h = figure_inches(spec, len(getattr(spec, "panels", ())))
    pixels = (spec.dpi * w) * (spec.dpi * h)
    if pixels > MAX_CANVAS_PIXELS:
        given = (
            "figsize"
            if spec.figsize is not None
            else "layout"
            if getattr(spec, "layout", None) is not None
            else "the default figure size"
        )
        raise ValueError(
            f"{where}: dpi = {spec.dpi} and {given} make a figure of {w:g} x {h:g} inches, a canvas of "
            f"{pixels / 1e6:.0f} million pixels; allowed: at most {MAX_CANVAS_PIXELS / 1e6:.0f} million "
            f"(lower dpi or figsize)"
        )


def _parse_scene(data, p: Path | None, where: str, check_output: bool) -> SceneSpec:
    name = p.stem if p is not None else "scene"
    data = _table(where, data)
    if "kind" not in data:
        raise ValueError(f"{where}: missing required key 'kind'; allowed: {', '.join(repr(k) for k in KINDS)}")
    kind = _str(f"{where}.kind", data["kind"], KINDS)
    if kind in FLOW_KINDS:
        allowed, required = _FLOW_KEYS[kind], ("kind", "output", "system") + _FLOW_REQUIRED[kind]
    else:
        allowed = {"portrait": _PORTRAIT_KEYS, "critical_orbits": _CRIT_KEYS, "hovering_area": _HOV_KEYS}[kind]
        required = ("kind", "output", "n_steps") + (("panels",) if kind != "hovering_area" else ("eps", "series"))
    _check_keys(where, data, allowed, required)
    common = dict(
        path=p,
        name=name,
        kind=kind,
        title=_str(f"{where}.title", data["title"]) if "title" in data else name,
        output=(
            output_path(
                f"{where}.output", _str(f"{where}.output", data["output"], limit=MAX_PATH_CHARS), within=output_dirs(p)
            )
            if check_output
            else Path(_str(f"{where}.output", data["output"], limit=MAX_PATH_CHARS))
        ),
        dpi=_int(f"{where}.dpi", data["dpi"], 30, 1200) if "dpi" in data else 130,
        figsize=_size(f"{where}.figsize", data["figsize"]) if "figsize" in data else None,
    )
    if kind in FLOW_KINDS:
        return _parse_flow_scene(where, kind, data, common)
    scene_map = {}
    if "map" in data:
        mt = _table(f"{where}.map", data["map"])
        _check_keys(f"{where}.map", mt, _MAP_KEYS)
        scene_map = _map_params(f"{where}.map", mt)
    common["n_steps"] = _int(f"{where}.n_steps", data["n_steps"], 1, 10_000_000)
    if kind == "hovering_area":
        return _parse_hovering_area(where, data, scene_map, common)
    return _parse_orbit_scene(where, kind, data, scene_map, common)


def _parse_orbit_scene(where: str, kind: str, data: dict, scene_map: dict, common: dict) -> SceneSpec:
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

    raw = _tables(f"{where}.panels", data["panels"], "panels")
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
            panels.append(
                PanelSpec(
                    id=_str(f"{pw}.id", pt["id"]),
                    map=m,
                    n_orbits=_int(f"{pw}.n_orbits", pt["n_orbits"], 1, 10_000) if "n_orbits" in pt else n_orbits,
                    K0_range=kr,
                    **_limits(pw, pt),
                )
            )
        elif "zoom" in pt:
            _check_keys(pw, pt, _ZOOM_PANEL_KEYS, ("id", "zoom"))
            panels.append(PanelSpec(id=_str(f"{pw}.id", pt["id"]), zoom=_parse_zoom(f"{pw}.zoom", pt["zoom"])))
        else:
            _check_keys(pw, pt, _CRIT_PANEL_KEYS, ("id", "eps"))
            panels.append(_parse_crit_panel(pw, pt, scene_map, common["n_steps"]))
    _check_panel_refs(where, panels)
    layout = _layout(f"{where}.layout", data["layout"], len(panels)) if "layout" in data else None
    return OrbitScene(panels=tuple(panels), layout=layout, **opts, **common)


def _limits(pw: str, pt: dict) -> dict:
    return {k: _pair(f"{pw}.{k}", pt[k]) for k in ("xlim", "ylim") if k in pt}


def _check_band(where: str, m: MapSpec, K) -> None:
    lo = m.build().valid_band()[0]
    Kmin = min(K)
    if not Kmin > lo:
        raise ValueError(
            f"{where}: K0 = {Kmin} lies below the band floor {lo:.6g} of this panel's map; allowed: K0 > {lo:.6g}"
        )


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
        raise ValueError(
            f"{pw}: orbit label(s) {sorted(dup)} used twice (labels must be unique, and "
            f"{list(SPECIAL_ORBITS) + ['critical']} are reserved)"
        )
    if not labels:
        raise ValueError(f"{pw}: the panel draws no orbit (special = [] and no orbits or critical)")
    return PanelSpec(
        id=_str(f"{pw}.id", pt["id"]),
        map=m,
        special=special,
        orbits=tuple(orbits),
        critical=critical,
        **_limits(pw, pt),
    )


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
        raise ValueError(
            f"{zw}: missing required key(s) {[k for k in ('xlim', 'ylim') if k not in lims]} for on = 'fixed'"
        )
    if on != "fixed" and lims:
        raise ValueError(f"{zw}: 'xlim'/'ylim' need on = 'fixed' (the window is otherwise chosen from the data)")
    return ZoomSpec(
        of=_str(f"{zw}.of", zt["of"]),
        on=on,
        orbits=orbits,
        pad=_real(f"{zw}.pad", zt["pad"], lo=0.0, hi=5.0) if "pad" in zt else 0.5,
        **lims,
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


def _layout(where: str, value, n: int) -> tuple:
    if not isinstance(value, list) or len(value) != 2:
        raise ValueError(f"{where} must be [rows, cols], got {value!r}")
    r, c = _int(f"{where}[0]", value[0], 1, 20), _int(f"{where}[1]", value[1], 1, 20)
    if r * c < n:
        raise ValueError(f"{where} = {value!r} has {r * c} cells for {n} panels; allowed: rows * cols >= {n}")
    return (r, c)


def _parse_hovering_area(where: str, data: dict, scene_map: dict, common: dict) -> SceneSpec:
    eps = _eps_list(f"{where}.eps", data["eps"])
    sv = _tables(f"{where}.series", data["series"], "series")
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
                raise ValueError(
                    f"{sw}.golden_c = {st['golden_c']!r} is out of range; allowed: |c| < |tau0| = {abs(vals['tau0'])}"
                )
            vals["Omega0"] = vals["theta_w"] = None
        else:
            for k in ("Omega0", "theta_w"):
                if k not in vals:
                    raise ValueError(f"{sw}: missing required key {k!r} (in [map] or the series), or 'golden_c'")
        s = SeriesSpec(
            label=_str(f"{sw}.label", st["label"]),
            golden_c=c,
            color=_color(f"{sw}.color", st["color"]) if "color" in st else None,
            K_low=_real(f"{sw}.K_low", st["K_low"], hi=0.0, hi_open=True) if "K_low" in st else None,
            **{k: vals[k] for k in _MAP_KEYS},
        )
        for e in eps:
            try:
                m = s.map_at(e).build()
            except ValueError as err:
                raise ValueError(f"{sw} at eps = {e}: {err}") from None
            if s.K_low is not None and not s.K_low > m.valid_band()[0]:
                raise ValueError(
                    f"{sw}.K_low = {st['K_low']!r} lies below the band floor {m.valid_band()[0]:.6g} "
                    f"of the map at eps = {e}; allowed: ({m.valid_band()[0]:.6g}, 0)"
                )
        series.append(s)
    return HoveringAreaScene(
        eps=eps,
        samples=_int(f"{where}.samples", data["samples"], 1, 100_000_000) if "samples" in data else 100_000,
        seed=_int(f"{where}.seed", data["seed"], 0, 2**63 - 1) if "seed" in data else 0,
        series=tuple(series),
        **common,
    )


def _potential(where: str, value) -> PotentialSpec:
    t = _table(where, value)
    _check_keys(where, t, _POTENTIAL_KEYS, ("kind", "omega"))
    kind = _str(f"{where}.kind", t["kind"], ("harmonic", "tan"))
    omega = _real(f"{where}.omega", t["omega"], lo=1e-100, hi=1e100)
    if kind == "tan":
        if "alpha" not in t:
            raise ValueError(f"{where}: missing required key 'alpha' for kind = 'tan'")
        alpha = _real(f"{where}.alpha", t["alpha"], lo=1e-100, hi=1e100)
    else:
        if "alpha" in t:
            raise ValueError(f"{where}: 'alpha' is only used with kind = 'tan', got kind = 'harmonic'")
        alpha = None
    return PotentialSpec(kind, omega, alpha)


def _coupling(where: str, value) -> tuple:
    if value == "bilinear":
        return ((1.0, 1, 1),)
    if value == "none":
        return ()
    if not isinstance(value, list) or not value or len(value) > 64:
        raise ValueError(
            f"{where} must be 'bilinear', 'none' or a list of 1..64 terms [c, i, j] (c q1^i q2^j), got {value!r}"
        )
    terms = []
    first: dict = {}  # (i, j) -> the entry that gave it
    for k, term in enumerate(value):
        tw = f"{where}[{k}]"
        if not isinstance(term, list) or len(term) != 3:
            raise ValueError(f"{tw} must be a term [c, i, j] (c q1^i q2^j), got {term!r}")
        c, i, j = _real(f"{tw}[0]", term[0]), _int(f"{tw}[1]", term[1], 0, 20), _int(f"{tw}[2]", term[2], 0, 20)
        if (i, j) in first:
            # A dict of terms would keep only the last: the first coefficient would vanish silently.
            raise ValueError(
                f"{tw} = {term!r} repeats the term q1^{i} q2^{j} of {where}[{first[(i, j)]}]; allowed: each "
                f"power (i, j) once (write the sum of the coefficients as one term)"
            )
        first[(i, j)] = k
        terms.append((c, i, j))
    return tuple(terms)


def _system(where: str, value) -> SystemSpec:
    t = _table(where, value)
    _check_keys(where, t, _SYSTEM_KEYS, ("V1", "V2"))
    spec = SystemSpec(
        V1=_potential(f"{where}.V1", t["V1"]),
        V2=_potential(f"{where}.V2", t["V2"]),
        coupling=_coupling(f"{where}.coupling", t["coupling"]) if "coupling" in t else ((1.0, 1, 1),),
        eps=_real(f"{where}.eps", t["eps"], lo=-10.0, hi=10.0) if "eps" in t else 0.0,
        qw1=_real(f"{where}.qw1", t["qw1"], hi=0.0, hi_open=True) if "qw1" in t else -1.0,
        qw2=_real(f"{where}.qw2", t["qw2"], hi=0.0, hi_open=True) if "qw2" in t else -0.5,
        geometry=_str(f"{where}.geometry", t["geometry"], ("none", "wall", "step")) if "geometry" in t else "step",
    )
    try:
        spec.build()
    except ValueError as e:
        raise ValueError(f"{where}: {e}") from None
    return spec


def _flow_common(where: str, kind: str, data: dict) -> dict:
    """The [system], [section], [integrator] and [outputs] tables, checked against each other."""
    system = _system(f"{where}.system", data["system"])
    h = 1.0
    if "section" in data:
        st = _table(f"{where}.section", data["section"])
        _check_keys(f"{where}.section", st, _SECTION_KEYS, ("h",))
        h = _real(f"{where}.section.h", st["h"], lo=0.0, lo_open=True)
    sys = system.build()
    hw = sys.step_energy
    # Normal coordinates (every flow figure but the tori) need the tangential band: h above the
    # step energy; the tori need both tangent tori, which exist for the same h.
    if not h > hw:
        raise ValueError(
            f"{where}.section.h = {h!r} is out of range; allowed: above the step energy "
            f"V1(qw1) + V2(qw2) + eps Vc(qw1, qw2) = {hw:.6g} (no tangency band below it)"
        )
    integ = IntegratorSpec()
    if "integrator" in data:
        it = _table(f"{where}.integrator", data["integrator"])
        _check_keys(f"{where}.integrator", it, _INTEGRATOR_KEYS)
        rtol = _real(f"{where}.integrator.rtol", it["rtol"], lo=1e-15, hi=1e-2) if "rtol" in it else 1e-10
        atol = _real(f"{where}.integrator.atol", it["atol"], lo=1e-15, hi=1e-2) if "atol" in it else rtol
        stepper = _str(f"{where}.integrator.stepper", it["stepper"], _STEPPERS) if "stepper" in it else "rk8pd"
        accuracy = None
        if "accuracy" in it:
            both = sorted({"stepper", "rtol", "atol"} & set(it))
            if both:
                raise ValueError(
                    f"{where}.integrator: 'accuracy' picks the stepper and tolerances itself; "
                    f"remove {both} or 'accuracy'"
                )
            accuracy = _real(f"{where}.integrator.accuracy", it["accuracy"], lo=1e-13, hi=1e-2)
        integ = IntegratorSpec(stepper, rtol, atol, accuracy)
    allowed, required = _FLOW_RECORDS[kind]
    record = tuple(sorted(set(required) | ({"regions"} & set(allowed))))
    dt = 0.02
    if "outputs" in data:
        ow = f"{where}.outputs"
        ot = _table(ow, data["outputs"])
        _check_keys(ow, ot, _OUTPUTS_KEYS)
        if "record" in ot:
            rv = ot["record"]
            if not isinstance(rv, list):
                raise ValueError(f"{ow}.record must be a list of names from {list(allowed)}, got {rv!r}")
            for r in rv:
                _str(f"{ow}.record", r, allowed)
            missing = [r for r in required if r not in rv]
            if missing:
                raise ValueError(f"{ow}.record = {rv!r} lacks {missing}: a {kind} figure is drawn from them")
            record = tuple(sorted(set(rv)))
        if "trajectory_dt" in ot:
            if "trajectory" not in allowed:
                raise ValueError(f"{ow}.trajectory_dt is only used by scenes that record 'trajectory'")
            dt = _real(f"{ow}.trajectory_dt", ot["trajectory_dt"], lo=1e-4, hi=10.0)
    return dict(system=system, h=h, integrator=integ, outputs=OutputsSpec(record, dt))


def _parse_flow_scene(where: str, kind: str, data: dict, common: dict) -> SceneSpec:
    common.update(_flow_common(where, kind, data))
    system = common["system"]
    if (
        kind
        in (
            "flow_portrait",
            "flow_hovering_area",
            "sigma_structure",
            "corner_directions",
            "wall_tangency",
            "wall_section",
            "impact_zone",
        )
        and system.geometry != "step"
    ):
        raise ValueError(
            f"{where}.system.geometry = {system.geometry!r}: a {kind} scene draws the regions of "
            f"the step; allowed: 'step'"
        )
    if kind == "tangent_tori" and (system.eps != 0 or system.geometry != "none"):
        raise ValueError(
            f"{where}.system: the tangent tori are those of the unperturbed smooth flow; allowed: "
            f"eps = 0 and geometry = 'none' (got eps = {system.eps!r}, geometry = {system.geometry!r}: "
            f"with walls, a tangent trajectory stops as GRAZING)"
        )
    if kind == "flow_portrait":
        kr = _pair(f"{where}.K0_range", data["K0_range"]) if "K0_range" in data else (-0.1, 0.05)
        return FlowPortraitScene(
            n_steps=_int(f"{where}.n_steps", data["n_steps"], 1, 1_000_000),
            n_orbits=_int(f"{where}.n_orbits", data["n_orbits"], 1, 1000) if "n_orbits" in data else 12,
            K0_range=kr,
            model=_str(f"{where}.model", data["model"], ("measured", "first_mode")) if "model" in data else "measured",
            corner_K=_int(f"{where}.corner_K", data["corner_K"], 0, 200) if "corner_K" in data else 12,
            marker_size=(
                _real(f"{where}.marker_size", data["marker_size"], lo=0.0, hi=100.0, lo_open=True)
                if "marker_size" in data
                else 0.5
            ),
            **common,
        )
    if kind == "flow_hovering_area":
        eps = _eps_list(f"{where}.eps", data["eps"], lo=-1.0, hi=1.0)
        models = ("onset", "measured")
        if "models" in data:
            mv = data["models"]
            if not isinstance(mv, list):
                raise ValueError(f"{where}.models must be a list from ['onset', 'measured'], got {mv!r}")
            models = tuple(_str(f"{where}.models", m, ("onset", "measured")) for m in mv)
        return FlowHoveringScene(
            n_steps=_int(f"{where}.n_steps", data["n_steps"], 1, 1_000_000),
            eps=eps,
            samples=_int(f"{where}.samples", data["samples"], 16, 10_000_000) if "samples" in data else 1000,
            seed=_int(f"{where}.seed", data["seed"], 0, 2**63 - 1) if "seed" in data else 0,
            models=models,
            **common,
        )
    if kind == "tangent_tori":
        return TangentToriScene(
            n_returns=_int(f"{where}.n_returns", data["n_returns"], 1, 100) if "n_returns" in data else 3,
            n_points=_int(f"{where}.n_points", data["n_points"], 16, 100_000) if "n_points" in data else 400,
            **common,
        )
    if kind in ("corner_directions", "wall_tangency", "wall_section"):
        return _parse_wall_scene(where, kind, data, common)
    if kind == "impact_zone":
        return _parse_zone_scene(where, data, common)
    grid = (240, 60)
    if "grid" in data:
        gv = data["grid"]
        if not isinstance(gv, list) or len(gv) != 2:
            raise ValueError(f"{where}.grid must be [n_phi, n_K], got {gv!r}")
        grid = (_int(f"{where}.grid[0]", gv[0], 8, 4000), _int(f"{where}.grid[1]", gv[1], 2, 4000))
    kr = _pair(f"{where}.K_range", data["K_range"]) if "K_range" in data else (-0.12, 0.03)
    return SigmaStructureScene(
        grid=grid,
        K_range=kr,
        marker_size=(
            _real(f"{where}.marker_size", data["marker_size"], lo=0.0, hi=100.0, lo_open=True)
            if "marker_size" in data
            else 1.0
        ),
        **common,
    )


def _parse_zone_scene(where: str, data: dict, common: dict) -> SceneSpec:
    """The ``impact_zone`` kind: counts bounded so that a scene from elsewhere cannot ask for days."""
    if common["system"].eps == 0:
        raise ValueError(
            f"{where}.system.eps = 0: at eps = 0 every level K is invariant and the zone has no critical "
            "curve; allowed: eps != 0"
        )

    def num(key, lo, hi, default):
        return _int(f"{where}.{key}", data[key], lo, hi) if key in data else default

    return ImpactZoneScene(
        n_starts=num("n_starts", 2, 2000, 40),
        n_steps=num("n_steps", 256, 10_000_000, 20_000),
        transit_orbits=num("transit_orbits", 1, 100_000, 40),
        transit_steps=num("transit_steps", 1, 100_000_000, 100_000),
        model_factor=num("model_factor", 1, 1000, 20),
        model=_str(f"{where}.model", data["model"], ("measured", "first_mode")) if "model" in data else "measured",
        line=_str(f"{where}.line", data["line"], ("L1", "L2")) if "line" in data else "L1",
        critical_steps=num("critical_steps", 500, 10_000_000, 20_000),
        keep=num("keep", 0, 100_000, 2000),
        **common,
    )


def _parse_wall_scene(where: str, kind: str, data: dict, common: dict) -> SceneSpec:
    """The corner and wall-section kinds (fig:corner_directions, fig:Sigma_0_wall, fig:wallsection)."""
    system, h = common["system"], common["h"]
    hw = corner_energy(system.build())
    if not h > hw:
        raise ValueError(
            f"{where}.section.h = {h!r} is out of range; allowed: above the energy at rest at the corner "
            f"V1(qw1) + V2(qw2) + eps Vc(qw1, qw2) = {hw:.6g} (def:heps: below it no orbit reaches the "
            f"corner)"
        )
    if kind == "corner_directions":
        fr = (0.3, 0.7)
        if "p1w_fractions" in data:
            fv = data["p1w_fractions"]
            if not isinstance(fv, list) or not 1 <= len(fv) <= 12:
                raise ValueError(
                    f"{where}.p1w_fractions must be a list of 1 to 12 numbers in (0, 1) (p1w / p1w_max), got {fv!r}"
                )
            fr = tuple(
                _real(f"{where}.p1w_fractions[{i}]", v, lo=0.0, hi=1.0, lo_open=True, hi_open=True)
                for i, v in enumerate(fv)
            )
            if len(set(fr)) != len(fr):
                raise ValueError(f"{where}.p1w_fractions = {fv!r} lists a value twice")
        return CornerDirectionsScene(
            p1w_fractions=fr,
            n_curve=_int(f"{where}.n_curve", data["n_curve"], 4, 2000) if "n_curve" in data else 48,
            **common,
        )
    if kind == "wall_tangency":
        if system.eps != 0:
            raise ValueError(
                f"{where}.system.eps = {system.eps!r}: fig:Sigma_0_wall draws the unperturbed tangency "
                f"line; allowed: eps = 0 (the wall_section kind takes eps != 0)"
            )
        grid = (180, 40)
        if "grid" in data:
            gv = data["grid"]
            if not isinstance(gv, list) or len(gv) != 2:
                raise ValueError(f"{where}.grid must be [n_theta, n_rho], got {gv!r}")
            grid = (_int(f"{where}.grid[0]", gv[0], 8, 2000), _int(f"{where}.grid[1]", gv[1], 2, 1000))
        return WallTangencyScene(
            grid=grid,
            n_points=_int(f"{where}.n_points", data["n_points"], 16, 100_000) if "n_points" in data else 400,
            marker_size=(
                _real(f"{where}.marker_size", data["marker_size"], lo=0.0, hi=100.0, lo_open=True)
                if "marker_size" in data
                else 2.0
            ),
            **common,
        )
    # wall_section: its coordinates need the tangency line I_tan^{eps,-}(theta) near the unperturbed one
    try:
        wall_tangency_action(system.build(), h, [-3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0])
    except ValueError as e:
        raise ValueError(f"{where}.system.eps = {system.eps!r}: {e}") from None
    return WallSectionScene(
        rho_w_fraction=(
            _real(f"{where}.rho_w_fraction", data["rho_w_fraction"], lo=0.0, hi=1.0, lo_open=True)
            if "rho_w_fraction" in data
            else 0.5
        ),
        n_theta=_int(f"{where}.n_theta", data["n_theta"], 32, 20_000) if "n_theta" in data else 720,
        n_circles=_int(f"{where}.n_circles", data["n_circles"], 2, 200) if "n_circles" in data else 16,
        bisections=_int(f"{where}.bisections", data["bisections"], 1, 50) if "bisections" in data else 30,
        segments=_int(f"{where}.segments", data["segments"], 0, 10) if "segments" in data else 2,
        **common,
    )


def load_scene(path: os.PathLike, check_output: bool = True) -> SceneSpec:
    """Read and validate a scene file (TOML).

    Parameters
    ----------
    path : path-like
        The ``.toml`` file.
    check_output : bool, optional
        Check the scene's output path (see :func:`parse_scene`).

    Returns
    -------
    SceneSpec

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
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise ValueError(f"{p.name}: not UTF-8 text (TOML files are UTF-8): byte {e.start}") from None
    _check_toml_text(p.name, text)
    try:
        data = tomllib.loads(text)
    except ValueError as e:  # TOMLDecodeError, or a number Python will not convert
        raise ValueError(f"{p.name}: not valid TOML: {e}") from None
    except RecursionError:  # _check_toml_text bounds the nesting; kept for a text it misjudged
        raise ValueError(
            f"{p.name}: arrays or tables nested too deeply; allowed: at most {MAX_SCENE_DEPTH} levels"
        ) from None
    return parse_scene(data, p, check_output=check_output)


# TOML strings and comments, skipped when counting brackets and dots (multi-line strings first).
_TOML_SKIP = re.compile(
    r'"""(?:[^"\\]|\\.|"(?!""))*"""|\'\'\'[\s\S]*?\'\'\'|"(?:[^"\\\n]|\\.)*"|\'[^\'\n]*\'|#[^\n]*', re.S
)
# A dotted key of more than MAX_KEY_PARTS parts, where a key can start (possessive: linear time).
_KEY_PART = r'(?:[A-Za-z0-9_-]++|"")'
_LONG_KEY = re.compile(rf"(?:^|[\[{{,])\[?[ \t]*+{_KEY_PART}(?:[ \t]*+\.[ \t]*+{_KEY_PART}){{{MAX_KEY_PARTS},}}", re.M)


# A run of digits longer than any number a double holds (2**1024 has 309); Python's own integer
# conversion refuses beyond 4300 digits with a message that names no key.
_MAX_DIGITS = 400
_LONG_NUMBER = re.compile(rf"[0-9][0-9_]{{{_MAX_DIGITS},}}")


def _check_toml_text(name: str, text: str) -> None:
    """Before Python's TOML reader sees the text: no number of more than _MAX_DIGITS digits, no
    dotted key of more than MAX_KEY_PARTS parts, no arrays or inline tables nested more than
    MAX_SCENE_DEPTH deep; each named by its line and key."""
    # Strings become "" (newlines kept, so line numbers stay): brackets and dots in them do not count.
    skel = _TOML_SKIP.sub(lambda m: "#" if m.group()[0] == "#" else '""' + "\n" * m.group().count("\n"), text)

    def line_of(pos: int) -> tuple:
        start = skel.rfind("\n", 0, pos) + 1
        key = re.match(r"\s*([^=\s][^=]*?)\s*=", skel[start:pos])
        return skel.count("\n", 0, pos) + 1, (key.group(1)[:60] if key else skel[start:pos].strip()[:60])

    m = _LONG_NUMBER.search(skel)
    if m:
        line, key = line_of(m.start())
        raise ValueError(
            f"{name}: line {line}: {key!r} has a number of {len(m.group())} digits; allowed: numbers "
            f"within the range of a double (at most {_MAX_DIGITS} digits)"
        )
    m = _LONG_KEY.search(skel)
    if m:
        line, _ = line_of(m.start())
        raise ValueError(
            f"{name}: line {line}: the key {m.group().lstrip('[{, ')[:60]!r}... has more than "
            f"{MAX_KEY_PARTS} dotted parts; allowed: at most {MAX_KEY_PARTS}"
        )
    depth = outer = 0
    for b in re.finditer(r"[\[\]{}]", skel):
        if b.group() in "[{":
            depth += 1
            outer = b.start() if depth == 1 else outer
            if depth > MAX_SCENE_DEPTH:
                line, key = line_of(outer)
                raise ValueError(
                    f"{name}: line {line}: {key!r} nests arrays or tables more than {MAX_SCENE_DEPTH} "
                    f"deep; allowed: at most {MAX_SCENE_DEPTH} levels"
                )
        else:
            depth = max(depth - 1, 0)


# ------------------------------------------------------------------------------------------------
# A spec read from elsewhere (a saved result): the same checks as a scene file's


def _map_table(m: MapSpec) -> dict:
    t = {"eps": m.eps, "tau0": m.tau0, "tau1": m.tau1, "lam": m.lam}
    if m.golden_c is not None:
        t["golden"] = {"c": m.golden_c, "eps": m.golden_eps}
    else:
        t.update(Omega0=m.Omega0, theta_w=m.theta_w)
    return t


def _some(**kw) -> dict:
    return {k: (list(v) if isinstance(v, tuple) else v) for k, v in kw.items() if v is not None}


def _panel_table(spec, pn: PanelSpec) -> dict:
    if pn.zoom is not None:
        z = pn.zoom
        zt = _some(
            of=z.of, on=z.on, pad=z.pad, orbits=z.orbits if z.on == "islands" else None, xlim=z.xlim, ylim=z.ylim
        )
        return {"id": pn.id, "zoom": zt}
    t = {"id": pn.id, **_map_table(pn.map), **_some(xlim=pn.xlim, ylim=pn.ylim)}
    if spec.kind == "portrait":
        t.update(n_orbits=pn.n_orbits, **_some(K0_range=pn.K0_range))
        return t
    t["special"] = list(pn.special)
    t["orbits"] = [_some(label=o.label, K0=o.K0, phi0=o.phi0, line=o.line, color=o.color) for o in pn.orbits]
    if pn.critical is not None:
        c = pn.critical
        t["critical"] = _some(n_steps=c.n_steps, K_range=c.K_range, line=c.line, color=c.color)
    return t


def _system_table(s) -> dict:
    pot = lambda v: _some(kind=v.kind, omega=v.omega, alpha=v.alpha)  # noqa: E731
    coupling = (
        "bilinear"
        if s.coupling == ((1.0, 1, 1),)
        else "none"
        if s.coupling == ()
        else [list(term) for term in s.coupling]
    )
    return {
        "V1": pot(s.V1),
        "V2": pot(s.V2),
        "coupling": coupling,
        "eps": s.eps,
        "qw1": s.qw1,
        "qw2": s.qw2,
        "geometry": s.geometry,
    }


def scene_table(spec: SceneSpec) -> dict:
    """The scene file (as the parsed TOML dict) that :func:`parse_scene` reads as ``spec``.

    Parameters
    ----------
    spec : SceneSpec
        A scene spec (e.g. one read from a saved result).

    Returns
    -------
    dict
        Every value written out (defaults included); expressions appear as their values.
    """
    t = {
        "kind": spec.kind,
        "title": spec.title,
        "output": str(spec.output),
        "dpi": spec.dpi,
        **_some(figsize=spec.figsize),
    }
    if isinstance(spec, OrbitScene):
        t.update(
            n_steps=spec.n_steps,
            marker_size=spec.marker_size,
            corner_curves=spec.corner_curves,
            panels=[_panel_table(spec, pn) for pn in spec.panels],
            **_some(layout=spec.layout),
        )
        if spec.kind == "portrait":
            t.update(line=spec.line, color_by=spec.color_by)
        else:
            t.update(rotation=spec.rotation, leading_curve=spec.leading_curve)
    elif isinstance(spec, HoveringAreaScene):
        t.update(
            n_steps=spec.n_steps,
            eps=list(spec.eps),
            samples=spec.samples,
            seed=spec.seed,
            series=[
                _some(
                    label=s.label,
                    tau0=s.tau0,
                    tau1=s.tau1,
                    lam=s.lam,
                    golden_c=s.golden_c,
                    Omega0=s.Omega0,
                    theta_w=s.theta_w,
                    color=s.color,
                    K_low=s.K_low,
                )
                for s in spec.series
            ],
        )
    else:
        allowed, _ = _FLOW_RECORDS[spec.kind]
        ig = spec.integrator
        t.update(
            system=_system_table(spec.system),
            section={"h": spec.h},
            integrator={"accuracy": ig.accuracy}
            if ig.accuracy is not None
            else {"stepper": ig.stepper, "rtol": ig.rtol, "atol": ig.atol},
            outputs={
                "record": list(spec.outputs.record),
                **({"trajectory_dt": spec.outputs.trajectory_dt} if "trajectory" in allowed else {}),
            },
        )
        t.update(_some(**{k: getattr(spec, k) for k in _KIND_KEYS[spec.kind]}))
    return t


def _first_difference(a, b, where: str):
    """Where two specs first differ (None if they agree; floats within 1e-12 relative agree, so that a
    value derived again, e.g. a golden-family Omega0, may differ in its last bits on another machine)."""
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        if type(a) is not type(b):
            return where, a, b
        for f in dataclasses.fields(a):
            d = _first_difference(getattr(a, f.name), getattr(b, f.name), f"{where}.{f.name}")
            if d:
                return d
        return None
    if isinstance(a, (tuple, list)):
        if type(a) is not type(b) or len(a) != len(b):
            return where, a, b
        for i, (x, y) in enumerate(zip(a, b)):
            d = _first_difference(x, y, f"{where}[{i}]")
            if d:
                return d
        return None
    if isinstance(a, float) and isinstance(b, float):
        return None if a == b or math.isclose(a, b, rel_tol=1e-12, abs_tol=0.0) else (where, a, b)
    return None if type(a) is type(b) and a == b else (where, a, b)


@register("check_spec")
def check_spec(spec: SceneSpec) -> SceneSpec:
    """Check a scene spec from elsewhere (a saved result) with the checks a scene file gets.

    The spec is written out as its scene file (:func:`scene_table`) and read by :func:`parse_scene`
    (the output path is not checked: nothing is written to it); the spec read must be ``spec``,
    so every value is in range and of its type, and no field holds what a scene file cannot give.

    Parameters
    ----------
    spec : SceneSpec
        The spec.

    Returns
    -------
    SceneSpec
        ``spec``.

    Raises
    ------
    ValueError
        Naming the field and the allowed values, as for a scene file.
    """
    if not isinstance(spec, SceneSpec) or spec.kind not in KINDS:
        raise ValueError(f"a scene spec of kind {getattr(spec, 'kind', None)!r}; allowed kinds: {', '.join(KINDS)}")
    if spec.path is not None and not isinstance(spec.path, Path):
        raise ValueError(f"scene.path must be a path, got {spec.path!r}")
    try:
        table = scene_table(spec)
    except (AttributeError, TypeError) as e:  # a field of another type than the kind has
        raise ValueError(f"a {spec.kind} scene spec with a field of the wrong type ({e})") from None
    again = parse_scene(table, spec.path, check_output=False)
    d = _first_difference(spec, again, "scene")
    if d is not None:
        where, a, b = d
        raise ValueError(f"{where} = {_clip(a)} is not what a scene file can give (its other values give {_clip(b)})")
    return spec


def _clip(value) -> str:
    r = repr(value)
    return r if len(r) <= 80 else r[:77] + "..."


# ------------------------------------------------------------------------------------------------
# Running
