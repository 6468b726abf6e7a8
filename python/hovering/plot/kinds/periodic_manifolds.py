"""The figure of the ``periodic_manifolds`` kind: the portrait, the periodic orbits over it and the
manifolds of the hyperbolic ones."""

from __future__ import annotations

import numpy as np

from ...scenes.results import PeriodicManifoldsResult
from ...scenes.spec import figure_inches
from ..common import draws, quick_mark, system_text

__all__ = ["periodic_manifolds_figure"]


@draws("periodic_manifolds")
def periodic_manifolds_figure(result: PeriodicManifoldsResult):
    """The portrait in grey; elliptic orbits as green circles, hyperbolic ones as red crosses (with
    their residues); unstable branches red, stable branches blue (drawn in phi wrapped to the box,
    broken where they cross phi = +-pi or a corner curve).

    Parameters
    ----------
    result : PeriodicManifoldsResult
        The computed scene.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    scene = result.scene
    fig, ax = plt.subplots(figsize=figure_inches(scene), constrained_layout=True)
    if result.portrait_phi.size:
        ax.plot(
            result.portrait_phi.ravel(),
            result.portrait_K.ravel(),
            ".",
            ms=0.8,
            color="0.55",
            rasterized=True,
            gid="portrait",
        )
    for w in result.manifolds:
        p, k = np.array(w.phi, dtype=float), np.array(w.K, dtype=float)
        jump = np.abs(np.diff(p)) > np.pi
        p = np.insert(p, np.flatnonzero(jump) + 1, np.nan)
        k = np.insert(k, np.flatnonzero(jump) + 1, np.nan)
        color = "C3" if w.kind == "unstable" else "C0"
        (ln,) = ax.plot(p, k, color=color, lw=0.6)
        ln.set_gid(f"manifold:{w.kind}")
    style = {"elliptic": ("o", "C2"), "parabolic": ("D", "0.3")}
    for i, o in enumerate(result.orbits):
        marker, color = style.get(o.stability, ("x", "C3"))
        label = f"{o.stability} {o.winding}/{o.period}, R = {o.residue:.3g}"
        (pt,) = ax.plot(o.phi, o.K, marker, color=color, ms=6, mew=1.5, label=label)
        pt.set_gid(f"orbit:{i}")
    ax.set_xlim(*scene.phi_range)
    ax.set_ylim(*scene.K_range)
    ax.set_xlabel(r"$\phi$")
    ax.set_ylabel(r"$K$")
    if result.orbits:
        ax.legend(fontsize=7, loc="upper right", title=f"period {scene.period}")
    fig.suptitle(f"{scene.title}{quick_mark(result)}\n{system_text(scene, result)}  [{scene.map}]", fontsize=9)
    return fig
