"""The figure of the ``wall_section`` kind (fig:wallsection): the wall section's corner-singularity
curves and a circle's arcs, in the (q2, p2) plane and in wall coordinates, and the trajectory
segments through the circle.
"""

from __future__ import annotations

import numpy as np

from ..._enums import Region
from ..._style import CORNER_COLORS, WALL_REGION_COLORS
from ...scenes.results import WallSectionResult
from ...scenes.spec import figure_inches
from ..common import WALL_LABELS, draw_step, draws, grid, quick_mark, system_text

__all__ = ["wall_section_figure"]

#: Region of each arc label of a wall segment.
_ARC_REGION = {"R": Region.RIGHT, "0": Region.ABOVE, "1": Region.UPPER}


def _segment_color(kind: str) -> str:
    """Colour of a wall segment: its arc's region colour, or at a corner crossing the caption's
    red, blue, black (fig:wallsection draws the sigma_1R^- curve green but its segment black)."""
    if kind in CORNER_COLORS:
        return "k" if kind == "1R" else CORNER_COLORS[kind]
    return WALL_REGION_COLORS[_ARC_REGION[kind]]


@draws("wall_section")
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
    fig, (axw, axq, axr, axz) = grid(4, (2, 2), figure_inches(scene))
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
            lab = WALL_LABELS[reg] + rf" arc of $\rho_w={result.rho_w:.4f}$"
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
        draw_step(ax, result.qw1, result.qw2, lo1, lo2)
        ax.axvline(result.qw1, color="k", lw=0.6, ls=":")
        labelled = set()
        for i, g in enumerate(result.segments):
            c = _segment_color(g.kind)
            lab = None
            if ax is axq and (g.kind, g.itinerary, g.status) not in labelled:
                labelled.add((g.kind, g.itinerary, g.status))
                lab = (
                    rf"on $\sigma^-_{{{g.kind}}}$" if g.kind in CORNER_COLORS else WALL_LABELS[_ARC_REGION[g.kind]]
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
    fig.suptitle(scene.title + quick_mark(result) + "\n" + system_text(scene, result), fontsize=9)
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
