"""The full return map of the impact flow measured in normal coordinates, and truncated maps built from it.

* :class:`TangentialCurve`: ``I_tan^eps(theta)`` sampled once and evaluated by trigonometric
  interpolation, so that normal coordinates cost one return map per point instead of a bisection.
* :func:`corner_curves`: the corner-singularity curves ``phi_R0(K), phi_01(K), phi_1R(K)``
  (thm:cornersing) on circles ``K = const`` of the flow, by bisection on itineraries, with the
  arcs ``|J_R|, |J_0|, |J_1|`` and the rotation ``Omega(K)`` of the non-impacting orbits.
* :func:`truncated_from_flow`: the general truncated family ``F_{eps1,eps2}`` (eq:trunceps1eps2)
  with those measured arcs, i.e. the truncation of thm:returnmap without the small-K expansion of
  the onset parameters.
* :func:`compare_maps`: full map vs a truncated map on the same ``(phi, K)`` points, per region.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from .geometry import wrap
from .maps import TruncatedFamily
from .system import FlowStatus, Section, forcing_function, onset_parameters, tangential_curve

__all__ = ["TangentialCurve", "CornerCurves", "corner_curves", "truncated_from_flow", "compare_maps", "MapComparison"]

_TWO_PI = 2 * np.pi


class TangentialCurve:
    """``I_tan^eps(theta)`` (Def:sing_curve) from ``n`` bisections, evaluated by Fourier interpolation.

    The curve is smooth and 2 pi-periodic in theta, so the trigonometric interpolant of ``n``
    equispaced samples converges spectrally; :attr:`interpolation_error` reports the measured error
    at ``n_check`` off-grid angles (compared with direct bisection there).

    Parameters
    ----------
    sec : Section
        The section (system, energy).
    n : int, optional
        Number of equispaced samples (even).
    rtol : float, optional
        Integration tolerance of the bisections.
    n_check : int, optional
        Off-grid angles at which the interpolant is checked against direct bisection (0: skip).

    Raises
    ------
    ValueError
        If ``n`` is not an even integer >= 8 (or as :func:`hovering.tangential_curve`).
    """

    def __init__(self, sec: Section, n: int = 64, rtol: float = 1e-12, n_check: int = 4):
        if not (isinstance(n, (int, np.integer)) and n >= 8 and n % 2 == 0):
            raise ValueError(f"n must be an even integer >= 8, got {n!r}")
        self.sec = sec
        self.theta = -np.pi + _TWO_PI * np.arange(n) / n
        self.values = tangential_curve(sec, self.theta, rtol=rtol)
        c = np.fft.rfft(self.values) / n
        c[1:] *= 2
        c[-1] /= 2  # the Nyquist mode is shared by +-n/2
        self._c = c
        self.interpolation_error = np.nan
        if n_check:
            th = -np.pi + _TWO_PI * (np.arange(n_check) + 0.37) / n_check + np.pi / n
            self.interpolation_error = float(np.max(np.abs(self(th) - tangential_curve(sec, th, rtol=rtol))))

    def __call__(self, theta) -> np.ndarray:
        """``I_tan^eps`` at the angles ``theta`` (array_like)."""
        th = np.asarray(theta, dtype=float)
        k = np.arange(self._c.size)
        ph = np.multiply.outer(th + np.pi, k)
        return np.real(np.exp(1j * ph) @ self._c)

    def to_normal(self, theta, I):
        """``(phi, K) = (theta, I - I_tan(theta))`` (eq:kphidef)."""
        th = np.asarray(theta, dtype=float)
        return th, np.asarray(I, dtype=float) - self(th)

    def from_normal(self, phi, K):
        """``(theta, I) = (phi, K + I_tan(phi))`` (eq:kphiinvdef)."""
        ph = np.asarray(phi, dtype=float)
        return ph, np.asarray(K, dtype=float) + self(ph)


def _labels(sec, curve, phi, K, rtol):
    """Itinerary of each (phi, K): '0' (J_0), 'u' (J_0u), 'R', '1', ...; '?' for non-OK statuses."""
    th, I = curve.from_normal(wrap(phi), K)
    out = sec.return_map(th, I, rtol=rtol, atol=rtol)
    lab = np.array([s if st == FlowStatus.OK else "?" for s, st in zip(out.itinerary, out.status)], dtype=object)
    return lab, out


@dataclass
class CornerCurves:
    """Corner-singularity curves and arcs of the full return map on circles ``K = const``.

    Attributes
    ----------
    K : ndarray
        The circles.
    phi_R0, phi_01, phi_1R : ndarray
        Boundaries ``phi_ab(K)`` where the itinerary changes from a to b with increasing phi
        (``'0'`` = no impact), in [-pi, pi); NaN where the circle has no such boundary (K >= 0).
    JR, J0, J1 : ndarray
        Arc lengths ``|J_R|, |J_0|, |J_1|`` (the whole circle is J_0 for K >= 0).
    Omega : ndarray
        Rotation of non-impacting orbits ``phi_bar - phi`` (mean over J_0 sample points, lifted to
        the branch of the onset parameters' Omega0 + tau0 K).
    Omega_spread : ndarray
        Max - min of that rotation over the J_0 samples (0 at eps = 0: a rigid rotation; O(eps) else).
    other : ndarray
        Number of circle samples with any other itinerary or a non-OK status (0 inside the band).
    resolution : float
        Bracket width left by the bisection (angle units).
    """

    K: np.ndarray
    phi_R0: np.ndarray
    phi_01: np.ndarray
    phi_1R: np.ndarray
    JR: np.ndarray
    J0: np.ndarray
    J1: np.ndarray
    Omega: np.ndarray
    Omega_spread: np.ndarray
    other: np.ndarray
    resolution: float


def corner_curves(sec: Section, K, curve: Optional[TangentialCurve] = None, n_phi: int = 256,
                  bisections: int = 36, rtol: float = 1e-12) -> CornerCurves:
    """Measure the corner-singularity curves of the flow's return map on circles ``K = const``.

    On each circle, ``n_phi`` equispaced points are mapped by the flow; each change of itinerary
    between neighbours is then bisected (all brackets of all circles at once, one multi-threaded
    return map per bisection step) down to ``2 pi / n_phi / 2^bisections``.

    Parameters
    ----------
    sec : Section
        A section of a step system (geometry "step").
    K : array_like
        Circles (normal coordinate K of eq:kphidef).
    curve : TangentialCurve, optional
        The tangential curve of ``sec`` (computed if not given).
    n_phi : int, optional
        Samples per circle: arcs narrower than ``2 pi / n_phi`` can be missed (|J_1| ~ 2 lam sqrt(-K)).
    bisections : int, optional
        Bisection steps per boundary.
    rtol : float, optional
        Integration tolerance (atol = rtol).

    Returns
    -------
    CornerCurves

    Raises
    ------
    ValueError
        If the section is not a step system, or for bad counts.
    """
    if sec.sys.geometry != "step":
        raise ValueError(f"corner curves need geometry 'step', got {sec.sys.geometry!r}")
    if not (isinstance(n_phi, (int, np.integer)) and n_phi >= 16):
        raise ValueError(f"n_phi must be an integer >= 16, got {n_phi!r}")
    if not (isinstance(bisections, (int, np.integer)) and 0 <= bisections <= 60):
        raise ValueError(f"bisections must be an integer in [0, 60], got {bisections!r}")
    Ks = np.atleast_1d(np.asarray(K, dtype=float))
    if not np.all(np.isfinite(Ks)):
        raise ValueError(f"K must be finite, got {Ks}")
    curve = curve if curve is not None else TangentialCurve(sec)
    nK = Ks.size
    ph = -np.pi + _TWO_PI * np.arange(n_phi) / n_phi
    P = np.tile(ph, nK)
    KK = np.repeat(Ks, n_phi)
    lab, out = _labels(sec, curve, P, KK, rtol)
    lab = lab.reshape(nK, n_phi)
    rot = wrap(out.theta - P).reshape(nK, n_phi)

    # Brackets (circle, left angle, left label, right label) of every label change.
    bk, a, la, lb = [], [], [], []
    for i in range(nK):
        for j in range(n_phi):
            x, y = lab[i, j], lab[i, (j + 1) % n_phi]
            if x != y and x != "?" and y != "?":
                bk.append(i)
                a.append(ph[j])
                la.append(x)
                lb.append(y)
    bk = np.array(bk, dtype=int)
    lo = np.array(a, dtype=float)
    hi = lo + _TWO_PI / n_phi
    la = np.array(la, dtype=object)
    for _ in range(bisections if bk.size else 0):
        mid = 0.5 * (lo + hi)
        lm, _ = _labels(sec, curve, mid, Ks[bk], rtol)
        left = lm == la
        lo = np.where(left, mid, lo)
        hi = np.where(left, hi, mid)
    bnd = wrap(0.5 * (lo + hi))

    names = {("R", "0"): "phi_R0", ("0", "1"): "phi_01", ("1", "R"): "phi_1R"}
    res = {v: np.full(nK, np.nan) for v in names.values()}
    for i, x, y, b in zip(bk, la, lb, bnd):
        key = names.get((x, y))
        if key is not None:
            res[key][i] = b
    p = onset_parameters(sec.sys, sec.h)
    Omega, spread = np.full(nK, np.nan), np.full(nK, np.nan)
    for i in range(nK):
        zero = (lab[i] == "0") | (lab[i] == "u")  # no impact: J_0, or J_0u on circles K >= 0
        if zero.any():
            ref = p.Omega0 + p.tau0 * Ks[i]
            lifted = ref + wrap(rot[i][zero] - wrap(ref))
            Omega[i], spread[i] = lifted.mean(), np.ptp(lifted)
    gap = lambda x, y: np.mod(y - x, _TWO_PI)  # noqa: E731
    JR = np.where(Ks < 0, gap(res["phi_1R"], res["phi_R0"]), 0.0)
    J0 = np.where(Ks < 0, gap(res["phi_R0"], res["phi_01"]), _TWO_PI)
    J1 = np.where(Ks < 0, gap(res["phi_01"], res["phi_1R"]), 0.0)
    other = np.array([np.sum(~np.isin(lab[i], ["0", "u", "R", "1"])) for i in range(nK)])
    return CornerCurves(K=Ks, JR=JR, J0=J0, J1=J1, Omega=Omega, Omega_spread=spread, other=other,
                        resolution=_TWO_PI / n_phi / 2.0 ** bisections, **res)


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
class MapComparison:
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
    from ._types import Region

    ph = np.atleast_1d(np.asarray(phi, dtype=float))
    Kk = np.broadcast_to(np.asarray(K, dtype=float), ph.shape).copy()
    lab, out = _labels(sec, curve, ph, Kk, rtol)
    pb, Kb = curve.to_normal(out.theta, out.I)
    pt, Kt = trunc.step(ph, Kk)
    reg = np.asarray(trunc.region(ph, Kk))
    letter = {int(Region.RIGHT): "R", int(Region.UPPER): "1", int(Region.ABOVE): "0", int(Region.BESIDE): "u"}
    rt = np.array([letter[int(r)] for r in reg], dtype=object)
    ok = (lab == rt)
    dphi = np.where(ok, wrap(np.asarray(pt) - pb), np.nan)
    dK = np.where(ok, np.asarray(Kt) - Kb, np.nan)
    f = trunc.forcing_at(pb) if hasattr(trunc, "forcing_at") else np.sin(pb)
    GK = np.where(ok, Kb - Kk - trunc.eps * f, np.nan)
    return MapComparison(phi=ph, K=Kk, dphi=dphi, dK=dK, GK=GK, region_full=lab, region_trunc=rt)


def forcing_coefficients(sec: Section, n_modes: int = 6, n_phi: int = 64, **kwargs) -> np.ndarray:
    """Sine coefficients ``b_k`` of the measured forcing f (eq:defoff), least squares on n_phi angles.

    Parameters
    ----------
    sec : Section
        Section of a system with eps != 0.
    n_modes : int, optional
        Number of sine modes.
    n_phi : int, optional
        Sample angles in (-pi, pi).
    **kwargs
        Passed to :func:`hovering.forcing_function`.

    Returns
    -------
    ndarray
        ``b_1 .. b_n_modes``.
    """
    ph = np.linspace(-np.pi, np.pi, n_phi + 2)[1:-1]
    f = forcing_function(sec, ph, **kwargs)
    A = np.stack([np.sin((k + 1) * ph) for k in range(n_modes)], 1)
    return np.linalg.lstsq(A, f, rcond=None)[0]


__all__ += ["forcing_coefficients"]
