"""The impact zone: the band of (phi, K) between its floor and its ceiling, as curves.

Its ceiling is the critical invariant curve (the lowest invariant curve that never impacts,
:func:`hovering.critical_curve`); its floor, for the flow, the deformed torus tangent to the upper
wall (the highest invariant curve below the zone that stays above the step,
:func:`impact_zone_floor`). The truncated map has no floor of its own: its zone
reaches down to the lower edge of the map's band, or to a floor the user gives. The zone coordinate
``s = (K - floor(phi)) / (ceiling(phi) - floor(phi))`` is 0 on the floor and 1 on the ceiling, so
orbits of different maps (the flow and its models) compare on one scale (sec:discussion, the
question whether anything crosses the zone).

Both boundaries of a flow's zone are invariant curves (and the truncated map's floor is the edge of
the band, where its orbits leave the map's domain): an orbit inside the zone can approach s = 0 or
1 but never reach it. Transport across the zone is therefore measured between levels strictly
inside it (:func:`hovering.transit`: by default ``s = margin`` and ``1 - margin``).
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass

import numpy as np

from .._checks import integer, real_array, real_number
from .._enums import Region, region_mask
from .._io.serial import Saveable
from ..curve import Curve
from ..interface import require_map
from .critical import critical_curve

__all__ = ["ImpactZone", "impact_zone", "impact_zone_floor"]

_log = logging.getLogger(__name__)

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

    Examples
    --------
    A zone given by two levels (:func:`impact_zone` finds a map's own):

    >>> import hovering
    >>> zone = hovering.ImpactZone(ceiling=hovering.Curve.constant(0.1), floor=hovering.Curve.constant(-0.2))
    >>> round(zone.s(0.3, 0.0), 4), round(zone.K_at(0.3, 0.5), 4), round(zone.height(0.3), 4)
    (0.6667, -0.05, 0.3)
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

    The floor is settled first, then the ceiling is searched above it: the lowest invariant curve
    that never impacts (``critical_curve(m)``, regions J_0u and J_0) among the starts on the search
    line that lie *above the floor*. Below a flow's floor the orbits pass above the step every
    return, so the invariant curves there never impact either; a search that reached below the
    floor could return one of them (it did, at the sign of eps that does not hover) and the zone
    would then be empty.

    Parameters
    ----------
    m : TruncatedMap, TruncatedFamily or FlowMap
        The map.
    ceiling : Curve or float, optional
        The upper boundary; default: the critical invariant curve ``critical_curve(m, n_steps,
        **kwargs).curve``, searched on the line ``critical_curve`` picks (L1 where the map hovers,
        L2 where it does not) between the floor and the band's top. Without ``K_range`` the search
        starts in the range the leading-order theory predicts, clipped to the band and to above
        the floor, and widens (down to the floor, up towards the band's top) when that range
        holds no curve or its lowest start already passes.
    floor : Curve or float, optional
        The lower boundary; default: for a :class:`hovering.FlowMap` its own floor
        (``impact_zone_floor(m).curve``, an invariant curve of the flow, used as it is); for the
        truncated maps, which have none, the lower edge of the band (``m.valid_band()[0]``). A
        given floor that dips within 1% of the zone's height (from the band's lower edge to the
        top of the ceiling, or to the band's top if lower) of the band's lower edge, or below it,
        is raised to that level there (``zone.raised``): no orbit of the map can start outside
        its band (the flow's floor given to its truncated model, whose band is narrower).
    n_steps : int, optional
        Iterates per tested orbit of the ceiling search; the flow's floor search uses
        ``min(n_steps, 2000)``.
    **kwargs
        Passed to :func:`critical_curve` (``K_range``, ``line``, ``regions``, ``n_grid``, ``digits``,
        ``tol``, ``n_threads``, ``progress``, ...); ``n_threads`` and ``progress`` also to the
        flow's floor search.

    Returns
    -------
    ImpactZone

    Raises
    ------
    ValueError
        For a map that is not one of the package's; a ceiling that is not above the floor; a
        search that finds no curve, saying why and what to pass instead (``K_range``, more
        ``n_steps``, or ``ceiling=`` / ``floor=`` as a Curve or a height). In particular the flow's
        floor search fails where the tori below the zone are destroyed or lie outside the band
        its normal coordinates cover (the README system at eps = -0.15 .. -0.3), and the zone is
        empty where the orbits just above the floor never impact (the README system at
        eps = +0.2, +0.3).
    KeyboardInterrupt
        On Ctrl-C (from the search's ``iterate``).

    Examples
    --------
    The first-mode model of docs/impact-zone.md's positive case (a zone that orbits cross), with
    a floor given at K = -0.2 (a truncated map has no floor of its own):

    >>> import numpy as np, hovering
    >>> m = hovering.TruncatedMap(eps=0.0914, Omega0=7.6696, theta_w=2.2117, tau0=3.0788, tau1=1.2223, lam=1.9072)
    >>> zone = hovering.impact_zone(m, floor=-0.2)
    >>> zone.floor_kind, zone.raised
    ('given', False)
    >>> print(f"{zone.s(0.0, -0.2):.3f} {zone.s(0.0, zone.ceiling(0.0)):.3f}")   # 0 on the floor, 1 on the ceiling
    0.000 1.000
    >>> bool(zone.ceiling.K.min() > -0.2)      # the ceiling, the critical curve, lies above the floor
    True
    """
    require_map("m", m)
    n_steps = integer("n_steps", n_steps, 16, 2**53)
    kw = dict(kwargs)
    kind = "given"
    t0 = time.perf_counter()
    if floor is None:
        if hasattr(m, "upper_tangent_K"):  # a FlowMap: the zone has a floor of its own
            floor_kw = {k: kw[k] for k in ("n_threads", "progress") if k in kw}
            floor, kind = impact_zone_floor(m, n_steps=min(n_steps, 2000), **floor_kw).curve, "flow"
        else:
            floor, kind = Curve.constant(m.valid_band()[0]), "band"
    elif not isinstance(floor, Curve):
        floor = Curve.constant(real_number("floor", floor))
    searched = ceiling is None
    if ceiling is None:
        ceiling = _ceiling(m, floor, n_steps, kw)
    elif not isinstance(ceiling, Curve):
        ceiling = Curve.constant(real_number("ceiling", ceiling))
    raised = False
    if kind == "given":
        # The flow's own floor is an orbit of the flow: every point of it lies on the section
        # (its normal-coordinate band is a conservative rectangle that the floor torus may leave,
        # e.g. K = -0.261 against a band from -0.257 at eps = -0.1); raising it would replace an
        # invariant curve by a level orbits cross. A given floor is only a level.
        floor, raised = _inside_band(m, floor, ceiling)
    _log.info(
        "impact_zone: floor %s, ceiling %s, %.1f s", kind,
        f"searched ({n_steps} steps per tested orbit)" if searched else "given", time.perf_counter() - t0,
    )  # fmt: skip
    return ImpactZone(ceiling=ceiling, floor=floor, floor_kind=kind, raised=raised)


