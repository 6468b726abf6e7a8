"""The ``tangent_tori`` kind (fig:two-tang computed): the two tangent tori of the unperturbed system,
each with a trajectory segment on it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._enums import Status
from ..._io.serial import saved_as
from ..base import SceneResult, check_array, fmt
from ..fields import integer
from ..registry import Kind, register
from ..values import color as color_value
from ..values import text as text_value
from ._flow import FlowScene, flowmap, work

__all__ = ["TangentToriScene", "TorusResult", "TangentToriResult", "compute", "summarize", "report", "KIND"]


def _check(where: str, values: dict) -> None:
    """The tangent tori are those of the unperturbed smooth flow."""
    system = values["system"]
    if system.eps != 0 or system.geometry != "none":
        raise ValueError(
            f"{where}.system: the tangent tori are those of the unperturbed smooth flow; allowed: "
            f"eps = 0 and geometry = 'none' (got eps = {system.eps!r}, geometry = {system.geometry!r}: "
            f"with walls, a tangent trajectory stops as GRAZING)"
        )


@saved_as("hovering.scenes.spec:TangentToriScene")
@dataclass(frozen=True, kw_only=True)
class TangentToriScene(FlowScene):
    """``tangent_tori`` (fig:two-tang): the two tangent tori of the unperturbed system.

    Attributes
    ----------
    n_returns : int
        Returns of each trajectory segment drawn.
    n_points : int
        Samples per torus circle.
    """

    n_returns: int = integer(3, lo=1, hi=100)
    n_points: int = integer(400, lo=16, hi=100_000)


@saved_as("hovering.scenes.results:TorusResult")
@dataclass
class TorusResult:
    """One tangent torus of the unperturbed system (fig:two-tang) and a trajectory on it.

    Attributes
    ----------
    name : str
        ``"right"`` (tangent to q1 = qw1, the paper's blue torus) or ``"upper"`` (tangent to
        q2 = qw2, red).
    h1, h2 : float
        Partial energies ``H1 = h1``, ``H2 = h2`` (``h1 + h2 = h``).
    q1, p1, q2, p2 : ndarray
        The two circles ``H1 = h1`` in (q1, p1) and ``H2 = h2`` in (q2, p2).
    trajectory : ndarray
        ``(m, 5)`` samples ``(t, q1, p1, q2, p2)`` of a trajectory on the torus.
    color : str
        Its colour.
    """

    name: str
    h1: float
    h2: float
    q1: np.ndarray
    p1: np.ndarray
    q2: np.ndarray
    p2: np.ndarray
    trajectory: np.ndarray
    color: str

    def _validate_loaded(self) -> None:

        text_value("name", self.name, ("right", "upper"))
        color_value("color", self.color)
        check_array("q1", self.q1, 1)
        for name in ("p1", "q2", "p2"):
            check_array(name, getattr(self, name), 1, shape=self.q1.shape)
        check_array("trajectory", self.trajectory, 2)
        if self.trajectory.shape[1] != 5:
            raise ValueError(f"trajectory has shape {self.trajectory.shape}; it must be (m, 5): t, q1, p1, q2, p2")


@saved_as("hovering.scenes.results:TangentToriResult")
@dataclass(repr=False)
class TangentToriResult(SceneResult):
    """Result of a ``tangent_tori`` scene (fig:two-tang).

    Attributes
    ----------
    tori : list of TorusResult
        The right-wall (blue) and upper-wall (red) tangent tori.
    qw1, qw2 : float
        The step's corner.
    well1, well2 : tuple of float
        Extent of each oscillator's motion at energy h (for the axes).
    """

    tori: list = field(default_factory=list)
    qw1: float = 0.0
    qw2: float = 0.0

    def _validate_loaded(self) -> None:
        super()._validate_loaded()
        for i, x in enumerate(self.tori):
            if not isinstance(x, TorusResult):
                raise ValueError(f"tori[{i}] must be a TorusResult, got {type(x).__name__}")


def _circle(V, e: float, n: int) -> tuple:
    """The level ``V(q) + p^2/2 = e`` as a closed curve, by the potential's own angle variable."""
    th = np.linspace(-np.pi, np.pi, n)
    qp = np.array([V.point_at(float(t), e) for t in th])
    return qp[:, 0], qp[:, 1]


