"""Figures of scene results: pure functions of a result, never computing a map.

:func:`render` turns any scene result into its figure: the one its kind's module draws
(``hovering/plot/kinds/<kind>.py``, registered with :func:`hovering.plot.common.draws`). Orbit
panels show, as in the paper: the orbits (one colour per orbit, or per region), the tangency line
K = 0 and the lines L1, L2 in light grey, the corner-singularity curves ``phi_01, phi_1R, phi_R0``
in black (measured on the flow where it is the flow: marked with dots), and in black the
leading-order curve. Artists carry ``gid`` tags (``orbit:<label>``, ``region:<label>``,
``leading_curve``, ``measured:<label>``, ``theory:<label>``, ``torus:<name>``,
``trajectory:<name>``) so tests can check a figure's content without looking at pixels.
"""

from __future__ import annotations

from ..scenes.results import SceneResult
from ..scenes.spec import figure_inches  # noqa: F401 (the figures' sizes, read here by tests)
from . import kinds  # noqa: F401 (every figure of the package registered)
from .common import figure_of
from .kinds.corner_directions import corner_directions_figure
from .kinds.flow_hovering_area import flow_hovering_figure
from .kinds.flow_portrait import flow_portrait_figure
from .kinds.hovering_area import hovering_area_figure
from .kinds.impact_zone import impact_zone_figure
from .kinds.orbits import orbit_figure, orbit_label, panel_title
from .kinds.sigma_structure import sigma_structure_figure
from .kinds.tangent_tori import tangent_tori_figure
from .kinds.wall_section import wall_section_figure
from .kinds.wall_tangency import wall_tangency_figure

__all__ = [
    "render",
    "panel_title",
    "orbit_label",
    "orbit_figure",
    "hovering_area_figure",
    "flow_portrait_figure",
    "flow_hovering_figure",
    "tangent_tori_figure",
    "sigma_structure_figure",
    "corner_directions_figure",
    "wall_tangency_figure",
    "wall_section_figure",
    "impact_zone_figure",
]


def render(result):
    """The figure of any scene result (a pure function of it: nothing is computed).

    Parameters
    ----------
    result : SceneResult
        From :func:`hovering.scenes.compute` or :func:`hovering.scenes.load_result`.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        For what is no scene result, or one of a kind no module draws.
    """
    fn = figure_of(result.scene.kind) if isinstance(result, SceneResult) else None
    if fn is None:
        raise ValueError(f"no figure for a {type(result).__name__}")
    return fn(result)
