"""Typed results of scenes: everything a figure or a report shows, and nothing else.

Each result holds its scene spec, the computed arrays and numbers, and ``meta`` (version, quick
run, timings). Results save to NPZ + JSON without pickle (:meth:`SceneResult.save`,
:func:`load_result`) and a figure is a pure function of them (:mod:`hovering.plot.figures`), so
``python -m hovering redraw RESULT.npz`` redraws any figure without computing.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import _serial
from .._display import Summarized
from .._enums import Region, Status
from .._output import write_text
from .._provenance import provenance
from ..analysis.barriers import BarrierScan
from ..analysis.transit import TransitResult
from ..analysis.zone import ImpactZone
from .values import MAX_TEXT
from .values import color as _color
from .values import text as _str
from .spec import SceneSpec

#: The ``format`` of a scene result's sidecar JSON.
SIDECAR_FORMAT = "hovering-scene-1"

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
    "load_result",
    "jsonable",
]


def jsonable(x):
    """``x`` with numpy scalars as Python numbers and non-finite floats as None (JSON-safe).

    Parameters
    ----------
    x : object
        Nested dicts, lists, tuples and numbers.

    Returns
    -------
    object
    """
    if isinstance(x, dict):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return jsonable(x.tolist())
    if isinstance(x, (np.floating, float)):
        return None if not math.isfinite(float(x)) else float(x)
    if isinstance(x, np.bool_):
        return bool(x)
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, Path):
        return str(x)
    return x


# ------------------------------------------------------------------------------------------------
# Checks of a result read from a file (hovering._serial calls ``_validate_loaded`` after checking
# each field's declared type): what the figure draws is what a computation could have made. Texts
# and colours get the scene schema's checks.


def _texts(where: str, values, n: int | None = None, color: bool = False) -> None:
    if not isinstance(values, list) or (n is not None and len(values) != n):
        raise ValueError(
            f"{where} must be a list of {n if n is not None else 'some'} strings, got "
            f"{'a list of ' + str(len(values)) if isinstance(values, list) else type(values).__name__}"
        )
    for i, v in enumerate(values):
        (_color if color else _str)(f"{where}[{i}]", v)


def _array(where: str, a, ndim: int, kinds: str = "iuf", shape: tuple | None = None) -> None:
    if not isinstance(a, np.ndarray) or a.ndim != ndim or a.dtype.kind not in kinds:
        got = f"shape {a.shape} dtype {a.dtype}" if isinstance(a, np.ndarray) else type(a).__name__
        raise ValueError(f"{where} must be a {ndim}-D array of numbers, got {got}")
    if shape is not None and a.shape != shape:
        raise ValueError(f"{where} has shape {a.shape}; it must have shape {shape} (as the arrays it goes with)")


@dataclass
class Geometry:
    """The lines a phase portrait on (phi, K) draws: K = 0, L1, L2 and the corner curves.

    Attributes
    ----------
    K : ndarray
        Heights of the lines L1, L2.
    L1, L2 : ndarray or None
        Their angles at ``K`` (None: not drawn).
    K_corner : ndarray
        Heights (K < 0) of the corner-singularity curves.
    corners : dict
        ``"01"``, ``"1R"``, ``"R0"`` -> angles at ``K_corner`` (empty: not drawn; NaN where a curve
        was not found).
    measured : bool
        Whether the corner curves were measured on the flow (else closed forms of the model).
    """

    K: np.ndarray
    L1: np.ndarray | None
    L2: np.ndarray | None
    K_corner: np.ndarray
    corners: dict
    measured: bool = False

    def _validate_loaded(self) -> None:
        _array("K", self.K, 1)
        for name in ("L1", "L2"):
            if getattr(self, name) is not None:
                _array(name, getattr(self, name), 1, shape=self.K.shape)
        _array("K_corner", self.K_corner, 1)
        for k, v in self.corners.items():
            if k not in ("01", "1R", "R0"):
                raise ValueError(f"corners has the key {str(k)[:40]!r}; allowed: '01', '1R', 'R0'")
            _array(f"corners.{k}", v, 1, shape=self.K_corner.shape)


@dataclass
class OrbitSet:
    """Orbits of one panel, with what each one is.

    Attributes
    ----------
    phi, K : ndarray
        Shape ``(n_orbits, n_steps + 1)``; NaN after an orbit stopped.
    region : ndarray of int8 or None
        Region of the point each step was taken from, ``(n_orbits, n_steps)``.
    status : ndarray of int8
        Per-orbit :class:`~hovering.Status`.
    steps_done : ndarray of int64
        Steps each orbit took.
    labels, colors, kinds : list of str
        Legend label, colour and kind (``"fan"``, a special orbit's name, ``"extra"``,
        ``"critical"``) of each orbit.
    rho : ndarray or None
        Rotation numbers.
    """

    phi: np.ndarray
    K: np.ndarray
    region: np.ndarray | None
    status: np.ndarray
    steps_done: np.ndarray
    labels: list
    colors: list
    kinds: list
    rho: np.ndarray | None = None

    def _validate_loaded(self) -> None:
        _array("phi", self.phi, 2)
        n, m = self.phi.shape
        _array("K", self.K, 2, shape=(n, m))
        if self.region is not None:
            _array("region", self.region, 2, "iu", shape=(n, max(m - 1, 0)))
        _array("status", self.status, 1, "iu", shape=(n,))
        _array("steps_done", self.steps_done, 1, "iu", shape=(n,))
        _texts("labels", self.labels, n)
        _texts("colors", self.colors, n, color=True)
        _texts("kinds", self.kinds, n)
        if self.rho is not None:
            _array("rho", self.rho, 1, shape=(n,))

    @classmethod
    def of(cls, res, labels, colors, kinds, rho=None) -> OrbitSet:
        """From an :class:`~hovering.IterateResult` (``"orbit"`` recorded).

        Parameters
        ----------
        res : IterateResult
            The orbits.
        labels, colors, kinds : list of str
            Per orbit.
        rho : ndarray, optional
            Rotation numbers.

        Returns
        -------
        OrbitSet
        """
        return cls(
            np.asarray(res.phi),
            np.asarray(res.K),
            None if res.region is None else np.asarray(res.region),
            np.asarray(res.status),
            np.asarray(res.steps_done),
            list(labels),
            list(colors),
            list(kinds),
            None if rho is None else np.asarray(rho, dtype=float),
        )

    @property
    def n_orbits(self) -> int:
        """Number of orbits."""
        return int(self.phi.shape[0])


@dataclass
class OrbitPanelResult:
    """One computed orbit panel of a truncated-map scene.

    Attributes
    ----------
    id : str
        Panel tag.
    params : dict
        The map's parameters (and golden-family c, eps).
    orbits : OrbitSet
        The orbits.
    geometry : Geometry
        Lines drawn under them.
    leading : tuple or None
        ``(phi, k, label)`` of the leading-order curve k_{eps,1} / k_{eps,2}, when drawn.
    K_crit, rho_crit, band_floor : float
        Predictions eq:kcrit, eq:rhocrit and the valid band's floor.
    xlim, ylim : tuple of float
        Axes limits.
    critical : dict or None
        The critical curve found (``found``, ``K0``, ``K_min``, ...), when searched.
    """

    id: str
    params: dict
    orbits: OrbitSet
    geometry: Geometry
    leading: tuple | None
    K_crit: float
    rho_crit: float
    band_floor: float
    xlim: tuple
    ylim: tuple
    critical: dict | None = None


@dataclass
class ZoomPanelResult:
    """A zoom into another panel: its window and the finer lines drawn in it.

    Attributes
    ----------
    id, of, on : str
        Panel tag, the panel zoomed into, how the window was chosen.
    window : dict
        ``xlim``, ``ylim``, ``rule`` (and the orbit(s) it was chosen from).
    geometry : Geometry
        Lines, sampled finely over the window.
    leading : tuple or None
        The leading-order curve, sampled finely.
    """

    id: str
    of: str
    on: str
    window: dict
    geometry: Geometry
    leading: tuple | None = None


@dataclass
class SeriesResult:
    """One curve of |HOV| against eps.

    Attributes
    ----------
    label, color : str
        Legend label and colour.
    eps, area, error, theory : ndarray
        Measured points and eq:hovsetsize at them.
    floor_touched : ndarray of bool
        Hovering points reached the lowest tenth of the sampled box.
    K_low, Omega0, theta_w : ndarray
        The box floor and the map at each point.
    theory_eps, theory_curve : ndarray
        The theory drawn as a line (empty when another series with the same map family drew it).
    golden_c : float or None
        Golden-family parameter.
    reused : int
        Points read from the checkpoint instead of computed.
    """

    label: str
    color: str
    eps: np.ndarray
    area: np.ndarray
    error: np.ndarray
    theory: np.ndarray
    floor_touched: np.ndarray
    K_low: np.ndarray
    Omega0: np.ndarray
    theta_w: np.ndarray
    theory_eps: np.ndarray
    theory_curve: np.ndarray
    golden_c: float | None = None
    reused: int = 0

    def _validate_loaded(self) -> None:

        _str("label", self.label)
        _color("color", self.color)
        _array("eps", self.eps, 1)
        for name in ("area", "error", "theory", "K_low", "Omega0", "theta_w"):
            _array(name, getattr(self, name), 1, shape=self.eps.shape)
        _array("floor_touched", self.floor_touched, 1, "b", shape=self.eps.shape)
        _array("theory_eps", self.theory_eps, 1)
        _array("theory_curve", self.theory_curve, 1, shape=self.theory_eps.shape)


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

        _str("name", self.name, ("right", "upper"))
        _color("color", self.color)
        _array("q1", self.q1, 1)
        for name in ("p1", "q2", "p2"):
            _array(name, getattr(self, name), 1, shape=self.q1.shape)
        _array("trajectory", self.trajectory, 2)
        if self.trajectory.shape[1] != 5:
            raise ValueError(f"trajectory has shape {self.trajectory.shape}; it must be (m, 5): t, q1, p1, q2, p2")


@dataclass(repr=False)
class SceneResult(Summarized):
    """What every scene result has.

    Attributes
    ----------
    scene : SceneSpec
        The validated scene.
    meta : dict
        ``version``, ``quick``, ``timings`` (seconds per stage), what was recorded and run.
    """

    scene: SceneSpec
    meta: dict

    def _validate_loaded(self) -> None:
        # What the figure and the summary take from meta (the scene itself was checked as it was read).

        for key, kind in (("quick", bool), ("n_steps", int), ("samples", int), ("timings", dict), ("version", str)):
            v = self.meta.get(key)
            if v is not None and (not isinstance(v, kind) or (kind is int and isinstance(v, bool))):
                raise ValueError(f"meta.{key} must be of type {kind.__name__}, got {type(v).__name__}")
        if len(self.meta.get("version") or "") > MAX_TEXT:
            raise ValueError(
                f"meta.version: a string of {len(self.meta['version'])} characters; allowed: at most {MAX_TEXT}"
            )
        for k, v in (self.meta.get("timings") or {}).items():
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise ValueError(f"meta.timings.{k} must be a number of seconds, got {type(v).__name__}")

    def _summary(self) -> list:
        out = [("scene", self.scene.name), ("kind", self.scene.kind)]
        out += [(k, self.meta[k]) for k in ("quick", "n_steps", "samples", "version") if self.meta.get(k) is not None]
        timings = self.meta.get("timings") or {}
        if timings:
            out.append(("seconds", sum(v for v in timings.values() if isinstance(v, (int, float)))))
        return out

    def summary(self) -> dict:
        """The numbers shown, as a JSON-able dict (what the CLI prints and the sidecar JSON holds).

        Returns
        -------
        dict
        """
        return summarize(self)

    def save(self, path: os.PathLike) -> tuple:
        """Write the result as NPZ (arrays + the typed tree) and a sidecar JSON (scene, meta, summary).

        Both record what made them (``provenance``: versions, build, machine, seed) and are
        written atomically: a failure leaves the previous files as they were.

        Parameters
        ----------
        path : path-like
            The ``.npz`` file (the JSON gets the same name with ``.json``).

        Returns
        -------
        tuple of str
            The two paths written.

        Raises
        ------
        hovering._output.WriteError
            (a ValueError) When a file cannot be written (e.g. ``no space left``).
        """

        npz = _serial.save(self, path, meta=jsonable(self.meta))
        side = str(Path(npz).with_suffix(".json"))
        # "format" first: it is how a later run recognises the file as one it may replace.
        doc = dict(
            format=SIDECAR_FORMAT,
            provenance=provenance(seed=getattr(self.scene, "seed", None)),
            scene=jsonable(_serial.to_tree(self.scene, {})),
            meta=jsonable(self.meta),
            summary=jsonable(self.summary()),
        )
        write_text(side, json.dumps(doc, indent=1, allow_nan=False))
        return npz, side


@dataclass(repr=False)
class OrbitSceneResult(SceneResult):
    """Result of a ``portrait`` or ``critical_orbits`` scene.

    Attributes
    ----------
    panels : list of OrbitPanelResult and ZoomPanelResult
        In the scene's order.
    """

    panels: list = field(default_factory=list)

    def _validate_loaded(self) -> None:
        super()._validate_loaded()
        if len(self.panels) != len(getattr(self.scene, "panels", ())):
            raise ValueError(f"panels: {len(self.panels)} results for the scene's {len(self.scene.panels)} panels")
        ids = []
        for i, p in enumerate(self.panels):
            if not isinstance(p, (OrbitPanelResult, ZoomPanelResult)):
                raise ValueError(f"panels[{i}] must be a panel result, got {type(p).__name__}")
            ids.append(p.id)
        for i, p in enumerate(self.panels):
            if isinstance(p, ZoomPanelResult) and not any(
                q.id == p.of and isinstance(q, OrbitPanelResult) for q in self.panels
            ):
                raise ValueError(f"panels[{i}].of = {p.of!r} names no orbit panel; panels: {ids}")

    def panel(self, id: str):
        """The panel with this id.

        Parameters
        ----------
        id : str
            Panel tag.

        Returns
        -------
        OrbitPanelResult or ZoomPanelResult
        """
        for p in self.panels:
            if p.id == id:
                return p
        raise KeyError(f"no panel {id!r}; panels: {[p.id for p in self.panels]}")


@dataclass(repr=False)
class HoveringAreaResult(SceneResult):
    """Result of a ``hovering_area`` scene.

    Attributes
    ----------
    series : list of SeriesResult
        One per curve.
    """

    series: list = field(default_factory=list)

    def _summary(self) -> list:
        eps = [float(e) for x in self.series for e in x.eps]
        rng = f"{min(eps):g}..{max(eps):g}" if eps else "none"
        return super()._summary() + [("series", [x.label for x in self.series]), ("eps", rng), ("points", len(eps))]

    def to_pandas(self):
        """The sweep as a :class:`pandas.DataFrame` (needs ``hovering[pandas]``): one row per
        (series label, eps), indexed by both; columns ``area``, ``error``, ``theory``,
        ``floor_touched``, ``K_low``, ``Omega0``, ``theta_w``.

        Returns
        -------
        pandas.DataFrame

        Raises
        ------
        ImportError
            Without pandas, naming ``pip install pandas`` and the extra ``.[pandas]``.
        """
        from .._interop import series_frame

        return series_frame(self)

    def to_xarray(self):
        """The sweep as an :class:`xarray.Dataset` (needs ``hovering[xarray]``): dimensions
        ``series`` (the labels) and ``eps`` (NaN where a series has no point at that eps), the
        columns of :meth:`to_pandas` as variables; units, the scene and provenance in attrs.

        Returns
        -------
        xarray.Dataset

        Raises
        ------
        ImportError
            Without xarray, naming ``pip install xarray`` and the extra ``.[xarray]``.
        """
        from .._interop import series_dataset

        return series_dataset(self)

    def _validate_loaded(self) -> None:
        super()._validate_loaded()
        for i, x in enumerate(self.series):
            if not isinstance(x, SeriesResult):
                raise ValueError(f"series[{i}] must be a SeriesResult, got {type(x).__name__}")


@dataclass(repr=False)
class FlowPortraitResult(SceneResult):
    """Result of a ``flow_portrait`` scene: the same starts under the flow and its model.

    Attributes
    ----------
    flow, model : OrbitSet
        The flow's orbits (FlowMap) and the truncated model's.
    flow_geometry, model_geometry : Geometry
        Measured corner curves and lines of the flow; closed forms of the model.
    onset : dict
        The onset parameters (Omega0, theta_w, tau0, tau1, lam).
    forcing : ndarray
        Sine coefficients of the measured forcing f.
    model_name : str
        ``"measured"`` or ``"first_mode"``.
    work : dict
        The flow's work counters, when the core reports them.
    """

    flow: OrbitSet = None
    model: OrbitSet = None
    flow_geometry: Geometry = None
    model_geometry: Geometry = None
    onset: dict = field(default_factory=dict)
    forcing: np.ndarray = None
    model_name: str = "measured"
    work: dict = field(default_factory=dict)


@dataclass(repr=False)
class FlowHoveringResult(SceneResult):
    """Result of a ``flow_hovering_area`` scene (one row per eps).

    Attributes
    ----------
    eps : ndarray
        The eps values.
    flow_area, flow_error, flow_both_sides : ndarray
        |HOV| of the flow, its error bar, and the part whose orbits visit both J_0 and J_0u.
    models : dict
        Model name -> ``{"area": ndarray, "error": ndarray, "agree": ndarray}`` (agree: fraction
        of the sample points with the flow's verdict).
    theory : ndarray
        eq:hovsetsize with the measured first forcing mode (0 on the sign that does not hover).
    K_low, b1, seconds, unresolved : ndarray
        Box floor, first forcing mode, the flow's seconds, its unresolved points.
    """

    eps: np.ndarray = None
    flow_area: np.ndarray = None
    flow_error: np.ndarray = None
    flow_both_sides: np.ndarray = None
    models: dict = field(default_factory=dict)
    theory: np.ndarray = None
    K_low: np.ndarray = None
    b1: np.ndarray = None
    seconds: np.ndarray = None
    unresolved: np.ndarray = None
    reused: int = 0

    def _summary(self) -> list:
        out = super()._summary() + [("eps", self.eps), ("models", list(self.models))]
        if self.flow_area is not None and len(self.flow_area):
            out.append(("flow_area", f"{np.nanmin(self.flow_area):.4g}..{np.nanmax(self.flow_area):.4g}"))
        return out

    def to_pandas(self):
        """The sweep as a :class:`pandas.DataFrame` (needs ``hovering[pandas]``): one row per eps
        (the index); the flow's columns (``flow_area``, ``flow_error``, ``flow_both_sides``,
        ``theory``, ``K_low``, ``b1``, ``seconds``, ``unresolved``) and ``{model}_{area, error,
        agree}`` for each model.

        Returns
        -------
        pandas.DataFrame

        Raises
        ------
        ImportError
            Without pandas, naming ``pip install pandas`` and the extra ``.[pandas]``.
        """
        from .._interop import flow_sweep_frame

        return flow_sweep_frame(self)

    def to_xarray(self):
        """The sweep as an :class:`xarray.Dataset` (needs ``hovering[xarray]``): the flow's
        columns over dimension ``eps``, each model's ``area``, ``error``, ``agree`` as
        ``model_area`` ... over (``model``, ``eps``); units, the scene and provenance in attrs.

        Returns
        -------
        xarray.Dataset

        Raises
        ------
        ImportError
            Without xarray, naming ``pip install xarray`` and the extra ``.[xarray]``.
        """
        from .._interop import flow_sweep_dataset

        return flow_sweep_dataset(self)


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


#: The corner's incoming directions (fig:corner_directions), as :data:`hovering.scenes.wall.DIRECTIONS`.
_DIRECTIONS = ("R0", "01", "1R")


def _status_name(where: str, value) -> None:
    from .._enums import FlowStatus

    _str(where, value, tuple(s.name for s in FlowStatus))


def _same_length(where: str, d: dict, keys, kinds: str = "iuf") -> None:
    """A dict of 1-D arrays under exactly ``keys``, all of one length."""
    if not isinstance(d, dict) or set(d) != set(keys):
        got = sorted(map(str, d)) if isinstance(d, dict) else type(d).__name__
        raise ValueError(f"{where} must hold the arrays {sorted(keys)}, got {got}")
    n = None
    for k in keys:
        _array(f"{where}.{k}", d[k], 1, "b" if k in ("reached",) else kinds)
        if n is None:
            n = d[k].shape
        elif d[k].shape != n:
            raise ValueError(f"{where}.{k} has shape {d[k].shape}; it must have shape {n} (as the arrays it goes with)")


def _trajectory(where: str, a) -> None:
    _array(where, a, 2)
    if a.shape[1] != 5:
        raise ValueError(f"{where} has shape {a.shape}; it must be (m, 5): t, q1, p1, q2, p2")


@dataclass
class CornerTrajectory:
    """A trajectory of the step system that arrives at the corner (fig:corner_directions).

    Attributes
    ----------
    direction : {"R0", "01", "1R"}
        Its incoming direction ``p_ab``.
    p1w : float
        The horizontal speed at the corner (eq:p2corner).
    start : ndarray
        Its point of Sigma_h, ``(q1, p1 = 0, q2, p2)``, found by the time-reversed smooth flow.
    theta, I, phi, K : float
        That point in section and normal coordinates.
    flight_time : float
        Time from the start to the corner (of the reversed trace).
    trajectory : ndarray
        ``(m, 5)`` rows ``t, q1, p1, q2, p2`` of the step system's flow from the start until it
        stopped (at the corner) or returned, sampled so that a sample falls at ``flight_time``.
    status : str
        :class:`~hovering.FlowStatus` name of that forward run (``CORNER`` when it hit the corner).
    arrival : ndarray
        The state of the forward run at ``flight_time`` (where it stopped, for a corner hit).
    """

    direction: str
    p1w: float
    start: np.ndarray
    theta: float
    I: float
    phi: float
    K: float
    flight_time: float
    trajectory: np.ndarray
    status: str
    arrival: np.ndarray

    def _validate_loaded(self) -> None:
        _str("direction", self.direction, _DIRECTIONS)
        _status_name("status", self.status)
        _array("start", self.start, 1, shape=(4,))
        _array("arrival", self.arrival, 1, shape=(4,))
        _trajectory("trajectory", self.trajectory)


@dataclass(repr=False)
class CornerDirectionsResult(SceneResult):
    """Result of a ``corner_directions`` scene (fig:corner_directions), all from the flow.

    Attributes
    ----------
    qw1, qw2 : float
        The corner.
    step_energy : float
        ``h_eps^w`` (def:heps).
    p1w_max : float
        ``sqrt(2 (h - h_eps^w))``: the radius of the momentum circle at the corner.
    curves : dict
        Direction -> arrays ``p1w``, ``theta``, ``I``, ``phi``, ``K`` (the corner-singularity curve of
        Sigma_h traced by the reversed flow, parametrized by p1w), ``reached`` (the step system's flow
        from that point hits the corner) and ``error`` (distance of its arrival from the corner).
    trajectories : list of CornerTrajectory
        The drawn trajectories, by direction and p1w.
    """

    qw1: float = 0.0
    qw2: float = 0.0
    step_energy: float = 0.0
    p1w_max: float = 0.0
    curves: dict = field(default_factory=dict)
    trajectories: list = field(default_factory=list)

    def _validate_loaded(self) -> None:
        super()._validate_loaded()
        if set(self.curves) != set(_DIRECTIONS):
            raise ValueError(f"curves must have the keys {list(_DIRECTIONS)}, got {sorted(map(str, self.curves))}")
        for k, c in self.curves.items():
            _same_length(f"curves.{k}", c, ("p1w", "theta", "I", "phi", "K", "reached", "error"))
        for i, t in enumerate(self.trajectories):
            if not isinstance(t, CornerTrajectory):
                raise ValueError(f"trajectories[{i}] must be a CornerTrajectory, got {type(t).__name__}")


@dataclass
class WallPoint:
    """A numbered point of the wall's tangency line and its trajectory (fig:Sigma_0_wall).

    Attributes
    ----------
    number : int
        The caption's number (1 and 7: above the corner; 2 and 6: at the corner; 3-5: below it).
    theta, q2, p2 : float
        The point (wall angle and its (q2, p2); p1 = 0 at q1 = qw1).
    trajectory : ndarray
        ``(m, 5)`` rows of the smooth flow through it, from Sigma_h to Sigma_h.
    status : str
        :class:`~hovering.FlowStatus` name of the step system's return from the same start.
    itinerary : str
        That return's itinerary.
    """

    number: int
    theta: float
    q2: float
    p2: float
    trajectory: np.ndarray
    status: str
    itinerary: str

    def _validate_loaded(self) -> None:
        if not 1 <= self.number <= 7:
            raise ValueError(f"number = {self.number!r} is out of range; allowed: 1 to 7")
        _status_name("status", self.status)
        _trajectory("trajectory", self.trajectory)
        if len(self.itinerary) > MAX_TEXT:
            raise ValueError(f"itinerary: a string of {len(self.itinerary)} characters; allowed: at most {MAX_TEXT}")


@dataclass(repr=False)
class WallTangencyResult(SceneResult):
    """Result of a ``wall_tangency`` scene (fig:Sigma_0_wall).

    Attributes
    ----------
    qw1, qw2 : float
        The corner.
    line : dict
        The tangency line ``Xi^0_wall``: arrays ``theta``, ``q2``, ``p2``.
    outer : dict
        The level ``H2 = h`` (outer edge of ``Sigma_h^>``): arrays ``q2``, ``p2``.
    points : list of WallPoint
        The seven numbered points.
    grid : dict
        Interior points in wall coordinates: arrays ``theta``, ``rho_w``, ``q2``, ``p2`` and
        ``region`` (the flow's label of the return through each).
    """

    qw1: float = 0.0
    qw2: float = 0.0
    line: dict = field(default_factory=dict)
    outer: dict = field(default_factory=dict)
    points: list = field(default_factory=list)
    grid: dict = field(default_factory=dict)

    def _validate_loaded(self) -> None:
        super()._validate_loaded()
        _same_length("line", self.line, ("theta", "q2", "p2"))
        _same_length("outer", self.outer, ("q2", "p2"))
        _same_length("grid", self.grid, ("theta", "rho_w", "q2", "p2", "region"))
        for i, p in enumerate(self.points):
            if not isinstance(p, WallPoint):
                raise ValueError(f"points[{i}] must be a WallPoint, got {type(p).__name__}")


@dataclass
class WallSegment:
    """A trajectory segment through a point of the wall section's fixed circle (fig:wallsection).

    Attributes
    ----------
    kind : str
        The region of the arc it starts on (``"R"``, ``"0"``, ``"1"``) or the corner-singularity
        curve it starts at (``"R0"``, ``"01"``, ``"1R"``).
    theta : float
        Its wall angle.
    wall : ndarray
        Its state on the wall section ``(qw1, p1, q2, p2)``.
    trajectory : ndarray
        ``(m, 5)`` rows of the step system's flow from its point of Sigma_h until it returned or
        stopped.
    status : str
        :class:`~hovering.FlowStatus` name of that return.
    itinerary : str
        Its itinerary.
    """

    kind: str
    theta: float
    wall: np.ndarray
    trajectory: np.ndarray
    status: str
    itinerary: str

    def _validate_loaded(self) -> None:
        _str("kind", self.kind, ("R", "0", "1") + _DIRECTIONS)
        _status_name("status", self.status)
        _array("wall", self.wall, 1, shape=(4,))
        _trajectory("trajectory", self.trajectory)
        if len(self.itinerary) > MAX_TEXT:
            raise ValueError(f"itinerary: a string of {len(self.itinerary)} characters; allowed: at most {MAX_TEXT}")


@dataclass(repr=False)
class WallSectionResult(SceneResult):
    """Result of a ``wall_section`` scene (fig:wallsection), all from the flow.

    Attributes
    ----------
    qw1, qw2 : float
        The corner.
    rho_w, rho_max : float
        The drawn circle and eq:rhomaxh.
    tangency : dict
        The tangency line ``rho_w = 0``: arrays ``theta``, ``q2``, ``p2``.
    circle : dict
        The circle's samples: arrays ``theta``, ``q2``, ``p2``, ``p1`` and ``region`` (the flow's
        label of the return through each).
    boundaries : dict
        ``"R0"``, ``"01"``, ``"1R"`` -> the bisected wall angle where the circle's label changes
        (R to 0, 0 to 1, 1 to R with increasing theta; NaN if not found).
    curves : dict
        The corner-singularity curves of the wall section: arrays ``rho_w`` (circles) and
        ``theta_R0``, ``theta_01``, ``theta_1R``, ``q2_R0``, ..., ``p2_1R`` (NaN where not found).
    segments : list of WallSegment
        The drawn trajectory segments.
    resolution : float
        Bracket width left by the bisections (radians).
    """

    qw1: float = 0.0
    qw2: float = 0.0
    rho_w: float = 0.0
    rho_max: float = 0.0
    tangency: dict = field(default_factory=dict)
    circle: dict = field(default_factory=dict)
    boundaries: dict = field(default_factory=dict)
    curves: dict = field(default_factory=dict)
    segments: list = field(default_factory=list)
    resolution: float = 0.0

    def _validate_loaded(self) -> None:
        super()._validate_loaded()
        _same_length("tangency", self.tangency, ("theta", "q2", "p2"))
        _same_length("circle", self.circle, ("theta", "q2", "p2", "p1", "region"))
        if set(self.boundaries) != set(_DIRECTIONS) or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in self.boundaries.values()
        ):
            raise ValueError(f"boundaries must map {list(_DIRECTIONS)} to numbers")
        _same_length(
            "curves", self.curves, ("rho_w",) + tuple(f"{c}_{d}" for c in ("theta", "q2", "p2") for d in _DIRECTIONS)
        )
        for i, p in enumerate(self.segments):
            if not isinstance(p, WallSegment):
                raise ValueError(f"segments[{i}] must be a WallSegment, got {type(p).__name__}")


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
        If the file is not a scene result of this package.
    """
    obj = _serial.load(path)
    if not isinstance(obj, SceneResult):
        raise ValueError(
            f"{os.fspath(path)} holds a {type(obj).__name__}, not a scene result "
            "(written by `python -m hovering scene`)"
        )
    return obj


