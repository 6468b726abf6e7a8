"""The figure of the ``sigma_structure`` kind (fig:structure_Sigma): regions J_R, J_0, J_1 (left)
and their images (right), in three coordinate systems.
"""

from __future__ import annotations

import numpy as np

from ..._enums import Region
from ..._style import REGION_COLORS, REGION_LABELS
from ...scenes.results import SigmaStructureResult
from ...scenes.spec import figure_inches
from ..common import draws, grid, quick_mark, region_legend, system_text
from ..primitives import draw_geometry

__all__ = ["sigma_structure_figure"]


@draws("sigma_structure")
def sigma_structure_figure(result: SigmaStructureResult):
    """fig:structure_Sigma computed: regions J_R, J_0, J_1 (left) and their images (right).

    Rows: the (q2, p2) plane, section coordinates (theta, I), normal coordinates (phi, K). Each
    point of the band is coloured by the region of its return (its itinerary), on the left at the
    point and on the right at its image; the tangency circle K = 0 and its image are drawn in
    black, the measured corner-singularity curves on the (phi, K) row.

    Parameters
    ----------
    result : SigmaStructureResult
        The computed scene.

    Returns
    -------
    matplotlib.figure.Figure
    """
    scene = result.scene
    fig, axes = grid(6, (3, 2), figure_inches(scene))
    s = scene.marker_size
    rows = (
        ("q2", "p2", "q21", "p21", r"$q_2$", r"$p_2$"),
        ("theta", "I", "theta1", "I1", r"$\theta$", r"$I$"),
        ("phi", "K", "phi1", "K1", r"$\phi$", r"$K$"),
    )
    tg = result.tangency
    for r, (x, y, x1, y1, xl, yl) in enumerate(rows):
        for c, (xa, ya) in enumerate(((x, y), (x1, y1))):
            ax = axes[2 * r + c]
            X, Y = getattr(result, xa), getattr(result, ya)
            handles = []
            for reg, col in REGION_COLORS.items():
                sel = (result.region == int(reg)) & np.isfinite(X) & np.isfinite(Y)
                if sel.any():
                    h = ax.scatter(
                        X[sel],
                        Y[sel],
                        s=s,
                        c=col,
                        lw=0,
                        rasterized=True,
                        label=("" if c == 0 else "image of ") + REGION_LABELS[reg],
                    )
                    h.set_gid(f"region:{Region(reg).label}")
                    handles.append(h)
            key = {"q2": "q2", "theta": "theta", "phi": "phi", "q21": "q21", "theta1": "theta1", "phi1": "phi1"}[xa]
            keyy = {"p2": "p2", "I": "I", "K": None, "p21": "p21", "I1": "I1", "K1": "K1"}[ya]
            ty = np.zeros_like(tg["phi"]) if keyy is None else tg[keyy]
            (lt,) = ax.plot(tg[key], ty, ".", color="k", ms=1.0, label="tangency K = 0" if c == 0 else "its image")
            lt.set_gid("tangency" if c == 0 else "tangency_image")
            if r == 2 and c == 0:
                draw_geometry(ax, result.corners, lines=False)
            ax.set_xlabel(xl if c == 0 else xl.replace("$", "$\\bar ", 1))
            ax.set_ylabel(yl if c == 0 else yl.replace("$", "$\\bar ", 1))
            if r == 0:
                ax.set_title("regions of the band" if c == 0 else "their images", fontsize=9)
            if handles:
                region_legend(ax, handles)
    fig.suptitle(scene.title + quick_mark(result) + "\n" + system_text(scene, result), fontsize=9)
    return fig
