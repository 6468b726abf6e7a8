"""Normal coordinates (phi, K) = (theta, I - I_tan^eps(theta)) of Sigma_h (eq:kphidef).

* :class:`TangentialCurve`: the tangential curve measured on the flow without bisection: the
  points that touch q1 = qw1 are known in closed form on the wall (eq:XiwallepsI) and are followed
  backward to Sigma_h; the curve comes out as s -> (theta(s), I(s)), a closed curve whose
  trigonometric interpolant converges spectrally, and it is a graph ``I = I_tan(theta)`` exactly
  when theta(s) increases. Where it is not, the curve says so (no normal coordinates exist).
* :func:`tangential_curve`: the same curve point by point, by bisection in I on the wall system's
  itineraries (an independent check; its bracket widens itself).
* :func:`forcing_function`, :func:`forcing_coefficients`: the odd forcing f of eq:defoff.
"""

from __future__ import annotations

import operator

import numpy as np

from .._checks import MAX_MODES, check_points, integer, real_array, require_angles, require_finite, require_type
from .._core import normal as _core_normal
from .._deprecated import renamed_keywords
from .._enums import wrap
from .._io.records import reduce_record
from .._io.serial import Saveable
from ..flow.section import FlowStatus, Section, flow_options

__all__ = [
    "TangentialCurve",
    "tangential_curve",
    "forcing_function",
    "forcing_coefficients",
    "to_normal",
    "from_normal",
]

_TWO_PI = 2 * np.pi


#: The compiled curve's state (its ``__getstate__``): what a saved or pickled curve is rebuilt from.
_CURVE_STATE = ("h", "eps", "I_tan0", "theta", "I", "err_theta", "err_I")


