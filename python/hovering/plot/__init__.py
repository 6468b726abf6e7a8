"""Drawing only: figures and primitives that take results and never iterate a map.

:mod:`.figures` (``render``: the figure of any scene result), :mod:`.kinds` (one module per scene
kind, its figure), :mod:`.common` (what several figures share, and the table of figures),
:mod:`.primitives` (``draw_geometry``, ``plot_orbits``) and :mod:`.style` (colours and labels
shared with the computing side).
"""

from .._style import REGION_COLORS, SPECIAL_COLORS, SPECIAL_LABELS
from .figures import render
from .primitives import draw_geometry, plot_orbits

__all__ = ["render", "draw_geometry", "plot_orbits", "REGION_COLORS", "SPECIAL_COLORS", "SPECIAL_LABELS"]
