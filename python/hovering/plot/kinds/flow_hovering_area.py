"""The figure of the ``flow_hovering_area`` kind: |HOV| against eps for the flow, its models and
eq:hovsetsize (a), and how often flow and models agree on a point (b).
"""

from __future__ import annotations

import numpy as np

from ...scenes.results import FlowHoveringResult
from ...scenes.spec import figure_inches
from ..common import draws, grid, quick_mark, system_text

__all__ = ["flow_hovering_figure"]


@draws("flow_hovering_area")
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
    fig, (ax, axa) = grid(2, (1, 2), figure_inches(scene))
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
    fig.suptitle(scene.title + quick_mark(result) + "\n" + system_text(scene, result), fontsize=9)
    return fig
