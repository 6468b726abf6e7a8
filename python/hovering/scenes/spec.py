"""Validated scene specifications: one frozen class per kind, no field a kind does not use.

These are the output of :mod:`hovering.scenes.schema` (TOML -> spec) and the input of
:mod:`hovering.scenes.compute` (spec -> results). A spec is plain data: it saves with the result
(:mod:`hovering._serial`) so a figure can be redrawn from the file alone.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from ..flow.system import Bilinear, Harmonic, Polynomial, StepSystem, Tan
from ..interface import hook
from ..truncated.maps import TruncatedMap
from ..truncated.theory import golden_family

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
    "Scene",
    "figure_inches",
]

#: Scene kinds of the truncated map (sec:truncatedmapnum).
TRUNCATED_KINDS = ("portrait", "critical_orbits", "hovering_area")
#: Scene kinds of the physical flow.
FLOW_KINDS = (
    "flow_portrait",
    "flow_hovering_area",
    "tangent_tori",
    "sigma_structure",
    "corner_directions",
    "wall_tangency",
    "wall_section",
    "impact_zone",
)
#: Every kind of scene.
KINDS = TRUNCATED_KINDS + FLOW_KINDS

#: The paper's four special initial conditions (sec:truncatedmapnumact), in legend order.
SPECIAL_ORBITS = ("blue", "orange", "green", "red")

#: Iterate counts (and hovering-area samples) are divided by this in ``quick`` runs.
QUICK_FACTOR = 50


# ------------------------------------------------------------------------------------------------
# The truncated map


@dataclass(frozen=True)
class MapSpec:
    """Parameters of one truncated map F_eps.

    Attributes
    ----------
    eps : float
        Perturbation amplitude.
    Omega0, theta_w, tau0, tau1, lam : float
        Map parameters (``Omega0, theta_w`` from the golden family when ``golden_c`` is set).
    golden_c : float or None
        Family parameter c of thm:hoveringc, if the panel uses the golden family.
    golden_eps : float or None
        The eps at which the golden-family ``(Omega0, theta_w)`` were computed (may differ from
        ``eps``: fig:epsbig d uses the eps = 0.92 parameters at eps = -0.92).
    """

    eps: float
    Omega0: float
    theta_w: float
    tau0: float = 1.0
    tau1: float = 0.5
    lam: float = 0.5
    golden_c: float | None = None
    golden_eps: float | None = None

    def build(self):
        """The :class:`~hovering.TruncatedMap` with these parameters.

        Returns
        -------
        TruncatedMap
        """
        return TruncatedMap(self.eps, self.Omega0, self.theta_w, self.tau0, self.tau1, self.lam)

    def as_dict(self) -> dict:
        """Parameters as a plain dict (for summaries and checkpoint keys).

        Returns
        -------
        dict
        """
        d = dict(eps=self.eps, Omega0=self.Omega0, theta_w=self.theta_w, tau0=self.tau0, tau1=self.tau1, lam=self.lam)
        if self.golden_c is not None:
            d.update(golden_c=self.golden_c, golden_eps=self.golden_eps)
        return d


@dataclass(frozen=True)
class OrbitSpec:
    """An extra orbit of a ``critical_orbits`` panel.

    Attributes
    ----------
    label : str
        Legend label (unique in the panel).
    K0 : float
        Initial height.
    phi0 : float or None
        Initial angle, or None when the orbit starts on ``line``.
    line : {"L1", "L2"} or None
        Start on this line at height K0.
    color : str or None
        Matplotlib colour (default: the next of C5, C6, ...).
    """

    label: str
    K0: float
    phi0: float | None = None
    line: str | None = None
    color: str | None = None


@dataclass(frozen=True)
class CriticalSpec:
    """Search of the critical curve of a panel (:func:`hovering.analysis.critical_curve`).

    Attributes
    ----------
    n_steps : int
        Iterates per tested orbit (default: the scene's, so that the critical orbit drawn is
        exactly the one that passed the test).
    K_range : tuple of float or None
        Heights searched on the line (default: the analysis module's).
    line : {"L1", "L2"}
        Search line.
    color : str
        Colour of the critical orbit.
    """

    n_steps: int
    K_range: tuple | None = None
    line: str = "L1"
    color: str = "C4"


@dataclass(frozen=True)
class ZoomSpec:
    """A zoom panel drawn from another panel's orbits (nothing is recomputed).

    Attributes
    ----------
    of : str
        Id of the panel zoomed into.
    on : {"critical", "islands", "fixed"}
        How the window is chosen: around the dip of the critical curve below K = 0, around the
        impacting points of the ``orbits`` named, or ``xlim``/``ylim`` as given.
    orbits : tuple of str
        Orbit labels for ``on = "islands"``.
    pad : float
        Margin added on each side, as a fraction of the window found.
    xlim, ylim : tuple of float or None
        The window for ``on = "fixed"``.
    """

    of: str
    on: str = "critical"
    orbits: tuple = ()
    pad: float = 0.5
    xlim: tuple | None = None
    ylim: tuple | None = None


@dataclass(frozen=True)
class PanelSpec:
    """One panel (axes) of an orbit scene.

    Attributes
    ----------
    id : str
        Panel tag, shown in its title ("(a)").
    map : MapSpec or None
        The map (None for a zoom panel).
    special : tuple of str
        Which of :data:`SPECIAL_ORBITS` to draw (``critical_orbits`` scenes).
    orbits : tuple of OrbitSpec
        Extra orbits.
    critical : CriticalSpec or None
        Whether (and how) to search and draw the critical curve.
    zoom : ZoomSpec or None
        Set for a zoom panel.
    n_orbits : int
        Orbits started on ``line`` (``portrait`` scenes).
    K0_range : tuple of float or None
        Their initial heights (``portrait`` scenes).
    xlim, ylim : tuple of float or None
        Axes limits (default: the full circle and the range of the orbits).
    """

    id: str
    map: MapSpec | None = None
    special: tuple = ()
    orbits: tuple = ()
    critical: CriticalSpec | None = None
    zoom: ZoomSpec | None = None
    n_orbits: int = 0
    K0_range: tuple | None = None
    xlim: tuple | None = None
    ylim: tuple | None = None


@dataclass(frozen=True)
class SeriesSpec:
    """One curve of a ``hovering_area`` scene: a map family over the scene's eps values.

    Attributes
    ----------
    label : str
        Legend label.
    Omega0, theta_w, tau0, tau1, lam : float or None
        Fixed parameters (``Omega0, theta_w`` None when ``golden_c`` is set).
    golden_c : float or None
        Use the golden family of thm:hoveringc: ``(Omega0, theta_w)`` recomputed at each eps.
    color : str or None
        Matplotlib colour.
    K_low : float or None
        Bottom of the sampled box ``[-pi, pi) x [K_low, 0)`` (default: the analysis module's,
        ``-2|eps|/|sin(Omega0/2)|``, which holds the critical band of eq:hovsetsize); set it near
        the band floor to measure HOV by its definition over the whole band.
    """

    label: str
    Omega0: float | None
    theta_w: float | None
    tau0: float = 1.0
    tau1: float = 0.5
    lam: float = 0.5
    golden_c: float | None = None
    color: str | None = None
    K_low: float | None = None

    def map_at(self, eps: float) -> MapSpec:
        """The map of this series at one eps.

        Parameters
        ----------
        eps : float
            Perturbation amplitude.

        Returns
        -------
        MapSpec
        """
        if self.golden_c is not None:
            O, tw = golden_family(eps, self.golden_c, self.tau0)
            return MapSpec(eps, O, tw, self.tau0, self.tau1, self.lam, self.golden_c, eps)
        return MapSpec(eps, self.Omega0, self.theta_w, self.tau0, self.tau1, self.lam)


# ------------------------------------------------------------------------------------------------
# The physical flow: the effects a scene names


@dataclass(frozen=True)
class PotentialSpec:
    """One oscillator's potential.

    Attributes
    ----------
    kind : {"harmonic", "tan"}
        ``omega^2 q^2 / 2`` or ``(omega / alpha)^2 tan^2(alpha q) / 2``.
    omega : float
        Frequency at the bottom of the well.
    alpha : float or None
        Tan only: the well's width parameter (walls at ``|q| = pi / (2 alpha)``).
    """

    kind: str
    omega: float
    alpha: float | None = None

    def build(self):
        """The compiled potential.

        Returns
        -------
        hovering.Harmonic or hovering.Tan
        """
        return Harmonic(self.omega) if self.kind == "harmonic" else Tan(self.omega, self.alpha)


@dataclass(frozen=True)
class SystemSpec:
    """The oscillators-step system ``H = H1 + H2 + eps Vc`` of a flow scene.

    Attributes
    ----------
    V1, V2 : PotentialSpec
        The oscillators.
    coupling : tuple of (float, int, int)
        Terms ``c q1^i q2^j`` of Vc (``"bilinear"`` is ``((1, 1, 1),)``); never evaluated at eps = 0.
    eps : float
        Coupling strength (a ``flow_hovering_area`` scene overrides it per point).
    qw1, qw2 : float
        The step's corner.
    geometry : {"none", "wall", "step"}
        Which walls exist: "none" integrates the smooth flow with no event search for walls.
    """

    V1: PotentialSpec
    V2: PotentialSpec
    coupling: tuple = ((1.0, 1, 1),)
    eps: float = 0.0
    qw1: float = -1.0
    qw2: float = -0.5
    geometry: str = "step"

    def build(self, eps: float | None = None, geometry: str | None = None):
        """The :class:`~hovering.StepSystem` (optionally at another eps or geometry).

        Parameters
        ----------
        eps : float, optional
            Override of ``eps``.
        geometry : str, optional
            Override of ``geometry``.

        Returns
        -------
        StepSystem

        Raises
        ------
        ValueError
            For a coupling that lists a power (i, j) twice (a scene file cannot: the schema
            refuses it), naming both terms.
        """
        if not self.coupling:
            c = None
        elif self.coupling == ((1.0, 1, 1),):
            c = Bilinear()
        else:
            terms: dict = {}
            for k, (v, i, j) in enumerate(self.coupling):
                if (int(i), int(j)) in terms:
                    raise ValueError(
                        f"coupling[{k}] = {(v, i, j)!r} repeats the power q1^{i} q2^{j} of coupling"
                        f"[{list(terms).index((int(i), int(j)))}]; allowed: each power (i, j) once"
                    )
                terms[(int(i), int(j))] = float(v)
            c = Polynomial(terms)
        return StepSystem(
            V1=self.V1.build(),
            V2=self.V2.build(),
            coupling=c,
            eps=self.eps if eps is None else eps,
            qw1=self.qw1,
            qw2=self.qw2,
            geometry=self.geometry if geometry is None else geometry,
        )


@dataclass(frozen=True)
class IntegratorSpec:
    """The integrator of a flow scene (GSL odeiv2 stepper and tolerances).

    Attributes
    ----------
    stepper : str
        ``rk8pd`` (default), ``rkck``, ``rkf45``, ``rk4``, ``rk2``, ``msadams`` or ``exact`` (the
        closed-form flow: eps = 0 with Harmonic/Tan potentials, or Harmonic ones with a bilinear
        coupling; it ignores the tolerances).
    rtol, atol : float
        Tolerances of the step control (atol defaults to rtol).
    accuracy : float or None
        An accuracy target instead (``accuracy = 1e-9`` in [integrator]): the map picks the
        fastest setting measured to reach it (:class:`~hovering.FlowMap` ``accuracy``).
    """

    stepper: str = "rk8pd"
    rtol: float = 1e-10
    atol: float = 1e-10
    accuracy: float | None = None

    def options(self) -> dict:
        """Keyword arguments of :class:`~hovering.FlowMap`.

        Returns
        -------
        dict
        """
        if self.accuracy is not None:
            return dict(accuracy=self.accuracy)
        return dict(stepper=self.stepper, rtol=self.rtol, atol=self.atol)


@dataclass(frozen=True)
class OutputsSpec:
    """What a flow scene records: nothing else is computed.

    Attributes
    ----------
    record : tuple of str
        Subset of ``"regions"`` (region labels: crossing bookkeeping of q1 = qw1), ``"trajectory"``
        (dense samples of the flow between returns), ``"section"`` (theta, I of every point),
        ``"states"``.
    trajectory_dt : float
        Time between trajectory samples.
    """

    record: tuple = ("regions",)
    trajectory_dt: float = 0.02


# ------------------------------------------------------------------------------------------------
# Scenes


@dataclass(frozen=True, kw_only=True)
class SceneSpec:
    """What every scene has (see :func:`hovering.scenes.load_scene`).

    Attributes
    ----------
    path : Path or None
        The file it was read from.
    name : str
        The file's stem (or ``"scene"``).
    kind : str
        One of :data:`KINDS`.
    title : str
        Figure title.
    output : Path
        PNG path (relative paths are relative to the working directory).
    dpi : int
        PNG resolution.
    figsize : tuple of float or None
        Figure size in inches (default from the layout).
    """

    path: Path | None = None
    name: str = "scene"
    kind: str
    title: str
    output: Path
    dpi: int = 130
    figsize: tuple | None = None

    def _validate_loaded(self) -> None:
        """A spec read from a file (:func:`hovering.load`) gets the checks a scene file gets (the
        schema, above the spec, registers them as the ``check_spec`` hook)."""
        hook("check_spec")(self)


@dataclass(frozen=True, kw_only=True)
class OrbitScene(SceneSpec):
    """``portrait`` and ``critical_orbits`` scenes of the truncated map.

    Attributes
    ----------
    n_steps : int
        Iterates per orbit.
    layout : tuple of int or None
        ``(rows, cols)`` of the panels (default: one column).
    panels : tuple of PanelSpec
        The panels.
    rotation : str
        ``"mean"`` (the paper's rho) or ``"birkhoff"`` (weighted average).
    color_by : str
        ``"orbit"`` or ``"region"`` (portrait scenes).
    marker_size : float
        Scatter marker size.
    corner_curves : bool
        Draw the corner-singularity curves (dashed black).
    leading_curve : bool
        Draw the leading-order curve ``k_{eps,1}(phi; 0)`` / ``k_{eps,2}(phi; 0)``.
    line : str
        Start line of portrait orbits.
    """

    n_steps: int
    layout: tuple | None = None
    panels: tuple = ()
    rotation: str = "mean"
    color_by: str = "orbit"
    marker_size: float = 0.3
    corner_curves: bool = True
    leading_curve: bool = True
    line: str = "L1"


@dataclass(frozen=True, kw_only=True)
class HoveringAreaScene(SceneSpec):
    """``hovering_area`` scene of the truncated map: |HOV| against eps.

    Attributes
    ----------
    n_steps : int
        The N of "never impacts within N steps".
    eps : tuple of float
        The eps values.
    samples : int
        Sample points per eps.
    seed : int
        Sampling seed.
    series : tuple of SeriesSpec
        The curves.
    """

    n_steps: int
    eps: tuple = ()
    samples: int = 100_000
    seed: int = 0
    series: tuple = ()


@dataclass(frozen=True, kw_only=True)
class FlowScene(SceneSpec):
    """What every scene of the physical flow has: its effects.

    Attributes
    ----------
    system : SystemSpec
        Potentials, coupling, eps, the step and which walls exist.
    h : float
        Energy of the section Sigma_h.
    integrator : IntegratorSpec
        Stepper and tolerances.
    outputs : OutputsSpec
        What is recorded.
    """

    system: SystemSpec
    h: float = 1.0
    integrator: IntegratorSpec = field(default_factory=IntegratorSpec)
    outputs: OutputsSpec = field(default_factory=OutputsSpec)


@dataclass(frozen=True, kw_only=True)
class FlowPortraitScene(FlowScene):
    """``flow_portrait``: the full return map and its truncated model side by side.

    Attributes
    ----------
    n_steps : int
        Returns per orbit (the same count of truncated-map steps).
    n_orbits : int
        Orbits started on the flow's L1.
    K0_range : tuple of float
        Their initial heights.
    model : {"measured", "first_mode"}
        The truncated model: onset arcs with the measured forcing, or its first mode (F_eps).
    corner_K : int
        Circles on which the flow's corner-singularity curves are measured (0: not drawn).
    marker_size : float
        Scatter marker size.
    """

    n_steps: int
    n_orbits: int = 12
    K0_range: tuple = (-0.1, 0.05)
    model: str = "measured"
    corner_K: int = 12
    marker_size: float = 0.5


@dataclass(frozen=True, kw_only=True)
class FlowHoveringScene(FlowScene):
    """``flow_hovering_area``: |HOV| against eps for the flow, its models and eq:hovsetsize.

    Attributes
    ----------
    n_steps : int
        Returns (and model steps) of "never impacts".
    eps : tuple of float
        The eps values (``system.eps`` is replaced by each).
    samples : int
        Sample points per eps (the same points for the flow and the models).
    seed : int
        Sampling seed.
    models : tuple of str
        Truncated models drawn: ``"onset"`` (onset arcs, measured forcing: ``FlowMap.truncated()``)
        and ``"measured"`` (arcs measured on the flow's corner curves,
        :func:`hovering.truncated_from_flow`).
    """

    n_steps: int
    eps: tuple = ()
    samples: int = 1000
    seed: int = 0
    models: tuple = ("onset", "measured")


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

    n_returns: int = 3
    n_points: int = 400


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

    grid: tuple = (240, 60)
    K_range: tuple = (-0.12, 0.03)
    marker_size: float = 1.0


@dataclass(frozen=True, kw_only=True)
class CornerDirectionsScene(FlowScene):
    """``corner_directions`` (fig:corner_directions): the three directions that reach the corner.

    On the energy surface h the corner is reached with momenta ``p_R0 = (-p1w, P2)``,
    ``p_01 = (p1w, -P2)``, ``p_1R = (-p1w, -P2)``, ``P2 = sqrt(2 (h - h_eps^w) - p1w^2)``
    (eq:p2corner); each is followed back by the smooth flow to its point of Sigma_h, and forward
    again by the step system's flow to the corner.

    Attributes
    ----------
    p1w_fractions : tuple of float
        The ``p1w`` of the trajectories drawn, as fractions of ``p1w_max = sqrt(2 (h - h_eps^w))``,
        each in (0, 1).
    n_curve : int
        Values of ``p1w`` on which each corner-singularity curve of Sigma_h is traced.
    """

    p1w_fractions: tuple = (0.3, 0.7)
    n_curve: int = 48


@dataclass(frozen=True, kw_only=True)
class WallTangencyScene(FlowScene):
    """``wall_tangency`` (fig:Sigma_0_wall): the tangency line of the wall section and its trajectories.

    The unperturbed wall section ``Sigma_h^{*,-}`` in the (q2, p2) plane: the tangency line
    ``Xi^0_wall`` (trajectories that touch q1 = qw1), its seven points of the paper's caption and
    their trajectories, and the regions of its interior ``Sigma_h^{w,-}`` labelled by the flow.

    Attributes
    ----------
    grid : tuple of int
        ``(n_theta, n_rho)`` points of the interior labelled by the flow (wall coordinates).
    n_points : int
        Samples of the tangency line.
    marker_size : float
        Scatter marker size of the labelled points.
    """

    grid: tuple = (180, 40)
    n_points: int = 400
    marker_size: float = 2.0


@dataclass(frozen=True, kw_only=True)
class WallSectionScene(FlowScene):
    """``wall_section`` (fig:wallsection): the wall section's corner-singularity curves and a fixed circle.

    In the wall coordinates ``(theta, rho_w)`` of ``Sigma_h^{w,-}`` (eq:rhow): the curves
    ``sigma_R0^-, sigma_01^-, sigma_1R^-`` measured on circles ``rho_w = const`` by bisection of the
    flow's region labels, one circle's arcs J_R, J_0, J_1, and trajectory segments from it.

    Attributes
    ----------
    rho_w_fraction : float
        The drawn circle's ``rho_w`` as a fraction of ``rho_max(h)`` (eq:rhomaxh), in (0, 1].
    n_theta : int
        Angles labelled on that circle.
    n_circles : int
        Circles on which the corner-singularity curves are measured.
    bisections : int
        Bisection steps per boundary (resolution ``2 pi / n / 2^bisections``).
    segments : int
        Trajectory segments drawn per region of the circle.
    """

    rho_w_fraction: float = 0.5
    n_theta: int = 720
    n_circles: int = 16
    bisections: int = 30
    segments: int = 2


@dataclass(frozen=True, kw_only=True)
class ImpactZoneScene(FlowScene):
    """``impact_zone``: does anything cross the impact zone? The flow and its model side by side.

    For each map (the flow's return map and its truncated model): the zone between the critical
    curve and the floor (:func:`hovering.impact_zone`), a :func:`hovering.barrier_scan` along a
    symmetry line (layers by class, two-sided barriers) and :func:`hovering.transit` up from near
    the floor and down from near the ceiling.

    Attributes
    ----------
    n_starts : int
        Starts of the barrier scan.
    n_steps : int
        Returns per orbit of the scan (steps of the model).
    transit_orbits : int
        Orbits per transit direction.
    transit_steps : int
        Returns per transit orbit (the model gets ``model_factor`` times more steps).
    model_factor : int
        How many more steps the model's orbits get than the flow's (it is ~1000x cheaper per step).
    model : {"measured", "first_mode"}
        The truncated model.
    line : {"L1", "L2"}
        Where the scan's starts lie.
    critical_steps : int
        Iterates per tested orbit of the critical-curve search (the zone's ceiling).
    keep : int
        Points of each scan orbit drawn.
    """

    n_starts: int = 40
    n_steps: int = 20_000
    transit_orbits: int = 40
    transit_steps: int = 100_000
    model_factor: int = 20
    model: str = "measured"
    line: str = "L1"
    critical_steps: int = 20_000
    keep: int = 2000


#: Old name of the truncated orbit scenes' spec (kept for one release).
Scene = SceneSpec


#: Figure size (inches) of the kinds with a fixed grid of axes, when the scene gives no ``figsize``.
_FIGSIZE = {
    "hovering_area": (13.0, 5.2),
    "flow_portrait": (13.0, 5.6),
    "flow_hovering_area": (13.0, 5.2),
    "tangent_tori": (12.0, 8.0),
    "sigma_structure": (12.0, 12.0),
    "corner_directions": (12.0, 10.0),
    "wall_tangency": (18.0, 6.2),
    "wall_section": (12.0, 10.0),
    "impact_zone": (14.0, 10.0),
}


def figure_inches(scene, n_panels: int = 1) -> tuple:
    """Width and height (inches) of a scene's figure: its ``figsize``, or its kind's and layout's default.

    Parameters
    ----------
    scene : SceneSpec
        The scene.
    n_panels : int, optional
        Its number of panels (orbit scenes without a layout: one column of them).

    Returns
    -------
    tuple of float
    """
    if scene.figsize is not None:
        return tuple(scene.figsize)
    if scene.kind in _FIGSIZE:
        return _FIGSIZE[scene.kind]
    rows, cols = scene.layout if scene.layout is not None else (n_panels, 1)
    return (6.0 * cols + 1.0, 4.6 * rows + 0.6)
