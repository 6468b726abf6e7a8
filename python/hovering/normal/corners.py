"""The corner-singularity curves phi_R0(K), phi_01(K), phi_1R(K) of the flow's return map
(thm:cornersing), measured on circles K = const by bisection on itineraries, with the arcs
|J_R|, |J_0|, |J_1| and the rotation Omega(K) of the non-impacting orbits.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._checks import integer, physical_memory, real_array, require_finite
from .._enums import wrap
from .._io.serial import Saveable
from ..flow.section import FlowStatus, Section
from ..flow.system import onset_parameters
from .coordinates import TangentialCurve, _curve_of, _section

__all__ = ["CornerCurves", "corner_curves"]

_TWO_PI = 2 * np.pi
#: Memory a circle sample takes while the circles are mapped (its start, return-map result,
#: itinerary and label): ~300 bytes measured, counted as 512.
_BYTES_PER_SAMPLE = 512


def _labels(sec, curve, phi, K, rtol):
    """Itinerary of each (phi, K): '0' (J_0), 'u' (J_0u), 'R', '1', ...; '?' for non-OK statuses."""
    th, I = curve.from_normal(wrap(phi), K)
    out = sec.return_map(th, I, rtol=rtol, atol=rtol)
    lab = np.array([s if st == FlowStatus.OK else "?" for s, st in zip(out.itinerary, out.status)], dtype=object)
    return lab, out


@dataclass
class CornerCurves(Saveable):
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


def corner_curves(
    sec: Section, K, curve: TangentialCurve | None = None, n_phi: int = 256, bisections: int = 36, rtol: float = 1e-12
) -> CornerCurves:
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
        If the section is not a step system, or for bad counts (naming the value and the allowed
        range), among them more circle samples (``K.size * n_phi``) than half of this machine's
        memory holds, refused before anything is allocated.
    """
    if _section("sec", sec).sys.geometry != "step":
        raise ValueError(f"corner curves need geometry 'step', got {sec.sys.geometry!r}")
    # n_phi <= 65536: each sample is a flow return per bisection; 10^9 ran for minutes.
    n_phi = integer("n_phi", n_phi, 16, 65536)
    bisections = integer("bisections", bisections, 0, 60)
    Ks = real_array("K", K)
    if Ks.ndim > 1:
        raise ValueError(f"K must be a number or a 1-D array of circles, got shape {Ks.shape}")
    Ks = np.atleast_1d(Ks)
    require_finite("K", Ks)
    # Checked before anything is allocated or traced: every circle's samples are mapped at once.
    most = physical_memory() // 2 // _BYTES_PER_SAMPLE
    if Ks.size * n_phi > most:
        raise ValueError(
            f"K ({Ks.size} circles) x n_phi ({n_phi}) = {Ks.size * n_phi} samples, mapped at once; allowed: at "
            f"most {most} (half of this machine's memory at {_BYTES_PER_SAMPLE} bytes a sample): fewer circles "
            "per call, or a smaller n_phi"
        )
    curve = _curve_of(sec, curve)
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
    return CornerCurves(
        K=Ks,
        JR=JR,
        J0=J0,
        J1=J1,
        Omega=Omega,
        Omega_spread=spread,
        other=other,
        resolution=_TWO_PI / n_phi / 2.0**bisections,
        **res,
    )
