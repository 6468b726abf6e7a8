"""Type stubs of hovering._core.truncated (use hovering.TruncatedMap / TruncatedFamily)."""

from collections.abc import Callable

import numpy as np
import numpy.typing as npt

class _MapCore:
    @property
    def eps(self) -> float: ...
    def valid_band(self) -> tuple[float, float]: ...
    def _step(self, phi: npt.NDArray[np.float64], K: npt.NDArray[np.float64]) -> tuple[np.ndarray, np.ndarray]: ...
    def _step_inverse(
        self, phi: npt.NDArray[np.float64], K: npt.NDArray[np.float64]
    ) -> tuple[np.ndarray, np.ndarray]: ...
    def _region_rotation(
        self, phi: npt.NDArray[np.float64], K: npt.NDArray[np.float64], who: str
    ) -> tuple[np.ndarray, np.ndarray]: ...
    def _arcs(self, K: npt.NDArray[np.float64]) -> np.ndarray: ...
    def _jacobian(self, phi: npt.NDArray[np.float64], K: npt.NDArray[np.float64]) -> dict[str, np.ndarray]: ...
    def _iterate(
        self,
        phi0: npt.NDArray[np.float64],
        K0: npt.NDArray[np.float64],
        n_steps: int,
        record_orbit: bool,
        record_regions: bool,
        record_rotation: bool,
        exit_mask: int,
        stop_on_exit: bool,
        n_threads: int,
        kernel: str,
        sin_ulp: float,
        record_visited: bool = ...,
        progress: Callable[[int, int], object] | None = ...,
        every: int = ...,
        stop_side: int = ...,
        stop_curve: object | None = ...,
        record_extrema: bool = ...,
        record_residence: bool = ...,
        record_jacobian: bool = ...,
    ) -> dict[str, object]: ...

class TruncatedMap(_MapCore):
    def __init__(
        self, eps: float, Omega0: float, theta_w: float, tau0: float, tau1: float, lam: float, K_max: float
    ) -> None: ...
    @property
    def Omega0(self) -> float: ...
    @property
    def theta_w(self) -> float: ...
    @property
    def tau0(self) -> float: ...
    @property
    def tau1(self) -> float: ...
    @property
    def lam(self) -> float: ...
    # Pickling: (eps, Omega0, theta_w, tau0, tau1, lam, K_max = the band's upper end).
    def __getstate__(self) -> tuple[float, float, float, float, float, float, float]: ...
    def __setstate__(self, state: tuple[float, float, float, float, float, float, float]) -> None: ...

class TruncatedFamily(_MapCore):
    def __init__(
        self,
        eps: float,
        K: list[float],
        Omega: list[float],
        JR: list[float],
        J1: list[float],
        forcing: list[float],
        K_max: float,
    ) -> None: ...
    @property
    def forcing(self) -> list[float]: ...
    # Pickling: (eps, K, Omega, JR, J1, forcing, K_max), the tables read back from the splines.
    def __getstate__(self) -> tuple[float, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]: ...
    def __setstate__(
        self, state: tuple[float, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]
    ) -> None: ...

def simd_is_avx2() -> bool: ...
def simd_width() -> int: ...
def simd_level() -> str: ...
def simd_levels() -> list[str]: ...
def set_simd_level(level: str) -> None: ...
