"""The figure of the orbit scenes of the truncated map (``portrait``, ``critical_orbits``): one axes
per panel, as in the paper: the orbits (one colour per orbit, or per region), K = 0 and the lines L1,
L2 in light grey, the corner-singularity curves in black, the leading-order curve; zoom panels.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from ..._style import SPECIAL_LABELS
from ...scenes.results import OrbitPanelResult, OrbitSceneResult
from ...scenes.spec import QUICK_FACTOR, figure_inches
from ..common import draws, grid, quick_mark, region_legend
from ..primitives import draw_geometry, plot_orbits

__all__ = ["panel_title", "orbit_label", "orbit_figure"]


def panel_title(tag: str, params: dict) -> str:
    """Title of a truncated-map panel: its tag and the map parameters.

    Parameters
    ----------
    tag : str
        Panel id ("a").
    params : dict
        ``eps, Omega0, theta_w, tau0, tau1, lam`` (and ``golden_c``, ``golden_eps``).

    Returns
    -------
    str
    """
    p = params
    s = (
        rf"({tag}) $\varepsilon={p['eps']:g}$, $\Omega_0={p['Omega0']:.4f}$, $\theta_w={p['theta_w']:.4f}$, "
        rf"$\tau_0={p['tau0']:g}$, $\tau_1={p['tau1']:g}$, $\lambda={p['lam']:g}$"
    )
    if p.get("golden_c") is not None:
        ge = p.get("golden_eps")
        at = "" if ge is None or ge == p["eps"] else rf" at $\varepsilon={ge:g}$"
        s += "\n" + rf"golden family $c={p['golden_c']:g}${at}"
    return s


def orbit_label(label: str, kind: str, K0: float, rho: float | None) -> str:
    """Legend text of one orbit: who it is, where it starts, and its rotation number.

    Parameters
    ----------
    label : str
        Orbit label (a special-orbit colour name, ``"critical"`` or a scene label).
    kind : str
        ``"blue"``, ..., ``"critical"``, ``"extra"`` or ``"fan"``.
    K0 : float
        Initial height.
    rho : float or None
        Rotation number (omitted when None).

    Returns
    -------
    str
    """
    if kind in SPECIAL_LABELS:
        head = SPECIAL_LABELS[kind]
        if kind in ("blue", "orange"):
            head += f" $={K0:.4f}$"
    elif kind == "critical":
        head = rf"critical curve, $K_0={K0:.4f}$"
    else:
        head = label
    return head if rho is None else rf"{head}: $\rho={rho:.3f}$"


def _draw_leading(ax, leading):
    phi, k, lab = leading
    (line,) = ax.plot(phi, k, color="k", lw=1.0, zorder=4, label=lab)
    line.set_gid("leading_curve")
    return line


def _draw_orbit_panel(ax, p: OrbitPanelResult, scene, quick: str) -> None:
    o = p.orbits
    portrait = scene.kind == "portrait"
    if portrait and scene.color_by == "region":
        region_legend(ax, plot_orbits(ax, o, color_by="region", s=scene.marker_size))
        handles = None
    else:
        colls = plot_orbits(ax, o, color_by="orbit", s=scene.marker_size, colors=o.colors)
        for i, c in enumerate(colls):
            c.set_gid(f"orbit:{o.labels[i]}")
            rho = None if o.rho is None else float(o.rho[i])
            c.set_label(orbit_label(o.labels[i], o.kinds[i], float(o.K[i, 0]), rho))
        handles = None if portrait else colls
    draw_geometry(ax, p.geometry, corner_curves=scene.corner_curves)
    if p.leading is not None:
        handles = (handles or []) + [_draw_leading(ax, p.leading)]
    ax.set_xlim(*p.xlim)
    ax.set_ylim(*p.ylim)
    ax.set_xlabel(r"$\phi$")
    ax.set_ylabel(r"$K$")
    title = panel_title(p.id, p.params)
    if p.critical is not None and not p.critical.get("found"):
        title += "\n(critical curve not found)"
    ax.set_title(title + quick, fontsize=8)
    if handles:
        leg = ax.legend(
            handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2, fontsize=7, frameon=False
        )
        for h in leg.legend_handles:
            if hasattr(h, "set_sizes"):
                h.set_sizes([25.0])  # legible legend dots whatever the marker size of the orbits


def _draw_zoom_panel(ax, z, src: OrbitPanelResult, scene, quick: str) -> None:
    (x0, x1), (y0, y1) = z.window["xlim"], z.window["ylim"]
    o = src.orbits
    inside = (o.phi >= x0) & (o.phi <= x1) & (o.K >= y0) & (o.K <= y1)
    view = SimpleNamespace(phi=np.where(inside, o.phi, np.nan), K=np.where(inside, o.K, np.nan), region=o.region)
    colls = plot_orbits(ax, view, color_by="orbit", s=max(4 * scene.marker_size, 0.5), colors=o.colors)
    for i, c in enumerate(colls):
        c.set_gid(f"orbit:{o.labels[i]}")
    draw_geometry(ax, z.geometry, corner_curves=scene.corner_curves)
    if z.leading is not None:
        _draw_leading(ax, z.leading)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_xlabel(r"$\phi$")
    ax.set_ylabel(r"$K$")
    what = {"critical": "the hovering set under the critical curve", "islands": "islands", "fixed": "fixed window"}[
        z.on
    ]
    ax.set_title(
        f"({z.id}) zoom of ({z.of}): {what}\n" + rf"$\phi\in[{x0:.3f}, {x1:.3f}]$, $K\in[{y0:.4f}, {y1:.4f}]$" + quick,
        fontsize=8,
    )


@draws("portrait", "critical_orbits")
def orbit_figure(result: OrbitSceneResult):
    """The figure of a ``portrait`` or ``critical_orbits`` scene.

    Parameters
    ----------
    result : OrbitSceneResult
        The computed scene.

    Returns
    -------
    matplotlib.figure.Figure
    """
    scene, q = result.scene, quick_mark(result)
    fig, axes = grid(len(result.panels), scene.layout, figure_inches(scene, len(result.panels)))
    by_id = {p.id: p for p in result.panels}
    for ax, p in zip(axes, result.panels):
        if isinstance(p, OrbitPanelResult):
            _draw_orbit_panel(ax, p, scene, q)
        else:
            _draw_zoom_panel(ax, p, by_id[p.of], scene, q)
    fig.suptitle(scene.title + (f"  [quick: iterates / {QUICK_FACTOR}]" if q else ""))
    return fig
