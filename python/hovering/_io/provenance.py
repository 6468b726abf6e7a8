"""What made a result: versions, build, machine and run settings, recorded beside every output.

One record, built here: :func:`hovering.save` (the NPZ's JSON document), scene results (their JSON
sidecar) and checkpoints (each record) store it, :func:`hovering.show_versions` prints it, and
``hovering_sweep`` writes the same facts of the C++ core (``hovering::build_info``, bound as
``hovering._core.build_info``) in its CSV header, so the build's facts are taken in one place.

Keys, in order: ``hovering`` (package version), ``git`` (commit the core was built from, with
``-dirty`` if the checkout had uncommitted changes; ``"unknown"`` when not built from a checkout),
``python``, ``numpy``, ``scipy`` and ``matplotlib`` (None when not installed), ``compiler``,
``gsl``, ``eigen``, ``sleef`` (the versions the core was compiled against), ``simd_width``
(doubles per SIMD packet: it can change which points a sampled run draws), ``platform``
(system-release-machine), ``hardware_threads``, ``threads`` (core threads of the run: all hardware
threads unless a run says otherwise) and ``seed`` (None where nothing is random).
"""

from __future__ import annotations

import functools
import importlib.metadata
import platform
import sys

import numpy as np

from .._core import build_info as _core_build_info
from .._version import __version__

__all__ = ["provenance", "show_versions"]


def _dist_version(name: str) -> str | None:
    # The installed distribution's metadata: no import (scipy costs ~0.3 s to import).
    try:
        return importlib.metadata.version(name)
    except importlib.metadata.PackageNotFoundError:
        return None


@functools.cache
def _static() -> tuple:
    core = dict(_core_build_info())
    rec = {
        "hovering": __version__,
        "git": core["git"],
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": _dist_version("scipy"),
        "matplotlib": _dist_version("matplotlib"),
        "compiler": core["compiler"],
        "gsl": core["gsl"],
        "eigen": core["eigen"],
        "sleef": core["sleef"],
        "simd_width": core["simd_width"],
        "platform": core["platform"],
        "hardware_threads": core["hardware_threads"],
    }
    return tuple(rec.items())


def provenance(seed: int | None = None, threads: int | None = None) -> dict:
    """The provenance record of a result computed here and now.

    Parameters
    ----------
    seed : int, optional
        The run's random seed (None: nothing random, or not known).
    threads : int, optional
        Core threads the run used (default: the core's default, every hardware thread).

    Returns
    -------
    dict
        JSON-able; the keys listed in :mod:`hovering._provenance`.
    """
    rec = dict(_static())
    rec["threads"] = int(threads) if threads else rec["hardware_threads"]
    rec["seed"] = None if seed is None else int(seed)
    return rec


def show_versions(file=None) -> None:
    """Print the versions and build facts a result of this installation records.

    The same record that :func:`hovering.save`, scene results and checkpoints store (without the
    run's seed); paste it into a bug report.

    Parameters
    ----------
    file : file-like, optional
        Where to print (default ``sys.stdout``).
    """
    rec = provenance()
    del rec["seed"]
    width = max(map(len, rec))
    out = sys.stdout if file is None else file
    print("INSTALLED VERSIONS", file=out)
    print("------------------", file=out)
    for k, v in rec.items():
        print(f"{k:<{width}} : {v}", file=out)
