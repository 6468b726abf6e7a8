"""hovering: a simulator for Hamiltonian impact systems near the onset of impacts.

The truncated near-tangency map of Pazi, Zobova and Rom-Kedar, "Hovering Sets in Near
Pseudo-Integrable Hamiltonian Impact Systems" (eq:truncatedmap), and its general family, with a
multi-threaded SIMD C++ core.

>>> import hovering
>>> m = hovering.TruncatedMap(eps=0.3, Omega0=hovering.OMEGA_G, theta_w=3 * 3.141592653589793 / 4)
>>> res = m.iterate([m.L1(0.0)], [0.0], 1000, record=("rotation",))
"""

from __future__ import annotations

from . import _core, analysis, fullmap, geometry
from .analysis import CriticalCurve, HoveringArea, birkhoff_average, regularity, rotation_number
from ._types import Region, Status, region_mask
from .geometry import (
    OMEGA_G,
    K_crit,
    L1,
    L2,
    golden_family,
    hovering_area_theory,
    k_eps1,
    k_eps2,
    rho1,
    rho2,
    rho_crit,
    wrap,
)
from .fullmap import CornerCurves, MapComparison, TangentialCurve, compare_maps, corner_curves, truncated_from_flow
from .maps import IterateResult, TruncatedFamily, TruncatedMap
from .potentials import CustomPotential, check_potential
from .system import (
    Bilinear,
    FlowStatus,
    Harmonic,
    Numerical,
    OnsetParameters,
    Polynomial,
    Potential,
    ReturnMapResult,
    Section,
    StepSystem,
    Tan,
    forcing_function,
    from_normal,
    onset_parameters,
    tangential_curve,
    to_normal,
)

__version__ = "0.1.0"

simd_is_avx2 = _core.simd_is_avx2

__all__ = [
    "TruncatedMap",
    "TruncatedFamily",
    "IterateResult",
    "Region",
    "Status",
    "region_mask",
    "geometry",
    "analysis",
    "rotation_number",
    "birkhoff_average",
    "regularity",
    "HoveringArea",
    "CriticalCurve",
    "OMEGA_G",
    "L1",
    "L2",
    "k_eps1",
    "k_eps2",
    "rho1",
    "rho2",
    "K_crit",
    "rho_crit",
    "hovering_area_theory",
    "golden_family",
    "wrap",
    "simd_is_avx2",
    "Potential",
    "Harmonic",
    "Tan",
    "Numerical",
    "CustomPotential",
    "check_potential",
    "Bilinear",
    "StepSystem",
    "OnsetParameters",
    "onset_parameters",
    "Polynomial",
    "Section",
    "ReturnMapResult",
    "FlowStatus",
    "tangential_curve",
    "TangentialCurve",
    "CornerCurves",
    "MapComparison",
    "corner_curves",
    "truncated_from_flow",
    "compare_maps",
    "forcing_function",
    "to_normal",
    "from_normal",
]
