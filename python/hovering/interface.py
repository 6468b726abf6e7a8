"""The one interface both models share: a return map on (phi, K), its result type and the argument
checks of its calls (DynamicalSystemsBase's idea that a flow's Poincare map *is* a map). Every
analysis is written once against it; it lives below every model, so models and analyses import it,
never each other.
"""

from __future__ import annotations

import operator
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, fields
from typing import Protocol, runtime_checkable

import numpy as np

from ._checks import _short, check_memory, integer, is_choice, loaded_array, loaded_codes, loaded_range, real_number
from ._deprecated import moved_method
from ._display import Summarized, status_counts
from ._enums import Region, Status, TrajectoryPoint, region_mask, status_code
from ._io.serial import Saveable
from .curve import StopCondition

__all__ = [
    "ReturnMap",
    "IterateResult",
    "StepJacobian",
    "MapAnalyses",
    "iterate_arguments",
    "transport_arguments",
    "recorded_counts",
    "trajectory_arguments",
    "trajectory_rows",
    "require_map",
    "MAX_TRAJECTORY_POINTS",
    "MAX_STEPS",
    "N_REGIONS",
]

#: Most steps per orbit, and the largest recording stride, an ``iterate`` call takes.
MAX_STEPS = 2**53
#: Regions a return is taken from (every :class:`Region` but NONE): the columns of ``residence``,
#: the bits of ``visited``.
N_REGIONS = sum(1 for r in Region if r.value >= 0)


@runtime_checkable
class ReturnMap(Protocol):
    """What :mod:`hovering.analysis` needs of a map: TruncatedMap, TruncatedFamily and FlowMap have it."""

    eps: float

    def step(self, phi, K):
        """One forward step."""

    def step_inverse(self, phi, K):
        """One backward step."""

    def region(self, phi, K):
        """Region of the return from each point."""

    def iterate(
        self,
        phi0,
        K0,
        n_steps: int,
        record: Sequence[str] = ...,
        exit_regions: Iterable | None = None,
        stop_on_exit: bool = False,
        n_threads: int = 0,
        progress=False,
        every: int = 1,
        stop: StopCondition | None = None,
    ):
        """Many orbits at once -> IterateResult (progress: see hovering._progress; every, stop: see
        :meth:`hovering.TruncatedMap.iterate`)."""

    def jacobian(self, phi, K):
        """One step with its Jacobian d(phibar, Kbar)/d(phi, K) -> StepJacobian."""

    def with_eps(self, eps: float) -> ReturnMap:
        """The same map at another eps (F_0 for the hovering set's definition)."""

    def valid_band(self) -> tuple[float, float]:
        """Open interval of K on which the map is defined."""

    def theory(self):
        """Leading-order predictions (hovering.Theory) for this map's parameters."""

    def L1(self, K):
        """Angle of the line L1 at heights K (def:L1L2)."""

    def L2(self, K):
        """Angle of the line L2 at heights K (def:L1L2)."""


class MapAnalyses:
    """What every map has beside its interface (mixed into TruncatedMap, TruncatedFamily, FlowMap).

    The analyses are free functions of a map, written once in :mod:`hovering.analysis`
    (``hovering.hovering_area(m)``, ``hovering.critical_curve(m)``), never methods: a model sits
    below the analyses and never calls up to them. The methods of those names are deprecated
    (:func:`hovering._deprecated.moved_method`).
    """

    hovering_area = moved_method("hovering_area", "hovering.analysis.hovering_area")
    critical_curve = moved_method("critical_curve", "hovering.analysis.critical_curve")

    def hovers(self) -> bool:
        """Whether the leading-order theory predicts a hovering set for this map (see :meth:`theory`)."""
        return bool(self.theory().hovers)  # type: ignore[attr-defined]  # every ReturnMap has theory()