def impact_zone_floor(m, n_steps: int = 2000, phi: float = 0.0, K_range=None, **kwargs):
    """The lower boundary of the impact zone: the highest invariant curve below it (sec:discussion).

    Searched on the vertical line ``phi``: the highest start whose orbit never leaves J_0 (passes
    above the step every return, no impact) and is a regular rotational curve; the deformed
    torus tangent to the upper wall at eps = 0 (:meth:`FlowMap.upper_tangent_K`). It is an orbit of
    the flow, so every point of it lies on the section, also where it leaves the rectangle
    :meth:`FlowMap.valid_band` (which is conservative: e.g. K = -0.261 against a band from -0.257 on
    the README system at eps = -0.1).

    Parameters
    ----------
    m : FlowMap
        The flow's map, in normal coordinates.
    n_steps : int, optional
        Returns per tested orbit.
    phi : float, optional
        The search line's angle.
    K_range : (float, float), optional
        Heights searched (default: ``upper_tangent_K() -+ (0.05 + 2 |eps|)``, clipped to the
        band (from 0.95 of its lower edge) and below ``K = -1e-3``).
    **kwargs
        ``n_grid``, ``digits``, ``tol``, ``n_threads``, ``progress`` of :func:`hovering.critical_curve`.

    Returns
    -------
    CriticalCurve
        ``K0`` (height on the line), ``K_min``, ``K_max`` (the curve's extent), rotation.

    Raises
    ------
    ValueError
        Outside normal coordinates; where the default range is empty (the eps = 0 torus and
        its eps-neighbourhood all outside the band); and where no curve is found (the message
        starts "no invariant curve", says why that happens - the tori below the zone destroyed
        at this eps (README system, eps = -0.15, -0.2), or lying below the band (eps = -0.3) -
        and what to pass: ``K_range``, more ``n_steps``, or to :func:`hovering.impact_zone` a
        ``floor=``).
    """
    require_map("m", m)
    if not hasattr(m, "upper_tangent_K"):
        raise ValueError(
            f"the impact zone floor is the flow's (the deformed torus tangent to the upper wall): m must be a "
            f"hovering.FlowMap, got a {type(m).__name__} (a truncated map's zone reaches down to its band)"
        )
    if m.coordinates != "normal":
        raise ValueError("the impact zone floor is searched in normal coordinates: use coordinates='normal'")
    Ku = m.upper_tangent_K()
    lo, hi = m.valid_band()
    if K_range is None:
        d = 0.05 + 2 * abs(m.eps)
        K_range = (max(Ku - d, 0.95 * lo), min(Ku + d, -1e-3, hi))
        if not K_range[0] < K_range[1]:
            raise ValueError(
                f"no invariant curve can be searched below the impact zone: the torus tangent to the upper wall "
                f"(K = {Ku:.6g} at eps = 0) and its eps-neighbourhood lie outside the band ({lo:.6g}, {hi:.6g}) "
                f"where this section's normal coordinates hold (eps = {m.eps:g}); pass impact_zone a floor= "
                f"(a hovering.Curve or a height, e.g. floor={0.95 * lo:.4g})"
            )
    try:
        return critical_curve(
            m, n_steps=n_steps, K_range=K_range, regions=("0",), line=float(phi), search="highest", **kwargs
        )
    except RuntimeError as e:
        below = Ku < lo
        raise ValueError(
            f"{e}. Below the impact zone (around the eps = 0 torus tangent to the upper wall, K = {Ku:.6g}) no "
            f"orbit in {tuple(float(k) for k in K_range)} stayed above the step for {n_steps} returns as a "
            "regular rotational curve: "
            + (
                f"that torus lies below the band ({lo:.6g}, {hi:.6g}) where the normal coordinates hold"
                if below
                else "at this eps the tori there are destroyed or impact (or need more returns to show regular)"
            )
            + "; pass K_range=(K_lo, K_hi), more n_steps, or impact_zone a floor= (a hovering.Curve or a "
            f"height, e.g. floor={0.95 * lo:.4g}, just inside the band's lower edge)"
        ) from None


