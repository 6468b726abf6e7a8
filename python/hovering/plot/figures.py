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

import numpy as np

from .._enums import Region
from .._style import (
    CLASS_COLORS,
    CORNER_COLORS,
    GEOMETRY_COLOR,
    QUICK_MARK,
    REGION_COLORS,
    REGION_LABELS,
    SPECIAL_LABELS,
    WALL_REGION_COLORS,
)
from ..scenes.results import (
    CornerDirectionsResult,
    FlowHoveringResult,
    FlowPortraitResult,
    HoveringAreaResult,
    ImpactZoneResult,
    OrbitPanelResult,
    OrbitSceneResult,
    SigmaStructureResult,
    TangentToriResult,
    WallSectionResult,
    WallTangencyResult,
)
from ..scenes.spec import QUICK_FACTOR, figure_inches
from .primitives import draw_geometry, plot_orbits

__all__ = [
    "render",
    "panel_title",
    "orbit_label",
    "orbit_figure",
    "hovering_area_figure",
    "flow_portrait_figure",
    "flow_hovering_figure",
    "tangent_tori_figure",
    "sigma_structure_figure",
    "corner_directions_figure",
    "wall_tangency_figure",
    "wall_section_figure",
    "impact_zone_figure",
]


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
        eb = ax.errorbar(
            s.eps, s.area, yerr=s.error, fmt="o", ms=4, capsize=3, color=s.color, label=f"{s.label} (measured)"
        )
        eb[0].set_gid(f"measured:{s.label}")
        if s.floor_touched.any():
            any_floor = True
            f = s.floor_touched
            ax.plot(s.eps[f], s.area[f], "o", ms=8, mfc="none", mec="k", mew=0.8, zorder=5)
        if s.theory_eps.size:
            (ln,) = ax.plot(
                s.theory_eps,
                s.theory_curve,
                "-",
                color=s.color,
                lw=1.0,
                alpha=0.8,
                label=f"{s.label}: theory eq:hovsetsize",
            )
            ln.set_gid(f"theory:{s.label}")
        pos = (s.eps > 0) & (s.theory > 0)
        if pos.any():
            axr.errorbar(
                s.eps[pos],
                s.area[pos] / s.theory[pos],
                yerr=s.error[pos] / s.theory[pos],
                fmt="o-",
                ms=4,
                capsize=3,
                color=s.color,
                lw=0.8,
                label=s.label,
            )
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

    return (
        rf"$V_1$={pot(s.V1)}, $V_2$={pot(s.V2)}, $\varepsilon={s.eps:g}$, $q_w=({s.qw1:g}, {s.qw2:g})$, "
        rf"$h={scene.h:g}$, {scene.integrator.stepper} rtol {scene.integrator.rtol:g}"
    )


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
    titles = (
        f"(a) full return map (flow), {result.meta.get('n_steps')} returns",
        f"(b) truncated model ({result.model_name} forcing), onset arcs "
        rf"$\Omega_0={o['Omega0']:.4f}$, $\theta_w={o['theta_w']:.4f}$",
    )
    for ax, orbits, geom, title in zip(
        axes, (result.flow, result.model), (result.flow_geometry, result.model_geometry), titles
    ):
        by_region = orbits.region is not None
        colls = plot_orbits(
            ax, orbits, color_by="region" if by_region else "orbit", s=scene.marker_size, colors=orbits.colors
        )
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
    eb = ax.errorbar(
        e[order],
        result.flow_area[order],
        yerr=result.flow_error[order],
        fmt="o",
        ms=5,
        capsize=3,
        color="k",
        label="full flow (FlowMap)",
    )
    eb[0].set_gid("measured:flow")
    (lb,) = ax.plot(
        e[order],
        result.flow_both_sides[order],
        "x",
        color="0.3",
        ms=6,
        label="flow, orbits visiting $J_0$ and $J_{0u}$",
    )
    lb.set_gid("measured:flow_both_sides")
    names = {"onset": "model, onset arcs", "measured": "model, arcs measured on the flow"}
    for k, (m, cols) in enumerate(result.models.items()):
        c = f"C{k}"
        shift = 0.004 * (k + 1) * (np.ptp(e) or 1.0)  # side by side: the error bars overlap otherwise
        eb = ax.errorbar(
            e[order] + shift,
            cols["area"][order],
            yerr=cols["error"][order],
            fmt="s",
            ms=4,
            capsize=3,
            color=c,
            label=names.get(m, m),
        )
        eb[0].set_gid(f"measured:{m}")
        (la,) = axa.plot(e[order], 100 * cols["agree"][order], "s-", color=c, lw=0.8, label=names.get(m, m))
        la.set_gid(f"agree:{m}")
    (lt,) = ax.plot(e[order], result.theory[order], "-", color="C3", lw=1.0, label="eq:hovsetsize (measured $b_1$)")
    lt.set_gid("theory:eq:hovsetsize")
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.axvline(0.0, color="0.6", lw=0.8)
    ax.set_xlabel(r"$\varepsilon$")
    ax.set_ylabel(r"$|\mathrm{HOV}(\varepsilon)|$")
    ax.set_title(
        f"(a) hovering set, {result.meta.get('n_steps')} returns, {result.meta.get('samples')} points", fontsize=9
    )
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
    rows = (
        ("q2", "p2", "q21", "p21", r"$q_2$", r"$p_2$"),
        ("theta", "I", "theta1", "I1", r"$\theta$", r"$I$"),
        ("phi", "K", "phi1", "K1", r"$\phi$", r"$K$"),
    )
    tg = result.tangency
    for r, (x, y, x1, y1, xl, yl) in enumerate(rows):
        for c, (xa, ya) in enumerate(((x, y), (x1, y1))):
            ax = axes[2 * r + c]
            X, Y = getattr(result, xa), getattr(result, ya)
            handles = []
            for reg, col in REGION_COLORS.items():
                sel = (result.region == int(reg)) & np.isfinite(X) & np.isfinite(Y)
                if sel.any():
                    h = ax.scatter(
                        X[sel],
                        Y[sel],
                        s=s,
                        c=col,
                        lw=0,
                        rasterized=True,
                        label=("" if c == 0 else "image of ") + REGION_LABELS[reg],
                    )
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


