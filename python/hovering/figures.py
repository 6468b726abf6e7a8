"""Figure makers of the paper's figures (sec:truncatedmapnumact), driven by :mod:`hovering.scenes`.

Each orbit panel shows, as in the paper: the orbits (one colour per orbit, or per region with
``color_by = "region"``), the tangency line K = 0 and the lines L1, L2 in light grey, the
corner-singularity curves ``phi_01, phi_1R, phi_R0`` in dashed black
(:func:`hovering.plotting.draw_geometry`), and in black the leading-order curve
``k_{eps,1}(phi; K_0 = 0)`` (eq:keps1) for eps > 0, ``k_{eps,2}(phi; K_0 = 0)`` (eq:keps2) for
eps < 0. Legends give each orbit's start and rotation number rho; titles give the parameters.

Zoom windows are chosen from the data (:func:`zoom_window_critical`, :func:`zoom_window_islands`):

* ``on = "critical"`` (fig:hoverinnc c): around the dip of the critical curve below K = 0. The
  critical orbit is the panel's numerically found critical curve if it hovers, else the hovering
  orbit (no impact, reaches K < 0) with the lowest minimum. The window spans the angles where that
  orbit lies below K = 0 and the heights ``[K_min, 0]``, each widened by ``pad`` times its size on
  both sides - so the hovering set (between the curve and K = 0) and the corner lines that bound it
  are in view.
* ``on = "islands"`` (fig:epsbig c): the bounding box of the points of the named island orbits that
  lie in the impacting regions J_1 and J_R (the islands cut by the corner lines and the tangency),
  widened by ``pad``; all their points if none impacts.

Windows are clipped to ``phi in [-pi, pi]``. Artists carry ``gid`` tags (``orbit:<label>``,
``leading_curve``) so that tests can check the content of a figure without looking at pixels.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Optional

import numpy as np

from ._common import Region, Status
from ._common import wrap
from .truncated.theory import golden_family, hovering_area_theory
from .plotting import draw_geometry, plot_orbits

__all__ = [
    "SPECIAL_COLORS",
    "SPECIAL_LABELS",
    "panel_title",
    "orbit_label",
    "draw_leading_curve",
    "draw_orbit_panel",
    "zoom_window_critical",
    "zoom_window_islands",
    "draw_zoom_panel",
    "orbit_figure",
    "hovering_area_figure",
]

#: Colours of the paper's special orbits (matplotlib's default cycle, as in the paper).
SPECIAL_COLORS = {"blue": "C0", "orange": "C1", "green": "C2", "red": "C3"}

#: Legend text of the special orbits' starts (sec:truncatedmapnumact).
SPECIAL_LABELS = {
    "blue": r"L1, $K_0=\tilde K_c$",
    "orange": r"L1, $K_0=\tilde K_c+0.05|\varepsilon|$",
    "green": r"L1, $K_0=0$",
    "red": r"L2, $K_0=0$",
}


def panel_title(tag: str, m, golden_c: Optional[float] = None, golden_eps: Optional[float] = None) -> str:
    """Title of a panel: its tag and the map parameters.

    Parameters
    ----------
    tag : str
        Panel id ("a").
    m : TruncatedMap
        The map.
    golden_c, golden_eps : float, optional
        Golden-family parameters (thm:hoveringc), shown when given.

    Returns
    -------
    str
    """
    s = (rf"({tag}) $\varepsilon={m.eps:g}$, $\Omega_0={m.Omega0:.4f}$, $\theta_w={m.theta_w:.4f}$, "
         rf"$\tau_0={m.tau0:g}$, $\tau_1={m.tau1:g}$, $\lambda={m.lam:g}$")
    if golden_c is not None:
        at = "" if golden_eps is None or golden_eps == m.eps else rf" at $\varepsilon={golden_eps:g}$"
        s += "\n" + rf"golden family $c={golden_c:g}${at}"
    return s


def orbit_label(label: str, kind: str, K0: float, rho: Optional[float]) -> str:
    """Legend text of one orbit: who it is, where it starts, and its rotation number.

    Parameters
    ----------
    label : str
        Orbit label (a special-orbit colour name, ``"critical"`` or a scene label).
    kind : str
        ``"blue"``, ..., ``"critical"`` or ``"extra"``.
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


