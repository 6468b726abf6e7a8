"""Barriers across the impact zone: where orbits started below never rise above orbits started above.

:func:`barrier_scan` launches orbits on a symmetry line (L1 or L2 of def:L1L2) at evenly spaced
levels of the zone coordinate ``s`` (:class:`hovering.ImpactZone`), classifies each by order
statistics (:func:`hovering.analysis.orbits.classify_orbits`: circle, island chain with its period,
chaotic layer; valid across the corner curves) and tests, between every two neighbouring starts,
whether the orbits below and the orbits above are separated: in every phi-bin the highest point of
every orbit started below lies under the lowest point of every orbit started above (a bin may lean
on its neighbours, the slack a sloping separatrix needs inside one bin). A separated cut is a
*two-sided barrier* for the orbits and steps computed: nothing launched below crossed it, nothing
launched above came down through it. Neighbouring starts with no barrier between them form a
*layer*, whose class is that of its orbits.

The verdicts are numerical evidence over ``n_steps`` returns, not proofs: a barrier may be a
cantorus that leaks after more steps, and an orbit may be an island chain of longer period than
tried. The only certificate here is :func:`hovering.analysis.orbits.converse_kam` (no rotational
invariant circle of the smooth twist region passes through a start), reported per start where it
applies (a TruncatedMap, starts in J_0u or J_0).
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass

import numpy as np

from .._arrays import unique
from .._checks import integer, is_choice, real_number
from .._display import Summarized, status_counts
from .._enums import Region, Status
from .._io.serial import Saveable
from ..interface import require_map
from ..parallel.executor import as_executor, run_pieces
from ..parallel.executor import executor as open_executor
from ..truncated import TruncatedMap
from .orbits import classify_orbits, converse_kam
from .zone import ImpactZone

__all__ = ["BarrierScan", "Layer", "barrier_scan", "launch_points"]

_log = logging.getLogger(__name__)

_TWO_PI = 2.0 * math.pi
#: Orbit points held in memory by one piece of a scan (phi, K and s: 24 bytes each).
_PIECE_POINTS = 4_000_000
#: Regions whose return hits a wall.
_IMPACTING = (int(Region.UPPER), int(Region.RIGHT))


@dataclass(frozen=True)
class Layer:
    """A run of neighbouring starts of a :class:`BarrierScan` with no barrier between them.

    Attributes
    ----------
    first, last : int
        Indices of its lowest and highest start.
    s_start : tuple of float
        Zone levels of its lowest and highest start on the line.
    s_min, s_max : float
        Extremes of s over every point of its orbits.
    kind : str
        ``"chaotic"`` if any orbit is chaotic, else ``"circle"`` if all are circles, else
        ``"islands"`` if any is an island chain, else ``"undecided"``.
    counts : dict
        Orbits of each class.
    periods : tuple of int
        Periods of its island chains (sorted, distinct).
    impacting : bool
        Whether any of its orbits returned from an impacting region (J_1 or J_R).

    Examples
    --------
    >>> import numpy as np, hovering
    >>> m = hovering.TruncatedMap(eps=0.0914, Omega0=7.6696, theta_w=2.2117, tau0=3.0788, tau1=1.2223, lam=1.9072)
    >>> zone = hovering.impact_zone(m, floor=-0.2)
    >>> layer = hovering.barrier_scan(m, zone, n_starts=8, n_steps=2000).layers[0]
    >>> layer.first, layer.last, layer.kind, layer.impacting   # one layer holds every start
    (0, 7, 'chaotic', True)
    """

    first: int
    last: int
    s_start: tuple
    s_min: float
    s_max: float
    kind: str
    counts: dict
    periods: tuple
    impacting: bool


@dataclass(frozen=True, repr=False)
class BarrierScan(Summarized, Saveable):
    """What :func:`barrier_scan` found (arrays: one entry per start, in order of rising s).

    Attributes
    ----------
    line : str
        ``"L1"``, ``"L2"`` or ``"phi=<value>"``: where the starts lie.
    n_steps : int
        Returns each orbit was given.
    phi0, K0, s0 : ndarray
        The starts and their zone level.
    kind, period, rotation, decided_by : ndarray
        The orbit classes (:class:`hovering.analysis.orbits.OrbitClasses`).
    status : ndarray of int8
        :class:`hovering.Status` (truncated maps) or flow status code per orbit.
    steps_done : ndarray of int64
        Returns computed per orbit.
    s_min, s_max : ndarray
        Extremes of s over the orbit's points.
    impact_fraction : ndarray
        Fraction of the orbit's returns from an impacting region (J_1 or J_R).
    margin : ndarray
        Per cut between start i and i + 1 (length ``n - 1``): the smallest gap, over the phi-bins,
        between the lowest point of the orbits above and the highest point of the orbits below
        (in s; >= 0 on a barrier, negative where the two sets overlap).
    barrier : ndarray of bool
        Per cut: two-sided barrier (``margin >= 0`` and both sides computed).
    cone : ndarray of str
        Per start: the converse-KAM verdict (``"crossing"``: no rotational invariant circle of
        the smooth twist region passes through it; ``"left_domain"`` (its cone orbit left the
        smooth region, or the map's band), ``"none"``, or ``"n/a"`` where it does not apply: see
        :func:`barrier_scan`).
    n_bins : int
        Phi-bins of the separation test.
    complete : bool
        False for the partial result of an interrupted scan (orbits not computed are
        ``"undecided"`` with ``decided_by == "interrupted"`` and NaN s extremes; no barrier is
        claimed next to them).
    phi, K : ndarray or None
        With ``keep=k``: k points of each orbit, evenly strided over its returns (NaN after an
        orbit ended), shape ``(n, k)``, for drawing.

    Examples
    --------
    >>> import numpy as np, hovering
    >>> m = hovering.TruncatedMap(eps=0.0914, Omega0=7.6696, theta_w=2.2117, tau0=3.0788, tau1=1.2223, lam=1.9072)
    >>> zone = hovering.impact_zone(m, floor=-0.2)
    >>> scan = hovering.barrier_scan(m, zone, n_starts=8, n_steps=2000, keep=100)
    >>> scan.complete, scan.kind.shape, scan.margin.shape, scan.phi.shape   # per start, per cut, kept points
    (True, (8,), (7,), (8, 100))
    >>> print(scan.summary().splitlines()[0])
    8 starts on L1, 2000 returns each: 0 barrier cut(s), 1 layer(s)
    """

    line: str
    n_steps: int
    phi0: np.ndarray
    K0: np.ndarray
    s0: np.ndarray
    kind: np.ndarray
    period: np.ndarray
    rotation: np.ndarray
    decided_by: np.ndarray
    status: np.ndarray
    steps_done: np.ndarray
    s_min: np.ndarray
    s_max: np.ndarray
    impact_fraction: np.ndarray
    margin: np.ndarray
    barrier: np.ndarray
    cone: np.ndarray
    n_bins: int
    complete: bool = True
    phi: np.ndarray | None = None
    K: np.ndarray | None = None

    def __len__(self) -> int:
        return int(self.s0.size)

    @property
    def barriers(self) -> np.ndarray:
        """Zone levels on the line where a barrier crosses it: the midpoint of each barrier cut's
        two starts, shape ``(n_barriers,)``."""
        i = np.flatnonzero(self.barrier)
        return 0.5 * (self.s0[i] + self.s0[i + 1])

    @property
    def layers(self) -> list[Layer]:
        """The layers, lowest first (see :class:`Layer`)."""
        cuts = np.flatnonzero(self.barrier)
        bounds = zip(np.concatenate([[0], cuts + 1]), np.concatenate([cuts, [len(self) - 1]]))
        out = []
        for a, b in bounds:
            a, b = int(a), int(b)
            kinds = self.kind[a : b + 1]
            counts = {k: int(np.count_nonzero(kinds == k)) for k in ("circle", "islands", "chaotic", "undecided")}
            if counts["chaotic"]:
                kind = "chaotic"
            elif counts["circle"] == b - a + 1:
                kind = "circle"
            elif counts["islands"]:
                kind = "islands"
            else:
                kind = "undecided"
            per = self.period[a : b + 1]
            with np.errstate(all="ignore"):
                lo, hi = np.nanmin(self.s_min[a : b + 1]), np.nanmax(self.s_max[a : b + 1])
            out.append(
                Layer(
                    first=a,
                    last=b,
                    s_start=(float(self.s0[a]), float(self.s0[b])),
                    s_min=float(lo),
                    s_max=float(hi),
                    kind=kind,
                    counts=counts,
                    periods=tuple(int(p) for p in unique(per[per > 0])),
                    impacting=bool(np.any(self.impact_fraction[a : b + 1] > 0)),
                )
            )
        return out

    def _summary(self) -> list:
        return [
            ("line", self.line),
            ("n_starts", len(self)),
            ("n_steps", self.n_steps),
            ("barriers", int(self.barrier.sum())),
            ("layers", len(self.layers)),
            (
                "classes",
                {k: int(np.count_nonzero(self.kind == k)) for k in ("circle", "islands", "chaotic", "undecided")},
            ),
            ("spanning 0.1..0.9", int(self.spanning(0.1, 0.9).size)),
            ("status", status_counts(self.status, Status)),
            ("complete", self.complete),
        ]

    def to_pandas(self):
        """One row per start as a :class:`pandas.DataFrame` (needs ``hovering[pandas]``): the start
        (s0, phi0, K0), its class, period, rotation, the s extremes, the impact fraction, the
        converse-KAM verdict, ``status`` (named), and whether the cut above it is a barrier (with
        its margin); ``line``, ``n_steps`` in ``df.attrs``.

        Returns
        -------
        pandas.DataFrame

        Raises
        ------
        ImportError
            Without pandas, naming ``pip install 'hovering[pandas]'``.
        """
        from .._io.interop import barrier_frame

        return barrier_frame(self)

    def spanning(self, lo: float = 0.1, hi: float = 0.9) -> np.ndarray:
        """Indices of the orbits that visited both ``s <= lo`` and ``s >= hi``.

        Parameters
        ----------
        lo, hi : float, optional
            Zone levels, ``lo < hi``.

        Returns
        -------
        ndarray of int
            Empty when no orbit crossed from one level to the other.
        """
        lo, hi = real_number("lo", lo), real_number("hi", hi)
        if not lo < hi:
            raise ValueError(f"lo must be below hi, got lo = {lo} and hi = {hi}")
        return np.flatnonzero((self.s_min <= lo) & (self.s_max >= hi))

    def summary(self) -> str:
        """A few lines: the layers (s-span, class, impacting) and the barriers.

        Returns
        -------
        str
        """
        lines = [
            f"{len(self)} starts on {self.line}, {self.n_steps} returns each: {int(self.barrier.sum())} barrier cut(s), "
            f"{len(self.layers)} layer(s){'' if self.complete else ' (interrupted: partial)'}"
        ]
        for ly in self.layers:
            per = f" periods {list(ly.periods)}" if ly.periods else ""
            lines.append(
                f"  starts s {ly.s_start[0]:.3f}..{ly.s_start[1]:.3f}: {ly.kind:9s} s in [{ly.s_min:.3f}, {ly.s_max:.3f}]"
                f"{' impacting' if ly.impacting else ''}{per}"
            )
        return "\n".join(lines)

    def _validate_loaded(self) -> None:
        n = self.s0.shape[0] if isinstance(self.s0, np.ndarray) and self.s0.ndim == 1 else -1
        for name in ("phi0", "K0", "kind", "period", "rotation", "decided_by", "status", "steps_done", "s_min",
                     "s_max", "impact_fraction", "cone"):  # fmt: skip
            a = getattr(self, name)
            if not isinstance(a, np.ndarray) or a.shape != (n,):
                raise ValueError(f"{name} must have the shape of s0 ({n},)")
        for name in ("margin", "barrier"):
            a = getattr(self, name)
            if not isinstance(a, np.ndarray) or a.shape != (max(n - 1, 0),):
                raise ValueError(f"{name} must have one entry per cut ({max(n - 1, 0)},)")


def launch_points(m, zone: ImpactZone, s, line="L1") -> tuple[np.ndarray, np.ndarray]:
    """Points of a symmetry line at zone levels ``s``: ``(phi, K)`` with ``phi = line(K)`` and
    ``zone.s(phi, K) = s``.

    Parameters
    ----------
    m : TruncatedMap, TruncatedFamily or FlowMap
        The map (its ``L1``/``L2``).
    zone : ImpactZone
        The zone.
    s : array_like
        Zone levels.
    line : {"L1", "L2"} or float, optional
        The line: L1/L2 of def:L1L2 (phi depends on K), or a constant angle.

    Returns
    -------
    (ndarray, ndarray)

    Raises
    ------
    ValueError
        If the fixed-point iteration ``K <- zone.K_at(line(K), s)`` does not settle to 1e-12 (a zone
        whose boundaries slope too steeply for the line), or for a bad line.
    """
    s = np.atleast_1d(np.asarray(s, dtype=float))
    if isinstance(line, str):
        if not is_choice(line, ("L1", "L2")):
            raise ValueError(f"line must be 'L1', 'L2' or an angle, got {line!r}")
        at = m.L1 if line == "L1" else m.L2
    else:
        phi_c = real_number("line", line, lo=-math.pi, lo_open=False, hi=math.pi)

        def at(K):
            return np.full_like(K, phi_c)

    K = np.asarray(zone.K_at(np.asarray(at(np.asarray(zone.K_at(0.0, s))), dtype=float), s), dtype=float)
    # K = K_at(line(K), s) contracts by |dK_at/dphi * dline/dK| (zone slopes O(eps) times tau0 / 2).
    for _ in range(200):
        K_new = np.asarray(zone.K_at(np.asarray(at(K), dtype=float), s), dtype=float)
        done = np.max(np.abs(K_new - K)) <= 1e-12 * max(1.0, float(np.max(np.abs(K_new))))
        K = K_new
        if done:
            return np.asarray(at(K), dtype=float), K
    raise ValueError(f"the launch points on {line} did not settle (the zone's boundaries are too steep for this line)")


def _envelopes(phi, s, n_bins):
    """Per orbit and phi-bin the highest and lowest s (-inf / +inf in empty bins)."""
    n = phi.shape[0]
    ok = np.isfinite(phi) & np.isfinite(s)
    u = np.mod(np.where(ok, phi, 0.0) + math.pi, _TWO_PI) / _TWO_PI
    b = np.floor(u * n_bins).astype(np.int64) % n_bins
    idx = (np.arange(n)[:, None] * n_bins + b)[ok]
    hi = np.full(n * n_bins, -np.inf)
    lo = np.full(n * n_bins, np.inf)
    np.maximum.at(hi, idx, s[ok])
    np.minimum.at(lo, idx, s[ok])
    return hi.reshape(n, n_bins), lo.reshape(n, n_bins)


def _scan_piece(m, zone, phi0, K0, n_steps, n_bins, classify, kwargs, keep=0):
    """Iterate, classify and reduce one piece of starts (runs in any process); returns small arrays."""
    interrupted = False
    try:
        res = m.iterate(phi0, K0, n_steps, record=("orbit", "residence"), **kwargs)
    except KeyboardInterrupt as e:
        res = getattr(e, "partial", None)
        if res is None:
            raise
        interrupted = True  # its orbits cut short carry Status.INTERRUPTED
    # Columns past the longest orbit are padding (an interrupted run stops far short of n_steps).
    width = int(np.max(res.steps_done, initial=0)) + 1
    phi, K = res.phi[:, :width], res.K[:, :width]
    n = phi.shape[0]
    computed = np.asarray(res.status) != int(Status.INTERRUPTED)
    # Orbits cut short by Ctrl-C get no verdict and no envelope (the scan marks them "interrupted"
    # and claims no barrier next to them): classifying and reducing their millions of points only
    # delayed the return to the prompt (3.2 s measured for one orbit of a 1e7-step scan; 0.7 s
    # with the classification skipped, 0.1-0.25 s with the reductions skipped too).
    phi, K = phi[computed], K[computed]
    c = classify_orbits(phi, K, **classify)
    kinds = np.full(n, "undecided", dtype=object)
    period = np.zeros(n, dtype=np.int64)
    rotation = np.full(n, np.nan)
    decided = np.full(n, "interrupted", dtype=object)
    kinds[computed], period[computed] = c.kind, c.period
    rotation[computed], decided[computed] = c.rotation, c.decided_by
    s = np.asarray(zone.s(phi, K), dtype=float)
    hi, lo = np.full((n, n_bins), -np.inf), np.full((n, n_bins), np.inf)
    hi[computed], lo[computed] = _envelopes(phi, s, n_bins)
    s_min, s_max = np.full(n, np.nan), np.full(n, np.nan)
    with np.errstate(all="ignore"):
        s_min[computed] = np.nanmin(np.where(np.isfinite(s), s, np.nan), axis=1)
        s_max[computed] = np.nanmax(np.where(np.isfinite(s), s, np.nan), axis=1)
    resid = np.asarray(res.residence, dtype=np.int64)
    total = resid.sum(axis=1)
    imp = resid[:, list(_IMPACTING)].sum(axis=1)  # columns in Region order, BESIDE = 0
    frac = np.where(total > 0, imp / np.maximum(total, 1), 0.0)
    out = {
        "kind": kinds.astype(str),
        "period": period,
        "rotation": rotation,
        "decided_by": decided.astype(str),
        "status": np.asarray(res.status),
        "steps_done": np.asarray(res.steps_done, dtype=np.int64),
        "s_min": s_min,
        "s_max": s_max,
        "impact_fraction": frac,
        "hi": hi,
        "lo": lo,
        # an orbit is done when it ran its steps or ended for a reason of its own (not Ctrl-C)
        "computed": computed,
    }
    if keep:
        take = np.linspace(0, n_steps, keep).round().astype(np.int64)  # on the full width: NaN after the end
        out["phi"], out["K"] = res.phi[:, take], res.K[:, take]
    return out, interrupted


def _margins(hi, lo, computed):
    """Per cut the separation margin (see BarrierScan.margin) from the per-orbit envelopes."""
    n = hi.shape[0]
    below = np.maximum.accumulate(hi, axis=0)[:-1]  # highest point of the orbits 0..i per bin
    above = np.minimum.accumulate(lo[::-1], axis=0)[::-1][1:]  # lowest point of the orbits i+1..n-1
    # A separatrix that slopes crosses a bin: the points below at one end of the bin may lie above
    # the points above at its other end; the neighbouring bin's lowest point bounds it there.
    # An empty neighbour (an island chain's gap) gives no slack: the bin's own point is used.
    nbs = [np.where(np.isinf(nb), above, nb) for nb in (np.roll(above, 1, axis=1), np.roll(above, -1, axis=1))]
    relaxed = np.maximum(above, np.maximum(*nbs))
    with np.errstate(invalid="ignore"):
        gap = relaxed - below
    gap = np.where(np.isnan(gap), np.inf, gap)  # a bin empty on one side does not constrain the cut
    margin = gap.min(axis=1) if n > 1 else np.zeros(0)
    margin = np.where(np.isfinite(margin), margin, np.nan)
    ready = np.minimum.accumulate(computed.astype(int))[:-1].astype(bool) & np.minimum.accumulate(
        computed[::-1].astype(int)
    )[::-1][1:].astype(bool)
    barrier = ready & (margin >= 0)
    return margin, barrier


def barrier_scan(
    m,
    zone: ImpactZone,
    n_starts: int = 64,
    n_steps: int = 20_000,
    line="L1",
    s_range=(0.0, 1.0),
    n_bins: int | None = None,
    cone_steps: int = 2000,
    executor=None,
    classify: dict | None = None,
    keep: int = 0,
    **iterate_kwargs,
) -> BarrierScan:
    """Scan the impact zone along a symmetry line for layers and two-sided barriers.

    The starts lie on ``line`` at the zone levels ``s_j = a + (j + 1/2) (b - a) / n_starts``,
    ``(a, b) = s_range``. Every orbit is followed ``n_steps`` returns and classified by order
    statistics; between each two neighbouring starts the orbits below and above are tested for
    separation (see the module's doc). Symmetric invariant circles and the island chains of
    reversible maps cross the fixed lines of the reversor, which is why the starts lie on L1/L2.

    Parameters
    ----------
    m : TruncatedMap, TruncatedFamily or FlowMap
        The map.
    zone : ImpactZone
        The zone (:func:`hovering.impact_zone`).
    n_starts : int, optional
        Starts (2 .. 100000).
    n_steps : int, optional
        Returns per orbit (>= 256, so that the classes can decide).
    line : {"L1", "L2"} or float, optional
        Where the starts lie (an angle in [-pi, pi] for a horizontal line).
    s_range : (float, float), optional
        Zone levels spanned by the starts (default the whole zone).
    n_bins : int, optional
        Phi-bins of the separation test (default ``n_steps // 64`` within [16, 1024]: about 64
        points of a circle-filling orbit per bin).
    cone_steps : int, optional
        Steps of the converse-KAM test for a TruncatedMap's starts in J_0u / J_0 (0: skip it).
    executor : optional
        Where the pieces run (:func:`hovering.parallel.executor.as_executor`); the result equals
        the one-process result.
    classify : dict, optional
        Options of :func:`hovering.analysis.orbits.classify_orbits`.
    keep : int, optional
        Points of each orbit kept in the result (``phi``, ``K``; 0: none), 0 .. n_steps + 1.
    **iterate_kwargs
        Passed to ``m.iterate`` (``n_threads``, ``kernel``, ``progress``, ...).

    Returns
    -------
    BarrierScan

    Raises
    ------
    ValueError
        For a map or zone of the wrong type, out-of-range options, or a start outside a truncated
        map's band (where it is undefined), before any iteration. A FlowMap's band is a
        conservative rectangle of its section (its floor torus may dip below it): its starts are
        not checked against it, and a start truly off the section ends with its own status.
    KeyboardInterrupt
        On Ctrl-C, with the scan so far as ``.partial`` (``complete=False``); the orbits cut short
        are not classified (``"undecided"``, decided by ``"interrupted"``), so the call returns
        within the core's reaction time.

    Examples
    --------
    Eight starts on L1 across a zone that orbits cross (see :func:`hovering.transit`):

    >>> import numpy as np, hovering
    >>> m = hovering.TruncatedMap(eps=0.0914, Omega0=7.6696, theta_w=2.2117, tau0=3.0788, tau1=1.2223, lam=1.9072)
    >>> zone = hovering.impact_zone(m, floor=-0.2)
    >>> scan = hovering.barrier_scan(m, zone, n_starts=8, n_steps=2000)
    >>> len(scan), scan.s0.tolist()           # the starts, at the middles of eight equal cuts of s
    (8, [0.0625, 0.1875, 0.3125, 0.4375, 0.5625, 0.6875, 0.8125, 0.9375])
    >>> int(scan.barrier.sum()), len(scan.layers), scan.layers[0].kind   # no barrier: one chaotic layer
    (0, 1, 'chaotic')
    """
    require_map("m", m)
    if not isinstance(zone, ImpactZone):
        raise ValueError(f"zone must be a hovering.ImpactZone (hovering.impact_zone(m)), got {type(zone).__name__}")
    n_starts = integer("n_starts", n_starts, 2, 100_000)
    n_steps = integer("n_steps", n_steps, 256, 2**40)
    cone_steps = integer("cone_steps", cone_steps, 0, 10**8)
    try:
        a, b = (float(v) for v in s_range)
    except (TypeError, ValueError):
        raise ValueError(f"s_range must be two zone levels (lo, hi), got {s_range!r}") from None
    a, b = real_number("s_range[0]", a), real_number("s_range[1]", b)
    if not a < b:
        raise ValueError(f"s_range must rise: got ({a}, {b})")
    n_bins = integer("n_bins", n_bins if n_bins is not None else min(1024, max(16, n_steps // 64)), 4, 1 << 16)
    classify = dict(classify or {})
    keep = integer("keep", keep, 0, n_steps + 1)
    spec = as_executor(executor)

    s0 = a + (np.arange(n_starts) + 0.5) * (b - a) / n_starts
    phi0, K0 = launch_points(m, zone, s0, line)
    line_name = line if isinstance(line, str) else f"phi={float(line):.6g}"
    lo_band, hi_band = m.valid_band()
    # A truncated map is undefined outside its band. A flow's band is a conservative rectangle of
    # its section: its floor torus (an orbit, on the section) may dip below it, and so may starts
    # just above that floor; a start truly off the section ends with its own status.
    exact_band = not hasattr(m, "upper_tangent_K")  # a truncated map (a FlowMap's band is conservative)
    if exact_band and np.any((K0 <= lo_band) | (K0 >= hi_band)):
        j = int(np.argmax((K0 <= lo_band) | (K0 >= hi_band)))
        raise ValueError(
            f"the start at s = {s0[j]:.6g} (K = {K0[j]:.6g}) lies outside the map's band ({lo_band}, {hi_band}); "
            "narrow s_range"
        )

    t0 = time.perf_counter()
    per_piece = max(1, min(n_starts, _PIECE_POINTS // (n_steps + 1)))
    cuts = [(i, min(i + per_piece, n_starts)) for i in range(0, n_starts, per_piece)]
    parts: list = [None] * len(cuts)
    interrupted = False
    try:
        if spec is None:
            for j, (i0, i1) in enumerate(cuts):
                parts[j], stop = _scan_piece(
                    m, zone, phi0[i0:i1], K0[i0:i1], n_steps, n_bins, classify, iterate_kwargs, keep
                )
                if stop:
                    interrupted = True
                    break
        else:
            with open_executor(**spec.where()) as ex:
                kw = dict(iterate_kwargs)
                kw.setdefault("n_threads", ex.threads_per_piece)
                args = [(m, zone, phi0[i0:i1], K0[i0:i1], n_steps, n_bins, classify, kw, keep) for i0, i1 in cuts]
                for j, part in run_pieces(ex, _scan_piece, args):
                    parts[j], stop = part
                    interrupted |= stop
    except KeyboardInterrupt:
        interrupted = True
    result = _assemble(m, line_name, n_steps, n_bins, phi0, K0, s0, cuts, parts, cone_steps, not interrupted, keep)
    _log.info(
        "barrier_scan on %s: %d orbits x %d steps from s in [%.3g, %.3g], %.1f s%s", line_name, n_starts, n_steps,
        a, b, time.perf_counter() - t0, " (interrupted)" if interrupted else "",
    )  # fmt: skip
    if interrupted:
        exc = KeyboardInterrupt("barrier_scan interrupted; the orbits so far are in .partial")
        exc.partial = result  # type: ignore[attr-defined]
        raise exc
    return result


def _cone(m, phi0, K0, cone_steps) -> np.ndarray:
    """The converse-KAM verdicts of starts in the smooth regions.

    converse_kam stops an orbit that leaves the smooth twist domain ("left_domain"), but a cone
    orbit that leaves the band altogether (a start in J_0 near a truncated map's band floor, as the
    zone's lowest starts at eps < 0 are) makes its region lookup raise, which lost the whole scan.
    Such a start is retried alone and, if it raises again, is "left_domain": it left the map's
    domain, and a circle of the smooth region cannot pass through it.
    """
    try:
        return np.asarray(converse_kam(m, phi0, K0, cone_steps).status)
    except ValueError:
        pass
    out = np.empty(phi0.size, dtype=object)
    for i in range(phi0.size):
        try:
            out[i] = converse_kam(m, phi0[i : i + 1], K0[i : i + 1], cone_steps).status[0]
        except ValueError as e:
            if "outside the band" not in str(e):
                raise
            out[i] = "left_domain"
    return out.astype(str)


def _assemble(m, line, n_steps, n_bins, phi0, K0, s0, cuts, parts, cone_steps, complete, keep=0) -> BarrierScan:
    n = s0.size
    kept = (np.full((n, keep), np.nan), np.full((n, keep), np.nan)) if keep else (None, None)
    cols = {
        "kind": np.full(n, "undecided", dtype=object),
        "period": np.zeros(n, dtype=np.int64),
        "rotation": np.full(n, np.nan),
        "decided_by": np.full(n, "interrupted", dtype=object),
        "status": np.full(n, int(Status.INTERRUPTED), dtype=np.int8),  # never run: cut short by Ctrl-C
        "steps_done": np.zeros(n, dtype=np.int64),
        "s_min": np.full(n, np.nan),
        "s_max": np.full(n, np.nan),
        "impact_fraction": np.zeros(n),
    }
    hi = np.full((n, n_bins), -np.inf)
    lo = np.full((n, n_bins), np.inf)
    computed = np.zeros(n, dtype=bool)
    for (i0, i1), part in zip(cuts, parts):
        if part is None:
            continue
        for k in cols:
            cols[k][i0:i1] = part[k]
        hi[i0:i1], lo[i0:i1] = part["hi"], part["lo"]
        computed[i0:i1] = part["computed"]
        if keep:
            kept[0][i0:i1], kept[1][i0:i1] = part["phi"], part["K"]
        cols["decided_by"][i0:i1] = np.where(part["computed"], part["decided_by"], "interrupted")
        cols["kind"][i0:i1] = np.where(part["computed"], part["kind"], "undecided")
    margin, barrier = _margins(hi, lo, computed)
    cone = np.full(n, "n/a", dtype=object)
    if complete and cone_steps > 0 and isinstance(m, TruncatedMap) and m.tau0 != 0:
        smooth = np.isin(np.asarray(m.region(phi0, K0)), (int(Region.BESIDE), int(Region.ABOVE)))
        if smooth.any():
            cone[smooth] = _cone(m, phi0[smooth], K0[smooth], cone_steps)
    return BarrierScan(
        line=line,
        n_steps=n_steps,
        phi0=phi0,
        K0=K0,
        s0=s0,
        kind=cols["kind"].astype(str),
        period=cols["period"],
        rotation=cols["rotation"],
        decided_by=cols["decided_by"].astype(str),
        status=cols["status"].astype(np.int8),
        steps_done=cols["steps_done"],
        s_min=cols["s_min"],
        s_max=cols["s_max"],
        impact_fraction=cols["impact_fraction"],
        margin=margin,
        barrier=barrier,
        cone=cone.astype(str),
        n_bins=n_bins,
        complete=complete,
        phi=kept[0],
        K=kept[1],
    )
