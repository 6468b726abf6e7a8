"""Argument checks shared by every public call: a bad value is a ValueError naming the parameter,
the value and what is allowed, raised before any work (README: "Outcomes are values, bad input is an
error"). The lowest layer of the package: it imports nothing of hovering but the compiled core.
"""

from __future__ import annotations

import math
import numbers
import operator
import os

import numpy as np

__all__ = [
    "MAX_ANGLE",
    "MAX_MODES",
    "real_number",
    "integer",
    "flag",
    "require_type",
    "is_choice",
    "thread_count",
    "MAX_SEED",
    "random_seed",
    "forcing_array",
    "BYTES_PER_POINT",
    "check_points",
    "point_pair",
    "real_array",
    "require_finite",
    "require_angles",
    "physical_memory",
    "check_memory",
    "loaded_array",
    "loaded_range",
    "loaded_codes",
]

#: Largest |angle| that can be wrapped to [-pi, pi) accurately (2 pi floor(x / 2 pi) loses a turn
#: beyond ~1e15; 1e6 keeps the wrapping error below 1e-9).
MAX_ANGLE = 1e6


def real_number(name: str, value, lo=None, lo_open=True, hi=None, hi_open=True) -> float:
    """A finite real number (not a bool, string or complex) in an optional interval, or a ValueError naming it.

    Parameters
    ----------
    name : str
        The parameter's name (for the message).
    value : object
        What was passed.
    lo, hi : float, optional
        Interval ends (None: unbounded).
    lo_open, hi_open : bool, optional
        Whether the ends are excluded.

    Returns
    -------
    float
    """
    if type(value) is float:  # the common case, without the ABC checks of _real_value
        v = value
    else:
        v = _real_value(name, value)
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite, got {v}")
    if (lo is not None and (v <= lo if lo_open else v < lo)) or (hi is not None and (v >= hi if hi_open else v > hi)):
        rng = f"{'(' if lo_open else '['}{'-inf' if lo is None else lo}, {'inf' if hi is None else hi}{')' if hi_open else ']'}"
        raise ValueError(f"{name} must lie in {rng}, got {v}")
    return v


def _real_value(name: str, value) -> float:
    """float(value) for any real number type (numpy scalars, 0-d arrays, Fractions), else a ValueError."""
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf":
        value = value.item()  # a 0-d array is a number, as numpy scalars are
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise ValueError(f"{name} must be a real number, got {_short(value)}")
    try:
        return float(value)
    except OverflowError:
        raise ValueError(f"{name} must be a real number within the range of a double, got {_short(value)}") from None


def integer(name: str, value, lo: int, hi: int) -> int:
    """An integer (not a bool, float or string) in [lo, hi], or a ValueError naming it and the range."""
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iu":
        value = value.item()
    try:
        v = operator.index(value)
    except TypeError:
        raise ValueError(f"{name} must be an integer in [{lo}, {hi}], got {value!r}") from None
    if isinstance(value, (bool, np.bool_)) or not lo <= v <= hi:
        raise ValueError(f"{name} must be an integer in [{lo}, {hi}], got {value!r}")
    return v


def flag(name: str, value) -> bool:
    """A True/False argument (not 'yes', None or 1), or a ValueError naming it."""
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be True or False, got {_short(value)}")
    return bool(value)


def require_type(name: str, value, cls, what: str):
    """``value`` if it is an instance of cls, else a ValueError naming the parameter and what it must be."""
    if not isinstance(value, cls):
        raise ValueError(f"{name} must be {what}, got {_short(value)}")
    return value


def is_choice(value, choices) -> bool:
    """Whether value is one of the string choices (False, not an error, for arrays and other types)."""
    return isinstance(value, str) and value in choices


#: Most worker threads a call takes (the core's kMaxThreads).
MAX_THREADS = 4096


def thread_count(value) -> int:
    """The ``n_threads`` argument every parallel call takes: an integer in [0, 4096], 0 = all cores."""
    try:
        v = operator.index(value)
    except TypeError:
        v = None
    if v is None or isinstance(value, (bool, np.bool_)) or not 0 <= v <= MAX_THREADS:
        raise ValueError(f"n_threads must be an integer in [0, {MAX_THREADS}] (0 = all cores), got {value!r}")
    return v


