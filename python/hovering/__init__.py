"""hovering: a simulator for Hamiltonian impact systems near the onset of impacts.

Two models of the return map of the perturbed oscillators-step system of Pazi, Zobova and
Rom-Kedar, "Hovering Sets in Near Pseudo-Integrable Hamiltonian Impact Systems", with one interface:

* :mod:`hovering.truncated`: the truncated near-tangency map F_eps (eq:truncatedmap) and the
  general family F_{eps1,eps2}, on a multi-threaded SIMD C++ core, and their theory;
* :mod:`hovering.flow`: the physical system (potentials, step, Sigma_h) and its impact flow;
* :mod:`hovering.normal`: the bridge: normal coordinates (phi, K) and :class:`FlowMap`, the flow's
  return map as a map you iterate;
* :mod:`hovering.analysis`: rotation numbers, hovering sets and critical curves of any of them.

Every map, system, potential and result pickles (multiprocessing, Dask); results, maps and
systems also save to NPZ without pickle (``result.save(path)``, :func:`save`, :func:`load`).

>>> import hovering
>>> m = hovering.TruncatedMap(eps=0.3, Omega0=hovering.OMEGA_G, theta_w=3 * 3.141592653589793 / 4)
>>> res = m.iterate([m.L1(0.0)], [0.0], 1000, record=("rotation",))
"""

from __future__ import annotations

from . import _core, analysis, flow, normal, paper, truncated
from ._enums import FlowStatus, Geometry, Region, Status, region_mask, wrap
from ._provenance import show_versions
from ._serial import load, save
from ._version import __version__
from .analysis import (
    BarrierScan,
    ConeCrossing,
    CriticalCurve,
    HoveringArea,
    HoveringComparison,
    HoveringComponents,
    ImpactZone,
    ModelVerdicts,
    OrbitClasses,
    barrier_scan,
    birkhoff_average,
    classify_orbits,
    compare_hovering,
    cone_crossing,
    converse_kam,
    critical_curve,
    hovering_area,
    impact_zone,
    regularity,
    rotation_number,
    transit,
)
from .curve import Above, Below, Curve
from .diagnostics import WorkPrecision, work_precision  # also registers the accuracy-target hook
from .explore import explore
from .flow import (
    Bilinear,
    CustomPotential,
    Harmonic,
    Numerical,
    OnsetParameters,
    Polynomial,
    Potential,
    ReturnMapResult,
    Section,
    StepSystem,
    Tan,
    TrajectoryPoint,
    check_potential,
    onset_parameters,
)
from .interface import ReturnMap
from .normal import (
    CornerCurves,
    FlowMap,
    FlowSteps,
    MapComparison,
    TangentialCurve,
    compare_maps,
    corner_curves,
    forcing_coefficients,
    forcing_function,
    from_normal,
    tangential_curve,
    to_normal,
    truncated_from_flow,
)
from .truncated import (
    L1,
    L2,
    OMEGA_G,
    IterateResult,
    K_crit,
    Theory,
    TruncatedFamily,
    TruncatedMap,
    golden_family,
    hovering_area_theory,
    k_eps1,
    k_eps2,
    rho1,
    rho2,
    rho_crit,
)
from .truncated.theory import theory

simd_is_avx2 = _core.truncated.simd_is_avx2


def simd_width() -> int:
    """Doubles per SIMD packet of the truncated map's lane kernel selected for this CPU.

    A portable build (the default, and every wheel) holds the kernel for SSE2, AVX2 and AVX-512 and
    selects at run time the widest this CPU runs; ``HOVERING_SIMD=sse2|avx2|avx512|auto`` set
    before the import forces one (a level this CPU does not run is a ValueError at import). A
    build with ``HOVERING_NATIVE=ON`` has the one kernel of the machine it was built on.

    Returns
    -------
    int
        8 (AVX-512), 4 (AVX2) or 2 (SSE2); another platform's vector width, or 1 without SIMD.
    """
    return _core.truncated.simd_width()


__all__ = [
    "__version__",
    "paper",
    "diagnostics",
    "pipeline",
    "WorkPrecision",
    "work_precision",
    "TruncatedMap",
    "TruncatedFamily",
    "IterateResult",
    "FlowMap",
    "FlowSteps",
    "ReturnMap",
    "Curve",
    "Above",
    "Below",
    "Region",
    "Status",
    "FlowStatus",
    "Geometry",
    "TrajectoryPoint",
    "region_mask",
    "truncated",
    "flow",
    "normal",
    "analysis",
    "geometry",
    "rotation_number",
    "birkhoff_average",
    "regularity",
    "hovering_area",
    "critical_curve",
    "HoveringArea",
    "HoveringComponents",
    "compare_hovering",
    "HoveringComparison",
    "ModelVerdicts",
    "CriticalCurve",
    "Theory",
    "theory",
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
    "simd_width",
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
    "tangential_curve",
    "TangentialCurve",
    "CornerCurves",
    "MapComparison",
    "corner_curves",
    "truncated_from_flow",
    "compare_maps",
    "forcing_function",
    "forcing_coefficients",
    "to_normal",
    "from_normal",
    "explore",
    "save",
    "load",
    "show_versions",
    "OrbitClasses",
    "classify_orbits",
    "ConeCrossing",
    "cone_crossing",
    "converse_kam",
    "ImpactZone",
    "impact_zone",
    "transit",
    "BarrierScan",
    "barrier_scan",
]

# Loaded when first used, so `import hovering` stays light (no matplotlib, dask or scene pipeline):
# the scene pipeline, the figures and the module that joins them; and the old module paths
# (hovering.geometry, hovering.fullmap, ...), which warn on use (hovering._deprecated).
_LAZY_MODULES = ("pipeline", "scenes", "plot")
_OLD_MODULES = (
    "accuracy",
    "references",
    "fullmap",
    "geometry",
    "maps",
    "potentials",
    "system",
    "plotting",
    "figures",
    "distribute",
    "sweeps",
)


def __getattr__(name: str):
    if name in _LAZY_MODULES or name in _OLD_MODULES:
        import importlib

        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