class TangentialCurve(Saveable):
    """``I_tan^eps(theta)`` (Def:sing_curve) measured on the flow; see the module docstring.

    A curve pickles, copies and saves (:meth:`save`, :func:`hovering.save`) as its section and
    measured samples: the interpolants are rebuilt from them bit for bit, without tracing the flow.

    Parameters
    ----------
    sec : Section
        The section (system, energy). Only the line q1 = qw1 matters, whatever the geometry.
    n : int, optional
        Wall points traced (even, in [8, 4096]); the interpolant's error falls spectrally with n.
        Default: 64, doubled (up to 1024) until the measured interpolation error is below 1e-12
        (the issue's system: 7e-15 with 64 at eps = -0.05; at eps = 0.5 the curve sharpens and
        needs 1024 for 1e-14); 64 without refinement when ``n_check = 0``.
    rtol : float, optional
        Integration tolerance of the backward traces (atol = rtol / 100).
    n_check : int, optional
        Off-grid wall points traced to measure the interpolation error (0: skip).

    Attributes
    ----------
    theta, values : ndarray
        The measured points (theta_k, I_k) of the curve (one per wall point).
    s : ndarray
        Their wall angles.
    interpolation_error : float
        Largest |I| deviation of the interpolant from direct traces at the ``n_check`` off-grid
        points (NaN if n_check = 0); ``interpolation_error_theta`` the same in theta.
    is_graph : bool
        Whether theta(s) increases, i.e. normal coordinates exist.
    min_slope : float
        min over s of dtheta/ds (> 0 for a graph).

    Raises
    ------
    ValueError
        If the wall tangency curve does not exist or is not a graph over the wall angle (eps too
        large; the message says which and where), or for bad n, rtol.
    """

    def __init__(self, sec: Section, n=None, rtol: float = 1e-12, n_check: int = 4):
        if not isinstance(sec, Section):
            raise ValueError(f"sec must be a hovering.Section, got {sec!r}")
        auto = n is None
        try:
            n = 64 if auto else operator.index(n)
            n_check = operator.index(n_check)
        except TypeError:
            raise ValueError(f"n and n_check must be integers, got {n!r}, {n_check!r}") from None
        if not (8 <= n <= 4096 and n % 2 == 0):
            raise ValueError(f"n must be an even integer in [8, 4096], got {n!r}")
        if not 0 <= n_check <= n:
            raise ValueError(f"n_check must be in [0, n], got {n_check!r}")
        opts = flow_options(rtol=rtol, atol=rtol * 1e-2)
        if auto:  # the core's rule (64 wall points, doubled up to 1024 for an error below 1e-12)
            c = _core_normal.TangentialCurve.measure_refined(sec.sys.core, sec.h, opts, n_check)
        else:
            c = _core_normal.TangentialCurve(sec.sys.core, sec.h, n, opts, n_check)
        self._adopt(sec, c, checked=bool(n_check))

    def _adopt(self, sec: Section, c, checked: bool) -> None:
        """Take the compiled curve ``c`` of ``sec`` (``checked``: its interpolation error was measured)."""
        self.sec = sec
        self._c = c
        self.s = c.s
        self.theta = c.theta
        self.values = c.I
        et, eI = c.interpolation_error
        self.interpolation_error = float(eI) if checked else float("nan")
        self.interpolation_error_theta = float(et) if checked else float("nan")
        self.is_graph = bool(c.is_graph)
        self.min_slope = float(c.min_slope)

    def _samples(self) -> dict:
        """The compiled curve's state by name (see :data:`_CURVE_STATE`), and whether its error was measured."""
        return dict(zip(_CURVE_STATE, self._c.__getstate__()), checked=not np.isnan(self.interpolation_error))

    @classmethod
    def _from_samples(cls, sec: Section, samples: dict) -> TangentialCurve:
        """The curve of ``sec`` with the samples of :meth:`_samples` (no trace of the flow; validated)."""
        sec = _section("sec", sec)
        try:
            state = tuple(samples[k] for k in _CURVE_STATE)
        except (KeyError, TypeError):
            raise ValueError(f"a tangential curve's samples need the entries {_CURVE_STATE}, got {samples!r}") from None
        if state[0] != sec.h:
            raise ValueError(
                f"the tangential curve's samples were measured at h = {state[0]}, not at the section's h = {sec.h}"
            )
        c = _core_normal.TangentialCurve.__new__(_core_normal.TangentialCurve)
        c.__setstate__(state)
        obj = cls.__new__(cls)
        obj._adopt(sec, c, checked=bool(samples.get("checked", True)))
        return obj

    def _to_record(self) -> dict:
        """What :func:`hovering.save` writes: the section and the measured samples."""
        return {"sec": self.sec, "samples": self._samples()}

    @classmethod
    def _from_record(cls, record: dict) -> TangentialCurve:
        """Inverse of :meth:`_to_record` (the interpolants are rebuilt bit for bit, the flow is not traced)."""
        return cls._from_samples(record["sec"], record["samples"])

    #: What the record rebuilds (the rest of the instance dict is pickled as it is).
    _OWN = frozenset(
        {
            "sec",
            "_c",
            "s",
            "theta",
            "values",
            "interpolation_error",
            "interpolation_error_theta",
            "is_graph",
            "min_slope",
        }
    )

    def __reduce__(self):
        """Pickle as the record: the section and the measured samples."""
        return reduce_record(self, {k: v for k, v in self.__dict__.items() if k not in self._OWN})

    def __repr__(self) -> str:
        return (
            f"TangentialCurve(h={self.sec.h}, eps={self.sec.sys.eps}, n={self.s.size}, graph={self.is_graph}, "
            f"interpolation_error={self.interpolation_error:.2g})"
        )

    @property
    def I_tan0(self) -> float:
        """The unperturbed tangent action ``I_tan(h) = H2^{-1}(h - V1(qw1))`` (eq:Itan)."""
        return float(self._c.I_tan0)

    @property
    def not_graph_reason(self) -> str:
        """Why the curve is not a graph (empty if it is)."""
        return self._c.not_graph_reason

    def _require_graph(self):
        if not self.is_graph:
            raise ValueError(self._c.not_graph_reason)

    def __call__(self, theta) -> np.ndarray:
        """``I_tan^eps`` at the angles ``theta`` (array_like; any real angle, wrapped).

        Raises
        ------
        ValueError
            If the curve is not a graph over theta.
        """
        self._require_graph()
        th = real_array("theta", theta)
        require_angles("theta", th)
        out = self._c.I_tan(np.ascontiguousarray(np.ravel(wrap(th)), dtype=float)).reshape(th.shape)
        return out if out.ndim else float(out)

    def at(self, s):
        """``(theta(s), I(s))`` of the closed curve at wall angles s (works for any curve)."""
        a = np.atleast_1d(real_array("s", s))
        require_angles("s", a)
        return self._c.at(np.ascontiguousarray(a.ravel()))

    def to_normal(self, theta, I):
        """``(phi, K) = (theta, I - I_tan(theta))`` (eq:kphidef); theta, I finite, I > 0."""
        th, I = _section_pair(theta, I)
        return th, I - self(th)

    def from_normal(self, phi, K):
        """``(theta, I) = (phi, K + I_tan(phi))`` (eq:kphiinvdef); a ValueError where I would be <= 0."""
        ph, K = _finite_pair("phi", phi, "K", K)
        I = K + self(ph)
        _positive_action(I, K)
        return ph, I

    def forcing(self, phi) -> np.ndarray:
        """``eps f(phi) = I_tan(-phi) - I_tan(phi)`` (eq:defoff), divided by eps.

        Raises
        ------
        ValueError
            At eps = 0 (f is defined through a division by eps) or if the curve is not a graph.
        """
        eps = self.sec.sys.eps
        if eps == 0:
            raise ValueError("f(phi) is defined for eps != 0 (eq:defoff divides by eps)")
        ph = real_array("phi", phi)
        require_angles("phi", ph)
        return (self(-ph) - self(ph)) / eps

    def forcing_coefficients(self, n_modes: int | None = None, n_phi: int | None = None) -> np.ndarray:
        """Sine coefficients ``b_1 .. b_n_modes`` of f (eq:defoff), fitted on n_phi angles.

        The core's one fit of the measured forcing (``hovering._core.normal``): f sampled at the
        midpoint angles ``-pi + 2 pi (j + 1/2) / n_phi``, where the sine modes are orthogonal and
        the least-squares fit is the discrete sine transform (spectrally accurate for the smooth f).

        Parameters
        ----------
        n_modes : int, optional
            Number of sine modes (default ``FORCING_MODES``, 8).
        n_phi : int, optional
            Sample angles, > 2 n_modes (default ``FORCING_SAMPLES``, 256).

        Returns
        -------
        ndarray

        Raises
        ------
        ValueError
            At eps = 0 (f divides by eps), if the curve is not a graph, or for bad counts.
        """
        n_modes, n_phi = _mode_counts(n_modes, n_phi)
        if self.sec.sys.eps == 0:
            raise ValueError("f(phi) is defined for eps != 0 (eq:defoff divides by eps)")
        self._require_graph()
        return self._c.forcing_coefficients(n_modes, n_phi)