def _error(curve: Curve) -> float:
    """A curve's error estimate, 0 for samples taken as exact (its max_error is NaN then)."""
    e = curve.max_error
    return e if math.isfinite(e) else 0.0


def _on_line(m, curve: Curve, line) -> float:
    """The height K at which ``curve`` crosses the search line: the fixed point of
    ``K = curve(line(K))`` (the line's slope tau0 / 2 times the curve's O(eps) slope is small), or
    the curve's top if that does not settle (any start above the top is above the curve)."""
    if isinstance(line, str):
        at = m.L1 if line == "L1" else m.L2
    else:
        return float(curve(float(line)))
    K = float(np.mean(curve.K))
    for _ in range(100):
        K_new = float(curve(float(np.asarray(at(K)))))
        if abs(K_new - K) <= 1e-13 * max(1.0, abs(K_new)):
            return K_new
        K = K_new
    return float(np.max(curve.K)) + _error(curve)


def _ceiling(m, floor: Curve, n_steps: int, kw: dict) -> Curve:
    """The ceiling: the lowest non-impacting invariant curve above ``floor`` (see impact_zone)."""
    th = m.theory()
    regions = kw.get("regions", ("0u", "0"))
    line = kw.pop("line", None)
    if line is None:  # critical_curve's own choice, made here to know where the floor crosses it
        try:
            hover_search = bool(region_mask(regions) >> int(Region.ABOVE) & 1)
        except ValueError:
            hover_search = True  # critical_curve names the bad regions
        line = "L2" if hover_search and not th.hovers and m.eps != 0 else "L1"
    lo, hi = (float(v) for v in m.valid_band())
    K_f = _on_line(m, floor, line)
    b = [abs(x) for x in th.forcing]
    scale = abs(m.eps) * max(b) / max(abs(math.sin(0.5 * th.Omega0)), 1e-3)  # the curves' O(eps) size
    width = max(scale, 1e-3)
    top = hi - 1e-3 * (hi - lo)  # strictly inside the band (critical_curve's K_range must be)
    # Starts closer to the floor than this may lie on the floor (the floor search bisects to 1e-6)
    # or on a non-impacting curve just above it, not on the ceiling.
    gap = max(1e-3 * width, 10 * _error(floor), 2 * float(kw.get("tol", 1e-6)))
    a_floor = max(K_f + gap, lo + 1e-9 * max(1.0, abs(lo)))
    grid = kw.get("n_grid", kw.get("grid", 64))  # grid=: the old name, which critical_curve warns about
    grid = int(grid) if isinstance(grid, (int, np.integer)) and grid >= 2 else 64  # critical_curve checks it

    def search(K_range):
        return critical_curve(m, n_steps, K_range=K_range, line=line, **kw)

    def why(e, K_range):
        return ValueError(
            f"no ceiling found for the impact zone: {e}. The ceiling is the lowest invariant curve that never "
            f"impacts, searched on {line} above the floor (K = {K_f:.6g} there) up to K = {K_range[1]:.6g} "
            f"(the map's band is ({lo:.6g}, {hi:.6g})). Pass K_range=(K_lo, K_hi) around it, more n_steps, "
            "or ceiling= (a hovering.Curve or a height)"
        )

    if "K_range" in kw:
        K_range = kw.pop("K_range")
        try:
            cc = search(K_range)
        except RuntimeError as e:
            raise why(e, tuple(K_range)) from None
        return _checked(cc, floor, line, K_f, a_floor)
    if a_floor >= top:
        raise ValueError(
            f"the floor (K = {K_f:.6g} on {line}) lies at or above the top of the map's band ({hi:.6g}): "
            "no room for a ceiling; pass floor= (a hovering.Curve or a height below the ceiling)"
        )
    # The leading-order range first (as critical_curve's default: narrow, so the bisection starts
    # from a fine grid), clipped into the band and above the floor.
    K_a = 3 * th.K_crit if th.hovers and math.isfinite(th.K_crit) and th.K_crit < 0 else -2 * scale
    K_a = max(K_a, a_floor)
    K_b = min(max(scale, K_a + width), top)
    if not K_a < K_b:
        K_a, K_b = a_floor, top
    try:
        cc = search((K_a, K_b))
    except RuntimeError:
        # No curve in the predicted range (the theory is first order; the flow's curves sit
        # O(eps^2) elsewhere, a large eps destroys the circles near K = 0): every height from the
        # floor up to a few times the range.
        wide = (a_floor, min(top, K_b + 4 * max(K_b - a_floor, width)))
        try:
            cc = search(wide)
        except RuntimeError as e:
            raise why(e, wide) from None
        return _checked(cc, floor, line, K_f, a_floor)
    if cc.K0 == K_a and K_a > a_floor:
        # The range's lowest start already passes: a lower curve may lie under it, down to the floor.
        spacing = (K_b - K_a) / max(grid - 1, 1)
        cc = search((a_floor, min(K_a + spacing, top)))
    return _checked(cc, floor, line, K_f, a_floor)