# ------------------------------------------------------------------------------------------------
# The corner and the wall section


#: Legend text of each incoming direction (eq:p2corner).
_DIRECTION_LABELS = {"R0": r"$p_{R0}=(-p_1^w, P_2)$", "01": r"$p_{01}=(p_1^w, -P_2)$", "1R": r"$p_{1R}=(-p_1^w, -P_2)$"}
#: Legend text of the wall-section regions in the paper's colours.
_WALL_LABELS = {
    Region.RIGHT: r"$J_R$",
    Region.ABOVE: r"$J_0$",
    Region.UPPER: r"$J_1$",
    Region.BESIDE: r"$J_{0u}$",
    Region.MULTI: "2+ impacts",
}
#: Region of each arc label of a wall segment.
_ARC_REGION = {"R": Region.RIGHT, "0": Region.ABOVE, "1": Region.UPPER}


def _draw_step(ax, qw1: float, qw2: float, lo1: float, lo2: float) -> None:
    """The step {q1 < qw1, q2 < qw2} shaded, its two walls in black."""
    ax.fill([lo1, qw1, qw1, lo1], [lo2, lo2, qw2, qw2], color="0.85", zorder=0, lw=0)
    (ln,) = ax.plot([lo1, qw1, qw1], [qw2, qw2, lo2], color="k", lw=1.2, zorder=1)
    ln.set_gid("step")


def _segment_color(kind: str) -> str:
    """Colour of a wall segment: its arc's region colour, or at a corner crossing the caption's
    red, blue, black (fig:wallsection draws the sigma_1R^- curve green but its segment black)."""
    if kind in CORNER_COLORS:
        return "k" if kind == "1R" else CORNER_COLORS[kind]
    return WALL_REGION_COLORS[_ARC_REGION[kind]]


