"""Every single-well potential's Python face: the compiled kinds of the core's registry
(:data:`POTENTIAL_KINDS`: :class:`Harmonic`, :class:`Tan`), :class:`Numerical`, and potentials
defined in Python (``CustomPotential(V, dV)`` and the checks it runs).

The compiled kinds come from the core's one list (``CompiledPotentials`` in
``cpp/include/hovering/flow/potential.hpp``): the bindings bind each with its parameters, scene files
and plans name it by its kind, and here each gets equality by value and the record
:func:`hovering.save` writes, all from the registry's parameter names.

The compiled core answers every energy question (period, action, energy, angles, turning points)
of any potential from V and V' alone, by GSL quadrature and root finding, so a Python-defined
potential works wherever a compiled one does: :class:`~hovering.StepSystem`, :class:`~hovering.Section`
(points, coordinates, return maps, also on worker threads), :func:`~hovering.onset_parameters`
("definitions" and "quadrature"), :func:`~hovering.tangential_curve` and the normal coordinates.

Two ways to define one:

* ``CustomPotential(V, dV, q_limit=math.inf, name=...)`` with two callables ``float -> float``
  (checked here at construction);
* a subclass of :class:`hovering.Potential` defining ``V(self, q)`` and ``dV(self, q)``, and
  optionally ``name`` and ``q_limit`` as class constants or properties (call
  ``super().__init__()``; :func:`check_potential` runs the same checks on it).

Each evaluation takes the GIL and costs a Python call (~0.2 us): with both potentials in Python
a return of the flow costs ~13x the compiled one, a section point (a root search on quadratures)
~200x, and threads make it slower, not faster (the GIL passes between them at every call): use
``n_threads=1``.
"""

from __future__ import annotations

import copy
import math
import pickle
from collections.abc import Callable

import numpy as np

from .._core import flow as _core_flow
from .._core.flow import Harmonic, Numerical, Potential, Tan, _CallablePotential
from .._io.records import pickler_stores_code, reduce_record

__all__ = [
    "Potential",
    "Harmonic",
    "Tan",
    "Numerical",
    "CustomPotential",
    "check_potential",
    "POTENTIAL_KINDS",
    "COMPILED",
]

#: The core's registry of compiled potentials, in its order: each kind's name in scene files and
#: plans (``kind``), its class (``cls``), its formula and its parameters (``params``: name, lo, hi)
#: in the constructor's order.
POTENTIAL_KINDS = tuple(_core_flow.POTENTIAL_KINDS)

#: The compiled potential classes, in the registry's order.
COMPILED = tuple(getattr(_core_flow, k.cls) for k in POTENTIAL_KINDS)


# ---------------------------------------------------------------- the compiled potentials' values
# Pickling is the compiled classes' own (bind_potential.cpp: their constructor arguments); these
# add equality by value and the records :func:`hovering.save` writes (no pickle in the file).


def _potential_eq(self, other):
    """Equal to a potential of the same class with the same parameters (for Numerical: an equal base)."""
    if not isinstance(other, Potential):
        return NotImplemented
    return type(self) is type(other) and self.__getstate__() == other.__getstate__()


def _potential_hash(self) -> int:
    """Hash of the class and the parameters (consistent with ``==``)."""
    return hash((type(self), self.__getstate__()))


def _record_fields(*names):
    def to_record(self) -> dict:
        """What :func:`hovering.save` writes: the constructor arguments."""
        return {name: getattr(self, name) for name in names}

    def from_record(cls, record: dict):
        """Inverse of ``_to_record`` (the constructor's checks run again)."""
        return cls(*(record[name] for name in names))

    return to_record, classmethod(from_record)


_FIELDS = [(c, tuple(p.name for p in k.params)) for c, k in zip(COMPILED, POTENTIAL_KINDS)]
for _cls, _names in (*_FIELDS, (Numerical, ("base",))):
    _cls.__eq__, _cls.__hash__ = _potential_eq, _potential_hash
    _cls._to_record, _cls._from_record = _record_fields(*_names)
    # Pickled by the record too (the compiled __setstate__ stays, to read the pickles written before).
    _cls.__reduce__ = reduce_record

