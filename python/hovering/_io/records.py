"""Pickling helpers: every class with parameters pickles as its one record.

A map, system, potential, section or curve has one representation of its parameters, its
``_to_record`` / ``_from_record`` pair, which :func:`hovering.save` (NPZ), checkpoint keys
(:func:`hovering._serial.record_key`) and pickle all use: :func:`reduce_record` pickles an object
as its class, its record and the instance attributes the record does not hold; unpickling runs
``_from_record`` (the constructor's checks, nothing measured), so the rebuilt object computes bit
for bit what the original did.

:func:`restore_compiled` reads the pickles written before (a compiled class's ``__setstate__``
state tuple), which stay loadable.
"""

from __future__ import annotations

import pickle
import sys

__all__ = ["pickler_stores_code", "reduce_compiled", "reduce_record", "restore_compiled", "restore_record"]


def reduce_record(obj, extra: dict | None = None) -> tuple:
    """``__reduce__`` value of ``obj`` by its record.

    Parameters
    ----------
    obj : object
        An instance of a class with ``_to_record`` and the classmethod ``_from_record``.
    extra : dict, optional
        Instance attributes the record does not hold (a subclass's own, caches), restored as they were.

    Returns
    -------
    tuple
        ``(restore_record, (type(obj), record, extra))``.
    """
    return restore_record, (type(obj), obj._to_record(), dict(extra or {}))


def restore_record(cls: type, record: dict, attrs: dict):
    """Inverse of :func:`reduce_record`: ``cls._from_record(record)`` with the attributes ``attrs``.

    Parameters
    ----------
    cls : type
        The class to rebuild.
    record : dict
        Its record.
    attrs : dict
        Instance attributes to set afterwards.

    Returns
    -------
    object
    """
    obj = cls._from_record(record)
    if attrs:
        obj.__dict__.update(attrs)
    return obj


def reduce_compiled(obj, base: type) -> tuple:
    """``__reduce__`` value of ``obj``, an instance of a Python subclass of the compiled class ``base``
    (how maps pickled before they pickled by their records; kept for :func:`restore_compiled`'s tests).

    Parameters
    ----------
    obj : object
        The instance.
    base : type
        The compiled class whose ``__getstate__``/``__setstate__`` carry the C++ state.

    Returns
    -------
    tuple
        ``(restore_compiled, (type(obj), base, state, instance dict))``.
    """
    return restore_compiled, (type(obj), base, base.__getstate__(obj), dict(obj.__dict__))


def restore_compiled(cls: type, base: type, state, attrs: dict):
    """Inverse of :func:`reduce_compiled`: a ``cls`` instance with ``base``'s state and the attributes ``attrs``
    (what pickles of maps written before records were their pickles load through).

    Parameters
    ----------
    cls : type
        The Python class to rebuild (a subclass of ``base``).
    base : type
        The compiled class.
    state : tuple
        ``base.__getstate__`` of the original.
    attrs : dict
        The original's instance dict.

    Returns
    -------
    object
    """
    obj = cls.__new__(cls)
    base.__setstate__(obj, state)
    obj.__dict__.update(attrs)
    return obj


# Picklers of the standard library: they store functions by their importable name only.
def _standard_picklers() -> tuple:
    out = [pickle.Pickler, pickle._Pickler]
    reduction = sys.modules.get("multiprocessing.reduction")
    if reduction is not None:
        out.append(reduction.ForkingPickler)
    return tuple(out)


def pickler_stores_code(max_depth: int = 64) -> bool:
    """Whether the pickling in progress is done by a pickler that may store code by value.

    cloudpickle (Dask's pickler) and dill store lambdas and local functions by value, which the
    standard pickler cannot. Such a pickler runs its ``dump`` method in Python, so it is found on
    the call stack: a frame of a method named ``dump`` whose ``self`` is a pickler of another class
    than the standard library's. Without one (``pickle.dumps``, multiprocessing), a callable that the
    standard pickler refuses can be named in a clear error before the pickler fails on it.

    Parameters
    ----------
    max_depth : int, optional
        Frames searched.

    Returns
    -------
    bool
    """
    standard = _standard_picklers()
    frame = sys._getframe(1)
    for _ in range(max_depth):
        if frame is None:
            return False
        if frame.f_code.co_name == "dump":
            owner = frame.f_locals.get("self")
            if isinstance(owner, (pickle.Pickler, pickle._Pickler)) and type(owner) not in standard:
                return True
        frame = frame.f_back
    return False
