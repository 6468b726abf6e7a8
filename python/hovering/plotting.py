"""Phase portraits in one call, and the old module path of the drawing primitives (one release).

:func:`phase_portrait` is compute then draw (:func:`hovering.scenes.compute.map_geometry` and
``IterateResult``, then :mod:`hovering.plot.primitives`); the primitives themselves never compute.
"""

from __future__ import annotations

import numpy as np

from .plot.primitives import break_seam as _break  # noqa: F401
from .plot.primitives import draw_geometry as _draw_geometry
from .plot.primitives import plot_orbits
from .plot.style import REGION_COLORS

__all__ = ["REGION_COLORS", "draw_geometry", "plot_orbits", "phase_portrait"]


def draw_geometry(ax, m, K_range, corner_curves=True, lines=True, n=400):
    """Draw K = 0, L1, L2 and the corner curves of a map (computes them, then draws).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Target axes.
    m : TruncatedMap, TruncatedFamily or a Geometry
        The map whose geometry is drawn (or precomputed lines).
    K_range : tuple of float
        ``(K_low, K_high)`` of the plot.
    corner_curves, lines : bool, optional
        What is drawn.
    n : int, optional
        Samples per curve.

    Returns
    -------
    list
        The artists added.
    """
    from .scenes.compute import map_geometry
    from .scenes.results import Geometry

    geom = m if isinstance(m, Geometry) else map_geometry(m, K_range, n, corner_curves, lines)
    return _draw_geometry(ax, geom, corner_curves=corner_curves, lines=lines)


def phase_portrait(m, n_orbits=30, n_steps=20_000, K_range=(-1.2, 0.6), ax=None, color_by="region", title=None):
    """Iterate orbits started evenly along L1 and draw them with the map's geometry.

    This is the construction of the paper's fig:smallepsmany: the iteration happens here, the
    drawing in :mod:`hovering.plot.primitives`.

    Parameters
    ----------
    m : TruncatedMap
        The map.
    n_orbits : int, optional
        Initial conditions, evenly spaced in K on L1.
    n_steps : int, optional
        Iterates per orbit.
    K_range : tuple of float, optional
        Range of initial K (and of the plot, padded).
    ax : matplotlib.axes.Axes, optional
        Target axes; a new figure is made if omitted.
    color_by : {"region", "orbit"}, optional
        See :func:`plot_orbits`.
    title : str, optional
        Axes title (default: the parameters).

    Returns
    -------
    ax : matplotlib.axes.Axes
    res : IterateResult
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(8, 5))
    K0 = np.linspace(K_range[0], K_range[1], n_orbits)
    res = m.iterate(m.L1(K0), K0, n_steps, record=("orbit", "regions", "rotation"))
    plot_orbits(ax, res, color_by=color_by)
    pad = 0.1 * (K_range[1] - K_range[0])
    draw_geometry(ax, m, (K_range[0] - pad, K_range[1] + pad))
    ax.set_xlim(-np.pi, np.pi)
    ax.set_ylim(K_range[0] - pad, K_range[1] + pad)
    ax.set_xlabel(r"$\phi$")
    ax.set_ylabel(r"$K$")
    if title is None:
        title = (rf"$\varepsilon={m.eps:g},\ \Omega_0={m.Omega0:.4f},\ \theta_w={m.theta_w:.4f},\ "
                 rf"\tau_0={m.tau0:g},\ \tau_1={m.tau1:g},\ \lambda={m.lam:g}$")
    ax.set_title(title, fontsize=9)
    if color_by == "region":
        ax.legend(loc="upper right", markerscale=40, fontsize=7, framealpha=0.8)
    return ax, res
