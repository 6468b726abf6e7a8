"""The figures of this package's scene kinds, one module each (``orbits`` draws the two orbit kinds
of the truncated map), each registered with :func:`hovering.plot.common.draws`.

A figure is a pure function of its kind's result (:mod:`hovering.scenes.kinds` declares the kind).
Every module here is imported, in name order, when this package is: adding a kind's figure is
adding its module, nothing else.
"""

from __future__ import annotations

import importlib
import pkgutil

__all__ = ["MODULES"]

#: The figure modules found here, in the order they were imported.
MODULES = tuple(
    importlib.import_module(f"{__name__}.{m.name}").__name__
    for m in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name)
    if not m.name.startswith("_")
)