@dataclass(frozen=True, repr=False)
class IterateResult(Summarized, Saveable):
    """Outcome of :meth:`TruncatedMap.iterate` for ``n_orbits`` orbits of ``n_steps`` steps.

    Every per-state and per-return record keeps every ``every``-th entry (``iterate(...,
    every=k)``): the states ``x_0, x_k, x_2k, ...`` (``n_steps // k + 1`` per orbit) and the returns
    taken from them (``ceil(n_steps / k)`` per orbit); ``every=1`` keeps all.

    Attributes
    ----------
    phi, K : ndarray or None
        Orbits, shape ``(n_orbits, n_steps // every + 1)`` (column j is the state ``x_{j every}``),
        when ``"orbit"`` was recorded; NaN for the states an orbit did not reach (after it
        stopped: see ``status`` and ``steps_done``).
    region : ndarray of int8 or None
        Region code (:class:`Region`) of the point each step was taken from, shape
        ``(n_orbits, ceil(n_steps / every))`` (column j: the return from ``x_{j every}``), when
        ``"regions"`` was recorded; ``Region.NONE`` (-1) for the returns not taken. With
        ``stop_on_exit`` the return that leaves ``exit_regions`` is recorded (at ``exit_step``),
        though the orbit does not take it: it stops at ``x_{exit_step}``.
    rotation : ndarray or None
        The paper's rotation number rho: the mean of omega_a over the steps taken (NaN for an
        orbit that took no step), when ``"rotation"`` was recorded.
    phi_final, K_final : ndarray
        Last state reached by each orbit.
    status : ndarray of int8
        Per-orbit :class:`Status` (``STOPPED``: it reached the set of ``stop``).
    steps_done : ndarray of int64
        Number of steps each orbit took.
    exit_step : ndarray of int64 or None
        First n at which the orbit point lay outside ``exit_regions`` (-1 if never), when
        ``exit_regions`` was given.
    stop_step : ndarray of int64 or None
        With ``stop``: the first n at which the state ``x_n`` lay in the stop set (-1 if never);
        the start counts (0: it started there). The orbit stopped there (``STOPPED``,
        ``steps_done == stop_step``, final state ``x_{stop_step}``, the first state in the set).
    K_min, K_max : ndarray or None
        Record ``"extrema"``: per orbit, the least and greatest K (I in the flow's section
        coordinates) over the states ``x_0 .. x_{steps_done}``, start and final state included
        (streamed: nothing per step is stored; ``every`` does not thin them).
    residence : ndarray of int64 or None
        Record ``"residence"``: per orbit, the number of returns taken from each region, shape
        ``(n_orbits, 5)``, columns in :class:`Region` order (BESIDE, ABOVE, UPPER, RIGHT, MULTI;
        MULTI only on the flow). It counts the returns ``region`` would record with ``every=1``:
        ``steps_done`` of them, plus the exiting one with ``stop_on_exit``; a region has a
        nonzero count exactly when ``visited`` has its bit.
    every : int
        The recording stride the result was made with.
    n_steps : int
        Steps requested per orbit.
    map : TruncatedMap, TruncatedFamily or FlowMap
        The map that produced the result (used by :func:`hovering.rotation_number`).
    theta, I : ndarray or None
        Flow only, record ``"section"``: section coordinates of the orbit points.
    z : ndarray or None
        Flow only, record ``"states"``: the points of Sigma_h, shape ``(n_orbits, n_steps + 1, 4)``.
    time, energy_error : ndarray or None
        Flow only, records ``"times"``, ``"energy_error"``: per return, shape ``(n_orbits,
        ceil(n_steps / every))`` (``|H - h|`` of each image before it is put back on Sigma_h); NaN
        for the returns not taken.
    integrator_steps : ndarray of int64 or None
        Flow only, record ``"steps"``: accepted integrator steps of each return (-1 for the
        returns not taken).
    itinerary : list of list of str or None
        Flow only, record ``"itinerary"``: each return's impacts ('R', '1', ...) or '0' / 'u'
        ('' on the smooth flow, which has no walls); ``'-'`` for a return not taken (the orbit had
        stopped; no return's itinerary is '-').
    visited : ndarray of int8 or None
        Record ``"visited"``: per orbit, bit r set when it took a step from a point of Region r
        (including the point where it left ``exit_regions``); e.g. a hovering orbit has the bits of
        both J_0 (ABOVE) and J_0u (BESIDE).
    trajectory : ndarray or None
        Flow only, record ``"trajectory"``: the flow between the returns, rows ``(t, q1, p1, q2,
        p2)`` of all orbits one after the other, shape ``(N_total, 5)`` (orbit i is
        ``trajectory[trajectory_index[i]:trajectory_index[i + 1]]``, see :meth:`trajectory_of`).
        Per orbit, in time order: the states at the uniform times ``t = k * trajectory_dt`` of the
        orbit's clock (it starts at 0 and runs on across returns), plus the exact states just
        before and after every impact (on the wall), each return point on Sigma_h and where the
        orbit stopped (``trajectory_kind`` tells which).
    trajectory_index : ndarray of int64 or None
        Offsets of each orbit's rows, shape ``(n_orbits + 1,)``.
    trajectory_kind : ndarray of int8 or None
        :class:`hovering.TrajectoryPoint` of each row: SAMPLE, IMPACT_IN, IMPACT_OUT, RETURN, END.
    trajectory_truncated : ndarray of bool or None
        Per orbit: it reached its share of ``max_trajectory_points`` and recorded no further point
        (the orbit itself was followed to the end).
    work : dict or None
        Flow only: what the integration did, summed over the call (ints): ``field_evaluations``,
        ``coupling_evaluations``, ``wall_searches``, ``section_searches``, ``label_operations``
        (crossings of q1 = qw1 and itinerary bookkeeping), ``dense_samples`` (trajectory samples),
        ``steps`` (accepted integrator steps). Effects nobody asked for cost nothing: no walls, no
        wall search; eps = 0, no coupling evaluation; no labels, no label operation; no trajectory,
        no dense sample.
    jacobian_q, jacobian_log, jacobian_r12 : ndarray or None
        Record ``"jacobian"``: per orbit, the product ``M = J_{n-1} ... J_1 J_0`` of the Jacobians
        of the ``n = steps_done`` steps it took (every step, whatever ``every``), kept in QR form
        so that it stays finite however long the orbit (Benettin's renormalisation):
        ``M = Q R``, ``Q = jacobian_q`` (rotation, shape ``(n_orbits, 2, 2)``), ``R =
        diag(exp(L1), exp(L2)) [[1, u], [0, 1]]`` with ``(L1, L2) = jacobian_log`` (shape
        ``(n_orbits, 2)``) and ``u = jacobian_r12``. ``L1 / n`` and ``L2 / n`` are the orbit's
        finite-time Lyapunov exponents, and ``L1 + L2`` the sum of ``log det J`` (0 for an
        area-preserving map, up to the Jacobians' own error). :meth:`jacobian` rebuilds ``M``.
    jacobian_status : ndarray of int8 or None
        Record ``"jacobian"``: :class:`Status` per orbit: ``OK``; ``CORNER`` (truncated map) when a
        step was taken from an arc start exactly, where the map is discontinuous and the factor is
        the one-sided derivative of the arc that owns the start; ``NON_FINITE`` (flow) when a
        return's Jacobian was not finite (left out of the product). An orbit that stops at a
        corner or a graze of the flow takes no return there: its status says so, and its product
        covers the returns it took.

    Examples
    --------
    >>> import numpy as np, hovering
    >>> m = hovering.TruncatedMap(eps=0.3, Omega0=hovering.OMEGA_G, theta_w=3 * np.pi / 4)
    >>> K0 = np.array([-0.2, 0.0, 0.5])
    >>> res = m.iterate(m.L1(K0), K0, 100, record=("orbit", "regions", "extrema"), every=10)
    >>> res
    <IterateResult n_orbits=3, n_steps=100, every=10, status={OK: 3}, ...>
    >>> res.phi.shape, res.region.shape       # the states x_0, x_10, ..., x_100 and the returns from them
    ((3, 11), (3, 10))
    >>> res.n_orbits, res.count(hovering.Status.OK), res.steps_done.tolist()
    (3, 3, [100, 100, 100])
    >>> bool(np.all(res.K_min <= res.K.min(axis=1)))   # extrema: over every state, not only the kept ones
    True
    """

    phi: np.ndarray | None
    K: np.ndarray | None
    region: np.ndarray | None
    rotation: np.ndarray | None
    phi_final: np.ndarray
    K_final: np.ndarray
    status: np.ndarray
    steps_done: np.ndarray
    exit_step: np.ndarray | None
    n_steps: int
    map: object = field(default=None, repr=False, compare=False)
    theta: np.ndarray | None = None
    I: np.ndarray | None = None
    z: np.ndarray | None = None
    time: np.ndarray | None = None
    energy_error: np.ndarray | None = None
    integrator_steps: np.ndarray | None = None
    itinerary: list | None = None
    visited: np.ndarray | None = None
    trajectory: np.ndarray | None = field(default=None, repr=False)
    trajectory_index: np.ndarray | None = field(default=None, repr=False)
    trajectory_kind: np.ndarray | None = field(default=None, repr=False)
    trajectory_truncated: np.ndarray | None = field(default=None, repr=False)
    work: dict | None = None
    stop_step: np.ndarray | None = None
    K_min: np.ndarray | None = None
    K_max: np.ndarray | None = None
    residence: np.ndarray | None = None
    every: int = 1
    jacobian_q: np.ndarray | None = None
    jacobian_log: np.ndarray | None = None
    jacobian_r12: np.ndarray | None = None
    jacobian_status: np.ndarray | None = None

    @classmethod
    def from_core(cls, d: dict, m, n_steps: int, every: int, names: dict | None = None) -> IterateResult:
        """The result of a core iterate's output dict: one reader for every map.

        Parameters
        ----------
        d : dict
            What the compiled iterate returned (records absent from it stay None).
        m : object
            The map that iterated.
        n_steps, every : int
            The call's arguments.
        names : dict, optional
            ``{field: key}`` where the core names a field otherwise (the flow's ``x``, ``y``).

        Returns
        -------
        IterateResult

        Raises
        ------
        KeyboardInterrupt
            If the core was interrupted; the result so far is its ``partial`` attribute.
        """
        names = names or {}
        keys = cls.__dict__.get("_field_names")
        if keys is None:  # the fields, listed once per class (dataclasses.fields costs ~1 us a field)
            keys = tuple(f.name for f in fields(cls) if f.name not in ("n_steps", "map", "every"))
            cls._field_names = keys
        values = {k: d.get(names.get(k, k)) for k in keys}
        values.update(n_steps=n_steps, map=m, every=every)
        # Every field given: the dataclass's __init__ would only set them, one frozen setattr each.
        res = object.__new__(cls)
        res.__dict__.update(values)
        if d["interrupted"]:
            exc = KeyboardInterrupt("iteration interrupted; the state reached is in .partial")
            exc.partial = res  # type: ignore[attr-defined]
            raise exc
        return res

    def _validate_loaded(self) -> None:
        """A file's result (untrusted): what ``iterate`` could have returned, or a ValueError naming
        the field.

        ``n_steps`` and ``every`` as ``iterate`` takes them; each record an array of its dtype kind
        and of the shape ``n_orbits``, ``n_steps`` and ``every`` give it (:func:`recorded_counts`);
        codes members of their enums (:class:`Status`, :class:`Region`, :class:`TrajectoryPoint`);
        step counts within ``[0, n_steps]``; the map a map (or None).
        """
        n_steps = integer("n_steps", self.n_steps, 0, MAX_STEPS)
        every = integer("every", self.every, 1, MAX_STEPS)
        if self.map is not None:
            require_map("map", self.map)
        n = loaded_array("status", self.status, "iu", (None,)).shape[0]
        states, returns = recorded_counts(n_steps, every)
        layout = {  # field: (dtype kinds, shape)
            "phi_final": ("f", (n,)),
            "K_final": ("f", (n,)),
            "steps_done": ("iu", (n,)),
            **dict.fromkeys(("phi", "K", "theta", "I"), ("f", (n, states))),
            "z": ("f", (n, states, 4)),
            "region": ("iu", (n, returns)),
            **dict.fromkeys(("time", "energy_error"), ("f", (n, returns))),
            "integrator_steps": ("iu", (n, returns)),
            **dict.fromkeys(("rotation", "K_min", "K_max", "jacobian_r12"), ("f", (n,))),
            **dict.fromkeys(("exit_step", "stop_step", "visited", "jacobian_status"), ("iu", (n,))),
            "residence": ("iu", (n, N_REGIONS)),
            "jacobian_q": ("f", (n, 2, 2)),
            "jacobian_log": ("f", (n, 2)),
            "trajectory": ("f", (None, 5)),
            "trajectory_index": ("iu", (n + 1,)),
            "trajectory_kind": ("iu", (None,)),
            "trajectory_truncated": ("b", (n,)),
        }
        for name, (kinds, shape) in layout.items():
            a = getattr(self, name)
            if a is not None or name in ("phi_final", "K_final", "steps_done"):  # every result has these
                loaded_array(name, a, kinds, shape)
        # Recorded together, used together (jacobian(), trajectory_of()): all of a group or none.
        for group in (
            ("jacobian_q", "jacobian_log", "jacobian_r12", "jacobian_status"),
            ("trajectory", "trajectory_index", "trajectory_kind", "trajectory_truncated"),
        ):
            given = [g for g in group if getattr(self, g) is not None]
            if given and len(given) != len(group):
                raise ValueError(f"{', '.join(group)} are recorded together; the file has only {', '.join(given)}")
        loaded_codes("status", self.status, Status)
        loaded_range("steps_done", self.steps_done, 0, n_steps)
        for name, enum in (("jacobian_status", Status), ("region", Region), ("trajectory_kind", TrajectoryPoint)):
            if getattr(self, name) is not None:
                loaded_codes(name, getattr(self, name), enum)
        for name, lo, hi in (
            ("exit_step", -1, n_steps),
            ("stop_step", -1, n_steps),
            ("integrator_steps", -1, MAX_STEPS),
            ("visited", 0, 2**N_REGIONS - 1),
            ("residence", 0, n_steps + 1),  # steps_done returns, and the exiting one
        ):
            if getattr(self, name) is not None:
                loaded_range(name, getattr(self, name), lo, hi)
        if self.trajectory is not None:
            rows = self.trajectory.shape[0]
            loaded_array("trajectory_kind", self.trajectory_kind, "iu", (rows,))  # a kind per row
            index = self.trajectory_index
            if index[0] != 0 or index[-1] != rows or np.any(index[1:] < index[:-1]):
                raise ValueError(
                    f"trajectory_index must rise from 0 to the {rows} rows of trajectory, got "
                    f"{int(index[0])}..{int(index[-1])}{'' if np.all(index[1:] >= index[:-1]) else ', not rising'}"
                )
        if self.itinerary is not None and (
            len(self.itinerary) != n
            or not all(
                isinstance(row, (list, tuple)) and len(row) == returns and all(isinstance(x, str) for x in row)
                for row in self.itinerary
            )
        ):
            raise ValueError(f"itinerary must be {n} lists (one per orbit) of {returns} strings (one per return)")
        if self.work is not None:
            for k, v in self.work.items():
                integer(f"work[{_short(k)}]", v, 0, 2**63 - 1)

    def trajectory_of(self, i: int) -> np.ndarray:
        """The recorded trajectory of orbit i: rows ``(t, q1, p1, q2, p2)``, shape ``(m_i, 5)`` (a view).

        Parameters
        ----------
        i : int
            Orbit index (negative counts from the end).

        Returns
        -------
        ndarray
            Its kinds are ``trajectory_kind[trajectory_index[i]:trajectory_index[i + 1]]``.

        Raises
        ------
        ValueError
            If no trajectory was recorded or i is out of range.
        """
        return trajectory_rows(self, i)

    @property
    def n_orbits(self) -> int:
        """Number of orbits."""
        return int(self.status.shape[0])

    def jacobian(self) -> np.ndarray:
        """The product of the Jacobians of each orbit's steps, rebuilt from its QR form.

        Returns
        -------
        ndarray
            Shape ``(n_orbits, 2, 2)``: ``Q diag(e^L1, e^L2) [[1, u], [0, 1]]``; entries overflow to
            +-inf once ``e^L1`` does (``L1 > 709``): use ``jacobian_q`` and ``jacobian_log`` then.

        Raises
        ------
        ValueError
            If ``"jacobian"`` was not recorded.
        """
        if self.jacobian_q is None:
            raise ValueError("no jacobian was recorded: pass record=(..., 'jacobian') to iterate")
        with np.errstate(over="ignore", invalid="ignore"):
            a = np.exp(self.jacobian_log[:, 0])
            d = np.exp(self.jacobian_log[:, 1])
            R = np.zeros((self.n_orbits, 2, 2))
            R[:, 0, 0] = a
            R[:, 0, 1] = a * self.jacobian_r12
            R[:, 1, 1] = d
            return np.einsum("nij,njk->nik", self.jacobian_q, R)

    def count(self, status: Status | int) -> int:
        """Number of orbits with the given status.

        Parameters
        ----------
        status : Status or int
            The outcome to count.

        Returns
        -------
        int
        """
        return int(np.count_nonzero(self.status == status_code(Status, status)))

    def _summary(self) -> list:
        out: list[tuple[str, object]] = [("n_orbits", self.n_orbits), ("n_steps", self.n_steps)]
        if self.every != 1:
            out.append(("every", self.every))
        out.append(("status", status_counts(self.status, Status)))
        out.append(("steps_done", f"{int(self.steps_done.min(initial=0))}..{int(self.steps_done.max(initial=0))}"))
        recorded = [
            f.name
            for f in fields(self)
            if isinstance(getattr(self, f.name), (np.ndarray, list))
            and f.name not in ("phi_final", "K_final", "status", "steps_done")
            and not f.name.startswith("trajectory_")
        ]
        out.append(("records", ", ".join(recorded) or "none"))
        if self.map is not None:
            out.append(("map", type(self.map).__name__))
        return out

    def to_xarray(self):
        """The result as an :class:`xarray.Dataset` (needs ``hovering[xarray]``).

        Dimensions ``orbit``, ``step`` (the kept states ``x_0, x_every, ...``, labelled by their
        step index) and ``return_step`` (the returns taken from them, labelled by the step they
        start from); ``region_name`` for the residence counts.
        Every per-orbit and per-state record present becomes a variable with its units and meaning
        in attrs; the dataset's attrs hold ``n_steps``, ``every``, the map's ``repr`` and the
        provenance of this installation (versions, build, machine). The flow's ``z`` and
        ``trajectory`` are left out (use the arrays).

        Returns
        -------
        xarray.Dataset

        Raises
        ------
        ImportError
            Without xarray, naming ``pip install 'hovering[xarray]'``.
        """
        from ._io.interop import iterate_dataset

        return iterate_dataset(self)


