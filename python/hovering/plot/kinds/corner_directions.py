"""The figure of the ``corner_directions`` kind (fig:corner_directions): the three directions that
reach the corner, at the corner, as momenta, and as curves of Sigma_h.
"""

from __future__ import annotations

import numpy as np

from ..._style import CORNER_COLORS, GEOMETRY_COLOR
from ...scenes.results import CornerDirectionsResult
from ...scenes.spec import figure_inches
from ..common import draw_step, draws, grid, quick_mark, system_text

__all__ = ["corner_directions_figure"]

#: Legend text of each incoming direction (eq:p2corner).
_DIRECTION_LABELS = {"R0": r"$p_{R0}=(-p_1^w, P_2)$", "01": r"$p_{01}=(p_1^w, -P_2)$", "1R": r"$p_{1R}=(-p_1^w, -P_2)$"}


@draws("corner_directions")
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
    fig, (axa, axb, axc, axd) = grid(4, (2, 2), figure_inches(scene))
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
        draw_step(ax, qw1, qw2, lo1, bottom)
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
    fig.suptitle(scene.title + quick_mark(result) + "\n" + system_text(scene, result), fontsize=9)
    return fig
