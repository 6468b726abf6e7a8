"""The Poincare section Sigma_h of a step system and its return map (one return per call, batched)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._checks import MAX_THREADS, check_points, integer, plain_point, real_array, real_number, thread_count
from .._core import flow as _core_flow
from .._display import Summarized, status_counts
from .._enums import FlowStatus, status_code
from .._io.records import reduce_record
from .._io.serial import Saveable
from .._progress import check_progress, progress_bar, stop_hook
from ..interface import MAX_TRAJECTORY_POINTS, trajectory_arguments, trajectory_rows
from .system import StepSystem

__all__ = ["Section", "ReturnMapResult", "FlowStatus", "flow_options", "STEPPERS"]

#: Steppers the flow offers, its default first: ``"auto"`` (``"taylor"`` where Taylor's method
#: applies, else ``"rk8pd"``), GSL's explicit Runge-Kutta methods, Adams multistep method and
#: implicit Gauss-Legendre methods, Taylor's method, and ``"exact"``, the flow in closed form where
#: the system has one (see :meth:`Section.return_map`). The core's list (``hovering._core.flow.STEPPERS``).
STEPPERS = tuple(_core_flow.STEPPERS)


#: The flow's options besides the stepper and its tolerances (how events are located and judged,
#: and the budgets): what FlowMap and an accuracy target take as ``**options``.
EVENT_OPTIONS = ("event_tol", "max_steps", "max_impacts", "grazing_tol", "corner_tol", "verify_steps")

# flow_options' checks: each names its option and the allowed range.
_OPTION_CHECKS = dict(
    rtol=lambda v: real_number("rtol", v, 1e-16, False, 1, True),
    atol=lambda v: real_number("atol", v, 0),
    event_tol=lambda v: real_number("event_tol", v, 0),
    max_steps=lambda v: integer("max_steps", v, 1, 2**62),
    max_impacts=lambda v: integer("max_impacts", v, 1, 1_000_000),
    grazing_tol=lambda v: real_number("grazing_tol", v, 0, False),
    corner_tol=lambda v: real_number("corner_tol", v, 0, False),
    verify_steps=lambda v: integer("verify_steps", v, -1, 2**62),
)


def flow_options(
    rtol: float | None = None,
    atol: float | None = None,
    stepper: str | None = None,
    event_tol: float | None = None,
    max_steps: int | None = None,
    max_impacts: int | None = None,
    grazing_tol: float | None = None,
    corner_tol: float | None = None,
    verify_steps: int | None = None,
) -> _core_flow.FlowOptions:
    """Integrator settings of the flow, validated with errors that name the value and its range.

    Parameters
    ----------
    rtol, atol, stepper, event_tol, max_steps, max_impacts, grazing_tol, corner_tol, verify_steps
        See :meth:`Section.return_map` (``"exact"`` ignores rtol and atol; whether it applies
        depends on the system: ``FlowOptions.validate_for(system)``). None: the core's default
        (``hovering._core.flow.FlowOptions()``: auto, rtol 1e-10, event_tol 1e-15, max_steps 1e6,
        max_impacts 100, grazing_tol 1e-12, corner_tol 1e-10, verify_steps -1; atol: the core's
        one policy, ``default_atol(rtol)`` = rtol).

    Returns
    -------
    hovering._core.flow.FlowOptions
    """
    kw = {}
    if stepper is not None:
        # The core parses the name (its message names the value and every stepper); anything but a
        # string is named the same way.
        kw["stepper"] = stepper if isinstance(stepper, str) else repr(stepper)
    given = (
        ("rtol", rtol),
        ("atol", atol),
        ("event_tol", event_tol),
        ("max_steps", max_steps),
        ("max_impacts", max_impacts),
        ("grazing_tol", grazing_tol),
        ("corner_tol", corner_tol),
        ("verify_steps", verify_steps),
    )
    kw.update({k: _OPTION_CHECKS[k](v) for k, v in given if v is not None})
    return _core_flow.FlowOptions(**kw)


def _threads(n_threads, python_defined: bool) -> int:
    n = thread_count(n_threads)
    # Every Python call takes the GIL: two threads measured 3.4x slower than one.
    return 1 if n == 0 and python_defined else n


@dataclass(frozen=True, repr=False)
class ReturnMapResult(Summarized, Saveable):
    """Images of points of Sigma_h under the return map, one entry per initial condition.

    Attributes
    ----------
    theta, I : ndarray
        Section coordinates of the image (unperturbed S2 of (q2, p2)); NaN where the status is not OK.
    z : ndarray
        Image states (q1, p1, q2, p2), shape (n, 4).
    time : ndarray
        Return times.
    itinerary : list of str
        Impacts in order ('R', '1', 'R1', ...); without impact '0' if the segment crossed
        q1 = qw1 above the step (J_0), 'u' if it never crossed it (J_0u); '' for the smooth flow
        (geometry "none") and for returns that did not end OK without impact.
    region : ndarray of int8
        :class:`Region` of each return (from its itinerary; ``NONE`` unless OK with walls).
    status : ndarray of int8
        Per-orbit :class:`FlowStatus`: OK, or why this orbit alone stopped (CORNER, GRAZING,
        STEP_LIMIT, NON_FINITE, IMPACT_LIMIT, OFF_SECTION for a start with no point of Sigma_h,
        INTERRUPTED, OUTSIDE_WELL where no accepted step keeps the state inside a bounded well such
        as Tan's, IMPRECISE where a verified return's error stayed above its band: see
        ``verify_steps``); the others are computed regardless. ``z`` and ``time`` of a stopped orbit are
        the last state reached (always inside the wells) and its time.
    energy_error : ndarray
        ``|H(image) - H(start)|``.
    steps : ndarray of int64
        Accepted integrator steps (of every trace of a verified return).
    stepper : str or None
        The stepper that ran (``"auto"`` resolved on the system: ``"taylor"`` or ``"rk8pd"``); None
        in results saved before it was recorded.
    work : dict or None
        What the integration did, summed over the call (see :attr:`hovering.IterateResult.work`).
    trajectory, trajectory_index, trajectory_kind, trajectory_truncated : ndarray or None
        With ``trajectory_dt``: each return's flow, rows ``(t, q1, p1, q2, p2)`` (its clock
        starts at 0), as in :class:`hovering.IterateResult`; see :meth:`trajectory_of`.

    Examples
    --------
    >>> import hovering
    >>> sec = hovering.Section(hovering.paper.system(eps=-0.05), h=1.0)
    >>> res = sec.return_map([0.0, 1.0], [0.3, 0.3], trajectory_dt=0.1)
    >>> res
    <ReturnMapResult n=2, status={OK: 2}>
    >>> res.z.shape, res.region.tolist()      # image states; Region.ABOVE for both
    ((2, 4), [1, 1])
    >>> rows = res.trajectory_of(0)           # the flow of the first return: (t, q1, p1, q2, p2)
    >>> rows.shape[1], bool(rows[0, 0] == 0.0)
    (5, True)
    """

    theta: np.ndarray
    I: np.ndarray
    z: np.ndarray
    time: np.ndarray
    itinerary: list
    status: np.ndarray
    energy_error: np.ndarray
    steps: np.ndarray
    region: np.ndarray | None = None
    work: dict | None = None
    stepper: str | None = None
    trajectory: np.ndarray | None = field(default=None, repr=False)
    trajectory_index: np.ndarray | None = field(default=None, repr=False)
    trajectory_kind: np.ndarray | None = field(default=None, repr=False)
    trajectory_truncated: np.ndarray | None = field(default=None, repr=False)

    @classmethod
    def _make(cls, fields: dict) -> ReturnMapResult:
        """The result with these fields (every one named; the core's own arrays, no checks): what
        the dataclass constructor makes, without its 14 frozen-attribute assignments (4 us of a
        one-point call)."""
        r = object.__new__(cls)
        r.__dict__.update(fields)
        return r

    def trajectory_of(self, i: int) -> np.ndarray:
        """The recorded flow of return i: rows ``(t, q1, p1, q2, p2)``, shape ``(m_i, 5)`` (a view).

        Raises
        ------
        ValueError
            If no trajectory was recorded (no ``trajectory_dt``) or i is out of range.
        """
        return trajectory_rows(self, i)

    def count(self, status) -> int:
        """Number of orbits with the given :class:`FlowStatus` (or its name, or the Status of that name)."""
        return int(np.count_nonzero(self.status == status_code(FlowStatus, status)))

    def _summary(self) -> list:
        return [("n", int(self.status.shape[0])), ("status", status_counts(self.status, FlowStatus))]

    def to_xarray(self):
        """The returns as an :class:`xarray.Dataset` (needs ``hovering[xarray]``): one entry per
        start along dimension ``start``; ``theta``, ``I``, ``time``, ``energy_error``,
        ``integrator_steps``, ``status`` (named in its flag attrs), ``itinerary``, ``region`` and the
        image state ``z`` over (``start``, ``component``: q1, p1, q2, p2); units and provenance in attrs.

        Returns
        -------
        xarray.Dataset

        Raises
        ------
        ImportError
            Without xarray, naming ``pip install xarray`` and the extra ``.[xarray]``.
        """
        from .._io.interop import return_map_dataset

        return return_map_dataset(self)


class Section:
    """The Poincare section ``Sigma_h = {p1 = 0, dp1/dt < 0, H = h}`` of a system.

    Parameters
    ----------
    sys : StepSystem
        The system.
    h : float
        Energy level.

    Raises
    ------
    ValueError
        If sys is not a StepSystem or h is not a finite number.

    Examples
    --------
    >>> import hovering
    >>> sec = hovering.Section(hovering.paper.system(eps=-0.05), h=1.0)
    >>> z = sec.point(0.5, 0.3)             # the state (q1, 0, q2, p2) at section coordinates (0.5, 0.3)
    >>> z.shape, sec.coordinates(z).round(6).tolist()
    ((1, 4), [[0.5, 0.3]])
    >>> res = sec.return_map([0.0, 2.0], [0.3, 0.45])   # one return of each point (see return_map)
    >>> res.itinerary
    ['0', 'u']
    """

    def __init__(self, sys: StepSystem, h: float):
        if not isinstance(sys, StepSystem):
            raise ValueError(f"sys must be a hovering.StepSystem, got {sys!r}")
        self.sys = sys
        # 1e100: far above any physical level, and the potentials' energy questions stay finite.
        self.h = real_number("h", h, hi=1e100, hi_open=False)

    def __setattr__(self, name, value):
        """``sys`` and ``h`` are fixed at construction: the kept mappers integrate that system, and
        the hash is theirs (a reassigned ``sys`` gave the old system's returns)."""
        if name in ("sys", "h") and name in self.__dict__:
            raise AttributeError(f"Section.{name} is fixed at construction; make a new Section(sys, h)")
        object.__setattr__(self, name, value)

    def __repr__(self) -> str:
        return f"Section({self.sys!r}, h={self.h!r})"

    def __eq__(self, other):
        """Equal to a section of an equal system at the same energy."""
        if not isinstance(other, Section):
            return NotImplemented
        return type(self) is type(other) and self.sys == other.sys and self.h == other.h

    def __hash__(self) -> int:
        """Hash of the system and the energy (consistent with ``==``)."""
        return hash((self.sys, self.h))

    def _to_record(self) -> dict:
        """What :func:`hovering.save` writes: the system and the energy."""
        return {"sys": self.sys, "h": self.h}

    @classmethod
    def _from_record(cls, record: dict) -> Section:
        """Inverse of :meth:`_to_record` (validated again)."""
        return cls(record["sys"], record["h"])

    def __reduce__(self):
        """Pickle as the record (and any other instance attribute but the kept core mappers)."""
        return reduce_record(
            self, {k: v for k, v in self.__dict__.items() if k not in ("sys", "h", "_mappers", "_last_mapper")}
        )

    #: Distinct option sets whose validated core mapper a section keeps (beyond, it starts afresh).
    _MAX_MAPPERS = 16

    def _mapper(self, args: tuple) -> _core_flow.ReturnMapper:
        """The core's return mapper for these integrator options (rtol, atol, stepper, event_tol,
        max_steps, max_impacts, grazing_tol, corner_tol, verify_steps): validated (flow_options,
        validate_for) at the first call with them, then kept with its tracers. The key holds the
        arguments' types too: a value equal to a validated one but of another type (True == 1,
        2000.0 == 2000) is validated itself, not taken for it."""
        key = (args, tuple(map(type, args)))
        mappers = self.__dict__.get("_mappers")
        if mappers is None:
            mappers = self.__dict__["_mappers"] = {}
        try:
            return mappers[key]
        except KeyError:
            pass
        except TypeError:  # an unhashable argument: validation names it
            return _core_flow.ReturnMapper(self.sys.core, flow_options(*args))
        m = _core_flow.ReturnMapper(self.sys.core, flow_options(*args))  # validate_for inside
        if len(mappers) >= self._MAX_MAPPERS:
            mappers.clear()
        mappers[key] = m
        return m

    def point(self, theta, I) -> np.ndarray:
        """States (q1, 0, q2, p2) of Sigma_h at section coordinates (theta, I).

        Parameters
        ----------
        theta, I : array_like
            Angle in [-pi, pi] and action of the unperturbed H2 (broadcast together).

        Returns
        -------
        ndarray
            Shape (n, 4).

        Raises
        ------
        ValueError
            Where no such point exists (e.g. H2(I) >= h), naming the point; for theta and I that
            do not broadcast, or broadcast to more points than half of this machine's memory holds
            (:func:`hovering._checks.check_points`, before anything is allocated).
        """
        z, ok, why = self._points(theta, I)
        if not ok.all():
            raise ValueError(why[int(np.argmin(ok))])
        return z

    def _points(self, theta, I):
        """Points of Sigma_h, a mask of those that exist, and why the others do not."""
        if plain_point(theta, I):  # one plain point: the core checks the angle's range itself
            return _core_flow.section_points(self.sys.core, self.h, np.array([float(theta)]), np.array([float(I)]))
        t, i = real_array("theta", theta), real_array("I", I)  # type errors first, named
        check_points(("theta", "I"), (t.shape, i.shape))  # before the copies of ravel
        t, i = np.broadcast_arrays(t, i)
        return _core_flow.section_points(
            self.sys.core, self.h, np.ascontiguousarray(t.ravel()), np.ascontiguousarray(i.ravel())
        )

    def coordinates(self, z) -> np.ndarray:
        """Section coordinates (theta, I) of states z (shape (n, 4)).

        Parameters
        ----------
        z : array_like
            States (q1, p1, q2, p2).

        Returns
        -------
        ndarray
            Shape (n, 2): theta in [-pi, pi), I; NaN rows where a state has no coordinates (a
            non-finite entry, or an H2 that overflows: the last state of a runaway orbit).
        """
        z = np.atleast_2d(real_array("z", z))
        if z.ndim != 2 or z.shape[1] != 4:
            raise ValueError(f"z must be states (q1, p1, q2, p2) of shape (n, 4), got shape {np.shape(z)}")
        return _core_flow.section_coordinates(self.sys.core, np.ascontiguousarray(z))

    def return_map(
        self,
        theta,
        I,
        rtol: float | None = None,
        atol: float | None = None,
        stepper: str | None = None,
        event_tol: float | None = None,
        max_steps: int | None = None,
        max_impacts: int | None = None,
        grazing_tol: float | None = None,
        corner_tol: float | None = None,
        verify_steps: int | None = None,
        n_threads: int = 0,
        trajectory_dt: float | None = None,
        max_trajectory_points: int = MAX_TRAJECTORY_POINTS,
        progress=False,
    ) -> ReturnMapResult:
        """Return map of many points of Sigma_h (multi-threaded, GIL released).

        Parameters
        ----------
        theta, I : array_like
            Section coordinates of the starting points.
        rtol, atol : float, optional
            Tolerances of the step-size control (not read by ``"exact"``; default rtol 1e-10, and atol
            rtol's: the core's one policy, ``FlowOptions::default_atol``, as for :class:`FlowMap`).
            Every integrator setting left None takes the core's default (:func:`flow_options`).
        stepper : {"auto", "rk8pd", "rkck", "rkf45", "rk4", "rk2", "msadams", "rk4imp", "rk2imp", "taylor", "exact"}, optional
            ``"auto"`` (default): ``"taylor"`` where it applies (V1, V2 each Harmonic or Tan, or
            Numerical of them), else ``"rk8pd"``; the result's ``stepper`` names the one that ran.
            ``"taylor"``: Taylor's method on the field, which is a polynomial in the state once each
            Tan potential carries u = tan(alpha q) (coefficients by recurrences, four orbits at a
            time in SIMD lanes; order ceil(1 - ln(rtol) / 1.2), step exp(-1.2) times the radius of
            convergence estimated from the last two coefficients, after Jorba & Zou; events and
            samples on the step's own polynomial); for V1, V2 each Harmonic or Tan (or Numerical
            of them) with any polynomial coupling, others raise ValueError. The fastest stepper at
            every tolerance measured and the only one that reaches the rounding floor (docs:
            Accuracy). Else a
            GSL stepper: an explicit Runge-Kutta method, or the variable-order Adams multistep
            method (its events are located on an rk8pd extension of each step; on this smooth,
            oscillatory flow it is ~7x slower than rk8pd at matched accuracy), or an implicit
            Gauss-Legendre method (``rk4imp``, ``rk2imp``: symplectic at a fixed step, with the
            flow's Jacobian; under the adaptive step control 30-500x slower than rk8pd at matched
            error, and its long-orbit error still grows nearly as m^2: README "Long orbits"). ``"exact"``: the
            flow in closed form, for eps = 0 (or no coupling) with V1, V2 each Harmonic or Tan
            (each oscillator turns on its own action-angle circle, an impact is an angle jump
            theta -> -theta_w: returns are computed event to event, to rounding, ~1e-15) and for
            Harmonic V1, V2 with a quadratic coupling at any eps (a linear flow, stepped through
            its normal modes; events located as for the GSL steppers, and a step cut wherever its closed
            form shows a watched velocity changing sign twice). Other systems raise
            ValueError. ``steps`` then counts events passed (or closed-form steps).
        event_tol : float, optional
            Time accuracy of located events (impacts, section crossing, a wall distance's
            minimum): Newton's method on exact stepper steps runs until its correction is below
            sqrt(event_tol), and that last correction is applied linearly (error ~ event_tol).
        max_steps : int, optional
            Step limit per return (status STEP_LIMIT beyond it).
        max_impacts : int, optional
            Impact limit per return (status IMPACT_LIMIT beyond it: chattering).
        grazing_tol : float, optional
            An orbit whose distance to a wall has a minimum within this of zero touches it
            tangentially (status GRAZING). Minima of the distance inside a step are searched, so
            dips deeper than this are impacts however short.
        corner_tol : float, optional
            An impact this close to the corner is a corner hit (status CORNER).
        verify_steps : int, optional
            Which returns are verified. rtol bounds each step's error, not a return's: errors add
            up over long returns, and chaos or impacts amplify them. A verified return is traced
            again at rtol / 100 (and rtol / 10^4 if needed; with ``"taylor"`` at the return's own
            order in shorter steps, in the SIMD lanes beside the other returns); the tighter
            trace is kept once a tenth of the difference is within the band (return time within
            ``rtol * max(1, t)``, each state component within ``rtol * |z| + atol``), else the
            return gets status IMPRECISE. A return is verified when its steps times its error
            amplification (the product over impacts of ``2 |a| / (|v| w)``, at least 1 each:
            a shallow impact's saltation; and the section crossing's ``|V1'(q1)| / |dp1/dt|``, at
            least 1: a crossing where the coupling nearly cancels V1's force) reach N. -1 (default): N = 128 with ``"taylor"``,
            ``40 (1e-8 / rtol)^(1/p)`` (at least 16) with a GSL stepper of order p (rk8pd: 40 at
            rtol 1e-8, 71 at 1e-10), never with ``"exact"``; 0: no verification; N >= 1: that N.
            ``steps`` counts the steps of every trace. Cost on the README system: 1-2% more steps
            with taylor, 13-28% with rk8pd (docs: Accuracy, "Verified returns").
        n_threads : int, optional
            Worker threads (0 = all cores, or 1 when a potential is defined in Python: its calls
            serialise on the GIL).
        trajectory_dt : float, optional
            Record each return's flow, sampled at ``t = k * trajectory_dt`` (> 0) plus every
            impact (before and after) and the return point (see :meth:`hovering.FlowMap.iterate`).
        max_trajectory_points : int, optional
            Bound of the recorded points of all returns together (default 10 million); each keeps
            at most ``max_trajectory_points // n`` and is flagged in ``trajectory_truncated``
            beyond.
        progress : bool or callable, optional
            ``True``: a tqdm bar on stderr (unit: return); a callable ``progress(done, total)``
            is called every ~0.1 s and at the end; ``False`` (default): none.

        Returns
        -------
        ReturnMapResult
            One entry per starting point; a point that is not on Sigma_h (no q1 solves H = h) has
            status OFF_SECTION and NaN coordinates, and no orbit's outcome stops the others.

        Raises
        ------
        ValueError
            For bad options (named, with the allowed range), a stepper the system does not
            admit ("exact" without a closed-form flow), non-finite / out-of-range angles,
            bad trajectory bounds or a bad ``progress``; and, before anything is allocated, for
            more starting points (after broadcasting theta with I) or trajectory points than half
            of this machine's memory holds.
        KeyboardInterrupt
            On Ctrl-C: its ``partial`` attribute holds the ReturnMapResult with every finished
            return and status INTERRUPTED for the rest.

        Examples
        --------
        >>> import numpy as np, hovering
        >>> sec = hovering.Section(hovering.paper.system(eps=-0.05), h=1.0)
        >>> res = sec.return_map([0.0, 1.0, 2.0], [0.3, 0.3, 0.45])
        >>> res.count("OK"), res.itinerary     # no impact: two pass above the step, one beside it
        (3, ['0', '0', 'u'])
        >>> print(np.round(res.theta, 3), np.round(res.I, 3))
        [-2.948 -1.924 -0.435] [0.226 0.267 0.488]
        >>> bool(res.energy_error.max() < 1e-8)
        True

        A point with no point of Sigma_h is an outcome of its own, not an error:

        >>> sec.return_map([0.0], [0.8]).count("OFF_SECTION")
        1
        """
        # Options are validated once per distinct set (the mapper is kept); n_threads and progress
        # every call (cheap), the points every call. A loop passes the same option objects call
        # after call: the last call's mapper is taken when each option is the very object it had
        # (0.1 us; the keyed lookup of _mapper took 0.6-0.8 us of a 15 us one-point call).
        try:
            r, a, s, e, ms, mi, g, c, v, mapper = self._last_mapper
        except AttributeError:
            mapper = None
        else:
            if not (
                r is rtol
                and a is atol
                and s is stepper
                and e is event_tol
                and ms is max_steps
                and mi is max_impacts
                and g is grazing_tol
                and c is corner_tol
                and v is verify_steps
            ):
                mapper = None
        if mapper is None:
            args = (rtol, atol, stepper, event_tol, max_steps, max_impacts, grazing_tol, corner_tol, verify_steps)
            mapper = self._mapper(args)
            try:
                hash(args)
            except TypeError:  # a mutable option (a 0-d array) can change in place: never taken by identity
                pass
            else:
                self._last_mapper = (*args, mapper)
        if (
            progress is False
            and trajectory_dt is None
            and (type(theta) is float and type(I) is float or plain_point(theta, I))
        ):
            # One point: on this thread (n_threads is checked, not used), the result made by the
            # core, no progress machinery: the batch path's return, bit for bit. The core checks
            # the point's range itself (section_points' messages): two floats need no other test.
            if type(n_threads) is not int or not 0 <= n_threads <= MAX_THREADS:
                thread_count(n_threads)  # its message
            return mapper.point(self.h, theta, I, ReturnMapResult)
        threads = _threads(n_threads, self.sys.python_defined)
        progress = check_progress(progress)
        z0, _, _ = self._points(theta, I)
        dt, per_orbit = (
            (0.0, 0)
            if trajectory_dt is None
            else trajectory_arguments(trajectory_dt, max_trajectory_points, z0.shape[0])
        )
        if progress is False:  # no bar; inside a parallel run's piece, its stop check (stop_hook)
            d = mapper.run(z0, threads, dt, per_orbit, stop_hook())
        else:
            with progress_bar(progress, z0.shape[0], desc="Section.return_map", unit="return") as bar:
                d = mapper.run(z0, threads, dt, per_orbit, bar.part(0) or None)
        # The image's coordinates, computed once by the tracer's chart check; NaN where there is no
        # image (a stopped orbit's z is its last state, which need not have coordinates).
        c = d["chart"]
        res = ReturnMapResult._make(
            dict(
                theta=c[:, 0],
                I=c[:, 1],
                z=d["z"],
                time=d["time"],
                itinerary=d["itinerary"],
                status=d["status"],
                energy_error=d["energy_error"],
                steps=d["steps"],
                region=d["region"],
                work=d["work"],
                stepper=d["stepper"],
                trajectory=d.get("trajectory"),
                trajectory_index=d.get("trajectory_index"),
                trajectory_kind=d.get("trajectory_kind"),
                trajectory_truncated=d.get("trajectory_truncated"),
            )
        )
        if d["interrupted"]:
            exc = KeyboardInterrupt("return map interrupted; the finished returns are in .partial")
            exc.partial = res
            raise exc
        return res
