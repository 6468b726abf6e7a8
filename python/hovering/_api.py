"""The public API of :mod:`hovering`, loaded on first use.

``import hovering`` itself imports neither the compiled core nor numpy (``hovering --version``
answers in milliseconds); the package's ``__getattr__`` imports this module the first time any of
its names is used, and from then on the package holds them all, as an eager import would. Importing
it also registers the hooks the models' convenience methods call (:func:`hovering.interface.hook`).
"""

from __future__ import annotations

# ruff: noqa: F401  (every name here is re-exported by the package's __getattr__)
from . import _core, analysis, dynamics, flow, normal, paper, truncated
from ._enums import FlowStatus, Geometry, Region, Status, region_mask, wrap
from ._provenance import show_versions
from ._serial import load, save
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
from .dynamics import (
    Branch,
    FTLEField,
    Lobes,
    LyapunovResult,
    Manifold,
    PeriodicOrbit,
    PeriodicOrbits,
    continue_orbit,
    ftle_field,
    lobes,
    lyapunov,
    manifold,
    periodic_orbit,
    periodic_orbits,
)
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
from .interface import ReturnMap, StepJacobian
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
