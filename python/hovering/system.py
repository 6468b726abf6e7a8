"""The oscillators-step system of sec:setup: potentials, coupling, geometry, onset parameters.

This release provides the system description (validated) and its onset parameters
(sec:parametersdef); the impact flow on GSL and the Poincare return map come next (issue 4).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

from . import _core
from ._core import Harmonic, Numerical, OnsetParameters, Potential, Tan

__all__ = ["Harmonic", "Tan", "Numerical", "Potential", "Bilinear", "StepSystem", "onset_parameters", "OnsetParameters"]

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
            if not isinstance(getattr(self, name), Potential):
                raise ValueError(f"{name} must be a hovering potential (Harmonic, Tan, ...), got {getattr(self, name)!r}")
        if not math.isfinite(self.eps):
            raise ValueError(f"eps must be finite, got {self.eps}")
        if self.eps != 0 and self.coupling is None:
            raise ValueError("eps != 0 needs a coupling (e.g. hovering.Bilinear())")
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