def draw_leading_curve(ax, m, n: int = 721):
    """Draw the leading-order upper critical curve in black.

    ``k_{eps,1}(phi; K_0 = 0)`` (eq:keps1) for eps > 0 and ``k_{eps,2}(phi; K_0 = 0)`` (eq:keps2)
    for eps < 0: the lowest invariant curve in K >= 0 to leading order (the lemma after
    eq:rotationsdiff).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Target axes.
    m : TruncatedMap
        The map.
    n : int, optional
        Samples.

    Returns
    -------
    matplotlib.lines.Line2D
        Tagged ``gid = "leading_curve"``.
    """
    phi = np.linspace(-np.pi, np.pi, n)
    if m.eps >= 0:
        k, lab = m.k_eps1(phi, 0.0), r"$k_{\varepsilon,1}(\phi;K_0=0)$ (leading order)"
    else:
        k, lab = m.k_eps2(phi, 0.0), r"$k_{\varepsilon,2}(\phi;K_0=0)$ (leading order)"
    (line,) = ax.plot(phi, k, color="k", lw=1.0, zorder=4, label=lab)
    line.set_gid("leading_curve")
    return line


def _auto_ylim(K, band_floor: float, pad: float = 0.05) -> tuple:
    """Heights of all finite orbit points (and K = 0), widened by ``pad``, inside the band."""
    K = np.asarray(K)
    lo = min(float(np.nanmin(K)), 0.0)
    hi = max(float(np.nanmax(K)), 0.0)
    d = pad * (hi - lo) if hi > lo else 0.1
    return (max(lo - d, band_floor), hi + d)


def draw_orbit_panel(ax, pr, scene, quick: bool = False) -> dict:
    """Draw one orbit panel: orbits, geometry, leading-order curve, legend, title and labels.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Target axes.
    pr : hovering.scenes.PanelResult
        What the panel computed.
    scene : hovering.scenes.Scene
        Drawing options (``color_by``, ``marker_size``, ``corner_curves``, ``leading_curve``).
    quick : bool, optional
        Mark the title as a quick run.

    Returns
    -------
    dict
        ``xlim``, ``ylim`` and ``n_orbits_drawn``.
    """
    m, res, spec = pr.map, pr.res, pr.spec
    region_handles = None
    if scene.kind == "portrait" and scene.color_by == "region":
        region_handles = plot_orbits(ax, res, color_by="region", s=scene.marker_size)
        legend_handles = None
    else:
        colls = plot_orbits(ax, res, color_by="orbit", s=scene.marker_size, colors=pr.colors)
        for i, c in enumerate(colls):
            c.set_gid(f"orbit:{pr.labels[i]}")
            rho = None if pr.rho is None else float(pr.rho[i])
            c.set_label(orbit_label(pr.labels[i], pr.kinds[i], float(res.K[i, 0]), rho))
        legend_handles = colls if scene.kind != "portrait" else None
    ylim = spec.ylim or _auto_ylim(res.K, m.valid_band()[0])
    xlim = spec.xlim or (-np.pi, np.pi)
    draw_geometry(ax, m, ylim, corner_curves=scene.corner_curves, lines=True)
    if scene.leading_curve:
        legend_handles = (legend_handles or []) + [draw_leading_curve(ax, m)]
    ax.set_xlim(*xlim)
    ax.set_ylim(*ylim)
    ax.set_xlabel(r"$\phi$")
    ax.set_ylabel(r"$K$")
    title = panel_title(spec.id, m, spec.map.golden_c, spec.map.golden_eps)
    if pr.critical_error:
        title += "\n(critical curve not found)"
    ax.set_title(title + (" [quick]" if quick else ""), fontsize=8)
    if region_handles:
        leg = ax.legend(handles=region_handles, loc="upper right", fontsize=7, framealpha=0.85)
        for h in leg.legend_handles:
            h.set_sizes([25.0])
    elif legend_handles:
        leg = ax.legend(handles=legend_handles, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2, fontsize=7,
                        frameon=False)
        for h in leg.legend_handles:
            if hasattr(h, "set_sizes"):
                h.set_sizes([25.0])  # legible legend dots whatever the marker size of the orbits
    return dict(xlim=[float(x) for x in xlim], ylim=[float(y) for y in ylim], n_orbits_drawn=int(res.n_orbits))


