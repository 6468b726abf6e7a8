"""The ``periodic_manifolds`` kind: the periodic orbits of one period in a box, drawn over a
portrait, with the stable and unstable manifolds of the hyperbolic ones and the turnstile flux of
their lobes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._io.serial import saved_as
from ...dynamics import Manifold, PeriodicOrbit, lobes, manifold, periodic_orbits
from ..base import SceneResult, check_array, fmt
from ..fields import integer, pair, real
from ..registry import Kind, register
from ._flow import FlowScene
from ._tangent import map_field, scene_model

__all__ = ["PeriodicManifoldsScene", "PeriodicManifoldsResult", "compute", "summarize", "report", "KIND"]


@saved_as("hovering.scenes.spec:PeriodicManifoldsScene")
@dataclass(frozen=True, kw_only=True)
class PeriodicManifoldsScene(FlowScene):
    """``periodic_manifolds``: periodic orbits with their manifolds over a portrait.

    Attributes
    ----------
    map : {"flow", "measured", "first_mode"}
        The flow's return map or one of its truncated models.
    period : int
        The period of the orbits searched.
    phi_range, K_range : tuple of float
        The box searched (and drawn).
    n_seeds : int
        Newton's seed grid per side (:func:`hovering.periodic_orbits`; 0: the symmetry lines only).
    n_line : int
        Samples of each symmetry line.
    manifold_length : float
        Arc length of each manifold branch (0: none).
    n_orbits, n_steps : int
        The portrait under them: orbits started on a vertical line through the box's middle.
    """

    map: str = map_field()
    period: int = integer(2, lo=1, hi=10_000)
    phi_range: tuple = pair((-3.141592653589793, 3.141592653589793))
    K_range: tuple = pair((-0.25, 0.05))
    n_seeds: int = integer(2, lo=0, hi=100)
    n_line: int = integer(24, lo=2, hi=10_000)
    manifold_length: float = real(1.0, lo=0.0)
    n_orbits: int = integer(16, lo=0, hi=1000)
    n_steps: int = integer(1000, lo=1, hi=1_000_000)


@saved_as("hovering.scenes.results:PeriodicManifoldsResult")
@dataclass(repr=False)
class PeriodicManifoldsResult(SceneResult):
    """Result of a ``periodic_manifolds`` scene.

    Attributes
    ----------
    orbits : list of PeriodicOrbit
        The orbits found in the box.
    manifolds : list of Manifold
        For each hyperbolic orbit (at its first point): unstable +, unstable -, stable +, stable -.
    owner : ndarray of int
        The index in ``orbits`` of each manifold.
    flux : ndarray
        Per hyperbolic orbit (NaN for the others), the turnstile flux of its branches' lobes per step
        (:func:`hovering.lobes` of the first unstable and stable branches that cross twice).
    portrait_phi, portrait_K : ndarray
        The portrait's points, shape ``(n_orbits, n_steps + 1)``.
    """

    orbits: list = field(default_factory=list)
    manifolds: list = field(default_factory=list)
    owner: np.ndarray = None
    flux: np.ndarray = None
    portrait_phi: np.ndarray = None
    portrait_K: np.ndarray = None

    def _validate_loaded(self) -> None:
        super()._validate_loaded()
        for i, o in enumerate(self.orbits):
            if not isinstance(o, PeriodicOrbit):
                raise ValueError(f"orbits[{i}] must be a PeriodicOrbit, got {type(o).__name__}")
        for i, w in enumerate(self.manifolds):
            if not isinstance(w, Manifold):
                raise ValueError(f"manifolds[{i}] must be a Manifold, got {type(w).__name__}")
        check_array("owner", self.owner, 1, kinds="iu", shape=(len(self.manifolds),))
        check_array("flux", self.flux, 1, shape=(len(self.orbits),))
        check_array("portrait_phi", self.portrait_phi, 2)
        check_array("portrait_K", self.portrait_K, 2, shape=self.portrait_phi.shape)


def compute(scene: PeriodicManifoldsScene, ctx) -> PeriodicManifoldsResult:
    """The portrait, the orbits of the period in the box, the hyperbolic ones' branches and lobes.

    Parameters
    ----------
    scene : PeriodicManifoldsScene
        The scene.
    ctx : hovering.scenes.base.Context
        Quick run, stages, meta.

    Returns
    -------
    PeriodicManifoldsResult
    """
    meta = ctx.meta
    m = scene_model(scene)
    stages = ctx.stages(3)
    n = ctx.scaled(scene.n_steps, floor=50)
    stages.start("portrait", f"{scene.n_orbits} orbits x {n} returns")
    K0 = np.linspace(*scene.K_range, scene.n_orbits + 2)[1:-1]
    phi_mid = 0.5 * (scene.phi_range[0] + scene.phi_range[1])
    if scene.n_orbits:
        res = m.iterate(np.full(K0.size, phi_mid), K0, n, record=("orbit",), **ctx.progress_kw)
        pp, pk = np.asarray(res.phi), np.asarray(res.K)
    else:
        pp = pk = np.zeros((0, n + 1))
    stages.end()
    stages.start("periodic orbits", f"period {scene.period} in the box")
    region = (tuple(scene.phi_range), tuple(scene.K_range))
    found = periodic_orbits(m, scene.period, region=region, n_seeds=scene.n_seeds, n_line=scene.n_line)
    stages.end()
    orbits = list(found)
    mans, owner, flux = [], [], np.full(len(orbits), np.nan)
    length = scene.manifold_length * (0.2 if ctx.quick else 1.0)
    stages.start("manifolds", f"length {length:g} per branch")
    if length > 0:
        for i, o in enumerate(orbits):
            if o.stability not in ("hyperbolic", "inverse hyperbolic"):
                continue
            br = {}
            for kind in ("unstable", "stable"):
                for b in (1, -1):
                    try:
                        w = manifold(m, o, kind, b, length=length, max_points=20_000)
                    except ValueError:
                        continue
                    br[(kind, b)] = w
                    mans.append(w)
                    owner.append(i)
            for bu in (1, -1):
                for bs in (1, -1):
                    if np.isfinite(flux[i]) or ("unstable", bu) not in br or ("stable", bs) not in br:
                        continue
                    try:
                        flux[i] = lobes(br[("unstable", bu)], br[("stable", bs)]).flux
                    except ValueError:
                        pass
    stages.end()
    meta.update(map=scene.map, portrait_steps=n, line_roots=found.line_roots, seeds=found.seeds)
    return PeriodicManifoldsResult(
        scene=scene,
        meta=meta,
        orbits=orbits,
        manifolds=mans,
        owner=np.asarray(owner, dtype=np.int64),
        flux=flux,
        portrait_phi=pp,
        portrait_K=pk,
    )


def summarize(result: PeriodicManifoldsResult) -> dict:
    """Each orbit's point, rotation, residue and stability; the hyperbolic ones' lobe flux.

    Parameters
    ----------
    result : PeriodicManifoldsResult
        The result.

    Returns
    -------
    dict
    """
    return {
        "orbits": [
            dict(
                phi=float(o.phi[0]),
                K=float(o.K[0]),
                rotation=f"{o.winding}/{o.period}",
                residue=float(o.residue),
                stability=o.stability,
                flux=None if not np.isfinite(result.flux[i]) else float(result.flux[i]),
            )
            for i, o in enumerate(result.orbits)
        ],
        "manifolds": len(result.manifolds),
    }


def report(summary: dict) -> list:
    """One line per orbit.

    Parameters
    ----------
    summary : dict
        From :func:`summarize`.

    Returns
    -------
    list of str
    """
    lines = []
    for o in summary.get("orbits", []):
        flux = "" if o["flux"] is None else f", lobe flux {fmt(o['flux'], '.3g')} per return"
        lines.append(
            f"  {o['stability']} orbit {o['rotation']} at (phi, K) = ({fmt(o['phi'], '.5f')}, {fmt(o['K'], '.5f')}): "
            f"residue {fmt(o['residue'], '.4g')}{flux}"
        )
    lines.append(f"  {summary.get('manifolds', 0)} manifold branches")
    return lines


KIND = register(
    Kind(
        "periodic_manifolds",
        PeriodicManifoldsScene,
        PeriodicManifoldsResult,
        compute,
        summarize,
        report,
        doc="periodic orbits of one period over a portrait, with the manifolds of the hyperbolic ones",
        figsize=(10.0, 7.0),
        scene_map=scene_model,
    )
)
