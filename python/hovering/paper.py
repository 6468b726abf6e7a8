"""The paper's parameter sets and the physical system used throughout, in one place (heyoka's
``model/`` style): tests, examples, benchmarks and docs build them from here instead of typing
them out.

Truncated map (sec:truncatedmapnum, fig:smalleps): ``(Omega0, theta_w, tau0, tau1, lam) =
(Omega_G, 3 pi / 4, 1, 1/2, 1/2)`` with ``Omega_G = 2 pi (sqrt 5 - 1) / 2``, at ``eps = +-0.3``
(fig:smalleps) and up to ``eps = 0.92`` (fig:epsbig); its critical rotation is eq:rhocrit.

Physical system (the README's, built for this package: the paper has no numeric one): harmonic
``V1 = Harmonic(1)``, ``V2 = Tan(1.4, 0.7)``, bilinear coupling ``eps q1 q2``, the step at
``(qw1, qw2) = (-1, -1/2)``, energy ``h = 1``.

>>> import hovering.paper as paper
>>> m = paper.truncated_map(-0.3)       # fig:smalleps, the sign that does not hover
>>> sec = paper.section(eps=0.05)        # the flow's return map to Sigma_h
"""

from __future__ import annotations

import math
from typing import Any

from .flow.section import Section
from .flow.system import Bilinear, Harmonic, StepSystem, Tan
from .normal.flowmap import FlowMap
from .truncated.maps import TruncatedMap
from .truncated.theory import OMEGA_G

__all__ = [
    "OMEGA_G",
    "FIGURE",
    "EPS_SMALL",
    "EPS_BIG",
    "truncated_map",
    "V1",
    "V2",
    "QW1",
    "QW2",
    "H",
    "system",
    "section",
    "flow_map",
]

#: The truncated map's parameters of fig:smalleps (and of every figure of sec:truncatedmapnum), eps aside.
FIGURE = dict(Omega0=OMEGA_G, theta_w=3 * math.pi / 4, tau0=1.0, tau1=0.5, lam=0.5)

#: The two signs of fig:smalleps: +0.3 hovers (sin(Omega_G / 2) > 0), -0.3 does not.
EPS_SMALL = (0.3, -0.3)

#: The largest eps of fig:epsbig.
EPS_BIG = 0.92


def truncated_map(eps: float = 0.3, **overrides) -> TruncatedMap:
    """The truncated map F_eps with the figure parameters (:data:`FIGURE`).

    Parameters
    ----------
    eps : float, optional
        Perturbation amplitude.
    **overrides
        Any other constructor argument of :class:`hovering.TruncatedMap` (e.g. ``theta_w``).

    Returns
    -------
    TruncatedMap
    """
    return TruncatedMap(eps=eps, **{**FIGURE, **overrides})


#: The physical system's potentials, step and energy.
V1 = Harmonic(1.0)
V2 = Tan(1.4, 0.7)
QW1, QW2 = -1.0, -0.5
H = 1.0


def system(eps: float = 0.0, geometry: str = "step", **overrides) -> StepSystem:
    """The physical system: ``V1``, ``V2``, bilinear coupling, the step at ``(QW1, QW2)``.

    Parameters
    ----------
    eps : float, optional
        Coupling strength.
    geometry : {"step", "wall", "none"}, optional
        The step, only its right wall, or no walls.
    **overrides
        Any other argument of :class:`hovering.StepSystem` (``V1``, ``V2``, ``coupling``, ``qw1``,
        ``qw2``); None keeps the default.

    Returns
    -------
    StepSystem
    """
    kw: dict[str, Any] = dict(V1=V1, V2=V2, coupling=Bilinear(), qw1=QW1, qw2=QW2)
    kw.update({k: v for k, v in overrides.items() if v is not None})
    return StepSystem(eps=eps, geometry=geometry, **kw)


def section(eps: float = 0.0, geometry: str = "step", h: float = H, **overrides) -> Section:
    """The physical system's section Sigma_h (its return map and coordinates).

    Parameters
    ----------
    eps, geometry, **overrides
        As :func:`system`.
    h : float, optional
        Energy.

    Returns
    -------
    Section
    """
    return Section(system(eps, geometry, **overrides), h)


def flow_map(eps: float = 0.0, geometry: str = "step", h: float = H, **options) -> FlowMap:
    """The physical system's return map as a map on (phi, K): :class:`hovering.FlowMap`.

    Parameters
    ----------
    eps, geometry : optional
        As :func:`system`.
    h : float, optional
        Energy.
    **options
        Keyword arguments of :class:`hovering.FlowMap` (``coordinates``, ``stepper``, ``rtol``, ...).

    Returns
    -------
    FlowMap
    """
    return FlowMap(system(eps, geometry), h, **options)
