"""Analyses written once for every map (TruncatedMap, TruncatedFamily, FlowMap): rotation numbers
and regularity, the hovering set HOV(eps), the critical invariant curve, orbit classes, the
impact zone, transport across it and its barriers."""

from .barriers import BarrierScan, Layer, barrier_scan
from .critical import CriticalCurve, critical_curve, max_angular_gap
from .hovering import HoveringArea, HoveringComponents, hovering_area
from .hovering_compare import HoveringComparison, ModelVerdicts, compare_hovering
from .orbits import (
    ConeCrossing,
    OrbitClasses,
    classify_orbits,
    cone_crossing,
    converse_kam,
    cyclic_order_violations,
    rank_rotation,
)
from .rotation import birkhoff_average, birkhoff_weights, regularity, rotation_number
from .transit import TransitResult, transit
from .zone import ImpactZone, impact_zone, impact_zone_floor

__all__ = [
    "birkhoff_weights",
    "birkhoff_average",
    "rotation_number",
    "regularity",
    "HoveringArea",
    "HoveringComponents",
    "hovering_area",
    "HoveringComparison",
    "ModelVerdicts",
    "compare_hovering",
    "CriticalCurve",
    "critical_curve",
    "max_angular_gap",
    "OrbitClasses",
    "classify_orbits",
    "cyclic_order_violations",
    "rank_rotation",
    "ConeCrossing",
    "cone_crossing",
    "converse_kam",
    "ImpactZone",
    "impact_zone",
    "impact_zone_floor",
    "TransitResult",
    "transit",
    "BarrierScan",
    "Layer",
    "barrier_scan",
]