def _mode_counts(n_modes, n_phi) -> tuple:
    """(n_modes, n_phi) of a sine fit: 1 <= n_modes <= MAX_MODES, 2 n_modes < n_phi <= 65536 (beyond,
    each sample is a flow trace and the fit gains nothing); None: the core's defaults."""
    n_modes = integer("n_modes", _core_normal.FORCING_MODES if n_modes is None else n_modes, 1, MAX_MODES)
    if n_phi is None:
        n_phi = _core_normal.FORCING_SAMPLES
    return n_modes, integer("n_phi (> 2 n_modes, so the fit is determined)", n_phi, 2 * n_modes + 1, 65536)


def _section(name: str, sec) -> Section:
    return require_type(name, sec, Section, "a hovering.Section (hovering.Section(system, h))")


def _curve_of(sec: Section, curve) -> TangentialCurve:
    """The tangential curve of sec (measured if None); a ValueError for any other object or the
    curve of another system or energy (whose normal coordinates mean something else)."""
    if curve is None:
        return TangentialCurve(sec)
    if not isinstance(curve, TangentialCurve) or curve.sec.sys != sec.sys or curve.sec.h != sec.h:
        raise ValueError(
            f"curve must be the TangentialCurve of this section (same system, h = {sec.h}), got {curve!r}"
            if not isinstance(curve, TangentialCurve)
            else f"curve must be the TangentialCurve of this section (same system, h = {sec.h}); it belongs "
            f"to h = {curve.sec.h}" + ("" if curve.sec.sys == sec.sys else " of another system")
        )
    return curve


