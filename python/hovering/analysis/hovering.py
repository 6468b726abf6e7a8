"""The hovering set HOV(eps) by its definition, on any map: truncated (F_eps, F_{eps1,eps2}) or the flow.

HOV(eps) is the set of points that impact under the eps = 0 map and never impact under the eps
map (sec:truncinvcurves). Both models share (phi, K): the flow's normal coordinates are those of
its own tangential curve, and a point is carried to eps = 0 by its normal coordinates, i.e. the
eps = 0 flow starts at (theta, I) = (phi, K + I_tan(h)). That is the identification under which
F_0 and F_eps act on one (phi, K) plane, as in the paper's definition and eq:hovsetsize.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field

import numpy as np

from .._arrays import unique
from .._checks import (
    MAX_SEED,
    check_memory,
    flag,
    integer,
    loaded_array,
    loaded_codes,
    loaded_range,
    random_seed,
    real_number,
    thread_count,
)
from .._core import analysis as _core_analysis
from .._core import truncated as _core_truncated
from .._deprecated import renamed_keywords
from .._display import Summarized
from .._enums import Status
from .._io.serial import Saveable
from .._progress import check_progress, progress_bar, stop_hook
from ..interface import MAX_STEPS, N_REGIONS, require_map
from ..parallel.checkpoint import Checkpoint
from ..parallel.executor import Executor, from_old_arguments, run_pieces
from ..parallel.executor import executor as open_executor
from .orbits import classify_orbits
from .zone import impact_zone_floor

__all__ = [
    "HoveringArea",
    "HoveringComponents",
    "hovering_area",
    "default_K_low",
    "default_depth",
    "check_estimate",
    "MAX_SAMPLES",
]

_log = logging.getLogger(__name__)

#: Names of the per-sample codes of :attr:`HoveringArea.component` (code = index).
COMPONENTS = ("none", "band", "islands", "under_floor")

#: Most samples :func:`hovering_area` takes.
MAX_SAMPLES = 2**53
#: Most doublings of the default box's depth (:func:`hovering_area`'s ``deepen``).
MAX_DEEPEN = 64

#: Points of the recorded orbit that classifies an island chain: classify_orbits needs 32 points
#: per island, so chains up to period 64 are found.
ORBIT_STEPS = 2048

#: Orbits classified per connected cluster of one-sided hovering points (spread over the cluster).
REPRESENTATIVES = 3


@dataclass(frozen=True)
class HoveringComponents:
    """The hovering set split by what its orbits do (:attr:`HoveringArea.components`).

    Every hovering sample lies in exactly one part, so ``band + islands + under_floor`` is
    :attr:`HoveringArea.area` (to rounding): the counts add up to the hovering samples.

    Attributes
    ----------
    band, band_error : float
        The non-resonant hovering band (eq:hovsetsize): hovering points whose orbit visits both
        J_0 and J_0u, "sometimes above the step and sometimes to its side". The error is two
        binomial sigmas of the part (the iteration error stays with the whole area).
    islands, islands_error : float
        Hovering points whose orbit stays on one side (J_0 only, never beside the step) above the
        zone's floor: island chains, which the definition counts and eq:hovsetsize does not.
    under_floor, under_floor_error : float
        Hovering points below the zone's floor (for a FlowMap its own floor curve,
        :func:`hovering.impact_zone_floor`: orbits that pass above the step every return
        there). The truncated maps have no floor (their zone reaches down to the band's edge, see
        :func:`hovering.impact_zone`): 0 there.
    periods : dict
        ``{period: area}`` of the ``islands`` part by chain period, from
        :func:`hovering.classify_orbits` of a recorded orbit; period 0 collects the points whose
        orbits were no island chain there (chaotic, sticky or undecided, e.g. period > 64).
    counts : dict
        Samples in each part: ``{"band": n, "islands": n, "under_floor": n}``.
    floor : str
        Where the floor came from: ``"flow"`` (the FlowMap's floor curve), ``"none"`` (a truncated
        map: no floor), ``"unneeded"`` (no one-sided hovering point, no search) or
        ``"not found: <why>"`` (the search failed; the one-sided points are then all in ``islands``).
    orbits_classified : int
        Orbits recorded and classified for the periods: up to 3 per connected cluster of
        one-sided points on the sample grid (one island of a chain is one cluster), not one per
        point (docs/orbit-classes.md measures the saving).
    orbit_steps : int
        Points of each classified orbit.

    Examples
    --------
    At the sign of eps that does not hover the leading-order theory predicts no hovering set;
    what the definition finds is a period-2 island chain:

    >>> import numpy as np, hovering
    >>> m = hovering.TruncatedMap(eps=-0.3, Omega0=hovering.OMEGA_G, theta_w=3 * np.pi / 4)
    >>> hv = hovering.hovering_area(m, 1000, 2000)   # N = 1000 steps, 2000 samples
    >>> c = hv.components
    >>> hv.theory, c.counts["band"], sorted(c.periods), c.floor
    (0.0, 0, [2], 'none')
    >>> bool(np.isclose(c.total, hv.area))
    True
    """

    band: float
    band_error: float
    islands: float
    islands_error: float
    under_floor: float
    under_floor_error: float
    periods: dict
    counts: dict
    floor: str
    orbits_classified: int
    orbit_steps: int

    @property
    def total(self) -> float:
        """``band + islands + under_floor``: the hovering area."""
        return self.band + self.islands + self.under_floor

    def __repr__(self) -> str:
        chains = ", ".join(f"{q}: {a:.4g}" if q else f"none: {a:.4g}" for q, a in sorted(self.periods.items()))
        return (
            f"HoveringComponents(band={self.band:.4g} +- {self.band_error:.2g}, islands={self.islands:.4g} "
            f"+- {self.islands_error:.2g} (by period {{{chains}}}), under_floor={self.under_floor:.4g} +- "
            f"{self.under_floor_error:.2g}, floor={self.floor!r})"
        )

    def _validate_loaded(self) -> None:
        """A file's components (untrusted): finite non-negative areas, integer counts and periods."""
        for name in ("band", "band_error", "islands", "islands_error", "under_floor", "under_floor_error"):
            real_number(name, getattr(self, name), lo=0.0, lo_open=False)
        for q, a in self.periods.items():
            integer("a period of periods", q, 0, 10**9)
            real_number(f"periods[{q}]", a, lo=0.0, lo_open=False)
        if set(self.counts) != {"band", "islands", "under_floor"}:
            raise ValueError(f"counts must have the keys band, islands, under_floor, got {sorted(self.counts)}")
        for k, v in self.counts.items():
            integer(f"counts[{k!r}]", v, 0, 2**62)
        integer("orbits_classified", self.orbits_classified, 0, 2**62)
        integer("orbit_steps", self.orbit_steps, 0, 2**62)


