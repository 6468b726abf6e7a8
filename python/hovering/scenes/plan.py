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

import dataclasses
import math
import os
from pathlib import Path

import numpy as np

from .._output import write_text
from .._version import __version__
from ..analysis.hovering import default_depth
from ..flow import Harmonic, Tan
from ..flow.system import Polynomial, StepSystem
from ..normal.compare import truncated_from_flow
from ..normal.corners import corner_curves
from ..normal.flowmap import FlowMap
from .spec import QUICK_FACTOR, FlowHoveringScene, HoveringAreaScene, SceneSpec

__all__ = ["FORMAT", "VERSION", "plan_points", "point_key", "plan_text", "write_plan", "sweep_counts"]

#: The plan's ``format`` and ``version`` (hovering_sweep refuses another version).
FORMAT = "hovering-sweep-plan"
VERSION = 1

#: Fields of a point that are not parameters: carried into its row (theory, b1) or shown (label).
_CARRIED = ("label", "theory", "b1")


def sweep_counts(scene: SceneSpec, quick: bool = False) -> tuple:
    """``(n_steps, samples)`` of each point of a sweep scene: the scene's, or a ``--quick`` run's.

    A quick run divides both by :data:`~hovering.scenes.spec.QUICK_FACTOR`, keeping at least
    100 steps and 400 samples (truncated map) or 50 returns and 100 samples (flow).

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
    flow = isinstance(scene, FlowHoveringScene)
    floor, min_samples = (50, 100) if flow else (100, 400)
    n = scene.n_steps
    if not quick:
        return n, scene.samples
    return max(n // QUICK_FACTOR, min(floor, n)), max(scene.samples // QUICK_FACTOR, min_samples)


def _truncated_points(scene: HoveringAreaScene, quick: bool) -> list:
    n_steps, samples = sweep_counts(scene, quick)
    out = []
    for s in scene.series:
        for e in scene.eps:
            ms = s.map_at(e)
            m = ms.build()
            if s.K_low is not None:
                K_low = float(s.K_low)
            else:  # the default box of hovering_area: the critical band, cut to the map's band
                depth = default_depth(m) if e != 0 else 0.1
                K_low = max(-depth, m.valid_band()[0] * (1 - 1e-9))
            mp = {k: float(getattr(ms, k)) for k in ("eps", "Omega0", "theta_w", "tau0", "tau1", "lam")}
            out.append(
                {
                    "label": s.label,
                    "n_steps": int(n_steps),
                    "samples": int(samples),
                    "seed": int(scene.seed),
                    "K_low": float(K_low),
                    "theory": float(m.theory().area),
                    "map": mp,
                }
            )
    return out


def _system(spec, eps: float) -> dict:
    def pot(p):
        d = {"kind": p.kind, "omega": float(p.omega)}
        if p.kind == "tan":
            d["alpha"] = float(p.alpha)
        return d

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
        return Harmonic(p["omega"]) if p["kind"] == "harmonic" else Tan(p["omega"], p["alpha"])

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


def _model(name: str, tm, K_low: float) -> dict:
    rec = tm._to_record()
    out = {"name": name, "K_low": float(K_low), "eps": float(rec["eps"])}
    for k in ("K", "Omega", "JR", "J1", "forcing"):
        out[k] = [float(x) for x in np.asarray(rec[k], dtype=float)]
    out["K_max"] = float(rec["K_max"])
    return out


def _measured_model(fm, K_low: float):
    """The truncated family with arcs measured on the flow's corner curves (and measured forcing).

    Circles below the flow's impact zone (eps > 0: under the deformed torus tangent to the upper
    wall, ``FlowMap.impact_zone_floor``) hold no J_1 / J_R arcs: the family then stops at the
    lowest circle that has them, and its band is shallower than the box asked for.
    """
    depth = min(-1.05 * K_low, -0.95 * fm.valid_band()[0])  # circles with a point of Sigma_h only
    s = np.linspace(math.sqrt(depth), 0.0, 17)[:-1]
    K = np.concatenate([-(s**2), [0.01, 0.03, 0.05]])
    cc = corner_curves(fm.section, K, fm.curve, n_phi=256, bisections=30, rtol=1e-12)
    ok = (K > 0) | (np.isfinite(cc.JR) & np.isfinite(cc.J1) & np.isfinite(cc.Omega))
    first = int(np.argmax(np.cumprod(ok[::-1])[::-1])) if not ok.all() else 0
    keep = np.zeros(K.size, bool)
    keep[first:] = True
    keep &= ok
    if not keep.all():
        cc = dataclasses.replace(
            cc,
            **{
                f: getattr(cc, f)[keep]
                for f in ("K", "phi_R0", "phi_01", "phi_1R", "JR", "J0", "J1", "Omega", "Omega_spread", "other")
            },
        )
    return truncated_from_flow(cc, fm.eps, forcing=tuple(fm.forcing_coefficients()))


def _flow_point(scene: FlowHoveringScene, e: float, n_steps: int, samples: int) -> dict:
    system = _system(scene.system, e)
    fm = FlowMap(build_system(system), h=scene.h, **scene.integrator.options())
    o = fm.integrator_options  # what an accuracy target chose, or the scene's setting
    integrator = {"stepper": o["stepper"], "rtol": float(o["rtol"]), "atol": float(o["atol"])}
    # One box for flow and models, so the same points are classified by each: the default depth
    # (the critical band of eq:hovsetsize), cut to the band every model is defined on.
    depth = default_depth(fm) if e != 0 else 0.1
    tms = {name: (fm.truncated() if name == "onset" else _measured_model(fm, -depth)) for name in scene.models}
    K_low = max(-depth, fm.valid_band()[0] * (1 - 1e-9))
    if "onset" in tms:
        K_low = max(K_low, tms["onset"].valid_band()[0] * (1 - 1e-9))
    # A model whose band is shallower than the box (measured arcs stop at the impact zone's floor)
    # samples its own box: its points are not the flow's.
    models = [_model(name, tm, max(K_low, tm.valid_band()[0] * (1 - 1e-9))) for name, tm in tms.items()]
    th = fm.theory()
    return {
        "n_steps": int(n_steps),
        "samples": int(samples),
        "seed": int(scene.seed),
        "K_low": float(K_low),
        "theory": float(th.area),
        "b1": float(th.forcing[0]),
        "h": float(scene.h),
        "system": system,
        "integrator": integrator,
        "models": models,
    }


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
    if isinstance(scene, HoveringAreaScene):
        return _truncated_points(scene, quick)
    if isinstance(scene, FlowHoveringScene):
        n_steps, samples = sweep_counts(scene, quick)
        return [_flow_point(scene, e, n_steps, samples) for e in scene.eps]
    raise ValueError(
        f"scene {scene.name!r} is of kind {scene.kind!r}; a plan is made of the sweep kinds "
        "'hovering_area' and 'flow_hovering_area'"
    )


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
