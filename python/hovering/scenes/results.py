"""Typed results of scenes: everything a figure or a report shows, and nothing else.

Each result holds its scene spec, the computed arrays and numbers, and ``meta`` (version, quick
run, timings). Results save to NPZ + JSON without pickle (:meth:`SceneResult.save`,
:func:`load_result`) and a figure is a pure function of them (:mod:`hovering.plot`), so
``python -m hovering redraw RESULT.npz`` redraws any figure without computing.

Each kind's result class is declared in its module (:mod:`hovering.scenes.kinds`), what every
result has in :mod:`hovering.scenes.base`; this module is where they are all found by name (the
name files give them) and where a saved result is read back.
"""

from __future__ import annotations

import os

from .._io import serial as _serial
from .base import SIDECAR_FORMAT, Geometry, OrbitSet, SceneResult, jsonable, summarize  # noqa: F401
from .kinds.corner_directions import CornerDirectionsResult, CornerTrajectory
from .kinds.flow_hovering_area import FlowHoveringResult
from .kinds.flow_portrait import FlowPortraitResult
from .kinds.ftle_field import FTLEResult
from .kinds.hovering_area import HoveringAreaResult, SeriesResult
from .kinds.impact_zone import ImpactZoneResult, ZoneStudy
from .kinds.orbits import OrbitPanelResult, OrbitSceneResult, ZoomPanelResult
from .kinds.periodic_manifolds import PeriodicManifoldsResult
from .kinds.residue_vs_eps import ResidueResult
from .kinds.sigma_structure import SigmaStructureResult
from .kinds.tangent_tori import TangentToriResult, TorusResult
from .kinds.wall_section import WallSectionResult, WallSegment
from .kinds.wall_tangency import WallPoint, WallTangencyResult
from .schema import check_spec

__all__ = [
    "Geometry",
    "OrbitSet",
    "OrbitPanelResult",
    "ZoomPanelResult",
    "SeriesResult",
    "TorusResult",
    "SceneResult",
    "OrbitSceneResult",
    "HoveringAreaResult",
    "FlowPortraitResult",
    "FlowHoveringResult",
    "TangentToriResult",
    "SigmaStructureResult",
    "CornerTrajectory",
    "CornerDirectionsResult",
    "WallPoint",
    "WallTangencyResult",
    "WallSegment",
    "WallSectionResult",
    "ZoneStudy",
    "ImpactZoneResult",
    "FTLEResult",
    "PeriodicManifoldsResult",
    "ResidueResult",
    "load_result",
    "jsonable",
]


def load_result(path: os.PathLike) -> SceneResult:
    """Read a scene result written by :meth:`SceneResult.save`.

    Parameters
    ----------
    path : path-like
        The ``.npz`` file.

    Returns
    -------
    SceneResult

    Raises
    ------
    ValueError
        If the file is not a scene result of this package, or its scene is not one a scene file
        can give (the schema's checks, :func:`hovering.scenes.schema.check_spec`: naming the
        file and the field).
    """
    obj = _serial.load(path)
    if not isinstance(obj, SceneResult):
        raise ValueError(
            f"{os.fspath(path)} holds a {type(obj).__name__}, not a scene result "
            "(written by `python -m hovering scene`)"
        )
    # The loader runs the schema's checks on the scene (the spec, a layer below the schema, checks
    # only its own bounds as it is rebuilt).
    try:
        check_spec(obj.scene)
    except ValueError as e:
        raise ValueError(f"{os.fspath(path)}: root.scene: {e}") from None
    return obj
