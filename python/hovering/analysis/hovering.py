"""The hovering set HOV(eps) by its definition, on any map: truncated (F_eps, F_{eps1,eps2}) or the flow.

HOV(eps) is the set of points that impact under the eps = 0 map and never impact under the eps
map (sec:truncinvcurves). Both models share (phi, K): the flow's normal coordinates are those of
its own tangential curve, and a point is carried to eps = 0 by its normal coordinates, i.e. the
eps = 0 flow starts at (theta, I) = (phi, K + I_tan(h)). That is the identification under which
F_0 and F_eps act on one (phi, K) plane, as in the paper's definition and eq:hovsetsize.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._checks import check_memory, flag, integer, real_number, thread_count
from .._core import analysis as _core_analysis
from .._core import truncated as _core_truncated
from .._display import Summarized
from .._progress import check_progress, progress_bar, stop_hook
from .._serial import Saveable
from ..interface import require_map
from ..parallel.checkpoint import Checkpoint
from ..parallel.executor import Executor, from_old_arguments, run_pieces
from ..parallel.executor import executor as open_executor

__all__ = ["HoveringArea", "hovering_area"]


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
        Whether a hovering point lies in the lowest tenth of the box (then enlarge it: K_low).
    area_both_sides : float
        The part of ``area`` whose orbits visit both J_0 and J_0u: the paper's hovering orbits,
        "sometimes above the step and sometimes to its side". The rest, ``area - area_both_sides``,
        never impacts but never passes beside the step either: orbits below the impact zone (the
        flow's region under the deformed torus tangent to the upper wall) or islands inside J_0;
        the definition counts them, eq:hovsetsize does not.
    unresolved : int
        Sample points whose orbit ended otherwise (the flow's corner hits, grazing, step limits:
        counted as not hovering).
    phi, K, hovering, both_sides : ndarray or None
        Sample points, their membership, and whether their orbit visits both J_0 and J_0u, when
        ``keep_points`` was set.
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
        from .._interop import hovering_area_dataset

        return hovering_area_dataset(self)


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


def _piece_key(m, n_steps, K_low, seed, samples, lo, hi) -> dict:
    """Everything that changes a piece's outcomes: the map's record (its parameters, integrator
    options, measured curve), the counts, the box, the seed and the piece's range."""
    from .._serial import record_key

    return {
        "hovering_area_piece": {
            "map": record_key(m),
            "n_steps": int(n_steps),
            "K_low": float(K_low),
            "seed": int(seed),
            "samples": int(samples),
            "lo": int(lo),
            "hi": int(hi),
        }
    }


def _piece_arrays(row, n: int) -> tuple:
    """A checkpointed piece (untrusted): four lists of n integers, each within its array's dtype."""
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
    return tuple(out)