@dataclass(frozen=True, repr=False)
class StepJacobian(Summarized):
    """One step of each point with its Jacobian: what ``m.jacobian(phi, K)`` returns for every map.

    Attributes
    ----------
    phi, K : ndarray or float
        The images (as :meth:`step` gives them; NaN where the step has no number: see ``status``).
    J : ndarray
        ``d(phibar, Kbar) / d(phi, K)``, shape ``(..., 2, 2)`` (``(2, 2)`` for one point): rows
        ``(dphibar/dphi, dphibar/dK)``, ``(dKbar/dphi, dKbar/dK)``. NaN where ``status`` is not
        OK, except CORNER on the truncated map (see there).
    status : ndarray of int8 or Status
        :class:`Status` of each step: OK; CORNER (truncated map: the point lies exactly on an arc
        start, a corner-singularity curve, where the map jumps: ``J`` is the one-sided derivative
        of the arc that owns it; flow: the return hits the corner, no number); GRAZING (flow: a
        wall touched tangentially, where the derivative is infinite: no number); any other flow
        outcome (OFF_SECTION, STEP_LIMIT, IMPRECISE, ...), no number.
    region : ndarray of int8 or Region
        :class:`Region` of each step.
    """

    phi: np.ndarray
    K: np.ndarray
    J: np.ndarray
    status: np.ndarray
    region: np.ndarray

    @property
    def det(self):
        """``det J`` of each step (1 for an area-preserving map, up to the Jacobian's error)."""
        return np.linalg.det(self.J)

    def _summary(self) -> list:
        n = int(np.size(self.phi))
        out: list[tuple[str, object]] = [("n_points", n)]
        out.append(("status", status_counts(np.atleast_1d(np.asarray(self.status, dtype=np.int8)), Status)))
        return out

    @classmethod
    def from_core(cls, d: dict, shape: tuple) -> StepJacobian:
        """The result of a core jacobian call (flat arrays ``x, y, J, status, region``) in ``shape``.

        Raises
        ------
        KeyboardInterrupt
            If the core was interrupted (the flow's batch); the result so far is its ``partial``.
        """
        x, y = d["x"].reshape(shape), d["y"].reshape(shape)
        J = d["J"].reshape(shape + (2, 2))
        st, reg = d["status"].reshape(shape), d["region"].reshape(shape)
        if shape == ():
            res = cls(float(x), float(y), J, Status(int(st)), Region(int(reg)))
        else:
            res = cls(x, y, J, st, reg)
        if d.get("interrupted"):
            exc = KeyboardInterrupt("jacobians interrupted; the finished ones are in .partial")
            exc.partial = res  # type: ignore[attr-defined]
            raise exc
        return res