@dataclass(frozen=True, repr=False)
class HoveringArea(Summarized, Saveable):
    """Measured area of the hovering set HOV(eps) (see :func:`hovering_area`).

    Attributes
    ----------
    area : float
        Estimate at the largest iteration count.
    error : float
        ``2 * sampling_error + iteration_error``.
    sampling_error : float
        One standard deviation of the sampling (binomial; an upper bound for the stratified scheme).
    iteration_error : float
        Change of the estimate over the last doubling of the iteration count (estimates only fall
        as orbits are followed longer).
    theory : float
        Leading-order prediction (eq:hovsetsize, generalised by :func:`hovering.theory` to every
        Omega0 and the map's own forcing): 0 for the sign of eps that does not hover.
    areas : dict
        Estimate at each iteration count (N/4, N/2, N).
    n_samples : int
        Initial conditions sampled.
    box : tuple
        ``(phi_lo, phi_hi, K_lo, K_hi)`` of the sampled box.
    impact_fraction_F0 : float
        Fraction of the box that impacts under F_0 within N steps (part of the definition).
    floor_touched : bool
        Whether a hovering point lies in the lowest tenth of the box (the default box deepens
        itself then: see ``deepened``; with a given K_low, enlarge it).
    area_both_sides : float
        The part of ``area`` whose orbits visit both J_0 and J_0u: the paper's hovering orbits,
        "sometimes above the step and sometimes to its side". The rest, ``area - area_both_sides``,
        never impacts but never passes beside the step either: orbits below the impact zone (the
        flow's region under the deformed torus tangent to the upper wall) or islands inside J_0;
        the definition counts them, eq:hovsetsize does not.
    unresolved : int
        Sample points whose orbit ended otherwise (the flow's corner hits, grazing, step limits:
        counted as not hovering).
    components : HoveringComponents or None
        ``area`` split into the non-resonant band, island chains (by period) and the region under
        the zone's floor; None with ``components=False`` (and in files written before 0.3.0).
    deepened : int
        Times the default box was doubled in depth because ``floor_touched`` (0 with a given K_low):
        ``box`` is the box finally used.
    band_edge : bool
        The default box reached the lower edge of the map's band while the floor was still touched:
        it could not deepen further (the band ends first).
    phi, K, hovering, both_sides : ndarray or None
        Sample points, their membership, and whether their orbit visits both J_0 and J_0u, when
        ``keep_points`` was set.
    component, period : ndarray or None
        Per sample (``keep_points`` and ``components``): the part it lies in, as an index into
        ``("none", "band", "islands", "under_floor")`` (:data:`COMPONENTS`), and its chain period
        (0 outside ``islands`` or where no chain was found).
    seed : int or None
        The seed the samples were drawn with (:func:`hovering_area`'s ``rng``, or the seed drawn
        from a Generator or from fresh entropy): ``hovering_area(m, ..., rng=seed)`` draws them
        again. None in files that predate it.

    Examples
    --------
    >>> import numpy as np, hovering
    >>> m = hovering.TruncatedMap(eps=0.2, Omega0=hovering.OMEGA_G, theta_w=3 * np.pi / 4)
    >>> hv = hovering.hovering_area(m, 2000, 4000)   # N = 2000 steps, 4000 samples
    >>> sorted(hv.areas)                         # the estimates at N/4, N/2 and N
    [500, 1000, 2000]
    >>> print("box: phi in [%.4f, %.4f), K in [%.4f, %.1f)" % hv.box)
    box: phi in [-3.1416, 3.1416), K in [-0.4292, 0.0)
    >>> hv.floor_touched, hv.unresolved
    (False, 0)
    >>> bool(np.isclose(hv.error, 2 * hv.sampling_error + hv.iteration_error))
    True
    """

    area: float
    error: float
    sampling_error: float
    iteration_error: float
    theory: float
    areas: dict
    n_samples: int
    box: tuple
    impact_fraction_F0: float
    floor_touched: bool
    area_both_sides: float = float("nan")
    unresolved: int = 0
    phi: np.ndarray | None = field(default=None, repr=False)
    K: np.ndarray | None = field(default=None, repr=False)
    hovering: np.ndarray | None = field(default=None, repr=False)
    both_sides: np.ndarray | None = field(default=None, repr=False)
    components: HoveringComponents | None = None
    deepened: int = 0
    band_edge: bool = False
    component: np.ndarray | None = field(default=None, repr=False)
    period: np.ndarray | None = field(default=None, repr=False)
    seed: int | None = None

    def _validate_loaded(self) -> None:
        """A file's estimate (untrusted): what :func:`hovering_area` could have returned, or a
        ValueError naming the field, its value and the allowed range.

        The box ``(phi_lo, phi_hi, K_lo, K_hi)`` finite with ``lo < hi``; the estimate's numbers
        within what its box allows (:func:`check_estimate`), ``areas`` too; the kept points, when
        kept, one per sample; the seed None or an integer seed, as ``rng=`` takes it.
        """
        if not isinstance(self.box, tuple) or len(self.box) != 4:
            raise ValueError(f"box must be a tuple (phi_lo, phi_hi, K_lo, K_hi), got {self.box!r:.80}")
        phi_lo, phi_hi, K_lo, K_hi = (real_number(f"box[{i}]", v) for i, v in enumerate(self.box))
        box_area = (phi_hi - phi_lo) * (K_hi - K_lo)
        if not (phi_lo < phi_hi and K_lo < K_hi and math.isfinite(box_area)):
            raise ValueError(f"box = {self.box} must have phi_lo < phi_hi, K_lo < K_hi and a finite area")
        names = ("area", "error", "sampling_error", "iteration_error", "area_both_sides", "impact_fraction_F0")
        check_estimate({k: getattr(self, k) for k in names + ("n_samples", "unresolved")}, box_area)
        for N, a in self.areas.items():
            integer("an iteration count (key) of areas", N, 0, MAX_STEPS)
            _area(f"areas[{N}]", a, box_area)
        integer("deepened", self.deepened, 0, MAX_DEEPEN)
        for name, kinds in (("phi", "f"), ("K", "f"), ("hovering", "b"), ("both_sides", "b"), ("period", "iu")):
            if getattr(self, name) is not None:
                loaded_array(name, getattr(self, name), kinds, (self.n_samples,))
        if self.component is not None:
            loaded_range(
                "component", loaded_array("component", self.component, "iu", (self.n_samples,)), 0, len(COMPONENTS) - 1
            )
        if self.seed is not None:
            integer("seed", self.seed, 0, MAX_SEED)

    def _summary(self) -> list:
        return [
            ("area", f"{self.area:.6g} +- {self.error:.2g}"),
            ("theory", self.theory),
            ("area_both_sides", self.area_both_sides),
            ("n_samples", self.n_samples),
            ("N", max(self.areas) if self.areas else None),
            ("K_low", self.box[2]),
            ("floor_touched", self.floor_touched),
            ("unresolved", self.unresolved),
        ]

    def to_xarray(self):
        """The estimate as an :class:`xarray.Dataset` (needs ``hovering[xarray]``): the numbers as
        scalar variables, ``area_at_N`` over dimension ``n_steps`` (N/4, N/2, N), the sample points
        over ``sample`` when kept; units, ``box`` and provenance in attrs.

        Returns
        -------
        xarray.Dataset

        Raises
        ------
        ImportError
            Without xarray, naming ``pip install 'hovering[xarray]'``.
        """
        from .._io.interop import hovering_area_dataset

        return hovering_area_dataset(self)


