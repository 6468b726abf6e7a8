"""The scene kinds of this package, one module each (``orbits`` declares the two orbit kinds of the
truncated map, which share their spec and result).

A kind's module declares its spec (fields with their default, range and choices:
:mod:`hovering.scenes.fields`), its result class, its computation, summary and report, and registers
them (:func:`hovering.scenes.registry.register`); its figure is ``hovering/plot/kinds/<kind>.py``.
Modules whose name starts with ``_`` hold what several kinds share (``_flow``: the ``[system]``,
``[section]``, ``[integrator]``, ``[outputs]`` tables; ``_truncated``: the map's parameters;
``_sweep``: the hovering-area sweep). Every other module here is imported, in name order, when
this package is: adding a kind is adding its module (and its figure's), nothing else.
"""

from __future__ import annotations

import importlib
import pkgutil

__all__ = ["MODULES"]

#: The kind modules found here, in the order they were imported (and registered).
MODULES = tuple(
    importlib.import_module(f"{__name__}.{m.name}").__name__
    for m in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name)
    if not m.name.startswith("_")
)
