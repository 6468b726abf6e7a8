"""What the tangent-dynamics tools ask of a map, in one place: n steps of many points with the
product of their Jacobians (one batched ``iterate`` call, in C++, threaded), the lifted rotation of
the steps, the reversor of both models, and each map's accuracy."""

from __future__ import annotations

import math

import numpy as np

from .._enums import Status, wrap
from ..interface import require_map

__all__ = ["Segments", "advance", "map_tolerance", "is_flow", "reversor"]


def is_flow(m) -> bool:
    """Whether m is the flow's map (it has integrator options and an accuracy below rounding)."""
    return hasattr(m, "integrator_options")


def map_tolerance(m) -> float:
    """The accuracy one step of m is computed to, as the tangent tools use it: for the truncated
    map rounding, amplified along long hyperbolic orbits (1e-12: a period-233 orbit of the
    standard map at k = 1 stalls at residuals ~1e-11, its rounding times its stretch); for the
    flow the integrator's per-return error band (100 rtol: what the differential tests measure)."""
    if is_flow(m):
        return 100.0 * float(m.integrator_options["rtol"])
    return 1e-12


class Segments:
    """n steps of many points with their Jacobian products: the states reached, their statuses,
    the products and the lifted phase advance (sum of the steps' rotations)."""

    __slots__ = ("phi", "K", "status", "M", "advance", "log_r")

    def __init__(self, phi, K, status, M, advance, log_r):
        self.phi, self.K, self.status, self.M, self.advance, self.log_r = phi, K, status, M, advance, log_r

    @property
    def ok(self) -> np.ndarray:
        return self.status == int(Status.OK)


def advance(m, phi, K, n_steps: int, n_threads: int = 0, orbit: bool = False):
    """``n_steps`` steps of each point (phi, K) with the product of their Jacobians.

    Returns
    -------
    Segments
        (and, with ``orbit``, the IterateResult as second value: its ``phi``, ``K`` hold every state)
    """
    require_map("m", m)
    record = ["jacobian", "rotation"] + (["orbit"] if orbit else [])
    p = np.atleast_1d(np.asarray(phi, dtype=float)).ravel()
    k = np.atleast_1d(np.asarray(K, dtype=float)).ravel()
    res = m.iterate(p, k, n_steps, record=tuple(record), n_threads=n_threads)
    M = res.jacobian()
    # The lifted phase advance: the rotation record is the mean of the steps' lifted rotations
    # (omega_a for the truncated map, the branch of the lift model for the flow).
    adv = res.rotation * res.steps_done if n_steps > 0 else np.zeros(p.size)
    st = np.asarray(res.status, dtype=np.int8).copy()
    # A product whose factors were not all finite (flow: a return's Jacobian undefined) is not usable.
    bad = (res.jacobian_status != int(Status.OK)) & (res.jacobian_status != int(Status.CORNER))
    st[bad & (st == int(Status.OK))] = int(Status.NON_FINITE)
    seg = Segments(
        np.asarray(res.phi_final, dtype=float), np.asarray(res.K_final, dtype=float), st, M, adv, res.jacobian_log
    )
    return (seg, res) if orbit else seg


def reversor(m, phi, K):
    """The time-reversal involution of both models, ``R(phi, K) = (-phi, K - eps f(phi))``
    (truncated: lem:truncreturnmap; flow: R2(theta, I) = (-theta, I) in normal coordinates, whose K
    part is ``K + I_tan(phi) - I_tan(-phi)``)."""
    phi = np.asarray(phi, dtype=float)
    if is_flow(m):
        if m.curve is None:
            return wrap(-phi), np.asarray(K, dtype=float)
        It = m.curve._c.I_tan
        p = np.atleast_1d(phi).astype(float)
        return wrap(-phi), np.asarray(K, dtype=float) + (It(wrap(p)) - It(wrap(-p))).reshape(np.shape(phi))
    return m.reversal(phi, K)


def angle_gap(a, b) -> np.ndarray:
    """a - b wrapped to [-pi, pi)."""
    return wrap(np.asarray(a, dtype=float) - np.asarray(b, dtype=float))


def finite_2x2(M) -> bool:
    return bool(np.all(np.isfinite(M)))


def residue_of(M) -> float:
    """Greene's residue (2 - tr M) / 4 of a monodromy matrix."""
    return (2.0 - float(np.trace(M))) / 4.0


def stability_of(residue: float, tol: float) -> str:
    """'elliptic' (0 < R < 1), 'hyperbolic' (R < 0), 'inverse hyperbolic' (R > 1) or 'parabolic'
    (R within tol of 0 or 1)."""
    if abs(residue) <= tol or abs(residue - 1.0) <= tol:
        return "parabolic"
    if residue < 0:
        return "hyperbolic"
    if residue > 1:
        return "inverse hyperbolic"
    return "elliptic"


def tau(x) -> float:
    return float(x) % (2 * math.pi)