def _area(name: str, value, box_area: float, times: int = 1) -> None:
    """``value`` a finite number in ``[0, times * box_area]``, or a ValueError naming it and the range."""
    # A fraction <= 1 of the box's area (count / n times it) may round an ulp above it.
    real_number(name, value, lo=0.0, lo_open=False, hi=times * box_area * (1 + 1e-12), hi_open=False)


def check_estimate(e: dict, box_area: float) -> None:
    """Check the numbers of an area estimate read from a file (a :class:`HoveringArea`'s fields, a
    sweep's checkpointed row) against what the estimate can be.

    The core's estimate counts samples of a box of area ``box_area``: every area (``area``,
    ``area_N2``, ``area_N4``, ``area_both_sides``) and ``sampling_error`` (``box_area sqrt(max(p (1 -
    p), 1 / n) / n)``) lie in ``[0, box_area]``, so does ``iteration_error`` (the fall of the area
    from N/2 to N iterates), and ``error = 2 sampling_error + iteration_error`` in ``[0, 3
    box_area]``; ``impact_fraction_F0`` is a fraction, ``n_samples`` at least 1 (the stratified
    grid has at most twice the samples asked for), ``unresolved`` at most ``n_samples``.
    Each of these numbers may be NaN: no estimate (a sweep's point that gave none, a file written
    before ``area_both_sides`` was measured), which the summaries print as ``nan``.

    Parameters
    ----------
    e : dict
        Field name -> value; only the names above that it holds are checked.
    box_area : float
        Area of the sampled box.

    Raises
    ------
    ValueError
        Naming the first field out of range, its value and the range.
    """

    def given(name):  # present, and not the NaN of "no estimate"
        return name in e and not (isinstance(e[name], float) and math.isnan(e[name]))

    for name in ("area", "area_N2", "area_N4", "area_both_sides", "sampling_error", "iteration_error", "error"):
        if given(name):
            _area(name, e[name], box_area, 3 if name == "error" else 1)
    if given("impact_fraction_F0"):
        real_number("impact_fraction_F0", e["impact_fraction_F0"], lo=0.0, lo_open=False, hi=1.0, hi_open=False)
    n = integer("n_samples", e["n_samples"], 1, 2 * MAX_SAMPLES) if "n_samples" in e else None
    if "unresolved" in e:
        integer("unresolved", e["unresolved"], 0, 2 * MAX_SAMPLES if n is None else n)


