"""What the kinds of the physical flow share: the ``[system]``, ``[section]``, ``[integrator]`` and
``[outputs]`` tables (declared once here, read by the generic reader for every flow kind), the
checks between them, and the flow's map and measured lines a kind computes from.

A flow scene names its effects: what its tables do not ask for is not simulated (geometry "none":
no wall events; eps = 0: no coupling; no "regions": no crossing bookkeeping; no "trajectory": no
dense output).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..._core import flow as _core_flow
from ..._io.serial import saved_as
from ...diagnostics.tolerance import accurate_flow_map
from ...flow.potentials import COMPILED, POTENTIAL_KINDS
from ...flow.section import STEPPERS, flow_options
from ...flow.system import Bilinear, Polynomial, StepSystem
from ...normal.corners import corner_curves
from ...normal.flowmap import FlowMap
from ..base import Geometry, SceneSpec
from ..fields import OMIT, choice, custom, real, table
from ..fields import integer as integer_field
from ..values import integer, text
from ..values import real as real_value
from ..wall import WallFlow, corner_energy

__all__ = [
    "PotentialSpec",
    "SystemSpec",
    "IntegratorSpec",
    "OutputsSpec",
    "FlowScene",
    "needs_step",
    "above_corner",
    "flowmap",
    "flow_geometry",
    "wall_flow",
    "work",
]


# ------------------------------------------------------------------ [system.V1], [system.V2]
# The kinds, their parameters and ranges are the core's registry of compiled potentials
# (hovering.flow.potentials.POTENTIAL_KINDS): a kind added there is a kind of scene files, with its
# parameters as keys, and nothing here changes.

_KINDS = {k.kind: k for k in POTENTIAL_KINDS}
_CLASSES = {k.kind: c for k, c in zip(POTENTIAL_KINDS, COMPILED)}
# Each parameter name once, declared with the range of the first kind that has it; a kind whose
# own range of that name differs is checked against it by _of_kind.
_PARAMS: dict = {}
for _k in POTENTIAL_KINDS:
    for _p in _k.params:
        _PARAMS.setdefault(_p.name, _p)


def _of_kind(name: str):
    """The check of parameter ``name``: required by the kinds that have it, refused by the others."""

    def check(where: str, value, reading) -> None:
        kind = _KINDS[reading.values["kind"]]
        own = [p for p in kind.params if p.name == name]
        if own:
            if value is None:
                raise ValueError(f"{reading.where}: missing required key {name!r} for kind = {kind.kind!r}")
            p = own[0]
            if not p.lo <= value <= p.hi:
                raise ValueError(
                    f"{where} = {value!r} is out of range; allowed: [{p.lo:g}, {p.hi:g}] for kind = {kind.kind!r}"
                )
        elif name in reading.table:
            users = " or ".join(repr(k.kind) for k in POTENTIAL_KINDS if any(p.name == name for p in k.params))
            raise ValueError(f"{reading.where}: {name!r} is only used with kind = {users}, got kind = {kind.kind!r}")

    return check


def _build_potential(self):
    """The compiled potential: the class of its kind, given its parameters in the kind's order.

    Returns
    -------
    hovering.Potential
        ``hovering.Harmonic``, ``hovering.Tan``, ... (the registry's class of ``kind``).
    """
    return _CLASSES[self.kind](*(getattr(self, p.name) for p in _KINDS[self.kind].params))


_POTENTIAL_DOC = f"""One oscillator's potential: a compiled kind of the core's registry and its parameters.

    Attributes
    ----------
    kind : {{{", ".join(repr(k) for k in _KINDS)}}}
        {"; ".join(f"{k.kind}: {k.formula}" for k in POTENTIAL_KINDS)}.
    {", ".join(_PARAMS)} : float or None
        The kind's parameters, in its order ({"; ".join(f"{k.kind}: {', '.join(p.name for p in k.params)}" for k in POTENTIAL_KINDS)}); None where the kind has no parameter of that name.
    """

#: One oscillator's potential (``[system.V1]``, ``[system.V2]``): its fields are ``kind`` and the
#: parameters of every compiled kind (the registry's names), built here from the registry.
PotentialSpec = dataclasses.make_dataclass(
    "PotentialSpec",
    [
        ("kind", str, choice(choices=tuple(_KINDS))),
        *((name, "float | None", real(None, lo=p.lo, hi=p.hi, check=_of_kind(name))) for name, p in _PARAMS.items()),
    ],
    namespace={"build": _build_potential, "__doc__": _POTENTIAL_DOC},
    frozen=True,
)
PotentialSpec.__module__ = __name__
PotentialSpec = saved_as("hovering.scenes.spec:PotentialSpec")(PotentialSpec)


#: The coupling ``"bilinear"``: Vc = q1 q2.
BILINEAR = ((1.0, 1, 1),)


def _coupling(where: str, value, reading) -> tuple:
    """``"bilinear"``, ``"none"`` or terms ``[[c, i, j], ...]`` (``c q1^i q2^j``), each power once."""
    if value == "bilinear":
        return BILINEAR
    if value == "none":
        return ()
    if not isinstance(value, list) or not value or len(value) > 64:
        raise ValueError(
            f"{where} must be 'bilinear', 'none' or a list of 1..64 terms [c, i, j] (c q1^i q2^j), got {value!r}"
        )
    terms = []
    first: dict = {}  # (i, j) -> the entry that gave it
    for k, term in enumerate(value):
        tw = f"{where}[{k}]"
        if not isinstance(term, list) or len(term) != 3:
            raise ValueError(f"{tw} must be a term [c, i, j] (c q1^i q2^j), got {term!r}")
        c = real_value(f"{tw}[0]", term[0])
        i, j = integer(f"{tw}[1]", term[1], 0, 20), integer(f"{tw}[2]", term[2], 0, 20)
        if (i, j) in first:
            # A dict of terms would keep only the last: the first coefficient would vanish silently.
            raise ValueError(
                f"{tw} = {term!r} repeats the term q1^{i} q2^{j} of {where}[{first[(i, j)]}]; allowed: each "
                f"power (i, j) once (write the sum of the coefficients as one term)"
            )
        first[(i, j)] = k
        terms.append((c, i, j))
    return tuple(terms)


def _coupling_value(coupling: tuple, kind) -> object:
    return "bilinear" if coupling == BILINEAR else "none" if coupling == () else [list(t) for t in coupling]


@saved_as("hovering.scenes.spec:SystemSpec")
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

    V1: PotentialSpec = table(PotentialSpec, required=True)
    V2: PotentialSpec = table(PotentialSpec, required=True)
    coupling: tuple = custom(
        BILINEAR, read=_coupling, write=_coupling_value, allowed="'bilinear', 'none' or 1..64 terms [c, i, j]"
    )
    eps: float = real(0.0, lo=-10.0, hi=10.0)
    qw1: float = real(-1.0, hi=0.0, hi_open=True)
    qw2: float = real(-0.5, hi=0.0, hi_open=True)
    geometry: str = choice("step", ("none", "wall", "step"))

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
        elif self.coupling == BILINEAR:
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


def _accuracy_alone(where: str, accuracy, reading) -> None:
    """An accuracy target picks the stepper and tolerances: the table gives one or the other."""
    both = sorted({"stepper", "rtol", "atol"} & set(reading.table))
    if "accuracy" in reading.table and both:
        raise ValueError(
            f"{reading.where}: 'accuracy' picks the stepper and tolerances itself; remove {both} or 'accuracy'"
        )


#: The core's integrator defaults (``FlowOptions{}``): the one place they are written.
_CORE = _core_flow.FlowOptions()


def _default_atol(where: str, reading) -> float:
    """An absent atol: the core's policy for the table's rtol."""
    return _core_flow.default_atol(reading.get("rtol"))


@saved_as("hovering.scenes.spec:IntegratorSpec")
@dataclass(frozen=True)
class IntegratorSpec:
    """The integrator of a flow scene (GSL odeiv2 stepper and tolerances).

    Attributes
    ----------
    stepper : str
        One of :data:`hovering.flow.STEPPERS` (default the core's, ``auto``: ``taylor`` where it
        applies, V1 and V2 each Harmonic or Tan, else ``rk8pd``; results record the one that ran), e.g. ``exact`` (the
        closed-form flow: eps = 0 with Harmonic/Tan potentials, or Harmonic ones with a bilinear
        coupling; it ignores the tolerances).
    rtol, atol : float
        Tolerances of the step control (default the core's; atol defaults to the core's policy
        for the given rtol, ``hovering._core.flow.default_atol``: rtol's).
    accuracy : float or None
        An accuracy target instead (``accuracy = 1e-9`` in [integrator]): the map is built at the
        fastest setting measured to reach it (:func:`hovering.diagnostics.accurate_flow_map`).
    event_tol, max_steps, max_impacts, grazing_tol, corner_tol, verify_steps : optional
        The rest of :class:`~hovering.FlowMap`'s integrator options (``Section.return_map``
        documents each), with an accuracy target too; default the core's (``FlowOptions{}``:
        1e-15, 1000000, 100, 1e-12, 1e-10, -1).
    """

    stepper: str = choice(_CORE.stepper, STEPPERS)
    rtol: float = real(_CORE.rtol, lo=1e-15, hi=1e-2)
    atol: float = real(_CORE.atol, lo=1e-15, hi=1e-2, default_from=_default_atol)
    accuracy: float | None = real(None, lo=1e-13, hi=1e-2, check=_accuracy_alone)
    # The ranges are the core's (FlowOptions::validate), the bounds made finite where a TOML
    # number needs one.
    event_tol: float = real(_CORE.event_tol, lo=0.0, hi=1.0, lo_open=True)
    max_steps: int = integer_field(_CORE.max_steps, lo=1, hi=2**62)
    max_impacts: int = integer_field(_CORE.max_impacts, lo=1, hi=1000000)
    grazing_tol: float = real(_CORE.grazing_tol, lo=0.0, hi=1.0)
    corner_tol: float = real(_CORE.corner_tol, lo=0.0, hi=1.0)
    verify_steps: int = integer_field(_CORE.verify_steps, lo=-1, hi=2**62)

    def events(self) -> dict:
        """The options besides the stepper and tolerances (what an accuracy target leaves to the
        scene), as keyword arguments of :class:`~hovering.FlowMap`.

        Returns
        -------
        dict
            ``event_tol``, ``max_steps``, ``max_impacts``, ``grazing_tol``, ``corner_tol``,
            ``verify_steps``: the counts as Python ints, the tolerances as floats, whatever a spec
            built in code holds (a plan's checkpoint key has the C++ reader's types).
        """
        return dict(
            event_tol=float(self.event_tol),
            max_steps=int(self.max_steps),
            max_impacts=int(self.max_impacts),
            grazing_tol=float(self.grazing_tol),
            corner_tol=float(self.corner_tol),
            verify_steps=int(self.verify_steps),
        )

    def options(self) -> dict:
        """The explicit setting, as keyword arguments of :class:`~hovering.FlowMap` (with an
        accuracy target, the setting is measured: see :meth:`flow_map`).

        Returns
        -------
        dict
            ``stepper``, ``rtol``, ``atol`` and :meth:`events`.
        """
        return dict(stepper=self.stepper, rtol=self.rtol, atol=self.atol, **self.events())

    def label(self, system: StepSystem | None = None, ran: dict | None = None) -> str:
        """What runs, in a figure's words: the setting a result recorded (``ran``), else the
        stepper (``auto`` resolved on the system, as a :class:`~hovering.FlowMap` resolves it) and
        rtol, or the accuracy target (whose setting is measured when the map is built).

        Parameters
        ----------
        system : StepSystem, optional
            The system the integrator runs on (needed without ``ran``).
        ran : dict, optional
            A recorded setting with ``stepper`` and ``rtol`` (:attr:`FlowMap.integrator_options`).

        Returns
        -------
        str
            E.g. ``"taylor rtol 1e-10"``, ``"exact (closed form)"`` (no tolerance) or
            ``"accuracy target 1e-09"``.
        """
        if ran is not None:
            stepper, rtol = ran["stepper"], float(ran["rtol"])
        elif self.accuracy is not None:
            return f"accuracy target {self.accuracy:g}"
        else:
            stepper = (
                flow_options(rtol=self.rtol, atol=self.atol, stepper=self.stepper).resolved_for(system.core).stepper
            )
            rtol = self.rtol
        return "exact (closed form)" if stepper == "exact" else f"{stepper} rtol {rtol:g}"

    def flow_map(self, system, h: float, coordinates: str = "normal") -> FlowMap:
        """The flow's map with this integrator: the explicit setting, or for an accuracy target the
        fastest setting measured to reach it (:func:`hovering.diagnostics.accurate_flow_map`).

        Parameters
        ----------
        system : StepSystem
            The system.
        h : float
            Energy of the section.
        coordinates : {"normal", "section"}, optional
            The map's coordinates.

        Returns
        -------
        FlowMap
        """
        if self.accuracy is not None:
            return accurate_flow_map(system, h, self.accuracy, coordinates=coordinates, **self.events())
        return FlowMap(system, h=h, coordinates=coordinates, **self.options())


def _record(where: str, value, reading) -> tuple:
    """What is recorded: names the kind allows, those its figure is drawn from included."""
    allowed, required = reading.kind.records
    if not isinstance(value, list):
        raise ValueError(f"{where} must be a list of names from {list(allowed)}, got {value!r}")
    for r in value:
        text(where, r, allowed)
    missing = [r for r in required if r not in value]
    if missing:
        raise ValueError(f"{where} = {value!r} lacks {missing}: a {reading.kind.name} figure is drawn from them")
    return tuple(sorted(set(value)))


def _default_record(where: str, reading) -> tuple:
    # What the kind's figure is drawn from, and the regions whenever it can colour by them.
    allowed, required = reading.kind.records
    return tuple(sorted(set(required) | ({"regions"} & set(allowed))))


def _dt_needs_trajectory(where: str, dt, reading) -> None:
    if "trajectory_dt" in reading.table and "trajectory" not in reading.kind.records[0]:
        raise ValueError(f"{where} is only used by scenes that record 'trajectory'")


def _dt_value(dt: float, kind) -> object:
    return dt if kind is not None and "trajectory" in kind.records[0] else OMIT


@saved_as("hovering.scenes.spec:OutputsSpec")
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

    record: tuple = custom(("regions",), read=_record, default_from=_default_record, allowed="the kind's records")
    trajectory_dt: float = real(0.02, lo=1e-4, hi=10.0, check=_dt_needs_trajectory, write=_dt_value)


def _system_builds(where: str, system: SystemSpec, reading) -> None:
    try:
        system.build()
    except ValueError as e:
        raise ValueError(f"{where}: {e}") from None


def _h_above_step(where: str, h: float, reading) -> None:
    # Normal coordinates (every flow figure but the tori) need the tangential band: h above the
    # step energy; the tori need both tangent tori, which exist for the same h.
    hw = reading.values["system"].build().step_energy
    if not h > hw:
        raise ValueError(
            f"{where} = {h!r} is out of range; allowed: above the step energy "
            f"V1(qw1) + V2(qw2) + eps Vc(qw1, qw2) = {hw:.6g} (no tangency band below it)"
        )


def _integrator_table(ig: IntegratorSpec, kind) -> dict:
    head = (
        {"accuracy": ig.accuracy}
        if ig.accuracy is not None
        else {"stepper": ig.stepper, "rtol": ig.rtol, "atol": ig.atol}
    )
    return {**head, **ig.events()}


@dataclass(frozen=True, kw_only=True)
class FlowScene(SceneSpec):
    """What every scene of the physical flow has: its effects.

    Attributes
    ----------
    system : SystemSpec
        Potentials, coupling, eps, the step and which walls exist.
    h : float
        Energy of the section Sigma_h (``[section] h``).
    integrator : IntegratorSpec
        Stepper and tolerances.
    outputs : OutputsSpec
        What is recorded.
    """

    system: SystemSpec = table(SystemSpec, required=True, check=_system_builds)
    h: float = real(1.0, lo=0.0, lo_open=True, in_table="section", check=_h_above_step)
    integrator: IntegratorSpec = table(IntegratorSpec, write=_integrator_table)
    outputs: OutputsSpec = table(OutputsSpec)


def needs_step(where: str, values: dict) -> None:
    """A kind that draws the regions of the step needs the step's two walls (a kind's
    :attr:`~hovering.scenes.registry.Kind.check`).

    Parameters
    ----------
    where : str
        The scene, for the message.
    values : dict
        The fields read so far (``kind``, ``system``).

    Raises
    ------
    ValueError
        For another geometry, naming it.
    """
    system = values["system"]
    if system.geometry != "step":
        raise ValueError(
            f"{where}.system.geometry = {system.geometry!r}: a {values['kind']} scene draws the regions of "
            f"the step; allowed: 'step'"
        )


def above_corner(where: str, values: dict) -> None:
    """A kind about the corner (or the wall section) needs orbits that reach the corner: h above
    the energy at rest there (def:heps).

    Parameters
    ----------
    where : str
        The scene, for the message.
    values : dict
        The fields read so far (``system``, ``h``).

    Raises
    ------
    ValueError
        Naming ``section.h``, its value and the energy it must exceed.
    """
    h, hw = values["h"], corner_energy(values["system"].build())
    if not h > hw:
        raise ValueError(
            f"{where}.section.h = {h!r} is out of range; allowed: above the energy at rest at the corner "
            f"V1(qw1) + V2(qw2) + eps Vc(qw1, qw2) = {hw:.6g} (def:heps: below it no orbit reaches the "
            f"corner)"
        )


# ------------------------------------------------------------------------------------------------
# What the flow kinds compute from


def flowmap(scene, eps: float | None = None, coordinates: str = "normal") -> FlowMap:
    """The scene's :class:`~hovering.FlowMap`: its system (optionally at another eps), section and integrator.

    Parameters
    ----------
    scene : FlowScene
        The scene.
    eps : float, optional
        Override of ``system.eps``.
    coordinates : {"normal", "section"}, optional
        The map's coordinates.

    Returns
    -------
    FlowMap
    """
    return scene.integrator.flow_map(scene.system.build(eps=eps), scene.h, coordinates)


def work(res) -> dict:
    """The core's work counters of a run, as plain ints (empty when it reports none).

    Parameters
    ----------
    res : object
        An iterate or return-map result.

    Returns
    -------
    dict
    """
    w = getattr(res, "work", None)
    return {} if w is None else {k: int(v) for k, v in dict(w).items()}


def flow_geometry(fm, K_range, n_circles: int, rtol: float, n: int = 200) -> Geometry:
    """K = 0, L1, L2 of a FlowMap and its corner curves measured on ``n_circles`` circles K < 0.

    Parameters
    ----------
    fm : FlowMap
        The flow's map (normal coordinates, geometry "step").
    K_range : (float, float)
        Heights drawn.
    n_circles : int
        Circles on which the corner curves are bisected (0: none).
    rtol : float
        Integration tolerance of the measurement.
    n : int, optional
        Samples of L1, L2.

    Returns
    -------
    Geometry
    """
    lo = fm.valid_band()[0]
    K = np.linspace(max(K_range[0], 0.95 * lo), K_range[1], n)
    corners, Kc = {}, np.zeros(0)
    if n_circles > 0 and K_range[0] < 0:
        top = min(K_range[1], 0.0)
        Kc = np.linspace(max(K_range[0], 0.95 * lo), top, n_circles + 1)[:-1] if top > K_range[0] else Kc
        if Kc.size:
            cc = corner_curves(fm.section, Kc, fm.curve, n_phi=256, bisections=30, rtol=max(rtol, 1e-13))
            corners = {"01": cc.phi_01, "1R": cc.phi_1R, "R0": cc.phi_R0}
    return Geometry(
        K=K,
        L1=np.asarray(fm.L1(K), dtype=float),
        L2=np.asarray(fm.L2(K), dtype=float),
        K_corner=Kc,
        corners=corners,
        measured=True,
    )


def wall_flow(scene, fm=None) -> WallFlow:
    """The scene's step system and integrator settings for the wall-section computations (an
    accuracy target resolved by its FlowMap).

    Parameters
    ----------
    scene : FlowScene
        The scene.
    fm : FlowMap, optional
        Its map, if already built.

    Returns
    -------
    WallFlow
    """
    if scene.integrator.accuracy is not None:
        opts = (fm if fm is not None else flowmap(scene)).integrator_options
    else:
        opts = scene.integrator.options()
    return WallFlow(scene.system.build(), opts)
