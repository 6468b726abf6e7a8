"""Periodic orbits of a return map (both models): Newton on the n-th return by multiple shooting,
symmetric search on the lines of the map's reversibility, all orbits of one period in a box, and
each orbit's monodromy matrix, multipliers, residue and stability.

The map F (TruncatedMap, TruncatedFamily, FlowMap) is reversible: F^{-1} = R0 F R0 with
``R0(phi, K) = (-phi, K - eps f(phi))`` (lem:truncreturnmap; the flow's R2(theta, I) = (-theta, I)
in normal coordinates), and R1 = R0 F is a second involution (F = R0 R1). Their fixed sets are the
symmetry lines: Fix(R0) = {phi = 0} u {phi = pi}, and Fix(R1) = {F(x) = R0(x)}, which on the
no-impact arcs is {phi = -Omega(K) / 2 mod pi} = L1 u L2 (def:L1L2). A symmetric orbit of period n
meets them twice: starting on Fix(R0), it closes after n = 2k steps if F^k(x) lies on Fix(R0) and
after n = 2k + 1 steps if F^k(x) lies on Fix(R1); starting on Fix(R1), after n = 2k if F^k(x) lies on
Fix(R1) and after n = 2k - 1 if it lies on Fix(R0) (DeVogelaere). That turns the 2-D problem into a
1-D one along a line, whose roots are bracketed by sign changes: how :func:`periodic_orbits` finds
every symmetric orbit of a period crossing a line segment.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._checks import _short, flag, integer, is_choice, real_number
from .._display import Summarized
from .._enums import Region, Status, wrap
from .._io.serial import Saveable
from ..interface import require_map
from . import _tangent as T

__all__ = ["PeriodicOrbit", "PeriodicOrbits", "periodic_orbit", "periodic_orbits", "LINES"]

#: The symmetry lines a symmetric search can start on: Fix(R0) = {phi = 0}, {phi = pi}, and the
#: two branches of Fix(R1) through L1 and L2 (def:L1L2).
LINES = ("0", "pi", "L1", "L2")
#: Longest period a search accepts (a Newton step costs one batched iterate of the period).
MAX_PERIOD = 100_000
#: Segments of the multiple-shooting system at most (its dense 2S x 2S solve).
MAX_SEGMENTS = 64


@dataclass(frozen=True, repr=False)
class PeriodicOrbit(Summarized, Saveable):
    """A periodic orbit of a map: its points, its monodromy matrix and how Newton found it.

    Attributes
    ----------
    phi, K : ndarray
        The orbit's ``period`` points, shape ``(period,)``, in the order the map visits them (NaN
        where the search failed before having an orbit).
    period : int
        Its period n (F^n(x) = x; the smallest period may divide n).
    status : str
        ``"converged"`` (residual below ``tol``, or stalled within 1e3 ``tol`` at the rounding
        floor of a long hyperbolic orbit, where Newton's correction is as small: see
        ``residuals``), ``"max_iterations"`` (also where Newton's correction stays far above the
        residual: a nearly parabolic orbit, multiplier ~1), ``"singular"`` (Newton's matrix could
        not be solved: a parabolic orbit, multiplier 1), ``"no_root"`` (the symmetric
        search found no sign change), or ``"step_failed"`` (a step of the orbit has no number:
        see ``step_status``).
    step_status : Status
        The first non-OK step status met (CORNER, GRAZING, ESCAPED, ...), else OK.
    monodromy : ndarray
        ``D F^n`` at ``(phi[0], K[0])``, shape (2, 2).
    multipliers : ndarray of complex
        Its eigenvalues (a pair ``lambda, 1 / lambda`` or ``e^{+-i 2 pi nu}``: the map preserves area).
    residue : float
        Greene's residue ``(2 - tr M) / 4``: < 0 hyperbolic, in (0, 1) elliptic, > 1 inverse
        hyperbolic.
    stability : str
        ``"elliptic"``, ``"hyperbolic"``, ``"inverse hyperbolic"`` or ``"parabolic"`` (R within
        100 ``period`` times one step's accuracy of 0 or 1: 1e-10 per step for the truncated map,
        1e4 rtol per return for the flow).
    winding : int
        Turns of phi over the period (the lifted advance / 2 pi): the rotation number is
        ``winding / period`` turns per step.
    regions : ndarray of int8
        :class:`Region` of each step of the orbit.
    residuals : ndarray
        max-norm residual of Newton's system after each iteration (the convergence history: quadratic
        convergence roughly squares it); the first entry is the starting guess's.
    newton_steps : int
        Newton iterations taken.
    line : str or None
        The symmetry line the orbit was found on (:data:`LINES`), None for a general search.
    minimal_period : int
        The least d dividing ``period`` with ``F^d(x) = x`` (to 1e4 ``tol``): an orbit of period 2
        solves the period-4 problem too; :func:`periodic_orbits` keeps only ``minimal_period ==
        period``.
    det_error : float
        ``|det M - 1|``: the departure from area preservation, a check of the Jacobians' accuracy.
    tol : float
        The residual tolerance used.
    """

    phi: np.ndarray
    K: np.ndarray
    period: int
    status: str
    step_status: Status
    monodromy: np.ndarray
    multipliers: np.ndarray
    residue: float
    stability: str
    winding: int
    regions: np.ndarray
    residuals: np.ndarray
    newton_steps: int
    line: str | None = None
    det_error: float = math.nan
    tol: float = math.nan
    minimal_period: int = 0

    @property
    def converged(self) -> bool:
        """Whether Newton converged."""
        return self.status == "converged"

    @property
    def rotation(self) -> float:
        """Rotation number in turns per step, ``winding / period``."""
        return self.winding / self.period

    @property
    def eigenvectors(self) -> np.ndarray:
        """Unit eigenvectors of the monodromy (columns, in the order of ``multipliers``): for a
        hyperbolic orbit the unstable (|lambda| > 1) and stable directions at ``(phi[0], K[0])``."""
        w, v = np.linalg.eig(self.monodromy)
        return v

    def convergence_orders(self) -> np.ndarray:
        """Estimated order of convergence of Newton's last iterations, ``log(r_{k+1} / r_k) /
        log(r_k / r_{k-1})`` (2 for quadratic), over the triples of the asymptotic regime: past the
        damped start (``r_{k-1} <= 1e-2``) and before rounding (``r_{k+1} >= 10 tol``)."""
        r = np.asarray(self.residuals, dtype=float)
        lo = 10 * self.tol if np.isfinite(self.tol) else 0.0
        out = [
            math.log(r[k + 1] / r[k]) / math.log(r[k] / r[k - 1])
            for k in range(1, r.size - 1)
            if r[k - 1] <= 1e-2 and r[k + 1] >= lo and 0 < r[k + 1] < r[k] < r[k - 1]
        ]
        return np.array(out)

    def _summary(self) -> list:
        out: list[tuple[str, object]] = [("period", self.period), ("status", self.status)]
        if self.status == "converged":
            out += [
                ("phi0, K0", f"({self.phi[0]:.6g}, {self.K[0]:.6g})"),
                ("rotation", f"{self.winding}/{self.period}"),
                ("residue", f"{self.residue:.6g}"),
                ("stability", self.stability),
            ]
        if self.line is not None:
            out.append(("line", self.line))
        out.append(("newton_steps", self.newton_steps))
        return out

    def same_orbit(self, other: PeriodicOrbit, tol: float = 1e-7) -> bool:
        """Whether ``other`` is this orbit (its first point within ``tol`` of one of this orbit's points)."""
        if other.period % self.period and self.period % other.period:
            return False
        d = np.hypot(T.angle_gap(self.phi, other.phi[0]), self.K - other.K[0])
        return bool(np.nanmin(d) <= tol)


def _failed(period, status, step_status, residuals, iterations, line, tol) -> PeriodicOrbit:
    nan = np.full(period, np.nan)
    return PeriodicOrbit(
        phi=nan,
        K=nan.copy(),
        period=period,
        status=status,
        step_status=Status(int(step_status)),
        monodromy=np.full((2, 2), np.nan),
        multipliers=np.full(2, np.nan + 0j),
        residue=math.nan,
        stability="unknown",
        winding=0,
        regions=np.full(period, int(Region.NONE), dtype=np.int8),
        residuals=np.asarray(residuals, dtype=float),
        newton_steps=iterations,
        line=line,
        tol=tol,
    )


def _first_bad(status) -> Status:
    bad = status[status != int(Status.OK)]
    return Status(int(bad[0])) if bad.size else Status.OK


def _segments(period: int, segment: int | None) -> tuple[int, int]:
    """(steps per segment m, segments S) with S m = period."""
    if segment is None:
        S = min(period, MAX_SEGMENTS)
        while period % S:
            S -= 1
        return period // S, S
    if period % segment:
        raise ValueError(f"segment = {segment} must divide the period {period}")
    if period // segment > MAX_SEGMENTS:
        raise ValueError(
            f"segment = {segment} gives {period // segment} segments; at most {MAX_SEGMENTS} (use a longer segment)"
        )
    return segment, period // segment


def _residual(seg, phi, K):
    """r_i = F^m(x_i) - x_{i+1} (phi wrapped), flattened (phi_0, K_0, phi_1, ...)."""
    r = np.empty(2 * phi.size)
    r[0::2] = T.angle_gap(seg.phi, np.roll(phi, -1))
    r[1::2] = seg.K - np.roll(K, -1)
    return r


def _newton(m, phi, K, period, tol, max_iter, segment, n_threads):
    """Multiple shooting: unknowns the S segment starts, equations F^m(x_i) = x_{i+1} (cyclic).
    Returns (phi, K, status, step_status, residuals, iterations)."""
    m_steps, S = _segments(period, segment)
    phi = np.asarray(phi, dtype=float).copy()
    K = np.asarray(K, dtype=float).copy()
    seg = T.advance(m, phi, K, m_steps, n_threads)
    if not np.all(seg.ok):
        return phi, K, "step_failed", _first_bad(seg.status), [math.inf], 0
    r = _residual(seg, phi, K)
    res = [float(np.max(np.abs(r)))]
    it = 0
    while res[-1] > tol and it < max_iter:
        it += 1
        A = np.zeros((2 * S, 2 * S))
        for i in range(S):
            A[2 * i : 2 * i + 2, 2 * i : 2 * i + 2] = seg.M[i]
            j = (i + 1) % S
            A[2 * i : 2 * i + 2, 2 * j : 2 * j + 2] -= np.eye(2)
        if not np.all(np.isfinite(A)):
            return phi, K, "step_failed", Status.NON_FINITE, res, it
        try:
            dx = np.linalg.solve(A, -r)
        except np.linalg.LinAlgError:
            return phi, K, "singular", Status.OK, res, it
        if not np.all(np.isfinite(dx)) or np.linalg.cond(A) > 1e15:
            return phi, K, "singular", Status.OK, res, it
        # The rounding floor: where the residual is noise (a long hyperbolic orbit's stretch times
        # the rounding of a step: 1e-11 at period 233 of the standard map at k = 1), Newton's
        # correction is as small as the residual itself. A correction far above it is no floor but
        # a Newton step that cannot make progress: near a parabolic orbit (multiplier ~ 1) the
        # matrix is nearly singular, the correction huge, and the residual grows along it.
        at_floor = res[-1] <= 1e3 * tol and float(np.max(np.abs(dx))) <= 1e3 * tol
        # Damped: halve the step until the residual decreases, or take the 10th halving anyway
        # (far from the orbit that is how the search moves on: a start 1.9 off the period-5 orbit
        # of the README's truncated map needs it); only the floor above may end the search early.
        lam = 1.0
        for _ in range(11):
            p1 = wrap(phi + lam * dx[0::2])
            k1 = K + lam * dx[1::2]
            seg1 = T.advance(m, p1, k1, m_steps, n_threads)
            if np.all(seg1.ok):
                r1 = _residual(seg1, p1, k1)
                if np.max(np.abs(r1)) < res[-1] or lam < 1e-3:
                    break
            lam *= 0.5
        if not np.all(seg1.ok):
            return phi, K, "step_failed", _first_bad(seg1.status), res, it
        phi, K, seg, r = p1, k1, seg1, r1
        res.append(float(np.max(np.abs(r))))
        # Two iterations that did not halve the residual, at the floor: the orbit as good as it gets.
        if len(res) >= 3 and at_floor and res[-1] > 0.5 * res[-3]:
            return phi, K, "converged", Status.OK, res, it
    status = "converged" if res[-1] <= tol else "max_iterations"
    return phi, K, status, Status.OK, res, it


def _finish(m, phi0, K0, period, status, step_status, residuals, iterations, line, tol, n_threads):
    """The orbit's points, monodromy and the rest, from a converged start."""
    seg, res = T.advance(m, [phi0], [K0], period, n_threads, orbit=True)
    if not seg.ok[0]:
        return _failed(period, "step_failed", seg.status[0], residuals, iterations, line, tol)
    M = seg.M[0]
    # The product in QR form overflows for long strongly hyperbolic orbits; R's logs still say it.
    if not T.finite_2x2(M):
        M = np.full((2, 2), np.nan)
    w = np.linalg.eigvals(M) if T.finite_2x2(M) else np.full(2, np.nan + 0j)
    R = T.residue_of(M) if T.finite_2x2(M) else (-math.inf if seg.log_r[0, 0] > 0 else math.nan)
    reg = np.full(period, int(Region.NONE), dtype=np.int8)
    try:
        reg = np.asarray(m.region(res.phi[0, :-1], res.K[0, :-1]), dtype=np.int8)
    except ValueError:
        pass
    winding = int(round(float(seg.advance[0]) / (2 * math.pi)))
    P, Kp = np.asarray(res.phi[0], dtype=float), np.asarray(res.K[0], dtype=float)
    same = max(1e-9, 1e4 * tol)
    minimal = next(
        (
            d
            for d in range(1, period + 1)
            if period % d == 0 and abs(float(T.angle_gap(P[d], P[0]))) <= same and abs(Kp[d] - Kp[0]) <= same
        ),
        period,
    )
    return PeriodicOrbit(
        phi=np.asarray(res.phi[0, :-1], dtype=float),
        K=np.asarray(res.K[0, :-1], dtype=float),
        period=period,
        status=status,
        step_status=Status(int(step_status)),
        monodromy=M,
        multipliers=w,
        residue=R,
        # Parabolic within what the Jacobians are good for: 100 x one step's accuracy per step.
        stability=T.stability_of(R, 100 * T.map_tolerance(m) * period)
        if math.isfinite(R)
        else ("hyperbolic" if R == -math.inf else "unknown"),
        winding=winding,
        regions=reg,
        residuals=np.asarray(residuals, dtype=float),
        newton_steps=iterations,
        line=line,
        det_error=abs(float(np.linalg.det(M)) - 1.0) if T.finite_2x2(M) else math.nan,
        tol=tol,
        minimal_period=minimal,
    )


# ------------------------------------------------------------------------------- symmetry lines


def _fix_r1_point(m, K, guess_phi, tol, n_threads):
    """The point of Fix(R1) = {F(x) = R0(x)} at height K near guess_phi. With the step's lifted
    advance a (phibar = phi + a, mod 2 pi), F(x) = R0(x) is 2 phi + a = 0 mod 2 pi: a root of
    h(phi) = sin(phi + a / 2), continuous in phi (no spurious roots: a jump of phi by 2 pi leaves h
    alone), by Newton with h' = cos(.) (1 + dphibar/dphi) / 2. Returns (phi, dphi/dK) or (nan, nan)."""
    phi = float(wrap(guess_phi))
    for _ in range(30):
        seg = T.advance(m, [phi], [K], 1, n_threads)
        if not seg.ok[0]:
            return math.nan, math.nan
        J, a = seg.M[0], float(seg.advance[0])
        u = phi + 0.5 * a
        d = math.cos(u) * 0.5 * (J[0, 0] + 1.0)
        if abs(d) < 1e-12:
            return math.nan, math.nan
        step = -math.sin(u) / d
        phi = float(wrap(phi + step))
        if abs(step) <= 0.1 * tol:
            seg = T.advance(m, [phi], [K], 1, n_threads)
            J = seg.M[0]
            return phi, -J[0, 1] / (J[0, 0] + 1.0)
    return math.nan, math.nan


def _line_start(m, line, K, guess_phi, tol, n_threads):
    """(phi, tangent (dphi/dK, 1)) of the point of `line` at height K."""
    if line == "0":
        return 0.0, (0.0, 1.0)
    if line == "pi":
        return -math.pi, (0.0, 1.0)
    if guess_phi is None:
        guess_phi = m.L1(K) if line == "L1" else m.L2(K)
    phi, slope = _fix_r1_point(m, K, guess_phi, tol, n_threads)
    return phi, (slope, 1.0)


def _plan(line: str, period: int) -> tuple[int, str]:
    """(steps k to the second symmetry point, which family it lies on: 'R0' or 'R1')."""
    if line in ("0", "pi"):
        return (period // 2, "R0") if period % 2 == 0 else ((period - 1) // 2, "R1")
    return (period // 2, "R1") if period % 2 == 0 else ((period + 1) // 2, "R0")


def _line_function(m, line, period, K, guess_phi, tol, n_threads, winding=None):
    """g(K) and g'(K) whose roots are the symmetric orbits of this period through `line`, and the
    start point. Without a winding: g = sin(phi_k) for an end on Fix(R0) (phi_k = 0 or pi), and
    g = sin(phi_k + a_k / 2) for an end on Fix(R1) (a_k the lifted advance of the step from x_k:
    F(x_k) = R0(x_k)); both continuous wherever the map is, none of their roots spurious. With a
    winding w, the lifted conditions, whose root is the orbit of rotation w / n (monotone in K
    where the map twists): with Phi_j the lifted angles and the orbit's symmetry
    Phi_{n-i} = C + 2 pi w - Phi_{i+c},

    * from Fix(R0) (C = 2 Phi_0, c = 0): n = 2k, g = Phi_k - Phi_0 - pi w; n = 2k + 1,
      g = 2 Phi_k + a_k - 2 Phi_0 - 2 pi w;
    * from Fix(R1) (C = Phi_0 + Phi_1, c = 1): n = 2k, g = 2 Phi_k + a_k - 2 Phi_0 - a_0 - 2 pi w;
      n = 2k - 1, g = 2 Phi_k - 2 Phi_0 - a_0 - 2 pi w.

    Returns (g, dg, phi0)."""
    phi0, tangent = _line_start(m, line, K, guess_phi, tol, n_threads)
    if not math.isfinite(phi0):
        return math.nan, math.nan, phi0
    k, end = _plan(line, period)
    v = np.array(tangent)
    if k > 0:
        seg = T.advance(m, [phi0], [K], k, n_threads)
        if not seg.ok[0]:
            return math.nan, math.nan, phi0
        y, Ky, Mk, adv = float(seg.phi[0]), float(seg.K[0]), seg.M[0], float(seg.advance[0])
    else:
        y, Ky, Mk, adv = phi0, K, np.eye(2), 0.0
    dy = Mk @ v
    need_ak = end == "R1"
    from_r1 = line in ("L1", "L2")
    if need_ak:
        one = T.advance(m, [y], [Ky], 1, n_threads)
        if not one.ok[0]:
            return math.nan, math.nan, phi0
        a_k, d_ak = float(one.advance[0]), (one.M[0] @ dy)[0] - dy[0]
    if winding is None:
        if end == "R0":
            return math.sin(y), math.cos(y) * dy[0], phi0
        u = y + 0.5 * a_k
        return math.sin(u), math.cos(u) * (dy[0] + 0.5 * d_ak), phi0
    Phi_k, dPhi_k = phi0 + adv, dy[0]  # the lifted angle after k steps, from Phi_0 = phi0
    g, dg = 2 * Phi_k - 2 * phi0 - 2 * math.pi * winding, 2 * dPhi_k - 2 * v[0]
    if need_ak:
        g, dg = g + a_k, dg + d_ak
    if from_r1:
        first = T.advance(m, [phi0], [K], 1, n_threads)
        if not first.ok[0]:
            return math.nan, math.nan, phi0
        g, dg = g - float(first.advance[0]), dg - ((first.M[0] @ v)[0] - v[0])
    elif end == "R0":
        g, dg = 0.5 * g, 0.5 * dg  # Phi_k - Phi_0 - pi w
    return g, dg, phi0


def _line_root(m, line, period, K_lo, K_hi, g_lo, g_hi, tol, n_threads, max_iter, winding=None):
    """Safeguarded Newton (bisection where Newton leaves the bracket) for g on [K_lo, K_hi]."""
    a, b, ga = K_lo, K_hi, g_lo
    K = 0.5 * (a + b)
    guess = None
    for _ in range(max_iter):
        g, dg, phi0 = _line_function(m, line, period, K, guess, tol, n_threads, winding)
        if not math.isfinite(g):
            return math.nan, math.nan
        if g == 0:
            return K, phi0
        guess = phi0
        if (g < 0) == (ga < 0):
            a, ga = K, g
        else:
            b = K
        Kn = K - g / dg if dg != 0 and math.isfinite(dg) else 0.5 * (a + b)
        if not (min(a, b) < Kn < max(a, b)):
            Kn = 0.5 * (a + b)
        # Converged when the step or the bracket is below the tolerance or the rounding of K (the
        # polish by the general search measures the orbit's own residual afterwards).
        small = 1e-3 * tol + 8 * np.finfo(float).eps * abs(K)
        if abs(Kn - K) <= small or abs(b - a) <= small:
            return Kn, phi0
        K = Kn
    return math.nan, math.nan


# ------------------------------------------------------------------------------- public functions


def _check_common(m, period, tol, max_iter, n_threads):
    require_map("m", m)
    period = integer("period", period, 1, MAX_PERIOD)
    tol = T.map_tolerance(m) * 10 if tol is None else real_number("tol", tol, lo=0.0)
    max_iter = integer("max_iter", max_iter, 1, 1000)
    n_threads = integer("n_threads", n_threads, 0, 4096)
    return period, tol, max_iter, n_threads


def periodic_orbit(
    m,
    phi,
    K,
    period: int,
    *,
    symmetric: bool = False,
    line: str | None = None,
    K_bracket=None,
    winding: int | None = None,
    tol: float | None = None,
    max_iter: int = 50,
    segment: int | None = None,
    n_threads: int = 0,
) -> PeriodicOrbit:
    """A periodic orbit of period n near (phi, K), by Newton on the n-th return.

    General search: multiple shooting on S segments of m = n / S steps (S = the largest divisor of
    n up to 64, or n / ``segment``): unknowns the segment starts x_i, equations F^m(x_i) = x_{i+1}
    (cyclic), each Newton step one batched iteration of all segments with their Jacobian products
    (in C++) and a dense 2S x 2S solve; damped by halving until the residual drops. Long periods
    stay well conditioned because no segment's product grows like the whole orbit's.

    Symmetric search (``symmetric=True``): on a symmetry line of the reversible map (see the
    module docstring and :data:`LINES`), a 1-D root of g(K) (safeguarded Newton, with the
    bracket ``K_bracket`` if given, else from ``K``), then the general search to polish it and to
    measure the monodromy. Every symmetric orbit of odd period meets Fix(R0) (lines "0" or "pi").

    Parameters
    ----------
    m : TruncatedMap, TruncatedFamily or FlowMap
        The map.
    phi, K : float
        Starting guess (a point of the orbit); for a symmetric search, K is the height on the line
        (phi is used only to choose the line when ``line`` is None: the nearest of "0", "pi", and
        of L1, L2 where the map has them).
    period : int
        n, in [1, 100000].
    symmetric : bool, optional
        Search on a symmetry line (see above).
    line : {"0", "pi", "L1", "L2"}, optional
        The line of a symmetric search.
    K_bracket : (float, float), optional
        Symmetric search: heights on the line between which g changes sign (a bracket makes the
        search certain to converge to the root inside it).
    winding : int, optional
        Symmetric search: the orbit's turns over the period, so its rotation number is
        ``winding / period``: the lifted conditions (see ``_line_function``), whose root on the
        line is that orbit's (unique where the map twists monotonically); without it, any
        symmetric orbit of the period near K.
    tol : float, optional
        Residual tolerance (max norm of F^m(x_i) - x_{i+1}); default 10x the map's accuracy
        (1e-11 for the truncated map, 1e3 rtol for the flow).
    max_iter : int, optional
        Newton iterations at most.
    segment : int, optional
        Steps per multiple-shooting segment (must divide the period; at most 64 segments).
    n_threads : int, optional
        Worker threads of the batched iterations (0: all cores).

    Returns
    -------
    PeriodicOrbit
        With its status (a failed search is a status, never an exception), points, monodromy,
        multipliers, residue, stability, winding and Newton's residual history.

    Raises
    ------
    ValueError
        For a map that is not one, a period outside [1, 100000], non-finite phi or K, a bad tol,
        max_iter, line, bracket or segment, or a ``symmetric`` that is not True or False.

    Examples
    --------
    The standard map (the truncated map above K = 0, with k = eps tau0): its fixed points at
    K = 2 pi - Omega0 have J = [[1, tau0], [eps cos(phi), 1 + eps tau0 cos(phi)]], so residue
    -k cos(phi) / 4: hyperbolic at phi = 0, elliptic at phi = pi.

    >>> import numpy as np, hovering
    >>> sm = hovering.TruncatedMap(eps=0.5, Omega0=0.3, theta_w=2.0)
    >>> po = hovering.periodic_orbit(sm, 0.1, 6.0, 1)
    >>> po.status, abs(float(po.phi[0])) < 1e-12, abs(float(po.K[0]) - (2 * np.pi - 0.3)) < 1e-12
    ('converged', True, True)
    >>> round(po.residue, 12), po.stability, po.residuals.size - 1   # Newton: 3 iterations
    (-0.125, 'hyperbolic', 3)
    >>> hovering.periodic_orbit(sm, 3.0, 6.0, 1).stability
    'elliptic'
    """
    period, tol, max_iter, n_threads = _check_common(m, period, tol, max_iter, n_threads)
    phi = real_number("phi", phi, lo=-1e6, hi=1e6)
    K = real_number("K", K)
    symmetric = flag("symmetric", symmetric)  # 'yes' or 0 would pick a search silently
    if segment is not None:
        segment = integer("segment", segment, 1, period)
    _segments(period, segment)  # the segment check, before any work
    if line is not None and not is_choice(line, LINES):
        raise ValueError(f"line must be one of {list(LINES)}, got {_short(line)}")
    if not symmetric and (line is not None or K_bracket is not None or winding is not None):
        raise ValueError("line, K_bracket and winding are for a symmetric search (symmetric=True)")
    if winding is not None:
        winding = integer("winding", winding, -(2**40), 2**40)
    if symmetric:
        if line is None:
            line = _nearest_line(m, phi, K)
        if K_bracket is not None:
            a, b = (real_number("K_bracket[0]", K_bracket[0]), real_number("K_bracket[1]", K_bracket[1]))
            if not a < b:
                raise ValueError(f"K_bracket must be (lo, hi) with lo < hi, got {K_bracket!r}")
        else:
            a, b = _bracket_around(m, line, period, K, tol, n_threads, winding)
            if not math.isfinite(a):
                return _failed(period, "no_root", Status.OK, [math.inf], 0, line, tol)
        ga = _line_function(m, line, period, a, None, tol, n_threads, winding)[0]
        gb = _line_function(m, line, period, b, None, tol, n_threads, winding)[0]
        if not (math.isfinite(ga) and math.isfinite(gb)) or (ga < 0) == (gb < 0):
            return _failed(period, "no_root", Status.OK, [math.inf], 0, line, tol)
        K0, phi0 = _line_root(m, line, period, a, b, ga, gb, tol, n_threads, max_iter, winding)
        if not math.isfinite(K0):
            return _failed(period, "no_root", Status.OK, [math.inf], 0, line, tol)
        phi, K = phi0, K0
    # The guess's orbit seeds the segments.
    m_steps, S = _segments(period, segment)
    seed, res = T.advance(m, [phi], [K], period, n_threads, orbit=True)
    if not seed.ok[0] and np.isnan(res.phi[0, -1]):
        pass
    idx = np.arange(S) * m_steps
    p0, k0 = res.phi[0, idx], res.K[0, idx]
    if not (np.all(np.isfinite(p0)) and np.all(np.isfinite(k0))):
        return _failed(period, "step_failed", _first_bad(seed.status), [math.inf], 0, line, tol)
    p, k, status, step_status, hist, it = _newton(m, p0, k0, period, tol, max_iter, segment, n_threads)
    if status == "step_failed":
        return _failed(period, status, step_status, hist, it, line, tol)
    orbit = _finish(m, float(p[0]), float(k[0]), period, status, step_status, hist, it, line, tol, n_threads)
    return orbit


def _nearest_line(m, phi, K) -> str:
    cands = {"0": 0.0, "pi": math.pi}
    try:
        cands["L1"] = float(m.L1(K))
        cands["L2"] = float(m.L2(K))
    except (ValueError, AttributeError):
        pass
    return min(cands, key=lambda n: abs(float(wrap(phi - cands[n]))))


def _bracket_around(m, line, period, K, tol, n_threads, winding=None):
    """A bracket of g around K: steps out geometrically from K until g changes sign."""
    lo, hi = m.valid_band()
    g0 = _line_function(m, line, period, K, None, tol, n_threads, winding)[0]
    if not math.isfinite(g0):
        return math.nan, math.nan
    d = 1e-3 * max(1.0, abs(K))
    for _ in range(12):
        for s in (-1.0, 1.0):
            x = K + s * d
            if not lo < x < hi:
                continue
            g = _line_function(m, line, period, x, None, tol, n_threads, winding)[0]
            if math.isfinite(g) and (g < 0) != (g0 < 0):
                return (x, K) if s < 0 else (K, x)
        d *= 2
    return math.nan, math.nan


@dataclass(frozen=True, repr=False)
class PeriodicOrbits(Summarized, Saveable):
    """The periodic orbits of one period found in a box (:func:`periodic_orbits`).

    Attributes
    ----------
    orbits : list of PeriodicOrbit
        The distinct converged orbits of minimal period ``period`` with a point in the box (each
        once), sorted by their lowest K.
    period : int
        The period searched.
    region : tuple
        ``((phi_lo, phi_hi), (K_lo, K_hi))``.
    seeds : int
        Newton starts of the general search (a ``n_seeds x n_seeds`` grid).
    line_roots : int
        Roots found by the scans of the symmetry lines.
    failed : int
        Searches that did not converge (their statuses are not kept; see ``failed_statuses``).
    failed_statuses : dict
        Count of each failure status.
    """

    orbits: list
    period: int
    region: tuple
    seeds: int
    line_roots: int
    failed: int
    failed_statuses: dict = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.orbits)

    def __iter__(self):
        return iter(self.orbits)

    def __getitem__(self, i) -> PeriodicOrbit:
        return self.orbits[i]

    @property
    def residues(self) -> np.ndarray:
        """Residue of each orbit."""
        return np.array([o.residue for o in self.orbits])

    def _summary(self) -> list:
        kinds: dict = {}
        for o in self.orbits:
            kinds[o.stability] = kinds.get(o.stability, 0) + 1
        return [
            ("period", self.period),
            ("orbits", len(self.orbits)),
            ("stability", kinds),
            ("seeds", self.seeds),
            ("line_roots", self.line_roots),
            ("failed", self.failed),
        ]


def _in_box(o, box) -> bool:
    (a, b), (c, d) = box
    phi_ok = (b - a >= 2 * math.pi) | _angle_in(o.phi, a, b)
    return bool(np.any(phi_ok & (o.K >= c) & (o.K <= d)))


def _angle_in(phi, a, b):
    return wrap(np.asarray(phi) - a) <= (b - a) if b - a < 2 * math.pi else np.ones(np.shape(phi), dtype=bool)


def periodic_orbits(
    m,
    period: int,
    region=None,
    *,
    n_seeds: int = 6,
    lines=LINES,
    n_line: int = 64,
    tol: float | None = None,
    max_iter: int = 50,
    n_threads: int = 0,
) -> PeriodicOrbits:
    """All periodic orbits of one period found in a box: symmetric ones by scanning the symmetry
    lines for sign changes, the others by Newton from a grid of seeds.

    The seeding, stated: (1) along each line of ``lines`` crossing the box, g (see
    :func:`periodic_orbit`) is sampled at ``n_line`` heights of the box; every sign change is a
    bracket, refined on the line and polished by the general search; (2) Newton's general search
    starts from each point of an ``n_seeds x n_seeds`` grid of the box. Converged orbits with a
    point in the box are kept once each (an orbit found twice, from any of its points, is one). A
    symmetric orbit whose crossing of the lines lies in the box between two samples that g does not
    separate, or a non-symmetric orbit whose basin holds no seed, can be missed: more samples or
    seeds find more.

    Parameters
    ----------
    m : TruncatedMap, TruncatedFamily or FlowMap
        The map.
    period : int
        The period n.
    region : ((float, float), (float, float)), optional
        ``((phi_lo, phi_hi), (K_lo, K_hi))``; default the whole circle and the map's band (at most
        [-1, 1]).
    n_seeds : int, optional
        Grid of the general search per side (0: none, symmetric orbits only).
    lines : sequence of str, optional
        Symmetry lines to scan (default all of :data:`LINES`, L1 and L2 where the map has them;
        ``()``: none). Odd periods need only "0" and "pi"; even ones also L1 and L2.
    n_line : int, optional
        Samples per line.
    tol, max_iter, n_threads
        As :func:`periodic_orbit`.

    Returns
    -------
    PeriodicOrbits

    Raises
    ------
    ValueError
        For a bad period, region, count or line.

    Examples
    --------
    >>> import hovering
    >>> sm = hovering.TruncatedMap(eps=0.5, Omega0=0.3, theta_w=2.0)
    >>> found = hovering.periodic_orbits(sm, 1, region=((-3.2, 3.2), (5.0, 7.0)), n_seeds=3)
    >>> sorted(o.stability for o in found)     # the standard map's two fixed points
    ['elliptic', 'hyperbolic']
    """
    period, tol, max_iter, n_threads = _check_common(m, period, tol, max_iter, n_threads)
    n_seeds = integer("n_seeds", n_seeds, 0, 1000)
    n_line = integer("n_line", n_line, 2, 100_000)
    lines = tuple(lines)
    for ln in lines:
        if not is_choice(ln, LINES):
            raise ValueError(f"lines: each must be one of {list(LINES)}, got {_short(ln)}")
    lo, hi = m.valid_band()
    if region is None:
        region = ((-math.pi, math.pi), (max(lo, -1.0), min(hi, 1.0)))
    try:
        (a, b), (c, d) = region
    except (TypeError, ValueError):
        raise ValueError(f"region must be ((phi_lo, phi_hi), (K_lo, K_hi)), got {_short(region)}") from None
    a, b = real_number("region phi_lo", a), real_number("region phi_hi", b)
    c, d = real_number("region K_lo", c), real_number("region K_hi", d)
    if not (a < b and c < d):
        raise ValueError(f"region must have phi_lo < phi_hi and K_lo < K_hi, got {region!r}")
    box = ((a, b), (c, d))
    found: list[PeriodicOrbit] = []
    failed: dict = {}
    roots = 0

    def keep(o):
        if not o.converged:
            failed[o.status] = failed.get(o.status, 0) + 1
            return
        if o.minimal_period != period or not _in_box(o, box):
            return
        for f in found:
            if f.same_orbit(o, tol=max(1e-7, 1e3 * tol)):
                return
        found.append(o)

    Kc = np.linspace(max(c, lo + 1e-12), min(d, hi - 1e-12), n_line)
    for ln in lines:
        if ln in ("L1", "L2"):
            try:
                getattr(m, ln)(0.0)
            except (ValueError, AttributeError):
                continue  # no onset model for the flow's lines: those lines are not scanned
        g = np.array([_line_function(m, ln, period, float(k), None, tol, n_threads)[0] for k in Kc])
        for i in range(n_line - 1):
            if not (math.isfinite(g[i]) and math.isfinite(g[i + 1])) or (g[i] < 0) == (g[i + 1] < 0):
                continue
            o = periodic_orbit(
                m, 0.0, 0.5 * (Kc[i] + Kc[i + 1]), period, symmetric=True, line=ln,
                K_bracket=(Kc[i], Kc[i + 1]), tol=tol, max_iter=max_iter, n_threads=n_threads,
            )  # fmt: skip
            if o.converged:
                roots += 1
            keep(o)
    if n_seeds:
        for ph in np.linspace(a, b, n_seeds + 2)[1:-1]:
            for k in np.linspace(c, d, n_seeds + 2)[1:-1]:
                keep(periodic_orbit(m, float(ph), float(k), period, tol=tol, max_iter=max_iter, n_threads=n_threads))
    found.sort(key=lambda o: float(np.min(o.K)))
    return PeriodicOrbits(
        orbits=found,
        period=period,
        region=box,
        seeds=n_seeds * n_seeds,
        line_roots=roots,
        failed=sum(failed.values()),
        failed_statuses=failed,
    )
