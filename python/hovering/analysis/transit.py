"""Transport across the impact zone: do orbits started near one boundary reach the other?

:func:`transit` launches orbits on a level ``s = start_s`` of the zone coordinate
(:class:`hovering.ImpactZone`) and stops each the first time it reaches ``s = target_s`` (a stop
condition of ``iterate``, evaluated per step inside the kernels). It reports first-passage steps,
the fraction that crossed with its binomial error, the extremes of K and s each orbit reached,
the returns spent in each region, and, when crossings exist, the escape rate of the censored
exponential fit (maximum likelihood: crossings divided by the steps observed) with its error.

A crossing is the arrival at a level strictly inside the zone, ``1 - margin`` going up and
``margin`` going down (default ``margin = 0.02``). The zone's boundaries are invariant curves (the
critical curve above, the flow's floor torus below): an orbit between them approaches them but
never lands on them, so a target on a boundary counts no crossing whatever the dynamics. The
earlier defaults did that: on the flow of docs/impact-zone.md's third system, a zone with no
barrier, they counted 0 of 40 orbits both ways, where 0.98 / 0.02 count 39 and 40 of 40 in 20,000
returns.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass

import numpy as np

from .._checks import MAX_SEED, integer, is_choice, random_seed, real_number
from .._deprecated import renamed_keywords
from .._display import Summarized, status_counts
from .._enums import Status
from .._io.serial import Saveable
from ..curve import Above, Below, Curve
from ..interface import require_map
from ..parallel.executor import as_executor, run_pieces
from ..parallel.executor import executor as open_executor
from .zone import ImpactZone

_log = logging.getLogger(__name__)

__all__ = ["TransitResult", "transit"]


@dataclass(frozen=True, repr=False)
class TransitResult(Summarized, Saveable):
    """What :func:`transit` measured (one entry per orbit where an array).

    Attributes
    ----------
    direction : str
        ``"up"`` (towards the ceiling) or ``"down"``.
    start_s, target_s : float
        The zone levels the orbits start on and must reach.
    n_steps : int
        Steps (returns) each orbit was given.
    phi0, K0 : ndarray
        The starts (on ``s = start_s``).
    first_passage : ndarray of int64
        The first step at which the orbit reached the target (-1 if it never did within ``n_steps``
        or stopped otherwise, see ``status``). An orbit whose image left the map's band on the
        target's far side (status ESCAPED: a truncated map's orbit that drops below the band's
        edge, the floor of its zone) reached the target with that image: its step counts.
    status : ndarray of int8
        :class:`hovering.Status` per orbit: STOPPED (crossed), OK (did not), ESCAPED (left the
        band: crossed if its last image lies past the target, see ``first_passage``), EXITED / a
        flow outcome (stopped for another reason: neither crossed nor censored at ``n_steps``).
    steps_done : ndarray of int64
        Steps taken by each orbit.
    K_min, K_max : ndarray
        The extremes of K over every state the orbit visited (start and final state included).
    s_min, s_max : ndarray
        The extremes of s over the recorded states ``x_0, x_k, x_2k, ...`` (``every = k``; exact
        for ``every=1``), and the final state.
    residence : ndarray of int64
        Returns from each region, shape ``(n_orbits, 5)`` (Region order).
    every : int
        The stride of the states s was measured on.
    target : Curve or None
        The target level ``s = target_s`` as the curve the stop condition used.
    seed : int or None
        The seed of the start angles' jitter (:func:`transit`'s ``rng``, or the seed drawn from a
        Generator or from fresh entropy): ``rng=seed`` starts the same orbits. None in files that
        predate it.

    Examples
    --------
    >>> import numpy as np, hovering
    >>> m = hovering.TruncatedMap(eps=0.0914, Omega0=7.6696, theta_w=2.2117, tau0=3.0788, tau1=1.2223, lam=1.9072)
    >>> zone = hovering.impact_zone(m, floor=-0.2)
    >>> tr = hovering.transit(m, zone, "up", n_orbits=24, n_steps=2000)
    >>> tr.direction, tr.start_s, tr.target_s      # the default levels, 2% inside the zone
    ('up', 0.05, 0.98)
    >>> tr.first_passage.shape, tr.residence.shape   # per orbit; returns per region
    ((24,), (24, 5))
    >>> bool(np.all(tr.crossed == (tr.first_passage >= 0))), bool(0 <= tr.fraction <= 1)
    (True, True)
    """

    direction: str
    start_s: float
    target_s: float
    n_steps: int
    phi0: np.ndarray
    K0: np.ndarray
    first_passage: np.ndarray
    status: np.ndarray
    steps_done: np.ndarray
    K_min: np.ndarray
    K_max: np.ndarray
    s_min: np.ndarray
    s_max: np.ndarray
    residence: np.ndarray
    every: int = 1
    target: Curve | None = None
    seed: int | None = None

    @property
    def crossed(self) -> np.ndarray:
        """Per orbit: it reached the target."""
        return self.first_passage >= 0

    @property
    def fraction(self) -> float:
        """Fraction of the orbits that crossed."""
        return float(np.mean(self.crossed)) if self.crossed.size else float("nan")

    @property
    def fraction_error(self) -> float:
        """Binomial standard error of :attr:`fraction` (for none or all crossed: the one-sided
        ``1 / n`` resolution instead of 0)."""
        n = self.crossed.size
        p = self.fraction
        return math.sqrt(p * (1 - p) / n) if 0 < p < 1 else 1.0 / max(n, 1)

    @property
    def escape_rate(self) -> tuple[float, float] | None:
        """``(gamma, error)`` of the exponential fit ``P(T > n) = exp(-gamma n)`` to the first
        passages, censored at each orbit's last step: the maximum-likelihood rate is the number of
        crossings over the steps observed, with standard error ``gamma / sqrt(crossings)``. None
        without crossings (the data then bound gamma below ~1 / (steps observed) only)."""
        k = int(np.count_nonzero(self.crossed))
        if k == 0:
            return None
        exposure = float(np.sum(np.where(self.crossed, self.first_passage, self.steps_done)))
        gamma = k / max(exposure, 1.0)
        return gamma, gamma / math.sqrt(k)

    def _summary(self) -> list:
        rate = self.escape_rate
        return [
            ("direction", self.direction),
            ("s", f"{self.start_s:g} -> {self.target_s:g}"),
            ("n_orbits", len(self.phi0)),
            ("n_steps", self.n_steps),
            ("fraction", f"{self.fraction:.4g} +- {self.fraction_error:.2g}"),
            ("escape_rate", "none crossed" if rate is None else f"{rate[0]:.4g} +- {rate[1]:.2g}"),
            ("status", status_counts(self.status, Status)),
        ]

    def to_pandas(self):
        """One row per orbit as a :class:`pandas.DataFrame` (needs ``hovering[pandas]``): the start,
        ``first_passage``, ``crossed``, ``steps_done``, the K and s extremes, ``status`` (named) and
        the returns from each region; ``direction``, the levels and ``n_steps`` in ``df.attrs``.

        Returns
        -------
        pandas.DataFrame

        Raises
        ------
        ImportError
            Without pandas, naming ``pip install 'hovering[pandas]'``.
        """
        from .._io.interop import transit_frame

        return transit_frame(self)

    def _validate_loaded(self) -> None:
        n = self.phi0.shape[0] if isinstance(self.phi0, np.ndarray) and self.phi0.ndim == 1 else -1
        for name in ("K0", "first_passage", "status", "steps_done", "K_min", "K_max", "s_min", "s_max"):
            a = getattr(self, name)
            if not isinstance(a, np.ndarray) or a.shape != (n,):
                raise ValueError(f"{name} must have the shape of phi0 ({n},)")
        if self.seed is not None:
            integer("seed", self.seed, 0, MAX_SEED)


def _target(zone: ImpactZone, s: float) -> Curve:
    """The level curve ``s`` of the zone as a Curve: on the finer of the two boundaries' grids
    (times 4), the spline through the level's values there."""
    n = max(zone.ceiling.n, zone.floor.n, 16) * 4
    return Curve.from_function(lambda p: zone.K_at(p, s), n=n)


