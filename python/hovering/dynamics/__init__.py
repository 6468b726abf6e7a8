"""Tangent dynamics on the map interface (both models): periodic orbits with their monodromy,
residues and stability, the orbits at the centres of island chains, Lyapunov exponents and the
finite-time field. The numerics (steps,
Jacobians, products along orbits) run in the core; these functions are written once against
:class:`hovering.ReturnMap`."""

from .continuation import Branch, continue_orbit, pseudo_arclength
from .greene import (
    GOLDEN,
    GreeneCritical,
    GreeneResidues,
    convergents,
    greene_critical,
    greene_residues,
    symmetric_orbit,
)
from .islands import IslandCentres, island_centres
from .lyapunov import FTLEField, LyapunovResult, ftle_field, lyapunov
from .manifolds import Lobes, Manifold, intersections, lobes, manifold
from .periodic import LINES, PeriodicOrbit, PeriodicOrbits, periodic_orbit, periodic_orbits

__all__ = [
    "LINES",
    "PeriodicOrbit",
    "PeriodicOrbits",
    "periodic_orbit",
    "periodic_orbits",
    "IslandCentres",
    "island_centres",
    "LyapunovResult",
    "lyapunov",
    "FTLEField",
    "ftle_field",
    "Manifold",
    "manifold",
    "intersections",
    "Lobes",
    "lobes",
    "Branch",
    "continue_orbit",
    "pseudo_arclength",
    "GOLDEN",
    "convergents",
    "symmetric_orbit",
    "GreeneResidues",
    "greene_residues",
    "GreeneCritical",
    "greene_critical",
]