# V(0) must vanish to this absolute accuracy: the core measures energies from the minimum.
_V0_TOL = 1e-12
# Relative agreement of dV with a Richardson central difference of V. The difference itself is
# good to ~1e-9 on the sampled points of smooth wells; 1e-6 flags a wrong V' (sign, factor, a
# different potential) without rejecting a V' that is merely rounded differently.
_DV_RTOL = 1e-6


def _sample_points(q_limit: float, extent: float) -> np.ndarray:
    """Points of (-Q, 0) u (0, Q), Q = q_limit (or ``extent`` for an unbounded well): geometric near
    0, where a wrong sign of V' first shows, uniform elsewhere, and none on the edge of a bounded well."""
    Q = q_limit if math.isfinite(q_limit) else extent
    top = 0.999 if math.isfinite(q_limit) else 1.0
    s = np.concatenate([np.geomspace(1e-6, 1e-2, 5), np.linspace(0.02, top, 64)])
    return np.concatenate([-Q * s[::-1], Q * s])


def _value(f: Callable, q: float, what: str, label: str) -> float:
    try:
        r = f(q)
    except Exception as e:  # name the potential and the point, keep the original as the cause
        raise ValueError(f"{label}: {what}({q!r}) raised {type(e).__name__}: {e}") from e
    try:
        v = float(r)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{label}: {what}({q!r}) returned {r!r}, expected a float") from e
    return v


def _check(V: Callable, dV: Callable, q_limit: float, label: str, extent: float) -> None:
    """The checks of :func:`check_potential` on the raw callables (raises ValueError)."""
    v0 = _value(V, 0.0, "V", label)
    if not abs(v0) <= _V0_TOL:
        raise ValueError(f"{label}: V(0) must be 0 (the minimum of the well; |V(0)| <= {_V0_TOL:g}), got {v0!r}")
    q = _sample_points(q_limit, extent)
    vals = np.array([_value(V, float(x), "V", label) for x in q])
    ders = np.array([_value(dV, float(x), "dV", label) for x in q])
    where = "inside the well" if math.isfinite(q_limit) else f"on |q| <= {extent:g} (check_extent)"
    for name, arr in (("V", vals), ("dV", ders)):
        bad = ~np.isfinite(arr)
        if bad.any():
            i = int(np.argmax(bad))
            raise ValueError(
                f"{label}: {name}({q[i]!r}) = {arr[i]!r}; V and V' must be finite {where}, |q| < q_limit = {q_limit!r}"
            )
    sign = q * ders
    if not (sign > 0).all():
        i = int(np.argmax(~(sign > 0)))
        raise ValueError(
            f"{label}: not a single well: q V'(q) must be > 0 for 0 < |q| < q_limit = {q_limit!r}, "
            f"got V'({q[i]!r}) = {ders[i]!r}"
        )
    if not (vals > v0).all():
        i = int(np.argmax(~(vals > v0)))
        raise ValueError(
            f"{label}: not a single well: V(q) must be > V(0) = {v0!r} for q != 0, got V({q[i]!r}) = {vals[i]!r}"
        )
    # V' against V: Richardson central differences at a few points well inside the well. The step
    # starts at 1e-2 |q| and shrinks 4x (truncation error 256x) until the estimate matches dV; only
    # an estimate that has settled (two in a row agree) away from dV is a mismatch, so steep wells
    # (V = exp(q^2) - 1 at q = 9 needs four shrinks) are not rejected for a coarse first step.
    for x in q[(np.abs(q) >= 1e-2 * np.abs(q).max()) & (np.abs(q) <= 0.9 * np.abs(q).max())][::8]:
        x = float(x)
        der = _value(dV, x, "dV", label)
        tol = _DV_RTOL * (abs(der) + abs(_value(V, x, "V", label) / x))

        def cd(step):
            return (_value(V, x + step, "V", label) - _value(V, x - step, "V", label)) / (2 * step)

        d, prev = 1e-2 * abs(x), None
        for _ in range(8):
            est = (4 * cd(0.5 * d) - cd(d)) / 3
            if abs(est - der) <= tol:
                break
            if prev is not None and abs(est - prev) <= tol:
                raise ValueError(
                    f"{label}: dV is not the derivative of V: dV({x!r}) = {der!r}, but V changes "
                    f"at the rate {est!r} there (relative tolerance {_DV_RTOL:g})"
                )
            prev, d = est, 0.25 * d


