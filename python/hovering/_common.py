"""Vocabulary shared by both models: region labels, outcomes, angle wrapping.

The enums are the core's own (bound from C++ as :class:`enum.IntEnum`, so their values cannot
drift from the kernels'); this module only adds the paper's labels and a parser.
"""

from __future__ import annotations

import numpy as np

from ._core import FlowStatus, Geometry, Kernel, Region, Status

__all__ = ["Region", "Status", "FlowStatus", "Geometry", "Kernel", "region_mask", "wrap", "REGION_LABELS",
           "iterate_arguments"]

#: The paper's label of each region code (``'m'``: more than one impact, the flow only).
REGION_LABELS = {-1: "-", 0: "0u", 1: "0", 2: "1", 3: "R", 4: "m"}


def _label(self) -> str:
    """The paper's label of the region: ``'0u'``, ``'0'``, ``'1'``, ``'R'`` (``'m'``: several impacts)."""
    return REGION_LABELS[int(self)]


def _parse(cls, value) -> "Region":
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
        for r in cls:
            if r is not cls.NONE and key in (r.name, r.name.lower(), REGION_LABELS[int(r)]):
                return r
    elif isinstance(value, (int, np.integer)) and not isinstance(value, bool) and 0 <= value < len(REGION_LABELS) - 1:
        return cls(int(value))
    allowed = ", ".join(f"{r.name} ('{REGION_LABELS[int(r)]}')" for r in cls if r is not cls.NONE)
    raise ValueError(f"unknown region {value!r}; allowed: {allowed}")


Region.label = property(_label)
Region.parse = classmethod(_parse)


def region_mask(regions) -> int:
    """Bit mask (bit r = Region r) of a collection of regions.

    Parameters
    ----------
    regions : iterable of Region, str or int
        Regions in any form accepted by ``Region.parse``.

    Returns
    -------
    int
        The mask, 0 for an empty collection.
    """
    mask = 0
    for r in regions:
        mask |= 1 << int(Region.parse(r))
    return mask


def wrap(x):
    """Wrap angles to ``[-pi, pi)``.

    Parameters
    ----------
    x : array_like
        Angles in radians.

    Returns
    -------
    ndarray or float
        ``x`` shifted by a multiple of ``2 pi`` into ``[-pi, pi)``.
    """
    y = np.asarray(x, dtype=float) - 2 * np.pi * np.floor((np.asarray(x, dtype=float) + np.pi) / (2 * np.pi))
    y = np.where(y >= np.pi, y - 2 * np.pi, y)
    y = np.where(y < -np.pi, y + 2 * np.pi, y)
    return y if np.ndim(y) else float(y)


def iterate_arguments(record, allowed, n_steps, exit_regions, stop_on_exit) -> tuple:
    """Check the arguments every map's ``iterate`` shares; ``(record tuple, n_steps, exit mask)``.

    Raises
    ------
    ValueError
        Naming the unknown record key, the bad step count or region, or an exit set that is
        empty or missing where ``stop_on_exit`` needs it.
    """
    import operator

    if isinstance(record, str):
        record = (record,)
    record = tuple(record)
    unknown = [r for r in record if r not in allowed]
    if unknown:
        raise ValueError(f"unknown record key(s) {unknown}; allowed: {list(allowed)}")
    try:
        n_steps = operator.index(n_steps)
    except TypeError:
        raise ValueError(f"n_steps must be an integer >= 0, got {n_steps!r}") from None
    if n_steps < 0:
        raise ValueError(f"n_steps must be >= 0, got {n_steps}")
    mask = region_mask(exit_regions) if exit_regions is not None else 0
    if exit_regions is not None and mask == 0:
        raise ValueError("exit_regions must name at least one region")
    if stop_on_exit and mask == 0:
        raise ValueError("stop_on_exit needs exit_regions (the regions an orbit must stay in)")
    return record, n_steps, mask