def _orbits(o: OrbitSet) -> list:
    out = []
    for i, lab in enumerate(o.labels):
        K = o.K[i]
        d = dict(
            label=lab,
            kind=o.kinds[i],
            phi0=float(o.phi[i, 0]),
            K0=float(K[0]),
            K_min=float(np.nanmin(K)),
            K_max=float(np.nanmax(K)),
            status=Status(int(o.status[i])).name,
            steps=int(o.steps_done[i]),
        )
        if o.rho is not None:
            d["rho"] = float(o.rho[i])
        if o.region is not None:
            reg = o.region[i]
            d["impacts"] = int(
                np.count_nonzero((reg == int(Region.UPPER)) | (reg == int(Region.RIGHT)) | (reg == int(Region.MULTI)))
            )
            d["hovering"] = bool(d["impacts"] == 0 and d["K_min"] < 0 and o.status[i] == int(Status.OK))
        out.append(d)
    return out


def _region_counts(region) -> dict:
    if region is None:
        return {}
    return {Region(r).label: int(np.count_nonzero(region == int(r))) for r in Region if r != Region.NONE}


@dataclass
class ZoneStudy:
    """One map's answer to "does anything cross the impact zone?" (an ``impact_zone`` scene).

    Attributes
    ----------
    name : str
        ``"flow"`` or the model's name.
    zone : ImpactZone
        Its floor and ceiling.
    scan : BarrierScan
        Layers and barriers along the scene's line (with ``keep`` points of each orbit).
    up, down : TransitResult
        Orbits from s = 0.05 towards the ceiling and from s = 0.95 towards the floor.
    seconds : dict
        Seconds per stage (``zone``, ``scan``, ``transit``).
    """

    name: str = ""
    zone: ImpactZone = None
    scan: BarrierScan = None
    up: TransitResult = None
    down: TransitResult = None
    seconds: dict = field(default_factory=dict)

    def _validate_loaded(self) -> None:
        for k in ("zone", "scan", "up", "down"):
            want = ImpactZone if k == "zone" else BarrierScan if k == "scan" else TransitResult
            if not isinstance(getattr(self, k), want):
                raise ValueError(f"{k} must be a {want.__name__}, got {type(getattr(self, k)).__name__}")
        if len(self.name) > MAX_TEXT:
            raise ValueError(f"name: a string of {len(self.name)} characters; allowed: at most {MAX_TEXT}")

    def summary(self) -> dict:
        """The numbers of the study, JSON-able: layers, barriers, transit fractions and extremes.

        Returns
        -------
        dict
        """
        sc = self.scan
        out = dict(
            name=self.name,
            floor=self.zone.floor_kind,
            starts=len(sc),
            n_steps=sc.n_steps,
            classes={k: int(np.count_nonzero(sc.kind == k)) for k in ("circle", "islands", "chaotic", "undecided")},
            barriers=[float(b) for b in sc.barriers],
            layers=[
                dict(
                    s_start=list(ly.s_start),
                    s=[ly.s_min, ly.s_max],
                    kind=ly.kind,
                    periods=list(ly.periods),
                    impacting=ly.impacting,
                )
                for ly in sc.layers
            ],
            spanning=int(sc.spanning(0.1, 0.9).size),
            seconds=self.seconds,
        )
        for d in ("up", "down"):
            t = getattr(self, d)
            rate = t.escape_rate
            out[d] = dict(
                orbits=int(t.crossed.size),
                n_steps=t.n_steps,
                start_s=t.start_s,
                target_s=t.target_s,
                crossed=int(np.count_nonzero(t.crossed)),
                fraction=t.fraction,
                fraction_error=t.fraction_error,
                s_reached=float(np.nanmax(t.s_max) if d == "up" else np.nanmin(t.s_min)),
                escape_rate=list(rate) if rate is not None else None,
            )
        return out