def _stratified(samples: int, K_low: float, seed: int, lo: int = 0, hi: int | None = None) -> tuple:
    """Samples lo..hi-1 ``(phi, K)`` of the box ``[-pi, pi) x [K_low, 0)``: one uniform point per cell
    of a near-square grid, jittered by ``numpy.random.default_rng(seed)`` (the core draws that
    stream: ``hovering._core.analysis.stratified_samples``).

    The grid has at most ``samples + n_phi`` cells whatever the box's aspect ratio (a thin box
    gets one row, not millions of columns).
    """
    return _core_analysis.stratified_samples(int(samples), float(K_low), int(seed), int(lo), hi)


def default_depth(m) -> float:
    """Depth of the default box below K = 0: twice the deepest leading-order curve through L1.

    ``2 |eps| max_psi |G(psi)|`` (:class:`hovering.Theory`, the map's own Omega0 and forcing), i.e.
    ``2 |eps| / |sin(Omega0/2)|`` for ``f = sin``; infinite when that is not finite (resonant
    Omega0), then the band's depth is used. Computed by the core
    (``hovering._core.analysis.default_depth``), which the sweep plans use too.
    """
    th = m.theory()
    return float(_core_analysis.default_depth(float(m.eps), float(th.Omega0), [float(b) for b in th.forcing]))


def default_K_low(m, band_lo: float | None = None) -> float:
    """Bottom of the default box of :func:`hovering_area`: ``-default_depth(m)`` (0.1 at eps = 0,
    which has no critical band), raised to just inside the band.

    The core's one rule (``hovering._core.analysis.default_K_low``), which :func:`hovering_area`
    and the sweep plans' writers call alike.

    Parameters
    ----------
    m : ReturnMap
        The map.
    band_lo : float, optional
        Lower end of the band the box must lie in (default: the map's, ``m.valid_band()[0]``;
        ``-inf``: the default box uncut).

    Returns
    -------
    float
    """
    lo = m.valid_band()[0] if band_lo is None else float(band_lo)
    if m.eps == 0:  # no critical band: the core's fixed depth, and no theory to compute
        return float(_core_analysis.default_K_low(0.0, 0.0, [], lo))
    th = m.theory()
    return float(_core_analysis.default_K_low(float(m.eps), float(th.Omega0), [float(b) for b in th.forcing], lo))


def _outcomes(m, phi, K, n_steps: int, n_threads: int, progress=False) -> tuple:
    """Per-sample outcomes (status under F_0, status, steps done, regions visited) of F_0 then F_eps
    with early exit from {J_0u, J_0}, by the core; KeyboardInterrupt on Ctrl-C."""
    if hasattr(m, "_core") and not isinstance(m, (_core_truncated.TruncatedMap, _core_truncated.TruncatedFamily)):
        m0 = m.with_eps(0.0)  # the flow's F_0: the eps = 0 flow on its own normal coordinates
        d = _core_analysis.hovering_outcomes(
            m._core, m0._core, phi, K, int(n_steps), _flow_threads(m, n_threads), progress or None
        )
    else:
        d = _core_analysis.hovering_outcomes(m, phi, K, int(n_steps), int(n_threads), progress or None)
    if d["interrupted"]:
        raise KeyboardInterrupt("hovering_area interrupted")
    return d["status_F0"], d["status"], d["steps_done"], d["visited"]


def _flow_threads(m, n_threads: int) -> int:
    # A potential defined in Python takes the GIL at every call: one thread (as FlowMap.iterate).
    return 1 if n_threads == 0 and m.sys.python_defined else int(n_threads)