def _finite_pair(na, a, nb, b):
    """(angle wrapped to [-pi, pi), finite value), broadcast together; ValueErrors name the argument."""
    a, b = real_array(na, a), real_array(nb, b)
    require_angles(na, a)
    require_finite(nb, b)
    check_points((na, nb), (a.shape, b.shape))  # before the copies below
    a, b = np.broadcast_arrays(np.asarray(wrap(a), dtype=float), b)
    return np.array(a), np.array(b)


def _section_pair(theta, I):
    th, I = _finite_pair("theta", theta, "I", I)
    if np.any(I <= 0):
        raise ValueError(f"I must be > 0 (an action), got {np.ravel(I)[np.argmax(np.ravel(I) <= 0)]}")
    return th, I


def _positive_action(I, K):
    if np.any(I <= 0):
        i = int(np.argmax(np.ravel(I) <= 0))
        raise ValueError(
            f"K = {np.ravel(K)[i]} gives the action I = {np.ravel(I)[i]} <= 0: no point of Sigma_h "
            "(K must exceed -I_tan(phi))"
        )


def _wall_section(sec: Section) -> Section:
    """The same system with the infinite wall q1 = qw1 (the tangential curve is about that line)."""
    return Section(sec.sys.replace(geometry="wall"), sec.h)


@renamed_keywords(iterations="bisections")
def tangential_curve(sec: Section, theta, rtol: float = 1e-12, bracket=None, bisections: int = 55) -> np.ndarray:
    """The tangential curve ``I_tan^eps(theta)`` (Def:sing_curve) point by point, by bisection in I.

    For each theta, the action at which the orbit from (theta, I) touches the line q1 = qw1
    tangentially before its return: below it the orbit crosses the line (impacts the infinite
    wall), above it the orbit turns back before the line. Found by a vectorised bisection between
    ``I_tan (1 -+ bracket)`` (eq:Itan) on the wall system's itineraries; without a bracket it
    starts at 0.2 and doubles until every theta is bracketed. Where the curve is not a graph over
    theta the bisection would return one of several tangency actions: :class:`TangentialCurve`
    detects that case and says so; prefer it for normal coordinates (one trace per wall point
    instead of ~55 returns per angle).

    Parameters
    ----------
    sec : Section
        The section (its system's eps, potentials and qw1 are used).
    theta : array_like
        Angles.
    rtol : float, optional
        Integration tolerance of each return.
    bracket : float, optional
        Relative half-width of the initial bracket around I_tan(h), in (0, 1); default automatic.
    bisections : int, optional
        Bisection steps in [1, 200] (55 reach ~1e-16 relative), as :func:`hovering.corner_curves`' own.
        Formerly ``iterations=`` (deprecated, still accepted with a DeprecationWarning).

    Returns
    -------
    ndarray
        ``I_tan^eps(theta)``.

    Raises
    ------
    ValueError
        For an empty theta, a bracket outside (0, 1) or bad bisections, or if no bracket up to
        I_tan (1 -+ 0.95) contains the tangency for every theta.
    """
    _section("sec", sec)
    shape = np.shape(theta) if np.ndim(theta) else (1,)
    th = np.atleast_1d(real_array("theta", theta)).ravel()
    require_angles("theta", th)
    if isinstance(bisections, bool) or not isinstance(bisections, (int, np.integer)) or not 1 <= bisections <= 200:
        raise ValueError(f"bisections must be an integer in [1, 200], got {bisections!r}")
    if bracket is not None and not (isinstance(bracket, (int, float)) and 0 < bracket < 1):
        raise ValueError(f"bracket must lie in (0, 1), got {bracket!r}")
    if th.size == 0:
        return np.zeros(shape)
    ws = _wall_section(sec)
    I0 = sec.sys.V2.action(sec.h - sec.sys.V1.V(sec.sys.qw1))

    def crosses(I):
        out = ws.return_map(th, I, rtol=rtol, atol=rtol * 1e-2)
        return np.array(["R" in s for s in out.itinerary]) | (out.status == FlowStatus.GRAZING)

    rel = 0.2 if bracket is None else float(bracket)
    while True:
        lo, hi = np.full(th.shape, I0 * (1 - rel)), np.full(th.shape, I0 * (1 + rel))
        if crosses(lo).all() and not crosses(hi).any():
            break
        if bracket is not None or rel >= 0.95:
            raise ValueError(
                f"the tangency is not inside I_tan (1 +- {rel}) for every theta (eps = {sec.sys.eps}); "
                "the curve may not be a graph: see hovering.TangentialCurve"
            )
        rel = min(0.95, 2 * rel)
    for _ in range(int(bisections)):
        mid = 0.5 * (lo + hi)
        c = crosses(mid)
        lo = np.where(c, mid, lo)
        hi = np.where(c, hi, mid)
    return (0.5 * (lo + hi)).reshape(shape)


