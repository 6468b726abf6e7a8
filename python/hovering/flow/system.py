"""The oscillators-step system of sec:setup: potentials, coupling, geometry and onset parameters."""

from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass

import numpy as np

from .._checks import is_choice, real_number
from .._core import flow as _core_flow
from .._core.flow import OnsetParameters
from .._enums import Geometry
from .._io.records import reduce_record
from .potentials import COMPILED, Harmonic, Numerical, Potential, Tan, _potential_hash

__all__ = [
    "Harmonic",  # re-exported: the potentials' home is hovering.flow.potentials
    "Tan",
    "Numerical",
    "Potential",
    "Bilinear",
    "Polynomial",
    "StepSystem",
    "onset_parameters",
    "OnsetParameters",
]

_GEOMETRIES = ("none", "wall", "step")


_ONSET_FIELDS = ("Omega0", "tau0", "tau1", "lam", "theta_w", "I_tan")


def _onset_to_record(self) -> dict:
    """What :func:`hovering.save` writes: the six parameters."""
    return {name: getattr(self, name) for name in _ONSET_FIELDS}


def _onset_from_record(cls, record: dict) -> OnsetParameters:
    """Inverse of ``_to_record``."""
    obj = cls.__new__(cls)
    obj.__setstate__(tuple(record[name] for name in _ONSET_FIELDS))
    return obj


def _onset_eq(self, other):
    """Equal to onset parameters with the same six values."""
    if not isinstance(other, OnsetParameters):
        return NotImplemented
    return self.__getstate__() == other.__getstate__()