def _piece(m, samples, K_low, seed, lo, hi, n_steps: int, n_threads: int):
    """The outcomes of samples lo..hi-1 (a piece of a distributed run: it draws its own samples)."""
    phi, K = _stratified(samples, K_low, seed, lo, hi)
    return _outcomes(m, phi, K, n_steps, n_threads, stop_hook() or False)


def _map_key(m):
    """The map's record as a checkpoint keys it (:func:`hovering._io.serial.record_key`), or a
    ValueError, before any work, for a map that has none: a potential defined in Python
    (CustomPotential, a Potential subclass) is code, which no record holds."""
    from .._io.serial import record_key

    try:
        return record_key(m)
    except TypeError as e:
        raise ValueError(
            f"checkpoint= keys each piece by the map's record, and this map has none ({e}); "
            "run without a checkpoint, or with compiled potentials (Harmonic, Tan, Numerical)"
        ) from None


def _piece_key(m, n_steps, K_low, seed, samples, lo, hi, map_key=None) -> dict:
    """Everything that changes a piece's outcomes: the map's record (its parameters, integrator
    options, measured curve; ``map_key`` if already computed), the counts, the box, the seed and
    the piece's range."""
    return {
        "hovering_area_piece": {
            "map": _map_key(m) if map_key is None else map_key,
            "n_steps": int(n_steps),
            "K_low": float(K_low),
            "seed": int(seed),
            "samples": int(samples),
            "lo": int(lo),
            "hi": int(hi),
        }
    }


def _piece_arrays(row, n: int, n_steps: int) -> tuple:
    """A checkpointed piece (untrusted): four lists of n integers, each within its array's dtype and
    what the core's outcomes hold: statuses of :class:`Status`, steps done in ``[0, n_steps]``,
    visited regions as bits of :class:`Region`'s codes."""
    names, dtypes = ("status_F0", "status", "steps_done", "visited"), (np.int8, np.int8, np.int64, np.int8)
    if not isinstance(row, dict) or not isinstance(row.get("outcomes"), list) or len(row["outcomes"]) != 4:
        raise ValueError(
            "row.outcomes must be a list of 4 lists (statuses under F_0 and F_eps, steps done, regions visited)"
        )
    out = []
    for name, a, dt in zip(names, row["outcomes"], dtypes):
        arr = np.asarray(a) if isinstance(a, list) else np.zeros(0, dtype=object)
        if (
            arr.shape != (n,)
            or arr.dtype.kind not in "iu"
            or (n and not (np.iinfo(dt).min <= arr.min() and arr.max() <= np.iinfo(dt).max))
        ):
            raise ValueError(f"row.outcomes.{name} must be {n} integers within {np.dtype(dt).name}")
        out.append(arr.astype(dt))
    loaded_codes("row.outcomes.status_F0", out[0], Status)
    loaded_codes("row.outcomes.status", out[1], Status)
    loaded_range("row.outcomes.steps_done", out[2], 0, n_steps)
    loaded_range("row.outcomes.visited", out[3], 0, 2**N_REGIONS - 1)
    return tuple(out)