def _hovering(pr) -> np.ndarray:
    """Per orbit: all steps taken, never in J_1 or J_R, and some point below K = 0."""
    res = pr.res
    imp = np.any((res.region == int(Region.UPPER)) | (res.region == int(Region.RIGHT)), axis=1)
    return (res.status == int(Status.OK)) & ~imp & (np.nanmin(res.K, axis=1) < 0)


def _clip_x(lo: float, hi: float) -> tuple:
    return (max(lo, -np.pi), min(hi, np.pi))


def zoom_window_critical(pr, pad: float = 0.5) -> dict:
    """Window around the dip of the critical curve below K = 0 (the hovering set).

    Parameters
    ----------
    pr : hovering.scenes.PanelResult
        The zoomed panel (recorded with regions).
    pad : float, optional
        Margin on each side as a fraction of the dip's width and depth.

    Returns
    -------
    dict
        ``xlim``, ``ylim``, ``rule`` (how it was chosen) and ``orbit`` (the label used, or None
        when no orbit hovers and the window falls back to the predicted dip at ``K~_c``,
        ``phi = L1(0) +- theta_w``).
    """
    hov = _hovering(pr)
    kinds = np.array(pr.kinds)
    Kmin = np.nanmin(pr.res.K, axis=1)
    if np.any(hov & (kinds == "critical")):
        i = int(np.flatnonzero(hov & (kinds == "critical"))[0])
    elif hov.any():
        i = int(np.flatnonzero(hov)[np.argmin(Kmin[hov])])
    else:
        m = pr.map
        c, Kc = m.L1(0.0), min(m.K_crit(), -0.05 * abs(m.eps))
        w, h = 2 * m.theta_w, -Kc
        return dict(xlim=list(_clip_x(c - m.theta_w - pad * w, c + m.theta_w + pad * w)),
                    ylim=[Kc - pad * h, pad * h], rule="predicted dip (no hovering orbit)", orbit=None)
    phi, K = pr.res.phi[i], pr.res.K[i]
    ok = np.isfinite(K)
    phi, K = phi[ok], K[ok]
    j = int(np.argmin(K))
    d = wrap(phi - phi[j])
    below = K < 0
    a, b = float(d[below].min()), float(d[below].max())
    w, h = b - a, -float(K[j])
    x0 = float(phi[j])
    return dict(xlim=list(_clip_x(x0 + a - pad * w, x0 + b + pad * w)), ylim=[-h - pad * h, pad * h],
                rule=f"dip of orbit '{pr.labels[i]}' below K=0, pad {pad:g}", orbit=pr.labels[i])


def zoom_window_islands(pr, orbits, pad: float = 0.3) -> dict:
    """Bounding box of the impacting points (J_1, J_R) of the named island orbits.

    Parameters
    ----------
    pr : hovering.scenes.PanelResult
        The zoomed panel (recorded with regions).
    orbits : sequence of str
        Labels of the island orbits.
    pad : float, optional
        Margin on each side as a fraction of the box size.

    Returns
    -------
    dict
        ``xlim``, ``ylim``, ``rule`` and ``orbits``.
    """
    idx = [pr.labels.index(o) for o in orbits]
    res = pr.res
    phis, Ks = [], []
    for i in idx:
        n = int(res.steps_done[i])
        reg = res.region[i, :n]
        sel = (reg == int(Region.UPPER)) | (reg == int(Region.RIGHT))
        phis.append(res.phi[i, :n][sel])
        Ks.append(res.K[i, :n][sel])
    phi, K = np.concatenate(phis), np.concatenate(Ks)
    rule = f"impacting points of {list(orbits)}, pad {pad:g}"
    if phi.size == 0:
        phi = np.concatenate([res.phi[i][np.isfinite(res.phi[i])] for i in idx])
        K = np.concatenate([res.K[i][np.isfinite(res.K[i])] for i in idx])
        rule = f"all points of {list(orbits)} (none impacts), pad {pad:g}"
    c = float(np.angle(np.mean(np.exp(1j * phi))))
    d = wrap(phi - c)
    a, b = c + float(d.min()), c + float(d.max())
    w, h = b - a, float(K.max() - K.min())
    return dict(xlim=list(_clip_x(a - pad * w, b + pad * w)), ylim=[float(K.min()) - pad * h, float(K.max()) + pad * h],
                rule=rule, orbits=list(orbits))


