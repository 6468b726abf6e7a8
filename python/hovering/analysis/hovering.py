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
from typing import Optional

import numpy as np

from .._checks import check_memory, flag, integer, real_number, thread_count
from .._enums import Region, Status
from ..interface import require_map
from .._serial import Saveable
from .._progress import check_progress, progress_bar

__all__ = ["HoveringArea", "hovering_area"]


@dataclass(frozen=True)
class HoveringArea(Saveable):
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
    phi: Optional[np.ndarray] = field(default=None, repr=False)
    K: Optional[np.ndarray] = field(default=None, repr=False)
    hovering: Optional[np.ndarray] = field(default=None, repr=False)
    both_sides: Optional[np.ndarray] = field(default=None, repr=False)



def _stratified(samples: int, K_low: float, rng) -> tuple:
    """One uniform point in each cell of a near-square grid over [-pi, pi) x [K_low, 0).

    The grid has at most ``samples + n_phi`` cells whatever the box's aspect ratio (a thin box
    gets one row, not millions of columns).
    """
    H = -K_low
    n_phi = int(min(max(1, round(math.sqrt(samples * 2 * math.pi / H))), samples))
    n_K = max(1, int(math.ceil(samples / n_phi)))
    i, j = np.meshgrid(np.arange(n_phi), np.arange(n_K), indexing="ij")
    phi = -math.pi + (i.ravel() + rng.random(i.size)) * (2 * math.pi / n_phi)
    K = K_low + (j.ravel() + rng.random(j.size)) * (H / n_K)
    K = np.minimum(K, -1e-300)  # the box is K < 0 (HOV lies in J_0)
    return phi, K


def default_depth(m) -> float:
    """Depth of the default box below K = 0: twice the deepest leading-order curve through L1.

    ``2 |eps| max_psi |G(psi)|`` (:class:`hovering.Theory`), i.e. ``2 |eps| / |sin(Omega0/2)|`` for
    ``f = sin``; the band's depth when that is not finite (resonant Omega0).
    """
    th = m.theory()
    psi = np.linspace(-math.pi, math.pi, 4001)
    with np.errstate(divide="ignore", invalid="ignore"):
        d = 2.0 * abs(m.eps) * float(np.max(np.abs(th.G(psi)))) if th.forcing else float("nan")
    return d if math.isfinite(d) and d > 0 else float("inf")


def _piece(m, phi, K, n_steps: int, n_threads: int):
    """The per-sample outcome of hovering_area for some samples (a piece of a distributed run)."""
    no_impact = ("0u", "0")
    r0 = m.with_eps(0.0).iterate(phi, K, n_steps, record=(), exit_regions=no_impact, stop_on_exit=True,
                                 n_threads=n_threads)
    r = m.iterate(phi, K, n_steps, record=("visited",), exit_regions=no_impact, stop_on_exit=True, n_threads=n_threads)
    return r0.status, r.status, r.steps_done, r.visited


def _piece_key(m, n_steps, K_low, seed, samples, lo, hi) -> str:
    # Everything that changes a piece's samples or their orbits: the map (its pickle: parameters,
    # integrator options, measured curve), the counts, the box, the seed and the piece's range.
    import hashlib
    import pickle

    blob = pickle.dumps((m, int(n_steps), float(K_low), int(seed), int(samples), int(lo), int(hi)), protocol=4)
    return hashlib.sha256(blob).hexdigest()


def _piece_arrays(row, n: int) -> tuple:
    """A checkpointed piece (untrusted): four lists of n integers, each within its array's dtype."""
    names, dtypes = ("status_F0", "status", "steps_done", "visited"), (np.int8, np.int8, np.int64, np.int8)
    if not isinstance(row, list) or len(row) != 4:
        raise ValueError("row must be a list of 4 lists (statuses under F_0 and F_eps, steps done, regions visited)")
    out = []
    for name, a, dt in zip(names, row, dtypes):
        arr = np.asarray(a) if isinstance(a, list) else np.zeros(0, dtype=object)
        if arr.shape != (n,) or arr.dtype.kind not in "iu" or (n and not (np.iinfo(dt).min <= arr.min() and
                                                                           arr.max() <= np.iinfo(dt).max)):
            raise ValueError(f"row.{name} must be {n} integers within {np.dtype(dt).name}")
        out.append(arr.astype(dt))
    return tuple(out)


