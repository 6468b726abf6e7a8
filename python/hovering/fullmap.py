"""Old path of :mod:`hovering.normal` (kept for one release; import from the new one)."""

import sys as _sys

from . import normal as _normal  # noqa: F401

_sys.modules[__name__] = _sys.modules["hovering.normal"]
