"""Old path of :mod:`hovering._common` (kept for one release; import from the new one)."""

import sys as _sys

from ._common import *  # noqa: F401,F403
from . import _common as _pkg  # noqa: F401

_sys.modules[__name__] = _sys.modules["hovering._common"]
