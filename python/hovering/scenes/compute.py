"""Scene spec -> typed result: the only place a scene simulates anything.

Each kind computes exactly what its figure and report show (its ``compute(spec, ctx)``, declared in
:mod:`hovering.scenes.kinds`): orbits with the records the figure colours by, the lines drawn
under them (L1, L2, corner curves, the leading-order curve), zoom windows, theory curves. Drawing
(:mod:`hovering.plot`) never computes. Flow scenes build their system from the scene's own
``[system]``, ``[section]``, ``[integrator]`` and ``[outputs]`` tables, so what a scene does not
name is not simulated: geometry "none" has no wall events, eps = 0 no coupling, no "regions" no
crossing bookkeeping, no "trajectory" no dense output.

:func:`compute` is the same for every kind: it checks the scene and where its points run, times the
kind's computation and hands it a :class:`~hovering.scenes.base.Context`.
"""

from __future__ import annotations

import logging
import os
import time

from .._progress import check_progress
from .._version import __version__
from ..parallel.executor import from_old_arguments
from . import kinds, registry  # noqa: F401 (kinds: every kind of the package registered)
from .base import QUICK_FACTOR, Context, SceneResult, SceneSpec, scaled
from .kinds._flow import flow_geometry
from .kinds._sweep import run_point
from .kinds._truncated import leading_curve, map_geometry
from .kinds.orbits import hovering_orbits, special_starts, zoom_window_critical, zoom_window_islands
from .kinds.wall_section import _circle_boundaries  # noqa: F401 (its tests read it here)

__all__ = [
    "compute",
    "map_geometry",
    "flow_geometry",
    "zoom_window_critical",
    "zoom_window_islands",
    "leading_curve",
    "special_starts",
    "hovering_orbits",
    "scaled",
    "scene_map",
    "run_point",
]

_log = logging.getLogger(__name__)


def scene_map(scene: SceneSpec):
    """The map a scene is about: an orbit scene's first panel's, a hovering-area scene's first
    series at its first eps, a flow scene's :class:`~hovering.FlowMap` (its system, section and
    integrator; a ``tangent_tori`` scene's in section coordinates): its kind's
    :attr:`~hovering.scenes.registry.Kind.scene_map`.

    Parameters
    ----------
    scene : SceneSpec
        A validated scene.

    Returns
    -------
    TruncatedMap or FlowMap

    Raises
    ------
    ValueError
        For a kind that defines no map.
    """
    kind = registry.get(scene.kind)
    if kind.scene_map is None:
        raise ValueError(f"scene {scene.name!r} defines no map")
    return kind.scene_map(scene)


def compute(
    scene: SceneSpec,
    quick: bool = False,
    progress=False,
    checkpoint: os.PathLike | None = None,
    workers: int | None = None,
    client=None,
    scheduler: str | None = None,
    dask: bool = False,
    *,
    executor=None,
) -> SceneResult:
    """Run a scene's simulation and return its typed result (nothing is drawn or written).

    Parameters
    ----------
    scene : SceneSpec
        From :func:`hovering.scenes.load_scene`.
    quick : bool, optional
        Divide iterate counts (and samples) by :data:`QUICK_FACTOR` for a fast check.
    progress : bool or callable, optional
        Progress bars on stderr for the long computations (see :mod:`hovering._progress`).
    checkpoint : path-like, optional
        Sweep scenes (``hovering_area``, ``flow_hovering_area``): the JSON-lines file every
        finished point is written to at once (default: next to the scene's output).
    workers, client, scheduler, dask : optional
        Deprecated (removed in 0.4.0): the fields of ``executor=Executor(...)``; each warns.
    executor : None, int, str, distributed.Client or hovering.parallel.Executor, optional
        Sweep scenes: run the points as pieces on local worker threads (``int``), a Dask
        scheduler (address), a Dask client, or as a :class:`~hovering.parallel.Executor` says (a Dask
        LocalCluster); each point is checkpointed as it arrives and the result is the one-process
        result. Other scenes: ignored (they are one computation). A scene's pieces are its points and
        its checkpoint is ``checkpoint``: an Executor's ``pieces`` and ``checkpoint`` are refused.

    Returns
    -------
    SceneResult
        The kind's result type, with ``meta`` (version, quick, timings).
    """

    if not isinstance(scene, SceneSpec):
        raise ValueError(f"scene must be a scene spec from hovering.scenes.load_scene, got {type(scene).__name__}")
    progress = check_progress(progress)
    meta = dict(version=__version__, quick=bool(quick), kind=scene.kind, name=scene.name, timings={})
    t0 = time.perf_counter()
    _log.info("scene %s: %s%s", scene.name, scene.kind, f" (quick: counts / {QUICK_FACTOR})" if quick else "")
    ck = checkpoint if checkpoint is not None else scene.output.with_suffix(".sweep.jsonl")
    where = from_old_arguments(
        "compute",
        executor,
        dict(workers=workers, client=client, scheduler=scheduler, dask=dask),
        allowed=("workers", "client", "scheduler", "dask"),
    )
    if where is not None and (where.pieces is not None or where.checkpoint is not None):
        raise ValueError(
            "compute: a scene's points are its pieces and checkpoint= its checkpoint; give an Executor "
            "without pieces and checkpoint"
        )
    try:
        kind = registry.get(scene.kind)
    except ValueError:
        raise ValueError(f"no computation for scene kind {scene.kind!r}") from None
    out = kind.compute(scene, Context(quick=bool(quick), progress=progress, meta=meta, checkpoint=ck, executor=where))
    meta["timings"]["total"] = time.perf_counter() - t0
    _log.info("scene %s: computed in %.1f s", scene.name, meta["timings"]["total"])
    return out
