"""NumPy operations as the package's long calls need them on any thread, also while the interpreter exits.

A long call may run on a daemon thread, which CPython ends at exit by a forced unwinding the next time
it takes the GIL (python/src/gil.hpp). Through C and Python frames that is harmless; through a C++
frame that takes the GIL back in a destructor it is std::terminate, an abort of the whole process.
NumPy >= 2.3 finds the distinct values of a numeric array (``np.unique`` without ``return_*``) with
a hash table in C++ that releases the GIL and takes it back in such a destructor
(``np::raii::SaveThreadState``): that is where daemon threads running ``hovering_area`` (its
components) or ``barrier_scan`` (``classify_orbits``' box dimension) aborted as the interpreter
exited (tests/package/test_exit_race.py).
"""

from __future__ import annotations

import numpy as np

__all__ = ["unique"]


def unique(a) -> np.ndarray:
    """The sorted distinct values of ``a`` (flattened), as ``np.unique(a)``, found by sorting.

    Sorting and comparing release and take back the GIL in NumPy's C code only, which a forced
    unwinding passes harmlessly (see the module docstring).

    Parameters
    ----------
    a : array_like
        Values without NaN (integers, in the package's uses).

    Returns
    -------
    numpy.ndarray
        1-D, sorted, each value once.
    """
    s = np.sort(np.asarray(a).ravel())
    if s.size < 2:
        return s
    keep = np.empty(s.size, dtype=bool)
    keep[0] = True
    np.not_equal(s[1:], s[:-1], out=keep[1:])
    return s[keep]
