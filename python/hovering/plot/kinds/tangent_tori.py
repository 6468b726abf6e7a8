"""The figure of the ``tangent_tori`` kind (fig:two-tang): the two tangent tori in (q1, q2), (q1, p1),
(q2, p2), with trajectories.
"""

from __future__ import annotations

import numpy as np

from ...scenes.results import TangentToriResult
from ...scenes.spec import figure_inches
from ..common import draws, quick_mark, system_text

__all__ = ["tangent_tori_figure"]


@draws("tangent_tori")
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
    fig.suptitle(scene.title + quick_mark(result) + "\n" + system_text(scene, result), fontsize=9)
    return fig
