"""The figure of the ``hovering_area`` kind: |HOV| against eps with error bars and the theory
eq:hovsetsize (a), and their ratio (b).
"""

from __future__ import annotations

from ...scenes.results import HoveringAreaResult
from ...scenes.spec import figure_inches
from ..common import draws, grid, quick_mark

__all__ = ["hovering_area_figure"]


@draws("hovering_area")
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
    fig, (ax, axr) = grid(2, (1, 2), figure_inches(scene))
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
    fig.suptitle(scene.title + quick_mark(result))
    return fig
