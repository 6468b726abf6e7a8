"""Drawing primitives: orbits and the lines under them, from data only (works headless on Agg).

Nothing here computes a map: the lines come as a :class:`~hovering.scenes.results.Geometry` and
the orbits as recorded arrays (an :class:`~hovering.IterateResult` or an ``OrbitSet``).
"""

from __future__ import annotations

import numpy as np

from .._enums import Region
from .._style import CORNER_STYLES, GEOMETRY_COLOR, REGION_COLORS, REGION_LABELS, orbit_color

__all__ = ["draw_geometry", "plot_orbits", "break_seam"]


def break_seam(phi):
    """Insert NaN where a wrapped curve jumps across phi = +-pi, so lines are not drawn across.

    Parameters
    ----------
    phi : array_like
        Angles along a curve.

    Returns
    -------
    ndarray
    """
    phi = np.array(phi, dtype=float)
    jumps = np.abs(np.diff(phi)) > np.pi
    phi[1:][jumps] = np.nan
    return phi


def draw_geometry(ax, geom, corner_curves: bool = True, lines: bool = True) -> list:
    """Draw the tangency circle K = 0, the lines L1, L2 and the corner-singularity curves.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Target axes.
    geom : Geometry
        The lines (computed by :func:`hovering.scenes.compute.map_geometry` or ``flow_geometry``).
    corner_curves : bool, optional
        Draw ``phi_01, phi_1R, phi_R0`` (black; dotted, dashed, dash-dotted).
    lines : bool, optional
        Draw K = 0, L1 and L2 (grey).

    Returns
    -------
    list
        The artists added (labelled ``L1``, ``L2``, ``phi_01``, ...).
    """
    artists = []
    if lines:
        artists.append(ax.axhline(0.0, color=GEOMETRY_COLOR, lw=0.8, zorder=1))
        for name in ("L1", "L2"):
            phi = getattr(geom, name)
            if phi is not None:
                artists += ax.plot(break_seam(phi), geom.K, color=GEOMETRY_COLOR, lw=0.8, ls="-", zorder=1, label=name)
    if corner_curves and geom.corners:
        marker = "." if geom.measured else None
        for key, style in CORNER_STYLES.items():
            phi = geom.corners.get(key)
            if phi is not None and len(phi):
                artists += ax.plot(
                    break_seam(phi),
                    geom.K_corner,
                    color="k",
                    lw=0.8,
                    ls=style,
                    marker=marker,
                    ms=2,
                    zorder=2,
                    label=f"phi_{key}",
                )
    return artists


def plot_orbits(ax, res, color_by: str = "region", s: float = 0.05, max_points: int = 2_000_000, colors=None) -> list:
    """Scatter recorded orbits.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Target axes.
    res : IterateResult or OrbitSet
        Orbits (``phi``, ``K``; ``region`` for ``color_by="region"``).
    color_by : {"region", "orbit"}, optional
        Colour each point by the region of the step taken from it, or each orbit by its own colour.
    s : float, optional
        Marker size.
    max_points : int, optional
        Thin each orbit uniformly so that at most this many points are drawn in all.
    colors : sequence, optional
        Per-orbit colours for ``color_by="orbit"``.

    Returns
    -------
    list
        One PathCollection per orbit (``color_by="orbit"``) or per region present (labelled
        ``J_0u``, ``J_0``, ``J_1``, ``J_R``, ``2+ impacts``).
    """
    if getattr(res, "phi", None) is None:
        raise ValueError("plot_orbits needs a result with record='orbit'")
    n_orb, n_pts = res.phi.shape
    stride = max(1, int(np.ceil(n_orb * n_pts / max_points)))
    phi, K = res.phi[:, ::stride], res.K[:, ::stride]
    out = []
    if color_by == "region":
        if res.region is None:
            raise ValueError("color_by='region' needs a result with record='regions'")
        reg = np.full(res.phi.shape, -1, dtype=np.int8)
        reg[:, :-1] = res.region
        reg = reg[:, ::stride]
        for r, c in REGION_COLORS.items():
            sel = reg == int(r)
            if sel.any():
                coll = ax.scatter(phi[sel], K[sel], s=s, c=c, lw=0, rasterized=True, label=REGION_LABELS[r])
                coll.set_gid(f"region:{Region(r).label}")
                out.append(coll)
    elif color_by == "orbit":
        cmap = colors if colors is not None else [orbit_color(i) for i in range(n_orb)]
        for i in range(n_orb):
            ok = np.isfinite(phi[i])
            out.append(ax.scatter(phi[i, ok], K[i, ok], s=s, color=cmap[i], lw=0, rasterized=True))
    else:
        raise ValueError(f"color_by must be 'region' or 'orbit', got {color_by!r}")
    return out
