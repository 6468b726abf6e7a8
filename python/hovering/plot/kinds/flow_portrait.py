"""The figure of the ``flow_portrait`` kind: the flow's return map (left) and its truncated model
(right) from the same starts.
"""

from __future__ import annotations

import numpy as np

from ...scenes.results import FlowPortraitResult
from ...scenes.spec import figure_inches
from ..common import draws, grid, quick_mark, region_legend, system_text
from ..primitives import draw_geometry, plot_orbits

__all__ = ["flow_portrait_figure"]


@draws("flow_portrait")
def flow_portrait_figure(result: FlowPortraitResult):
    """The full return map (left) and its truncated model (right) from the same starts.

    Points are coloured by the region of the return taken from them when regions were recorded
    (else by orbit); the flow panel draws the corner-singularity curves measured on the flow
    (dotted markers at the measured circles), the model panel its closed forms; both draw K = 0,
    L1 and L2.

    Parameters
    ----------
    result : FlowPortraitResult
        The computed scene.

    Returns
    -------
    matplotlib.figure.Figure
    """
    scene, q = result.scene, quick_mark(result)
    fig, axes = grid(2, (1, 2), figure_inches(scene), sharey=True)
    o = result.onset
    titles = (
        f"(a) full return map (flow), {result.meta.get('n_steps')} returns",
        f"(b) truncated model ({result.model_name} forcing), onset arcs "
        rf"$\Omega_0={o['Omega0']:.4f}$, $\theta_w={o['theta_w']:.4f}$",
    )
    for ax, orbits, geom, title in zip(
        axes, (result.flow, result.model), (result.flow_geometry, result.model_geometry), titles
    ):
        by_region = orbits.region is not None
        colls = plot_orbits(
            ax, orbits, color_by="region" if by_region else "orbit", s=scene.marker_size, colors=orbits.colors
        )
        if by_region:
            region_legend(ax, colls)
        else:
            for i, c in enumerate(colls):
                c.set_gid(f"orbit:{orbits.labels[i]}")
        draw_geometry(ax, geom)
        ax.set_xlim(-np.pi, np.pi)
        ax.set_xlabel(r"$\phi$")
        ax.set_ylabel(r"$K$")
        ax.set_title(title + q, fontsize=8)
    lo = min(float(np.nanmin(result.flow.K)), float(np.nanmin(result.model.K)), 0.0)
    hi = max(float(np.nanmax(result.flow.K)), float(np.nanmax(result.model.K)), 0.0)
    d = 0.05 * (hi - lo) if hi > lo else 0.1
    axes[0].set_ylim(lo - d, hi + d)
    fig.suptitle(scene.title + "\n" + system_text(scene, result), fontsize=9)
    return fig