def require_map(name: str, m):
    """``m`` if it is a return map (TruncatedMap, TruncatedFamily, FlowMap: the ReturnMap protocol)."""
    if not isinstance(m, ReturnMap):
        raise ValueError(f"{name} must be a map (hovering.TruncatedMap, TruncatedFamily or FlowMap), got {_short(m)}")
    return m


def iterate_arguments(record, allowed, n_steps, exit_regions, stop_on_exit) -> tuple:
    """Check the arguments every map's ``iterate`` shares; ``(record tuple, n_steps, exit mask)``.

    Raises
    ------
    ValueError
        Naming the unknown record key, the bad step count or region, or an exit set that is
        empty or missing where ``stop_on_exit`` needs it.
    """
    if isinstance(record, str):
        record = (record,)
    try:
        record = tuple(record)
    except TypeError:
        raise ValueError(
            f"record must be a sequence of keys from {list(allowed)} (or () for none), got {record!r}"
        ) from None
    unknown = [r for r in record if not is_choice(r, allowed)]
    if unknown:
        raise ValueError(f"record: unknown key(s) {unknown}; allowed: {list(allowed)}")
    try:
        if isinstance(n_steps, (bool, np.bool_)):
            raise TypeError
        n_steps = operator.index(n_steps)
    except TypeError:
        raise ValueError(f"n_steps must be an integer >= 0, got {n_steps!r}") from None
    if n_steps < 0:
        raise ValueError(f"n_steps must be >= 0, got {n_steps}")
    if n_steps > MAX_STEPS:
        raise ValueError(f"n_steps must be <= 2**53, got {n_steps}")
    if isinstance(stop_on_exit, (bool, np.bool_)) is False:
        raise ValueError(f"stop_on_exit must be True or False, got {stop_on_exit!r}")
    try:
        mask = region_mask(exit_regions) if exit_regions is not None else 0
    except ValueError as e:
        raise ValueError(f"exit_regions: {e}") from None
    if exit_regions is not None and mask == 0:
        raise ValueError("exit_regions must name at least one region")
    if stop_on_exit and mask == 0:
        raise ValueError("stop_on_exit needs exit_regions (the regions an orbit must stay in)")
    return record, n_steps, mask