def draw_zoom_panel(ax, pr, zoom, scene, window: dict, tag: str = "", quick: bool = False) -> dict:
    """Draw a zoom of an orbit panel: the same orbits and geometry inside ``window``.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Target axes.
    pr : hovering.scenes.PanelResult
        The panel zoomed into (nothing is recomputed).
    zoom : hovering.scenes.ZoomSpec
        The zoom's specification.
    scene : hovering.scenes.Scene
        Drawing options.
    window : dict
        ``xlim``, ``ylim`` (from :func:`zoom_window_critical` / :func:`zoom_window_islands`).
    tag : str, optional
        The zoom panel's id, shown in its title.
    quick : bool, optional
        Mark the title as a quick run.

    Returns
    -------
    dict
        The window and ``n_orbits_drawn``.
    """
    (x0, x1), (y0, y1) = window["xlim"], window["ylim"]
    res = pr.res
    inside = (res.phi >= x0) & (res.phi <= x1) & (res.K >= y0) & (res.K <= y1)
    view = SimpleNamespace(phi=np.where(inside, res.phi, np.nan), K=np.where(inside, res.K, np.nan),
                           region=res.region)
    s = max(4 * scene.marker_size, 0.5)
    colls = plot_orbits(ax, view, color_by="orbit", s=s, colors=pr.colors)
    drawn = 0
    for i, c in enumerate(colls):
        c.set_gid(f"orbit:{pr.labels[i]}")
        drawn += 1
    draw_geometry(ax, pr.map, (y0, y1), corner_curves=scene.corner_curves, lines=True, n=1200)
    if scene.leading_curve:
        draw_leading_curve(ax, pr.map, n=2001)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_xlabel(r"$\phi$")
    ax.set_ylabel(r"$K$")
    what = {"critical": "the hovering set under the critical curve", "islands": "islands",
            "fixed": "fixed window"}[zoom.on]
    (x0, x1), (y0, y1) = window["xlim"], window["ylim"]
    ax.set_title(f"({tag}) zoom of ({zoom.of}): {what}\n" + rf"$\phi\in[{x0:.3f}, {x1:.3f}]$, $K\in[{y0:.4f}, {y1:.4f}]$"
                 + (" [quick]" if quick else ""), fontsize=8)
    return dict(window=window, n_orbits_drawn=drawn)


def _grid(n: int, layout, figsize):
    import matplotlib.pyplot as plt

    rows, cols = layout if layout is not None else (n, 1)
    if figsize is None:
        figsize = (6.0 * cols + 1.0, 4.6 * rows + 0.6)
    fig, axes = plt.subplots(rows, cols, figsize=figsize, constrained_layout=True, squeeze=False)
    flat = list(axes.ravel())
    for ax in flat[n:]:
        fig.delaxes(ax)
    return fig, flat[:n]


def orbit_figure(scene, results: dict, quick: bool = False):
    """The figure of a ``portrait`` or ``critical_orbits`` scene.

    Parameters
    ----------
    scene : hovering.scenes.Scene
        The scene.
    results : dict
        Panel id -> :class:`hovering.scenes.PanelResult` for every non-zoom panel.
    quick : bool, optional
        Mark titles as a quick run.

    Returns
    -------
    fig : matplotlib.figure.Figure
    info : dict
        Panel id -> what was drawn (limits, zoom window, number of orbits).
    """
    fig, axes = _grid(len(scene.panels), scene.layout, scene.figsize)
    info = {}
    for ax, p in zip(axes, scene.panels):
        if p.zoom is None:
            info[p.id] = draw_orbit_panel(ax, results[p.id], scene, quick)
        else:
            src = results[p.zoom.of]
            if p.zoom.on == "critical":
                w = zoom_window_critical(src, p.zoom.pad)
            elif p.zoom.on == "islands":
                w = zoom_window_islands(src, p.zoom.orbits, p.zoom.pad)
            else:
                w = dict(xlim=list(p.zoom.xlim), ylim=list(p.zoom.ylim), rule="fixed")
            info[p.id] = draw_zoom_panel(ax, src, p.zoom, scene, w, tag=p.id, quick=quick)
    fig.suptitle(scene.title + (f"  [quick: iterates / {_quick_factor()}]" if quick else ""))
    return fig, info


def _quick_factor() -> int:
    from .scenes import QUICK_FACTOR

    return QUICK_FACTOR


