"""Closed-form geometry and leading-order predictions of the paper (sec:truncatedmapnum).

All functions are vectorised over NumPy arrays. Equation labels are the paper's ``\\label`` names.

The paper states its theory for ``Omega0`` in ``(0, 2 pi)`` and ``f = sin``. Written with
``sin(Omega0 / 2)`` it holds for every ``Omega0`` (negative ones and ``Omega0 > 2 pi`` included):
the map is ``4 pi``-periodic in ``Omega0`` (not ``2 pi``), and ``Omega0 -> Omega0 + 2 pi`` is
``eps -> -eps`` with ``phi -> phi + pi``. For a forcing ``f = b_1 sin(phi) + ...`` the sign of eps
that hovers is

    ``sign(sin(Omega0 / 2) * b_1)``  (lemma:mininj0jr, for every Omega0 and either sign of tau0),

so ``Omega0 mod 2 pi`` does not decide it: ``Omega0`` and ``Omega0 + 2 pi`` hover for opposite
signs of eps. :func:`theory` also takes any odd forcing ``f = sum_k b_k sin(k phi)`` (the measured
forcing of a physical system has ``b_2 = O(eps)``, and ``b_1 = 0`` for a coupling even in q2),
treats coefficients within a stated tolerance of 0 as absent, and states what applies in the
``"wall"`` and ``"none"`` geometries of :class:`hovering.StepSystem` (no hovering set).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .._checks import forcing_array, integer, is_choice, real_array, real_number, require_angles, require_finite
from .._core import analysis as _core_analysis
from .._core import normal as _core_normal
from .._enums import wrap
from .._io.serial import Saveable

__all__ = [
    "OMEGA_G",
    "wrap",
    "Theory",
    "theory",
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
    return wrap(-0.5 * _rotation(K, Omega0, tau0))


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
    return wrap(np.pi - 0.5 * _rotation(K, Omega0, tau0))


def _finite(name, x) -> np.ndarray:
    a = real_array(name, x)
    require_finite(name, a)
    return a


def _rotation(K, Omega0, tau0, name="K") -> np.ndarray:
    """Omega0 + tau0 K, refused (naming K) where it is too large an angle to wrap accurately."""
    k = _finite(name, K)
    with np.errstate(over="ignore", invalid="ignore"):
        try:
            Om = _omega0(Omega0) + _finite("tau0", tau0) * k
        except ValueError:
            raise ValueError(
                f"{name}, Omega0 and tau0 must have broadcastable shapes, got {np.shape(k)}, "
                f"{np.shape(Omega0)} and {np.shape(tau0)}"
            ) from None
    if np.any(~(np.abs(Om) <= 1e6)):
        i = int(np.argmax(~(np.ravel(np.abs(Om)) <= 1e6)))
        raise ValueError(
            f"{name} = {np.ravel(k + np.zeros_like(Om))[i]} gives the rotation Omega0 + tau0 {name} = "
            f"{np.ravel(Om)[i]:.6g}; allowed: |Omega0 + tau0 {name}| <= 1e6 (the ends of the band, where "
            f"angles can still be wrapped)"
        )
    return Om


def _omega0(Omega0):
    """Omega0 as a finite number (or array) with |Omega0| <= 1e6, the truncated map's own limit:
    beyond, sin(Omega0 / 2) is rounding noise (K_crit(Omega0 = 1e300) was a confident 0.24)."""
    om = _finite("Omega0", Omega0)
    if np.any(np.abs(om) > 1e6):
        raise ValueError(
            f"Omega0 must lie in [-1e6, 1e6] (a larger rotation cannot be reduced mod 2 pi accurately), "
            f"got {np.ravel(om)[int(np.argmax(np.ravel(np.abs(om)) > 1e6))]}"
        )
    return om if np.ndim(om) else float(om)


def _sin_half(Omega0) -> np.ndarray:
    """sin(Omega0 / 2), NaN where it vanishes (resonant Omega0: the first-order theory has no curve)."""
    s = np.sin(0.5 * _omega0(Omega0))
    return np.where(np.abs(s) < 1e-12, np.nan, s)


def _wall_angle(theta_w) -> np.ndarray:
    tw = _finite("theta_w", theta_w)
    if np.any((tw <= 0) | (tw >= np.pi)):
        raise ValueError(
            f"theta_w must lie in (0, pi), got {np.ravel(tw)[np.argmax(np.ravel((tw <= 0) | (tw >= np.pi)))]}"
        )
    return tw


def _broadcast_angle(phi, a):
    """phi + a for angles phi (finite, |phi| <= 1e6) broadcast against the half rotations a(K0)."""
    p = real_array("phi", phi)
    require_angles("phi", p)
    try:
        return p + a
    except ValueError:
        raise ValueError(f"phi and K0 must have broadcastable shapes, got {np.shape(p)} and {np.shape(a)}") from None


def _half_rotation(K0, Omega0, tau0):
    return 0.5 * _rotation(K0, Omega0, tau0, "K0")


def _sin_of(a) -> np.ndarray:
    """sin(a), NaN where it vanishes: the first-order curves divide by it and do not exist there."""
    s = np.sin(a)
    return np.where(np.abs(s) < 1e-12, np.nan, s)


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
    with np.errstate(over="ignore", invalid="ignore"):
        return K0 + _finite("eps", eps) * (1.0 - np.cos(_broadcast_angle(phi, a))) / (2.0 * _sin_of(a))


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
    with np.errstate(over="ignore", invalid="ignore"):
        return K0 - _finite("eps", eps) * (1.0 + np.cos(_broadcast_angle(phi, a))) / (2.0 * _sin_of(a))


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
    with np.errstate(over="ignore", invalid="ignore"):
        return 2 * a + 0.5 * _finite("tau0", tau0) * _finite("eps", eps) / _sin_of(a)


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
    with np.errstate(over="ignore", invalid="ignore"):
        return 2 * a - 0.5 * _finite("tau0", tau0) * _finite("eps", eps) / _sin_of(a)


def K_crit(eps, theta_w, Omega0):
    """Predicted lowest height of the critical invariant curve on L1 (eq:kcrit), evaluated formally.

    For ``f = sin``, at every Omega0: negative in the hovering case ``eps sin(Omega0/2) > 0``
    (so for ``Omega0`` in ``(2 pi, 4 pi)`` it is eps < 0 that hovers); positive otherwise, where no
    hovering critical curve exists (use :func:`theory`, whose ``K_crit`` is NaN there). NaN at a
    resonant Omega0 (sin(Omega0/2) = 0); theta_w must lie in (0, pi).

    Parameters
    ----------
    eps, theta_w, Omega0 : float or array_like
        Map parameters.

    Returns
    -------
    float or ndarray
        ``-eps (1 - cos theta_w) / (2 sin(Omega0/2))``.
    """
    with np.errstate(over="ignore"):  # huge eps: inf, as IEEE says
        out = -_finite("eps", eps) * (1.0 - np.cos(_wall_angle(theta_w))) / (2.0 * _sin_half(Omega0))
    return out if np.ndim(out) else float(out)


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
    with np.errstate(over="ignore", invalid="ignore"):
        out = _omega0(Omega0) + _finite("eps", eps) * _finite("tau0", tau0) * np.cos(_wall_angle(theta_w)) / (
            2.0 * _sin_half(Omega0)
        )
    return out if np.ndim(out) else float(out)


def hovering_area_theory(eps, theta_w, Omega0):
    """Leading-order area of the hovering set (eq:hovsetsize), for every Omega0 and either sign of eps.

    ``|eps| (sin theta_w - theta_w cos theta_w) / |sin(Omega0/2)|`` when ``eps sin(Omega0/2) > 0``
    (the hovering case of lemma:mininj0jr; ``f = sin``, so ``b_1 = 1``: the sign of eps that hovers
    is that of ``sin(Omega0/2)``, a function of period 4 pi in Omega0), 0 otherwise (the minima
    of the invariant curves lie near L2, in J_R: thm:hovering's destruction). NaN at
    ``sin(Omega0/2) = 0`` (resonant). For a forcing ``b_1 sin + ...`` use :func:`theory`.

    Parameters
    ----------
    eps, theta_w, Omega0 : float or array_like
        Map parameters.

    Returns
    -------
    float or ndarray
    """
    e = _finite("eps", eps)
    tw = _wall_angle(theta_w)
    s = _sin_half(Omega0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        a = np.where(e * s > 0, np.abs(e) * (np.sin(tw) - tw * np.cos(tw)) / np.abs(s), 0.0)
    a = np.where(np.isnan(s), np.nan, a)  # resonant: sin(Omega0/2) = 0 up to rounding of Omega0
    return a if np.ndim(a) else float(a)


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
    eps, c, tau0, Omega_G = (
        real_number(n, v) for n, v in (("eps", eps), ("c", c), ("tau0", tau0), ("Omega_G", Omega_G))
    )
    if not abs(c) < abs(tau0):
        raise ValueError(f"c must satisfy |c| < |tau0| = {abs(tau0)}, got c = {c}")
    _omega0(Omega_G)
    Omega0 = Omega_G - 0.5 * c * eps
    if not abs(Omega0) <= 1e6:
        raise ValueError(
            f"eps = {eps} and c = {c} give Omega0 = Omega_G - c eps / 2 = {Omega0:.6g}; allowed: "
            f"|Omega0| <= 1e6 (a larger rotation cannot be reduced mod 2 pi accurately)"
        )
    # The C library's scalar sin/acos (not NumPy's vector loops, 1 ulp off in places): correctly
    # rounded here, and the same doubles as the C++ reader of the scene files.
    theta_w = math.acos((c / tau0) * math.sin(0.5 * Omega_G - 0.25 * c * eps))
    return float(Omega0), theta_w


# ------------------------------------------------------------------------------------------------
# The theory of sec:truncinvcurves for any Omega0 and any odd forcing


#: Geometries of :class:`hovering.StepSystem` the theory speaks about.
_GEOMETRIES = ("step", "wall", "none")

#: Unit roundoff of IEEE double precision.
_UNIT_ROUNDOFF = 2.0**-53


def _forcing_rounding(forcing, n_samples: int | None = None) -> float:
    """Rounding bound of sine coefficients fitted from n samples of f: ``2 (n + 2) u sum_k |b_k|``.

    The package's fit (``hovering._core.normal``, ``FORCING_SAMPLES`` = 256 midpoint angles) is
    ``b_k = (2/n) sum_j f_j sin(k phi_j)``: a sum of n terms, each at most ``(2/n) max|f| <= (2/n)
    sum_k |b_k|`` in size, each rounded in its product and sine. Recursive summation errs by at
    most ``gamma_{n+2} = (n + 2) u / (1 - (n + 2) u)`` times the sum of the terms' sizes, which is
    at most ``2 sum_k |b_k|`` (u = 2^-53; ``gamma`` rounded down to ``(n + 2) u``, 1e-13 relative
    at n = 256). A coefficient this small is indistinguishable from 0 in such a fit.
    """
    n = int(_core_normal.FORCING_SAMPLES) if n_samples is None else int(n_samples)
    return 2.0 * (n + 2) * _UNIT_ROUNDOFF * float(sum(abs(x) for x in forcing))


@dataclass(frozen=True)
class Theory(Saveable):
    """Leading-order predictions of sec:truncinvcurves for one set of map parameters.

    At first order in eps, the invariant curves of ``K' = K + eps f(phi')``, ``phi' = phi + Omega0
    + tau0 K`` with ``f = sum_k b_k sin(k phi)`` that cross L1 at height K0 are
    ``K = K0 + eps G(phi + Omega0/2)``, ``G(psi) = sum_k b_k (1 - cos k psi) / (2 sin(k Omega0/2))``
    (eq:keps1 for ``f = sin``). At K = 0 the no-impact arc J_0 is ``|psi| < theta_w``. The critical
    curve is the lowest of them that stays at K >= 0 outside J_0, so
    ``K_c = -min_{|psi| >= theta_w} eps G(psi)``; HOV is the part of J_0 between it and K = 0,
    ``|HOV| = int max(0, -K_c - eps G) dpsi`` (eq:hovsetsize for ``f = sin``), and its rotation is
    ``Omega0 + tau0 (K_c + eps <G>)`` (eq:rhocrit). With ``eps b_1 sin(Omega0/2) < 0`` and
    ``f = b_1 sin`` this lowest curve is ``k_{eps,2}(phi, rho_2(0))``, touching K = 0 at L2 inside
    J_R: no hovering set (thm:hovering). The corrections are O(eps^2) (the corner curves'
    ``lam sqrt(-K)`` shifts the crossing angles by O(eps) only, see the proof of thm:hovering).

    The sign rule, for every Omega0 (negative, in (0, 2 pi), in (2 pi, 4 pi), ...) and either sign
    of tau0: eps hovers when ``eps b_1 sin(Omega0/2) > 0``, i.e. the sign of eps that hovers is
    ``sign(sin(Omega0/2) b_1)``, of period 4 pi in Omega0 (not 2 pi: Omega0 and Omega0 + 2 pi
    hover for opposite signs).

    Attributes
    ----------
    eps, Omega0, theta_w, tau0 : float
        The parameters.
    forcing : tuple of float
        Sine coefficients ``b_k`` of f used by the theory: the given ones, with those within
        ``forcing_tol`` of 0 set to 0.
    area : float
        Leading-order ``|HOV|`` (0 where nothing hovers; NaN when resonant).
    hovers : bool
        Whether a hovering set is predicted (``area > 0``).
    hovering_sign : int
        The sign of eps for which these parameters hover (+1 or -1): ``sign(sin(Omega0/2) b_1)``
        for ``f = b_1 sin``; for several modes, the sign whose first-order curves dip into J_0
        (that of ``sin(Omega0/2) b_1`` while b_1 dominates; set by the higher modes when
        ``b_1 = 0``). 0 if neither or both signs hover, if no mode forces (every ``b_k`` within
        ``forcing_tol`` of 0), in the ``"wall"`` and ``"none"`` geometries, or at eps-independent
        degeneracies (resonance, theta_w outside (0, pi)).
    K_crit : float
        Height of the critical curve on L1 (its minimum for ``f = sin``); NaN if nothing hovers.
    rho_crit : float
        Its rotation number; NaN if nothing hovers.
    K_lowest : float
        Height on L1 of the lowest invariant curve that avoids the impacting arcs at K = 0 (the
        critical curve when hovering, else the curve k^{u0}, which lies in K >= 0; NaN where no
        arc impacts, geometry ``"none"``).
    note : str
        Why the prediction is what it is (sign, resonance, missing twist, vanishing modes,
        geometry), in words.
    forcing_tol : float
        The tolerance below which a coefficient was taken as 0 (see :func:`theory`).
    geometry : str
        ``"step"`` (the paper's), ``"wall"`` or ``"none"`` (see :func:`theory`).

    Examples
    --------
    Every map has its theory (``m.theory()``); the two signs of eps of the paper's figure:

    >>> import numpy as np, hovering
    >>> th = hovering.TruncatedMap(eps=0.3, Omega0=hovering.OMEGA_G, theta_w=3 * np.pi / 4).theory()
    >>> th.hovers, round(th.area, 4), round(th.K_crit, 4), round(th.rho_crit, 4)
    (True, 0.7639, -0.2747, 3.7694)
    >>> th = hovering.TruncatedMap(eps=-0.3, Omega0=hovering.OMEGA_G, theta_w=3 * np.pi / 4).theory()
    >>> th.hovers, th.area, th.note.split(":")[0]
    (False, 0.0, 'impacting case')
    """

    eps: float
    Omega0: float
    theta_w: float
    tau0: float
    forcing: tuple
    area: float
    hovers: bool
    hovering_sign: int
    K_crit: float
    rho_crit: float
    K_lowest: float
    note: str
    forcing_tol: float = 0.0
    geometry: str = "step"

    def G(self, psi):
        """The first-order shape ``G(psi)``, ``psi = phi + Omega0/2``, of the curves through L1."""
        psi = np.asarray(psi, dtype=float)
        g = _core_analysis.first_order_shape(list(self.forcing), self.Omega0, np.ascontiguousarray(psi.ravel()))
        return g.reshape(psi.shape) if psi.ndim else float(g[0])

    def curve(self, phi):
        """The lowest curve avoiding the impacting arcs (critical curve if hovering, else k^{u0}) at phi."""
        return self.K_lowest + self.eps * self.G(np.asarray(phi, dtype=float) + 0.5 * self.Omega0)


def _lowest(eps: float, theta_w: float, G, n: int) -> tuple:
    """(|HOV|, K_low): the lowest curve K_low + eps G >= 0 outside J_0 = {|psi| < theta_w}, and the
    area between it and K = 0 inside J_0 (trapezoid rule on grids that contain +-theta_w exactly)."""
    out = np.linspace(theta_w, math.pi, n)
    K_low = -float(min(np.min(eps * G(out)), np.min(eps * G(-out))))
    inside = np.linspace(-theta_w, theta_w, n)
    depth = np.maximum(0.0, -(K_low + eps * G(inside)))
    area = float(np.sum(0.5 * (depth[1:] + depth[:-1])) * (inside[1] - inside[0]))
    return area, K_low


def _sign(x: float) -> int:
    return 1 if x > 0 else -1 if x < 0 else 0


def _dropped_note(dropped: list, tol: float) -> str:
    """What the tolerance removed, in words ('' if nothing)."""
    if not dropped:
        return ""
    listed = ", ".join(f"b_{k} = {x:.3g}" for k, x in dropped[:4]) + (", ..." if len(dropped) > 4 else "")
    return f" ({listed}: within the tolerance {tol:.3g} of 0, taken as 0)"


def _first_mode(base: dict, e: float, fields: dict) -> Theory:
    """The closed forms for f = b_1 sin (e = eps b_1): eq:kcrit, eq:rhocrit, eq:hovsetsize and k^{u0}."""
    Omega0, theta_w, tau0 = base["Omega0"], base["theta_w"], base["tau0"]
    s = math.sin(0.5 * Omega0)
    hovers = e * s > 0
    K_c = -e * (1 - math.cos(theta_w)) / (2 * s)
    K_low = K_c if hovers else -e / s  # k_{eps,2}(phi, rho_2(0)) = -e (1 + cos psi) / (2 s) on L1
    area = abs(e) * (math.sin(theta_w) - theta_w * math.cos(theta_w)) / abs(s) if hovers else 0.0
    sign = _sign(s * (base["forcing"][0] if base["forcing"] else 0.0))
    if base["eps"] == 0:
        note = "eps = 0: the hovering set is empty by definition"
    elif hovers:
        note = (
            f"hovering case: eps b_1 sin(Omega0/2) = {e * s:.4g} > 0, the minima of the invariant curves lie near "
            "L1 inside J_0 (lemma:mininj0jr)"
        )
    else:
        note = (
            f"impacting case: eps b_1 sin(Omega0/2) = {e * s:.4g} < 0, the minima of the invariant curves lie near "
            "L2 inside J_R (lemma:mininj0jr): no hovering set; the lowest curve avoiding the impacts is k^{u0} >= 0"
        )
    if tau0 == 0:
        note += "; tau0 = 0 (no twist): KAM curves need not exist, the first-order curves are formal"
    nan = float("nan")
    return Theory(
        **base,
        area=area,
        hovers=hovers,
        hovering_sign=sign,
        K_crit=K_c if hovers else nan,
        rho_crit=Omega0 + e * tau0 * math.cos(theta_w) / (2 * s) if hovers else nan,
        K_lowest=K_low,
        note=note,
        **fields,
    )


def _no_hovering(base: dict, fields: dict, K_lowest: float, note: str) -> Theory:
    """A Theory with an exactly empty hovering set (area 0, hovers False, sign 0)."""
    nan = float("nan")
    return Theory(
        **base,
        area=0.0,
        hovers=False,
        hovering_sign=0,
        K_crit=nan,
        rho_crit=nan,
        K_lowest=K_lowest,
        note=note,
        **fields,
    )


def _other_geometry(base: dict, fields: dict, geometry: str, n: int) -> Theory:
    """What applies without the step's corner: no hovering set (see :func:`theory`)."""
    b, eps, Omega0 = base["forcing"], base["eps"], base["Omega0"]
    if geometry == "none":
        return _no_hovering(
            base,
            fields,
            float("nan"),
            "geometry 'none': no walls, so nothing ever impacts and the hovering set (points that impact "
            "under F_0) is empty for every eps; the return map is smooth (the shifted standard map "
            "eq:shiftstandardmap to leading order) and no curve is critical",
        )
    # The wall: J_0 is empty, every K < 0 arc impacts, so the lowest curve avoiding the impacts is the
    # lowest first-order curve that stays at K >= 0 on the whole circle (k^{u0}).
    modes = [k + 1 for k, x in enumerate(b) if x != 0]
    if eps == 0 or not modes:
        K_low = 0.0
    elif any(abs(math.sin(0.5 * k * Omega0)) < 1e-9 for k in modes):
        K_low = float("nan")  # resonant: no first-order curves
    elif modes == [1]:
        K_low = max(0.0, -eps * b[0] / math.sin(0.5 * Omega0))
    else:
        probe = Theory(**base, area=0.0, hovers=False, hovering_sign=0, K_crit=0.0, rho_crit=0.0, K_lowest=0.0, note="")
        _, K_low = _lowest(eps, 0.0, probe.G, n)
    return _no_hovering(
        base,
        fields,
        K_low,
        "geometry 'wall': an infinite wall q1 = qw1 without the step's corner, so no orbit crosses q1 = qw1 "
        "without hitting it: J_0 and J_1 are empty, every K < 0 point impacts on its first return (the wall "
        "system's map eq:fwall/eq:gwall, of PnueliRomKedarTangency), and HOV, a subset of J_0, is empty for "
        "every eps and Omega0; the step's theory (thm:hovering, eq:hovsetsize) does not apply",
    )


def theory(
    eps: float,
    Omega0: float,
    theta_w: float,
    tau0: float = 1.0,
    forcing: Sequence[float] = (1.0,),
    n_grid: int = 100_001,
    geometry: str = "step",
    forcing_tol: float | None = None,
) -> Theory:
    """Leading-order hovering set, critical curve and its rotation for any Omega0 and odd forcing.

    The paper's theory (thm:hovering, eq:kcrit, eq:rhocrit, eq:hovsetsize) is stated for Omega0 in
    (0, 2 pi) and f = sin; here it holds for every Omega0, either sign of tau0 and any odd forcing
    ``f = sum_k b_k sin(k phi)``. The sign of eps that hovers is ``sign(sin(Omega0/2) b_1)`` (period
    4 pi in Omega0); see :class:`Theory`.

    Parameters
    ----------
    eps : float
        Forcing amplitude.
    Omega0, theta_w, tau0 : float
        Rotation at tangency, wall angle (in (0, pi)) and twist.
    forcing : sequence of float, optional
        Sine coefficients ``b_1, b_2, ...`` of f (default ``f = sin``).
    n_grid : int, optional
        Points of the grids in psi for a forcing with more than one mode (the integral converges
        as n_grid^-2: ~1e-10 relative at the default; f = b_1 sin uses the closed forms).
    geometry : {"step", "wall", "none"}, optional
        The walls of the system (:class:`hovering.StepSystem`). ``"step"``: the paper's theory.
        ``"wall"``: the infinite wall q1 = qw1 has no corner, so every orbit that crosses
        q1 = qw1 hits it (J_0 is empty: every K < 0 point impacts on its first return, eq:fwall):
        the hovering set, a subset of J_0, is empty exactly, for every eps (``area = 0``,
        ``hovers = False``, ``hovering_sign = 0``; ``K_lowest`` is the lowest first-order curve
        at K >= 0). ``"none"``: nothing ever impacts, the hovering set is empty by definition.
    forcing_tol : float, optional
        Coefficients with ``|b_k| <= forcing_tol`` are taken as 0 (rounding or measurement noise;
        the note names them). Default: the rounding bound of the package's sine fit of 256
        samples, ``2 (256 + 2) u sum_k |b_k|`` (u = 2^-53, i.e. 5.7e-14 times ``sum_k |b_k|``).
        :meth:`hovering.FlowMap.theory` passes the measured forcing's own error bound
        (:meth:`hovering.FlowMap.forcing_tolerance`). 0 keeps every nonzero coefficient.
        Without ``b_1`` ("no first-order forcing", e.g. a coupling even in q2) the higher modes
        decide and the note says so; without any mode the map is F_0 and nothing hovers.

    Returns
    -------
    Theory

    Raises
    ------
    ValueError
        For non-finite parameters, an empty forcing, ``n_grid < 101``, an unknown geometry or a
        negative ``forcing_tol``.

    Examples
    --------
    >>> import math, hovering
    >>> th = hovering.theory(0.3, hovering.OMEGA_G, 3 * math.pi / 4)   # eps, Omega0, theta_w
    >>> th.hovers, round(th.area, 4)
    (True, 0.7639)
    >>> hovering.theory(0.3, hovering.OMEGA_G, 3 * math.pi / 4, geometry="wall").area   # no corner: nothing hovers
    0.0
    """
    eps, theta_w, tau0 = (real_number(n, v) for n, v in (("eps", eps), ("theta_w", theta_w), ("tau0", tau0)))
    Omega0 = _omega0(real_number("Omega0", Omega0))
    given = tuple(float(x) for x in forcing_array(forcing))
    n_grid = integer("n_grid", n_grid, 101, 10**7)
    if not is_choice(geometry, _GEOMETRIES):
        raise ValueError(f"geometry must be one of {_GEOMETRIES}, got {geometry!r}")
    tol = (
        _forcing_rounding(given)
        if forcing_tol is None
        else real_number("forcing_tol", forcing_tol, lo=0.0, lo_open=False)
    )
    b = tuple(0.0 if abs(x) <= tol else x for x in given)
    dropped = [(k + 1, x) for k, x in enumerate(given) if x != 0 and b[k] == 0]
    nan = float("nan")
    base = dict(eps=float(eps), Omega0=float(Omega0), theta_w=float(theta_w), tau0=float(tau0), forcing=b)
    fields = dict(forcing_tol=float(tol), geometry=geometry)
    noise = _dropped_note(dropped, tol)
    if geometry != "step":
        th = _other_geometry(base, fields, geometry, int(n_grid))
        return dataclasses.replace(th, note=th.note + noise) if noise else th
    if not 0 < theta_w < math.pi:
        return Theory(
            **base,
            area=nan,
            hovers=False,
            hovering_sign=0,
            K_crit=nan,
            rho_crit=nan,
            K_lowest=nan,
            note=f"theta_w = {theta_w} outside (0, pi): no arc structure at the tangency",
            **fields,
        )
    res = [k + 1 for k, x in enumerate(b) if x != 0 and abs(math.sin(0.5 * (k + 1) * Omega0)) < 1e-9]
    if res:
        return Theory(
            **base,
            area=nan,
            hovers=False,
            hovering_sign=0,
            K_crit=nan,
            rho_crit=nan,
            K_lowest=nan,
            note=f"resonant: sin({res[0]} Omega0 / 2) = 0 (Omega0 = {Omega0}), the first-order "
            "invariant curves do not exist there",
            **fields,
        )
    modes = [k + 1 for k, x in enumerate(b) if x != 0]
    if not modes and eps != 0:
        # f = 0: K' = K, the circles K = const are invariant (F_eps = F_0 for the truncated map);
        # below K = 0 they keep impacting.
        return _no_hovering(
            base,
            fields,
            0.0,
            "no forcing: every sine coefficient of f is 0" + (noise or f" (b = {given})") + ", so K is preserved to "
            "that accuracy (K' = K + eps f = K): the circles K = const stay invariant, every orbit below K = 0 keeps impacting and no "
            "hovering set is predicted (no first-order forcing, no higher modes)",
        )
    if modes == [1] or not modes:
        th = _first_mode(base, float(eps) * (b[0] if modes else 0.0), fields)
        return dataclasses.replace(th, note=th.note + noise) if noise else th
    n = int(n_grid)
    probe = Theory(**base, area=nan, hovers=False, hovering_sign=0, K_crit=nan, rho_crit=nan, K_lowest=nan, note="")
    area_p, _ = _lowest(1.0, theta_w, probe.G, n)
    area_m, _ = _lowest(-1.0, theta_w, probe.G, n)
    sign = 1 if area_p > 0 and area_m == 0 else -1 if area_m > 0 and area_p == 0 else 0
    area, K_low = _lowest(float(eps), theta_w, probe.G, n)
    mean_G = sum(x / (2 * math.sin(0.5 * (k + 1) * Omega0)) for k, x in enumerate(b))
    hovers = area > 0
    s = math.sin(0.5 * Omega0)
    if b[0] != 0:
        first = f"eps b_1 sin(Omega0/2) = {eps * b[0] * s:.4g}"
        how = f"modes 2..{modes[-1]} of f shape it at O(their size)"
    else:
        k_big = 1 + max(range(len(b)), key=lambda k: abs(b[k]))
        first = (
            f"no first-order forcing: b_1 = 0, so the paper's first-mode theory predicts nothing; the higher "
            f"modes act (largest: eps b_{k_big} = {eps * b[k_big - 1]:.3g})"
        )
        how = f"set by mode{'s' if len(modes) > 1 else ''} {', '.join(str(k) for k in modes)} of f"
    if eps == 0:
        note = "eps = 0: the hovering set is empty by definition"
    elif hovers:
        note = f"hovering: the critical curve dips into J_0 near L1 ({first}; {how})"
    else:
        note = (
            f"no hovering set: every first-order invariant curve that dips below K = 0 does so in the impacting "
            f"arcs ({first}); the lowest curve avoiding the impacts stays in K >= 0"
        )
    note += noise
    if tau0 == 0:
        note += "; tau0 = 0 (no twist): KAM curves need not exist, the first-order curves are formal"
    return Theory(
        **base,
        area=area,
        hovers=hovers,
        hovering_sign=sign,
        K_crit=K_low if hovers else nan,
        rho_crit=Omega0 + tau0 * (K_low + eps * mean_G) if hovers else nan,
        K_lowest=K_low,
        note=note,
        **fields,
    )
