"""What the figures of several scene kinds share (a grid of axes, the quick-run mark, region
legends, the system's line under a flow figure's title, the step drawn in configuration space), and
the table of figures: each ``hovering/plot/kinds/<kind>.py`` registers its figure with
:func:`draws`, and :func:`hovering.plot.render` finds it by the result's kind.

Drawing only: every function here is a pure function of results and never computes a map.
"""

from __future__ import annotations

from collections.abc import Callable

from .._enums import Region
from .._style import QUICK_MARK

__all__ = [
    "draws",
    "figure_of",
    "drawn_kinds",
    "grid",
    "quick_mark",
    "region_legend",
    "system_text",
    "draw_step",
    "WALL_LABELS",
]

_FIGURES: dict = {}


def draws(*kinds: str) -> Callable:
    """Decorator: the figure of these scene kinds (``@draws("tangent_tori") def figure(result)``).

    Parameters
    ----------
    *kinds : str
        Names of registered scene kinds (:mod:`hovering.scenes.registry`).

    Returns
    -------
    callable
        The decorator; it returns the function unchanged.

    Raises
    ------
    ValueError
        For a kind another module already draws.
    """

    def register(fn: Callable) -> Callable:
        for k in kinds:
            old = _FIGURES.get(k)
            # A module imported again (importlib.reload) replaces its own figure; another may not.
            if old is not None and old.__module__ != fn.__module__:
                raise ValueError(f"the figure of kind {k!r} is already drawn by {old.__module__}.{old.__qualname__}")
            _FIGURES[k] = fn
        return fn

    return register


def figure_of(kind: str) -> Callable | None:
    """The figure function of a scene kind.

    Parameters
    ----------
    kind : str
        The kind's name.

    Returns
    -------
    callable or None
        ``figure(result) -> matplotlib.figure.Figure``; None when no module draws the kind.
    """
    return _FIGURES.get(kind)


def drawn_kinds() -> tuple:
    """The kinds that have a figure, sorted.

    Returns
    -------
    tuple of str
    """
    return tuple(sorted(_FIGURES))


def grid(n: int, layout, figsize, sharey: bool = False):
    """A figure with ``n`` axes on a ``(rows, cols)`` grid (default: one column), cells beyond ``n`` removed.

    Parameters
    ----------
    n : int
        Axes drawn.
    layout : tuple of int or None
        ``(rows, cols)``.
    figsize : tuple of float
        Inches.
    sharey : bool, optional
        Axes share their y axis.

    Returns
    -------
    tuple
        ``(figure, list of n axes)``.
    """
    import matplotlib.pyplot as plt

    rows, cols = layout if layout is not None else (n, 1)
    fig, axes = plt.subplots(rows, cols, figsize=figsize, constrained_layout=True, squeeze=False, sharey=sharey)
    flat = list(axes.ravel())
    for ax in flat[n:]:
        fig.delaxes(ax)
    return fig, flat[:n]


def quick_mark(result) -> str:
    """The mark a title of a quick run gets (empty for a full run).

    Parameters
    ----------
    result : SceneResult
        The result.

    Returns
    -------
    str
    """
    return QUICK_MARK if result.meta.get("quick") else ""


def region_legend(ax, handles) -> None:
    """A legend of region colours, its dots legible whatever the marker size of the points.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The axes.
    handles : list
        The region scatters.
    """
    leg = ax.legend(handles=handles, loc="upper right", fontsize=7, framealpha=0.85)
    for h in leg.legend_handles:
        h.set_sizes([25.0])


def system_text(scene, result=None) -> str:
    """One line under a flow figure's title: potentials, eps, the step's corner, h, the integrator.

    The integrator is named as it ran: the setting the result records (an accuracy target's
    measured choice), else the scene's stepper with ``auto`` resolved on its system.

    Parameters
    ----------
    scene : FlowScene
        The scene.
    result : SceneResult, optional
        Its result (``meta["accuracy"]["integrator"]``, where the kind records it).

    Returns
    -------
    str
    """
    s = scene.system

    def pot(p):
        return f"{p.kind}({p.omega:g}" + (f", {p.alpha:g})" if p.alpha is not None else ")")

    ran = (((getattr(result, "meta", None) or {}).get("accuracy") or {}).get("integrator")) or {}
    if "stepper" in ran and "rtol" in ran:
        integrator = scene.integrator.label(ran=ran)
    else:
        integrator = scene.integrator.label(s.build())
    return (
        rf"$V_1$={pot(s.V1)}, $V_2$={pot(s.V2)}, $\varepsilon={s.eps:g}$, $q_w=({s.qw1:g}, {s.qw2:g})$, "
        rf"$h={scene.h:g}$, {integrator}"
    )


#: Legend text of the wall-section regions in the paper's colours.
WALL_LABELS = {
    Region.RIGHT: r"$J_R$",
    Region.ABOVE: r"$J_0$",
    Region.UPPER: r"$J_1$",
    Region.BESIDE: r"$J_{0u}$",
    Region.MULTI: "2+ impacts",
}


def draw_step(ax, qw1: float, qw2: float, lo1: float, lo2: float) -> None:
    """The step {q1 < qw1, q2 < qw2} shaded, its two walls in black.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The axes (configuration space).
    qw1, qw2 : float
        The corner.
    lo1, lo2 : float
        Where the shading ends, left and below.
    """
    ax.fill([lo1, qw1, qw1, lo1], [lo2, lo2, qw2, qw2], color="0.85", zorder=0, lw=0)
    (ln,) = ax.plot([lo1, qw1, qw1], [qw2, qw2, lo2], color="k", lw=1.2, zorder=1)
    ln.set_gid("step")