def _distributed(m, phi, K, n_steps, K_low, seed, samples, n_threads, bar, workers, client, scheduler, dask,
                 pieces, checkpoint):
    from ..distribute import executor, run_pieces
    from ..sweeps import Checkpoint

    n = phi.size
    with executor(workers, client, scheduler, dask) as ex:
        threads = n_threads if n_threads != 0 else ex.threads_per_piece
        k = integer("pieces", pieces if pieces is not None else 4 * ex.workers, 1, max(1, n))
        bounds = [(n * i // k, n * (i + 1) // k) for i in range(k)]
        store = Checkpoint(checkpoint) if checkpoint is not None else None
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
                store.put(_piece_key(m, n_steps, K_low, seed, samples, lo, hi), [np.asarray(a).tolist() for a in res])
            bar.advance(2 * (hi - lo) * n_steps)

        for _ in run_pieces(ex, _piece, [(m, phi[bounds[i][0]:bounds[i][1]], K[bounds[i][0]:bounds[i][1]], n_steps,
                                          threads) for i in todo], on_result=done):
            pass
    return tuple(np.concatenate([o[j] for o in out]) for j in range(4))


def hovering_area(m, n_steps: int = 10_000, samples: int = 100_000, K_low: Optional[float] = None, seed: int = 0,
                  n_threads: int = 0, keep_points: bool = False, progress=False, *, workers: Optional[int] = None,
                  client=None, scheduler: Optional[str] = None, dask: bool = False, pieces: Optional[int] = None,
                  checkpoint=None) -> HoveringArea:
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
    workers : int, optional
        Split the samples into ``pieces`` and run them on this many local worker processes (a
        process pool; with ``dask=True`` a Dask LocalCluster). The result is identical to the
        single-process one for the same seed: the samples are drawn once, here, and each piece
        iterates a contiguous slice of them.
    client : distributed.Client, optional
        Run the pieces on an existing Dask cluster.
    scheduler : str, optional
        Address of a running Dask scheduler to run the pieces on.
    dask : bool, optional
        With ``workers``: a Dask LocalCluster instead of a process pool.
    pieces : int, optional
        Number of pieces (default 4 per worker).
    checkpoint : path-like, optional
        A :class:`hovering.sweeps.Checkpoint` file: each finished piece is written as it arrives,
        keyed by every parameter that changes it (map, counts, box, seed, range); a rerun computes
        only the missing pieces (distributed runs only).

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
        raise ValueError(f"this map's band has no part below K = 0 (lower end {lo}): no point impacts under F_0, "
                         f"nothing can hover")
    if K_low is None:
        depth = default_depth(m) if m.eps != 0 else 0.1
        K_low = max(-depth, lo * (1 - 1e-9))
    K_low = real_number("K_low", K_low)
    if not (lo < K_low < 0):
        raise ValueError(f"K_low must lie in the band below 0, ({lo}, 0), got {K_low}")
    rng = np.random.default_rng(seed)
    phi, K = _stratified(samples, K_low, rng)
    n = phi.size
    no_impact = ("0u", "0")

    m0 = m.with_eps(0.0)
    unit = getattr(m, "_progress_unit", "step")
    distributed = workers is not None or client is not None or scheduler is not None
    if checkpoint is not None and not distributed:
        raise ValueError("checkpoint applies to distributed runs (give workers, client or scheduler)")
    with progress_bar(progress, 2 * n * n_steps, desc="hovering_area", unit=unit) as bar:
        if distributed:
            s0, s1, steps_done, visited = _distributed(m, phi, K, n_steps, K_low, seed, samples, n_threads, bar,
                                                       workers, client, scheduler, dask, pieces, checkpoint)
        else:
            # Part 1 of the definition: the point impacts under F_0 (checked, not assumed).
            r0 = m0.iterate(phi, K, n_steps, record=(), exit_regions=no_impact, stop_on_exit=True,
                            n_threads=n_threads, progress=bar.part(0))
            # Part 2: it never impacts under F_eps (for N/4, N/2, N steps: exit_step beyond each count).
            r = m.iterate(phi, K, n_steps, record=("visited",), exit_regions=no_impact, stop_on_exit=True,
                          n_threads=n_threads, progress=bar.part(n * n_steps))
            s0, s1, steps_done, visited = r0.status, r.status, r.steps_done, r.visited
    impacts0 = np.isin(s0, [int(Status.EXITED), int(Status.CORNER), int(Status.GRAZING)])
    stayed = s1 == Status.OK
    box_area = 2 * math.pi * (-K_low)
    areas = {}
    for N in (n_steps // 4, n_steps // 2, n_steps):
        # Stopped at or after N steps for any reason (exit, escape, the flow's corner hits): survived N.
        survive = stayed | (steps_done >= N)
        areas[N] = box_area * np.count_nonzero(impacts0 & survive) / n
    hov = impacts0 & stayed
    both = (1 << int(Region.BESIDE)) | (1 << int(Region.ABOVE))
    hov_both = hov & ((visited & both) == both)
    p = np.count_nonzero(hov) / n
    sampling = box_area * math.sqrt(max(p * (1 - p), 1.0 / n) / n)
    iteration = areas[n_steps // 2] - areas[n_steps]
    theory = m.theory().area
    floor_touched = bool(np.any(hov & (K < 0.9 * K_low)))
    unresolved = int(np.count_nonzero(~np.isin(s1, [int(Status.OK), int(Status.EXITED), int(Status.ESCAPED)])))
    return HoveringArea(
        area=areas[n_steps],
        error=2 * sampling + iteration,
        sampling_error=sampling,
        iteration_error=iteration,
        theory=float(theory),
        areas=areas,
        n_samples=n,
        box=(-math.pi, math.pi, K_low, 0.0),
        impact_fraction_F0=float(np.count_nonzero(impacts0) / n),
        floor_touched=floor_touched,
        area_both_sides=box_area * np.count_nonzero(hov_both) / n,
        unresolved=unresolved,
        phi=phi if keep_points else None,
        K=K if keep_points else None,
        hovering=hov if keep_points else None,
        both_sides=hov_both if keep_points else None,
    )