def corner_directions_figure(result: CornerDirectionsResult):
    """fig:corner_directions computed: the three directions that reach the corner, from the flow.

    (a) configuration space: trajectories of the step system from Sigma_h to the corner, one
    colour per direction; (b) the same at the corner, with the arrival momenta as arrows; (c) the
    momenta at the corner, ``|p| = p1w_max``: the three admissible quarter circles and the
    measured arrivals; (d) the corner-singularity curves of Sigma_h (normal coordinates) traced by
    the reversed flow, parametrized by p1w, with the drawn trajectories' starts.

    Parameters
    ----------
    result : CornerDirectionsResult
        The computed scene.

    Returns
    -------
    matplotlib.figure.Figure
    """
    scene = result.scene
    fig, (axa, axb, axc, axd) = _grid(4, (2, 2), figure_inches(scene))
    qw1, qw2 = result.qw1, result.qw2
    allq = (
        np.concatenate([t.trajectory[:, [1, 3]] for t in result.trajectories])
        if result.trajectories
        else np.array([[qw1, qw2]])
    )
    lo1, lo2 = min(allq[:, 0].min(), qw1) - 0.2, min(allq[:, 1].min(), qw2) - 0.2
    hi1, hi2 = allq[:, 0].max() + 0.1, allq[:, 1].max() + 0.1
    zoom = 0.12 * max(hi1 - lo1, hi2 - lo2)
    styles = ("-", "--", "-.", ":")
    fr = sorted({t.p1w for t in result.trajectories})
    bottom = lo2 - 0.45 * (hi2 - lo2)  # room for panel (a)'s legend under the trajectories
    for ax in (axa, axb):
        _draw_step(ax, qw1, qw2, lo1, bottom)
        for i, t in enumerate(result.trajectories):
            c = CORNER_COLORS[t.direction]
            ls = styles[fr.index(t.p1w) % len(styles)]
            lab = (_DIRECTION_LABELS[t.direction] + rf", $p_1^w={t.p1w:.3f}$") if ax is axa else None
            (ln,) = ax.plot(t.trajectory[:, 1], t.trajectory[:, 3], color=c, lw=1.0, ls=ls, label=lab)
            ln.set_gid(f"trajectory:{t.direction}:{i}")
            if ax is axa:
                (st,) = ax.plot(t.trajectory[0, 1], t.trajectory[0, 3], "o", color=c, ms=4)
                st.set_gid(f"start:{t.direction}:{i}")
            else:
                p = t.arrival[[1, 3]] / result.p1w_max * 0.6 * zoom
                arr = ax.annotate(
                    "",
                    xy=(qw1, qw2),
                    xytext=(qw1 - p[0], qw2 - p[1]),
                    arrowprops=dict(arrowstyle="-|>", color=c, lw=1.2),
                )
                arr.set_gid(f"arrival:{t.direction}:{i}")
        ax.set_xlabel(r"$q_1$")
        ax.set_ylabel(r"$q_2$")
        ax.set_aspect("equal", adjustable="box")
    axa.set_xlim(lo1, hi1)
    axa.set_ylim(bottom, hi2)
    axa.legend(fontsize=6.5, loc="lower right", framealpha=0.85, ncol=2)
    axa.set_title(r"(a) trajectories of the step system from $\Sigma_h$ to the corner", fontsize=9)
    axb.set_xlim(qw1 - zoom, qw1 + zoom)
    axb.set_ylim(qw2 - zoom, qw2 + zoom)
    for d, (dx, dy) in (("R0", (0.25, -0.55)), ("01", (-0.75, 0.45)), ("1R", (0.25, 0.5))):
        axb.text(
            qw1 + dx * zoom,
            qw2 + dy * zoom,
            _DIRECTION_LABELS[d].split("=")[0] + "$",
            color=CORNER_COLORS[d],
            fontsize=11,
        )
    axb.set_title("(b) at the corner: the arrival momenta (arrows)", fontsize=9)
    r = result.p1w_max
    a = np.linspace(0, 2 * np.pi, 361)
    axc.plot(r * np.cos(a), r * np.sin(a), color="0.8", lw=0.8)
    quarter = {"R0": (np.pi / 2, np.pi), "01": (1.5 * np.pi, 2 * np.pi), "1R": (np.pi, 1.5 * np.pi)}
    for d, (a0, a1) in quarter.items():
        aa = np.linspace(a0, a1, 91)
        (ln,) = axc.plot(r * np.cos(aa), r * np.sin(aa), color=CORNER_COLORS[d], lw=2.5, label=_DIRECTION_LABELS[d])
        ln.set_gid(f"momenta:{d}")
    axc.text(0.35 * r, 0.35 * r, "none:\nwould come from\ninside the step", fontsize=7, color="0.4", ha="center")
    for i, t in enumerate(result.trajectories):
        (pt,) = axc.plot(t.arrival[1], t.arrival[3], "o", color=CORNER_COLORS[t.direction], ms=5, mec="k", mew=0.5)
        pt.set_gid(f"arrival_momentum:{t.direction}:{i}")
    axc.axhline(0, color="0.6", lw=0.6)
    axc.axvline(0, color="0.6", lw=0.6)
    axc.set_aspect("equal")
    axc.set_xlabel(r"$p_1$ at the corner")
    axc.set_ylabel(r"$p_2$ at the corner")
    axc.legend(fontsize=7, loc="lower left", framealpha=0.85)
    axc.set_title(rf"(c) incoming momenta, $|p|=\sqrt{{2(h-h^w_\varepsilon)}}={r:.4f}$ (dots: measured)", fontsize=9)
    for d, c in result.curves.items():
        ok = c["reached"]
        (ln,) = axd.plot(
            np.where(ok, c["phi"], np.nan),
            np.where(ok, c["K"], np.nan),
            "-",
            color=CORNER_COLORS[d],
            lw=1.2,
            marker=".",
            ms=3,
            label=rf"$\sigma_{{{d}}}$ ({int(ok.sum())}/{ok.size} reach the corner)",
        )
        ln.set_gid(f"curve:{d}")
        if (~ok & np.isfinite(c["phi"])).any():
            axd.plot(c["phi"][~ok], c["K"][~ok], "x", color=CORNER_COLORS[d], ms=4)
    for i, t in enumerate(result.trajectories):
        (pt,) = axd.plot(t.phi, t.K, "o", color=CORNER_COLORS[t.direction], ms=6, mec="k", mew=0.6)
        pt.set_gid(f"start:{t.direction}:{i}")
    axd.axhline(0.0, color=GEOMETRY_COLOR, lw=0.8)
    axd.set_xlim(-np.pi, np.pi)
    axd.set_xlabel(r"$\phi$")
    axd.set_ylabel(r"$K$")
    axd.legend(fontsize=7, loc="lower right", framealpha=0.85)
    axd.set_title(r"(d) corner-singularity curves of $\Sigma_h$, traced back from the corner", fontsize=9)
    fig.suptitle(scene.title + _quick(result) + "\n" + _system_text(scene), fontsize=9)
    return fig


