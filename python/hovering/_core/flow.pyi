"""Type stubs of hovering._core.flow (use hovering.StepSystem, Section and the potentials)."""

from collections.abc import Callable
from typing import TypeVar

import numpy as np
import numpy.typing as npt

from . import Geometry

_T = TypeVar("_T")

class Potential:
    def __init__(self) -> None: ...
    # Pickling (every potential): the constructor arguments; a Python subclass's instance dict.
    def __getstate__(self) -> object: ...
    def __setstate__(self, state: object) -> None: ...
    @property
    def name(self) -> str: ...
    @property
    def q_limit(self) -> float: ...
    def V(self, q: float) -> float: ...
    def dV(self, q: float) -> float: ...
    def turning_points(self, h: float) -> tuple[float, float]: ...
    def period(self, h: float) -> float: ...
    def frequency(self, h: float) -> float: ...
    def action(self, h: float) -> float: ...
    def energy(self, I: float) -> float: ...
    def angle_of(self, q: float, h: float) -> float: ...
    def point_at(self, theta: float, h: float) -> tuple[float, float]: ...
    def angle_of_point(self, q: float, p: float, h: float) -> float: ...

class Harmonic(Potential):
    def __init__(self, omega: float) -> None: ...
    @property
    def omega(self) -> float: ...

class Tan(Potential):
    def __init__(self, omega: float, alpha: float) -> None: ...
    @property
    def omega(self) -> float: ...
    @property
    def alpha(self) -> float: ...

class Numerical(Potential):
    def __init__(self, base: Potential) -> None: ...
    @property
    def base(self) -> Potential: ...

class _CallablePotential(Potential):
    def __init__(
        self, V: Callable[[float], float], dV: Callable[[float], float], q_limit: float, name: str
    ) -> None: ...
    @property
    def V_callable(self) -> Callable[[float], float]: ...
    @property
    def dV_callable(self) -> Callable[[float], float]: ...

class OnsetParameters:
    def __getstate__(self) -> tuple[float, float, float, float, float, float]: ...
    def __setstate__(self, state: tuple[float, float, float, float, float, float]) -> None: ...
    Omega0: float
    tau0: float
    tau1: float
    lam: float
    theta_w: float
    I_tan: float

def _onset_parameters(
    V1: Potential, V2: Potential, qw1: float, qw2: float, h: float, rtol: float = 1e-6
) -> OnsetParameters: ...
def _onset_parameters_closed_form(
    omega1: float, alpha1: float, omega2: float, alpha2: float, qw1: float, qw2: float, h: float, rtol: float = 1e-6
) -> OnsetParameters: ...
def _onset_estimate(
    V1: Potential, V2: Potential, qw1: float, qw2: float, h: float, rtol: float = 1e-6
) -> tuple[OnsetParameters, OnsetParameters]: ...
def _onset_estimate_closed_form(
    omega1: float, alpha1: float, omega2: float, alpha2: float, qw1: float, qw2: float, h: float, rtol: float = 1e-6
) -> tuple[OnsetParameters, OnsetParameters]: ...

class FlowSystem:
    def __init__(
        self,
        V1: Potential,
        V2: Potential,
        terms: list[tuple[float, float, float]],
        eps: float,
        qw1: float,
        qw2: float,
        geometry: Geometry,
    ) -> None: ...
    eps: float
    qw1: float
    qw2: float
    geometry: Geometry
    @property
    def terms(self) -> list[tuple[float, float, float]]: ...
    def energy(self, z: npt.NDArray[np.float64]) -> np.ndarray: ...
    def __getstate__(
        self,
    ) -> tuple[Potential, Potential, list[tuple[float, float, float]], float, float, float, Geometry]: ...
    def __setstate__(
        self, state: tuple[Potential, Potential, list[tuple[float, float, float]], float, float, float, Geometry]
    ) -> None: ...

STEPPERS: tuple[str, ...]

def default_atol(rtol: float) -> float: ...

class PotentialParam:
    @property
    def name(self) -> str: ...
    @property
    def lo(self) -> float: ...
    @property
    def hi(self) -> float: ...

class PotentialKind:
    @property
    def kind(self) -> str: ...
    @property
    def cls(self) -> str: ...
    @property
    def formula(self) -> str: ...
    @property
    def params(self) -> list[PotentialParam]: ...

# The core's registry of compiled potentials (CompiledPotentials), in its order.
POTENTIAL_KINDS: tuple[PotentialKind, ...]

class FlowOptions:
    def __init__(
        self,
        stepper: str = ...,
        rtol: float = ...,
        atol: float | None = ...,
        event_tol: float = ...,
        max_steps: int = ...,
        max_impacts: int = ...,
        grazing_tol: float = ...,
        corner_tol: float = ...,
        verify_steps: int = ...,
    ) -> None: ...
    def __getstate__(self) -> tuple[str, float, float, float, int, int, float, float, int]: ...
    def __setstate__(self, state: tuple[str, float, float, float, int, int, float, float, int]) -> None: ...
    def validate_for(self, system: FlowSystem) -> None: ...
    stepper: str
    rtol: float
    atol: float
    event_tol: float
    max_steps: int
    max_impacts: int
    grazing_tol: float
    corner_tol: float

def section_points(
    system: FlowSystem, h: float, theta: npt.NDArray[np.float64], I: npt.NDArray[np.float64]
) -> tuple[np.ndarray, np.ndarray, list[str]]: ...
def section_coordinates(system: FlowSystem, z: npt.NDArray[np.float64]) -> np.ndarray: ...
def return_maps(
    system: FlowSystem,
    z0: npt.NDArray[np.float64],
    options: FlowOptions,
    n_threads: int,
    trajectory_dt: float = ...,
    max_points_per_orbit: int = ...,
    progress: Callable[[int, int], object] | None = ...,
) -> dict[str, object]: ...

class ReturnMapper:
    def __init__(self, system: FlowSystem, options: FlowOptions) -> None: ...
    def run(
        self,
        z0: npt.NDArray[np.float64],
        n_threads: int,
        trajectory_dt: float = ...,
        max_points_per_orbit: int = ...,
        progress: Callable[[int, int], object] | None = ...,
    ) -> dict[str, object]: ...
    def point(self, h: float, theta: float, I: float, result_type: type[_T]) -> _T: ...
