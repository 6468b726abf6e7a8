"""What the tangent-dynamics kinds share (``ftle_field``, ``periodic_manifolds``,
``residue_vs_eps``): the choice of the map a scene is about - the flow's return map itself or one of
its truncated models - so that each kind runs on both models from one ``[system]`` table."""

from __future__ import annotations

from ..fields import choice
from ._flow import flowmap

__all__ = ["MAP_CHOICES", "map_field", "scene_model"]

#: ``"flow"``: the return map of the flow (FlowMap); ``"measured"``, ``"first_mode"``: its truncated
#: models (fm.truncated(forcing=...): onset arcs, all measured forcing modes or the first).
MAP_CHOICES = ("flow", "measured", "first_mode")


def map_field():
    """The ``map`` key of a tangent-dynamics scene: which model it runs on (default the flow)."""
    return choice("flow", MAP_CHOICES)


def scene_model(scene, eps: float | None = None):
    """The map a tangent-dynamics scene is about (at another eps if given).

    Parameters
    ----------
    scene : FlowScene
        A scene with a ``map`` key.
    eps : float, optional
        Override of ``system.eps``.

    Returns
    -------
    FlowMap, TruncatedFamily or TruncatedMap
    """
    fm = flowmap(scene, eps=eps)
    return fm if scene.map == "flow" else fm.truncated(forcing=scene.map)
