"""The physical system of sec:setup: potentials with action-angle variables, the oscillators-step
system and its onset parameters, the section Sigma_h and the return map of the impact flow."""

from .._enums import TrajectoryPoint
from .potentials import CustomPotential, check_potential
from .section import STEPPERS, FlowStatus, ReturnMapResult, Section, flow_options
from .system import (
    Bilinear,
    Harmonic,
    Numerical,
    OnsetParameters,
    Polynomial,
    Potential,
    StepSystem,
    Tan,
    onset_parameters,
)

__all__ = [
    "Potential",
    "Harmonic",
    "Tan",
    "Numerical",
    "CustomPotential",
    "check_potential",
    "Bilinear",
    "Polynomial",
    "StepSystem",
    "OnsetParameters",
    "onset_parameters",
    "Section",
    "ReturnMapResult",
    "FlowStatus",
    "TrajectoryPoint",
    "flow_options",
    "STEPPERS",
]
