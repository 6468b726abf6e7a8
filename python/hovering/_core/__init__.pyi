"""Type stubs of the compiled module hovering._core: the core's enums, one submodule per topic."""

import enum

import numpy as np
import numpy.typing as npt

from . import analysis as analysis
from . import flow as flow
from . import normal as normal
from . import truncated as truncated

def build_info() -> list[tuple[str, str | int]]: ...
def wrap(x: np.ndarray | float) -> np.ndarray | float: ...

class Curve:
    def __init__(self, K: npt.NDArray[np.float64]) -> None: ...
    def evaluate(self, phi: npt.NDArray[np.float64]) -> np.ndarray: ...
    @property
    def samples(self) -> np.ndarray: ...
    @property
    def cells(self) -> np.ndarray: ...
    @property
    def lower(self) -> float: ...
    @property
    def upper(self) -> float: ...
    @property
    def max_samples(self) -> int: ...

class Region(enum.IntEnum):
    NONE = -1
    BESIDE = 0
    ABOVE = 1
    UPPER = 2
    RIGHT = 3
    MULTI = 4
    # Added by hovering._enums (the paper's labels and a parser):
    @property
    def label(self) -> str: ...
    @classmethod
    def parse(cls, value: object) -> Region: ...

class Status(enum.IntEnum):
    OK = 0
    ESCAPED = 1
    EXITED = 2
    INTERRUPTED = 3
    CORNER = 4
    GRAZING = 5
    STEP_LIMIT = 6
    NON_FINITE = 7
    IMPACT_LIMIT = 8
    OFF_SECTION = 9
    OUTSIDE_WELL = 10
    STOPPED = 11

class FlowStatus(enum.IntEnum):
    OK = 0
    CORNER = 1
    GRAZING = 2
    STEP_LIMIT = 3
    NON_FINITE = 4
    IMPACT_LIMIT = 5
    OFF_SECTION = 6
    INTERRUPTED = 7
    OUTSIDE_WELL = 8

class TrajectoryPoint(enum.IntEnum):
    SAMPLE = 0
    IMPACT_IN = 1
    IMPACT_OUT = 2
    RETURN = 3
    END = 4

class Geometry(enum.IntEnum):
    NONE = 0
    WALL = 1
    STEP = 2

class Kernel(enum.IntEnum):
    SIMD = 0
    SCALAR = 1
