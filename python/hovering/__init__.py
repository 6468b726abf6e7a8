"""hovering: a simulator for Hamiltonian impact systems near the onset of impacts.

Two models of the return map of the perturbed oscillators-step system of Pazi, Zobova and
Rom-Kedar, "Hovering Sets in Near Pseudo-Integrable Hamiltonian Impact Systems", with one interface:

* :mod:`hovering.truncated`: the truncated near-tangency map F_eps (eq:truncatedmap) and the
  general family F_{eps1,eps2}, on a multi-threaded SIMD C++ core, and their theory;
* :mod:`hovering.flow`: the physical system (potentials, step, Sigma_h) and its impact flow;
* :mod:`hovering.normal`: the bridge: normal coordinates (phi, K) and :class:`FlowMap`, the flow's
  return map as a map you iterate;
* :mod:`hovering.analysis`: rotation numbers, hovering sets and critical curves of any of them.

Every map, system, potential and result pickles (multiprocessing, Dask); results, maps and
systems also save to NPZ without pickle (``result.save(path)``, :func:`save`, :func:`load`).

>>> import hovering
>>> m = hovering.TruncatedMap(eps=0.3, Omega0=hovering.OMEGA_G, theta_w=3 * 3.141592653589793 / 4)
>>> res = m.iterate([m.L1(0.0)], [0.0], 1000, record=("rotation",))
"""

from __future__ import annotations

import logging as _logging
import sys as _sys
import types as _types
from typing import TYPE_CHECKING

from ._deprecated import install as _install_old_paths
from ._version import __version__ as __version__

if TYPE_CHECKING:  # what type checkers and editors see; at run time each name loads at its first use (__getattr__)
    from ._api import *  # noqa: F403

_install_old_paths()  # the old module paths (hovering.geometry, ...): a table in _deprecated, no files

# A library's logger: records go where the application sends them (the command line's -v), and
# nowhere by default (no "No handlers" fallback printing warnings on stderr).
_logging.getLogger(__name__).addHandler(_logging.NullHandler())


def simd_width() -> int:
    """Doubles per SIMD packet of the truncated map's lane kernel selected for this CPU.

    A portable build (the default, and every wheel) holds the kernel for SSE2, AVX2 and AVX-512 and
    selects at run time the widest this CPU runs; ``HOVERING_SIMD=sse2|avx2|avx512|auto`` set
    before the import forces one (a level this CPU does not run is a ValueError at the first use
    of a kernel, before any computation; ``import hovering`` alone loads no core). A
    build with ``HOVERING_NATIVE=ON`` has the one kernel of the machine it was built on.

    Returns
    -------
    int
        8 (AVX-512), 4 (AVX2) or 2 (SSE2); another platform's vector width, or 1 without SIMD.
    """
    from ._core import truncated

    return truncated.simd_width()


# The public names: every name python/hovering/_api.py imports (the one list; type checkers read
# it through the TYPE_CHECKING import above), plus these defined or kept here.
_OWN = ("__version__", "simd_width", "geometry")

#: {public name: (module, attribute)}, read from _api.py's imports at the first use of a name.
_PUBLIC: dict | None = None


def _public() -> dict:
    """The public API's table, from the imports of :mod:`hovering._api` (parsed, not run: each name
    loads its own module at its first use, and nothing else)."""
    global _PUBLIC
    if _PUBLIC is None:
        import ast
        import os

        path = os.path.join(os.path.dirname(__file__), "_api.py")
        with open(path, encoding="utf-8") as f:
            tree = ast.parse(f.read(), path)
        table = {}
        for node in tree.body:
            if isinstance(node, ast.ImportFrom) and node.level == 1:
                module = f"{__name__}.{node.module}" if node.module else __name__
                for a in node.names:
                    table[a.asname or a.name] = (module, a.name)
        _PUBLIC = table
    return _PUBLIC


def _resolve(module: str, attr: str):
    """``module.attr``, importing only what holds it (a submodule of the package is itself the value)."""
    import importlib

    if module == __name__:
        return importlib.import_module(f"{__name__}.{attr}")
    try:
        mod = importlib.import_module(module)
    except ModuleNotFoundError:  # a submodule of the compiled core (hovering._core.truncated)
        parent, _, child = module.rpartition(".")
        mod = getattr(importlib.import_module(parent), child)
    return getattr(mod, attr)


def __getattr__(name: str):
    import importlib

    if name == "__all__":
        value = [*_OWN[:2], *_public(), *_OWN[2:]]
        globals()["__all__"] = value
        return value
    if name.startswith("__") and name.endswith("__"):  # Python's probes, not names of ours
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    if name in _public():
        # Only the module that holds the name (and what it imports): hovering.TruncatedMap loads
        # the truncated map, not the analyses or the diagnostics.
        value = _resolve(*_public()[name])
        globals()[name] = value
        return value
    # Any other submodule is imported alone (scenes, plot, pipeline; an old path, which
    # hovering._deprecated's finder serves): the package's own modules ask for theirs this way too.
    import importlib.util

    if name.isidentifier() and importlib.util.find_spec(f"{__name__}.{name}") is not None:
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list:
    return sorted(set(globals()) | set(__getattr__("__all__")))


#: Public functions named as the submodule that holds them: the name is the function.
_FUNCTION_MODULES = ("explore",)


class _Package(_types.ModuleType):
    """The package's module type. Importing a submodule sets it as its package's attribute; for
    ``hovering.explore`` (the function, in the module hovering.explore) the function is kept, as
    the eager ``from .explore import explore`` kept it, whenever the module is first imported."""

    def __setattr__(self, name: str, value) -> None:
        if name in _FUNCTION_MODULES and isinstance(value, _types.ModuleType) and hasattr(value, name):
            value = getattr(value, name)
        super().__setattr__(name, value)


_sys.modules[__name__].__class__ = _Package
