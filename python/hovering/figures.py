"""Old path of :mod:`hovering.plot.figures` (deprecated; removed in 0.4.0)."""

from ._deprecated import moved_module

__getattr__ = moved_module(
    __name__, "hovering.plot.figures", {"SPECIAL_COLORS": "hovering._style", "SPECIAL_LABELS": "hovering._style"}
)