def check_potential(pot: Potential, check_extent: float = 10.0) -> None:
    """Check that a potential is a single well: ``V(0) = 0``, ``q V'(q) > 0``, finite values, V' = dV/dq.

    V and V' are sampled on 138 points of the well ``0 < |q| < q_limit`` (of ``0 < |q| <=
    check_extent`` when the well is unbounded); V' is compared with central differences of V at a
    few of them. A sample cannot prove convexity between its points, but it catches double wells,
    wrong signs, a V' that belongs to another V, and functions undefined inside the declared well.

    Parameters
    ----------
    pot : Potential
        Any hovering potential (a :class:`hovering.Potential` subclass defined in Python included).
    check_extent : float, optional
        Half-width of the sampled interval when ``pot.q_limit`` is infinite.

    Raises
    ------
    ValueError
        Naming the potential, the offending value and the allowed range.
    """
    if not isinstance(pot, Potential):
        raise ValueError(f"pot must be a hovering potential, got {pot!r}")
    _check(pot.V, pot.dV, _q_limit(pot.q_limit, repr(pot)), repr(pot), _extent(check_extent))


def _q_limit(q_limit, label: str) -> float:
    try:
        if isinstance(q_limit, (bool, str)):
            raise TypeError
        lim = float(q_limit)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{label}: q_limit must be a float > 0 (or math.inf), got {q_limit!r}") from e
    if not lim > 0:
        raise ValueError(f"{label}: q_limit must be > 0 (or math.inf), got {q_limit!r}")
    return lim


def _extent(check_extent) -> float:
    e = float(check_extent)
    if not (math.isfinite(e) and e > 0):
        raise ValueError(f"check_extent must be finite and > 0, got {check_extent!r}")
    return e