OnsetParameters._to_record, OnsetParameters._from_record = _onset_to_record, classmethod(_onset_from_record)
OnsetParameters.__reduce__ = reduce_record
OnsetParameters.__eq__, OnsetParameters.__hash__ = _onset_eq, _potential_hash


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

    def _to_record(self) -> dict:
        """What :func:`hovering.save` writes: nothing (the coupling has no parameter)."""
        return {}

    @classmethod
    def _from_record(cls, record: dict) -> Bilinear:
        """Inverse of :meth:`_to_record`."""
        return cls()

    def __reduce__(self):
        """Pickle as the record."""
        return reduce_record(self)


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
        if not isinstance(self.coefficients, dict) or not self.coefficients:
            raise ValueError(f"coefficients must be a non-empty dict {{(i, j): c}}, got {self.coefficients!r}")
        for key, c in self.coefficients.items():
            if not (isinstance(key, tuple) and len(key) == 2):
                raise ValueError(f"each key must be a pair of exponents (i, j) for c q1^i q2^j, got {key!r}")
            i, j = key
            if not all(isinstance(e, (int, np.integer)) and not isinstance(e, bool) and 0 <= e <= 20 for e in (i, j)):
                raise ValueError(f"exponents must be integers in [0, 20], got ({i!r}, {j!r})")
            if isinstance(c, bool) or not isinstance(c, numbers.Real) or not math.isfinite(c):
                raise ValueError(f"coefficient of q1^{i} q2^{j} must be a finite real number, got {c!r}")

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

    def _to_record(self) -> dict:
        """What :func:`hovering.save` writes: the terms ``[i, j, c_ij]`` in order."""
        return {"terms": [[int(i), int(j), float(c)] for (i, j), c in self.coefficients.items()]}

    @classmethod
    def _from_record(cls, record: dict) -> Polynomial:
        """Inverse of :meth:`_to_record` (validated again: a file's terms are untrusted).

        Each term is ``[i, j, c]`` and each power ``(i, j)`` appears once: a dict built from a
        repeated power would keep its last coefficient and drop the others without a word.
        """
        terms = record["terms"]
        if not isinstance(terms, list) or not terms:
            raise ValueError(f"terms must be a non-empty list of [i, j, c], got {type(terms).__name__}")
        coefficients: dict = {}
        for n, term in enumerate(terms):
            if not isinstance(term, list) or len(term) != 3:
                raise ValueError(f"terms[{n}] must be a term [i, j, c] (c q1^i q2^j), got {str(term)[:80]}")
            i, j, c = term
            if not all(isinstance(e, (int, np.integer)) and not isinstance(e, bool) and 0 <= e <= 20 for e in (i, j)):
                raise ValueError(f"terms[{n}]: exponents must be integers in [0, 20], got {str(term)[:80]}")
            if (i, j) in coefficients:
                raise ValueError(
                    f"terms[{n}] = {str(term)[:80]} repeats the power q1^{i} q2^{j} of an earlier term; "
                    "allowed: each power (i, j) once"
                )
            coefficients[(i, j)] = c
        return cls(coefficients)

    def __reduce__(self):
        """Pickle as the record."""
        return reduce_record(self)


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

    Examples
    --------
    The README's system: V1 harmonic, V2 a Tan well, coupled by ``eps q1 q2``:

    >>> import hovering
    >>> system = hovering.StepSystem(hovering.Harmonic(1.0), hovering.Tan(1.4, 0.7), hovering.Bilinear(), eps=-0.05)
    >>> round(system.step_energy, 4)     # above this energy orbits can reach the corner
    0.7665
    >>> p = hovering.onset_parameters(system, h=1.0)   # the truncated model's parameters at h = 1
    >>> round(p.Omega0, 4), round(p.theta_w, 4)
    (9.8347, 2.4445)
    >>> system.replace(eps=0.0).eps     # a validated copy with a field changed
    0.0
    """

    V1: Potential
    V2: Potential
    coupling: object | None = None
    eps: float = 0.0
    qw1: float = -1.0
    qw2: float = -0.5
    geometry: str = "step"

    def __post_init__(self):
        for name in ("V1", "V2"):
            pot = getattr(self, name)
            if not isinstance(pot, Potential):
                raise ValueError(
                    f"{name} must be a hovering potential (Harmonic, Tan, CustomPotential, ...), got {pot!r}"
                )
            # The core computes a compiled potential's forces from its parameters: a Python override
            # of V or dV in a subclass of one would be silently ignored by the flow.
            for base in COMPILED:
                if isinstance(pot, base) and any(getattr(type(pot), f) is not getattr(base, f) for f in ("V", "dV")):
                    raise ValueError(
                        f"{name}: {type(pot).__name__} overrides V/dV of the compiled {base.__name__}, which the "
                        "core would ignore; subclass hovering.Potential (or use CustomPotential) instead"
                    )
        for name in ("eps", "qw1", "qw2"):
            object.__setattr__(self, name, real_number(name, getattr(self, name)))
        if not math.isfinite(self.eps):
            raise ValueError(f"eps must be finite, got {self.eps}")
        if self.eps != 0 and self.coupling is None:
            raise ValueError("eps != 0 needs a coupling (e.g. hovering.Bilinear())")
        _terms(self.coupling)
        if isinstance(self.geometry, Geometry):  # the core's enum is as good as its name
            object.__setattr__(self, "geometry", self.geometry.name.lower())
        if not is_choice(self.geometry, _GEOMETRIES):
            raise ValueError(f"geometry must be one of {_GEOMETRIES}, got {self.geometry!r}")
        for name, pot in (("qw1", self.V1), ("qw2", self.V2)):
            q = getattr(self, name)
            if not (math.isfinite(q) and q < 0):
                raise ValueError(f"{name} must be finite and < 0 (the minimum lies outside the step), got {q}")
            if not abs(q) < pot.q_limit:
                raise ValueError(f"{name} = {q} lies outside the well of {pot!r} (|{name}| < {pot.q_limit})")

        geometry = {"none": Geometry.NONE, "wall": Geometry.WALL, "step": Geometry.STEP}[self.geometry]
        # The core's validated copy, built once (frozen: set through object.__setattr__).
        object.__setattr__(
            self,
            "_core",
            _core_flow.FlowSystem(self.V1, self.V2, _terms(self.coupling), self.eps, self.qw1, self.qw2, geometry),
        )
        # Asked by every batch call that picks its thread count (0.7 us to work out): fixed here.
        object.__setattr__(
            self,
            "_python_defined",
            any(
                isinstance(p, _core_flow._CallablePotential) or not type(p).__module__.startswith("hovering._core")
                for p in (self.V1, self.V2)
            ),
        )

    @property
    def core(self) -> _core_flow.FlowSystem:
        """The core's FlowSystem of this system (what the compiled flow integrates)."""
        return self._core

    @property
    def step_energy(self) -> float:
        """``h_0^w = V1(qw1) + V2(qw2)``: above it, orbits can reach the corner (def:heps)."""
        return self.V1.V(self.qw1) + self.V2.V(self.qw2)

    @property
    def python_defined(self) -> bool:
        """Whether V1 or V2 calls back into Python (CustomPotential or a Python subclass)."""
        return self._python_defined

    def replace(self, **changes) -> StepSystem:
        """A copy with some fields changed (e.g. ``eps=0.0``, ``geometry="wall"``), validated again.

        Parameters
        ----------
        **changes
            Field values: V1, V2, coupling, eps, qw1, qw2, geometry.

        Returns
        -------
        StepSystem
        """
        fields = dict(
            V1=self.V1,
            V2=self.V2,
            coupling=self.coupling,
            eps=self.eps,
            qw1=self.qw1,
            qw2=self.qw2,
            geometry=self.geometry,
        )
        unknown = set(changes) - set(fields)
        if unknown:
            raise ValueError(f"unknown StepSystem field(s) {sorted(unknown)}; allowed: {sorted(fields)}")
        fields.update(changes)
        return StepSystem(**fields)

    def __reduce__(self):
        """Pickle as the record (the constructor arguments; the core's copy is rebuilt, and validated, on
        unpickling)."""
        return reduce_record(self)

    def _to_record(self) -> dict:
        """What :func:`hovering.save` writes: the fields (potentials and coupling as their own records)."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.init}

    @classmethod
    def _from_record(cls, record: dict) -> StepSystem:
        """Inverse of :meth:`_to_record` (validated again)."""
        return cls(**record)


def onset_parameters(sys: StepSystem, h: float, method: str = "definitions", rtol: float = 1e-6, errors: bool = False):
    """Onset parameters Omega0, tau0, tau1, lam, theta_w (sec:parametersdef) at energy h.

    Every parameter comes with an estimate of its absolute error: the potentials' own error
    (closed forms: a few ulps; quadrature: its 1e-12 tolerance; derivatives: their extrapolation
    table) plus the rounding of h, V1(qw1) and V2(qw2) carried through. The step energy h_w is
    known only to a few ulps, so h - h_w is too: theta_w and tau1, which have a square-root
    singularity at h = h_w, cannot be had arbitrarily close to it.

    Parameters
    ----------
    sys : StepSystem
        The system (only V1, V2, qw1, qw2 enter: the parameters are defined at eps = 0).
    h : float
        Energy, above the step energy ``sys.step_energy``, at most 1e100.
    method : {"definitions", "quadrature", "closed_form"}, optional
        ``"definitions"``: eq:omega0ofI .. eq:deftau1 by the chain rule, Omega0 = omega2(h2) T1(h1w),
        tau0 = omega2 (omega2'(h2) T1(h1w) - omega2 T1'(h1w)), tau1 = -2 omega2 dtheta_w/dh2
        (h1w = V1(qw1), h2 = h - h1w), with the potentials' own action-angle variables and their
        energy slopes (closed forms for Harmonic/Tan; Ridders-extrapolated differences of the
        quadratures otherwise). ``"quadrature"``: the same with every period, action, angle and
        slope by GSL quadrature (any potential). ``"closed_form"``: the appendix formulas
        (Harmonic/Tan only), corrected where they disagree with the definitions (tau0's last term
        over W1^3, not W1^4; theta_w = arccos(+...), not arccos(-...)) and evaluated without their
        cancellations near the step energy.
    rtol : float, optional
        Largest accepted estimated relative error of each parameter, in [1e-15, 1].
    errors : bool, optional
        Also return the error estimates.

    Returns
    -------
    OnsetParameters
        ``.Omega0, .tau0, .tau1, .lam, .theta_w, .I_tan``. A tau0 or tau1 smaller than its own error,
        when that error is below ``rtol`` times the parameter's scale (Omega0 / I_tan for tau0,
        1 / I_tan for tau1), is returned as 0 (zero within its error).
    OnsetParameters, optional
        With ``errors=True``: the estimated absolute error of each parameter (same fields).

    Raises
    ------
    ValueError
        If h is not above the step energy or above 1e100, for an unknown method, or if a parameter's
        estimated relative error exceeds ``rtol`` (the message names the parameter, the energy,
        h - h_w and why: e.g. h - h_w below the resolution of the step energy, or a derivative of
        quadratures too noisy for a quantity that tends to 0).
    """
    if not isinstance(sys, StepSystem):
        raise ValueError(f"sys must be a hovering.StepSystem, got {sys!r}")
    h = float(real_number("h", h, hi=1e100, hi_open=False))
    rtol = float(real_number("rtol", rtol, lo=1e-15, lo_open=False, hi=1.0, hi_open=False))
    if not isinstance(errors, bool):
        raise ValueError(f"errors must be True or False, got {errors!r}")
    if method == "definitions":
        r = _core_flow._onset_estimate(sys.V1, sys.V2, sys.qw1, sys.qw2, h, rtol)
    elif method == "quadrature":
        r = _core_flow._onset_estimate(Numerical(sys.V1), Numerical(sys.V2), sys.qw1, sys.qw2, h, rtol)
    elif method == "closed_form":

        def wa(p):
            if isinstance(p, Tan):
                return p.omega, p.alpha
            if isinstance(p, Harmonic):
                return p.omega, 0.0
            raise ValueError(f"closed_form needs Harmonic or Tan potentials, got {p!r}")

        (w1, a1), (w2, a2) = wa(sys.V1), wa(sys.V2)
        r = _core_flow._onset_estimate_closed_form(w1, a1, w2, a2, sys.qw1, sys.qw2, h, rtol)
    else:
        raise ValueError(f"method must be 'definitions', 'quadrature' or 'closed_form', got {method!r}")
    return r if errors else r[0]
