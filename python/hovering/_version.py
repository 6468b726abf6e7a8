"""The package's version, written once: CMake's ``project(hovering VERSION ...)``, compiled into the
core (``hovering::build_info``); pyproject.toml reads the same line."""

from ._core import build_info

__all__ = ["__version__"]

#: The version of this build (PEP 440).
__version__: str = str(dict(build_info())["hovering"])
