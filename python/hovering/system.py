"""Old path of :mod:`hovering.flow` (system, section) and of the normal-coordinate functions now in
:mod:`hovering.normal.coordinates` (deprecated; removed in 0.4.0)."""

from ._deprecated import moved_module

__getattr__ = moved_module(
    __name__,
    "hovering.flow",
    {n: "hovering.normal.coordinates" for n in ("forcing_function", "from_normal", "tangential_curve", "to_normal")},
)
