"""Region labels and per-orbit outcomes, shared by every model of the return map."""

from __future__ import annotations

from enum import IntEnum

__all__ = ["Region", "Status", "region_mask"]


class Region(IntEnum):
    """Region of the tangential band a point lies in (paper labels ``0u, 0, 1, R``).

    The integer values are the codes stored in region arrays (dtype int8).
    """

    NONE = -1  #: no step was taken from this point (the orbit had already stopped)
    BESIDE = 0  #: J_0u, K >= 0: passes beside the step without crossing q1 = qw1
    ABOVE = 1  #: J_0: hovers above the step without impact
    UPPER = 2  #: J_1: one impact on the upper wall of the step
    RIGHT = 3  #: J_R: one impact on the right wall of the step

    @property
    def label(self) -> str:
        """The paper's label of the region: ``'0u'``, ``'0'``, ``'1'`` or ``'R'``."""
        return {-1: "-", 0: "0u", 1: "0", 2: "1", 3: "R"}[int(self)]

    @classmethod
    def parse(cls, value) -> "Region":
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
            If the value names no region of the band.
        """
        if isinstance(value, Region):
            return value
        if isinstance(value, str):
            key = value.strip()
            for r in cls:
                if r is not cls.NONE and key in (r.name, r.name.lower(), r.label):
                    return r
        elif isinstance(value, (int,)) and 0 <= value <= 3:
            return cls(value)
        allowed = ", ".join(f"{r.name} ('{r.label}')" for r in cls if r is not cls.NONE)
        raise ValueError(f"unknown region {value!r}; allowed: {allowed}")


class Status(IntEnum):
    """Per-orbit outcome of a batch iteration (numerical outcomes, not errors)."""

    OK = 0  #: all requested steps were taken
    ESCAPED = 1  #: the orbit left the band where the map is defined
    EXITED = 2  #: the orbit left the requested regions and ``stop_on_exit`` was set
    INTERRUPTED = 3  #: the run was interrupted (Ctrl-C); the state reached so far is kept


def region_mask(regions) -> int:
    """Bit mask (bit r = Region r) of a collection of regions.

    Parameters
    ----------
    regions : iterable of Region, str or int
        Regions in any form accepted by :meth:`Region.parse`.

    Returns
    -------
    int
        The mask, 0 for an empty collection.
    """
    mask = 0
    for r in regions:
        mask |= 1 << int(Region.parse(r))
    return mask
