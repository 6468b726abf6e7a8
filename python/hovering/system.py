"""Old path of :mod:`hovering.flow` (system, section) and the normal-coordinate functions now in
:mod:`hovering.normal` (kept for one release; import from the new ones)."""

from .flow.section import *  # noqa: F401,F403
from .flow.system import *  # noqa: F401,F403
from .normal.coordinates import forcing_function, from_normal, tangential_curve, to_normal  # noqa: F401
