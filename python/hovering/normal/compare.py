"""Full return map vs truncated maps: the truncated family F_{eps1,eps2} with arcs measured on the
flow (the truncation of thm:returnmap without the small-K expansion of the onset parameters), and
a point-by-point comparison of any two maps on the same (phi, K).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._checks import forcing_array, real_number, require_type
from .._enums import Region, wrap
from .._io.serial import Saveable
from ..flow.section import Section
from ..truncated.maps import TruncatedFamily, TruncatedMap
from .coordinates import TangentialCurve, _curve_of, _finite_pair, _section
from .corners import CornerCurves, _labels

__all__ = ["truncated_from_flow", "MapComparison", "compare_maps"]


def truncated_from_flow(cc: CornerCurves, eps: float, forcing=(1.0,)) -> TruncatedFamily:
    """The truncated family ``F_{eps, eps2}`` (eq:trunceps1eps2) with arcs measured on the flow.

    ``eps2`` is the eps of the section the curves were measured on; ``eps`` is the forcing
    amplitude eps_1. The grid must hold >= 3 circles with K < 0 and >= 1 with K > 0; the values at
    K = 0 (the tangency circle, where the flow grazes) are added by extrapolation: |J_R| and Omega
    quadratically in K from the three nearest circles below 0, |J_1| = 0.

    Parameters
    ----------
    cc : CornerCurves
        Measured curves (from :func:`corner_curves`).
    eps : float
        Forcing amplitude.
    forcing : sequence of float, optional
        Sine coefficients of f (e.g. a fit of :func:`hovering.forcing_function`).

    Returns
    -------
    TruncatedFamily

    Raises
    ------
    ValueError
        If the grid lacks circles on either side of 0 or an arc is missing (NaN) below 0.
    """
    require_type("cc", cc, CornerCurves, "the CornerCurves of hovering.corner_curves(...)")
    eps = real_number("eps", eps)
    forcing = forcing_array(forcing)
    K = cc.K
    order = np.argsort(K)
    K, JR, J1, Om = K[order], cc.JR[order], cc.J1[order], cc.Omega[order]
    neg, pos = K < 0, K > 0
    if neg.sum() < 3 or pos.sum() < 1:
        raise ValueError(f"need >= 3 circles with K < 0 and >= 1 with K > 0, got K = {K}")
    if not (np.all(np.isfinite(JR[neg]) & np.isfinite(J1[neg])) and np.all(np.isfinite(Om))):
        raise ValueError("an arc or rotation is missing (NaN) on some circle: refine n_phi or stay inside the band")
    k3 = K[neg][-3:]
    ext = lambda v: float(np.polyval(np.polyfit(k3, v[neg][-3:], 2), 0.0))  # noqa: E731
    Kg = np.concatenate([K[neg], [0.0], K[pos]])
    JRg = np.concatenate([JR[neg], [ext(JR)], np.zeros(pos.sum())])
    J1g = np.concatenate([J1[neg], [0.0], np.zeros(pos.sum())])
    Omg = np.concatenate([Om[neg], [ext(Om)], Om[pos]])
    return TruncatedFamily(eps, Kg, Omg, JRg, J1g, forcing=tuple(forcing))


@dataclass
class MapComparison(Saveable):
    """Full return map vs a truncated map on the same points (see :func:`compare_maps`).

    Attributes
    ----------
    phi, K : ndarray
        Starting points.
    dphi, dK : ndarray
        Truncated minus full images (dphi wrapped); NaN where the regions differ or the flow
        stopped. ``-dphi`` is the remainder G_phi of eq:returnmapfull.
    GK : ndarray
        The remainder ``G_K = K_bar - K - eps f(phi_bar)`` of eq:returnmapfull at the flow's image
        (dK also contains eps (f(phi_bar_trunc) - f(phi_bar)) = O(eps dphi)); NaN like dK.
    region_full, region_trunc : ndarray
        Itinerary of the flow ('0' J_0, 'u' J_0u, 'R', '1', '?' = not OK) and the same letter for
        the truncated map's region.
    """

    phi: np.ndarray
    K: np.ndarray
    dphi: np.ndarray
    dK: np.ndarray
    GK: np.ndarray
    region_full: np.ndarray
    region_trunc: np.ndarray

    @property
    def agree(self) -> np.ndarray:
        """Where both maps put the point in the same region."""
        return self.region_full == self.region_trunc


def compare_maps(sec: Section, curve: TangentialCurve, trunc, phi, K, rtol: float = 1e-12) -> MapComparison:
    """Map the same normal-coordinate points with the flow and with a truncated map.

    Parameters
    ----------
    sec : Section
        The section of the full system.
    curve : TangentialCurve
        Its tangential curve (defines the normal coordinates).
    trunc : TruncatedMap or TruncatedFamily
        The truncated model.
    phi, K : array_like
        Points (same shape).
    rtol : float, optional
        Integration tolerance.

    Returns
    -------
    MapComparison
    """
    _section("sec", sec)
    curve = _curve_of(sec, curve)
    require_type("trunc", trunc, (TruncatedMap, TruncatedFamily), "a TruncatedMap or TruncatedFamily")
    ph, Kk = _finite_pair("phi", phi, "K", K)
    if ph.ndim > 1:
        raise ValueError(f"phi and K must be numbers or 1-D arrays, got shape {ph.shape}")
    ph, Kk = np.atleast_1d(ph), np.atleast_1d(Kk)
    lab, out = _labels(sec, curve, ph, Kk, rtol)
    pb, Kb = curve.to_normal(out.theta, out.I)
    pt, Kt = trunc.step(ph, Kk)
    reg = np.asarray(trunc.region(ph, Kk))
    letter = {int(Region.RIGHT): "R", int(Region.UPPER): "1", int(Region.ABOVE): "0", int(Region.BESIDE): "u"}
    rt = np.array([letter[int(r)] for r in reg], dtype=object)
    ok = lab == rt
    dphi = np.where(ok, wrap(np.asarray(pt) - pb), np.nan)
    dK = np.where(ok, np.asarray(Kt) - Kb, np.nan)
    f = trunc.forcing_at(pb) if hasattr(trunc, "forcing_at") else np.sin(pb)
    GK = np.where(ok, Kb - Kk - trunc.eps * f, np.nan)
    return MapComparison(phi=ph, K=Kk, dphi=dphi, dK=dK, GK=GK, region_full=lab, region_trunc=rt)
