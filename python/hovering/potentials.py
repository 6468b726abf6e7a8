"""Old path of :mod:`hovering.flow.potentials` (kept for one release; import from the new one)."""

import sys as _sys

from .flow.potentials import *  # noqa: F401,F403
from . import flow as _pkg  # noqa: F401

_sys.modules[__name__] = _sys.modules["hovering.flow.potentials"]
