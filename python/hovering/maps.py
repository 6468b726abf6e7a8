"""Old path of :mod:`hovering.truncated.maps` (kept for one release; import from the new one)."""

import sys as _sys

from .truncated.maps import *  # noqa: F401,F403
from . import truncated as _pkg  # noqa: F401

_sys.modules[__name__] = _sys.modules["hovering.truncated.maps"]
