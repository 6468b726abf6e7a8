"""The ``sigma_structure`` kind (fig:structure_Sigma computed from the flow): the regions J_R, J_0,
J_1 of a band of Sigma_h and their images, in the (q2, p2) plane, section and normal coordinates.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._io.serial import saved_as
from ..base import Geometry, SceneResult, region_counts
from ..fields import integers, pair, real
from ..registry import Kind, register
from ._flow import FlowScene, flow_geometry, flowmap, needs_step

__all__ = ["SigmaStructureScene", "SigmaStructureResult", "compute", "summarize", "report", "KIND"]


@saved_as("hovering.scenes.spec:SigmaStructureScene")
@dataclass(frozen=True, kw_only=True)
class SigmaStructureScene(FlowScene):
    """``sigma_structure`` (fig:structure_Sigma): regions J_R, J_0, J_1 and their images, from the flow.

    Attributes
    ----------
    grid : tuple of int
        ``(n_phi, n_K)`` points of the band ``[-pi, pi) x [K_low, K_high]``.
    K_range : tuple of float
        ``(K_low, K_high)`` of the band.
    marker_size : float
        Scatter marker size.
    """

    grid: tuple = integers((240, 60), names=("n_phi", "n_K"), ranges=((8, 4000), (2, 4000)))
    K_range: tuple = pair((-0.12, 0.03))
    marker_size: float = real(1.0, lo=0.0, hi=100.0, lo_open=True)


@saved_as("hovering.scenes.results:SigmaStructureResult")
@dataclass(repr=False)
class SigmaStructureResult(SceneResult):
    """Result of a ``sigma_structure`` scene (fig:structure_Sigma), all from the flow.

    Attributes
    ----------
    phi, K : ndarray
        Grid points of the band (normal coordinates) that have a point of Sigma_h.
    region : ndarray of int8
        Region of each point's return (J_0u, J_0, J_1, J_R, ...).
    theta, I, q2, p2 : ndarray
        The same points in section coordinates and in the (q2, p2) plane.
    phi1, K1, theta1, I1, q21, p21 : ndarray
        Their images (NaN where the return failed).
    tangency : dict
        The tangential curve K = 0: ``theta``, ``I``, ``q2``, ``p2`` on a fine grid, and
        ``phi1``, ``K1`` of its image (the curve ``K = eps f(phi)`` of thm:reversalinkphi).
    corners : Geometry
        Measured corner-singularity curves in (phi, K).
    """

    phi: np.ndarray = None
    K: np.ndarray = None
    region: np.ndarray = None
    theta: np.ndarray = None
    I: np.ndarray = None
    q2: np.ndarray = None
    p2: np.ndarray = None
    phi1: np.ndarray = None
    K1: np.ndarray = None
    theta1: np.ndarray = None
    I1: np.ndarray = None
    q21: np.ndarray = None
    p21: np.ndarray = None
    tangency: dict = field(default_factory=dict)
    corners: Geometry = None


def compute(scene: SigmaStructureScene, ctx) -> SigmaStructureResult:
    """One return of every point of the band's grid, the tangency circle and its image, and the
    measured corner-singularity curves.

    Parameters
    ----------
    scene : SigmaStructureScene
        The scene.
    ctx : hovering.scenes.base.Context
        Quick run, progress, meta.

    Returns
    -------
    SigmaStructureResult
    """
    meta, quick = ctx.meta, ctx.quick
    fm = flowmap(scene)
    nphi, nK = scene.grid
    if quick:
        nphi, nK = max(nphi // 4, 16), max(nK // 4, 4)
    meta["grid"] = [nphi, nK]
    lo = max(scene.K_range[0], 0.95 * fm.valid_band()[0])
    P, KK = np.meshgrid(-np.pi + 2 * np.pi * (np.arange(nphi) + 0.5) / nphi, np.linspace(lo, scene.K_range[1], nK))
    stages = ctx.stages(2)
    stages.start("returns", f"{nphi} x {nK} points, 1 return each")
    res = fm.iterate(P.ravel(), KK.ravel(), 1, record=("orbit", "regions", "section", "states"), **ctx.progress_kw)
    stages.end()
    ok = np.isfinite(res.theta[:, 0])  # points with a point of Sigma_h
    z = res.z
    # The tangency circle K = 0 and its image (K = eps f(phi) to leading order).
    ph = np.linspace(-np.pi, np.pi, 721, endpoint=False)
    tg = fm.iterate(ph, np.zeros_like(ph), 1, record=("orbit", "section", "states"))
    tangency = dict(
        phi=ph,
        theta=tg.theta[:, 0],
        I=tg.I[:, 0],
        q2=tg.z[:, 0, 2],
        p2=tg.z[:, 0, 3],
        phi1=tg.phi[:, 1],
        K1=tg.K[:, 1],
        theta1=tg.theta[:, 1],
        I1=tg.I[:, 1],
        q21=tg.z[:, 1, 2],
        p21=tg.z[:, 1, 3],
    )
    stages.start("corner curves", f"{10 if quick else 24} circles")
    corners = flow_geometry(fm, (lo, min(scene.K_range[1], 0.0)), 10 if quick else 24, fm.integrator_options["rtol"])
    stages.end()
    return SigmaStructureResult(
        scene=scene,
        meta=meta,
        phi=res.phi[ok, 0],
        K=res.K[ok, 0],
        region=res.region[ok, 0],
        theta=res.theta[ok, 0],
        I=res.I[ok, 0],
        q2=z[ok, 0, 2],
        p2=z[ok, 0, 3],
        phi1=res.phi[ok, 1],
        K1=res.K[ok, 1],
        theta1=res.theta[ok, 1],
        I1=res.I[ok, 1],
        q21=z[ok, 1, 2],
        p21=z[ok, 1, 3],
        tangency=tangency,
        corners=corners,
    )


def summarize(result: SigmaStructureResult) -> dict:
    """How many points of the band return through each region.

    Parameters
    ----------
    result : SigmaStructureResult
        The result.

    Returns
    -------
    dict
        ``regions``, ``points``.
    """
    return {"regions": region_counts(result.region), "points": int(result.phi.size)}


def report(summary: dict) -> list:
    """One line: the band's points and their regions.

    Parameters
    ----------
    summary : dict
        From :func:`summarize` (with the common numbers).

    Returns
    -------
    list of str
    """
    return [f"  {summary['points']} points of the band, regions {summary['regions']}"]


KIND = register(
    Kind(
        "sigma_structure",
        SigmaStructureScene,
        SigmaStructureResult,
        compute,
        summarize,
        report,
        doc="fig:structure_Sigma from the flow: regions J_R, J_0, J_1 and their images",
        figsize=(12.0, 12.0),
        records=(("regions", "section", "states"), ("regions", "section", "states")),
        check=needs_step,
        scene_map=flowmap,
    )
)
