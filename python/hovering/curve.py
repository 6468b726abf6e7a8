"""Closed curves K(phi) on the circle, and the stop conditions of an iteration on them.

:class:`Curve` is a curve of the cylinder (phi, K) that goes once around: an invariant circle, the
critical curve, the floor of the impact zone, or any function of phi. It is the periodic cubic
spline through samples on a uniform grid, evaluated by the compiled core, so the kernels of every
map test it per step (``iterate(..., stop=Above(curve))``) with the very arithmetic
``curve(phi)`` uses here.

Why a cubic spline (and not the trigonometric interpolant of the samples): on a smooth curve both
converge fast, the spline as ``h**4`` (``|error| <= 5/384 h**4 max|K''''|``, ``h = 2 pi / n``).
But the invariant curves of the piecewise-smooth maps have kinks where they cross the corner
curves; there the trigonometric interpolant rings over the whole circle (Gibbs), while the
spline's error stays local: it decays by a factor ``2 - sqrt(3) = 0.27`` per cell away from a kink.
And a spline value costs a few operations (one cell), which a kernel can pay every step, where a
trigonometric sum costs O(n).
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import operator
from collections.abc import Callable

import numpy as np

from ._checks import _short, real_array, require_finite
from ._core import Curve as _core_Curve
from ._enums import wrap

__all__ = ["Curve", "Above", "Below", "StopCondition", "MAX_SAMPLES"]

#: Most samples of a curve (the SIMD kernel gathers its cells with 32-bit indices).
MAX_SAMPLES = 2**24


def _sample_count(name: str, n) -> int:
    """A number of samples: 1 (a constant) or 3 .. MAX_SAMPLES."""
    try:
        if isinstance(n, (bool, np.bool_)):
            raise TypeError
        v = operator.index(n)
    except TypeError:
        raise ValueError(
            f"{name} must be an integer, 1 (a constant) or in [3, {MAX_SAMPLES}], got {_short(n)}"
        ) from None
    if not (v == 1 or 3 <= v <= MAX_SAMPLES):
        raise ValueError(
            f"{name} must be 1 (a constant) or in [3, {MAX_SAMPLES}] (a periodic cubic spline needs "
            f"three samples), got {v}"
        )
    return v


class Curve:
    """A closed curve ``K(phi)`` on the circle: the periodic cubic spline through uniform samples.

    The samples ``K[j]`` sit at ``phi[j] = -pi + 2 pi j / n``; between them the curve is the
    periodic cubic spline (C^2) through them, so it interpolates the samples (through each, to
    rounding). One sample is a constant curve. Build one from samples (this constructor), from a
    function (:meth:`from_function`) or from the points of a circle-filling orbit
    (:meth:`from_orbit`); :class:`Above` / :class:`Below` make it a stop condition of
    ``iterate``. See the module docstring for why a cubic spline.

    Parameters
    ----------
    K : array_like
        The samples, 1-D: one (a constant) or at least 3, at most ``2**24``, all finite.
    error : array_like, optional
        An error estimate per sample (finite, >= 0), as :meth:`from_function` and
        :meth:`from_orbit` give; None (default) for samples taken as exact.

    Raises
    ------
    ValueError
        For samples that are not 1-D finite real numbers (naming the first bad one), two samples,
        or an ``error`` of another shape or with a negative or non-finite entry.

    Notes
    -----
    A curve pickles and saves (:func:`hovering.save`) as its samples and error; it is rebuilt
    through the constructor and evaluates bit for bit as the original. The evaluation is the
    compiled core's (``hovering._core.Curve``), the one the iterations use per step.

    Examples
    --------
    >>> import numpy as np, hovering
    >>> c = hovering.Curve.from_function(lambda phi: 0.1 * np.cos(phi), n=64)
    >>> bool(abs(c(0.3) - 0.1 * np.cos(0.3)) < 1e-7)
    True
    """

    __slots__ = ("_c", "_error")

    def __init__(self, K, error=None):
        k = real_array("K (curve samples)", K)
        if k.ndim != 1:
            raise ValueError(f"K (curve samples) must be a 1-D array, got shape {k.shape}")
        _sample_count("the number of samples", k.size)
        require_finite("K (curve samples)", k)
        if error is not None:
            e = real_array("error", error)
            if e.shape != k.shape:
                raise ValueError(f"error must have the shape of K {k.shape}, got {e.shape}")
            require_finite("error", e)
            if np.any(e < 0):
                raise ValueError(f"error must be >= 0, got {e[np.argmax(e < 0)]} at sample {int(np.argmax(e < 0))}")
            error = np.array(e, dtype=float)
            error.setflags(write=False)
        self._c = _core_Curve(np.ascontiguousarray(k, dtype=float))
        self._error = error

    # ------------------------------------------------------------------ construction

    @classmethod
    def constant(cls, K) -> Curve:
        """The constant curve ``K(phi) = K``.

        Parameters
        ----------
        K : float
            The height, finite.

        Returns
        -------
        Curve
        """
        if isinstance(K, (bool, np.bool_)) or not isinstance(K, numbers.Real):
            raise ValueError(f"K must be a real number, got {_short(K)}")
        return cls([float(K)])

    @classmethod
    def from_function(cls, f: Callable, n: int = 256) -> Curve:
        """The curve through ``f`` at ``n`` uniform samples, with its interpolation error measured.

        Parameters
        ----------
        f : callable
            ``f(phi) -> K`` on an array of angles in ``[-pi, pi)`` (a scalar result is a constant).
        n : int, optional
            Number of samples: 1 or 3 .. 2**24 (default 256).

        Returns
        -------
        Curve
            With ``error[j]`` the larger of ``|f - curve|`` at the two cell midpoints beside
            sample j: the spline's interpolation error there (for a smooth f within a factor of
            ~1 of the largest in the cell; near a kink of f it shows the spline's local overshoot).

        Raises
        ------
        ValueError
            For an ``n`` out of range, or an ``f`` that does not give finite real numbers of the
            shape of its argument (naming the first bad value).
        """
        n = _sample_count("n", n)
        if not callable(f):
            raise ValueError(f"f must be a callable f(phi) -> K, got {_short(f)}")
        phi = _grid(n)
        mid = phi + math.pi / n  # the cell midpoints, in (-pi, pi)
        K, Km = (_values(f, x) for x in (phi, mid))
        c = cls(K)
        dev = np.abs(Km - c(mid))
        return cls(K, error=np.maximum(dev, np.roll(dev, 1)))

    @classmethod
    def from_orbit(cls, phi, K, n: int | None = None) -> Curve:
        """The curve through the points of a circle-filling orbit, with the scatter about it as error.

        The points are sorted by phi (wrapped to ``[-pi, pi)``); the sample at each grid angle
        ``phi_j`` is the linear interpolation between the two points on either side of it
        (periodically). On an invariant circle with N points that error is ``~K'' (2 pi / N)**2 / 8``,
        far below the spline's own. Every bin ``[phi_j - h/2, phi_j + h/2)`` must hold a point.

        Parameters
        ----------
        phi, K : array_like
            The orbit's points (any shape, flattened together; NaN entries, the padding of an
            orbit that stopped, are dropped). ``|phi| <= 1e6``.
        n : int, optional
            Number of samples, 3 .. 2**24; default ``N // 8`` (about 8 points per bin) within
            [3, 4096], lowered where needed so that every bin holds a point (a bin at least as
            wide as the orbit's widest gap in phi; an orbit near a resonance clusters its points).

        Returns
        -------
        Curve
            With ``error[j]`` the largest ``|K_p - curve(phi_p)|`` over the orbit's points p in
            bin j: how far the orbit lies from the curve there. On an invariant circle it is the
            spline's interpolation error measured on the circle's own points; on an island chain
            or a chaotic layer (not a graph over phi) it is the layer's width, so a large
            ``error`` says the orbit is not a curve at this resolution.

        Raises
        ------
        ValueError
            For points that are not real, shapes that differ, fewer than 3 points, an ``n`` out of
            range, or a bin without a point (the orbit does not fill the circle at this
            resolution: the message gives the widest gap; use a smaller n or a longer orbit).
        """
        p, k = real_array("phi", phi).ravel(), real_array("K", K).ravel()
        if p.shape != k.shape:
            raise ValueError(f"phi and K must have the same number of points, got {np.size(phi)} and {np.size(K)}")
        keep = ~(np.isnan(p) | np.isnan(k))
        p, k = p[keep], k[keep]
        require_finite("K", k)
        p = np.asarray(wrap(p), dtype=float).ravel()
        N = p.size
        if N < 3:
            raise ValueError(f"an orbit needs at least 3 points (not NaN) to make a curve, got {N}")
        order = np.argsort(p, kind="stable")
        p, k = p[order], k[order]
        if n is None:
            widest = float(np.max(np.diff(np.concatenate([p, [p[0] + 2 * math.pi]]))))
            n = max(3, min(4096, N // 8, int(0.999 * 2 * math.pi / widest)))
        else:
            n = _sample_count("n", n)
        if n == 1:
            raise ValueError("n must be in [3, 2**24] for a curve from an orbit, got 1")
        h = 2 * math.pi / n
        grid = _grid(n)
        bins = np.floor((p + math.pi) / h + 0.5).astype(np.int64) % n
        counts = np.bincount(bins, minlength=n)
        if np.any(counts == 0):
            gaps = np.diff(np.concatenate([p, [p[0] + 2 * math.pi]]))
            raise ValueError(
                f"the orbit leaves {int(np.count_nonzero(counts == 0))} of the n = {n} bins empty (its "
                f"widest gap in phi is {float(np.max(gaps)):.3g} rad, a bin is {h:.3g}): it does not fill "
                "the circle at this resolution; use a smaller n or a longer orbit"
            )
        # The neighbours of each grid angle: the last point below it and the first at or above it.
        right = np.searchsorted(p, grid, side="left")
        left = right - 1
        pr = np.where(right < N, p[right % N], p[0] + 2 * math.pi)
        pl = np.where(left >= 0, p[left % N], p[-1] - 2 * math.pi)
        kr, kl = k[right % N], k[left % N]
        w = np.where(pr > pl, (grid - pl) / np.where(pr > pl, pr - pl, 1.0), 1.0)
        samples = kl + w * (kr - kl)
        c = cls(samples)
        err = np.zeros(n)
        np.maximum.at(err, bins, np.abs(k - c(p)))
        return cls(samples, error=err)

    # ------------------------------------------------------------------ the curve

    @property
    def n(self) -> int:
        """Number of samples."""
        return int(self._c.samples.size)

    @property
    def phi(self) -> np.ndarray:
        """The sample angles ``-pi + 2 pi j / n``, shape ``(n,)``."""
        return _grid(self.n)

    @property
    def K(self) -> np.ndarray:
        """The samples, shape ``(n,)`` (a copy)."""
        return np.array(self._c.samples)

    @property
    def error(self) -> np.ndarray | None:
        """Error estimate per sample (see :meth:`from_function`, :meth:`from_orbit`), or None."""
        return self._error

    @property
    def max_error(self) -> float:
        """The largest entry of :attr:`error` (NaN when there is none)."""
        return float(np.max(self._error)) if self._error is not None else math.nan

    def __call__(self, phi):
        """K on the curve at the angles phi.

        Parameters
        ----------
        phi : array_like or float
            Angles, ``|phi| <= 1e6`` (wrapped to ``[-pi, pi)``); NaN gives NaN (a missing value,
            e.g. the padding of an orbit that stopped).

        Returns
        -------
        ndarray or float
            Of the shape of phi; a float for a scalar.

        Raises
        ------
        ValueError
            For an infinite angle or one beyond 1e6.
        """
        a = real_array("phi", phi)
        out = self._c.evaluate(np.ascontiguousarray(a.ravel(), dtype=float)).reshape(a.shape)
        return float(out) if a.ndim == 0 else out

    def __repr__(self) -> str:
        k = self._c.samples
        if k.size == 1:
            return f"Curve.constant({float(k[0])!r})"
        err = "" if self._error is None else f", max_error={self.max_error:.3g}"
        return f"Curve(n={k.size}, K in [{float(np.min(k)):.6g}, {float(np.max(k)):.6g}]{err})"

    def __eq__(self, other) -> bool:
        if not isinstance(other, Curve):
            return NotImplemented
        e1, e2 = self._error, other._error
        return bool(
            np.array_equal(self._c.samples, other._c.samples)
            and ((e1 is None and e2 is None) or (e1 is not None and e2 is not None and np.array_equal(e1, e2)))
        )

    def __hash__(self) -> int:
        return hash(self._c.samples.tobytes())

    # ------------------------------------------------------------------ pickling and saving

    def __reduce__(self):
        """Pickle as the samples and the error (rebuilt through the constructor)."""
        return Curve._from_record, (self._to_record(),)

    def _to_record(self) -> dict:
        """What :func:`hovering.save` writes: the samples and the error (or None)."""
        return {"K": np.array(self._c.samples), "error": None if self._error is None else np.array(self._error)}

    @classmethod
    def _from_record(cls, record: dict) -> Curve:
        """Inverse of :meth:`_to_record` (validated again by the constructor)."""
        unknown = sorted(set(record) - {"K", "error"})
        if unknown:
            raise ValueError(f"a curve's record has the fields K and error, not {unknown}")
        return cls(record["K"], error=record.get("error"))


def _grid(n: int) -> np.ndarray:
    return -math.pi + 2 * math.pi * np.arange(n) / n


def _values(f: Callable, phi: np.ndarray) -> np.ndarray:
    """f(phi) as finite floats of phi's shape (a scalar is a constant), or a ValueError naming the problem."""
    v = real_array("f(phi)", f(phi.copy()))
    if v.ndim == 0:
        v = np.full(phi.shape, float(v))
    if v.shape != phi.shape:
        raise ValueError(f"f(phi) must return an array of the shape of phi {phi.shape} (or a number), got {v.shape}")
    require_finite("f(phi)", v)
    return v


def _as_curve(who: str, curve_or_K) -> Curve:
    if isinstance(curve_or_K, Curve):
        return curve_or_K
    if isinstance(curve_or_K, (bool, np.bool_)) or not isinstance(curve_or_K, numbers.Real):
        raise ValueError(f"{who} takes a hovering.Curve or a number K (a constant curve), got {_short(curve_or_K)}")
    if not math.isfinite(float(curve_or_K)):
        raise ValueError(f"{who}: K must be finite, got {float(curve_or_K)}")
    return Curve.constant(float(curve_or_K))


@dataclasses.dataclass(frozen=True, init=False)
class StopCondition:
    """A set of the cylinder on one side of a curve, at whose first state an orbit stops.

    Use :class:`Above` or :class:`Below`; ``iterate(..., stop=...)`` of every map takes them.

    Attributes
    ----------
    curve : Curve
        The curve (a number given to the constructor is a constant curve).
    """

    curve: Curve
    _side = 0  # the core's code: 1 above, 2 below

    def __init__(self, curve_or_K):
        object.__setattr__(self, "curve", _as_curve(type(self).__name__, curve_or_K))

    def contains(self, phi, K):
        """Whether the points lie in the set (the test the kernels make at every state).

        Parameters
        ----------
        phi, K : array_like
            Points (broadcast together).

        Returns
        -------
        ndarray of bool or bool
        """
        c = self.curve(phi)
        k = real_array("K", K)
        out = (k >= c) if self._side == 1 else (k <= c)
        return bool(out) if np.ndim(out) == 0 else out

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.curve!r})"

    def _validate_loaded(self) -> None:
        if not isinstance(self.curve, Curve):
            raise ValueError(f"{type(self).__name__}.curve must be a Curve, got {type(self.curve).__name__}")


@dataclasses.dataclass(frozen=True, init=False, repr=False)
class Above(StopCondition):
    """Stop condition: the set ``K >= curve(phi)`` (on or above the curve).

    Parameters
    ----------
    curve_or_K : Curve or float
        The curve, or a number (a constant curve).

    Raises
    ------
    ValueError
        For anything else, or a non-finite number.

    Examples
    --------
    >>> import hovering
    >>> hovering.Above(0.5).contains(0.0, [0.4, 0.5, 0.6]).tolist()
    [False, True, True]
    """

    _side = 1


@dataclasses.dataclass(frozen=True, init=False, repr=False)
class Below(StopCondition):
    """Stop condition: the set ``K <= curve(phi)`` (on or below the curve).

    Parameters
    ----------
    curve_or_K : Curve or float
        The curve, or a number (a constant curve).

    Raises
    ------
    ValueError
        For anything else, or a non-finite number.
    """

    _side = 2
