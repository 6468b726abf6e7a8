"""Vocabulary shared by both models: region labels, outcomes, angle wrapping.

The enums are the core's own (bound from C++ as :class:`enum.IntEnum`, so their values cannot
drift from the kernels'); this module only adds the paper's labels, a parser and the wrap of angles.
"""

from __future__ import annotations

import numpy as np

from ._checks import MAX_ANGLE, _short, real_array
from ._core import FlowStatus, Geometry, Kernel, Region, Status, TrajectoryPoint
from ._core import wrap as _core_wrap

__all__ = [
    "Region",
    "Status",
    "FlowStatus",
    "Geometry",
    "Kernel",
    "TrajectoryPoint",
    "REGION_LABELS",
    "region_mask",
    "status_code",
    "wrap",
]

#: The paper's label of each region code (``'m'``: more than one impact, the flow only).
REGION_LABELS = {-1: "-", 0: "0u", 1: "0", 2: "1", 3: "R", 4: "m"}


def _label(self) -> str:
    """The paper's label of the region: ``'0u'``, ``'0'``, ``'1'``, ``'R'`` (``'m'``: several impacts)."""
    return REGION_LABELS[int(self)]


def _parse(cls, value) -> Region:
    """Convert a Region, its name (``'ABOVE'``), paper label (``'0'``) or code (1) to a Region.

    Parameters
    ----------
    value : Region, str or int
        What to convert.

    Returns
    -------
    Region

    Raises
    ------
    ValueError
        If the value names no region.
    """
    if isinstance(value, cls):
        return value
    if isinstance(value, str):
        key = value.strip()
        if key == "u":  # the itinerary's letter for a return beside the step
            return cls.BESIDE
        for r in cls:
            if r is not cls.NONE and key in (r.name, r.name.lower(), REGION_LABELS[int(r)]):
                return r
    elif isinstance(value, (int, np.integer)) and not isinstance(value, bool) and 0 <= value < len(REGION_LABELS) - 1:
        return cls(int(value))
    allowed = ", ".join(f"{r.name} ('{REGION_LABELS[int(r)]}')" for r in cls if r is not cls.NONE)
    raise ValueError(f"unknown region {value!r}; allowed: {allowed}")


Region.label = property(_label)  # type: ignore[method-assign,assignment]  # declared in _core's stub


Region.parse = classmethod(_parse)  # type: ignore[method-assign,assignment]


def region_mask(regions) -> int:
    """Bit mask (bit r = Region r) of a collection of regions (or of one region).

    Parameters
    ----------
    regions : Region, str, int or iterable of them
        Regions in any form accepted by ``Region.parse``; a single label such as ``"0u"`` is one
        region, not the characters of its name.

    Returns
    -------
    int
        The mask, 0 for an empty collection.
    """
    if isinstance(regions, (str, int, np.integer, Region)):
        regions = (regions,)
    try:
        items = list(regions)
    except TypeError:
        raise ValueError(f"regions must be a region or a collection of regions, got {regions!r}") from None
    mask = 0
    for r in items:
        if isinstance(r, Region) and r is Region.NONE:
            raise ValueError(
                "Region.NONE (no return) is not a region an orbit can be in; allowed: "
                + ", ".join(f"{x.name} ('{REGION_LABELS[int(x)]}')" for x in Region if x is not Region.NONE)
            )
        mask |= 1 << int(Region.parse(r))
    return mask


def wrap(x):
    """Wrap angles to ``[-pi, pi)``.

    Parameters
    ----------
    x : array_like
        Angles in radians, |x| <= 1e6 (NaN stays NaN: a missing value, e.g. of a stopped orbit).

    Returns
    -------
    ndarray or float
        ``x`` shifted by a multiple of ``2 pi`` into ``[-pi, pi)``.

    Raises
    ------
    ValueError
        For an infinite angle or one beyond 1e6, which cannot be wrapped accurately.
    """
    x = real_array("angle", x)
    with np.errstate(invalid="ignore"):
        if np.any(np.abs(x) > MAX_ANGLE):
            bad = x[np.abs(x) > MAX_ANGLE] if x.ndim else x
            raise ValueError(
                f"angles to wrap must satisfy |x| <= 1e6 (beyond, 2 pi floor(x / 2 pi) loses accuracy), "
                f"got {np.ravel(bad)[0]}"
            )
    y = _core_wrap(x)  # the core's one definition: every entry point wraps alike
    return y if np.ndim(y) else float(y)


def status_code(cls, value) -> int:
    """The code of a status in the enum ``cls`` (Status or FlowStatus) from a member of either enum
    (by name: their numbers differ), its name (``"OFF_SECTION"``, any case) or its code."""
    if isinstance(value, (Status, FlowStatus)) or isinstance(value, str):
        name = value.name if not isinstance(value, str) else value.strip().upper()
        if name in cls.__members__:
            return int(cls.__members__[name])
    elif isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_)):
        if int(value) in {int(m) for m in cls}:
            return int(value)
    raise ValueError(f"status must be one of {', '.join(cls.__members__)} ({cls.__name__}), got {_short(value)}")