def transport_arguments(every, stop) -> tuple:
    """Check the recording stride and the stop condition of an ``iterate`` call.

    Parameters
    ----------
    every : int
        Record every k-th state, k >= 1.
    stop : Above, Below or None
        The stop condition.

    Returns
    -------
    (int, int, hovering._core.Curve or None)
        The stride, the core's side code (0 none, 1 above, 2 below) and the compiled curve.

    Raises
    ------
    ValueError
        For a stride that is not an integer >= 1, or a ``stop`` that is not ``hovering.Above(...)``
        or ``hovering.Below(...)`` (or None).
    """
    try:
        if isinstance(every, (bool, np.bool_)):
            raise TypeError
        k = operator.index(every)
    except TypeError:
        raise ValueError(f"every must be an integer >= 1 (record every k-th state), got {_short(every)}") from None
    if not 1 <= k <= MAX_STEPS:
        raise ValueError(f"every must be an integer in [1, 2**53] (record every k-th state), got {k}")
    if stop is None:
        return k, 0, None
    if not isinstance(stop, StopCondition) or type(stop) is StopCondition:
        raise ValueError(
            f"stop must be hovering.Above(curve_or_K) or hovering.Below(curve_or_K) (or None), got {_short(stop)}"
        )
    return k, stop._side, stop.curve._c


