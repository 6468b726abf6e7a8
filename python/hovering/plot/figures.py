"""Figures of scene results: pure functions of a result, never computing a map.

:func:`render` turns any scene result into its figure. Orbit panels show, as in the paper: the
orbits (one colour per orbit, or per region), the tangency line K = 0 and the lines L1, L2 in
light grey, the corner-singularity curves ``phi_01, phi_1R, phi_R0`` in black (measured on the
flow where it is the flow: marked with dots), and in black the leading-order curve. Artists carry
``gid`` tags (``orbit:<label>``, ``region:<label>``, ``leading_curve``, ``measured:<label>``,
``theory:<label>``, ``torus:<name>``, ``trajectory:<name>``) so tests can check a figure's
content without looking at pixels.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Optional

import numpy as np

from .._enums import Region
from ..scenes.results import (FlowHoveringResult, FlowPortraitResult, HoveringAreaResult, OrbitPanelResult,
                              OrbitSceneResult, SigmaStructureResult, TangentToriResult)
from ..scenes.spec import QUICK_FACTOR, figure_inches
from .primitives import draw_geometry, plot_orbits
from .._style import QUICK_MARK, REGION_COLORS, REGION_LABELS, SPECIAL_LABELS

__all__ = ["render", "panel_title", "orbit_label", "orbit_figure", "hovering_area_figure", "flow_portrait_figure",
           "flow_hovering_figure", "tangent_tori_figure", "sigma_structure_figure"]


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
    s = (rf"({tag}) $\varepsilon={p['eps']:g}$, $\Omega_0={p['Omega0']:.4f}$, $\theta_w={p['theta_w']:.4f}$, "
         rf"$\tau_0={p['tau0']:g}$, $\tau_1={p['tau1']:g}$, $\lambda={p['lam']:g}$")
    if p.get("golden_c") is not None:
        ge = p.get("golden_eps")
        at = "" if ge is None or ge == p["eps"] else rf" at $\varepsilon={ge:g}$"
        s += "\n" + rf"golden family $c={p['golden_c']:g}${at}"
    return s


def orbit_label(label: str, kind: str, K0: float, rho: Optional[float]) -> str:
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






def _grid(n: int, layout, figsize, sharey: bool = False):
    import matplotlib.pyplot as plt

    rows, cols = layout if layout is not None else (n, 1)
    fig, axes = plt.subplots(rows, cols, figsize=figsize, constrained_layout=True, squeeze=False, sharey=sharey)
    flat = list(axes.ravel())
    for ax in flat[n:]:
        fig.delaxes(ax)
    return fig, flat[:n]


def _quick(result) -> str:
    return QUICK_MARK if result.meta.get("quick") else ""


def _draw_leading(ax, leading):
    phi, k, lab = leading
    (line,) = ax.plot(phi, k, color="k", lw=1.0, zorder=4, label=lab)
    line.set_gid("leading_curve")
    return line


def _region_legend(ax, handles):
    leg = ax.legend(handles=handles, loc="upper right", fontsize=7, framealpha=0.85)
    for h in leg.legend_handles:
        h.set_sizes([25.0])


def _draw_orbit_panel(ax, p: OrbitPanelResult, scene, quick: str) -> None:
    o = p.orbits
    portrait = scene.kind == "portrait"
    if portrait and scene.color_by == "region":
        _region_legend(ax, plot_orbits(ax, o, color_by="region", s=scene.marker_size))
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
        leg = ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2, fontsize=7,
                        frameon=False)
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
    what = {"critical": "the hovering set under the critical curve", "islands": "islands", "fixed": "fixed window"}[z.on]
    ax.set_title(f"({z.id}) zoom of ({z.of}): {what}\n" + rf"$\phi\in[{x0:.3f}, {x1:.3f}]$, $K\in[{y0:.4f}, {y1:.4f}]$"
                 + quick, fontsize=8)


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
    scene, q = result.scene, _quick(result)
    fig, axes = _grid(len(result.panels), scene.layout, figure_inches(scene, len(result.panels)))
    by_id = {p.id: p for p in result.panels}
    for ax, p in zip(axes, result.panels):
        if isinstance(p, OrbitPanelResult):
            _draw_orbit_panel(ax, p, scene, q)
        else:
            _draw_zoom_panel(ax, p, by_id[p.of], scene, q)
    fig.suptitle(scene.title + (f"  [quick: iterates / {QUICK_FACTOR}]" if q else ""))
    return fig


def hovering_area_figure(result: HoveringAreaResult):
    """|HOV(eps)| against eps with error bars and the theory eq:hovsetsize, and their ratio.

    Panel (a): the measured area (error bars: :attr:`HoveringArea.error`) and the leading-order
    theory as a line (0 for the sign of eps that does not hover, thm:hovering), once per map
    family; a black ring marks a measurement whose hovering points reach the lowest tenth of the
    sampled box. Panel (b): measured / theory where the theory is positive, which tends to 1 as
    eps -> 0 if eq:hovsetsize is the right leading order.

    Parameters
    ----------
    result : HoveringAreaResult
        The computed scene.

    Returns
    -------
    matplotlib.figure.Figure
    """
    scene = result.scene
    fig, (ax, axr) = _grid(2, (1, 2), figure_inches(scene))
    any_floor = False
    for s in result.series:
        eb = ax.errorbar(s.eps, s.area, yerr=s.error, fmt="o", ms=4, capsize=3, color=s.color,
                         label=f"{s.label} (measured)")
        eb[0].set_gid(f"measured:{s.label}")
        if s.floor_touched.any():
            any_floor = True
            f = s.floor_touched
            ax.plot(s.eps[f], s.area[f], "o", ms=8, mfc="none", mec="k", mew=0.8, zorder=5)
        if s.theory_eps.size:
            (ln,) = ax.plot(s.theory_eps, s.theory_curve, "-", color=s.color, lw=1.0, alpha=0.8,
                            label=f"{s.label}: theory eq:hovsetsize")
            ln.set_gid(f"theory:{s.label}")
        pos = (s.eps > 0) & (s.theory > 0)
        if pos.any():
            axr.errorbar(s.eps[pos], s.area[pos] / s.theory[pos], yerr=s.error[pos] / s.theory[pos], fmt="o-", ms=4,
                         capsize=3, color=s.color, lw=0.8, label=s.label)
    if any_floor:
        ax.plot([], [], "o", ms=8, mfc="none", mec="k", mew=0.8, label="hovering points at the box floor")
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.axvline(0.0, color="0.6", lw=0.8)
    ax.set_xlabel(r"$\varepsilon$")
    ax.set_ylabel(r"$|\mathrm{HOV}(\varepsilon)|$")
    ax.set_title(f"(a) area of the hovering set, {result.meta.get('n_steps')} iterates", fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    axr.axhline(1.0, color="k", lw=0.8, ls="--")
    axr.set_xlabel(r"$\varepsilon$")
    axr.set_ylabel(r"$|\mathrm{HOV}|$ / theory")
    axr.set_title("(b) measured / leading order (tends to 1 as eps -> 0)", fontsize=9)
    if axr.get_legend_handles_labels()[0]:
        axr.legend(fontsize=7)
    fig.suptitle(scene.title + _quick(result))
    return fig


def _system_text(scene) -> str:
    s = scene.system

    def pot(p):
        return f"{p.kind}({p.omega:g}" + (f", {p.alpha:g})" if p.alpha is not None else ")")

    return (rf"$V_1$={pot(s.V1)}, $V_2$={pot(s.V2)}, $\varepsilon={s.eps:g}$, $q_w=({s.qw1:g}, {s.qw2:g})$, "
            rf"$h={scene.h:g}$, {scene.integrator.stepper} rtol {scene.integrator.rtol:g}")


def flow_portrait_figure(result: FlowPortraitResult):
    """The full return map (left) and its truncated model (right) from the same starts.

    Points are coloured by the region of the return taken from them when regions were recorded
    (else by orbit); the flow panel draws the corner-singularity curves measured on the flow
    (dotted markers at the measured circles), the model panel its closed forms; both draw K = 0,
    L1 and L2.

    Parameters
    ----------
    result : FlowPortraitResult
        The computed scene.

    Returns
    -------
    matplotlib.figure.Figure
    """
    scene, q = result.scene, _quick(result)
    fig, axes = _grid(2, (1, 2), figure_inches(scene), sharey=True)
    o = result.onset
    titles = (f"(a) full return map (flow), {result.meta.get('n_steps')} returns",
              f"(b) truncated model ({result.model_name} forcing), onset arcs "
              rf"$\Omega_0={o['Omega0']:.4f}$, $\theta_w={o['theta_w']:.4f}$")
    for ax, orbits, geom, title in zip(axes, (result.flow, result.model), (result.flow_geometry,
                                                                             result.model_geometry), titles):
        by_region = orbits.region is not None
        colls = plot_orbits(ax, orbits, color_by="region" if by_region else "orbit", s=scene.marker_size,
                            colors=orbits.colors)
        if by_region:
            _region_legend(ax, colls)
        else:
            for i, c in enumerate(colls):
                c.set_gid(f"orbit:{orbits.labels[i]}")
        draw_geometry(ax, geom)
        ax.set_xlim(-np.pi, np.pi)
        ax.set_xlabel(r"$\phi$")
        ax.set_ylabel(r"$K$")
        ax.set_title(title + q, fontsize=8)
    lo = min(float(np.nanmin(result.flow.K)), float(np.nanmin(result.model.K)), 0.0)
    hi = max(float(np.nanmax(result.flow.K)), float(np.nanmax(result.model.K)), 0.0)
    d = 0.05 * (hi - lo) if hi > lo else 0.1
    axes[0].set_ylim(lo - d, hi + d)
    fig.suptitle(scene.title + "\n" + _system_text(scene), fontsize=9)
    return fig


def flow_hovering_figure(result: FlowHoveringResult):
    """|HOV| against eps: the flow, its truncated models and eq:hovsetsize, both signs of eps.

    Parameters
    ----------
    result : FlowHoveringResult
        The computed scene.

    Returns
    -------
    matplotlib.figure.Figure
    """
    scene = result.scene
    fig, (ax, axa) = _grid(2, (1, 2), figure_inches(scene))
    e = result.eps
    order = np.argsort(e)
    eb = ax.errorbar(e[order], result.flow_area[order], yerr=result.flow_error[order], fmt="o", ms=5, capsize=3,
                     color="k", label="full flow (FlowMap)")
    eb[0].set_gid("measured:flow")
    (lb,) = ax.plot(e[order], result.flow_both_sides[order], "x", color="0.3", ms=6,
                    label="flow, orbits visiting $J_0$ and $J_{0u}$")
    lb.set_gid("measured:flow_both_sides")
    names = {"onset": "model, onset arcs", "measured": "model, arcs measured on the flow"}
    for k, (m, cols) in enumerate(result.models.items()):
        c = f"C{k}"
        shift = 0.004 * (k + 1) * (np.ptp(e) or 1.0)  # side by side: the error bars overlap otherwise
        eb = ax.errorbar(e[order] + shift, cols["area"][order], yerr=cols["error"][order], fmt="s", ms=4, capsize=3,
                         color=c, label=names.get(m, m))
        eb[0].set_gid(f"measured:{m}")
        (la,) = axa.plot(e[order], 100 * cols["agree"][order], "s-", color=c, lw=0.8, label=names.get(m, m))
        la.set_gid(f"agree:{m}")
    (lt,) = ax.plot(e[order], result.theory[order], "-", color="C3", lw=1.0, label="eq:hovsetsize (measured $b_1$)")
    lt.set_gid("theory:eq:hovsetsize")
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.axvline(0.0, color="0.6", lw=0.8)
    ax.set_xlabel(r"$\varepsilon$")
    ax.set_ylabel(r"$|\mathrm{HOV}(\varepsilon)|$")
    ax.set_title(f"(a) hovering set, {result.meta.get('n_steps')} returns, {result.meta.get('samples')} points",
                 fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    axa.set_xlabel(r"$\varepsilon$")
    axa.set_ylabel("verdicts equal to the flow's (%)")
    axa.set_title("(b) the same points classified by flow and model", fontsize=9)
    if axa.get_legend_handles_labels()[0]:
        axa.legend(fontsize=7)
    fig.suptitle(scene.title + _quick(result) + "\n" + _system_text(scene), fontsize=9)
    return fig


def tangent_tori_figure(result: TangentToriResult):
    """fig:two-tang computed: the two tangent tori in (q1, q2), (q1, p1), (q2, p2), with trajectories.

    Upper row: configuration space with the step, each torus's box of motion and a trajectory
    segment on it. Lower row: the circles ``H1 = h1`` in (q1, p1) and ``H2 = h2`` in (q2, p2).

    Parameters
    ----------
    result : TangentToriResult
        The computed scene.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    scene = result.scene
    fig = plt.figure(figsize=figure_inches(scene), constrained_layout=True)
    gs = fig.add_gridspec(2, 2)
    axc = [fig.add_subplot(gs[0, 0]), fig.add_subplot(gs[0, 1])]
    ax1, ax2 = fig.add_subplot(gs[1, 0]), fig.add_subplot(gs[1, 1])
    qw1, qw2 = result.qw1, result.qw2
    for ax, t in zip(axc, result.tori):
        q1lo, q1hi = float(np.min(t.q1)), float(np.max(t.q1))
        q2lo, q2hi = float(np.min(t.q2)), float(np.max(t.q2))
        ax.plot([q1lo, q1hi, q1hi, q1lo, q1lo], [q2lo, q2lo, q2hi, q2hi, q2lo], color=t.color, lw=0.8, ls=":")
        tr = t.trajectory
        (ln,) = ax.plot(tr[:, 1], tr[:, 3], color=t.color, lw=0.9, label=f"trajectory on the {t.name} torus")
        ln.set_gid(f"trajectory:{t.name}")
        lo1, lo2 = min(q1lo, qw1) - 0.3, min(q2lo, qw2) - 0.3
        ax.fill([lo1, qw1, qw1, lo1], [lo2, lo2, qw2, qw2], color="0.85", zorder=0)
        ax.plot([lo1, qw1, qw1], [qw2, qw2, lo2], color="k", lw=1.2)
        ax.set_xlabel(r"$q_1$")
        ax.set_ylabel(r"$q_2$")
        wall = "right wall $q_1=q_1^w$" if t.name == "right" else "upper wall $q_2=q_2^w$"
        ax.set_title(f"{t.name} torus: $H_1={t.h1:.4f}$, $H_2={t.h2:.4f}$, tangent to the {wall}", fontsize=8)
        ax.legend(fontsize=7, loc="upper right")
    for ax, qa, pa, wq, lab in ((ax1, "q1", "p1", qw1, "1"), (ax2, "q2", "p2", qw2, "2")):
        for t in result.tori:
            (ln,) = ax.plot(getattr(t, qa), getattr(t, pa), color=t.color, lw=1.2, label=f"{t.name} torus")
            ln.set_gid(f"torus:{t.name}")
        ax.axvline(wq, color="k", lw=1.0, ls="--", label=rf"$q_{lab}^w$")
        ax.set_xlabel(rf"$q_{lab}$")
        ax.set_ylabel(rf"$p_{lab}$")
        ax.set_aspect("equal", adjustable="datalim")
        ax.legend(fontsize=7, loc="upper right")
    fig.suptitle(scene.title + _quick(result) + "\n" + _system_text(scene), fontsize=9)
    return fig