def wall_tangency_figure(result: WallTangencyResult):
    """fig:Sigma_0_wall computed: the wall's tangency line, its seven points and their trajectories.

    (a) The wall section in the (q2, p2) plane: the interior of the tangency line
    (``Sigma_h^{w,-}``) coloured by the flow's label of the return through each point (J_R, J_0,
    J_1 in the paper's colours), the band ``Sigma_h^>`` outside it (J_0u), the line q2 = qw2 and
    the caption's seven points. (b) Their trajectories (the smooth flow: they only touch
    q1 = qw1) in configuration space, from Sigma_h to Sigma_h; (c) the same at the wall. Points
    1-3 move down when they touch (p2 < 0: solid), 5-7 up (dashed); 1 and 7, 2 and 6, 3 and 5 touch
    at the same place (one colour each): at eps = 0 each pair is one curve run both ways (time
    reversal flips p2 where p1 = 0).

    Parameters
    ----------
    result : WallTangencyResult
        The computed scene.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    scene = result.scene
    fig, (axw, axq, axz) = _grid(3, (1, 3), figure_inches(scene))
    ln_, out = result.line, result.outer
    band = axw.fill(
        np.concatenate([out["q2"], ln_["q2"][::-1]]),
        np.concatenate([out["p2"], ln_["p2"][::-1]]),
        color=WALL_REGION_COLORS[Region.BESIDE],
        lw=0,
        zorder=0,
        label=r"$\Sigma_h^{>}$: turns back before $q_1=q_1^w$ ($J_{0u}$)",
    )
    band[0].set_gid("band")
    g = result.grid
    handles = [band[0]]
    for reg, col in WALL_REGION_COLORS.items():
        sel = (g["region"] == int(reg)) & np.isfinite(g["q2"])
        if sel.any():
            h = axw.scatter(
                g["q2"][sel],
                g["p2"][sel],
                s=scene.marker_size,
                c=col,
                lw=0,
                rasterized=True,
                label=_WALL_LABELS[reg] + " (the flow's label)",
            )
            h.set_gid(f"region:{Region(reg).label}")
            handles.append(h)
    (lt,) = axw.plot(ln_["q2"], ln_["p2"], color="k", lw=1.2, label=r"tangency line $\Xi^0_{wall}$ ($p_1=0$)")
    lt.set_gid("tangency")
    handles.append(lt)
    axw.axvline(result.qw2, color="k", lw=0.8, ls="--")
    tab = plt.get_cmap("tab10")

    def colors(number):  # one colour per place of touching: 1 and 7, 2 and 6, 3 and 5, 4
        return tab(min(number, 8 - number) - 1)

    for p in result.points:
        (pt,) = axw.plot(p.q2, p.p2, "o", color=colors(p.number), ms=7, mec="k", mew=0.7)
        pt.set_gid(f"point:{p.number}")
        axw.annotate(str(p.number), (p.q2, p.p2), xytext=(6, 4), textcoords="offset points", fontsize=10, weight="bold")
    axw.set_xlabel(r"$q_2$")
    axw.set_ylabel(r"$p_2$")
    axw.set_aspect("equal", adjustable="datalim")
    leg = axw.legend(handles=handles, fontsize=7, loc="upper right", framealpha=0.85)
    for h in leg.legend_handles:
        if hasattr(h, "set_sizes"):
            h.set_sizes([25.0])
    axw.set_title(r"(a) the wall section $\Sigma_h^{*,-}$ ($q_1=q_1^w$); dashed: $q_2=q_2^w$", fontsize=9)
    allq = np.concatenate([p.trajectory[:, [1, 3]] for p in result.points])
    lo1, lo2 = min(allq[:, 0].min(), result.qw1) - 0.2, min(allq[:, 1].min(), result.qw2) - 0.2
    where = {
        1: "above the corner",
        2: "at the corner",
        3: "right wall",
        4: "right wall",
        5: "right wall",
        6: "at the corner",
        7: "above the corner",
    }
    for ax in (axq, axz):
        _draw_step(ax, result.qw1, result.qw2, lo1, lo2)
        ax.axvline(result.qw1, color="k", lw=0.6, ls=":")
        for p in result.points:
            c = colors(p.number)
            lab = f"{p.number}: {where[p.number]} (step system: {p.status.lower()})" if ax is axq else None
            (ln,) = ax.plot(
                p.trajectory[:, 1], p.trajectory[:, 3], color=c, lw=1.0, ls="-" if p.p2 <= 0 else "--", label=lab
            )
            ln.set_gid(f"trajectory:{p.number}")
            ax.plot(result.qw1, p.q2, "o", color=c, ms=5, mec="k", mew=0.5, zorder=4)
        ax.set_xlabel(r"$q_1$")
        ax.set_ylabel(r"$q_2$")
    for q2 in sorted({round(p.q2, 9) for p in result.points}):
        nums = ", ".join(str(p.number) for p in result.points if round(p.q2, 9) == q2)
        axz.annotate(
            nums,
            (result.qw1, q2),
            xytext=(-8, 0),
            textcoords="offset points",
            fontsize=9,
            weight="bold",
            va="center",
            ha="right",
        )
    axq.set_xlim(lo1, allq[:, 0].max() + 0.1)
    axq.set_ylim(lo2, allq[:, 1].max() + 0.1)
    axq.legend(fontsize=6.5, loc="lower right", framealpha=0.9)
    axq.set_title("(b) their trajectories (smooth flow), one return; pairs 1-7, 2-6, 3-5 share one curve", fontsize=9)
    span = max(p.q2 for p in result.points) - min(p.q2 for p in result.points)
    axz.set_xlim(result.qw1 - 0.15 * span, result.qw1 + 0.45 * span)
    axz.set_ylim(min(p.q2 for p in result.points) - 0.15 * span, max(p.q2 for p in result.points) + 0.15 * span)
    axz.set_title("(c) at the wall: each touches $q_1=q_1^w$", fontsize=9)
    fig.suptitle(scene.title + _quick(result) + "\n" + _system_text(scene), fontsize=9)
    return fig


def wall_section_figure(result: WallSectionResult):
    """fig:wallsection computed: corner-singularity curves of the wall section and a fixed circle.

    Left column: the wall section in the (q2, p2) plane (top) and in wall coordinates
    (theta, rho_w) (bottom): the tangency line, the corner-singularity curves sigma_R0^-, sigma_01^-,
    sigma_1R^- measured by bisection of the flow's labels (red, blue, green), and the circle
    ``rho_w = const`` coloured by the flow's label of each point (J_R yellow, J_0 gray, J_1 cyan).
    Right column: the trajectory segments through chosen points of the circle in configuration
    space (top: one return; bottom: at the corner), those at the circle's corner crossings in the
    caption's red, blue and black; solid dots where each crosses the wall section, in both columns.

    Parameters
    ----------
    result : WallSectionResult
        The computed scene.

    Returns
    -------
    matplotlib.figure.Figure
    """
    scene = result.scene
    fig, (axw, axq, axr, axz) = _grid(4, (2, 2), figure_inches(scene))
    tg, ci, cu = result.tangency, result.circle, result.curves
    order = np.argsort(result.tangency["theta"])
    (lt,) = axw.plot(
        np.append(tg["q2"][order], tg["q2"][order][0]),
        np.append(tg["p2"][order], tg["p2"][order][0]),
        color="k",
        lw=1.0,
        label=r"tangency line $\rho_w=0$",
    )
    lt.set_gid("tangency")
    axr.axhline(0.0, color="k", lw=1.0)
    axw.axvline(result.qw2, color="k", lw=0.8, ls="--")
    handles = [lt]
    for reg, col in WALL_REGION_COLORS.items():
        sel = ci["region"] == int(reg)
        if sel.any():
            lab = _WALL_LABELS[reg] + rf" arc of $\rho_w={result.rho_w:.4f}$"
            h = axw.scatter(ci["q2"][sel], ci["p2"][sel], s=6, c=col, lw=0, label=lab, zorder=3)
            h.set_gid(f"arc:{Region(reg).label}")
            hr = axr.scatter(ci["theta"][sel], np.full(sel.sum(), result.rho_w), s=6, c=col, lw=0, zorder=3)
            hr.set_gid(f"arc:{Region(reg).label}")
            handles.append(h)
    for d in ("R0", "01", "1R"):
        c = CORNER_COLORS[d]
        (lw,) = axw.plot(
            cu[f"q2_{d}"], cu[f"p2_{d}"], "-", color=c, lw=1.2, marker=".", ms=4, label=rf"$\sigma^-_{{{d}}}$"
        )
        lw.set_gid(f"curve:{d}")
        (lr,) = axr.plot(cu[f"theta_{d}"], cu["rho_w"], "-", color=c, lw=1.2, marker=".", ms=4)
        lr.set_gid(f"curve:{d}")
        handles.append(lw)
    for i, g in enumerate(result.segments):
        c = _segment_color(g.kind)
        for ax, x, y in ((axw, g.wall[2], g.wall[3]), (axr, g.theta, result.rho_w)):
            (pt,) = ax.plot(x, y, "o", color=c, ms=6, mec="k", mew=0.6, zorder=4)
            pt.set_gid(f"dot:{g.kind}:{i}")
    axw.set_xlabel(r"$q_2$")
    axw.set_ylabel(r"$p_2$")
    axw.set_aspect("equal", adjustable="datalim")
    axw.legend(handles=handles, fontsize=7, loc="upper right", framealpha=0.85)
    axw.set_title(r"(a) the wall section $\Sigma_h^{w,-}$ in the $(q_2, p_2)$ plane; dashed $q_2=q_2^w$", fontsize=9)
    axr.set_xlim(-np.pi, np.pi)
    axr.set_ylim(-0.04 * result.rho_max, 1.05 * max(result.rho_max, np.nanmax(cu["rho_w"])))
    axr.set_xlabel(r"$\theta$ (wall angle)")
    axr.set_ylabel(r"$\rho_w$")
    b = result.boundaries
    axr.set_title(
        rf"(c) wall coordinates: $\theta_{{R0}}={b['R0']:.4f}$, $\theta_{{01}}={b['01']:.4f}$, "
        rf"$\theta_{{1R}}={b['1R']:.4f}$",
        fontsize=9,
    )
    segs = [g.trajectory[:, [1, 3]] for g in result.segments]
    allq = np.concatenate(segs) if segs else np.array([[result.qw1, result.qw2]])
    lo1, lo2 = min(allq[:, 0].min(), result.qw1) - 0.2, min(allq[:, 1].min(), result.qw2) - 0.2
    zoom = 0.25
    for ax in (axq, axz):
        _draw_step(ax, result.qw1, result.qw2, lo1, lo2)
        ax.axvline(result.qw1, color="k", lw=0.6, ls=":")
        labelled = set()
        for i, g in enumerate(result.segments):
            c = _segment_color(g.kind)
            lab = None
            if ax is axq and (g.kind, g.itinerary, g.status) not in labelled:
                labelled.add((g.kind, g.itinerary, g.status))
                lab = (
                    rf"on $\sigma^-_{{{g.kind}}}$" if g.kind in CORNER_COLORS else _WALL_LABELS[_ARC_REGION[g.kind]]
                ) + f": {g.itinerary or g.status.lower()}"
            # At eps = 0 the segment on sigma_1R leaves the corner (after the upper wall) along the one
            # on sigma_01 reversed, and the one on sigma_R0 (after the right wall) along the one on
            # sigma_1R reversed (the same |p1| and H2): widths, dashes and order keep all visible.
            style = _CORNER_SEGMENT_STYLE.get(g.kind, dict(lw=1.0, ls="-", zorder=2))
            (ln,) = ax.plot(
                g.trajectory[:, 1],
                g.trajectory[:, 3],
                color=c if g.kind in CORNER_COLORS else _darker(c),
                label=lab,
                **style,
            )
            ln.set_gid(f"segment:{g.kind}:{i}")
            (pt,) = ax.plot(g.wall[0], g.wall[2], "o", color=c, ms=6, mec="k", mew=0.6, zorder=4)
            pt.set_gid(f"dot:{g.kind}:{i}")
        ax.set_xlabel(r"$q_1$")
        ax.set_ylabel(r"$q_2$")
    hi2 = allq[:, 1].max() + 0.05
    axq.set_xlim(lo1, allq[:, 0].max() + 0.1)
    axq.set_ylim(lo2, hi2 + 0.3 * (hi2 - lo2))  # room for the legend above the segments
    axq.legend(fontsize=6.5, loc="upper right", framealpha=0.85, ncol=3)
    axq.set_title("(b) trajectory segments through the circle's points (dots: on the wall section)", fontsize=9)
    axz.set_xlim(result.qw1 - zoom, result.qw1 + zoom)
    axz.set_ylim(result.qw2 - zoom, result.qw2 + zoom)
    axz.set_aspect("equal")
    axz.set_title("(d) the same at the corner", fontsize=9)
    fig.suptitle(scene.title + _quick(result) + "\n" + _system_text(scene), fontsize=9)
    return fig


#: Line styles of the segments at the corner-singularity crossings (drawn over the others).
_CORNER_SEGMENT_STYLE = {
    "R0": dict(lw=3.5, ls="-", zorder=3),
    "1R": dict(lw=1.8, ls="-", zorder=3.5),
    "01": dict(lw=1.4, ls=(0, (4, 2)), zorder=3.8),
}


def _darker(color: str) -> tuple:
    """A darker shade of a fill colour, for a line drawn in it (the paper's yellow is faint as a line)."""
    from matplotlib.colors import to_rgb

    return tuple(0.8 * x for x in to_rgb(color))


def _transit_text(study) -> str:
    lines = []
    for d, t in (("up", study.up), ("down", study.down)):
        k = int(np.count_nonzero(t.crossed))
        reach = np.nanmax(t.s_max) if d == "up" else np.nanmin(t.s_min)
        rate = t.escape_rate
        lines.append(
            f"{d}: {k}/{t.crossed.size} crossed s={t.start_s:g}->{t.target_s:g} in {t.n_steps:,} returns; "
            f"{'highest' if d == 'up' else 'lowest'} s reached {reach:.3f}"
            + (f"; rate {rate[0]:.2g}+-{rate[1]:.1g}/return" if rate is not None else "")
        )
    return "\n".join(lines)


def impact_zone_figure(result: ImpactZoneResult):
    """Does anything cross the impact zone? The flow (left) and its model (right).

    Top: the scan's orbits in the zone coordinate s (0 on the floor, 1 on the critical curve),
    coloured by class (circle, islands, chaotic, undecided); the levels where a two-sided barrier
    crosses the scan's line are dashed. Bottom: for each start (its level s0 on the line), the
    range of s its orbit visited, in the class colour; barriers dashed; the transit statistics.

    Parameters
    ----------
    result : ImpactZoneResult
        The computed scene.

    Returns
    -------
    matplotlib.figure.Figure
    """
    scene, q = result.scene, _quick(result)
    fig, axes = _grid(4, (2, 2), figure_inches(scene))
    for col, study in enumerate((result.flow, result.model)):
        top, bottom = axes[col], axes[2 + col]
        sc, zone = study.scan, study.zone
        title = "full return map (flow)" if col == 0 else f"truncated model ({result.model_name} forcing)"
        for kind, color in CLASS_COLORS.items():
            rows = np.flatnonzero(sc.kind == kind)
            if sc.phi is not None and rows.size:
                P, Kk = sc.phi[rows].ravel(), sc.K[rows].ravel()
                ok = np.isfinite(P) & np.isfinite(Kk)
                top.scatter(
                    P[ok], zone.s(P[ok], Kk[ok]), s=0.3, color=color, rasterized=True, label=f"{kind} ({rows.size})"
                ).set_gid(f"class:{kind}")
            if rows.size:
                bottom.vlines(sc.s0[rows], sc.s_min[rows], sc.s_max[rows], color=color, lw=2).set_gid(f"range:{kind}")
        for ax in (top, bottom):
            for b in sc.barriers:
                (top if ax is top else bottom).axhline(b, color="k", ls="--", lw=0.7, gid="barrier")
            ax.axhline(0.0, color=GEOMETRY_COLOR, lw=1.0, gid="floor")
            ax.axhline(1.0, color="k", lw=1.0, gid="ceiling")
        for b in sc.barriers:
            bottom.axvline(b, color="k", ls=":", lw=0.5)
        bottom.plot([0, 1], [0, 1], color=GEOMETRY_COLOR, lw=0.5)
        top.set_xlim(-np.pi, np.pi)
        top.set_ylim(-0.1, 1.1)
        top.set_xlabel(r"$\phi$")
        top.set_ylabel(r"zone coordinate $s$ (floor 0, critical curve 1)")
        top.set_title(
            f"({'ab'[col]}) {title}: {len(sc)} orbits on {sc.line}, {sc.n_steps:,} returns; "
            f"{int(sc.barrier.sum())} barrier(s), {len(sc.layers)} layer(s){q}",
            fontsize=8,
        )
        top.legend(loc="upper right", fontsize=7, markerscale=12)
        bottom.set_xlim(0, 1)
        bottom.set_ylim(-0.1, 1.1)
        bottom.set_xlabel(f"start level $s_0$ on {sc.line}")
        bottom.set_ylabel("levels visited by the orbit")
        bottom.set_title(
            f"({'cd'[col]}) layers; no orbit spans s 0.1..0.9: {sc.spanning(0.1, 0.9).size == 0}", fontsize=8
        )
        bottom.text(0.02, 0.98, _transit_text(study), transform=bottom.transAxes, fontsize=7, va="top", gid="transit")
    fig.suptitle(
        scene.title + "\n" + _system_text(scene) + f"; the model acts with eps b1 = {scene.system.eps * result.b1:.4g}",
        fontsize=9,
    )
    return fig


_RENDERERS = {
    OrbitSceneResult: orbit_figure,
    HoveringAreaResult: hovering_area_figure,
    FlowPortraitResult: flow_portrait_figure,
    FlowHoveringResult: flow_hovering_figure,
    TangentToriResult: tangent_tori_figure,
    SigmaStructureResult: sigma_structure_figure,
    CornerDirectionsResult: corner_directions_figure,
    WallTangencyResult: wall_tangency_figure,
    WallSectionResult: wall_section_figure,
    ImpactZoneResult: impact_zone_figure,
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