def _checked(cc, floor: Curve, line, K_f: float, a_floor: float) -> Curve:
    """The search's curve, refused (ValueError) where no impacting start lies between it and the
    floor (an empty zone) or where it does not lie above the floor."""
    if cc.K0 <= a_floor:
        raise ValueError(
            f"the impact zone is empty on {line}: the lowest start above the floor (K = {a_floor:.6g}; the floor "
            f"crosses the line at {K_f:.6g}) already lies on an invariant curve that never impacts (a torus passing "
            "above the step, or the critical curve itself), so no impacting orbit separates the floor from it. This "
            "happens where a flow's floor torus reaches up to K = 0 (the README system at eps = +0.2, +0.3, the sign "
            "that does not hover) and where a given floor lies just under such a torus or reaches the critical curve; pass a "
            "floor= at or above the highest curve that never impacts below the zone (impact_zone_floor with "
            "a K_range), or both ceiling= and floor="
        )
    c = cc.curve
    phi = -np.pi + 2 * np.pi * np.arange(_CHECK_POINTS) / _CHECK_POINTS
    gap = c(phi) - floor(phi)
    if not np.all(gap > 0):
        j = int(np.argmin(gap))
        raise ValueError(
            f"the ceiling search found a curve (from K0 = {cc.K0:.6g} on {line}) that dips to the floor at "
            f"phi = {phi[j]:.6g} (ceiling {c(phi[j]):.6g}, floor {floor(phi[j]):.6g}): it is not the zone's "
            "upper boundary; pass K_range=(K_lo, K_hi) on the line above the floor, or ceiling= / floor="
        )
    return c


