"""Type stubs of hovering._core.normal (use hovering.TangentialCurve and hovering.FlowMap)."""

from collections.abc import Callable

import numpy as np
import numpy.typing as npt

from .flow import FlowOptions, FlowSystem

class TangentialCurve:
    def __init__(self, system: FlowSystem, h: float, n: int, options: FlowOptions, n_check: int) -> None: ...
    def I_tan(self, theta: npt.NDArray[np.float64]) -> np.ndarray: ...
    def parameter_of(self, theta: npt.NDArray[np.float64]) -> np.ndarray: ...
    def at(self, s: npt.NDArray[np.float64]) -> tuple[np.ndarray, np.ndarray]: ...
    @staticmethod
    def measure_refined(system: FlowSystem, h: float, options: FlowOptions, n_check: int = ...) -> TangentialCurve: ...
    def forcing_coefficients(self, n_modes: int = ..., n_phi: int = ...) -> np.ndarray: ...
    # Pickling: (h, eps, I_tan0, theta, I, err_theta, err_I), the measured samples (no trace on unpickling).
    def __getstate__(self) -> tuple[float, float, float, np.ndarray, np.ndarray, float, float]: ...
    def __setstate__(self, state: tuple[float, float, float, np.ndarray, np.ndarray, float, float]) -> None: ...
    is_graph: bool
    min_slope: float
    min_slope_at: float
    interpolation_error: tuple[float, float]
    not_graph_reason: str
    I_tan0: float
    h: float
    s: np.ndarray
    theta: np.ndarray
    I: np.ndarray

class FlowMap:
    def __init__(
        self,
        system: FlowSystem,
        h: float,
        options: FlowOptions,
        curve: TangentialCurve | None,
        lift: tuple[float, float, float, float, float] | None,
    ) -> None: ...
    def steps(
        self, x: npt.NDArray[np.float64], y: npt.NDArray[np.float64], inverse: bool, n_threads: int
    ) -> dict[str, object]: ...
    def step1(self, x: float, y: float, inverse: bool = ...) -> tuple[float, float, int, int]: ...
    def jacobians(
        self, x: npt.NDArray[np.float64], y: npt.NDArray[np.float64], n_threads: int
    ) -> dict[str, object]: ...
    def iterate(
        self,
        x0: npt.NDArray[np.float64],
        y0: npt.NDArray[np.float64],
        n_steps: int,
        record: set[str],
        exit_mask: int,
        stop_on_exit: bool,
        n_threads: int,
        trajectory_dt: float = ...,
        max_points_per_orbit: int = ...,
        progress: Callable[[int, int], object] | None = ...,
        every: int = ...,
        stop_side: int = ...,
        stop_curve: object | None = ...,
    ) -> dict[str, object]: ...
    def to_section(self, x: npt.NDArray[np.float64], y: npt.NDArray[np.float64]) -> tuple[np.ndarray, np.ndarray]: ...
    def from_section(self, x: npt.NDArray[np.float64], y: npt.NDArray[np.float64]) -> tuple[np.ndarray, np.ndarray]: ...
    h: float

FORCING_MODES: int
FORCING_SAMPLES: int

def forcing_angles(n_phi: int = ...) -> np.ndarray: ...
def sine_coefficients(f: npt.NDArray[np.float64], n_modes: int = ...) -> np.ndarray: ...