@dataclass
class ImpactZoneResult(SceneResult):
    """Result of an ``impact_zone`` scene: the flow's and its model's :class:`ZoneStudy`.

    Attributes
    ----------
    flow, model : ZoneStudy
        The two studies.
    model_name : str
        ``"measured"`` or ``"first_mode"``.
    onset : dict
        The onset parameters (Omega0, theta_w, tau0, tau1, lam).
    b1 : float
        First mode of the measured forcing: the model acts with eps b1.
    """

    flow: ZoneStudy = None
    model: ZoneStudy = None
    model_name: str = "measured"
    onset: dict = field(default_factory=dict)
    b1: float = float("nan")

    def _validate_loaded(self) -> None:
        super()._validate_loaded()
        for k in ("flow", "model"):
            if not isinstance(getattr(self, k), ZoneStudy):
                raise ValueError(f"{k} must be a ZoneStudy, got {type(getattr(self, k)).__name__}")


def summarize(result) -> dict:
    """The numbers a scene result shows, as a JSON-able dict.

    Parameters
    ----------
    result : SceneResult
        Any scene result.

    Returns
    -------
    dict
        ``scene``, ``kind``, ``title``, ``quick``, ``n_steps`` (when it has one), ``runtime_s`` and
        per kind: ``panels`` (orbit scenes), ``series`` (hovering_area), ``flow`` / ``model``
        (flow_portrait), ``points`` (flow_hovering_area), ``tori`` (tangent_tori), ``regions``
        (sigma_structure), ``curves`` and ``arrivals`` (corner_directions), ``tangency_points``
        and ``regions`` (wall_tangency), ``boundaries``, ``arcs`` and ``segments`` (wall_section).
    """
    sc, meta = result.scene, result.meta
    s = dict(
        scene=sc.name,
        kind=sc.kind,
        title=sc.title,
        quick=bool(meta.get("quick")),
        runtime_s=float(meta.get("timings", {}).get("total", float("nan"))),
    )
    for k in ("n_steps", "samples", "points_reused", "checkpoint", "grid", "accuracy"):
        if k in meta:
            s[k] = meta[k]
    if isinstance(result, OrbitSceneResult):
        panels = []
        for p in result.panels:
            if isinstance(p, OrbitPanelResult):
                info = dict(
                    id=p.id,
                    params=p.params,
                    K_crit=p.K_crit,
                    rho_crit=p.rho_crit,
                    band_floor=p.band_floor,
                    orbits=_orbits(p.orbits),
                    n_escaped=int(np.count_nonzero(p.orbits.status == int(Status.ESCAPED))),
                    xlim=list(p.xlim),
                    ylim=list(p.ylim),
                    n_orbits_drawn=p.orbits.n_orbits,
                )
                if p.critical is not None:
                    info["critical"] = p.critical
            else:
                info = dict(id=p.id, zoom_of=p.of, window=p.window)
            panels.append(info)
        s["panels"] = panels
    elif isinstance(result, HoveringAreaResult):
        s["series"] = [
            dict(
                label=r.label,
                golden_c=r.golden_c,
                points=[
                    dict(
                        eps=float(e),
                        area=float(a),
                        error=float(er),
                        theory=float(t),
                        floor_touched=bool(f),
                        K_low=float(kl),
                        Omega0=float(O),
                        theta_w=float(tw),
                    )
                    for e, a, er, t, f, kl, O, tw in zip(
                        r.eps, r.area, r.error, r.theory, r.floor_touched, r.K_low, r.Omega0, r.theta_w
                    )
                ],
            )
            for r in result.series
        ]
    elif isinstance(result, FlowPortraitResult):
        s.update(onset=result.onset, forcing=result.forcing[:3], model_name=result.model_name, work=result.work)
        for name, o in (("flow", result.flow), ("model", result.model)):
            s[name] = dict(
                orbits=_orbits(o),
                regions=_region_counts(o.region),
                statuses={Status(int(v)).name: int(np.count_nonzero(o.status == v)) for v in np.unique(o.status)},
            )
    elif isinstance(result, FlowHoveringResult):
        pts = []
        for i, e in enumerate(result.eps):
            d = dict(
                eps=float(e),
                flow=float(result.flow_area[i]),
                flow_error=float(result.flow_error[i]),
                flow_both_sides=float(result.flow_both_sides[i]),
                theory=float(result.theory[i]),
                K_low=float(result.K_low[i]),
                b1=float(result.b1[i]),
                seconds=float(result.seconds[i]),
                unresolved=int(result.unresolved[i]),
            )
            d["models"] = {m: {k: float(v[i]) for k, v in cols.items()} for m, cols in result.models.items()}
            pts.append(d)
        s["points"] = pts
    elif isinstance(result, TangentToriResult):
        s["tori"] = [
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
        s.update(qw1=result.qw1, qw2=result.qw2, status=meta.get("status", {}), work=meta.get("work", {}))
    elif isinstance(result, SigmaStructureResult):
        s["regions"] = _region_counts(result.region)
        s["points"] = int(result.phi.size)
    elif isinstance(result, CornerDirectionsResult):
        s.update(corner=[result.qw1, result.qw2], step_energy=result.step_energy, p1w_max=result.p1w_max)
        s["curves"] = {
            k: dict(
                points=int(c["p1w"].size),
                reached=int(np.count_nonzero(c["reached"])),
                max_error=float(np.nanmax(c["error"])) if np.isfinite(c["error"]).any() else None,
                K_range=[float(np.nanmin(c["K"])), float(np.nanmax(c["K"]))] if np.isfinite(c["K"]).any() else None,
            )
            for k, c in result.curves.items()
        }
        s["arrivals"] = [
            dict(
                direction=t.direction,
                p1w=t.p1w,
                status=t.status,
                phi=t.phi,
                K=t.K,
                flight_time=t.flight_time,
                error=float(np.hypot(t.arrival[0] - result.qw1, t.arrival[2] - result.qw2)),
                momentum=[float(t.arrival[1]), float(t.arrival[3])],
            )
            for t in result.trajectories
        ]
    elif isinstance(result, WallTangencyResult):
        s["tangency_points"] = [
            dict(number=p.number, theta=p.theta, q2=p.q2, p2=p.p2, status=p.status, itinerary=p.itinerary)
            for p in result.points
        ]
        s["regions"] = _region_counts(result.grid["region"])
    elif isinstance(result, ImpactZoneResult):
        s.update(onset=result.onset, b1=result.b1, model_name=result.model_name)
        s["flow"], s["model"] = result.flow.summary(), result.model.summary()
    elif isinstance(result, WallSectionResult):
        b = result.boundaries
        two_pi = 2 * math.pi
        s.update(
            rho_w=result.rho_w,
            rho_max=result.rho_max,
            boundaries=b,
            resolution=result.resolution,
            arcs={
                "R": (b["R0"] - b["1R"]) % two_pi,
                "0": (b["01"] - b["R0"]) % two_pi,
                "1": (b["1R"] - b["01"]) % two_pi,
            },
            circle_regions=_region_counts(result.circle["region"]),
            curve_points={k: int(np.count_nonzero(np.isfinite(result.curves[f"theta_{k}"]))) for k in _DIRECTIONS},
            segments=[
                dict(kind=g.kind, theta=g.theta, status=g.status, itinerary=g.itinerary) for g in result.segments
            ],
        )
    return jsonable(s)
