"""Old module path of the figure makers (one release): see :mod:`hovering.plot.figures`."""

from .plot.figures import *  # noqa: F401,F403
from .plot.figures import __all__  # noqa: F401
from .plot.style import SPECIAL_COLORS, SPECIAL_LABELS  # noqa: F401
