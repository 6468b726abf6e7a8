"""Greene's residue criterion: whether the invariant circle of a rotation number exists, from the
residues of the periodic orbits whose rotation numbers are its continued-fraction convergents.

For an irrational rotation nu with convergents p_k / q_k, the symmetric orbits of rotation
p_k / q_k approach the circle of rotation nu (if it exists) or its cantorus. Greene (1979): their
residues R_k tend to 0 when the circle exists, grow without bound when it does not, and at the
critical parameter tend to a universal value (R ~ 0.25 for the elliptic orbits of the golden mean,
the standard map's k_c = 0.971635...). So the parameter at which R_k crosses 1/4, for growing
q_k, converges to the critical one.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._checks import _short, integer, is_choice, real_number
from .._display import Summarized
from .._io.serial import Saveable
from ..interface import require_map
from . import periodic as P

__all__ = ["convergents", "symmetric_orbit", "GreeneResidues", "greene_residues", "GreeneCritical", "greene_critical"]

#: The golden mean's reciprocal (sqrt 5 - 1) / 2: the rotation of the most robust circle.
GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


def convergents(x: float, n: int) -> list[tuple[int, int]]:
    """The first n continued-fraction convergents p / q of x (q > 0), from its integer part on.

    Parameters
    ----------
    x : float
        A real number.
    n : int
        How many.

    Returns
    -------
    list of (int, int)

    Examples
    --------
    >>> import hovering
    >>> hovering.dynamics.convergents(0.6180339887498949, 6)
    [(0, 1), (1, 1), (1, 2), (2, 3), (3, 5), (5, 8)]
    """
    x = real_number("x", x)
    n = integer("n", n, 1, 90)
    out, (p0, q0), (p1, q1) = [], (1, 0), (int(math.floor(x)), 1)
    out.append((p1, q1))
    r = x - math.floor(x)
    while len(out) < n and r > 1e-15:
        a = int(math.floor(1.0 / r))
        r = 1.0 / r - a
        p0, q0, p1, q1 = p1, q1, a * p1 + p0, a * q1 + q0
        out.append((p1, q1))
    return out


def symmetric_orbit(
    m, p: int, q: int, line: str, K_range, *, n_samples: int = 24, K_guess=None, tol=None, n_threads: int = 0
):
    """The symmetric periodic orbit of rotation p / q (winding p over period q) through a symmetry
    line, found where its lifted condition changes sign among ``n_samples`` heights of
    ``K_range`` on the line (monotone where the map twists: one root; where it does not, the sign
    change nearest ``K_guess``, default the middle of the range).

    Returns
    -------
    PeriodicOrbit
        With status ``"no_root"`` if g does not change sign on the range.
    """
    require_map("m", m)
    q = integer("q", q, 1, P.MAX_PERIOD)
    p = integer("p", p, -(2**40), 2**40)
    if not is_choice(line, P.LINES):
        raise ValueError(f"line must be one of {list(P.LINES)}, got {_short(line)}")
    a, b = (real_number("K_range[0]", K_range[0]), real_number("K_range[1]", K_range[1]))
    tol = 10 * P.T.map_tolerance(m) if tol is None else tol
    Ks = np.linspace(a, b, integer("n_samples", n_samples, 2, 10_000))
    g = np.array([P._line_function(m, line, q, float(k), None, tol, n_threads, p)[0] for k in Ks])
    sign = [
        i
        for i in range(Ks.size - 1)
        if math.isfinite(g[i]) and math.isfinite(g[i + 1]) and (g[i] < 0) != (g[i + 1] < 0)
    ]
    guess = 0.5 * (a + b) if K_guess is None else K_guess
    sign.sort(key=lambda i: abs(0.5 * (Ks[i] + Ks[i + 1]) - guess))
    if sign:
        i = sign[0]
        return P.periodic_orbit(
            m, 0.0, float(Ks[i]), q, symmetric=True, line=line, K_bracket=(float(Ks[i]), float(Ks[i + 1])),
            winding=p, tol=tol, n_threads=n_threads,
        )  # fmt: skip
    return P._failed(q, "no_root", P.Status.OK, [math.inf], 0, line, tol)


@dataclass(frozen=True, repr=False)
class GreeneResidues(Summarized, Saveable):
    """Residues of the convergents' symmetric orbits (:func:`greene_residues`).

    Attributes
    ----------
    rotation : float
        The rotation number nu (turns per step).
    p, q : ndarray of int
        The convergents used.
    residues : ndarray
        ``(n, len(lines))``: the residue of the orbit of rotation p / q on each line (NaN where
        none was found).
    lines : tuple of str
        The symmetry lines searched.
    K : ndarray
        ``(n, len(lines))``: the orbit's height on the line.
    verdict : str
        ``"exists"`` (the last residues fall towards 0), ``"destroyed"`` (they grow past 1),
        ``"critical"`` (they stay near the universal 0.25) or ``"undecided"``.
    """

    rotation: float
    p: np.ndarray
    q: np.ndarray
    residues: np.ndarray
    lines: tuple
    K: np.ndarray
    verdict: str

    def _summary(self) -> list:
        last = self.residues[-1] if self.residues.size else []
        return [
            ("rotation", f"{self.rotation:.10g}"),
            ("periods", f"{int(self.q[0])}..{int(self.q[-1])}" if self.q.size else "-"),
            ("last residues", ", ".join(f"{r:.4g}" for r in last)),
            ("verdict", self.verdict),
        ]


def _verdict(R: np.ndarray) -> str:
    r = np.abs(R[np.isfinite(R)])
    if r.size < 3:
        return "undecided"
    tail = r[-3:]
    if tail[-1] < 0.05 and tail[-1] < tail[0]:
        return "exists"
    if tail[-1] > 1.0 and tail[-1] > tail[0]:
        return "destroyed"
    if np.all((tail > 0.1) & (tail < 0.5)):
        return "critical"
    return "undecided"


def greene_residues(
    m,
    rotation: float,
    K_range,
    *,
    min_period: int = 2,
    max_period: int = 1000,
    lines=("0", "pi"),
    n_samples: int = 24,
    tol=None,
    n_threads: int = 0,
) -> GreeneResidues:
    """Residues of the symmetric periodic orbits whose rotations are the convergents of ``rotation``.

    Parameters
    ----------
    m : TruncatedMap, TruncatedFamily or FlowMap
        The map.
    rotation : float
        The invariant circle's rotation number, in turns per step with its integer part (e.g. a
        :func:`hovering.critical_curve` rotation divided by 2 pi): the convergents p / q give
        the orbits of winding p over period q.
    K_range : (float, float)
        Heights on the lines between which the orbits are searched (the circle's neighbourhood).
    min_period, max_period : int, optional
        The convergents' periods used.
    lines : sequence of str, optional
        Symmetry lines (:data:`hovering.dynamics.LINES`); the default Fix(R0) lines hold one point
        of every symmetric orbit of odd period.
    n_samples, tol, n_threads
        As :func:`symmetric_orbit`.

    Returns
    -------
    GreeneResidues

    Examples
    --------
    The standard map below and above Greene's k_c = 0.9716 (golden circle, rotation 0.618):

    >>> import hovering
    >>> from hovering.dynamics import greene_residues, GOLDEN
    >>> below = hovering.TruncatedMap(eps=0.9, Omega0=0.0, theta_w=2.0)
    >>> greene_residues(below, GOLDEN, (2.5, 5.5), min_period=13, max_period=233).verdict
    'exists'
    >>> above = hovering.TruncatedMap(eps=1.05, Omega0=0.0, theta_w=2.0)
    >>> greene_residues(above, GOLDEN, (2.5, 5.5), min_period=13, max_period=233).verdict
    'destroyed'
    """
    require_map("m", m)
    rotation = real_number("rotation", rotation)
    min_period = integer("min_period", min_period, 1, P.MAX_PERIOD)
    max_period = integer("max_period", max_period, min_period, P.MAX_PERIOD)
    lines = tuple(lines)
    for ln in lines:
        if not is_choice(ln, P.LINES):
            raise ValueError(f"lines: each must be one of {list(P.LINES)}, got {_short(ln)}")
    cv = [(p, q) for p, q in convergents(rotation, 90) if min_period <= q <= max_period]
    R = np.full((len(cv), len(lines)), np.nan)
    Kh = np.full((len(cv), len(lines)), np.nan)
    for i, (p, q) in enumerate(cv):
        for j, ln in enumerate(lines):
            o = symmetric_orbit(m, p, q, ln, K_range, n_samples=n_samples, tol=tol, n_threads=n_threads)
            if o.converged and o.minimal_period == q:
                R[i, j], Kh[i, j] = o.residue, float(o.K[0])
    # the verdict from the elliptic orbits (positive residues: the dominant line's)
    pos = np.where(R > 0, R, np.nan)
    best = pos[:, int(np.argmax(np.sum(np.isfinite(pos), axis=0)))] if pos.size else np.array([])
    return GreeneResidues(
        rotation=rotation,
        p=np.array([p for p, _ in cv], dtype=np.int64),
        q=np.array([q for _, q in cv], dtype=np.int64),
        residues=R,
        lines=lines,
        K=Kh,
        verdict=_verdict(best),
    )


@dataclass(frozen=True, repr=False)
class GreeneCritical(Summarized, Saveable):
    """The parameter where each convergent's residue crosses the criterion (:func:`greene_critical`).

    Attributes
    ----------
    q : ndarray of int
        The convergents' periods.
    parameter : ndarray
        For each q, the parameter at which the residue of its orbit equals ``target``.
    estimate : float
        The last of them: Greene's estimate of the critical parameter.
    error : float
        |difference of the last two| (their convergence, geometric in q).
    target : float
        The residue value of the criterion (1/4).
    line : str
        The symmetry line of the orbits used.
    """

    q: np.ndarray
    parameter: np.ndarray
    estimate: float
    error: float
    target: float
    line: str

    def _summary(self) -> list:
        return [
            ("periods", f"{int(self.q[0])}..{int(self.q[-1])}" if self.q.size else "-"),
            ("estimate", f"{self.estimate:.8g}"),
            ("error", f"{self.error:.2g}"),
        ]


def greene_critical(
    m,
    rotation: float,
    bracket,
    K_range,
    *,
    family: Callable | None = None,
    min_period: int = 5,
    max_period: int = 400,
    line: str = "pi",
    target: float = 0.25,
    xtol: float = 1e-10,
    n_threads: int = 0,
) -> GreeneCritical:
    """The critical parameter of the circle of a rotation number by Greene's criterion: for each
    convergent's orbit, the parameter where its residue equals ``target`` (1/4), by safeguarded
    secant steps in the parameter; the sequence converges to the critical value as q grows.

    Parameters
    ----------
    m : map
        The map at some parameter (only ``family`` matters for the values).
    rotation : float
        The circle's rotation number (turns per step).
    bracket : (float, float)
        Parameters between which every convergent's residue crosses ``target`` (a convergent
        whose orbit is not found at both ends, e.g. too unstable far above the critical value, is
        left out: keep the bracket close).
    K_range : (float, float)
        Heights on the line where the orbits are searched.
    family : callable, optional
        p -> map (default ``m.with_eps``).
    min_period, max_period : int, optional
        The convergents used.
    line : str, optional
        The line of the orbits (the one holding the elliptic orbits: ``"pi"`` for the truncated
        map's standard-map part, where ``Kbar = K + eps sin(phibar)``).
    target : float, optional
        The criterion's residue.
    xtol : float, optional
        Tolerance in the parameter.
    n_threads : int, optional
        Worker threads.

    Returns
    -------
    GreeneCritical

    Examples
    --------
    >>> import hovering
    >>> from hovering.dynamics import greene_critical, GOLDEN
    >>> sm = hovering.TruncatedMap(eps=1.0, Omega0=0.0, theta_w=2.0)
    >>> gc = greene_critical(sm, GOLDEN, (0.95, 1.0), (2.5, 5.5), min_period=89, max_period=233)
    >>> gc.q.tolist(), round(gc.estimate, 4)
    ([89, 144, 233], 0.9716)
    """
    require_map("m", m)
    family = m.with_eps if family is None else family
    if not callable(family):
        raise ValueError(f"family must be a callable p -> map, got {_short(family)}")
    a, b = real_number("bracket[0]", bracket[0]), real_number("bracket[1]", bracket[1])
    if not a < b:
        raise ValueError(f"bracket must be (lo, hi) with lo < hi, got {bracket!r}")
    target = real_number("target", target)
    min_period = integer("min_period", min_period, 1, P.MAX_PERIOD)
    max_period = integer("max_period", max_period, min_period, P.MAX_PERIOD)
    cv = [(p, q) for p, q in convergents(real_number("rotation", rotation), 90) if min_period <= q <= max_period]

    last_K: dict = {}

    def residue(p, q, par):
        # The orbit moves little with the parameter: search near where it was last (8 samples of
        # +-0.2), the whole K_range otherwise.
        # The orbit is followed in the parameter: searched within +-0.05 of where it was (its height
        # on the line moves ~0.007 over the bracket of the standard map's golden orbits), the
        # root nearest that height: the same orbit, not another of the same rotation.
        guess = last_K.get(q)
        if guess is None:
            o = symmetric_orbit(family(par), p, q, line, K_range, n_threads=n_threads)
        else:
            o = symmetric_orbit(family(par), p, q, line, (guess - 0.05, guess + 0.05), n_samples=11,
                                K_guess=guess, n_threads=n_threads)  # fmt: skip
        if not o.converged:
            return math.nan
        last_K[q] = float(o.K[0])
        return o.residue - target

    qs, pars = [], []
    for p, q in cv:
        lo, hi = a, b
        flo, fhi = residue(p, q, lo), residue(p, q, hi)
        if not (math.isfinite(flo) and math.isfinite(fhi)) or (flo < 0) == (fhi < 0):
            continue
        x = lo
        for _ in range(200):
            # secant inside the bracket (Illinois-like halving of the stale end's value)
            x = hi - fhi * (hi - lo) / (fhi - flo) if fhi != flo else 0.5 * (lo + hi)
            if not lo < x < hi:
                x = 0.5 * (lo + hi)
            fx = residue(p, q, x)
            if not math.isfinite(fx):
                x = 0.5 * (lo + hi)
                fx = residue(p, q, x)
                if not math.isfinite(fx):
                    break
            if (fx < 0) == (flo < 0):
                lo, flo = x, fx
                fhi *= 0.5
            else:
                hi, fhi = x, fx
                flo *= 0.5
            if hi - lo <= xtol or fx == 0:
                break
        qs.append(q)
        pars.append(x)
    pars = np.array(pars)
    return GreeneCritical(
        q=np.array(qs, dtype=np.int64),
        parameter=pars,
        estimate=float(pars[-1]) if pars.size else math.nan,
        error=float(abs(pars[-1] - pars[-2])) if pars.size >= 2 else math.nan,
        target=target,
        line=line,
    )
