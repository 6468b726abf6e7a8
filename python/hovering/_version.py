"""The package's version, written once: CMake's ``project(hovering VERSION ...)``, compiled into the
core (``hovering::build_info``); pyproject.toml reads the same line into the package's metadata.

Read from the metadata, so that ``import hovering`` and ``hovering --version`` load neither the
compiled core nor numpy. The metadata is trusted only when it describes this copy of the package
(its files are these files): a source tree put on ``sys.path`` beside another installed hovering,
or an install that left no metadata, reads the core's own record instead.
"""

from __future__ import annotations

import os
from importlib import metadata

__all__ = ["__version__"]


def _read() -> str:
    try:
        dist = metadata.distribution("hovering")
        here = os.path.realpath(__file__)
        if os.path.realpath(str(dist.locate_file("hovering/_version.py"))) == here and dist.version:
            return str(dist.version)
    except (metadata.PackageNotFoundError, OSError, ValueError):
        pass
    from ._core import build_info  # the build's own record (costs the core's import)

    return str(dict(build_info())["hovering"])


#: The version of this build (PEP 440).
__version__: str = _read()