def forcing_function(sec: Section, phi, **kwargs) -> np.ndarray:
    """``f(phi) = (I_tan^eps(-phi) - I_tan^eps(phi)) / eps`` (eq:defoff) by :func:`tangential_curve`.

    Parameters
    ----------
    sec : Section
        The section of a system with eps != 0.
    phi : array_like
        Angles.
    **kwargs
        Passed to :func:`tangential_curve`.

    Returns
    -------
    ndarray
    """
    if _section("sec", sec).sys.eps == 0:
        raise ValueError("f(phi) is defined for eps != 0 (eq:defoff divides by eps)")
    p = np.atleast_1d(real_array("phi", phi)).ravel()
    require_angles("phi", p)
    both = tangential_curve(sec, np.concatenate([-p, p]), **kwargs)
    return (both[: p.size] - both[p.size :]) / sec.sys.eps


def forcing_coefficients(sec: Section, n_modes: int | None = None, n_phi: int | None = None, **kwargs) -> np.ndarray:
    """Sine coefficients ``b_k`` of the measured forcing f (eq:defoff), f by :func:`forcing_function`.

    The same fit as :meth:`TangentialCurve.forcing_coefficients` (the core's, on the same midpoint
    angles), of f found point by point by bisection: an independent check of the curve's.

    Parameters
    ----------
    sec : Section
        Section of a system with eps != 0.
    n_modes : int, optional
        Number of sine modes (default ``FORCING_MODES``, 8).
    n_phi : int, optional
        Sample angles in (-pi, pi), > 2 n_modes (default ``FORCING_SAMPLES``, 256).
    **kwargs
        Passed to :func:`forcing_function`.

    Returns
    -------
    ndarray
        ``b_1 .. b_n_modes``.
    """
    _section("sec", sec)
    n_modes, n_phi = _mode_counts(n_modes, n_phi)
    f = forcing_function(sec, _core_normal.forcing_angles(n_phi), **kwargs)
    return _core_normal.sine_coefficients(np.ascontiguousarray(f, dtype=float), n_modes)


def to_normal(sec: Section, theta, I, **kwargs):
    """Normal coordinates ``(phi, K) = (theta, I - I_tan^eps(theta))`` (eq:kphidef), by bisection.

    Parameters
    ----------
    sec : Section
        The section.
    theta, I : array_like
        Section coordinates.
    **kwargs
        Passed to :func:`tangential_curve`.

    Returns
    -------
    phi, K : ndarray
    """
    _section("sec", sec)
    th, I = _section_pair(np.atleast_1d(theta), I)
    return th, I - tangential_curve(sec, th, **kwargs)


def from_normal(sec: Section, phi, K, **kwargs):
    """Inverse of :func:`to_normal`: ``(theta, I) = (phi, K + I_tan^eps(phi))`` (eq:kphiinvdef).

    Parameters
    ----------
    sec : Section
        The section.
    phi, K : array_like
        Normal coordinates.
    **kwargs
        Passed to :func:`tangential_curve`.

    Returns
    -------
    theta, I : ndarray
    """
    _section("sec", sec)
    p, K = _finite_pair("phi", np.atleast_1d(phi), "K", K)
    I = K + tangential_curve(sec, p, **kwargs)
    _positive_action(I, K)
    return p, I
