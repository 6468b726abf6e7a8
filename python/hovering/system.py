"""The oscillators-step system of sec:setup: potentials, coupling, geometry, onset parameters,
the section Sigma_h and the return map of the impact flow (geometry "none", "wall", "step").
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import IntEnum
from typing import Optional

import numpy as np

from . import _core
from ._core import Harmonic, Numerical, OnsetParameters, Potential, Tan

__all__ = [
    "Harmonic",
    "Tan",
    "Numerical",
    "Potential",
    "Bilinear",
    "Polynomial",
    "StepSystem",
    "onset_parameters",
    "OnsetParameters",
    "Section",
    "ReturnMapResult",
    "FlowStatus",
    "tangential_curve",
    "forcing_function",
    "to_normal",
    "from_normal",
]

_GEOMETRIES = ("none", "wall", "step")


@dataclass(frozen=True)
class Bilinear:
    """The coupling ``Vc(q1, q2) = q1 q2``."""

    def __call__(self, q1, q2):
        """Vc(q1, q2).

        Parameters
        ----------
        q1, q2 : float or array_like
            Positions.

        Returns
        -------
        float or ndarray
        """
        return q1 * q2


@dataclass(frozen=True)
class Polynomial:
    """The coupling ``Vc(q1, q2) = sum c_ij q1^i q2^j``.

    Parameters
    ----------
    coefficients : dict
        ``{(i, j): c_ij}`` with integer exponents in [0, 20].
    """

    coefficients: dict

    def __post_init__(self):
        for (i, j), c in self.coefficients.items():
            if not (int(i) == i and int(j) == j and 0 <= i <= 20 and 0 <= j <= 20):
                raise ValueError(f"exponents must be integers in [0, 20], got ({i}, {j})")
            if not math.isfinite(c):
                raise ValueError(f"coefficient of q1^{i} q2^{j} must be finite, got {c}")

    def __call__(self, q1, q2):
        """Vc(q1, q2).

        Parameters
        ----------
        q1, q2 : float or array_like
            Positions.

        Returns
        -------
        float or ndarray
        """
        return sum(c * q1**i * q2**j for (i, j), c in self.coefficients.items())


def _terms(coupling) -> list:
    if coupling is None:
        return []
    if isinstance(coupling, Bilinear):
        return [(1.0, 1.0, 1.0)]
    if isinstance(coupling, Polynomial):
        return [(float(c), float(i), float(j)) for (i, j), c in coupling.coefficients.items()]
    raise ValueError(f"coupling must be hovering.Bilinear() or hovering.Polynomial({{(i, j): c}}), got {coupling!r}")


@dataclass(frozen=True)
class StepSystem:
    """``H = p1^2/2 + V1(q1) + p2^2/2 + V2(q2) + eps Vc(q1, q2)`` with a step ``{q1 < qw1, q2 < qw2}``.

    Parameters
    ----------
    V1, V2 : Potential
        Single-well potentials (``hovering.Harmonic``, ``hovering.Tan``, ...).
    coupling : object, optional
        ``Vc`` (e.g. :class:`Bilinear`); ignored (not evaluated) when ``eps == 0``.
    eps : float, optional
        Coupling strength.
    qw1, qw2 : float
        Corner of the step, both < 0 (the minima lie outside the step) and inside the wells.
    geometry : {"none", "wall", "step"}, optional
        Which walls the flow sees: none, the right wall q1 = qw1 only, or the step.

    Raises
    ------
    ValueError
        Naming the bad value and its allowed range.
    """

    V1: Potential
    V2: Potential
    coupling: Optional[object] = None
    eps: float = 0.0
    qw1: float = -1.0
    qw2: float = -0.5
    geometry: str = "step"

    def __post_init__(self):
        for name in ("V1", "V2"):
            pot = getattr(self, name)
            if not isinstance(pot, Potential):
                raise ValueError(f"{name} must be a hovering potential (Harmonic, Tan, CustomPotential, ...), got {pot!r}")
            # The core computes Harmonic and Tan forces from their parameters: a Python override of
            # V or dV in a subclass of them would be silently ignored by the flow.
            for base in (Harmonic, Tan):
                if isinstance(pot, base) and any(getattr(type(pot), f) is not getattr(base, f) for f in ("V", "dV")):
                    raise ValueError(f"{name}: {type(pot).__name__} overrides V/dV of the compiled {base.__name__}, which the "
                                     "core would ignore; subclass hovering.Potential (or use CustomPotential) instead")
        if not math.isfinite(self.eps):
            raise ValueError(f"eps must be finite, got {self.eps}")
        if self.eps != 0 and self.coupling is None:
            raise ValueError("eps != 0 needs a coupling (e.g. hovering.Bilinear())")
        _terms(self.coupling)
        if self.geometry not in _GEOMETRIES:
            raise ValueError(f"geometry must be one of {_GEOMETRIES}, got {self.geometry!r}")
        for name, pot in (("qw1", self.V1), ("qw2", self.V2)):
            q = getattr(self, name)
            if not (math.isfinite(q) and q < 0):
                raise ValueError(f"{name} must be finite and < 0 (the minimum lies outside the step), got {q}")
            if not abs(q) < pot.q_limit:
                raise ValueError(f"{name} = {q} lies outside the well of {pot!r} (|{name}| < {pot.q_limit})")

    @property
    def step_energy(self) -> float:
        """``h_0^w = V1(qw1) + V2(qw2)``: above it, orbits can reach the corner (def:heps)."""
        return self.V1.V(self.qw1) + self.V2.V(self.qw2)


def onset_parameters(sys: StepSystem, h: float, method: str = "definitions") -> OnsetParameters:
    """Onset parameters Omega0, tau0, tau1, lam, theta_w (sec:parametersdef) at energy h.

    Parameters
    ----------
    sys : StepSystem
        The system (only V1, V2, qw1, qw2 enter: the parameters are defined at eps = 0).
    h : float
        Energy, above the step energy ``sys.step_energy``.
    method : {"definitions", "quadrature", "closed_form"}, optional
        ``"definitions"``: eq:omega0ofI .. eq:deftau1 with the potentials' own action-angle
        variables (closed forms for Harmonic/Tan) and Richardson central differences for tau0,
        tau1. ``"quadrature"``: the same with every period, action and angle by GSL quadrature
        (any potential). ``"closed_form"``: the appendix formulas (Harmonic/Tan only), corrected
        where they disagree with the definitions (tau0's last term over W1^3, not W1^4;
        theta_w = arccos(+...), not arccos(-...)).

    Returns
    -------
    OnsetParameters
        ``.Omega0, .tau0, .tau1, .lam, .theta_w, .I_tan``.

    Raises
    ------
    ValueError
        If h is not above the step energy, or for an unknown method.
    """
    if method == "definitions":
        return _core._onset_parameters(sys.V1, sys.V2, sys.qw1, sys.qw2, float(h))
    if method == "quadrature":
        return _core._onset_parameters(Numerical(sys.V1), Numerical(sys.V2), sys.qw1, sys.qw2, float(h))
    if method == "closed_form":
        def wa(p):
            if isinstance(p, Tan):
                return p.omega, p.alpha
            if isinstance(p, Harmonic):
                return p.omega, 0.0
            raise ValueError(f"closed_form needs Harmonic or Tan potentials, got {p!r}")

        (w1, a1), (w2, a2) = wa(sys.V1), wa(sys.V2)
        return _core._onset_parameters_closed_form(w1, a1, w2, a2, sys.qw1, sys.qw2, float(h))
    raise ValueError(f"method must be 'definitions', 'quadrature' or 'closed_form', got {method!r}")


class FlowStatus(IntEnum):
    """Per-orbit outcome of a return-map computation."""

    OK = 0  #: returned to Sigma_h
    CORNER = 1  #: hit the corner of the step (the orbit stops)
    GRAZING = 2  #: touched a wall tangentially
    STEP_LIMIT = 3  #: max_steps reached before returning
    NON_FINITE = 4  #: the state became non-finite
    IMPACT_LIMIT = 5  #: more impacts than max_impacts in one return (chattering)


@dataclass(frozen=True)
class ReturnMapResult:
    """Images of points of Sigma_h under the return map, one entry per initial condition.

    Attributes
    ----------
    theta, I : ndarray
        Section coordinates of the image (unperturbed S2 of (q2, p2)).
    z : ndarray
        Image states (q1, p1, q2, p2), shape (n, 4).
    time : ndarray
        Return times.
    itinerary : list of str
        Impacts in order ('R', '1', 'R1', ...); without impact '0' if the segment crossed
        q1 = qw1 above the step (J_0), 'u' if it never crossed it (J_0u); '' for the smooth flow
        (geometry "none") and for returns that did not end OK without impact.
    status : ndarray of int8
        Per-orbit :class:`FlowStatus`.
    energy_error : ndarray
        ``|H(image) - H(start)|``.
    steps : ndarray of int64
        Accepted integrator steps.
    """

    theta: np.ndarray
    I: np.ndarray
    z: np.ndarray
    time: np.ndarray
    itinerary: list
    status: np.ndarray
    energy_error: np.ndarray
    steps: np.ndarray


class Section:
    """The Poincare section ``Sigma_h = {p1 = 0, dp1/dt < 0, H = h}`` of a system.

    Parameters
    ----------
    sys : StepSystem
        The system.
    h : float
        Energy level.
    """

    def __init__(self, sys: StepSystem, h: float):
        if not isinstance(sys, StepSystem):
            raise ValueError(f"sys must be a hovering.StepSystem, got {sys!r}")
        if not math.isfinite(h):
            raise ValueError(f"h must be finite, got {h}")
        self.sys = sys
        self.h = float(h)
        self._args = (sys.V1, sys.V2, _terms(sys.coupling), float(sys.eps), float(sys.qw1), float(sys.qw2),
                      _GEOMETRIES.index(sys.geometry))

    def point(self, theta, I) -> np.ndarray:
        """States (q1, 0, q2, p2) of Sigma_h at section coordinates (theta, I).

        Parameters
        ----------
        theta, I : array_like
            Angle in [-pi, pi] and action of the unperturbed H2 (broadcast together).

        Returns
        -------
        ndarray
            Shape (n, 4).

        Raises
        ------
        ValueError
            Where no such point exists (e.g. H2(I) >= h), naming the point.
        """
        t, i = np.broadcast_arrays(np.asarray(theta, dtype=float), np.asarray(I, dtype=float))
        return _core._section_points(*self._args, self.h, np.ascontiguousarray(t.ravel()), np.ascontiguousarray(i.ravel()))

    def coordinates(self, z) -> np.ndarray:
        """Section coordinates (theta, I) of states z (shape (n, 4)).

        Parameters
        ----------
        z : array_like
            States.

        Returns
        -------
        ndarray
            Shape (n, 2): theta in [-pi, pi), I.
        """
        return _core._section_coordinates(*self._args, np.ascontiguousarray(np.atleast_2d(np.asarray(z, dtype=float))))

    def return_map(self, theta, I, rtol: float = 1e-10, atol: float = 1e-12, stepper: str = "rk8pd",
                   event_tol: float = 1e-15, max_steps: int = 1_000_000, max_impacts: int = 100,
                   grazing_tol: float = 1e-12, corner_tol: float = 1e-10, n_threads: int = 0) -> ReturnMapResult:
        """Return map of many points of Sigma_h (multi-threaded, GIL released).

        Parameters
        ----------
        theta, I : array_like
            Section coordinates of the starting points.
        rtol, atol : float, optional
            Tolerances of GSL's step-size control.
        stepper : {"rk8pd", "rkck", "rkf45", "rk4", "rk2", "msadams"}, optional
            GSL stepper: an explicit Runge-Kutta method, or the variable-order Adams multistep
            method (its events are located on an rk8pd extension of each step; on this smooth,
            oscillatory flow it is ~7x slower than rk8pd at matched accuracy).
        event_tol : float, optional
            Time accuracy of located events (impacts, section crossing, a wall distance's
            minimum): Newton's method on exact stepper steps runs until its correction is below
            sqrt(event_tol), and that last correction is applied linearly (error ~ event_tol).
        max_steps : int, optional
            Step limit per return (status STEP_LIMIT beyond it).
        max_impacts : int, optional
            Impact limit per return (status IMPACT_LIMIT beyond it: chattering).
        grazing_tol : float, optional
            An orbit whose distance to a wall has a minimum within this of zero touches it
            tangentially (status GRAZING). Minima of the distance inside a step are searched, so
            dips deeper than this are impacts however short.
        corner_tol : float, optional
            An impact this close to the corner is a corner hit (status CORNER).
        n_threads : int, optional
            Worker threads (0 = all cores, or 1 when a potential is defined in Python: its calls
            serialise on the GIL).

        Returns
        -------
        ReturnMapResult
        """
        z0 = self.point(theta, I)
        if int(n_threads) == 0 and _python_defined(self.sys):
            n_threads = 1  # every Python call takes the GIL: two threads measured 3.4x slower than one
        d = _core._return_maps(*self._args, z0, stepper, float(rtol), float(atol), float(event_tol), int(max_steps),
                               int(max_impacts), float(grazing_tol), float(corner_tol), int(n_threads))
        c = self.coordinates(d["z"])
        return ReturnMapResult(theta=c[:, 0], I=c[:, 1], z=d["z"], time=d["time"], itinerary=d["itinerary"],
                               status=d["status"], energy_error=d["energy_error"], steps=d["steps"])


def _python_defined(sys: "StepSystem") -> bool:
    """Whether V1 or V2 calls back into Python (CustomPotential or a Python subclass)."""
    return any(isinstance(p, _core._CallablePotential) or type(p).__module__ != "hovering._core" for p in (sys.V1, sys.V2))


def _wall_section(sec: "Section") -> "Section":
    """The same system with the infinite wall q1 = qw1 (the tangential curve is about that line)."""
    s = sec.sys
    return Section(StepSystem(V1=s.V1, V2=s.V2, coupling=s.coupling, eps=s.eps, qw1=s.qw1, qw2=s.qw2, geometry="wall"), sec.h)


def tangential_curve(sec: "Section", theta, rtol: float = 1e-12, bracket: float = 0.2, iterations: int = 55) -> np.ndarray:
    """The tangential curve ``I_tan^eps(theta)`` (Def:sing_curve), by bisection in I.

    For each theta, the action at which the orbit from (theta, I) touches the line q1 = qw1
    tangentially before its return: below it the orbit crosses the line (impacts the infinite
    wall), above it the orbit turns back before the line. Found by a vectorised bisection between
    ``I_tan (1 -+ bracket)`` (eq:Itan) on the wall system's itineraries.

    Parameters
    ----------
    sec : Section
        The section (its system's eps, potentials and qw1 are used).
    theta : array_like
        Angles.
    rtol : float, optional
        Integration tolerance of each return.
    bracket : float, optional
        Relative half-width of the initial bracket around I_tan(h).
    iterations : int, optional
        Bisection steps (55 reach ~1e-16 relative).

    Returns
    -------
    ndarray
        ``I_tan^eps(theta)``.

    Raises
    ------
    ValueError
        If the bracket does not contain the tangency for some theta (eps too large for it).
    """
    th = np.atleast_1d(np.asarray(theta, dtype=float))
    ws = _wall_section(sec)
    I0 = sec.sys.V2.action(sec.h - sec.sys.V1.V(sec.sys.qw1))
    lo, hi = np.full(th.shape, I0 * (1 - bracket)), np.full(th.shape, I0 * (1 + bracket))

    def crosses(I):
        out = ws.return_map(th, I, rtol=rtol, atol=rtol * 1e-2)
        return np.array(["R" in s for s in out.itinerary]) | (out.status == FlowStatus.GRAZING)

    if not (crosses(lo).all() and not crosses(hi).any()):
        raise ValueError(f"the tangency is not inside I_tan (1 +- {bracket}) for every theta; raise bracket")
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        c = crosses(mid)
        lo = np.where(c, mid, lo)
        hi = np.where(c, hi, mid)
    return 0.5 * (lo + hi)


def forcing_function(sec: "Section", phi, **kwargs) -> np.ndarray:
    """``f(phi) = (I_tan^eps(-phi) - I_tan^eps(phi)) / eps`` (eq:defoff), odd in phi.

    Parameters
    ----------
    sec : Section
        The section of a system with eps != 0.
    phi : array_like
        Angles.
    **kwargs
        Passed to :func:`tangential_curve`.

    Returns
    -------
    ndarray
    """
    if sec.sys.eps == 0:
        raise ValueError("f(phi) is defined for eps != 0 (eq:defoff divides by eps)")
    p = np.atleast_1d(np.asarray(phi, dtype=float))
    both = tangential_curve(sec, np.concatenate([-p, p]), **kwargs)
    return (both[: p.size] - both[p.size :]) / sec.sys.eps


def to_normal(sec: "Section", theta, I, **kwargs):
    """Normal coordinates ``(phi, K) = (theta, I - I_tan^eps(theta))`` (eq:kphidef).

    Parameters
    ----------
    sec : Section
        The section.
    theta, I : array_like
        Section coordinates.
    **kwargs
        Passed to :func:`tangential_curve`.

    Returns
    -------
    phi, K : ndarray
    """
    th = np.atleast_1d(np.asarray(theta, dtype=float))
    return th, np.asarray(I, dtype=float) - tangential_curve(sec, th, **kwargs)


def from_normal(sec: "Section", phi, K, **kwargs):
    """Inverse of :func:`to_normal`: ``(theta, I) = (phi, K + I_tan^eps(phi))`` (eq:kphiinvdef).

    Parameters
    ----------
    sec : Section
        The section.
    phi, K : array_like
        Normal coordinates.
    **kwargs
        Passed to :func:`tangential_curve`.

    Returns
    -------
    theta, I : ndarray
    """
    p = np.atleast_1d(np.asarray(phi, dtype=float))
    return p, np.asarray(K, dtype=float) + tangential_curve(sec, p, **kwargs)
