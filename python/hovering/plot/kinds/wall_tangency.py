"""The figure of the ``wall_tangency`` kind (fig:Sigma_0_wall): the wall section's tangency line with
the flow's labels of its interior, the caption's seven points and their trajectories.
"""

from __future__ import annotations

import numpy as np

from ..._enums import Region
from ..._style import WALL_REGION_COLORS
from ...scenes.results import WallTangencyResult
from ...scenes.spec import figure_inches
from ..common import WALL_LABELS, draw_step, draws, grid, quick_mark, system_text

__all__ = ["wall_tangency_figure"]


@draws("wall_tangency")
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
    fig, (axw, axq, axz) = grid(3, (1, 3), figure_inches(scene))
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
                label=WALL_LABELS[reg] + " (the flow's label)",
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
        draw_step(ax, result.qw1, result.qw2, lo1, lo2)
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
    fig.suptitle(scene.title + quick_mark(result) + "\n" + system_text(scene, result), fontsize=9)
    return fig
