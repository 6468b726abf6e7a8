"""The figures' colours, line styles and legend texts (public path; they live in
:mod:`hovering._style`, below both the computing side, which stores colour names in results, and
the drawing side)."""

from .._style import *  # noqa: F401,F403
from .._style import __all__  # noqa: F401
