"""Resolved sweep plans: a sweep scene's points with every number explicit (docs/sweep-plan.md).

``python -m hovering plan SCENE.toml [-o PLAN.toml] [--quick]`` writes one; ``hovering_sweep --plan
PLAN.toml`` (C++, no Python at run time) runs it, and ``python -m hovering scene`` runs the same
points (:func:`plan_points`) through the same core functions, so both programs give the same rows
and resume each other's checkpoints (:mod:`hovering.parallel.checkpoint`).

What the scene leaves to be worked out is worked out here, once: the map parameters as evaluated
(the golden family at each eps), the default box, the counts of a ``--quick`` run, the integrator
an accuracy target picks, the theory value, and for the flow the truncated models as tables (the
onset parameters' arcs and the arcs measured on the flow's corner curves, with the measured
forcing). A plan holds no expression and no default: a person can write one by hand.

A point's key in a checkpoint (:func:`point_key`) is the canonical record of its parameters: the
point's fields except ``label``, ``theory`` and ``b1`` (carried into the row), with the kind.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

from .._io.output import write_text
from .._version import __version__
from ..flow.potentials import COMPILED, POTENTIAL_KINDS
from ..flow.system import Polynomial, StepSystem
from . import registry
from .base import QUICK_FACTOR, SceneSpec

__all__ = [
    "FORMAT",
    "VERSION",
    "plan_points",
    "point_key",
    "plan_text",
    "write_plan",
    "sweep_counts",
    "system_record",
    "build_system",
]

#: The plan's ``format`` and ``version`` (hovering_sweep refuses another version).
FORMAT = "hovering-sweep-plan"
VERSION = 1

# The core's registry of compiled potentials: a kind's parameters, in its order, and its class.
_KINDS = {k.kind: k for k in POTENTIAL_KINDS}
_CLASSES = {k.kind: c for k, c in zip(POTENTIAL_KINDS, COMPILED)}

#: Fields of a point that are not parameters: carried into its row (theory, b1) or shown (label).
_CARRIED = ("label", "theory", "b1")


def sweep_counts(scene: SceneSpec, quick: bool = False) -> tuple:
    """``(n_steps, samples)`` of each point of a sweep scene: the scene's, or a ``--quick`` run's.

    A quick run divides both by :data:`~hovering.scenes.spec.QUICK_FACTOR`, keeping at least its
    kind's :attr:`~hovering.scenes.registry.Kind.quick_floor` (100 steps and 400 samples for the
    truncated map, 50 returns and 100 samples for the flow).

    Parameters
    ----------
    scene : HoveringAreaScene or FlowHoveringScene
        The scene.
    quick : bool, optional
        A quick run.

    Returns
    -------
    tuple of int
    """
    floor, min_samples = registry.get(scene.kind).quick_floor
    n = scene.n_steps
    if not quick:
        return n, scene.samples
    return max(n // QUICK_FACTOR, min(floor, n)), max(scene.samples // QUICK_FACTOR, min_samples)


def system_record(spec, eps: float) -> dict:
    """A flow scene's system as a plan point's ``system`` table, at one eps.

    Parameters
    ----------
    spec : SystemSpec
        The scene's system.
    eps : float
        The point's eps.

    Returns
    -------
    dict
        ``V1``, ``V2`` (``kind`` and its parameters: ``omega``, ``alpha`` of a tan), ``coupling`` terms, ``eps``,
        ``qw1``, ``qw2``, ``geometry``: plain numbers and strings.
    """

    def pot(p):
        # The kind and its parameters by the core's registry (the plan reader reads the same names).
        return {"kind": p.kind, **{q.name: float(getattr(p, q.name)) for q in _KINDS[p.kind].params}}

    # Each (i, j) once: the schema (and SystemSpec.build) refuse a repeated power.
    return {
        "V1": pot(spec.V1),
        "V2": pot(spec.V2),
        "coupling": [[float(c), int(i), int(j)] for c, i, j in spec.coupling],
        "eps": float(eps),
        "qw1": float(spec.qw1),
        "qw2": float(spec.qw2),
        "geometry": spec.geometry,
    }


def build_system(system: dict):
    """The :class:`~hovering.StepSystem` of a plan point's ``system`` table.

    Parameters
    ----------
    system : dict
        ``V1``, ``V2`` (``kind``, ``omega``, ``alpha``), ``coupling`` (``[c, i, j]`` terms),
        ``eps``, ``qw1``, ``qw2``, ``geometry``.

    Returns
    -------
    StepSystem
    """

    def pot(p):
        return _CLASSES[p["kind"]](*(p[q.name] for q in _KINDS[p["kind"]].params))

    c = Polynomial({(int(i), int(j)): float(v) for v, i, j in system["coupling"]}) if system["coupling"] else None
    return StepSystem(
        V1=pot(system["V1"]),
        V2=pot(system["V2"]),
        coupling=c,
        eps=system["eps"],
        qw1=system["qw1"],
        qw2=system["qw2"],
        geometry=system["geometry"],
    )


def plan_points(scene: SceneSpec, quick: bool = False) -> list:
    """The resolved points of a sweep scene, in order (series-major for ``hovering_area``).

    Parameters
    ----------
    scene : HoveringAreaScene or FlowHoveringScene
        The scene.
    quick : bool, optional
        The counts of a ``--quick`` run (:func:`sweep_counts`).

    Returns
    -------
    list of dict
        One plan point each (see docs/sweep-plan.md): plain numbers, strings, lists and dicts.

    Raises
    ------
    ValueError
        For a scene of another kind.
    """
    kind = registry.get(scene.kind)
    if kind.plan is None:
        sweeps = [k for k in registry.names() if registry.get(k).sweep]
        raise ValueError(
            f"scene {scene.name!r} is of kind {scene.kind!r}; a plan is made of the sweep kinds "
            + " and ".join(repr(k) for k in sweeps)
        )
    return kind.plan(scene, quick)


def point_key(kind: str, point: dict) -> dict:
    """A point's key in a checkpoint: its parameters (every field but label, theory, b1) and the kind.

    Parameters
    ----------
    kind : str
        ``"hovering_area"`` or ``"flow_hovering_area"``.
    point : dict
        A plan point.

    Returns
    -------
    dict
    """
    key = {k: v for k, v in point.items() if k not in _CARRIED}
    key["kind"] = kind
    return key


# ------------------------------------------------------------------------------------------------
# The TOML text (no TOML writer is a dependency; the plan's shapes are few)


def _toml_str(s: str) -> str:
    out = []
    for ch in s:
        if ch in '"\\':
            out.append("\\" + ch)
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04x}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def _toml(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        # repr: the shortest text that reads back as this double; TOML spells inf and nan the same.
        return repr(v) if math.isfinite(v) else ("nan" if math.isnan(v) else ("inf" if v > 0 else "-inf"))
    if isinstance(v, str):
        return _toml_str(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {_toml(x)}" for k, x in v.items()) + " }"
    raise TypeError(f"cannot write {type(v).__name__} to a plan")


def plan_text(scene: SceneSpec, quick: bool = False, points: list | None = None, checkpoint: str = "") -> str:
    """The plan of a sweep scene as TOML text.

    Parameters
    ----------
    scene : HoveringAreaScene or FlowHoveringScene
        The scene.
    quick : bool, optional
        A ``--quick`` run's counts.
    points : list, optional
        The points (default :func:`plan_points`).
    checkpoint : str, optional
        The default checkpoint of the plan's runs (relative to the plan's folder; "" for none).

    Returns
    -------
    str
    """
    pts = plan_points(scene, quick) if points is None else points
    lines = [
        f"# The resolved sweep plan of {scene.name}{' (--quick)' if quick else ''}: every number explicit "
        "(docs/sweep-plan.md).",
        f"# Written by hovering {__version__} (python -m hovering plan); run it with hovering_sweep --plan FILE.",
        f"format = {_toml(FORMAT)}",
        f"version = {VERSION}",
        f"kind = {_toml(scene.kind)}",
        f"name = {_toml(scene.name)}",
    ]
    if checkpoint:
        lines.append(f"checkpoint = {_toml(checkpoint)}")
    for p in pts:
        lines += ["", "[[points]]"]
        tables = []
        for k, v in p.items():
            if k == "models":
                tables = v
            else:
                lines.append(f"{k} = {_toml(v)}")
        for m in tables:
            lines += ["", "[[points.models]]"] + [f"{k} = {_toml(v)}" for k, v in m.items()]
    return "\n".join(lines) + "\n"


def write_plan(scene: SceneSpec, path: os.PathLike, quick: bool = False, checkpoint: str | None = None) -> str:
    """Write the plan of a sweep scene to ``path`` (atomically).

    Parameters
    ----------
    scene : HoveringAreaScene or FlowHoveringScene
        The scene.
    path : path-like
        The plan file.
    quick : bool, optional
        A ``--quick`` run's counts.
    checkpoint : str, optional
        The checkpoint its runs append to by default, relative to the plan's folder (default: the
        one ``python -m hovering scene`` run from this working directory uses, the scene output's
        ``.sweep.jsonl``, so that both programs append to one file).

    Returns
    -------
    str
        The path written.
    """
    path = os.fspath(path)
    if checkpoint is None:
        # python -m hovering scene's checkpoint (the output, relative to the working directory),
        # as seen from the plan's folder: both programs then append to one file.
        ck = Path(scene.output).with_suffix(".sweep.jsonl")
        checkpoint = os.path.relpath(
            ck if ck.is_absolute() else Path.cwd() / ck, os.path.dirname(os.path.abspath(path))
        )
    return write_text(path, plan_text(scene, quick, checkpoint=checkpoint))
