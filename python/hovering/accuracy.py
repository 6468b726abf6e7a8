"""Old path of :mod:`hovering.diagnostics` (deprecated; removed in 0.4.0)."""

from ._deprecated import moved_module

__getattr__ = moved_module(
    __name__,
    "hovering.diagnostics",
    {
        "_reference_run": "hovering.diagnostics.work_precision",
        "_best_time": "hovering.diagnostics.work_precision",
        "_reverse": "hovering.diagnostics.work_precision",
    },
)