def sigma_structure_figure(result: SigmaStructureResult):
    """fig:structure_Sigma computed: regions J_R, J_0, J_1 (left) and their images (right).

    Rows: the (q2, p2) plane, section coordinates (theta, I), normal coordinates (phi, K). Each
    point of the band is coloured by the region of its return (its itinerary), on the left at the
    point and on the right at its image; the tangency circle K = 0 and its image are drawn in
    black, the measured corner-singularity curves on the (phi, K) row.

    Parameters
    ----------
    result : SigmaStructureResult
        The computed scene.

    Returns
    -------
    matplotlib.figure.Figure
    """
    scene = result.scene
    fig, axes = _grid(6, (3, 2), figure_inches(scene))
    s = scene.marker_size
    rows = (("q2", "p2", "q21", "p21", r"$q_2$", r"$p_2$"),
            ("theta", "I", "theta1", "I1", r"$\theta$", r"$I$"),
            ("phi", "K", "phi1", "K1", r"$\phi$", r"$K$"))
    tg = result.tangency
    for r, (x, y, x1, y1, xl, yl) in enumerate(rows):
        for c, (xa, ya) in enumerate(((x, y), (x1, y1))):
            ax = axes[2 * r + c]
            X, Y = getattr(result, xa), getattr(result, ya)
            handles = []
            for reg, col in REGION_COLORS.items():
                sel = (result.region == int(reg)) & np.isfinite(X) & np.isfinite(Y)
                if sel.any():
                    h = ax.scatter(X[sel], Y[sel], s=s, c=col, lw=0, rasterized=True,
                                   label=("" if c == 0 else "image of ") + REGION_LABELS[reg])
                    h.set_gid(f"region:{Region(reg).label}")
                    handles.append(h)
            key = {"q2": "q2", "theta": "theta", "phi": "phi", "q21": "q21", "theta1": "theta1", "phi1": "phi1"}[xa]
            keyy = {"p2": "p2", "I": "I", "K": None, "p21": "p21", "I1": "I1", "K1": "K1"}[ya]
            ty = np.zeros_like(tg["phi"]) if keyy is None else tg[keyy]
            (lt,) = ax.plot(tg[key], ty, ".", color="k", ms=1.0, label="tangency K = 0" if c == 0 else "its image")
            lt.set_gid("tangency" if c == 0 else "tangency_image")
            if r == 2 and c == 0:
                draw_geometry(ax, result.corners, lines=False)
            ax.set_xlabel(xl if c == 0 else xl.replace("$", "$\\bar ", 1))
            ax.set_ylabel(yl if c == 0 else yl.replace("$", "$\\bar ", 1))
            if r == 0:
                ax.set_title("regions of the band" if c == 0 else "their images", fontsize=9)
            if handles:
                _region_legend(ax, handles)
    fig.suptitle(scene.title + _quick(result) + "\n" + _system_text(scene), fontsize=9)
    return fig


_RENDERERS = {
    OrbitSceneResult: orbit_figure,
    HoveringAreaResult: hovering_area_figure,
    FlowPortraitResult: flow_portrait_figure,
    FlowHoveringResult: flow_hovering_figure,
    TangentToriResult: tangent_tori_figure,
    SigmaStructureResult: sigma_structure_figure,
}


def render(result):
    """The figure of any scene result (a pure function of it: nothing is computed).

    Parameters
    ----------
    result : SceneResult
        From :func:`hovering.scenes.compute` or :func:`hovering.scenes.load_result`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fn = _RENDERERS.get(type(result))
    if fn is None:
        raise ValueError(f"no figure for a {type(result).__name__}")
    return fn(result)