def _distributed(m, n, n_steps, K_low, seed, samples, n_threads, bar, spec: Executor):
    # Checked before the pool starts: only a checkpoint needs the map's record (a map with a
    # Python-defined potential has none, and runs without one).
    map_key = _map_key(m) if spec.checkpoint is not None else None
    python_defined = bool(getattr(getattr(m, "sys", None), "python_defined", False))
    with open_executor(**spec.where()) as ex:
        ex.check_sendable(m, "the map")
        threads = n_threads if n_threads != 0 else ex.threads_per_piece
        if python_defined and n_threads == 0:
            threads = 1  # its calls serialise on the GIL: more core threads per piece only contend
        k = integer("pieces", spec.pieces if spec.pieces is not None else 4 * ex.workers, 1, max(1, n))
        bounds = [(n * i // k, n * (i + 1) // k) for i in range(k)]
        store = Checkpoint(spec.checkpoint) if spec.checkpoint is not None else None
        out = [None] * k
        todo = []
        for i, (lo, hi) in enumerate(bounds):
            row = None
            if store is not None:
                key = _piece_key(m, n_steps, K_low, seed, samples, lo, hi, map_key)
                row = store.get(key, lambda r, n=hi - lo: _piece_arrays(r, n, n_steps))
            if row is not None:
                out[i] = _piece_arrays(row, hi - lo, n_steps)
                bar.advance(2 * (hi - lo) * n_steps)
            else:
                todo.append(i)

        def done(j, res):
            i = todo[j]
            lo, hi = bounds[i]
            out[i] = res
            if store is not None:
                store.put(
                    _piece_key(m, n_steps, K_low, seed, samples, lo, hi, map_key),
                    {"outcomes": [np.asarray(a).tolist() for a in res]},
                )
            bar.advance(2 * (hi - lo) * n_steps)

        for _ in run_pieces(
            ex, _piece, [(m, samples, K_low, seed, *bounds[i], n_steps, threads) for i in todo], on_result=done
        ):
            pass
    return tuple(np.concatenate([o[j] for o in out]) for j in range(4))


def _clusters(one: np.ndarray, n_K: int) -> list:
    """Connected clusters of the samples ``one`` (bool per sample) on the sample grid: sample i sits
    in column ``i // n_K``, row ``i % n_K``; 8 neighbours, periodic in phi (the columns wrap). A
    list of index arrays (each sorted), by union-find over the marked samples only."""
    n_phi = one.size // n_K
    idx = np.flatnonzero(one)
    parent = {int(i): int(i) for i in idx}

    def find(a: int) -> int:
        while parent[a] != a:
            parent[a] = parent[parent[a]]  # path halving
            a = parent[a]
        return a

    for i in parent:
        c, r = divmod(i, n_K)
        # The four neighbours before i in scan order: each pair of neighbours is joined once.
        for dc, dr in ((0, -1), (-1, -1), (-1, 0), (-1, 1)):
            if 0 <= r + dr < n_K:
                j = ((c + dc) % n_phi) * n_K + r + dr
                if j in parent:
                    a, b = find(i), find(j)
                    if a != b:
                        parent[max(a, b)] = min(a, b)
    if idx.size == 0:
        return []
    roots = np.fromiter((find(int(i)) for i in idx), dtype=np.int64, count=idx.size)
    _, label = np.unique(roots, return_inverse=True)
    order = np.argsort(label, kind="stable")
    return np.split(idx[order], np.flatnonzero(np.diff(label[order])) + 1)


def _chain_periods(m, phi, K, one, n_K: int, n_threads: int) -> tuple:
    """The chain period of each sample of ``one`` (0 where none was found) and the number of
    orbits classified: per connected cluster, up to :data:`REPRESENTATIVES` samples spread over it
    are iterated for :data:`ORBIT_STEPS` points and classified (:func:`hovering.classify_orbits`);
    the cluster takes the commonest island period among them (the smallest on a tie)."""
    period = np.zeros(one.size, dtype=np.int64)
    groups = _clusters(one, n_K)
    if not groups:
        return period, 0
    reps = [unique(g[[g.size // 4, g.size // 2, (3 * g.size) // 4]]) for g in groups]
    flat = np.concatenate(reps)
    res = m.iterate(phi[flat], K[flat], ORBIT_STEPS - 1, record=("orbit",), n_threads=n_threads)
    classes = classify_orbits(res)
    start = 0
    for g, r in zip(groups, reps):
        kind, q = classes.kind[start : start + r.size], classes.period[start : start + r.size]
        start += r.size
        qs = q[kind == "islands"]
        if qs.size:
            values, counts = np.unique(qs, return_counts=True)
            period[g] = values[np.argmax(counts)]
    return period, int(flat.size)


def _split(m, phi, K, hovering, both_sides, samples: int, K_low: float, n_steps: int, n_threads: int) -> tuple:
    """The components of the hovering samples: (HoveringComponents, per-sample code, per-sample
    period). Only hovering samples that stay on one side cost anything: one floor search (a
    FlowMap's) and a few classified orbits per cluster."""
    n = phi.size
    code = np.zeros(n, dtype=np.int8)
    code[hovering & both_sides] = COMPONENTS.index("band")
    one = hovering & ~both_sides
    floor = "none"
    if hasattr(m, "upper_tangent_K"):  # a FlowMap: the zone has a floor of its own
        floor = "unneeded"
        if one.any():
            try:
                # Orbits of the search no longer than the measurement's own "never" (as impact_zone).
                curve = impact_zone_floor(m, n_steps=min(n_steps, 2000), n_threads=n_threads).curve
            except (ValueError, RuntimeError) as e:  # no curve found: say why, keep the points in `islands`
                floor = f"not found: {e}"
            else:
                floor = "flow"
                under = np.zeros(n, dtype=bool)
                under[one] = K[one] < curve(phi[one])
                code[under] = COMPONENTS.index("under_floor")
                one &= ~under
    code[one] = COMPONENTS.index("islands")
    period, classified = _chain_periods(m, phi, K, one, _core_analysis.sample_grid(samples, K_low)[1], n_threads)

    def part(mask):
        area, sigma = _core_analysis.part_area(int(np.count_nonzero(mask)), n, float(K_low))
        return area, 2 * sigma

    band, band_err = part(code == COMPONENTS.index("band"))
    isl, isl_err = part(one)
    under, under_err = part(code == COMPONENTS.index("under_floor"))
    periods = {int(q): part(one & (period == q))[0] for q in unique(period[one])}
    comp = HoveringComponents(
        band=band,
        band_error=band_err,
        islands=isl,
        islands_error=isl_err,
        under_floor=under,
        under_floor_error=under_err,
        periods=periods,
        counts={name: int(np.count_nonzero(code == COMPONENTS.index(name))) for name in COMPONENTS[1:]},
        floor=floor,
        orbits_classified=classified,
        orbit_steps=ORBIT_STEPS if classified else 0,
    )
    return comp, code, period


def _measure(m, n_steps, samples, K_low, seed, n_threads, progress, spec) -> tuple:
    """Samples, outcomes and the core's estimate (with the per-sample membership) of one box."""
    phi, K = _stratified(samples, K_low, seed)
    n = phi.size
    unit = getattr(m, "_progress_unit", "step")
    with progress_bar(progress, 2 * n * n_steps, desc="hovering_area", unit=unit) as bar:
        if spec is not None:
            s0, s1, steps_done, visited = _distributed(m, n, n_steps, K_low, seed, samples, n_threads, bar, spec)
        else:
            s0, s1, steps_done, visited = _outcomes(m, phi, K, n_steps, n_threads, bar.part(0))
    e = _core_analysis.hovering_estimate(s0, s1, steps_done, visited, K, int(n_steps), float(K_low), True)
    return phi, K, e


@renamed_keywords(samples="n_samples", seed="rng")
def hovering_area(
    m,
    n_steps: int = 10_000,
    n_samples: int = 100_000,
    K_low: float | None = None,
    rng: int | np.random.Generator | None = 0,
    n_threads: int = 0,
    keep_points: bool = False,
    progress=False,
    *,
    components: bool = True,
    deepen: int = 3,
    executor=None,
    workers: int | None = None,
    client=None,
    scheduler: str | None = None,
    dask: bool = False,
    pieces: int | None = None,
    checkpoint=None,
) -> HoveringArea:
    """Area of the hovering set HOV(eps) of a map, by its definition.

    HOV(eps) is the set of points that impact under F_0 (some iterate leaves J_0 u J_0u) and never
    impact under F_eps (every iterate stays in J_0 u J_0u). It lies in J_0, so the box
    ``[-pi, pi) x [K_low, 0)`` is sampled with one uniform point per cell of a near-square grid
    (stratified sampling). Each point is iterated under F_0 (``m.with_eps(0)``) and under F_eps
    with early exit: an orbit stops at its first impact, so only hovering orbits cost the full N
    steps. For the flow, F_0 is the eps = 0 flow in its own normal coordinates (see the module
    docstring); an orbit that hits the corner or grazes counts as impacting.

    Parameters
    ----------
    m : TruncatedMap, TruncatedFamily or FlowMap
        The map F_eps.
    n_steps : int, optional
        N: iterates that count as "never" (estimates at N/4 and N/2 come from the same run).
    n_samples : int, optional
        Number of sample points (rounded up to fill the grid). Formerly ``samples=`` (deprecated,
        still accepted with a DeprecationWarning).
    K_low : float, optional
        Bottom of the box. Default: twice the deepest leading-order critical curve (see
        :func:`default_depth`; ``-2 |eps| / |sin(Omega0/2)|`` for f = sin), clipped to the band;
        that box deepens itself (see ``deepen``). A given K_low is used as it is.
    rng : int, numpy.random.Generator or None, optional
        The jitter's randomness (SPEC 7): an integer seed in [0, 2**63 - 1] (default 0: the same
        samples every call), a Generator (one seed is drawn from it), or None (a seed from fresh
        OS entropy). The seed used is the result's ``seed``. Formerly ``seed=`` (deprecated, still
        accepted with a DeprecationWarning; giving both is a TypeError).
    n_threads : int, optional
        Worker threads (0 = all cores).
    keep_points : bool, optional
        Keep the sample points and their membership in the result (for plotting).
    progress : bool or callable, optional
        One report per box measured (both iterations, ``2 * n_samples * n_steps`` steps or
        returns): ``True`` a tqdm bar on stderr, a callable ``progress(done, total)``, ``False``
        (default) none. See :mod:`hovering._progress`.
    components : bool, optional
        Split the area into its parts (:class:`HoveringComponents`: the non-resonant band, island
        chains by period, the region under the zone's floor). Only hovering samples whose orbit
        stays on one side cost extra: a FlowMap's floor search (:func:`hovering.impact_zone_floor`)
        and a recorded orbit of 2048 points for up to 3 samples per connected cluster of them.
        ``False``: ``components`` is None.
    deepen : int, optional
        With the default box only: how many times it may double its depth (a fresh measurement of
        the deeper box each time, with the same ``n_samples``) while ``floor_touched``; it stops at
        the lower edge of the map's band (``band_edge``). 0 keeps the first box. >= 0.
    executor : None, int, str, distributed.Client or hovering.parallel.Executor, optional
        Where it runs (:func:`hovering.parallel.executor.as_executor`): ``None`` in this process on
        ``n_threads`` core threads; otherwise the samples are cut into pieces run on that many local
        worker threads (``int``), a Dask scheduler (address), a Dask client, or as an
        :class:`~hovering.parallel.Executor` says (a Dask LocalCluster, the number of pieces, a
        checkpoint file that keeps finished pieces, keyed by every parameter that changes them). The
        result is identical to the single-process one for the same ``rng``: each piece draws its own
        contiguous range of the samples (the core jumps the random stream ahead to it), and the
        estimate only counts.
    workers, client, scheduler, dask, pieces, checkpoint : optional
        Deprecated (removed in 0.4.0): the fields of ``executor=Executor(...)``; each warns.

    Returns
    -------
    HoveringArea

    Raises
    ------
    TypeError
        For an ``rng`` that is not None, an int or a Generator, or both ``rng`` and ``seed``.
    ValueError
        For counts that are not integers in range, or a K_low outside the band below 0; with an
        ``executor``, before any piece runs: for a ``checkpoint`` of a map that has no record to
        key its pieces by (a potential defined in Python), or a map the workers cannot receive (a
        process pool or Dask, and a map that does not pickle, e.g. a CustomPotential of lambdas;
        threads of this process take any map).
    KeyboardInterrupt
        On Ctrl-C, within ~0.1 s.

    Examples
    --------
    A quick estimate (the paper's tables use 1e5 samples and N = 1e4: 0.4985 +- 0.0066 here):

    >>> import numpy as np, hovering
    >>> m = hovering.TruncatedMap(eps=0.2, Omega0=hovering.OMEGA_G, theta_w=3 * np.pi / 4)
    >>> hv = hovering.hovering_area(m, 2000, 4000)   # N = 2000 steps, 4000 samples
    >>> round(hv.theory, 4)                      # eq:hovsetsize
    0.5093
    >>> bool(abs(hv.area - hv.theory) < hv.error), bool(hv.error < 0.05)
    (True, True)
    """
    require_map("m", m)
    n_steps = integer("n_steps", n_steps, 4, 2**53)
    samples = integer("n_samples", n_samples, 1, MAX_SAMPLES)
    keep_points = flag("keep_points", keep_points)
    components = flag("components", components)
    deepen = integer("deepen", deepen, 0, MAX_DEEPEN)
    seed = random_seed(rng)
    n_threads = thread_count(n_threads)
    progress = check_progress(progress)
    check_memory(f"hovering_area with {samples} samples", 64 * samples)
    lo = m.valid_band()[0]
    if not lo < 0:
        raise ValueError(
            f"this map's band has no part below K = 0 (lower end {lo}): no point impacts under F_0, nothing can hover"
        )
    bottom = _core_analysis.box_floor(lo)  # the deepest box inside the band
    default_box = K_low is None
    if default_box:
        K_low = default_K_low(m, lo)
    K_low = real_number("K_low", K_low)
    if not (lo < K_low < 0):
        raise ValueError(f"K_low must lie in the band below 0, ({lo}, 0), got {K_low}")
    spec = from_old_arguments(
        "hovering_area",
        executor,
        dict(workers=workers, client=client, scheduler=scheduler, dask=dask, pieces=pieces, checkpoint=checkpoint),
    )
    deepened, band_edge = 0, False
    t0 = time.perf_counter()
    while True:
        t = time.perf_counter()
        phi, K, e = _measure(m, n_steps, samples, K_low, seed, n_threads, progress, spec)
        _log.debug(
            "hovering_area: box K in [%.4g, 0), %d samples x %d %ss (both maps), %s, %.1f s",
            K_low, phi.size, n_steps, getattr(m, "_progress_unit", "step"),
            "floor touched" if e["floor_touched"] else "floor clear", time.perf_counter() - t,
        )  # fmt: skip
        if not (default_box and e["floor_touched"]):
            break
        if K_low <= bottom:  # the band ends first: nothing deeper to sample
            band_edge = True
            break
        if deepened == deepen:
            break
        # A fresh box: a deeper box's stratified grid shares no point with this one, and its
        # estimate is the core's count over one box (no stitching of two densities).
        K_low, deepened = max(2.0 * K_low, bottom), deepened + 1
    hovering, both = e["hovering"], e["both_sides"]
    comp = code = period = None
    if components:
        t = time.perf_counter()
        comp, code, period = _split(m, phi, K, hovering, both, samples, K_low, n_steps, n_threads)
        _log.debug(
            "hovering_area: components (floor %s, %d orbits classified), %.1f s",
            comp.floor, comp.orbits_classified, time.perf_counter() - t,
        )  # fmt: skip
    theory = float(m.theory().area)
    _log.info(
        "hovering_area: area %.6g +- %.2g (theory %.6g), %d samples, seed %d, %.1f s",
        e["area"], e["error"], theory, phi.size, seed, time.perf_counter() - t0,
    )  # fmt: skip
    return HoveringArea(
        area=e["area"],
        error=e["error"],
        sampling_error=e["sampling_error"],
        iteration_error=e["iteration_error"],
        theory=theory,
        areas={n_steps // 4: e["area_N4"], n_steps // 2: e["area_N2"], n_steps: e["area"]},
        n_samples=int(e["n_samples"]),
        box=(-math.pi, math.pi, K_low, 0.0),
        impact_fraction_F0=e["impact_fraction_F0"],
        floor_touched=bool(e["floor_touched"]),
        area_both_sides=e["area_both_sides"],
        unresolved=int(e["unresolved"]),
        phi=phi if keep_points else None,
        K=K if keep_points else None,
        hovering=hovering if keep_points else None,
        both_sides=both if keep_points else None,
        components=comp,
        deepened=deepened,
        band_edge=band_edge,
        component=code if keep_points else None,
        period=period if keep_points else None,
        seed=seed,
    )
