"""Rotation numbers, hovering-set measurement and critical-curve search (sec:truncatedmapnum).

* :func:`birkhoff_average`, :func:`rotation_number`, :func:`regularity`: the paper's rho (mean of
  omega_a) and the weighted Birkhoff average of Das, Sander and Yorke, whose convergence rate also
  tells a quasi-periodic orbit (super-polynomial) from a chaotic one (about N^-1/2).
* :func:`hovering_area`: |HOV(eps)| by its definition, with a sampling and an iteration error.
* :func:`critical_curve`: the lowest invariant curve in a set of no-impact regions, searched
  along L1 (or L2), next to the predictions of eq:kcrit and eq:rhocrit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Optional, Sequence

import numpy as np

from . import geometry as _geo
from ._types import Status

__all__ = [
    "birkhoff_weights",
    "birkhoff_average",
    "rotation_number",
    "regularity",
    "HoveringArea",
    "hovering_area",
    "CriticalCurve",
    "critical_curve",
    "max_angular_gap",
]


# ------------------------------------------------------------------------------------------------
# Weighted Birkhoff averages


def birkhoff_weights(n: int) -> np.ndarray:
    """Normalised weights ``w(t) = exp(-1/(t(1-t)))`` at ``t = (j + 1/2)/n``, ``j = 0..n-1``.

    The weight vanishes to all orders at both ends, which is what makes the weighted average of a
    smooth observable along a quasi-periodic orbit converge faster than any power of n (Das,
    Sander, Yorke 2017), instead of the 1/n of a plain average.

    Parameters
    ----------
    n : int
        Number of samples (>= 1).

    Returns
    -------
    ndarray
        Shape (n,), summing to 1.
    """
    if n < 1:
        raise ValueError(f"n must be >= 1, got {n}")
    t = (np.arange(n) + 0.5) / n
    w = np.exp(-1.0 / (t * (1.0 - t)))
    return w / w.sum()


def birkhoff_average(values, axis: int = -1) -> np.ndarray:
    """Weighted Birkhoff average of a time series along ``axis``.

    Parameters
    ----------
    values : array_like
        Observable along orbits, time along ``axis``; must be finite.
    axis : int, optional
        Time axis.

    Returns
    -------
    ndarray or float
        The weighted average (the time axis removed).
    """
    v = np.moveaxis(np.asarray(values, dtype=float), axis, -1)
    if v.shape[-1] == 0:
        raise ValueError("birkhoff_average needs at least one sample along the time axis")
    if not np.all(np.isfinite(v)):
        raise ValueError("birkhoff_average: values must be finite (an orbit that stopped early has NaN tails)")
    out = v @ birkhoff_weights(v.shape[-1])
    return float(out) if np.ndim(out) == 0 else out


def _omegas(res, i: int) -> np.ndarray:
    """omega_a of each step orbit i took, recomputed from its recorded points (bit-exact)."""
    if res.phi is None or res.K is None:
        raise ValueError("this needs a result recorded with record=('orbit', ...)")
    if res.map is None:
        raise ValueError("this result does not know its map (made outside TruncatedMap.iterate)")
    n = int(res.steps_done[i])
    return res.map.rotation(res.phi[i, :n], res.K[i, :n])


def rotation_number(res, method: str = "mean") -> np.ndarray:
    """Rotation number of each orbit of an iteration result.

    Parameters
    ----------
    res : IterateResult
        Result of :meth:`TruncatedMap.iterate`. ``"mean"`` uses ``record`` ``"rotation"`` (or the
        orbit); ``"birkhoff"`` needs ``"orbit"``.
    method : {"mean", "birkhoff"}, optional
        ``"mean"``: the paper's ``rho = <omega_a>`` over the steps taken. ``"birkhoff"``: the
        weighted Birkhoff average of omega_a, exact to ~1e-12 after a few thousand steps on a
        quasi-periodic orbit where the plain mean is only accurate to ~1/N.

    Returns
    -------
    ndarray
        Shape (n_orbits,); NaN for an orbit that took no step.
    """
    if method not in ("mean", "birkhoff"):
        raise ValueError(f"method must be 'mean' or 'birkhoff', got {method!r}")
    if method == "mean" and res.rotation is not None:
        return res.rotation
    out = np.full(res.n_orbits, np.nan)
    for i in range(res.n_orbits):
        w = _omegas(res, i)
        if w.size:
            out[i] = w.mean() if method == "mean" else birkhoff_average(w)
    return out


def regularity(res) -> np.ndarray:
    """Digits of agreement of the weighted Birkhoff rotation number over the two halves of each orbit.

    ``-log10 |WB(first half) - WB(second half)|``: about 10-15 on an invariant curve
    (quasi-periodic), 2-5 on a chaotic orbit (Das, Sander, Yorke's "dig"). Orbits inside a
    resonance island are quasi-periodic too and score high.

    Parameters
    ----------
    res : IterateResult
        Result recorded with ``"orbit"``.

    Returns
    -------
    ndarray
        Shape (n_orbits,); 16 means agreement to rounding; NaN for orbits with < 4 steps.
    """
    out = np.full(res.n_orbits, np.nan)
    for i in range(res.n_orbits):
        w = _omegas(res, i)
        h = w.size // 2
        if h < 2:
            continue
        d = abs(birkhoff_average(w[:h]) - birkhoff_average(w[h : 2 * h]))
        out[i] = 16.0 if d == 0 else min(16.0, -math.log10(d))
    return out


# ------------------------------------------------------------------------------------------------
# Hovering set


@dataclass(frozen=True)
class HoveringArea:
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
        Leading-order prediction eq:hovsetsize for eps > 0, 0 for eps <= 0 (thm:hovering).
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
    phi, K, hovering : ndarray or None
        Sample points and their membership, when ``keep_points`` was set.
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
    phi: Optional[np.ndarray] = field(default=None, repr=False)
    K: Optional[np.ndarray] = field(default=None, repr=False)
    hovering: Optional[np.ndarray] = field(default=None, repr=False)


def _stratified(samples: int, K_low: float, rng) -> tuple:
    """One uniform point in each cell of a near-square grid over [-pi, pi) x [K_low, 0)."""
    H = -K_low
    n_phi = max(1, int(round(math.sqrt(samples * 2 * math.pi / H))))
    n_K = max(1, int(math.ceil(samples / n_phi)))
    i, j = np.meshgrid(np.arange(n_phi), np.arange(n_K), indexing="ij")
    phi = -math.pi + (i.ravel() + rng.random(i.size)) * (2 * math.pi / n_phi)
    K = K_low + (j.ravel() + rng.random(j.size)) * (H / n_K)
    K = np.minimum(K, -1e-300)  # the box is K < 0 (HOV lies in J_0)
    return phi, K


def hovering_area(m, n_steps: int = 10_000, samples: int = 100_000, K_low: Optional[float] = None, seed: int = 0,
                  n_threads: int = 0, keep_points: bool = False) -> HoveringArea:
    """Area of the hovering set HOV(eps) of a truncated map, by its definition.

    HOV(eps) is the set of points that impact under F_0 (some iterate leaves J_0 u J_0u) and never
    impact under F_eps (every iterate stays in J_0 u J_0u). It lies in J_0, so the box
    ``[-pi, pi) x [K_low, 0)`` is sampled with one uniform point per cell of a near-square grid
    (stratified sampling). Each point is iterated under F_0 and under F_eps with early exit: an
    orbit stops at its first impact, so only hovering orbits cost the full N steps.

    Parameters
    ----------
    m : TruncatedMap
        The map F_eps.
    n_steps : int, optional
        N: iterates that count as "never" (estimates at N/4 and N/2 come from the same run).
    samples : int, optional
        Number of sample points (rounded up to fill the grid).
    K_low : float, optional
        Bottom of the box. Default ``-2 |eps| / |sin(Omega0/2)|`` (twice the deepest possible
        leading-order critical curve, eq:kcrit), clipped to the band.
    seed : int, optional
        Seed of the jitter.
    n_threads : int, optional
        Worker threads (0 = all cores).
    keep_points : bool, optional
        Keep the sample points and their membership in the result (for plotting).

    Returns
    -------
    HoveringArea
    """
    if n_steps < 4:
        raise ValueError(f"n_steps must be >= 4 (estimates at N/4, N/2, N), got {n_steps}")
    if samples < 1:
        raise ValueError(f"samples must be >= 1, got {samples}")
    lo = m.valid_band()[0]
    if K_low is None:
        s = abs(math.sin(0.5 * m.Omega0))
        depth = 2.0 * abs(m.eps) / s if s > 1e-3 else -lo
        K_low = max(-depth, lo * (1 - 1e-9)) if m.eps != 0 else max(-0.1, lo * (1 - 1e-9))
    K_low = float(K_low)
    if not (lo < K_low < 0):
        raise ValueError(f"K_low must lie in the band below 0, ({lo}, 0), got {K_low}")
    rng = np.random.default_rng(seed)
    phi, K = _stratified(samples, K_low, rng)
    n = phi.size
    no_impact = ("0u", "0")

    # Part 1 of the definition: the point impacts under F_0 (checked, not assumed).
    r0 = m.with_eps(0.0).iterate(phi, K, n_steps, record=(), exit_regions=no_impact, stop_on_exit=True,
                                 n_threads=n_threads)
    impacts0 = r0.status == Status.EXITED
    # Part 2: it never impacts under F_eps (for N/4, N/2, N steps: exit_step beyond each count).
    r = m.iterate(phi, K, n_steps, record=(), exit_regions=no_impact, stop_on_exit=True, n_threads=n_threads)
    stayed = r.status == Status.OK
    box_area = 2 * math.pi * (-K_low)
    areas = {}
    for N in (n_steps // 4, n_steps // 2, n_steps):
        survive = stayed | ((r.status == Status.EXITED) & (r.exit_step >= N)) | ((r.status == Status.ESCAPED) & (r.steps_done >= N))
        areas[N] = box_area * np.count_nonzero(impacts0 & survive) / n
    hov = impacts0 & stayed
    p = np.count_nonzero(hov) / n
    sampling = box_area * math.sqrt(max(p * (1 - p), 1.0 / n) / n)
    iteration = areas[n_steps // 2] - areas[n_steps]
    theory = float(_geo.hovering_area_theory(m.eps, m.theta_w, m.Omega0)) if m.eps > 0 else 0.0
    floor_touched = bool(np.any(hov & (K < 0.9 * K_low)))
    return HoveringArea(
        area=areas[n_steps],
        error=2 * sampling + iteration,
        sampling_error=sampling,
        iteration_error=iteration,
        theory=theory,
        areas=areas,
        n_samples=n,
        box=(-math.pi, math.pi, K_low, 0.0),
        impact_fraction_F0=float(np.count_nonzero(impacts0) / n),
        floor_touched=floor_touched,
        phi=phi if keep_points else None,
        K=K if keep_points else None,
        hovering=hov if keep_points else None,
    )


# ------------------------------------------------------------------------------------------------
# Critical curve


def max_angular_gap(phi) -> float:
    """Largest gap between consecutive angles of a point set on the circle.

    Parameters
    ----------
    phi : array_like
        Angles (NaN entries are ignored).

    Returns
    -------
    float
        The largest gap, in ``[0, 2 pi]`` (``2 pi`` for fewer than two points).
    """
    a = np.sort(np.mod(np.asarray(phi, dtype=float)[np.isfinite(phi)], 2 * np.pi))
    if a.size < 2:
        return 2 * np.pi
    return float(max(np.max(np.diff(a)), a[0] + 2 * np.pi - a[-1]))


@dataclass(frozen=True)
class CriticalCurve:
    """The lowest invariant curve inside a set of no-impact regions (see :func:`critical_curve`).

    Attributes
    ----------
    K0 : float
        Height where the critical orbit starts on the search line (L1 or L2).
    K_min : float
        Lowest K along the critical orbit (the curve's minimum).
    rotation : float
        Weighted Birkhoff rotation number of the critical orbit.
    rotation_mean : float
        The paper's rho = <omega_a> of the same orbit.
    digits : float
        Regularity of the orbit (see :func:`regularity`).
    K_pred, rotation_pred : float
        Predictions eq:kcrit and eq:rhocrit (meaningful for the hovering case, eps > 0 on L1).
    K_fail : float
        Highest tested start below K0 whose orbit impacts or is not regular (bracket of K0).
    phi, K : ndarray
        The critical orbit.
    """

    K0: float
    K_min: float
    rotation: float
    rotation_mean: float
    digits: float
    K_pred: float
    rotation_pred: float
    K_fail: float
    phi: np.ndarray = field(repr=False)
    K: np.ndarray = field(repr=False)


def critical_curve(m, n_steps: int = 20_000, K_range: Optional[Sequence[float]] = None,
                   regions=("0u", "0"), line: str = "L1", grid: int = 64, digits: float = 8.0,
                   tol: float = 1e-6, n_threads: int = 0) -> CriticalCurve:
    """Search the lowest invariant curve that stays in ``regions``, along the line L1 (or L2).

    A start ``(L(K), K)`` passes when its orbit stays in ``regions`` for ``n_steps``, its
    weighted Birkhoff rotation number agrees over the two halves of the orbit to ``digits``
    digits (quasi-periodic), and it fills the circle: its largest gap in phi is below 20 times the
    mean spacing ``2 pi / n_steps`` (a rotational invariant curve; an island chain of period p
    leaves gaps ~ 2 pi / p). The lowest passing start of a grid over ``K_range`` is then refined
    by bisection against the grid point below it.

    Parameters
    ----------
    m : TruncatedMap
        The map.
    n_steps : int, optional
        Iterates per tested orbit.
    K_range : (float, float), optional
        Heights searched. Default: from ``3 K~_c`` (eq:kcrit; ``-2|eps|/sin(Omega0/2)`` when
        that is not below 0) up to ``|eps| / |sin(Omega0/2)|``, inside the band.
    regions : iterable, optional
        The no-impact set: ``("0u", "0")`` for the hovering critical curve, ``("0u",)`` for the
        curve k^{u0} (lowest curve in K >= 0).
    line : {"L1", "L2"}, optional
        Search line: minima of the curves lie near L1 when ``eps sin(Omega0/2) > 0``, near L2
        otherwise (thm:minmaxinvriantcurves).
    grid : int, optional
        Grid points of the first scan.
    digits : float, optional
        Regularity threshold.
    tol : float, optional
        Bisection tolerance on K0.
    n_threads : int, optional
        Worker threads for the scan.

    Returns
    -------
    CriticalCurve

    Raises
    ------
    RuntimeError
        If no start in ``K_range`` passes (no invariant curve found: widen the range).
    """
    if line not in ("L1", "L2"):
        raise ValueError(f"line must be 'L1' or 'L2', got {line!r}")
    line_fn = m.L1 if line == "L1" else m.L2
    lo, hi = m.valid_band()
    s = abs(math.sin(0.5 * m.Omega0))
    scale = abs(m.eps) / max(s, 1e-3)
    if K_range is None:
        kc = m.K_crit()
        K_a = 3 * kc if kc < 0 else -2 * scale
        K_range = (max(K_a, lo * (1 - 1e-9)), min(scale, hi))
    K_a, K_b = map(float, K_range)
    if not (lo < K_a < K_b < hi):
        raise ValueError(f"K_range must be increasing inside the band ({lo}, {hi}), got {K_range}")

    def test(K0s):
        K0s = np.atleast_1d(np.asarray(K0s, dtype=float))
        res = m.iterate(line_fn(K0s), K0s, n_steps, record=("orbit",), exit_regions=regions, stop_on_exit=True,
                        n_threads=n_threads)
        stayed = res.status == Status.OK
        dig = np.where(stayed, regularity(res), 0.0)
        circle = np.array([stayed[i] and max_angular_gap(res.phi[i]) < 20 * 2 * np.pi / n_steps
                           for i in range(res.n_orbits)])
        return stayed & (dig >= digits) & circle, res, dig

    K_grid = np.linspace(K_a, K_b, grid)
    ok, _, _ = test(K_grid)
    if not ok.any():
        raise RuntimeError(
            f"no invariant curve in regions {tuple(regions)} found on {line} for K0 in [{K_a}, {K_b}] "
            f"with {n_steps} steps and {digits} digits; widen K_range")
    j = int(np.argmax(ok))
    K_pass = K_grid[j]
    K_fail = K_grid[j - 1] if j > 0 else K_a
    if j > 0:
        while K_pass - K_fail > tol:
            mid = 0.5 * (K_pass + K_fail)
            if test([mid])[0][0]:
                K_pass = mid
            else:
                K_fail = mid
    _, res, dig = test([K_pass])
    rho_w = rotation_number(res, "birkhoff")[0]
    rho_m = rotation_number(res, "mean")[0]
    return CriticalCurve(
        K0=float(K_pass),
        K_min=float(np.min(res.K[0])),
        rotation=float(rho_w),
        rotation_mean=float(rho_m),
        digits=float(dig[0]),
        K_pred=float(m.K_crit()),
        rotation_pred=float(m.rho_crit()),
        K_fail=float(K_fail),
        phi=res.phi[0],
        K=res.K[0],
    )
