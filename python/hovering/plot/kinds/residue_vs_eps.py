"""The figure of the ``residue_vs_eps`` kind: a periodic orbit's residue along its branch in eps."""

from __future__ import annotations

from ...scenes.results import ResidueResult
from ...scenes.spec import figure_inches
from ..common import draws, quick_mark, system_text

__all__ = ["residue_figure"]


@draws("residue_vs_eps")
def residue_figure(result: ResidueResult):
    """Residue against eps: the elliptic band 0 < R < 1 shaded, folds (R through 0) and period
    doublings (R through 1) marked.

    Parameters
    ----------
    result : ResidueResult
        The computed scene.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    scene = result.scene
    fig, ax = plt.subplots(figsize=figure_inches(scene), constrained_layout=True)
    ax.axhspan(0.0, 1.0, color="C2", alpha=0.12, label="elliptic: 0 < R < 1")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.axhline(1.0, color="k", lw=0.6, ls="--")
    b = result.branch
    if b is not None:
        (ln,) = ax.plot(b.parameter, b.residue, "-o", ms=2.5, color="C0", label=f"period {b.period}")
        ln.set_gid("branch")
        for e in b.events:
            ax.axvline(e["parameter"], color="C3" if e["kind"] == "fold" else "C1", lw=0.8, ls=":")
            ax.annotate(e["kind"], (e["parameter"], 1.0), fontsize=7, rotation=90, va="bottom")
    elif result.start is not None and result.start.converged:
        ax.plot([result.start.residue], "o")
    ax.set_xlabel(r"$\varepsilon$")
    ax.set_ylabel(r"residue $R = (2 - \mathrm{tr}\,M) / 4$")
    ax.legend(fontsize=7)
    fig.suptitle(f"{scene.title}{quick_mark(result)}\n{system_text(scene, result)}  [{scene.map}]", fontsize=9)
    return fig