def recorded_counts(n_steps: int, every: int) -> tuple[int, int]:
    """States and returns an orbit's records keep with stride ``every``: ``(n_steps // every + 1,
    ceil(n_steps / every))`` (the core's recorded_states / recorded_returns)."""
    return n_steps // every + 1, -(-n_steps // every)


#: Default bound of the points a trajectory recording keeps in total (all orbits of one call):
#: 10 million points are ~410 MB (five float64 and one int8 each).
MAX_TRAJECTORY_POINTS = 10_000_000


def trajectory_arguments(trajectory_dt, max_trajectory_points, n_orbits: int) -> tuple:
    """Check the arguments of a trajectory recording before anything is computed.

    Parameters
    ----------
    trajectory_dt : float
        Sample spacing, > 0.
    max_trajectory_points : int
        Bound of the points of all orbits together.
    n_orbits : int
        Number of orbits of the call.

    Returns
    -------
    (float, int)
        The sample spacing and the points each orbit may keep (``max_trajectory_points //
        n_orbits``: an orbit that would record more stops recording and is flagged in
        ``trajectory_truncated``).

    Raises
    ------
    ValueError
        For a spacing that is not a finite number > 0, a bound below two points per orbit (the
        start and one more), or a bound whose worst case would not fit in memory.
    """
    dt = real_number("trajectory_dt", trajectory_dt, 0.0)
    least = 2 * max(n_orbits, 1)
    cap = integer(
        f"max_trajectory_points (at least 2 per orbit: {n_orbits} orbits)", max_trajectory_points, least, 2**62
    )
    per_orbit = cap // max(n_orbits, 1)
    # Per-orbit vectors (growing by doubling) and the flat arrays they are copied into: ~3x the
    # 41 bytes of a point in the worst case.
    check_memory(f"a trajectory of up to {cap} points (max_trajectory_points)", 3 * 41 * per_orbit * n_orbits)
    return dt, per_orbit


def trajectory_rows(res, i) -> np.ndarray:
    """Rows ``(t, q1, p1, q2, p2)`` of orbit i of a result with a recorded trajectory.

    Parameters
    ----------
    res : IterateResult or ReturnMapResult
        A result with ``trajectory`` and ``trajectory_index``.
    i : int
        Orbit index (negative counts from the end).

    Returns
    -------
    ndarray
        Shape ``(m_i, 5)``, a view into ``res.trajectory``.

    Raises
    ------
    ValueError
        If no trajectory was recorded or i is out of range.
    """
    if res.trajectory is None:
        raise ValueError(
            "no trajectory was recorded: pass record=('trajectory',) (FlowMap.iterate) or "
            "trajectory_dt (Section.return_map)"
        )
    n = res.trajectory_index.size - 1
    i = integer("i (orbit index)", i, -n, n - 1) % n
    return res.trajectory[res.trajectory_index[i] : res.trajectory_index[i + 1]]
