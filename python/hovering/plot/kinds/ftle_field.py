"""The figure of the ``ftle_field`` kind: the finite-time Lyapunov exponent over the box, forward and
backward side by side."""

from __future__ import annotations

import numpy as np

from ...scenes.results import FTLEResult
from ...scenes.spec import figure_inches
from ..common import draws, quick_mark, system_text

__all__ = ["ftle_figure"]


@draws("ftle_field")
def ftle_figure(result: FTLEResult):
    """The FTLE fields as images of (phi, K): ridges of the forward field are stable manifolds, of
    the backward field unstable ones; NaN (an orbit that stopped before n returns) is white.

    Parameters
    ----------
    result : FTLEResult
        The computed scene.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    scene = result.scene
    n = len(result.fields)
    fig, axes = plt.subplots(1, n, figsize=figure_inches(scene), constrained_layout=True, squeeze=False)
    for ax, f in zip(axes[0], result.fields):
        v = np.ma.masked_invalid(f.ftle)
        im = ax.pcolormesh(f.phi, f.K, v, shading="nearest", cmap="magma")
        im.set_gid(f"ftle:{f.direction}")
        ax.set_xlabel(r"$\phi$")
        ax.set_ylabel(r"$K$")
        ridge = "stable" if f.direction == "forward" else "unstable"
        ax.set_title(f"{f.direction} FTLE, n = {f.n_steps} (ridges: {ridge} manifolds)", fontsize=9)
        fig.colorbar(im, ax=ax, label="FTLE per return")
    fig.suptitle(f"{scene.title}{quick_mark(result)}\n{system_text(scene, result)}  [{scene.map}]", fontsize=9)
    return fig