def hovering_area_figure(scene, series: list, n_steps: Optional[int] = None):
    """|HOV(eps)| against eps with error bars and the theory eq:hovsetsize, and their ratio.

    Panel (a): the measured area (error bars: :attr:`HoveringArea.error`) and the leading-order
    theory ``eps (sin theta_w - theta_w cos theta_w) / sin(Omega0/2)`` (0 for eps <= 0,
    thm:hovering) as a line, for every series (once per distinct map family). A black ring marks
    a measurement whose hovering points reach the lowest tenth of the sampled box (the box may
    cut the set). Panel (b): measured / theory for eps > 0, which
    tends to 1 as eps -> 0 if eq:hovsetsize is the right leading order.

    Parameters
    ----------
    scene : hovering.scenes.Scene
        A ``hovering_area`` scene.
    series : list of dict
        Per series: ``label``, ``golden_c`` and ``points`` (dicts with ``eps, area, error,
        theory, Omega0, theta_w``), as in the :func:`hovering.scenes.run_scene` summary.
    n_steps : int, optional
        Iterates used (shown in the title; default ``scene.n_steps``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (ax, axr) = _grid(2, (1, 2), scene.figsize or (13.0, 5.2))
    e_all = np.array([r["eps"] for s in series for r in s["points"]])
    e_hi = max(float(e_all.max()), 0.0)
    e_lo = min(float(e_all.min()), 0.0)
    drawn_theory = set()
    any_floor = False
    for k, (s, spec) in enumerate(zip(series, scene.series)):
        color = spec.color or f"C{k}"
        pts = s["points"]
        e = np.array([r["eps"] for r in pts])
        a = np.array([r["area"] for r in pts])
        err = np.array([r["error"] for r in pts])
        th = np.array([r["theory"] for r in pts])
        floor = np.array([r["floor_touched"] for r in pts], dtype=bool)
        eb = ax.errorbar(e, a, yerr=err, fmt="o", ms=4, capsize=3, color=color, label=f"{s['label']} (measured)")
        eb[0].set_gid(f"measured:{s['label']}")
        if floor.any():
            # hovering points in the lowest tenth of the sampled box: the box may cut the set
            any_floor = True
            ax.plot(e[floor], a[floor], "o", ms=8, mfc="none", mec="k", mew=0.8, zorder=5)
        key = (spec.golden_c, spec.Omega0, spec.theta_w, spec.tau0)
        if key not in drawn_theory:
            drawn_theory.add(key)
            eg = np.linspace(0.0, e_hi, 200)[1:]
            if spec.golden_c is not None:
                tg = []
                for x in eg:
                    O, tw = golden_family(x, spec.golden_c, spec.tau0)
                    tg.append(hovering_area_theory(x, tw, O))
                tg = np.array(tg)
            else:
                tg = hovering_area_theory(eg, spec.theta_w, spec.Omega0)
            eg = np.concatenate([[e_lo, 0.0], eg])
            tg = np.concatenate([[0.0, 0.0], tg])
            (ln,) = ax.plot(eg, tg, "-", color=color, lw=1.0, alpha=0.8, label=f"{s['label']}: theory eq:hovsetsize")
            ln.set_gid(f"theory:{s['label']}")
        pos = (e > 0) & (th > 0)
        if pos.any():
            axr.errorbar(e[pos], a[pos] / th[pos], yerr=err[pos] / th[pos], fmt="o-", ms=4, capsize=3, color=color,
                         lw=0.8, label=s["label"])
    if any_floor:
        ax.plot([], [], "o", ms=8, mfc="none", mec="k", mew=0.8, label="hovering points at the box floor")
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.axvline(0.0, color="0.6", lw=0.8)
    ax.set_xlabel(r"$\varepsilon$")
    ax.set_ylabel(r"$|\mathrm{HOV}(\varepsilon)|$")
    ax.set_title(f"(a) area of the hovering set, {n_steps or scene.n_steps} iterates", fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    axr.axhline(1.0, color="k", lw=0.8, ls="--")
    axr.set_xlabel(r"$\varepsilon$")
    axr.set_ylabel(r"$|\mathrm{HOV}|$ / theory")
    axr.set_title("(b) measured / leading order (tends to 1 as eps -> 0)", fontsize=9)
    if axr.get_legend_handles_labels()[0]:
        axr.legend(fontsize=7)
    fig.suptitle(scene.title)
    return fig