#: Largest seed: what the core's numpy-compatible generator, a scene file and a checkpoint key hold
#: (a non-negative int64).
MAX_SEED = 2**63 - 1


def random_seed(rng, name: str = "rng") -> int:
    """The integer seed of a run from its ``rng`` argument (SPEC 7: None, an int or a Generator).

    Every random draw of the package starts from one integer seed: the core draws
    ``numpy.random.default_rng(seed)``'s stream itself (and jumps it ahead for each piece of a
    distributed run), and results, checkpoints and provenance record that integer. So an int is
    the seed as it is; a :class:`numpy.random.Generator` gives one, drawn from it once (the
    Generator advances; the result records the seed drawn, which reproduces the run); None draws
    one from fresh OS entropy (``numpy.random.default_rng()``), also recorded.

    Parameters
    ----------
    rng : None, int or numpy.random.Generator
        The argument as given.
    name : str, optional
        The parameter's name (for the message).

    Returns
    -------
    int
        The seed, in [0, :data:`MAX_SEED`].

    Raises
    ------
    TypeError
        For anything else (a float, a string, a bool, a legacy ``RandomState``, a ``SeedSequence``
        or a bit generator), naming the value and what is allowed.
    ValueError
        For an integer outside [0, MAX_SEED], naming it and the range.
    """
    if rng is None or isinstance(rng, np.random.Generator):
        gen = np.random.default_rng() if rng is None else rng
        return int(gen.integers(0, MAX_SEED, endpoint=True))
    if isinstance(rng, np.ndarray) and rng.ndim == 0 and rng.dtype.kind in "iu":
        rng = rng.item()
    try:
        v = None if isinstance(rng, (bool, np.bool_)) else operator.index(rng)
    except TypeError:
        v = None
    if v is None:
        raise TypeError(
            f"{name} must be None, an integer seed in [0, {MAX_SEED}] or a numpy.random.Generator "
            f"(numpy.random.default_rng(seed)), got {' '.join(_short(rng).split())} of type {type(rng).__name__}"
        )
    if not 0 <= v <= MAX_SEED:
        raise ValueError(f"{name} must be an integer seed in [0, {MAX_SEED}] (or a numpy.random.Generator), got {v}")
    return v


#: Most sine coefficients of a forcing f: the theory's cost grows with each (1000 took 20 s) and the
#: measured f of the flow needs ~8.
MAX_MODES = 64


def forcing_array(value) -> np.ndarray:
    """Sine coefficients ``b_1, b_2, ...`` of a forcing: 1 to MAX_MODES finite real numbers."""
    if isinstance(value, str):
        raise ValueError(f"forcing must be a sequence of sine coefficients, got {value!r}")
    b = np.atleast_1d(real_array("forcing", value))
    if b.ndim != 1 or not 1 <= b.size <= MAX_MODES:
        raise ValueError(f"forcing must be a 1-D sequence of 1 to {MAX_MODES} sine coefficients, got shape {b.shape}")
    require_finite("forcing", b)
    return b


#: Memory one point of a call on many points takes, counted at most: its two coordinates as given
#: and as the core reads them (C-ordered copies), its image, region and status (a call that also
#: records orbits checks those: :func:`check_memory`).
BYTES_PER_POINT = 64


def check_points(names: tuple, shapes: tuple) -> tuple:
    """The shape arrays of ``shapes`` broadcast to, refused before anything is allocated when its
    points would not fit in half of this machine's memory (at :data:`BYTES_PER_POINT` each).

    Broadcasting is free (views), but the copies a call makes of its points are not: an (n, 1) and
    a (1, n) array are n^2 points.

    Parameters
    ----------
    names : tuple of str
        The arguments' names, for the message.
    shapes : tuple of tuple
        Their shapes.

    Returns
    -------
    tuple
        The broadcast shape.

    Raises
    ------
    ValueError
        For shapes that do not broadcast, or too many points (naming the shapes, the count and the
        largest count allowed).
    """
    try:
        # Equal shapes (the common case) broadcast to themselves.
        shape = shapes[0] if len(set(shapes)) == 1 else np.broadcast_shapes(*shapes)
    except ValueError:
        raise ValueError(
            f"{' and '.join(names)} must have broadcastable shapes, got {' and '.join(str(s) for s in shapes)}"
        ) from None
    n = math.prod(shape)
    most = physical_memory() // 2 // BYTES_PER_POINT
    if n > most:
        given = " and ".join(f"{a} (shape {s})" for a, s in zip(names, shapes))
        raise ValueError(
            f"{given} broadcast to {n} points; allowed: at most {most} (half of this machine's memory at "
            f"{BYTES_PER_POINT} bytes a point): pass fewer points per call"
        )
    return shape


