"""The public API of :mod:`hovering`: the one list of its names, as the imports that define them.

It is read, not run: ``import hovering`` imports neither the compiled core nor numpy
(``hovering --version`` answers in milliseconds), and the package's ``__getattr__`` parses these
imports to load, at the first use of a name, the module that holds it and nothing else
(``hovering.TruncatedMap`` loads the truncated map, not the analyses or the diagnostics; SPEC 1's
lazy loading from a stub). Type checkers and editors see them through the package's
``TYPE_CHECKING`` import. Importing this module loads the whole API at once.
"""

from __future__ import annotations

# ruff: noqa: F401  (every name here is re-exported by the package's __getattr__)
from . import analysis, diagnostics, dynamics, flow, normal, paper, pipeline, truncated
from ._core.truncated import simd_is_avx2
from ._enums import FlowStatus, Geometry, Region, Status, region_mask, wrap
from ._io.provenance import show_versions
from ._io.serial import load, save
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
    impact_zone_floor,
    regularity,
    rotation_number,
    transit,
)
from .curve import Above, Below, Curve
from .diagnostics import WorkPrecision, accurate_flow_map, work_precision
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
