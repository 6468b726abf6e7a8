"""Scenes: one TOML file per figure, validated, computed, saved and drawn, arrows forward only.

::

    TOML --load_scene--> spec (one frozen class per kind) --compute--> typed result
         --save--> NPZ + JSON (scene, parameters, version, timings)
         --render--> Figure (pure function of the result)  /  --summarize--> text report

A scene names its effects; nothing else is simulated. Each kind is one declaration,
``hovering/scenes/kinds/<kind>.py`` (its keys with their defaults, ranges and choices, its
computation, result, summary and report) with its figure in ``hovering/plot/kinds/<kind>.py``;
:data:`KINDS` lists them and ``registry.get(kind).doc`` says what each draws (the truncated map's
orbits, critical curves and |HOV|; the flow's return map beside its model, |HOV| of the flow and
its models, the paper's figures of the tangent tori, of Sigma_h, of the corner and the wall
section; the impact zone).

Flow scenes carry ``[system]`` (potentials ``harmonic`` / ``tan``, ``coupling`` = ``"bilinear"``,
``"none"`` or terms ``[[c, i, j], ...]``, ``eps``, ``qw1``, ``qw2``, ``geometry`` none / wall /
step), ``[section]`` (``h``), ``[integrator]`` (``stepper``, ``rtol``, ``atol``) and
``[outputs]`` (``record``: what is recorded; ``trajectory_dt``). See ``examples/scenes``.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from .._deprecated import moved_module
from . import registry
from .compute import compute
from .report import format_summary
from .results import SceneResult, load_result, summarize
from .schema import MAX_PANELS, MAX_SCENE_BYTES, MAX_SERIES_POINTS, load_scene, parse_scene
from .spec import (
    FLOW_KINDS,
    KINDS,
    QUICK_FACTOR,
    SPECIAL_ORBITS,
    TRUNCATED_KINDS,
    CriticalSpec,
    MapSpec,
    OrbitSpec,
    PanelSpec,
    Scene,
    SceneSpec,
    SeriesSpec,
    ZoomSpec,
)

#: The kinds that checkpoint their points (``<output>.sweep.jsonl``): those with a sweep plan.
SWEEP_KINDS = tuple(k for k in KINDS if registry.get(k).sweep)

__all__ = [
    "KINDS",
    "TRUNCATED_KINDS",
    "FLOW_KINDS",
    "SPECIAL_ORBITS",
    "QUICK_FACTOR",
    "MAX_PANELS",
    "MAX_SERIES_POINTS",
    "MAX_SCENE_BYTES",
    "MapSpec",
    "OrbitSpec",
    "CriticalSpec",
    "ZoomSpec",
    "PanelSpec",
    "SeriesSpec",
    "Scene",
    "SceneSpec",
    "SceneResult",
    "load_scene",
    "parse_scene",
    "compute",
    "load_result",
    "summarize",
    "format_summary",
    "packaged_scene",
]


def packaged_scene(name: str) -> Path:
    """Path of a scene file shipped with the package (``"demo"``).

    Parameters
    ----------
    name : str
        The scene's name.

    Returns
    -------
    Path
    """
    p = resources.files(__name__).joinpath("data", f"{name}.toml")
    if not p.is_file():
        raise ValueError(f"no packaged scene {name!r}; available: demo")
    return Path(str(p))


# Computing and drawing are joined in hovering.pipeline, above both; the old names warn.
__getattr__ = moved_module(__name__, "hovering.pipeline")
