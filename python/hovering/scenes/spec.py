"""Validated scene specifications: one frozen class per kind, no field a kind does not use.

These are the output of :mod:`hovering.scenes.schema` (TOML -> spec) and the input of
:mod:`hovering.scenes.compute` (spec -> results). A spec is plain data: it saves with the result
(:mod:`hovering._io.serial`) so a figure can be redrawn from the file alone.

Each kind's spec is declared in its module, :mod:`hovering.scenes.kinds` (``<kind>.py``), its
fields carrying their defaults, ranges and choices; what several kinds share (the map's
parameters, the flow's ``[system]``, ``[integrator]`` and ``[outputs]`` tables) beside them. This
module is where they are all found by name (and the name files give them).
"""

from __future__ import annotations

from . import registry
from .base import QUICK_FACTOR, SceneSpec, figure_inches
from .kinds._flow import FlowScene, IntegratorSpec, OutputsSpec, PotentialSpec, SystemSpec
from .kinds._truncated import MapSpec, TruncatedScene
from .kinds.corner_directions import CornerDirectionsScene
from .kinds.flow_hovering_area import FlowHoveringScene
from .kinds.flow_portrait import FlowPortraitScene
from .kinds.ftle_field import FTLEScene
from .kinds.hovering_area import HoveringAreaScene, SeriesSpec
from .kinds.impact_zone import ImpactZoneScene
from .kinds.orbits import SPECIAL_ORBITS, CriticalSpec, OrbitScene, OrbitSpec, PanelSpec, ZoomSpec
from .kinds.periodic_manifolds import PeriodicManifoldsScene
from .kinds.residue_vs_eps import ResidueScene
from .kinds.sigma_structure import SigmaStructureScene
from .kinds.tangent_tori import TangentToriScene
from .kinds.wall_section import WallSectionScene
from .kinds.wall_tangency import WallTangencyScene

__all__ = [
    "KINDS",
    "TRUNCATED_KINDS",
    "FLOW_KINDS",
    "SPECIAL_ORBITS",
    "QUICK_FACTOR",
    "MapSpec",
    "OrbitSpec",
    "CriticalSpec",
    "ZoomSpec",
    "PanelSpec",
    "SeriesSpec",
    "PotentialSpec",
    "SystemSpec",
    "IntegratorSpec",
    "OutputsSpec",
    "SceneSpec",
    "TruncatedScene",
    "FlowScene",
    "OrbitScene",
    "HoveringAreaScene",
    "FlowPortraitScene",
    "FlowHoveringScene",
    "TangentToriScene",
    "SigmaStructureScene",
    "CornerDirectionsScene",
    "WallTangencyScene",
    "WallSectionScene",
    "ImpactZoneScene",
    "FTLEScene",
    "PeriodicManifoldsScene",
    "ResidueScene",
    "Scene",
    "figure_inches",
]

#: Scene kinds of the truncated map (sec:truncatedmapnum), as this package registers them.
TRUNCATED_KINDS = registry.names("truncated")
#: Scene kinds of the physical flow.
FLOW_KINDS = registry.names("flow")
#: Every kind of scene of this package (a kind registered later, from elsewhere, is in
#: :func:`hovering.scenes.registry.names`).
KINDS = TRUNCATED_KINDS + FLOW_KINDS

#: Old name of the truncated orbit scenes' spec (kept for one release).
Scene = SceneSpec
