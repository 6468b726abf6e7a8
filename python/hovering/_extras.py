"""The optional dependencies: which feature needs which, and the one message when one is missing.

numpy (and matplotlib, for the figures) is all installing hovering brings. The rest are extras,
each named after what it is for (from a clone; no package index carries hovering yet, so an
installed wheel takes the packages themselves, e.g. ``pip install xarray``)::

    pip install '.[distributed]'   # Dask: executor= a cluster, a scheduler or dask=True
    pip install '.[xarray]'        # to_xarray() of the results
    pip install '.[pandas]'        # to_pandas() of the tabular results
    pip install '.[progress]'      # tqdm bars (a plain-text bar without it)
    pip install '.[scipy]'         # the scipy reference integrator of the accuracy diagrams
    pip install '.[all]'           # all of them
"""

from __future__ import annotations

import importlib
from types import ModuleType

__all__ = ["EXTRAS", "require"]

#: The extra of pyproject.toml that installs each optional top-level module.
EXTRAS = {
    "distributed": "distributed",
    "dask": "distributed",
    "xarray": "xarray",
    "pandas": "pandas",
    "tqdm": "progress",
    "scipy": "scipy",
}


def require(module: str, feature: str) -> ModuleType:
    """Import an optional dependency, or say which extra installs it.

    Parameters
    ----------
    module : str
        The module to import (``"xarray"``, ``"scipy.integrate"``); its top-level package is one
        of :data:`EXTRAS`.
    feature : str
        What needs it, for the message (``"IterateResult.to_xarray()"``).

    Returns
    -------
    module
        The imported module.

    Raises
    ------
    ImportError
        When it is not installed: naming the feature, ``pip install PACKAGE`` and the extra that
        brings it (``pip install '.[EXTRA]'`` in a clone).
    """
    top = module.split(".")[0]
    try:
        return importlib.import_module(module)
    except ImportError as e:
        raise ImportError(
            f"{feature} needs {top}, an optional dependency of hovering that is not installed: "
            f"pip install {top} (hovering's extra {EXTRAS[top]!r}: pip install '.[{EXTRAS[top]}]' in a clone)"
        ) from e
