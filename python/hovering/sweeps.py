"""Old path of :mod:`hovering.parallel.checkpoint` (deprecated; removed in 0.4.0)."""

from ._deprecated import moved_module

__getattr__ = moved_module(__name__, "hovering.parallel.checkpoint")
