"""Pickling helpers shared by the Python classes built on compiled ones (maps, potentials).

A Python subclass of a compiled class (``hovering.TruncatedMap`` of ``_core.truncated.TruncatedMap``)
pickles as its class, the compiled part's state (the compiled class's ``__getstate__``: its
constructor arguments) and its instance dict; unpickling creates the instance, rebuilds the
compiled part with the compiled ``__setstate__`` (the constructor's checks run again) and restores
the dict. Nothing is recomputed beyond what the compiled constructor does, so the rebuilt object
computes bit for bit what the original did.
"""

from __future__ import annotations

import pickle
import sys

__all__ = ["pickler_stores_code", "reduce_compiled", "restore_compiled"]


def reduce_compiled(obj, base: type) -> tuple:
    """``__reduce__`` value of ``obj``, an instance of a Python subclass of the compiled class ``base``.

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
    """Inverse of :func:`reduce_compiled`: a ``cls`` instance with ``base``'s state and the attributes ``attrs``.

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
