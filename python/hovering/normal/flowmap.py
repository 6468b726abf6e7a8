"""The flow's return map to Sigma_h as a map you iterate: :class:`FlowMap`.

It has the map interface of :class:`hovering.TruncatedMap` (``step``, ``step_inverse``,
``region``, ``iterate -> IterateResult`` with the same records, statuses, regions and early exit),
so every analysis (rotation numbers, regularity, hovering area, critical curve) runs on it
unchanged. Iterations run in C++ on the core's thread pool with no Python between returns.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from .._checks import MAX_MODES, check_memory, flag, forcing_array, integer, is_choice, plain_point, point_pair
from .._core import normal as _core_normal
from .._core import wrap as _core_wrap
from .._deprecated import call_moved, moved_argument, moved_method
from .._enums import Region, wrap
from .._io.records import reduce_record
from .._io.serial import Saveable
from .._progress import check_progress, progress_bar, stop_hook
from ..flow.section import EVENT_OPTIONS, Section, _threads, flow_options
from ..flow.system import StepSystem, onset_parameters
from ..interface import (
    MAX_TRAJECTORY_POINTS,
    IterateResult,
    MapAnalyses,
    StepJacobian,
    iterate_arguments,
    recorded_counts,
    trajectory_arguments,
    transport_arguments,
)
from ..truncated import theory as _theory  # the module (hovering.truncated does not export the function)
from ..truncated.maps import TruncatedFamily, TruncatedMap
from .coordinates import TangentialCurve

__all__ = ["FlowMap", "FlowSteps", "FLOW_RECORD_KEYS"]

#: What :meth:`FlowMap.iterate` can record (nothing else is computed or stored).
FLOW_RECORD_KEYS = (
    "orbit",
    "regions",
    "rotation",
    "visited",
    "section",
    "states",
    "times",
    "energy_error",
    "steps",
    "itinerary",
    "trajectory",
    "extrema",
    "residence",
    "jacobian",
)


@dataclass(frozen=True)
class FlowSteps(Saveable):
    """One return of many points (:meth:`FlowMap.returns`), with what the flow reported.

    Attributes
    ----------
    phi, K : ndarray
        Images in map coordinates (NaN where the status is not OK).
    status : ndarray of int8
        :class:`FlowStatus` of each return (OFF_SECTION: the point has no point of Sigma_h).
    region : ndarray of int8
        :class:`Region` of each return (NONE unless OK).
    itinerary : list of str
        Impacts in order, or '0' / 'u' for a return without impact.
    time, energy_error : ndarray
        Return times and ``|H(image) - h|``.
    steps : ndarray of int64
        Accepted integrator steps.
    z : ndarray
        The image states (q1, p1, q2, p2), shape (n, 4).

    Examples
    --------
    >>> import hovering
    >>> fm = hovering.paper.flow_map(eps=-0.05)
    >>> st = fm.returns([0.3, 0.3], [-0.02, -0.2])      # one return of two points
    >>> st.status.tolist(), st.region.tolist(), st.itinerary
    ([0, 0], [1, 1], ['0', '0'])
    >>> print(f"{st.phi[0]:.3f} {st.K[0]:.4f}")
    -2.487 -0.0026
    >>> st.z.shape
    (2, 4)
    """

    phi: np.ndarray
    K: np.ndarray
    status: np.ndarray
    region: np.ndarray
    itinerary: list
    time: np.ndarray
    energy_error: np.ndarray
    steps: np.ndarray
    z: np.ndarray


#: The eps at which the forcing's eps -> 0 limit is measured (a FlowMap at eps = 0).
_EPS_LIMIT = 1e-6

#: Where the flow's core names a field of IterateResult otherwise (its states are (x, y) = (phi, K)
#: or (theta, I)).
_CORE_NAMES = {"phi": "x", "K": "y", "phi_final": "x_final", "K_final": "y_final", "K_min": "y_min", "K_max": "y_max"}


class FlowMap(MapAnalyses):
    """The impact flow's return map to Sigma_h on normal coordinates (phi, K) (or (theta, I)).

    Each return starts on Sigma_h at energy h exactly (the image's coordinates are computed and
    the next point of Sigma_h is solved from them), so iterating is bit for bit the same as
    repeated :meth:`step`, and the energy error of the integrator does not accumulate.

    Parameters
    ----------
    sys : StepSystem
        The system (any geometry; regions need walls).
    h : float
        Energy of the section.
    coordinates : {"normal", "section"}, optional
        ``"normal"``: ``(phi, K) = (theta, I - I_tan^eps(theta))`` (eq:kphidef) from the measured
        tangential curve, which must be a graph over theta (else a ValueError says so; use
        ``"section"``). ``"section"``: ``(theta, I)`` of the unperturbed H2.
    rtol : float, optional
        Relative tolerance of the integrator (GSL step control; default the core's, 1e-10).
    atol : float, optional
        Absolute tolerance (default: the core's policy, ``FlowOptions::default_atol``: rtol's; the
        flow's variables are O(1) here, and an atol below rtol only tightens the steps where a
        momentum crosses zero: at rtol 1e-10, atol 1e-12 costs 17% more steps for a 2.5x smaller
        error per return).
    stepper : str, optional
        One of :data:`hovering.flow.STEPPERS` (default the core's, ``"auto"``: ``"taylor"`` where
        Taylor's method applies, V1 and V2 each Harmonic or Tan, else ``"rk8pd"``; the map keeps and
        shows the one chosen), or ``"exact"`` for the closed-form flow (see
        :meth:`hovering.Section.return_map`; it ignores rtol and atol).
    curve : TangentialCurve, optional
        The tangential curve of this section (measured at rtol 1e-13 if not given, with as many
        wall points as its interpolation error below 1e-12 needs).
    accuracy, accuracy_returns : float, int, optional
        Deprecated (removed in 0.4.0): an accuracy target is resolved above the models, by
        :func:`hovering.diagnostics.accurate_flow_map` ``(sys, h, accuracy, returns)``, which
        measures the fastest setting that reaches it and builds the map with it.
    **options
        ``event_tol``, ``max_steps``, ``max_impacts``, ``grazing_tol``, ``corner_tol``,
        ``verify_steps`` (see :meth:`hovering.Section.return_map`).

    Raises
    ------
    ValueError
        For bad parameters (named, with the allowed range), or normal coordinates where the
        tangential curve is not a graph.

    Notes
    -----
    A FlowMap pickles and saves (:func:`hovering.save`) as its constructor arguments and its
    tangential curve's measured samples: it is rebuilt through the constructor with that curve (no
    trace of the flow, no measurement) and steps bit for bit as the original.

    Examples
    --------
    The README's system: a harmonic and a Tan oscillator, bilinear coupling, the step at
    (qw1, qw2) = (-1, -0.5), on the section at energy h = 1:

    >>> import hovering
    >>> system = hovering.StepSystem(hovering.Harmonic(1.0), hovering.Tan(1.4, 0.7), hovering.Bilinear(), eps=-0.05)
    >>> fm = hovering.FlowMap(system, h=1.0)
    >>> print(repr(fm).split("# ")[1])      # what its truncated model will see
    effective eps = eps b1 = -0.0282 (b1 = 0.5639), band K in [-0.2966, 0.2638]
    >>> fm.region(0.3, -0.02)               # J_0: this return passes above the step
    <Region.ABOVE: 1>
    >>> th = fm.theory()                    # leading order, from the onset parameters and measured forcing
    >>> th.hovers, round(th.area, 4)
    (True, 0.0745)
    >>> model = fm.truncated()              # its truncated model (every measured forcing mode)
    >>> type(model).__name__
    'TruncatedFamily'
    """

    #: Unit of work of this map's progress reports (one return of the flow).
    _progress_unit = "return"

    #: Regularity threshold of the critical-curve search (digits of agreement of the two half-orbit
    #: rotation averages): the integration error of each return caps invariant curves at 7-9.
    regularity_digits = 6.0

    def __init__(
        self,
        sys: StepSystem,
        h: float = 1.0,
        coordinates: str = "normal",
        rtol: float | None = None,
        atol: float | None = None,
        stepper: str | None = None,
        curve: TangentialCurve | None = None,
        accuracy: float | None = None,
        accuracy_returns: int = 1,
        **options,
    ):
        if not isinstance(sys, StepSystem):
            raise ValueError(f"sys must be a hovering.StepSystem, got {sys!r}")
        if not is_choice(coordinates, ("normal", "section")):
            raise ValueError(f"coordinates must be 'normal' or 'section', got {coordinates!r}")
        self.section = Section(sys, h)
        self.sys, self.h, self.coordinates = sys, self.section.h, coordinates
        unknown = set(options) - set(EVENT_OPTIONS)
        if unknown:
            raise ValueError(f"unknown option(s) {sorted(unknown)}; allowed: {', '.join(EVENT_OPTIONS)}")
        #: What an accuracy target chose (:func:`hovering.diagnostics.accurate_flow_map` sets it;
        #: None without one): the row of the measurement.
        self.accuracy_choice = None
        if accuracy is not None:
            # The old form: measuring is the harness's business, two layers up. It is found by
            # name through the deprecation module only, as long as the old form lives.
            moved_argument("FlowMap", "accuracy", "hovering.diagnostics.accurate_flow_map(sys, h, accuracy, returns)")
            self.accuracy_choice = call_moved(
                "hovering.diagnostics.tolerance.choose_setting", self.section, accuracy, accuracy_returns
            )
            stepper, rtol = self.accuracy_choice["method"], self.accuracy_choice["tolerance"]
            atol = rtol
        # None: the core's default (its FlowOptions{} and default_atol, the one policy).
        self._options = flow_options(rtol=rtol, atol=atol, stepper=stepper, **options)
        self._options.validate_for(sys.core)  # before the tangential curve is measured
        # "auto" resolved once, here: integrator_options, the repr and saved records name the stepper that runs.
        self._options = o = self._options.resolved_for(sys.core)
        self.integrator_options = dict(rtol=float(o.rtol), atol=float(o.atol), stepper=o.stepper, **options)
        #: Why there are no onset parameters (None when there are): below the step energy, or
        #: too close to it for them to be accurate (onset_parameters raises rather than guess).
        self.onset_error = None
        try:
            self.onset = onset_parameters(sys, self.h)
        except ValueError as e:
            self.onset, self.onset_error = None, str(e)  # no tangential band or no accurate one: no lift model
        self.curve = None
        if coordinates == "normal":
            self.curve = curve if curve is not None else TangentialCurve(self.section, rtol=1e-13)
            if not isinstance(self.curve, TangentialCurve) or self.curve.sec.sys != sys or self.curve.sec.h != self.h:
                raise ValueError("curve must be the TangentialCurve of this system at this h")
            if not self.curve.is_graph:
                raise ValueError(self.curve.not_graph_reason)
        p = self.onset
        lift = None if p is None else (p.Omega0, p.theta_w, p.tau0, p.tau1, p.lam)
        self._core = _core_normal.FlowMap(sys.core, self.h, self._options, self.curve._c if self.curve else None, lift)
        self._forcing = None
        self._delta = None  # the tangential curve's measured error (forcing_tolerance), on first use

    def __repr__(self) -> str:
        base = (
            f"FlowMap({self.sys!r}, h={self.h!r}, coordinates={self.coordinates!r}, "
            f"stepper={self._options.stepper!r}, rtol={self._options.rtol!r})"
        )
        # What a user needs before reading any result: the perturbation the truncated model sees is
        # eps b1 (the measured forcing's first mode), not eps - or, where b1 vanishes within its
        # measurement error, that the higher modes act; and where points of Sigma_h exist. A
        # comment, so the text still evaluates to the map.
        lo, hi = self.valid_band()
        if self.coordinates != "normal" or self.eps == 0:
            return f"{base}  # band {'K' if self.coordinates == 'normal' else 'I'} in [{lo:.4g}, {hi:.4g}]"
        band = f"band K in [{lo:.4g}, {hi:.4g}]"
        try:
            b = self.forcing_coefficients()
            tol = self.forcing_tolerance()
        except ValueError:  # a tangential curve that is not a graph has no forcing: say so
            return f"{base}  # eps b1 undefined (the tangential curve is not a graph), {band}"
        b1 = float(b[0])
        if abs(b1) > tol:
            text = f"effective eps = eps b1 = {self.eps * b1:.4g} (b1 = {b1:.4g})"
        else:
            higher = [(k + 1, float(x)) for k, x in enumerate(b) if k > 0 and abs(x) > tol]
            if higher:
                k, x = max(higher, key=lambda kx: abs(kx[1]))
                text = (
                    f"b1 = {b1:.2g} is 0 within its error {tol:.2g}: the first mode vanishes (no first-order "
                    f"forcing), the higher modes act (largest: eps b{k} = {self.eps * x:.4g}, b{k} = {x:.4g})"
                )
            else:
                text = (
                    f"no forcing: every b_k is 0 within its error {tol:.2g} (K is preserved: the circles K = const "
                    "are invariant)"
                )
        geometry = ""
        if self.sys.geometry == "wall":
            geometry = "; geometry 'wall': no step corner, every K < 0 start impacts, nothing hovers"
        elif self.sys.geometry == "none":
            geometry = "; geometry 'none': no walls, nothing impacts or hovers"
        return f"{base}  # {text}, {band}{geometry}"

    # ---------------------------------------------------------------- pickling and saving
    # A FlowMap is rebuilt from its constructor arguments, with its tangential curve passed in: the
    # curve pickles (and saves) as its measured samples, so unpickling neither traces the flow nor
    # measures anything; the onset parameters (closed forms or a few quadratures) are recomputed by
    # the constructor. The same doubles go through the same construction: the rebuilt map steps bit
    # for bit as the original. Other instance attributes (the forcing cache, a subclass's own) are
    # restored as they were.

    _OWN = frozenset(
        {
            "section",
            "sys",
            "h",
            "coordinates",
            "_options",
            "integrator_options",
            "onset",
            "onset_error",
            "curve",
            "_core",
        }
    )

    def __reduce__(self):
        """Pickle as the record (system, h, coordinates, integrator options, the curve's samples, the
        forcing cache) and the other instance attributes."""
        return reduce_record(self, {k: v for k, v in self.__dict__.items() if k not in self._OWN | {"_forcing"}})

    def _to_record(self) -> dict:
        """What :func:`hovering.save` writes: system, h, coordinates, integrator options, the curve's samples
        (not its system again: it is this map's) and the forcing cache."""
        return {
            "sys": self.sys,
            "h": self.h,
            "coordinates": self.coordinates,
            "options": dict(self.integrator_options),
            "curve": None if self.curve is None else self.curve._samples(),
            "forcing": self._forcing,
        }

    #: Entries of the record derived from the others (the forcing fit of the curve): not part of
    #: the map's identity in a checkpoint key (:func:`hovering._io.serial.record_key`).
    _RECORD_CACHE = ("forcing",)

    #: The integrator options a saved FlowMap holds (:attr:`integrator_options`): a file's options
    #: are these or nothing, never an ``accuracy`` target (that would measure, i.e. compute, on load).
    _RECORD_OPTIONS = frozenset(
        {
            "rtol",
            "atol",
            "stepper",
            "event_tol",
            "max_steps",
            "max_impacts",
            "grazing_tol",
            "corner_tol",
            "verify_steps",
        }
    )

    @classmethod
    def _from_record(cls, record: dict) -> FlowMap:
        """Inverse of :meth:`_to_record`: validated again, and rebuilt from the stored values only (no
        flow is traced, no accuracy target measured: a record asking for either is refused)."""
        sys, h = record["sys"], record["h"]
        if not isinstance(sys, StepSystem):
            raise ValueError(f"the FlowMap's sys must be a StepSystem, got {type(sys).__name__}")
        options = record["options"]
        if not isinstance(options, dict):
            raise ValueError(f"the FlowMap's options must be a dict, got {type(options).__name__}")
        unknown = sorted(set(options) - cls._RECORD_OPTIONS)
        if unknown:
            raise ValueError(
                f"the FlowMap's options {unknown} are not stored settings; allowed: "
                f"{sorted(cls._RECORD_OPTIONS)} (a saved map holds the setting an accuracy target chose, "
                f"never the target: reading a file does not measure)"
            )
        if not is_choice(record["coordinates"], ("normal", "section")):
            raise ValueError(f"the FlowMap's coordinates must be 'normal' or 'section', got {record['coordinates']!r}")
        curve = None
        if record["curve"] is not None:
            curve = TangentialCurve._from_samples(Section(sys, h), record["curve"])
        elif record["coordinates"] == "normal":
            raise ValueError(
                "the FlowMap is in normal coordinates but the file holds no tangential curve (a saved "
                "map holds its measured curve; reading a file does not measure one)"
            )
        forcing = record["forcing"]
        if forcing is not None:
            forcing = np.asarray(forcing_array(forcing), dtype=float)
        return _restore_flowmap(cls, sys, h, record["coordinates"], options, curve, {"_forcing": forcing})

    # ---------------------------------------------------------------- the map interface

    @property
    def eps(self) -> float:
        """Coupling strength eps of the system."""
        return self.sys.eps

    def returns(self, phi, K, inverse: bool = False, n_threads: int = 0) -> FlowSteps:
        """One return (or, with ``inverse``, one step back) of many points, with the flow's report.

        Parameters
        ----------
        phi, K : array_like
            Points in map coordinates (broadcast together; phi any finite angle, wrapped).
        inverse : bool, optional
            Step back by time reversal (lem:timerevgen): ``F^{-1} = R2 F R2`` in (theta, I).
        n_threads : int, optional
            Worker threads (0 = all cores).

        Returns
        -------
        FlowSteps
            Flat arrays, one entry per point.

        Raises
        ------
        KeyboardInterrupt
            On Ctrl-C, with ``.partial`` (INTERRUPTED for the returns not finished).

        Examples
        --------
        >>> import hovering
        >>> fm = hovering.paper.flow_map(eps=-0.05)
        >>> st = fm.returns([0.3, 0.3], [-0.02, -0.2])
        >>> st.itinerary, st.status.tolist()          # both pass above the step: returns OK
        (['0', '0'], [0, 0])
        >>> back = fm.returns(st.phi, st.K, inverse=True)   # one step back, by time reversal
        >>> bool(abs(back.phi[0] - 0.3) < 1e-6 and abs(back.K[0] + 0.02) < 1e-6)
        True
        """
        p, k, _ = point_pair(phi, K, "returns")
        d = self._core.steps(
            np.ascontiguousarray(p.ravel()),
            np.ascontiguousarray(k.ravel()),
            flag("inverse", inverse),
            _threads(n_threads, self.sys.python_defined),
        )
        # Every field given, the core's own arrays: no dataclass __init__ (a frozen setattr each).
        res = object.__new__(FlowSteps)
        res.__dict__.update(
            phi=d["x"],
            K=d["y"],
            status=d["status"],
            region=d["region"],
            itinerary=d["itinerary"],
            time=d["time"],
            energy_error=d["energy_error"],
            steps=d["steps"],
            z=d["z"],
        )
        if d["interrupted"]:
            exc = KeyboardInterrupt("returns interrupted; the finished ones are in .partial")
            exc.partial = res
            raise exc
        return res

    def step(self, phi, K):
        """One return ``(phi, K) -> (phibar, Kbar)`` (NaN where the orbit does not return: see :meth:`returns`).

        Parameters
        ----------
        phi, K : array_like or float
            Points (broadcast together).

        Returns
        -------
        phi1, K1 : ndarray or float
            Images, ``phi1`` in ``[-pi, pi)``; floats when both inputs are scalars.

        Notes
        -----
        One point given as two floats (or ints) goes straight to the core on this thread, a tuple
        back, no arrays: the same return as :meth:`returns` bit for bit, at the cost of the return
        itself plus ~1-2 us (``benchmarks/bench_per_call.py``).
        """
        if plain_point(phi, K):
            x, y, _, _ = self._core.step1(phi, K, False)
            return x, y
        p, k, scalar = point_pair(phi, K, "step")
        r = self.returns(p, k)
        a, b = r.phi.reshape(p.shape), r.K.reshape(p.shape)
        return (float(a), float(b)) if scalar else (a, b)

    def jacobian(self, phi, K, n_threads: int = 0) -> StepJacobian:
        """One return of each point with its Jacobian ``d(phibar, Kbar) / d(phi, K)``.

        The variational equations are integrated with the state (every stepper: Taylor's method
        carries their Taylor series, the closed forms their derivatives), through a saltation
        matrix at every impact, then projected onto Sigma_h along the flow at the return and
        carried through the charts: H2's action-angle variables (theta, I) and, on normal
        coordinates, the tangential curve (``K = I - I_tan(theta)``). The return itself is
        :meth:`step`'s, bit for bit for the explicit steppers and ``"taylor"`` (the step control
        reads the state only; msadams, rk2imp and rk4imp see the tangents too and can step
        differently, within the tolerance). A return that is verified at a tighter tolerance
        (``verify_steps``) gets its Jacobian from the trace that is kept.

        Parameters
        ----------
        phi, K : array_like or float
            Points in map coordinates (broadcast together).
        n_threads : int, optional
            Worker threads (0 = all cores).

        Returns
        -------
        StepJacobian
            Images, ``J`` (shape ``(..., 2, 2)``), per-point :class:`Status` and :class:`Region`.
            A return that hits the corner (CORNER) or touches a wall tangentially (GRAZING), or
            ends otherwise than OK, has a status and no number (NaN). A near-grazing impact gives
            a large but finite J: the square-root singularity of the impact map, ``2 |a| / |v|``
            in the saltation matrix.

        Raises
        ------
        ValueError
            For non-finite or broadcast-incompatible points.
        KeyboardInterrupt
            On Ctrl-C, with ``.partial`` (INTERRUPTED for the returns not finished).

        Examples
        --------
        >>> import numpy as np, hovering
        >>> fm = hovering.paper.flow_map(eps=-0.05)
        >>> t = fm.jacobian(0.3, -0.02)
        >>> t.status, t.region
        (<Status.OK: 0>, <Region.ABOVE: 1>)
        >>> bool(abs(t.det - 1) < 1e-8)          # area preserving, to the integration tolerance
        True
        >>> (t.phi, t.K) == fm.step(0.3, -0.02)  # the same return as step()
        True
        """
        p, k, scalar = point_pair(phi, K, "jacobian")
        shape = () if scalar else p.shape
        d = self._core.jacobians(
            np.ascontiguousarray(p.ravel()),
            np.ascontiguousarray(k.ravel()),
            _threads(n_threads, self.sys.python_defined),
        )
        return StepJacobian.from_core(d, shape)

    def step_inverse(self, phi, K):
        """One step back, by time reversal (lem:timerevgen): the exact inverse of :meth:`step` up to
        the integration tolerance.

        Parameters
        ----------
        phi, K : array_like or float
            Image points.

        Returns
        -------
        phi0, K0 : ndarray or float
        """
        if plain_point(phi, K):  # one point: as step()
            x, y, _, _ = self._core.step1(phi, K, True)
            return x, y
        p, k, scalar = point_pair(phi, K, "step_inverse")
        r = self.returns(p, k, inverse=True)
        a, b = r.phi.reshape(p.shape), r.K.reshape(p.shape)
        return (float(a), float(b)) if scalar else (a, b)

    def region(self, phi, K):
        """Region of the return from each point (costs one return per point).

        Parameters
        ----------
        phi, K : array_like or float
            Points.

        Returns
        -------
        Region or ndarray of int8
            A :class:`Region` for scalar input, else an int8 array of its codes; ``Region.NONE``
            (-1) where the point has no return: outside :meth:`valid_band` (no point of the
            section has that K) or where the return failed. :meth:`returns` gives the reason as
            a :class:`FlowStatus` (``OFF_SECTION``, ``STEP_LIMIT``, ...) and :meth:`step` NaN
            there. The truncated maps raise instead for a K outside their band, where they are
            not defined.
        """
        if plain_point(phi, K):  # one point: as step()
            return Region(self._core.step1(phi, K, False)[3])
        p, k, scalar = point_pair(phi, K, "region")
        r = self.returns(p, k).region.reshape(p.shape)
        return Region(int(r)) if scalar else r

    def iterate(
        self,
        phi0,
        K0,
        n_steps: int,
        record: Sequence[str] = ("orbit", "regions", "rotation"),
        exit_regions: Iterable | None = None,
        stop_on_exit: bool = False,
        n_threads: int = 0,
        trajectory_dt: float | None = None,
        max_trajectory_points: int = MAX_TRAJECTORY_POINTS,
        progress=False,
        every: int = 1,
        stop=None,
    ) -> IterateResult:
        """Iterate many orbits in C++ (the core's thread pool, GIL released, no Python between returns).

        Parameters
        ----------
        phi0, K0 : array_like
            Initial points, broadcast together and flattened to ``n_orbits`` orbits; phi0 (|phi0| <= 1e6)
            is wrapped to [-pi, pi).
        n_steps : int
            Returns per orbit (>= 0).
        record : sequence of str, optional
            What to keep besides the final state and status (nothing else is computed or stored):
            ``"orbit"`` (phi, K), ``"regions"``, ``"rotation"`` (mean lifted angle advance, see
            :meth:`step_rotations`), ``"visited"`` (regions each orbit went through), ``"section"``
            (theta, I), ``"states"`` (points of Sigma_h),
            ``"times"``, ``"energy_error"``, ``"steps"`` (integrator steps), ``"itinerary"``,
            ``"trajectory"`` (the flow between the returns, sampled every ``trajectory_dt``: see
            :class:`IterateResult`), ``"extrema"`` (per orbit the least and greatest K reached:
            ``K_min``, ``K_max``), ``"residence"`` (per orbit the returns from each region),
            ``"jacobian"`` (per orbit the product of its returns' Jacobians, QR-renormalised, as
            :meth:`jacobian` computes each: see :class:`IterateResult`; the orbit is the same, bit
            for bit for the explicit steppers and taylor).
            Returns are labelled (crossings of q1 = qw1 tracked, itineraries built) only when
            ``"regions"``, ``"visited"``, ``"itinerary"``, ``"rotation"``, ``"residence"`` or
            ``exit_regions`` need it; the orbit is the same either way.
        exit_regions : iterable of Region or str, optional
            Regions to watch (e.g. ``{"0u", "0"}``): ``exit_step`` is the first return from a point
            outside them.
        stop_on_exit : bool, optional
            Stop an orbit (status EXITED) when it first leaves ``exit_regions``: at the point
            ``x_{exit_step}``. The return that leaves (already computed) is recorded in every
            per-return record (region, itinerary, time, ...) and in ``residence``, but not taken:
            the orbit's last point is ``x_{exit_step}``.
        n_threads : int, optional
            Worker threads (0 = all cores; 1 when a potential is defined in Python).
        trajectory_dt : float, optional
            With record ``"trajectory"`` (and only then): the spacing of the uniform samples, > 0.
            Each sample is one exact step of the integrator from the start of the accepted step it
            falls in, so it carries the integrator's accuracy (not an interpolant's), at the cost
            of one stepper step per sample; without a trajectory no such work is done.
        max_trajectory_points : int, optional
            Bound of the recorded points of all orbits together (default 10 million, ~410 MB):
            each orbit keeps at most ``max_trajectory_points // n_orbits`` (at least 2) and stops
            recording beyond, flagged in ``trajectory_truncated`` (its orbit goes on). Checked
            before computing: below 2 points per orbit, or a worst case that would not fit in
            memory, is a ValueError.
        progress : bool or callable, optional
            ``True``: a tqdm bar on stderr (unit: return, total ``n_orbits * n_steps``; an orbit
            that stops early counts its remaining returns). A callable ``progress(done, total)``
            is called every ~0.1 s and at the end. ``False`` (default): none.
        every : int, optional
            Record every k-th point (default 1): per-point records hold ``x_0, x_k, x_2k, ...``
            (``n_steps // k + 1`` columns), per-return records the returns from them
            (``ceil(n_steps / k)`` columns); the trajectory is not thinned.
        stop : hovering.Above or hovering.Below, optional
            Stop each orbit at the first point ``x_n`` (the start included) in the set
            (``K >= curve(phi)``, resp. ``<=``, in this map's coordinates: (phi, K), or (theta, I)
            with ``coordinates="section"``): status ``STOPPED``, ``stop_step = n`` (-1 if never),
            final point ``x_n``. A start with no point of Sigma_h is ``OFF_SECTION`` instead.

        Returns
        -------
        IterateResult
            The same result type as the truncated map's. Per-orbit statuses: OK, EXITED,
            INTERRUPTED, and the flow's CORNER, GRAZING, STEP_LIMIT, NON_FINITE, IMPACT_LIMIT,
            OFF_SECTION (the orbit stops there, NaN after; the others go on). ``work`` counts what
            the integration did.

        Raises
        ------
        ValueError
            For non-finite initial points, a negative ``n_steps``, unknown record keys or regions,
            a ``trajectory_dt`` without record ``"trajectory"`` (or the reverse), bad trajectory
            bounds or a bad ``progress``.
        KeyboardInterrupt
            On Ctrl-C (honoured within ~0.1 s): ``.partial`` holds every orbit up to where it was.

        Examples
        --------
        Two orbits from the line L1, 100 returns each, with the itinerary of every return:

        >>> import numpy as np, hovering
        >>> fm = hovering.paper.flow_map(eps=-0.05)
        >>> K0 = np.array([-0.04, 0.0])
        >>> res = fm.iterate(fm.L1(K0), K0, 100, record=("orbit", "regions", "itinerary"))
        >>> res.phi.shape, res.count(hovering.Status.OK)
        ((2, 101), 2)
        >>> res.itinerary[0][:4], res.itinerary[1][:4]   # impacts on the right wall; beside the step
        (['0', 'R', '0', 'R'], ['u', 'u', 'u', 'u'])
        """
        record, n_steps, mask = iterate_arguments(record, FLOW_RECORD_KEYS, n_steps, exit_regions, stop_on_exit)
        every, stop_side, stop_curve = transport_arguments(every, stop)
        progress = check_progress(progress)
        p, k, _ = point_pair(phi0, K0, names=("phi0", "K0"))
        # The recorded orbit starts on [-pi, pi) like every later point (point_pair checked
        # |phi0| <= 1e6: the core's wrap directly).
        p, k = np.ascontiguousarray(_core_wrap(p.ravel()), dtype=float), np.ascontiguousarray(k.ravel())
        n_states, n_returns = recorded_counts(n_steps, every)
        per_point = 2 * ("orbit" in record) + 2 * ("section" in record) + 4 * ("states" in record)
        per_return = (
            8 * (("times" in record) + ("energy_error" in record) + ("steps" in record))
            + ("regions" in record)
            + 64 * ("itinerary" in record)
        )
        thinned = f" (every {every})" if every > 1 else ""
        check_memory(
            f"recording {record} for {p.size} orbits x {n_steps} returns{thinned}",
            8 * per_point * p.size * n_states + per_return * p.size * n_returns,
        )
        dt, per_orbit = 0.0, 0
        if "trajectory" in record:
            if trajectory_dt is None:
                raise ValueError(
                    "trajectory_dt (the sample spacing) must be a number in (0, inf) with record 'trajectory', got None"
                )
            dt, per_orbit = trajectory_arguments(trajectory_dt, max_trajectory_points, p.size)
        elif trajectory_dt is not None:
            raise ValueError(
                f"trajectory_dt = {trajectory_dt!r} is only used with record 'trajectory'; add it to record "
                "or leave trajectory_dt out"
            )
        threads = _threads(n_threads, self.sys.python_defined)
        args = (p, k, n_steps, set(record), mask, bool(stop_on_exit), threads, dt, per_orbit)
        if progress is False:  # no bar machinery; inside a parallel run's piece, its stop check
            d = self._core.iterate(*args, stop_hook(), every, stop_side, stop_curve)
        else:
            with progress_bar(progress, p.size * n_steps, desc="FlowMap.iterate", unit="return") as bar:
                d = self._core.iterate(*args, bar.part(0) or None, every, stop_side, stop_curve)
        return IterateResult.from_core(d, self, n_steps, every, names=_CORE_NAMES)

    def with_eps(self, eps: float) -> FlowMap:
        """The same system, section and integrator at another eps (its own tangential curve).

        Used for the hovering set's F_0: a point is carried to eps = 0 by its normal coordinates.

        Parameters
        ----------
        eps : float
            New coupling strength.

        Returns
        -------
        FlowMap
        """
        return FlowMap(self.sys.replace(eps=eps), self.h, coordinates=self.coordinates, **self.integrator_options)

    def valid_band(self) -> tuple:
        """Range of K (or I) where Sigma_h has points: ``I > 0`` and ``H2(I) < h`` (approximately,
        with the coupling); points outside are OFF_SECTION."""
        I_hi = self.sys.V2.action(self.h) if self.h > 0 else 0.0
        if self.curve is None:
            return (0.0, I_hi)
        I = self.curve.values
        return (-float(np.min(I)), I_hi - float(np.max(I)))

    # ---------------------------------------------------------------- theory and the model

    def _require_onset(self):
        if self.onset is None:
            raise ValueError(
                f"no onset parameters at h = {self.h} (step energy {self.sys.step_energy}): {self.onset_error}"
            )
        if self.coordinates != "normal":
            raise ValueError("the theory and the model live in normal coordinates: use coordinates='normal'")

    def _forcing_curve(self):
        """The tangential curve whose f (eq:defoff) is this map's forcing: its own, or at eps = 0 the
        curve of the system at eps = 1e-6 (f's eps -> 0 limit); None at eps = 0 without a coupling."""
        if self.curve is None:
            raise ValueError("the forcing needs normal coordinates (coordinates='normal')")
        if self.eps != 0:
            return self.curve
        if self.sys.coupling is None:
            return None
        return TangentialCurve(Section(self.sys.replace(eps=_EPS_LIMIT), self.h), rtol=1e-13)

    def forcing_coefficients(self, n_modes: int | None = None) -> np.ndarray:
        """Sine coefficients of the measured forcing f (eq:defoff) of this section (cached).

        The core's one fit (:meth:`TangentialCurve.forcing_coefficients`, ``n_modes`` default
        ``FORCING_MODES``). At eps = 0 f is undefined (eq:defoff divides by eps); its eps -> 0 limit
        is used there, measured on the system at eps = 1e-6 (zeros without a coupling). Each
        coefficient carries a measurement error of at most :meth:`forcing_tolerance`.
        """
        n_modes = integer("n_modes", _core_normal.FORCING_MODES if n_modes is None else n_modes, 1, MAX_MODES)
        if self._forcing is None or self._forcing.size != n_modes:
            curve = self._forcing_curve()
            self._forcing = np.zeros(n_modes) if curve is None else curve.forcing_coefficients(n_modes)
        return self._forcing

    #: Tolerance of the second trace of the tangential curve that measures the first one's error
    #: (:meth:`forcing_tolerance`); 1e-14 if GSL cannot reach it.
    _REFERENCE_RTOL = (1e-15, 1e-14)

    def _curve_error(self) -> float:
        """delta: the largest error of the interpolated I_tan^eps values the forcing fit uses (cached).

        Measured: the curve traced again (same wall points) at rtol 1e-15 is compared with this
        map's on the fit's angles, and the curve's measured interpolation error (off-grid traces)
        is added; 0 without a forcing curve."""
        if self._delta is None:
            curve = self._forcing_curve()
            if curve is None:
                self._delta = 0.0
                return self._delta
            phi = _core_normal.forcing_angles(_core_normal.FORCING_SAMPLES)
            phi = np.concatenate([phi, -phi])
            err = None
            for rtol in self._REFERENCE_RTOL:
                try:
                    ref = TangentialCurve(curve.sec, n=int(curve.s.size), rtol=rtol, n_check=0)
                except (ValueError, RuntimeError) as e:
                    err = e
                    continue
                break
            else:
                raise ValueError(f"the tangential curve's error could not be measured (second trace failed: {err})")
            interp = curve.interpolation_error if math.isfinite(curve.interpolation_error) else 0.0
            self._delta = float(np.max(np.abs(curve(phi) - ref(phi)))) + float(interp)
        return self._delta

    def forcing_tolerance(self, n_modes: int | None = None) -> float:
        """Error bound of the measured sine coefficients b_k: a ``|b_k|`` at or below it is 0 within rounding.

        The fit takes ``f_j = (I(-phi_j) - I(phi_j)) / eps`` at the ``n = FORCING_SAMPLES`` (256)
        midpoint angles and ``b_k = (2/n) sum_j f_j sin(k phi_j)``. If every interpolated value of
        ``I_tan^eps`` it uses is within delta of the truth, each ``f_j`` is within ``2 delta / |eps|``
        and each ``b_k`` within ``(2/n) n (2 delta / |eps|) = 4 delta / |eps|``; the fit's own rounding
        adds at most ``2 (n + 2) u sum_k |b_k|`` (u = 2^-53, recursive summation of n terms). So

            ``tol = 4 delta / |eps| + 2 (n + 2) u sum_k |b_k|``.

        delta is measured, not assumed: the largest difference on the fit's angles between this map's
        curve and the same curve traced again at rtol 1e-15, plus the curve's measured interpolation
        error (README system at eps = -0.05 / +0.05: delta = 5.7e-15 / 6.7e-15, tol = 4.9e-13 /
        5.7e-13, against b_1 = 0.564; a coupling even in q2, ``q1 q2^2``, gives |b_1| = 6e-15 below
        its tol 4.0e-13: no first-order forcing). At eps = 0
        the forcing and delta are those of the system at eps = 1e-6. The first call traces the curve
        once more (milliseconds for the compiled potentials); the result is cached.

        Parameters
        ----------
        n_modes : int, optional
            Modes of the fit whose rounding is bounded (default ``FORCING_MODES``, 8).

        Returns
        -------
        float
            The tolerance (0 without a forcing: eps = 0 and no coupling).

        Raises
        ------
        ValueError
            Without normal coordinates, where the tangential curve is not a graph, or if the second
            trace fails.
        """
        b = self.forcing_coefficients(n_modes)
        if self.eps == 0 and self.sys.coupling is None:
            return 0.0  # no forcing at all: f = 0 exactly
        eps_f = self.eps if self.eps != 0 else _EPS_LIMIT
        return 4.0 * self._curve_error() / abs(eps_f) + _theory._forcing_rounding(b)

    def theory(self) -> _theory.Theory:
        """Leading-order predictions with this system's onset parameters and measured forcing.

        :func:`hovering.theory` with the onset ``Omega0, theta_w, tau0``, the measured forcing
        (:meth:`forcing_coefficients`), its error bound as the tolerance below which a coefficient
        is 0 (:meth:`forcing_tolerance`) and this system's geometry. Stated for every Omega0 the
        system can have (a physical Omega0 is often beyond 2 pi: 9.83 for the README system).

        Returns
        -------
        hovering.Theory
            ``hovers``, ``hovering_sign`` (the sign of eps that hovers: ``sign(sin(Omega0/2) b_1)``,
            period 4 pi in Omega0; set by the higher modes where b_1 is 0 within its error, e.g. a
            coupling even in q2; 0 where nothing forces), ``area`` (eq:hovsetsize with the measured
            forcing), ``K_crit``, ``rho_crit``, ``note`` (which says why). In the ``"wall"`` geometry
            (no step corner) and ``"none"`` the hovering set is empty exactly: every K < 0 start
            impacts the wall on its first return, resp. nothing impacts; ``hovers`` is False,
            ``area`` 0 and ``hovering_sign`` 0, with the reason in ``note``.
        """
        self._require_onset()
        p = self.onset
        b = self.forcing_coefficients()
        return _theory.theory(
            self.eps,
            p.Omega0,
            p.theta_w,
            p.tau0,
            forcing=tuple(float(x) for x in b),
            geometry=self.sys.geometry,
            forcing_tol=self.forcing_tolerance(),
        )

    def L1(self, K):
        """Angle of the line L1 at heights K (def:L1L2) with the onset Omega0 and tau0."""
        self._require_onset()
        return _theory.L1(K, self.onset.Omega0, self.onset.tau0)

    def L2(self, K):
        """Angle of the line L2 at heights K (def:L1L2) with the onset Omega0 and tau0."""
        self._require_onset()
        return _theory.L2(K, self.onset.Omega0, self.onset.tau0)

    def truncated(self, forcing: str = "measured", n_modes: int | None = None):
        """The truncated model of this system (eq:trunceps1eps2), with no hand scaling.

        The arcs are the onset parameters' (eq:omegaofalead); the forcing is the measured f of
        eq:defoff: all ``n_modes`` sine modes (``forcing="measured"``, a TruncatedFamily) or its
        first mode only (``forcing="first_mode"``: the paper's F_eps with amplitude ``eps b_1``, a
        TruncatedMap). For arcs measured on the flow instead see
        :func:`hovering.normal.truncated_from_flow`.

        Parameters
        ----------
        forcing : {"measured", "first_mode"}, optional
            Which forcing.
        n_modes : int, optional
            Sine modes kept for ``"measured"`` (default ``FORCING_MODES``, 8).

        Returns
        -------
        TruncatedFamily or TruncatedMap

        Raises
        ------
        ValueError
            Without onset parameters or normal coordinates, for an unknown ``forcing``, or in the
            ``"wall"`` and ``"none"`` geometries: the model's arcs J_0 (crossing q1 = qw1 above the
            step) and J_1 (one impact on the upper wall) exist only with the step's corner.

        Notes
        -----
        Coefficients within :meth:`forcing_tolerance` of 0 (measurement noise) are set to 0, as in
        :meth:`theory`: where b_1 vanishes (a coupling even in q2) the ``"first_mode"`` model is F_0.
        """
        self._require_onset()
        if not is_choice(forcing, ("measured", "first_mode")):
            raise ValueError(f"forcing must be 'measured' or 'first_mode', got {forcing!r}")
        if self.sys.geometry != "step":
            why = (
                "an infinite wall without the step's corner: every K < 0 start impacts the wall on its first "
                "return (one impacting arc for every K < 0, eq:fwall), which TruncatedMap and TruncatedFamily "
                "cannot represent, and nothing hovers (FlowMap.theory() says so)"
                if self.sys.geometry == "wall"
                else "no walls: nothing impacts, the return map is smooth (eq:shiftstandardmap to leading order)"
            )
            raise ValueError(
                f"the truncated model (eq:truncatedmap, eq:trunceps1eps2) is the step's: its arcs J_0 and J_1 need "
                f"the step's corner; geometry {self.sys.geometry!r} has {why}. Iterate the FlowMap itself, or "
                "model the step: FlowMap(sys.replace(geometry='step'), h)"
            )
        p = self.onset
        b = self.forcing_coefficients(n_modes)
        b = np.where(np.abs(b) <= self.forcing_tolerance(n_modes), 0.0, b)
        m = TruncatedMap(eps=self.eps * b[0], Omega0=p.Omega0, theta_w=p.theta_w, tau0=p.tau0, tau1=p.tau1, lam=p.lam)
        if forcing == "first_mode":
            return m
        depth = min(0.95 * -m.valid_band()[0], 1.0)
        s = np.linspace(math.sqrt(depth), 0.0, 121)
        Kgrid = np.concatenate([-(s**2), np.linspace(depth / 60, depth, 40)])
        return TruncatedFamily.from_map(m.with_eps(self.eps), Kgrid, forcing=tuple(b))

    def upper_tangent_K(self) -> float:
        """K of the unperturbed torus tangent to the upper wall, ``H2^{-1}(V2(qw2)) - I_tan(h)``.

        Below it (eps = 0) q2 never reaches qw2: the orbits pass above the step every return and
        never impact. The impact zone of the flow lies between this torus and the tangential curve
        (sec:discussion); the region below it has no analogue in the truncated model.
        """
        I_up = self.sys.V2.action(self.sys.V2.V(self.sys.qw2))
        return float(I_up - (self.curve.I_tan0 if self.curve is not None else 0.0))

    #: Deprecated (removed in 0.4.0): the search is an analysis of the map, :func:`hovering.impact_zone_floor`.
    impact_zone_floor = moved_method("impact_zone_floor", "hovering.analysis.zone.impact_zone_floor")

    def step_rotations(self, res: IterateResult, i: int) -> np.ndarray:
        """The rotation of each return of orbit i of ``res``: the angle advance ``phi_{n+1} - phi_n``
        lifted to the branch nearest the onset model's ``omega_a(K_n)`` of the return's region (the
        truncated map's own rotation, eq:omegaofalead), so the flow's and the model's rotation
        numbers compare directly. Needs ``record=("orbit", "regions")``."""
        if not isinstance(res, IterateResult) or res.map is not self:
            raise ValueError("res must be the IterateResult of this FlowMap's iterate(...)")
        if res.region is None:
            raise ValueError("the flow's rotations need record=('orbit', 'regions')")
        i = integer("i (orbit index)", i, -res.n_orbits, res.n_orbits - 1)
        self._require_onset()
        n = int(res.steps_done[i])
        ph, K, reg = res.phi[i, : n + 1], res.K[i, : n + 1], res.region[i, :n]
        p = self.onset
        Kn = K[:n]
        s = np.sqrt(np.maximum(-Kn, 0.0))
        ref = p.Omega0 + p.tau0 * Kn
        ref = np.where(reg == int(Region.UPPER), ref + 2 * (np.pi - p.theta_w) + p.tau1 * Kn, ref)
        ref = np.where(reg == int(Region.RIGHT), ref - 2 * p.lam * s, ref)
        return ref + wrap(np.diff(ph) - ref)


def _restore_flowmap(cls, sys, h, coordinates, options, curve, extra):
    """A ``cls`` (FlowMap or a subclass) built by ``FlowMap.__init__`` with the given curve, plus ``extra`` attributes."""
    obj = cls.__new__(cls)
    FlowMap.__init__(obj, sys, h, coordinates=coordinates, curve=curve, **options)
    obj.__dict__.update(extra)
    return obj
