"""The impact zone: the band of (phi, K) between its floor and its ceiling, as curves.

Its ceiling is the critical invariant curve (the lowest invariant curve that never impacts,
:func:`hovering.critical_curve`); its floor, for the flow, the deformed torus tangent to the upper
wall (the highest invariant curve below the zone that stays above the step,
:meth:`hovering.FlowMap.impact_zone_floor`). The truncated map has no floor of its own: its zone
reaches down to the lower edge of the map's band, or to a floor the user gives. The zone coordinate
``s = (K - floor(phi)) / (ceiling(phi) - floor(phi))`` is 0 on the floor and 1 on the ceiling, so
orbits of different maps (the flow and its models) compare on one scale (sec:discussion, the
question whether anything crosses the zone).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._checks import real_array
from .._serial import Saveable
from ..curve import Curve
from ..interface import require_map

__all__ = ["ImpactZone", "impact_zone"]

#: Angles on which a zone checks that its ceiling lies above its floor.
_CHECK_POINTS = 4096


@dataclass(frozen=True)
class ImpactZone(Saveable):
    """The band between two closed curves ``floor(phi) < ceiling(phi)`` (see :func:`impact_zone`).

    Parameters
    ----------
    ceiling, floor : Curve
        Its upper and lower boundary.
    floor_kind : str, optional
        Where the floor comes from: ``"flow"`` (the flow's own floor), ``"band"`` (the lower edge of
        the map's band) or ``"given"``.
    raised : bool, optional
        Whether :func:`impact_zone` raised the floor to just inside the map's band where it dipped
        below it (orbits cannot start outside the band).

    Raises
    ------
    ValueError
        If ``ceiling`` and ``floor`` are not curves, or the ceiling is not above the floor at every
        one of 4096 angles (the message names the angle and the gap).
    """

    ceiling: Curve
    floor: Curve
    floor_kind: str = "given"
    raised: bool = False

    def __post_init__(self):
        for name in ("ceiling", "floor"):
            if not isinstance(getattr(self, name), Curve):
                raise ValueError(f"{name} must be a hovering.Curve, got {type(getattr(self, name)).__name__}")
        if self.floor_kind not in ("flow", "band", "given"):
            raise ValueError(f"floor_kind must be one of 'flow', 'band', 'given', got {self.floor_kind!r}")
        phi = -np.pi + 2 * np.pi * np.arange(_CHECK_POINTS) / _CHECK_POINTS
        gap = self.ceiling(phi) - self.floor(phi)
        if not np.all(gap > 0):
            j = int(np.argmin(gap))
            raise ValueError(
                f"the ceiling must lie above the floor at every angle; at phi = {phi[j]:.6g} the ceiling "
                f"{self.ceiling(phi[j]):.6g} is {'below' if gap[j] < 0 else 'on'} the floor {self.floor(phi[j]):.6g}"
            )

    def height(self, phi) -> np.ndarray | float:
        """The zone's height ``ceiling(phi) - floor(phi)`` (> 0).

        Parameters
        ----------
        phi : array_like
            Angles (any real; wrapped).

        Returns
        -------
        ndarray or float
        """
        return self.ceiling(phi) - self.floor(phi)

    def s(self, phi, K) -> np.ndarray | float:
        """The zone coordinate ``(K - floor(phi)) / (ceiling(phi) - floor(phi))``.

        Parameters
        ----------
        phi, K : array_like
            Points (broadcast together; NaN stays NaN: the padding of a stopped orbit).

        Returns
        -------
        ndarray or float
            0 on the floor, 1 on the ceiling; below 0 under the floor, above 1 over the ceiling.
        """
        phi, K = np.broadcast_arrays(real_array("phi", phi), real_array("K", K))
        f = self.floor(phi)
        out = (K - f) / (self.ceiling(phi) - f)
        return out if np.ndim(out) else float(out)

    def K_at(self, phi, s) -> np.ndarray | float:
        """The height at zone coordinate ``s``: ``floor(phi) + s (ceiling(phi) - floor(phi))``.

        Parameters
        ----------
        phi, s : array_like
            Angles and zone coordinates (broadcast together).

        Returns
        -------
        ndarray or float
            The inverse of :meth:`s` at each angle (to rounding).
        """
        phi, s = np.broadcast_arrays(real_array("phi", phi), real_array("s", s))
        f = self.floor(phi)
        out = f + s * (self.ceiling(phi) - f)
        return out if np.ndim(out) else float(out)

    def _validate_loaded(self) -> None:
        self.__post_init__()


def impact_zone(m, ceiling=None, floor=None, n_steps: int = 20_000, **kwargs) -> ImpactZone:
    """The impact zone of a map: its ceiling and floor as :class:`hovering.Curve` objects.

    Parameters
    ----------
    m : TruncatedMap, TruncatedFamily or FlowMap
        The map.
    ceiling : Curve or float, optional
        The upper boundary; default: the critical invariant curve ``m.critical_curve(n_steps,
        **kwargs).curve``.
    floor : Curve or float, optional
        The lower boundary; default: for a :class:`hovering.FlowMap` its own floor
        (``m.impact_zone_floor().curve``); for the truncated maps, which have none, the lower edge
        of the band (``m.valid_band()[0]``). A flow's or given floor that dips within 1% of the
        band's height of the band's lower edge (or below it) is raised to that level there
        (``zone.raised``): no orbit can start outside the band.
    n_steps : int, optional
        Iterates per tested orbit of the curve searches.
    **kwargs
        Passed to :meth:`critical_curve` (``K_range``, ``grid``, ``n_threads``, ``progress``, ...).

    Returns
    -------
    ImpactZone

    Raises
    ------
    ValueError
        For a map that is not one of the package's, a ceiling that is not above the floor, or a
        curve search that finds no curve (its own message).
    """
    require_map("m", m)
    if ceiling is None:
        ceiling = m.critical_curve(n_steps, **kwargs).curve
    elif not isinstance(ceiling, Curve):
        ceiling = Curve.constant(ceiling)
    kind = "given"
    if floor is None:
        if hasattr(m, "impact_zone_floor"):
            floor, kind = m.impact_zone_floor(n_steps=min(n_steps, 2000)).curve, "flow"
        else:
            floor, kind = Curve.constant(m.valid_band()[0]), "band"
    elif not isinstance(floor, Curve):
        floor = Curve.constant(floor)
    floor, raised = (floor, False) if kind == "band" else _inside_band(m, floor)
    return ImpactZone(ceiling=ceiling, floor=floor, floor_kind=kind, raised=raised)


def _inside_band(m, floor: Curve) -> tuple[Curve, bool]:
    """The floor, raised where it dips below 1% of the band's height above its lower edge.

    A flow's torus tangent to the upper wall can lie below the band where its normal coordinates
    hold (Tan(1, 0.5) x Harmonic(0.7): floor -0.541, band from -0.531), and no orbit can start
    there; the zone then starts just inside the band.
    """
    lo, hi = (float(v) for v in m.valid_band())
    if not (np.isfinite(lo) and np.isfinite(hi)):
        return floor, False
    edge = lo + 0.01 * (hi - lo)
    phi = -np.pi + 2 * np.pi * np.arange(_CHECK_POINTS) / _CHECK_POINTS
    if float(np.min(floor(phi))) > edge:
        return floor, False
    # The spline through the kinks where the floor meets the edge overshoots by O(slope jump x
    # sample spacing); 1024 samples keep that far inside the 1% margin.
    raised = Curve.from_function(lambda p: np.maximum(floor(p), edge), n=max(floor.n, 1024))
    if not float(np.min(raised(phi))) > lo:
        raise ValueError(f"the floor dips below the map's band ({lo}, {hi}) and could not be raised inside it")
    return raised, True