def _distributed(m, n, n_steps, K_low, seed, samples, n_threads, bar, spec: Executor):
    with open_executor(**spec.where()) as ex:
        threads = n_threads if n_threads != 0 else ex.threads_per_piece
        k = integer("pieces", spec.pieces if spec.pieces is not None else 4 * ex.workers, 1, max(1, n))
        bounds = [(n * i // k, n * (i + 1) // k) for i in range(k)]
        store = Checkpoint(spec.checkpoint) if spec.checkpoint is not None else None
        out = [None] * k
        todo = []
        for i, (lo, hi) in enumerate(bounds):
            key = _piece_key(m, n_steps, K_low, seed, samples, lo, hi)
            row = store.get(key, lambda r, n=hi - lo: _piece_arrays(r, n)) if store else None
            if row is not None:
                out[i] = _piece_arrays(row, hi - lo)
                bar.advance(2 * (hi - lo) * n_steps)
            else:
                todo.append(i)

        def done(j, res):
            i = todo[j]
            lo, hi = bounds[i]
            out[i] = res
            if store is not None:
                store.put(
                    _piece_key(m, n_steps, K_low, seed, samples, lo, hi),
                    {"outcomes": [np.asarray(a).tolist() for a in res]},
                )
            bar.advance(2 * (hi - lo) * n_steps)

        for _ in run_pieces(
            ex, _piece, [(m, samples, K_low, seed, *bounds[i], n_steps, threads) for i in todo], on_result=done
        ):
            pass
    return tuple(np.concatenate([o[j] for o in out]) for j in range(4))


def hovering_area(
    m,
    n_steps: int = 10_000,
    samples: int = 100_000,
    K_low: float | None = None,
    seed: int = 0,
    n_threads: int = 0,
    keep_points: bool = False,
    progress=False,
    *,
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
    samples : int, optional
        Number of sample points (rounded up to fill the grid).
    K_low : float, optional
        Bottom of the box. Default: twice the deepest leading-order critical curve (see
        :func:`default_depth`; ``-2 |eps| / |sin(Omega0/2)|`` for f = sin), clipped to the band.
    seed : int, optional
        Seed of the jitter.
    n_threads : int, optional
        Worker threads (0 = all cores).
    keep_points : bool, optional
        Keep the sample points and their membership in the result (for plotting).
    progress : bool or callable, optional
        One report for the whole call (both iterations, ``2 * n_samples * n_steps`` steps or
        returns): ``True`` a tqdm bar on stderr, a callable ``progress(done, total)``, ``False``
        (default) none. See :mod:`hovering._progress`.
    executor : None, int, str, distributed.Client or hovering.parallel.Executor, optional
        Where it runs (:func:`hovering.parallel.executor.as_executor`): ``None`` in this process on
        ``n_threads`` core threads; otherwise the samples are cut into pieces run on that many local
        worker threads (``int``), a Dask scheduler (address), a Dask client, or as an
        :class:`~hovering.parallel.Executor` says (a Dask LocalCluster, the number of pieces, a
        checkpoint file that keeps finished pieces, keyed by every parameter that changes them). The
        result is identical to the single-process one for the same seed: each piece draws its own
        contiguous range of the samples (the core jumps the random stream ahead to it), and the
        estimate only counts.
    workers, client, scheduler, dask, pieces, checkpoint : optional
        Deprecated (removed in 0.4.0): the fields of ``executor=Executor(...)``; each warns.

    Returns
    -------
    HoveringArea

    Raises
    ------
    ValueError
        For counts that are not integers in range, or a K_low outside the band below 0.
    """
    require_map("m", m)
    n_steps = integer("n_steps", n_steps, 4, 2**53)
    samples = integer("samples", samples, 1, 2**53)
    keep_points = flag("keep_points", keep_points)
    seed = integer("seed", seed, 0, 2**63 - 1)
    n_threads = thread_count(n_threads)
    progress = check_progress(progress)
    check_memory(f"hovering_area with {samples} samples", 64 * samples)
    lo = m.valid_band()[0]
    if not lo < 0:
        raise ValueError(
            f"this map's band has no part below K = 0 (lower end {lo}): no point impacts under F_0, nothing can hover"
        )
    if K_low is None:
        depth = default_depth(m) if m.eps != 0 else 0.1
        K_low = max(-depth, lo * (1 - 1e-9))
    K_low = real_number("K_low", K_low)
    if not (lo < K_low < 0):
        raise ValueError(f"K_low must lie in the band below 0, ({lo}, 0), got {K_low}")
    phi, K = _stratified(samples, K_low, seed)
    n = phi.size
    unit = getattr(m, "_progress_unit", "step")
    spec = from_old_arguments(
        "hovering_area",
        executor,
        dict(workers=workers, client=client, scheduler=scheduler, dask=dask, pieces=pieces, checkpoint=checkpoint),
    )
    with progress_bar(progress, 2 * n * n_steps, desc="hovering_area", unit=unit) as bar:
        if spec is not None:
            s0, s1, steps_done, visited = _distributed(m, n, n_steps, K_low, seed, samples, n_threads, bar, spec)
        else:
            s0, s1, steps_done, visited = _outcomes(m, phi, K, n_steps, n_threads, bar.part(0))
    e = _core_analysis.hovering_estimate(s0, s1, steps_done, visited, K, int(n_steps), float(K_low), keep_points)
    return HoveringArea(
        area=e["area"],
        error=e["error"],
        sampling_error=e["sampling_error"],
        iteration_error=e["iteration_error"],
        theory=float(m.theory().area),
        areas={n_steps // 4: e["area_N4"], n_steps // 2: e["area_N2"], n_steps: e["area"]},
        n_samples=int(e["n_samples"]),
        box=(-math.pi, math.pi, K_low, 0.0),
        impact_fraction_F0=e["impact_fraction_F0"],
        floor_touched=bool(e["floor_touched"]),
        area_both_sides=e["area_both_sides"],
        unresolved=int(e["unresolved"]),
        phi=phi if keep_points else None,
        K=K if keep_points else None,
        hovering=e["hovering"] if keep_points else None,
        both_sides=e["both_sides"] if keep_points else None,
    )