#: Exact types of a number a one-point fast path takes as it is (bools and other types, and
#: anything non-finite or out of range, take the checked array path, which names what is wrong).
_PLAIN = (float, int, np.float64)
_DBL_MAX = 1.7976931348623157e308


def plain_point(phi, K) -> bool:
    """Whether (phi, K) is one point that needs no array checks: each a Python float or int or a
    NumPy float64 (not a bool), K finite, phi a finite angle with ``|phi| <= MAX_ANGLE``.

    The one-point fast paths (``step`` of both models, ``Section.return_map``) take such a point
    straight to the core; everything else goes through :func:`point_pair`, whose messages name the
    offending value. Comparisons, not ``math.isfinite``: a huge int compares exactly (no overflow).

    Parameters
    ----------
    phi, K : object
        What was passed.

    Returns
    -------
    bool
    """
    return type(phi) in _PLAIN and type(K) in _PLAIN and -MAX_ANGLE <= phi <= MAX_ANGLE and -_DBL_MAX <= K <= _DBL_MAX


def point_pair(phi, K, who: str = "", names=("phi", "K")) -> tuple:
    """Points (phi, K) of a map: real, finite, |phi| <= 1e6, broadcast together (C-ordered); and
    whether both were scalars. Messages name ``who: phi`` (or the given names, e.g. phi0, K0).
    The broadcast size is checked (:func:`check_points`) before the copies are made."""
    if plain_point(phi, K):  # one plain point: nothing to check or broadcast
        return np.array(float(phi)), np.array(float(K)), True
    na, nb = (f"{who}: {n}" if who else n for n in names)
    scalar = np.ndim(phi) == 0 and np.ndim(K) == 0
    p, k = real_array(na, phi), real_array(nb, K)  # type errors first, named
    require_angles(na, p)
    require_finite(nb, k)
    try:
        check_points(tuple(names), (p.shape, k.shape))
    except ValueError as e:
        raise ValueError(f"{who}: {e}" if who else str(e)) from None
    if p.shape != k.shape:
        p, k = np.broadcast_arrays(p, k)
    # np.ascontiguousarray would turn 0-d into 1-d; the bindings copy non-contiguous views themselves.
    return np.asarray(p, order="C"), np.asarray(k, order="C"), scalar


