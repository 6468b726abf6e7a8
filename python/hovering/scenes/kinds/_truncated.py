"""What the kinds of the truncated map share: its parameters (:class:`MapSpec`, each key's default
and range declared once), the scene's ``[map]`` table of defaults, the resolution of a panel's or
series' map (the golden family of thm:hoveringc included) and the lines drawn under its orbits.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import MISSING, dataclass

import numpy as np

from ..._io.serial import saved_as
from ...truncated.maps import TruncatedMap
from ...truncated.theory import golden_family
from ..base import Geometry, SceneSpec
from ..fields import PARAM, custom, declared, integer, real
from ..values import check_keys
from ..values import real as real_value
from ..values import table as table_value

__all__ = [
    "MapSpec",
    "MAP_KEYS",
    "MAP_DEFAULTS",
    "TruncatedScene",
    "map_params",
    "map_key",
    "golden",
    "resolve_map",
    "check_band",
    "map_geometry",
    "leading_curve",
    "auto_ylim",
]


@saved_as("hovering.scenes.spec:MapSpec")
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

    eps: float = real()
    Omega0: float = real()
    theta_w: float = real(lo=0.0, hi=math.pi, lo_open=True, hi_open=True)
    tau0: float = real(1.0)
    tau1: float = real(0.5)
    lam: float = real(0.5, lo=0.0, lo_open=True)
    golden_c: float | None = None
    golden_eps: float | None = None

    def build(self):
        """The :class:`~hovering.TruncatedMap` with these parameters.

        Returns
        -------
        TruncatedMap
        """
        return TruncatedMap(self.eps, self.Omega0, self.theta_w, self.tau0, self.tau1, self.lam)

    def as_dict(self) -> dict:
        """Parameters as a plain dict (for summaries and checkpoint keys).

        Returns
        -------
        dict
        """
        d = dict(eps=self.eps, Omega0=self.Omega0, theta_w=self.theta_w, tau0=self.tau0, tau1=self.tau1, lam=self.lam)
        if self.golden_c is not None:
            d.update(golden_c=self.golden_c, golden_eps=self.golden_eps)
        return d


#: The map's keys a ``[map]`` table, a panel or a series may give (``eps`` is each panel's own).
MAP_KEYS = tuple(d.name for d in declared(MapSpec) if d.name != "eps")
#: Their defaults (MapSpec's, read from its fields).
MAP_DEFAULTS = {d.name: d.default for d in declared(MapSpec) if d.default is not MISSING}
_MAP_PARAMS = {d.name: d.param for d in declared(MapSpec)}


def map_key(name: str):
    """A map parameter of a table under a scene with a ``[map]`` (a series): MapSpec's declaration
    (its range), and when absent the scene's ``[map]`` value, else MapSpec's default.

    Parameters
    ----------
    name : str
        One of :data:`MAP_KEYS`.

    Returns
    -------
    dataclasses.Field
        Without a default where MapSpec has none (``Omega0``, ``theta_w``: required of the table
        or the ``[map]``, unless something else sets them).
    """
    default = MAP_DEFAULTS.get(name, MISSING)

    def from_map(where, reading):
        return reading.get("map", {}).get(name, default)

    param = dataclasses.replace(_MAP_PARAMS[name], required=False, default_from=from_map)
    if default is MISSING:
        return dataclasses.field(metadata={PARAM: param})
    return dataclasses.field(default=default, metadata={PARAM: param})


def map_params(where: str, table: dict) -> dict:
    """The map keys present in a table, each checked by MapSpec's declaration of it.

    Parameters
    ----------
    where : str
        The table, for messages.
    table : dict
        A ``[map]`` table, a panel or a series.

    Returns
    -------
    dict
        The values given (no defaults).
    """
    return {k: _MAP_PARAMS[k].read(f"{where}.{k}", table[k], None) for k in MAP_KEYS if k in table}


def _scene_map(where: str, value, reading) -> dict:
    mt = table_value(where, value)
    check_keys(where, mt, MAP_KEYS)
    return map_params(where, mt)


def golden(where: str, value, eps_default: float, tau0: float) -> tuple:
    """A ``golden = {c, eps}`` table: the family parameter and the ``(Omega0, theta_w)`` it gives.

    Parameters
    ----------
    where : str
        The table, for messages.
    value : object
        What the file holds.
    eps_default : float
        The eps of the family when the table gives none (the panel's).
    tau0 : float
        The map's tau0 (``|c| < |tau0|``).

    Returns
    -------
    tuple
        ``(c, eps, Omega0, theta_w)``.
    """
    t = table_value(where, value)
    check_keys(where, t, ("c", "eps"), required=("c",))
    c = real_value(f"{where}.c", t["c"])
    if not abs(c) < abs(tau0):
        raise ValueError(f"{where}.c = {t['c']!r} is out of range; allowed: |c| < |tau0| = {abs(tau0)}")
    ge = real_value(f"{where}.eps", t["eps"]) if "eps" in t else eps_default
    O, tw = golden_family(ge, c, tau0)
    if not 0 < tw < math.pi:
        raise ValueError(f"{where}: the golden family gives theta_w = {tw} outside (0, pi) for c = {c}, eps = {ge}")
    return c, ge, O, tw


def resolve_map(where: str, scene_map: dict, panel: dict) -> MapSpec:
    """A panel's map: the scene's ``[map]`` values overridden by the panel's; the golden family when
    the panel has ``golden``.

    Parameters
    ----------
    where : str
        The panel, for messages.
    scene_map : dict
        The scene's ``[map]`` values.
    panel : dict
        The panel's table (its ``eps`` required).

    Returns
    -------
    MapSpec
    """
    vals = {**MAP_DEFAULTS, **scene_map, **map_params(where, panel)}
    eps = _MAP_PARAMS["eps"].read(f"{where}.eps", panel["eps"], None)
    if "golden" in panel:
        for k in ("Omega0", "theta_w"):
            if k in panel:
                raise ValueError(
                    f"{where}: give either 'golden' or {k!r}, not both (the golden family sets Omega0 and theta_w)"
                )
        c, ge, O, tw = golden(f"{where}.golden", panel["golden"], eps, vals["tau0"])
        vals.update(Omega0=O, theta_w=tw)
        spec = MapSpec(eps=eps, **{k: vals[k] for k in MAP_KEYS}, golden_c=c, golden_eps=ge)
    else:
        for k in ("Omega0", "theta_w"):
            if k not in vals:
                raise ValueError(
                    f"{where}: missing required key {k!r} (in [map] or the panel), "
                    f"or a 'golden' table; allowed keys: {', '.join(MAP_KEYS)}, golden"
                )
        spec = MapSpec(eps=eps, **{k: vals[k] for k in MAP_KEYS})
    try:
        spec.build()
    except ValueError as e:
        raise ValueError(f"{where}: {e}") from None
    return spec


def check_band(where: str, m: MapSpec, K) -> None:
    """Heights inside the map's valid band.

    Parameters
    ----------
    where : str
        The key, for the message.
    m : MapSpec
        The map.
    K : sequence of float
        The heights.

    Raises
    ------
    ValueError
        For a height at or below the band floor, naming it.
    """
    lo = m.build().valid_band()[0]
    Kmin = min(K)
    if not Kmin > lo:
        raise ValueError(
            f"{where}: K0 = {Kmin} lies below the band floor {lo:.6g} of this panel's map; allowed: K0 > {lo:.6g}"
        )


@dataclass(frozen=True, kw_only=True)
class TruncatedScene(SceneSpec):
    """What every scene of the truncated map has: its iterate count, and the ``[map]`` table of
    defaults for its panels or series (a key of the file, no field: the maps are resolved).

    Attributes
    ----------
    n_steps : int
        Iterates per orbit (the N of "never impacts within N steps").
    """

    _keys = {"map": custom({}, read=_scene_map, allowed="a table of " + ", ".join(MAP_KEYS))}

    n_steps: int = integer(lo=1, hi=10_000_000)


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


def auto_ylim(K, band_floor: float, pad: float = 0.05) -> tuple:
    """Heights of all finite orbit points (and K = 0), widened by ``pad``, inside the band.

    Parameters
    ----------
    K : array_like
        Heights of the orbits' points (NaN: none).
    band_floor : float
        The lowest height allowed.
    pad : float, optional
        Margin on each side, as a fraction of the range.

    Returns
    -------
    tuple of float
    """
    K = np.asarray(K)
    lo = min(float(np.nanmin(K)), 0.0)
    hi = max(float(np.nanmax(K)), 0.0)
    d = pad * (hi - lo) if hi > lo else 0.1
    return (max(lo - d, band_floor), hi + d)