class CustomPotential(_CallablePotential):
    """A single-well potential from two Python callables ``V(q)`` and ``V'(q)``.

    Usable wherever a compiled potential is (``StepSystem``, ``Section``, ``onset_parameters``,
    ``tangential_curve``, ...): period, action, energy and angles come from the core's GSL
    quadrature and root finding on V and V'. The callables are checked at construction
    (:func:`check_potential`).

    Parameters
    ----------
    V, dV : callable
        ``float -> float``: the potential, with ``V(0) = 0`` and ``q V'(q) > 0`` for ``q != 0``,
        and its derivative. They may be called from the return map's worker threads (holding the
        GIL), so they must not rely on thread-local state. An exception they raise propagates to
        the caller of the computation; a non-float result is a ``Potential.ReturnError`` (both a
        TypeError and a ValueError, naming the callable), a non-finite one a ValueError (for
        ``|q| < q_limit``; outside the well the integrator rejects the trial step).
    q_limit : float, optional
        Largest ``|q|`` of the well (``math.inf``: unbounded). For a singular well such as
        ``tan^2``, the position of the singularity.
    name : str, optional
        Used in ``repr`` and error messages; default ``"CustomPotential(<V's name>)"``.
    check_extent : float, optional
        Half-width of the interval sampled by the checks when ``q_limit`` is infinite.

    Raises
    ------
    ValueError
        If V or dV is not callable, q_limit is not > 0, ``|V(0)| > 1e-12``, the sampled ``q V'(q)``
        is not > 0 (e.g. a double well), a sampled value is not finite, or dV disagrees with the
        derivative of V; the message names the value and the allowed range.

    Notes
    -----
    It pickles (multiprocessing, Dask) when V and dV do: module-level functions or picklable
    callables for the standard pickler, also lambdas for cloudpickle; otherwise pickling raises
    ``pickle.PicklingError`` naming the callable. It compares equal to a CustomPotential of the same
    callables (``is``), q_limit and name. It cannot be saved to NPZ (:func:`hovering.save` writes no
    code): a ``TypeError`` says so.

    Examples
    --------
    >>> import math, hovering
    >>> quartic = hovering.CustomPotential(lambda q: q**2 / 2 + q**4 / 4, lambda q: q + q**3, name="quartic")
    >>> round(quartic.period(1.0), 10)   # 4 K(k) / (1 + q_max^2)^(1/2), an elliptic integral
    4.5483303981
    """

    def __init__(
        self,
        V: Callable[[float], float],
        dV: Callable[[float], float],
        q_limit: float = math.inf,
        name: str | None = None,
        check_extent: float = 10.0,
    ):
        for what, f in (("V", V), ("dV", dV)):
            if not callable(f):
                raise ValueError(f"{what} must be callable ({what}(q) -> float), got {f!r}")
        if name is None:
            name = f"CustomPotential({getattr(V, '__name__', type(V).__name__)})"
        if not isinstance(name, str):
            raise ValueError(f"name must be a str, got {name!r}")
        lim = _q_limit(q_limit, name)
        _check(V, dV, lim, name, _extent(check_extent))
        super().__init__(V, dV, lim, name)

    # ------------------------------------------------------------------ equality, copying, saving

    def __eq__(self, other):
        """Equal to a CustomPotential of the same class with the same callables (``is``), q_limit and name."""
        if not isinstance(other, Potential):
            return NotImplemented
        return (
            type(self) is type(other)
            and self.V_callable is other.V_callable
            and self.dV_callable is other.dV_callable
            and self.q_limit == other.q_limit
            and self.name == other.name
        )

    def __hash__(self) -> int:
        """Hash of the callables' identities, q_limit and name (consistent with ``==``)."""
        return hash((type(self), id(self.V_callable), id(self.dV_callable), self.q_limit, self.name))

    def __reduce_ex__(self, protocol):
        """Pickle as the callables, q_limit and name (unpickling does not run the checks again).

        The callables are pickled by the pickler in use: the standard one (``pickle``,
        ``multiprocessing``) stores functions by their importable name, so V and dV must be
        module-level functions or picklable callable objects; cloudpickle and dill (Dask) also
        store lambdas and local functions.

        Raises
        ------
        pickle.PicklingError
            Naming this potential and the callable that the standard pickler cannot store.
        """
        V, dV = self.V_callable, self.dV_callable
        if not pickler_stores_code():
            for what, f in (("V", V), ("dV", dV)):
                try:
                    pickle.dumps(f, protocol)
                except Exception as e:
                    raise pickle.PicklingError(
                        f"cannot pickle {self.name}: its {what} = {f!r} cannot be pickled ({type(e).__name__}: {e}); "
                        "pickle stores functions by their importable name: define V and dV at module level (not as "
                        "lambdas or local functions), or pass picklable callables (e.g. functools.partial of "
                        "module-level functions); cloudpickle (Dask's pickler) also stores lambdas"
                    ) from e
        return _restore_custom, (type(self), V, dV, self.q_limit, self.name, dict(self.__dict__))

    def __copy__(self) -> CustomPotential:
        """A new potential with the same callables (no checks run; any callable can be copied)."""
        return _restore_custom(
            type(self), self.V_callable, self.dV_callable, self.q_limit, self.name, dict(self.__dict__)
        )

    def __deepcopy__(self, memo) -> CustomPotential:
        """A new potential with deep copies of the callables (functions are their own deep copies)."""
        V, dV, attrs = copy.deepcopy((self.V_callable, self.dV_callable, dict(self.__dict__)), memo)
        return _restore_custom(type(self), V, dV, self.q_limit, self.name, attrs)

    def _to_record(self) -> dict:
        """Refused: V and dV are Python code, which an NPZ file (written without pickle) cannot hold.

        Raises
        ------
        TypeError
            Always, naming the potential and what to do instead.
        """
        raise TypeError(_NOT_SAVEABLE.format(what=f"{self.name} (a CustomPotential)"))


_NOT_SAVEABLE = (
    "cannot save {what} to NPZ: its V and V' are Python code, which the NPZ format (written without "
    "pickle, so that reading a file never runs code) cannot hold; pickle the object instead (with "
    "module-level V and dV), or save a result without its map, e.g. "
    "dataclasses.replace(result, map=None).save(path)"
)


def _restore_custom(cls, V, dV, q_limit, name, attrs):
    """A ``cls`` (CustomPotential or a subclass) from checked callables, without checking them again."""
    obj = cls.__new__(cls)
    _CallablePotential.__init__(obj, V, dV, q_limit, name)
    obj.__dict__.update(attrs)
    return obj


def _python_potential_record(self) -> dict:
    """Refused: a Potential subclass defined in Python is Python code (see :data:`_NOT_SAVEABLE`)."""
    raise TypeError(_NOT_SAVEABLE.format(what=f"{self!r} (a {type(self).__name__}, a Potential defined in Python)"))


# The base class answers for Python subclasses; the compiled potentials define their own records
# (hovering.flow.system).
Potential._to_record = _python_potential_record