def real_array(name: str, value) -> np.ndarray:
    """``value`` as a float array; a ValueError naming it for strings, objects, booleans or complex numbers."""
    try:
        a = np.asarray(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be real numbers, got {value!r}") from None
    if a.dtype.kind not in "iuf":
        raise ValueError(f"{name} must be real numbers, got dtype {a.dtype} ({_short(value)})")
    return a.astype(float, copy=False)


def require_finite(name: str, a) -> None:
    """Raise a ValueError naming the first non-finite entry of ``a``."""
    a = np.asarray(a)
    if a.dtype.kind in "iub" or np.isfinite(a).all():  # one pass where all is well
        return
    bad = ~np.isfinite(a)
    if bad.any():
        i = np.unravel_index(int(np.argmax(bad)), a.shape) if a.ndim else ()
        raise ValueError(f"{_entry(name, i)} must be finite, got {a[i]}")


def require_angles(name: str, a) -> None:
    """Raise unless every entry is a finite angle that can be wrapped accurately (|x| <= MAX_ANGLE)."""
    a = np.asarray(a)
    if a.size and a.dtype.kind == "f":
        lo, hi = a.min(), a.max()
        if -MAX_ANGLE <= lo and hi <= MAX_ANGLE:  # finite angles in range (NaN fails both): done
            return
    require_finite(name, a)
    if a.size and np.max(np.abs(a)) > MAX_ANGLE:
        i = np.unravel_index(int(np.argmax(np.abs(a.ravel()) > MAX_ANGLE)), a.shape)
        raise ValueError(
            f"{_entry(name, i)} must be an angle in [-1e6, 1e6] (larger ones cannot be wrapped to "
            f"[-pi, pi) accurately in double precision), got {a[i]}"
        )


_MEMORY: list = []  # physical_memory(), asked once (two system calls a call otherwise)


def physical_memory() -> int:
    """Bytes of physical memory of this machine (64 GiB where the system does not say)."""
    if not _MEMORY:
        try:
            _MEMORY.append(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
        except (ValueError, OSError, AttributeError):
            _MEMORY.append(2**36)
    return _MEMORY[0]


def check_memory(what: str, nbytes: int) -> None:
    """Refuse, before any work, a result that would need more than half of this machine's memory."""
    total = physical_memory()
    if nbytes > total // 2:
        raise ValueError(
            f"{what} needs {nbytes / 2**30:.3g} GiB, more than half of this machine's "
            f"{total / 2**30:.3g} GiB: record less, or fewer orbits or steps per call"
        )


# ------------------------------------------------------------------------------------------------
# Arrays read from a file (untrusted): a result's ``_validate_loaded`` checks each against what the
# computation that makes it could return, before anything uses it.

_KIND_NAMES = {"b": "booleans", "i": "integers", "u": "integers", "f": "floats"}


def loaded_array(name: str, a, kinds: str, shape: tuple) -> np.ndarray:
    """``a`` if it is an array of ``shape`` whose dtype is of ``kinds``, else a ValueError naming it.

    Parameters
    ----------
    name : str
        The field, for the message.
    a : object
        The field's value.
    kinds : str
        Allowed numpy dtype kinds (``"f"``: floats, ``"iu"``: integers, ``"b"``: bools).
    shape : tuple
        Its shape; an entry None matches any length.

    Returns
    -------
    ndarray

    Raises
    ------
    ValueError
        Naming the field, the shape and dtype required and those it has.
    """
    if (
        not isinstance(a, np.ndarray)
        or a.dtype.kind not in kinds
        or a.ndim != len(shape)
        or any(want is not None and got != want for got, want in zip(a.shape, shape))
    ):
        what = " or ".join(dict.fromkeys(_KIND_NAMES[k] for k in kinds))
        want = "(" + ", ".join("any" if d is None else str(d) for d in shape) + ("," if len(shape) == 1 else "") + ")"
        got = f"shape {a.shape}, dtype {a.dtype}" if isinstance(a, np.ndarray) else _short(a)
        raise ValueError(f"{name} must be an array of {what} of shape {want}, got {got}")
    return a


def loaded_range(name: str, a: np.ndarray, lo: int, hi: int) -> None:
    """Raise a ValueError naming the first entry of the integer array ``a`` outside ``[lo, hi]``.

    Parameters
    ----------
    name : str
        The field, for the message.
    a : ndarray
        Integers (checked by :func:`loaded_array`).
    lo, hi : int
        The allowed range.
    """
    if a.size and not (lo <= a.min() and a.max() <= hi):
        i = np.unravel_index(int(np.argmax((a < lo) | (a > hi))), a.shape)
        raise ValueError(f"{_entry(name, i)} = {a[i]} is out of range; allowed: [{lo}, {hi}]")


def loaded_codes(name: str, a: np.ndarray, enum) -> None:
    """Raise a ValueError naming the first entry of the integer array ``a`` that is no code of ``enum``.

    Parameters
    ----------
    name : str
        The field, for the message.
    a : ndarray
        Integers (checked by :func:`loaded_array`).
    enum : enum.IntEnum
        The codes' enum (:class:`hovering.Status`, :class:`hovering.Region`, ...): its members are
        the allowed values.
    """
    bad = ~np.isin(a, [int(m) for m in enum])
    if bad.any():
        i = np.unravel_index(int(np.argmax(bad)), a.shape)
        allowed = ", ".join(f"{m.name} ({int(m)})" for m in enum)
        raise ValueError(f"{_entry(name, i)} = {a[i]} is not a {enum.__name__}; allowed: {allowed}")


def _entry(name: str, index: tuple) -> str:
    """``name[i]`` (or ``name[i, j]``, or ``name`` for a scalar): the entry a message is about."""
    return f"{name}[{', '.join(str(int(k)) for k in index)}]" if index else name


def _short(value) -> str:
    r = repr(value)
    return r if len(r) <= 60 else r[:57] + "..."
