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

import logging as _logging
import sys as _sys
import types as _types
from typing import TYPE_CHECKING

from ._version import __version__

# ruff: noqa: F405  (__all__ names what _api holds: star-imported for type checkers, loaded at first use)
if TYPE_CHECKING:  # what type checkers and editors see; at run time the first use loads it (__getattr__)
    from ._api import *  # noqa: F403

# A library's logger: records go where the application sends them (the command line's -v), and
# nowhere by default (no "No handlers" fallback printing warnings on stderr).
_logging.getLogger(__name__).addHandler(_logging.NullHandler())


def simd_width() -> int:
    """Doubles per SIMD packet of the truncated map's lane kernel selected for this CPU.

    A portable build (the default, and every wheel) holds the kernel for SSE2, AVX2 and AVX-512 and
    selects at run time the widest this CPU runs; ``HOVERING_SIMD=sse2|avx2|avx512|auto`` set
    before the import forces one (a level this CPU does not run is a ValueError at the first use
    of a kernel, before any computation; ``import hovering`` alone loads no core). A
    build with ``HOVERING_NATIVE=ON`` has the one kernel of the machine it was built on.

    Returns
    -------
    int
        8 (AVX-512), 4 (AVX2) or 2 (SSE2); another platform's vector width, or 1 without SIMD.
    """
    from ._core import truncated

    return truncated.simd_width()


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
    "StepJacobian",
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
    "dynamics",
    "PeriodicOrbit",
    "PeriodicOrbits",
    "periodic_orbit",
    "periodic_orbits",
    "lyapunov",
    "LyapunovResult",
    "ftle_field",
    "FTLEField",
    "manifold",
    "Manifold",
    "lobes",
    "Lobes",
    "continue_orbit",
    "Branch",
]

# Loaded when first used, so `import hovering` stays light (no core, numpy, matplotlib, dask or scene
# pipeline): the public API (hovering._api, at the first use of any of its names), the scene
# pipeline, the figures and the module that joins them; and the old module paths
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


def _load_api() -> None:
    """Import the public API (:mod:`hovering._api`: the core, numpy, the models and analyses) and
    keep its names here, so that only the first use pays (later lookups never reach __getattr__)."""
    import importlib

    api = importlib.import_module(f"{__name__}._api")
    g = globals()
    for n in __all__:
        # The API's value wins over a submodule of the same name, as the eager ``from .explore
        # import explore`` did (importing hovering.explore set the package's attribute first).
        if hasattr(api, n):
            g[n] = getattr(api, n)


def __getattr__(name: str):
    import importlib

    if name in _LAZY_MODULES or name in _OLD_MODULES:
        return importlib.import_module(f"{__name__}.{name}")
    if name.startswith("__") and name.endswith("__"):  # Python's probes, not names of ours
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    if name in __all__:
        # Asked again, half-loaded, while _api itself imports (``from . import analysis``): the
        # name is not there yet, the AttributeError lets the import system import the submodule.
        _load_api()
        if name in globals():
            return globals()[name]
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    # Any other submodule is imported alone: the package's own modules ask for theirs this way
    # (``from . import _untrusted`` looks here first), also while the API is half imported.
    import importlib.util

    if name.isidentifier() and importlib.util.find_spec(f"{__name__}.{name}") is not None:
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list:
    return sorted(set(globals()) | set(__all__))


#: Public functions named as the submodule that holds them: the name is the function.
_FUNCTION_MODULES = ("explore",)


class _Package(_types.ModuleType):
    """The package's module type. Importing a submodule sets it as its package's attribute; for
    ``hovering.explore`` (the function, in the module hovering.explore) the function is kept, as
    the eager ``from .explore import explore`` kept it, whenever the module is first imported."""

    def __setattr__(self, name: str, value) -> None:
        if name in _FUNCTION_MODULES and isinstance(value, _types.ModuleType) and hasattr(value, name):
            value = getattr(value, name)
        super().__setattr__(name, value)


_sys.modules[__name__].__class__ = _Package