def _inside_band(m, floor: Curve, ceiling: Curve) -> tuple[Curve, bool]:
    """The floor, raised where it dips below 1% of the zone's height above the band's lower edge.

    The zone's height is measured from the band's lower edge to the ceiling's top (or the band's
    top if that is lower): the band's own height is no scale for a truncated map, whose band
    reaches up to |Omega| = 1e6 (a 1% margin of it put a given floor at K ~ 1e4, above the
    ceiling). A floor given to a map whose band does not reach it (the flow's floor torus given to
    its truncated model, or Tan(1, 0.5) x Harmonic(0.7)'s floor at K = -0.541) cannot hold starts
    there; the zone then starts just inside the band.
    """
    lo, hi = (float(v) for v in m.valid_band())
    if not (np.isfinite(lo) and np.isfinite(hi)):
        return floor, False
    top = min(hi, float(np.max(ceiling.K)) + _error(ceiling))
    if not top > lo:
        return floor, False  # the ceiling lies under the band: ImpactZone says so
    edge = lo + 0.01 * (top - lo)
    phi = -np.pi + 2 * np.pi * np.arange(_CHECK_POINTS) / _CHECK_POINTS
    if float(np.min(floor(phi))) > edge:
        return floor, False
    # The spline through the kinks where the floor meets the edge overshoots by O(slope jump x
    # sample spacing); 1024 samples keep that far inside the 1% margin.
    raised = Curve.from_function(lambda p: np.maximum(floor(p), edge), n=max(floor.n, 1024))
    if not float(np.min(raised(phi))) > lo:
        raise ValueError(f"the floor dips below the map's band ({lo}, {hi}) and could not be raised inside it")
    return raised, True
