"""The bridge between the models (sec:mainresults): normal coordinates of the flow's section, the
flow's return map as a map on (phi, K), its corner-singularity curves, and truncated maps built
from and compared with it."""

from .compare import MapComparison, compare_maps, truncated_from_flow
from .coordinates import (
    TangentialCurve,
    forcing_coefficients,
    forcing_function,
    from_normal,
    tangential_curve,
    to_normal,
)
from .corners import CornerCurves, corner_curves
from .flowmap import FLOW_RECORD_KEYS, FlowMap, FlowSteps

__all__ = [
    "TangentialCurve",
    "tangential_curve",
    "forcing_function",
    "forcing_coefficients",
    "to_normal",
    "from_normal",
    "FlowMap",
    "FlowSteps",
    "FLOW_RECORD_KEYS",
    "CornerCurves",
    "corner_curves",
    "truncated_from_flow",
    "MapComparison",
    "compare_maps",
]
