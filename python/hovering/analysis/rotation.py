"""Rotation numbers of orbits of either model: the paper's mean, and the weighted Birkhoff average
of Das, Sander and Yorke, whose convergence rate also tells a quasi-periodic orbit
(super-polynomial) from a chaotic one (about N^-1/2).
"""

from __future__ import annotations

import math

import numpy as np

from .._checks import is_choice, real_array
from ..interface import IterateResult

__all__ = ["birkhoff_weights", "birkhoff_average", "rotation_number", "regularity"]


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


def birkhoff_average(values, axis: int = -1) -> np.ndarray | float:
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
    v = real_array("values", values)
    if (
        isinstance(axis, (bool, np.bool_))
        or not isinstance(axis, (int, np.integer))
        or not -max(v.ndim, 1) <= axis < max(v.ndim, 1)
    ):
        raise ValueError(
            f"axis must be an integer in [-{max(v.ndim, 1)}, {max(v.ndim, 1) - 1}] (values has {v.ndim} "
            f"dimension(s)), got {axis!r}"
        )
    if v.ndim == 0:
        raise ValueError("values must be a time series (at least 1-D), got a number")
    v = np.moveaxis(v, int(axis), -1)
    if v.shape[-1] == 0:
        raise ValueError("values must hold at least one sample along the time axis")
    if not np.all(np.isfinite(v)):
        raise ValueError("values must be finite (an orbit that stopped early has NaN tails: cut them off)")
    out = v @ birkhoff_weights(v.shape[-1])
    return float(out) if np.ndim(out) == 0 else out


def _omegas(res, i: int) -> np.ndarray:
    """The rotation of each step orbit i took: omega_a of the truncated map recomputed from the
    recorded points (bit-exact), or the flow's lifted angle advances (see FlowMap.step_rotations)."""
    if res.phi is None or res.K is None:
        raise ValueError("this needs a result recorded with record=('orbit', ...)")
    if res.map is None:
        raise ValueError("this result does not know its map (made outside a map's iterate)")
    n = int(res.steps_done[i])
    if hasattr(res.map, "step_rotations"):
        return res.map.step_rotations(res, i)
    return res.map.rotation(res.phi[i, :n], res.K[i, :n])


def _result(name: str, res):

    if not isinstance(res, IterateResult):
        raise ValueError(f"{name} must be the IterateResult of a map's iterate(...), got {type(res).__name__}")
    return res


def rotation_number(res, method: str = "mean") -> np.ndarray:
    """Rotation number of each orbit of an iteration result.

    Parameters
    ----------
    res : IterateResult
        Result of a map's ``iterate`` (TruncatedMap, TruncatedFamily or FlowMap). ``"mean"`` uses
        ``record`` ``"rotation"`` (or the orbit); ``"birkhoff"`` needs ``"orbit"`` (and, for the
        flow, ``"regions"``).
    method : {"mean", "birkhoff"}, optional
        ``"mean"``: the paper's ``rho = <omega_a>`` over the steps taken. ``"birkhoff"``: the
        weighted Birkhoff average of omega_a, exact to ~1e-12 after a few thousand steps on a
        quasi-periodic orbit where the plain mean is only accurate to ~1/N.

    Returns
    -------
    ndarray
        Shape (n_orbits,); NaN for an orbit that took no step.

    Examples
    --------
    An invariant circle above the tangency: the weighted average converges far faster than the mean.

    >>> import numpy as np, hovering
    >>> m = hovering.TruncatedMap(eps=0.3, Omega0=hovering.OMEGA_G, theta_w=3 * np.pi / 4)
    >>> orbit = m.iterate(m.L1([0.3]), [0.3], 20_000, record=("orbit",))
    >>> print(np.round(hovering.rotation_number(orbit, method="birkhoff"), 8))
    [4.37764562]
    >>> print(np.round(hovering.rotation_number(orbit), 4))   # the plain mean: error ~1/N
    [4.3776]
    """
    _result("res", res)
    if not is_choice(method, ("mean", "birkhoff")):
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
    _result("res", res)
    out = np.full(res.n_orbits, np.nan)
    for i in range(res.n_orbits):
        w = _omegas(res, i)
        h = w.size // 2
        if h < 2:
            continue
        d = abs(birkhoff_average(w[:h]) - birkhoff_average(w[h : 2 * h]))
        out[i] = 16.0 if d == 0 else min(16.0, -math.log10(d))
    return out