def compute(scene: TangentToriScene, ctx) -> TangentToriResult:
    """Each torus's two circles and a trajectory on it from the point of Sigma_h at theta = 0.

    Parameters
    ----------
    scene : TangentToriScene
        The scene.
    ctx : hovering.scenes.base.Context
        Progress, meta.

    Returns
    -------
    TangentToriResult
    """
    meta = ctx.meta
    sys = scene.system.build()
    h = scene.h
    h1w, h2w = float(sys.V1.V(sys.qw1)), float(sys.V2.V(sys.qw2))
    fm = flowmap(scene, coordinates="section")
    tori = []
    stages = ctx.stages(2)
    for name, h1, color in (("right", h1w, "C0"), ("upper", h - h2w, "C3")):
        stages.start(f"torus {name}", f"1 orbit x {scene.n_returns} returns with its trajectory")
        h2 = h - h1
        q1, p1 = _circle(sys.V1, h1, scene.n_points)
        q2, p2 = _circle(sys.V2, h2, scene.n_points)
        # A point of Sigma_h on this torus: (theta, I) with H2(I) = h2; theta = 0 (p2 = 0, q2 at
        # its maximum) starts the segment at a clean corner of the configuration-space box.
        I = float(sys.V2.action(h2))
        res = fm.iterate(
            [0.0],
            [I],
            scene.n_returns,
            record=("trajectory",),
            trajectory_dt=scene.outputs.trajectory_dt,
            **ctx.progress_kw,
        )
        meta.setdefault("status", {})[name] = Status(int(res.status[0])).name
        meta.setdefault("work", {})[name] = work(res)
        stages.end()
        tori.append(
            TorusResult(
                name=name,
                h1=h1,
                h2=h2,
                q1=q1,
                p1=p1,
                q2=q2,
                p2=p2,
                trajectory=np.asarray(res.trajectory_of(0)),
                color=color,
            )
        )
    return TangentToriResult(scene=scene, meta=meta, tori=tori, qw1=sys.qw1, qw2=sys.qw2)


def summarize(result: TangentToriResult) -> dict:
    """Each torus's energies and how close its trajectory comes to its wall.

    Parameters
    ----------
    result : TangentToriResult
        The result.

    Returns
    -------
    dict
        ``tori``, ``qw1``, ``qw2``, ``status``, ``work``.
    """
    meta = result.meta
    s = {
        "tori": [
            dict(
                name=t.name,
                h1=t.h1,
                h2=t.h2,
                trajectory_points=int(t.trajectory.shape[0]),
                q1_min=float(np.nanmin(t.trajectory[:, 1])) if t.trajectory.size else None,
                q2_min=float(np.nanmin(t.trajectory[:, 3])) if t.trajectory.size else None,
            )
            for t in result.tori
        ]
    }
    s.update(qw1=result.qw1, qw2=result.qw2, status=meta.get("status", {}), work=meta.get("work", {}))
    return s


def report(summary: dict) -> list:
    """One line per torus.

    Parameters
    ----------
    summary : dict
        From :func:`summarize` (with the common numbers).

    Returns
    -------
    list of str
    """
    f, lines = fmt, []
    for t in summary.get("tori", []):
        lines.append(
            f"  {t['name']} torus: h1 = {f(t['h1'], '.5f')}, h2 = {f(t['h2'], '.5f')}, "
            f"{t['trajectory_points']} trajectory samples, min q1 = {f(t['q1_min'], '.6f')} "
            f"(qw1 = {f(summary['qw1'], 'g')}), min q2 = {f(t['q2_min'], '.6f')} "
            f"(qw2 = {f(summary['qw2'], 'g')})"
        )
    return lines


KIND = register(
    Kind(
        "tangent_tori",
        TangentToriScene,
        TangentToriResult,
        compute,
        summarize,
        report,
        doc="fig:two-tang: the two tangent tori of the unperturbed system with trajectories",
        figsize=(12.0, 8.0),
        records=(("trajectory",), ("trajectory",)),
        check=_check,
        scene_map=lambda scene: flowmap(scene, coordinates="section"),
    )
)
