"""Type stubs of hovering._core.analysis (use hovering.hovering_area): the hovering area's numerics."""

from collections.abc import Callable

import numpy as np
import numpy.typing as npt

from .normal import FlowMap
from .truncated import TruncatedFamily, TruncatedMap

def sample_grid(samples: int, K_low: float) -> tuple[int, int]: ...
def stratified_samples(
    samples: int, K_low: float, seed: int, lo: int = ..., hi: int | None = ...
) -> tuple[np.ndarray, np.ndarray]: ...
def hovering_outcomes(
    m: TruncatedMap | TruncatedFamily | FlowMap,
    *args: object,
    progress: Callable[[int, int], object] | None = ...,
    **kwargs: object,
) -> dict[str, object]: ...
def hovering_estimate(
    status_F0: npt.NDArray[np.int8],
    status: npt.NDArray[np.int8],
    steps_done: npt.NDArray[np.int64],
    visited: npt.NDArray[np.int8],
    K: npt.NDArray[np.float64],
    n_steps: int,
    K_low: float,
    keep_points: bool = ...,
) -> dict[str, object]: ...
def part_area(count: int, n: int, K_low: float) -> tuple[float, float]: ...
def default_depth(eps: float, Omega0: float, forcing: list[float]) -> float: ...
def box_floor(band_lo: float) -> float: ...
def default_K_low(eps: float, Omega0: float, forcing: list[float], band_lo: float) -> float: ...
def first_order_shape(forcing: list[float], Omega0: float, psi: npt.NDArray[np.float64]) -> np.ndarray: ...