def _piece(m, phi, K, n_steps, stop, every, kwargs):
    """One piece of orbits (runs in any process)."""
    try:
        res = m.iterate(phi, K, n_steps, record=("orbit", "extrema", "residence"), every=every, stop=stop, **kwargs)
    except KeyboardInterrupt as e:
        res = getattr(e, "partial", None)
        if res is None:
            raise
        return res, True
    return res, False


@renamed_keywords(seed="rng")
def transit(
    m,
    zone: ImpactZone,
    direction: str = "up",
    n_orbits: int = 1000,
    n_steps: int = 10_000,
    start_s: float | None = None,
    target_s: float | None = None,
    margin: float = 0.02,
    rng: int | np.random.Generator | None = 0,
    every: int | None = None,
    executor=None,
    **iterate_kwargs,
) -> TransitResult:
    """Launch orbits on one level of the impact zone and measure whether they reach another.

    Parameters
    ----------
    m : TruncatedMap, TruncatedFamily or FlowMap
        The map.
    zone : ImpactZone
        The zone (:func:`hovering.impact_zone`).
    direction : {"up", "down"}, optional
        Towards the ceiling (stop on ``K >= target``) or the floor (``K <= target``).
    n_orbits : int, optional
        Orbits, started at stratified angles (one per cell of ``[-pi, pi)``, jittered by ``rng``).
    n_steps : int, optional
        Steps (returns) per orbit.
    start_s, target_s : float, optional
        Zone levels; defaults: up from 0.05 to ``1 - margin``, down from 0.95 to ``margin``. They
        must lie on the direction's side of each other. A target on a boundary (0 or 1) or beyond
        it is accepted (for a zone given by levels that are not invariant), but the boundaries
        :func:`hovering.impact_zone` finds cannot be reached from inside: the ceiling (the critical
        curve) and a flow's floor (its torus) are invariant curves, which orbits inside the zone
        approach but never land on or pass, so such a target reports 0 crossings whatever the
        dynamics; a truncated map's band floor is the edge of its domain, passed only by leaving
        the band (ESCAPED).
    margin : float, optional
        How far inside the zone the default targets lie, in (0, 0.5): up to ``s = 1 - margin``,
        down to ``s = margin`` (default 0.02: 2% of the zone's height). The last few percent
        under the critical curve are sticky (24 orbits of a zone with no barrier, Tan(1, 0.7) at
        eps = 0.05 in docs/impact-zone.md, reach s = 0.974-0.996 in 10,000 returns going up, and
        s = 0.0001-0.01 going down), while a barrier keeps them tenths of the zone away, so 2%
        separates the two answers without waiting for the approach to the boundary. Ignored where
        ``target_s`` is given.
    rng : int, numpy.random.Generator or None, optional
        The angle jitter's randomness (SPEC 7): an integer seed in [0, 2**63 - 1] (default 0), a
        Generator (one seed is drawn from it) or None (a seed from fresh OS entropy); the seed used
        is the result's ``seed``. Formerly ``seed=`` (deprecated, still accepted with a
        DeprecationWarning; giving both is a TypeError).
    every : int, optional
        Stride of the states s is measured on (default ``max(1, n_steps // 1000)``: at most 1001
        states per orbit kept); first passages and K extremes are exact at any stride.
    executor : optional
        Where it runs (see :func:`hovering.parallel.executor.as_executor`): the orbits are cut into
        pieces; the result is the one-process result.
    **iterate_kwargs
        Passed to ``m.iterate`` (``n_threads``, ``kernel``, ``progress``, ...).

    Returns
    -------
    TransitResult

    Raises
    ------
    TypeError
        For an ``rng`` that is not None, an int or a Generator, or both ``rng`` and ``seed``.
    ValueError
        For a map or zone of the wrong type, a direction other than up/down, levels on the wrong
        side of each other or not finite, a margin outside (0, 0.5), counts out of range; before
        any iteration.
    KeyboardInterrupt
        On Ctrl-C, with the result so far (orbits cut short keep their steps) as ``.partial`` (in
        this process; on an executor the finished pieces are cancelled with the rest).

    Examples
    --------
    Orbits started near the ceiling of a zone with no barrier fall to its floor within a few
    thousand steps (docs/guide/transport.md runs 100,000 steps both ways):

    >>> import numpy as np, hovering
    >>> m = hovering.TruncatedMap(eps=0.0914, Omega0=7.6696, theta_w=2.2117, tau0=3.0788, tau1=1.2223, lam=1.9072)
    >>> zone = hovering.impact_zone(m, floor=-0.2)
    >>> down = hovering.transit(m, zone, "down", n_orbits=24, n_steps=2000)
    >>> down.start_s, down.target_s
    (0.95, 0.02)
    >>> bool(down.fraction > 0.5), down.escape_rate is not None   # most crossed: a rate is fitted
    (True, True)
    """
    require_map("m", m)
    if not isinstance(zone, ImpactZone):
        raise ValueError(f"zone must be a hovering.ImpactZone (hovering.impact_zone(m)), got {type(zone).__name__}")
    if not is_choice(direction, ("up", "down")):
        raise ValueError(f"direction must be 'up' or 'down', got {direction!r}")
    n_orbits = integer("n_orbits", n_orbits, 1, 2**31 - 1)
    n_steps = integer("n_steps", n_steps, 1, 2**53)
    seed = random_seed(rng)
    up = direction == "up"
    margin = real_number("margin", margin, lo=0.0, hi=0.5)
    start_s = real_number("start_s", 0.05 if up and start_s is None else 0.95 if start_s is None else start_s)
    if target_s is None:
        target_s = 1.0 - margin if up else margin
    target_s = real_number("target_s", target_s)
    if not (start_s < target_s if up else start_s > target_s):
        raise ValueError(
            f"for direction={direction!r} start_s must lie {'below' if up else 'above'} target_s, got start_s = "
            f"{start_s} and target_s = {target_s}"
        )
    every = integer("every", every if every is not None else max(1, n_steps // 1000), 1, 2**53)
    spec = as_executor(executor)

    t0 = time.perf_counter()
    jitter = np.random.default_rng(seed).random(n_orbits)
    phi0 = -np.pi + 2 * np.pi * (np.arange(n_orbits) + jitter) / n_orbits
    K0 = np.asarray(zone.K_at(phi0, start_s), dtype=float)
    target = _target(zone, target_s)
    stop = Above(target) if up else Below(target)

    if spec is None:
        parts = [_piece(m, phi0, K0, n_steps, stop, every, iterate_kwargs)]
    else:
        with open_executor(**spec.where()) as ex:
            k = min(n_orbits, spec.pieces if spec.pieces is not None else 4 * ex.workers)
            cuts = [(n_orbits * i // k, n_orbits * (i + 1) // k) for i in range(k)]
            kw = dict(iterate_kwargs)
            kw.setdefault("n_threads", ex.threads_per_piece)
            out = [None] * k
            for i, part in run_pieces(ex, _piece, [(m, phi0[a:b], K0[a:b], n_steps, stop, every, kw) for a, b in cuts]):
                out[i] = part
            parts = out
    interrupted = any(p[1] for p in parts)
    res = [p[0] for p in parts]

    def cat(name):
        return np.concatenate([getattr(r, name) for r in res])

    s_states = np.concatenate([zone.s(r.phi, r.K) for r in res])  # recorded states (NaN after a stop)
    s_final = zone.s(cat("phi_final"), cat("K_final"))
    with np.errstate(all="ignore"):
        s_min = np.fmin(np.nanmin(np.where(np.isfinite(s_states), s_states, np.inf), axis=1), s_final)
        s_max = np.fmax(np.nanmax(np.where(np.isfinite(s_states), s_states, -np.inf), axis=1), s_final)
    first = cat("stop_step").astype(np.int64)
    status = cat("status")
    steps_done = cat("steps_done").astype(np.int64)
    # An image outside the band ends the orbit as ESCAPED before the stop is tested on it; one on
    # the target's far side (below a truncated map's band floor, going down) has passed the target.
    K_final, phi_final = cat("K_final"), cat("phi_final")
    esc = (status == int(Status.ESCAPED)) & (first < 0) & np.isfinite(K_final) & np.isfinite(phi_final)
    if esc.any():
        level = target(phi_final[esc])
        past = K_final[esc] >= level if up else K_final[esc] <= level
        first[np.flatnonzero(esc)[past]] = steps_done[esc][past]
    result = TransitResult(
        direction=direction,
        start_s=start_s,
        target_s=target_s,
        n_steps=n_steps,
        phi0=phi0,
        K0=K0,
        first_passage=first,
        status=status,
        steps_done=steps_done,
        K_min=cat("K_min"),
        K_max=cat("K_max"),
        s_min=s_min,
        s_max=s_max,
        residence=cat("residence").astype(np.int64),
        every=every,
        target=target,
        seed=seed,
    )
    _log.info(
        "transit %s: s %.3g -> %.3g, %d orbits x %d steps: %.4g crossed, %.1f s%s",
        direction, start_s, target_s, n_orbits, n_steps, result.fraction, time.perf_counter() - t0,
        " (interrupted)" if interrupted else "",
    )  # fmt: skip
    if interrupted:
        exc = KeyboardInterrupt("transit interrupted; the orbits so far are in .partial")
        exc.partial = result  # type: ignore[attr-defined]
        raise exc
    return result
