"""Closed-form geometry and leading-order predictions of the paper (sec:truncatedmapnum).

All functions are vectorised over NumPy arrays. Equation labels are the paper's ``\\label`` names.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "OMEGA_G",
    "wrap",
    "L1",
    "L2",
    "k_eps1",
    "k_eps2",
    "rho1",
    "rho2",
    "K_crit",
    "rho_crit",
    "hovering_area_theory",
    "golden_family",
]

#: The golden-mean rotation ``2 pi (sqrt(5) - 1) / 2`` used in the paper's figures.
OMEGA_G = float(np.pi * (np.sqrt(5.0) - 1.0))


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


def L1(K, Omega0, tau0):
    """Angle of the line L1 at height K (def:L1L2): ``-(Omega0 + tau0 K) / 2``, wrapped.

    Near L1 the invariant curves of the shifted standard map have their minima for
    ``eps sin((Omega0 + tau0 K)/2) > 0`` (thm:minmaxinvriantcurves); L1 is the midline of J_0.

    Parameters
    ----------
    K : array_like
        Heights.
    Omega0, tau0 : float
        Map parameters.

    Returns
    -------
    ndarray or float
        ``phi_m1(K)`` in ``[-pi, pi)``.
    """
    return wrap(-0.5 * (Omega0 + tau0 * np.asarray(K, dtype=float)))


def L2(K, Omega0, tau0):
    """Angle of the line L2 at height K (def:L1L2): ``pi - (Omega0 + tau0 K) / 2``, wrapped.

    Parameters
    ----------
    K : array_like
        Heights.
    Omega0, tau0 : float
        Map parameters.

    Returns
    -------
    ndarray or float
        ``phi_m2(K)`` in ``[-pi, pi)``.
    """
    return wrap(np.pi - 0.5 * (Omega0 + tau0 * np.asarray(K, dtype=float)))


def _half_rotation(K0, Omega0, tau0):
    return 0.5 * (Omega0 + tau0 * np.asarray(K0, dtype=float))


def k_eps1(phi, K0, eps, Omega0, tau0):
    """Leading-order invariant curve through L1 at height K0 (eq:keps1).

    ``k = K0 + eps (1 - cos(phi + a)) / (2 sin a)`` with ``a = (Omega0 + tau0 K0)/2``; valid to
    ``O(eps^2)`` for a Diophantine rotation.

    Parameters
    ----------
    phi : array_like
        Angles at which to evaluate the curve.
    K0 : float
        Height at which the curve crosses L1.
    eps, Omega0, tau0 : float
        Map parameters.

    Returns
    -------
    ndarray
        Heights of the curve at ``phi``.
    """
    a = _half_rotation(K0, Omega0, tau0)
    return K0 + eps * (1.0 - np.cos(np.asarray(phi, dtype=float) + a)) / (2.0 * np.sin(a))


def k_eps2(phi, K0, eps, Omega0, tau0):
    """Leading-order invariant curve through L2 at height K0 (eq:keps2).

    Parameters
    ----------
    phi : array_like
        Angles at which to evaluate the curve.
    K0 : float
        Height at which the curve crosses L2.
    eps, Omega0, tau0 : float
        Map parameters.

    Returns
    -------
    ndarray
        ``K0 - eps (1 + cos(phi + a)) / (2 sin a)``, ``a = (Omega0 + tau0 K0)/2``.
    """
    a = _half_rotation(K0, Omega0, tau0)
    return K0 - eps * (1.0 + np.cos(np.asarray(phi, dtype=float) + a)) / (2.0 * np.sin(a))


def rho1(K0, eps, Omega0, tau0):
    """Leading-order rotation of the invariant curve crossing L1 at K0 (eq:rotationscaled).

    Parameters
    ----------
    K0 : array_like
        Crossing heights.
    eps, Omega0, tau0 : float
        Map parameters.

    Returns
    -------
    ndarray or float
        ``Omega0 + tau0 K0 + (tau0 eps / 2) / sin((Omega0 + tau0 K0)/2)``.
    """
    a = _half_rotation(K0, Omega0, tau0)
    return 2 * a + 0.5 * tau0 * eps / np.sin(a)


def rho2(K0, eps, Omega0, tau0):
    """Leading-order rotation of the invariant curve crossing L2 at K0 (eq:rotationscaled2).

    Parameters
    ----------
    K0 : array_like
        Crossing heights.
    eps, Omega0, tau0 : float
        Map parameters.

    Returns
    -------
    ndarray or float
        ``Omega0 + tau0 K0 - (tau0 eps / 2) / sin((Omega0 + tau0 K0)/2)``.
    """
    a = _half_rotation(K0, Omega0, tau0)
    return 2 * a - 0.5 * tau0 * eps / np.sin(a)


def K_crit(eps, theta_w, Omega0):
    """Predicted lowest height of the critical invariant curve on L1 (eq:kcrit).

    Parameters
    ----------
    eps, theta_w, Omega0 : float or array_like
        Map parameters.

    Returns
    -------
    float or ndarray
        ``-eps (1 - cos theta_w) / (2 sin(Omega0/2))``.
    """
    return -eps * (1.0 - np.cos(theta_w)) / (2.0 * np.sin(0.5 * np.asarray(Omega0, dtype=float)))


def rho_crit(eps, theta_w, Omega0, tau0):
    """Predicted rotation number of the critical invariant curve (eq:rhocrit).

    Parameters
    ----------
    eps, theta_w, Omega0, tau0 : float or array_like
        Map parameters.

    Returns
    -------
    float or ndarray
        ``Omega0 + eps tau0 cos(theta_w) / (2 sin(Omega0/2))``.
    """
    return Omega0 + eps * tau0 * np.cos(theta_w) / (2.0 * np.sin(0.5 * np.asarray(Omega0, dtype=float)))


def hovering_area_theory(eps, theta_w, Omega0):
    """Leading-order area of the hovering set (eq:hovsetsize), for 0 < eps small.

    Parameters
    ----------
    eps, theta_w, Omega0 : float or array_like
        Map parameters.

    Returns
    -------
    float or ndarray
        ``eps (sin theta_w - theta_w cos theta_w) / sin(Omega0/2)``.
    """
    return eps * (np.sin(theta_w) - theta_w * np.cos(theta_w)) / np.sin(0.5 * np.asarray(Omega0, dtype=float))


def golden_family(eps, c, tau0=1.0, Omega_G=OMEGA_G):
    """Parameters ``(Omega0, theta_w)`` of the family of thm:hoveringc.

    The critical curve of this family has rotation ``Omega_G + O(eps^2)``.

    Parameters
    ----------
    eps : float
        Perturbation amplitude.
    c : float
        Family parameter, ``|c| < |tau0|``.
    tau0 : float, optional
        Twist (default 1).
    Omega_G : float, optional
        Target rotation (default the golden mean :data:`OMEGA_G`).

    Returns
    -------
    tuple of float
        ``(Omega0, theta_w)`` with ``Omega0 = Omega_G - c eps / 2`` and
        ``theta_w = arccos((c / tau0) sin(Omega_G/2 - c eps / 4))``.

    Raises
    ------
    ValueError
        If ``|c| >= |tau0|`` (theta_w would leave (0, pi)) or a value is not finite.
    """
    for name, v in (("eps", eps), ("c", c), ("tau0", tau0), ("Omega_G", Omega_G)):
        if not np.isfinite(v):
            raise ValueError(f"{name} must be finite, got {v}")
    if not abs(c) < abs(tau0):
        raise ValueError(f"c must satisfy |c| < |tau0| = {abs(tau0)}, got c = {c}")
    Omega0 = Omega_G - 0.5 * c * eps
    theta_w = float(np.arccos((c / tau0) * np.sin(0.5 * Omega_G - 0.25 * c * eps)))
    return float(Omega0), theta_w
