"""The critical invariant curve: the lowest invariant curve inside a set of no-impact regions,
searched along L1 (or L2), next to the leading-order predictions (eq:kcrit, eq:rhocrit, and
:func:`hovering.theory` for every Omega0 and forcing). Works on any map: truncated or the flow.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .._checks import is_choice, real_array
from .._deprecated import renamed_keywords
from .._display import Summarized
from .._enums import REGION_LABELS, Region, Status, region_mask
from .._io.serial import Saveable
from .._progress import check_progress, progress_bar
from ..curve import Curve
from ..interface import require_map
from .rotation import regularity, rotation_number

__all__ = ["CriticalCurve", "critical_curve", "max_angular_gap"]


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


@dataclass(frozen=True, repr=False)
class CriticalCurve(Summarized, Saveable):
    """The lowest invariant curve inside a set of no-impact regions (see :func:`critical_curve`).

    Attributes
    ----------
    K0 : float
        Height where the critical orbit starts on the search line (L1 or L2).
    K_min, K_max : float
        Lowest and highest K along the critical orbit (the curve's extent).
    rotation : float
        Weighted Birkhoff rotation number of the critical orbit.
    rotation_mean : float
        The paper's rho = <omega_a> of the same orbit.
    digits : float
        Regularity of the orbit (see :func:`regularity`).
    K_pred, rotation_pred : float
        Leading-order predictions of the curve's height on its search line and its rotation
        (eq:kcrit and eq:rhocrit in the hovering case; for the other sign the curve k^{u0}, whose
        rotation the first-order theory gives only through its mean height).
    K_fail : float
        Highest tested start below K0 whose orbit impacts or is not regular (bracket of K0).
    line : str
        The search line ("L1" or "L2").
    hovers : bool
        Whether these parameters hover (:class:`hovering.Theory`); if not, the curve found is the
        lowest invariant curve avoiding impacts, k^{u0}, not a hovering critical curve.
    note : str
        The theory's explanation (sign of eps b_1 sin(Omega0/2), vanishing modes, resonance, geometry).
    phi, K : ndarray
        The critical orbit.

    Examples
    --------
    At the sign of eps that does not hover the search moves to L2 and finds k^{u0}, the lowest
    curve that avoids the impacts:

    >>> import numpy as np, hovering
    >>> m = hovering.TruncatedMap(eps=-0.3, Omega0=hovering.OMEGA_G, theta_w=3 * np.pi / 4)
    >>> cc = hovering.critical_curve(m, n_steps=2000)
    >>> cc.hovers, cc.line, cc.note.split(":")[0]
    (False, 'L2', 'impacting case')
    >>> bool(cc.K_min >= 0), cc.phi.shape      # k^{u0} lies in K >= 0; the orbit: n_steps + 1 points
    (True, (2001,))
    >>> c = cc.curve                           # the orbit as a closed curve K(phi)
    >>> bool(abs(c(float(cc.phi[0])) - cc.K[0]) < 1e-3)
    True
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
    K_max: float = float("nan")
    line: str = "L1"
    hovers: bool = True
    note: str = ""

    @property
    def curve(self) -> Curve:
        """The critical orbit as a closed curve K(phi) (:meth:`hovering.Curve.from_orbit`; its
        ``error`` is the orbit's scatter about the curve, per bin).

        Raises
        ------
        ValueError
            If the orbit does not fill the circle at the default resolution (too few points).
        """
        return Curve.from_orbit(self.phi, self.K)

    def _summary(self) -> list:
        return [
            ("K0", self.K0),
            ("K_pred", self.K_pred),
            ("K_min", self.K_min),
            ("K_max", self.K_max),
            ("rotation", self.rotation),
            ("rotation_pred", self.rotation_pred),
            ("digits", self.digits),
            ("line", self.line),
            ("hovers", self.hovers),
            ("points", len(self.phi)),
        ]

    def to_xarray(self):
        """The curve as an :class:`xarray.Dataset` (needs ``hovering[xarray]``): the critical orbit
        ``phi``, ``K`` over dimension ``point``, the numbers as scalar variables, units, ``line``,
        ``hovers``, ``note`` and provenance in attrs.

        Returns
        -------
        xarray.Dataset

        Raises
        ------
        ImportError
            Without xarray, naming ``pip install 'hovering[xarray]'``.
        """
        from .._io.interop import critical_curve_dataset

        return critical_curve_dataset(self)


@renamed_keywords(grid="n_grid")
def critical_curve(
    m,
    n_steps: int = 20_000,
    K_range: Sequence[float] | None = None,
    regions=("0u", "0"),
    line=None,
    n_grid: int = 64,
    digits: float | None = None,
    tol: float = 1e-6,
    n_threads: int = 0,
    search: str = "lowest",
    progress=False,
) -> CriticalCurve:
    """Search the lowest invariant curve that stays in ``regions``, along the line L1 (or L2).

    A start ``(L(K), K)`` passes when its orbit stays in ``regions`` for ``n_steps``, its
    weighted Birkhoff rotation number agrees over the two halves of the orbit to ``digits``
    digits (quasi-periodic), and it fills the circle: its largest gap in phi is below 20 times the
    mean spacing ``2 pi / n_steps`` (a rotational invariant curve; an island chain of period p
    leaves gaps ~ 2 pi / p). The lowest passing start of a grid over ``K_range`` is then refined
    by bisection against the grid point below it.

    Where the parameters do not hover (``eps b_1 sin(Omega0/2) < 0`` for a forcing ``b_1 sin + ...``,
    at every Omega0: the sign of eps that hovers is ``sign(sin(Omega0/2) b_1)``, of period 4 pi in
    Omega0; thm:hovering) the lowest curve avoiding impacts is k^{u0}, with its minimum near L2 at
    K >= 0: the default search moves to L2 and the result says ``hovers=False`` with the reason in
    ``note`` (:meth:`theory` of the map decides, :class:`hovering.Theory`).

    Parameters
    ----------
    m : TruncatedMap, TruncatedFamily or FlowMap
        The map.
    n_steps : int, optional
        Iterates per tested orbit (>= 16).
    K_range : (float, float), optional
        Heights searched. Default: from 3 times the predicted critical height (or ``-2 |eps| /
        |sin(Omega0/2)|`` when none is predicted; ``-|eps| / (4 |sin(Omega0/2)|)`` where the sign of
        eps does not hover, whose curve k^{u0} crosses L2 at K >= 0) up to ``|eps| /
        |sin(Omega0/2)|``, clipped strictly inside the band (a ValueError names it if that leaves
        nothing).
    regions : iterable, optional
        The no-impact set: ``("0u", "0")`` for the hovering critical curve, ``("0u",)`` for the
        curve k^{u0} (lowest curve in K >= 0).
    line : {"L1", "L2"} or float, optional
        Search line. Default: L1 in the hovering case, L2 otherwise (minima of the curves lie near
        L1 when ``eps b_1 sin(Omega0/2) > 0``, near L2 otherwise: thm:minmaxinvriantcurves). A number
        is a vertical line phi = line (any rotational invariant curve crosses it once).
    n_grid : int, optional
        Grid points of the first scan (>= 2). Formerly ``grid=`` (deprecated, still accepted with a
        DeprecationWarning).
    digits : float, optional
        Regularity threshold, in (0, 16]. Default: the map's ``regularity_digits`` (8 for the
        truncated maps, exact to rounding; 6 for the flow, whose per-return integration error
        limits the agreement of the two half-orbit averages on an invariant curve to 7-9 digits
        at rtol 1e-10, where chaotic orbits give 2-4).
    tol : float, optional
        Bisection tolerance on K0, > 0 (at least 1e-14 times the scale of K0).
    n_threads : int, optional
        Worker threads for the scan.
    search : {"lowest", "highest"}, optional
        ``"lowest"``: the lowest passing start (the floor of a no-impact region above the impacts,
        as the hovering critical curve). ``"highest"``: the highest passing start (the roof of a
        no-impact region under the impacts, as the flow's lower boundary of the impact zone).
    progress : bool or callable, optional
        One report for the whole search (grid scan, bisection, final orbit; its total, fixed up
        front from the grid spacing and ``tol``, is corrected at the end if the bisection was
        shorter): ``True`` a tqdm bar on stderr, a callable ``progress(done, total)``, ``False``
        (default) none.

    Returns
    -------
    CriticalCurve

    Raises
    ------
    ValueError
        For bad arguments (named, with the allowed range).
    RuntimeError
        If no start in ``K_range`` passes (no invariant curve found: widen the range); the message
        says when the sign of eps does not hover.

    Examples
    --------
    The paper's map at eps = 0.3, against eq:kcrit and eq:rhocrit (the docs' numbers use the
    default ``n_steps=20_000``):

    >>> import numpy as np, hovering
    >>> m = hovering.TruncatedMap(eps=0.3, Omega0=hovering.OMEGA_G, theta_w=3 * np.pi / 4)
    >>> cc = hovering.critical_curve(m, n_steps=5000)
    >>> cc.hovers, cc.line
    (True, 'L1')
    >>> round(cc.K_pred, 4), round(cc.rotation_pred, 4)
    (-0.2747, 3.7694)
    >>> bool(abs(cc.K_min - cc.K_pred) < 0.01), bool(abs(cc.rotation - cc.rotation_pred) < 0.02)
    (True, True)
    """
    progress = check_progress(progress)
    th = require_map("m", m).theory()
    try:
        mask = region_mask(regions)
    except ValueError as e:
        raise ValueError(f"regions: {e}") from None
    if mask == 0:
        raise ValueError(f"regions must name at least one region, got {regions!r}")
    regions = tuple(REGION_LABELS[r] for r in range(5) if mask >> r & 1)  # labels, in the paper's order
    hover_search = bool(mask >> int(Region.ABOVE) & 1)
    if line is None:
        line = "L2" if hover_search and not th.hovers and m.eps != 0 else "L1"
    if not is_choice(search, ("lowest", "highest")):
        raise ValueError(f"search must be 'lowest' or 'highest', got {search!r}")
    if isinstance(line, (int, float, np.floating)) and not isinstance(line, bool) and math.isfinite(line):
        phi_line = float(line)
        line = f"phi = {phi_line:g}"
        line_fn = lambda K: np.full(np.shape(K), phi_line)  # noqa: E731
    elif is_choice(line, ("L1", "L2")):
        line_fn = m.L1 if line == "L1" else m.L2
    else:
        raise ValueError(f"line must be 'L1', 'L2' or a finite angle, got {line!r}")
    if digits is None:
        digits = getattr(m, "regularity_digits", 8.0)
    # n_grid <= 1e6: more starts than that resolve nothing the bisection does not (and cost memory).
    grid = n_grid
    for name, v, least, most in (("n_steps", n_steps, 16, 2**53), ("n_grid", grid, 2, 10**6)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not least <= v <= most:
            raise ValueError(f"{name} must be an integer in [{least}, {most}], got {v!r}")
    if not (isinstance(digits, (int, float, np.floating)) and 0 < digits <= 16):
        raise ValueError(f"digits must be a number in (0, 16], got {digits!r}")
    lo, hi = m.valid_band()
    s = abs(math.sin(0.5 * th.Omega0))
    scale = abs(m.eps) * max(abs(b) for b in th.forcing) / max(s, 1e-3)
    if K_range is None:
        # Hovering: the critical curve dips to ~K_crit < 0 near L1. Otherwise the lowest curve
        # avoiding impacts is k^{u0}, crossing L2 at K >= 0: a start far below 0 would find the
        # tori under the impact zone (a curve under its floor), so the search starts just below 0.
        K_a = 3 * th.K_crit if th.hovers and th.K_crit < 0 else (-2 * scale if th.hovers else -0.25 * scale)
        K_b = max(scale, 1e-6)
        # strictly inside the band (its edges are refused below: the map is not defined past them)
        pad = 1e-6 * min(hi - lo, 1.0)
        K_a, K_b = min(max(K_a, lo + pad), hi - pad), min(max(K_b, lo + pad), hi - pad)
        if not K_a < K_b:
            raise ValueError(
                f"the default K_range ({K_a:.6g}, {K_b:.6g}) is empty inside the band ({lo}, {hi}) "
                f"at eps = {m.eps} (the predicted heights lie outside it): pass K_range"
            )
        K_range = (K_a, K_b)
    kr = real_array("K_range", K_range) if not isinstance(K_range, str) else None
    if kr is None or kr.shape != (2,):
        raise ValueError(f"K_range must be a pair (K_lo, K_hi), got {K_range!r}")
    K_a, K_b = map(float, kr)
    K_range = (K_a, K_b)
    if not (lo < K_a < K_b < hi):
        raise ValueError(f"K_range must be increasing inside the band ({lo}, {hi}), got {K_range}")
    if not (
        isinstance(tol, (int, float, np.floating)) and math.isfinite(tol) and tol >= 1e-14 * max(abs(K_a), abs(K_b))
    ):
        raise ValueError(
            f"tol must be finite and >= 1e-14 x the scale of K_range ({1e-14 * max(abs(K_a), abs(K_b)):.3g}), "
            f"got {tol!r}"
        )
    flow = hasattr(m, "step_rotations")
    record = ("orbit", "regions") if flow else ("orbit",)
    # Work of the whole search: the grid, the bisection from one grid spacing down to tol, the final orbit.
    spacing = (K_b - K_a) / (grid - 1)
    n_bisect = max(0, math.ceil(math.log2(spacing / tol))) if spacing > tol else 0
    with progress_bar(
        progress, (grid + n_bisect + 1) * n_steps, desc="critical_curve", unit=getattr(m, "_progress_unit", "step")
    ) as bar:
        done = 0

        def test(K0s):
            nonlocal done
            K0s = np.atleast_1d(np.asarray(K0s, dtype=float))
            res = m.iterate(
                line_fn(K0s),
                K0s,
                n_steps,
                record=record,
                exit_regions=regions,
                stop_on_exit=True,
                n_threads=n_threads,
                progress=bar.part(done),
            )
            done += K0s.size * n_steps
            stayed = res.status == Status.OK
            dig = np.where(stayed, regularity(res), 0.0)
            circle = np.array(
                [stayed[i] and max_angular_gap(res.phi[i]) < 20 * 2 * np.pi / n_steps for i in range(res.n_orbits)]
            )
            return stayed & (dig >= digits) & circle, res, dig

        K_pass, K_fail, res, dig = _search(
            test, K_a, K_b, grid, tol, search, regions, line, n_steps, digits, hover_search, th
        )
        bar.set_total(done)  # the bisection may have been shorter than its bound
    rho_w = rotation_number(res, "birkhoff")[0]
    rho_m = rotation_number(res, "mean")[0]
    if th.hovers or not hover_search:
        K_pred, rho_pred = th.K_crit, th.rho_crit
    else:  # k^{u0}: crosses L2 at its minimum ~0, and L1 at K_lowest
        K_pred = 0.0 if line == "L2" else th.K_lowest
        rho_pred = th.Omega0 + th.tau0 * (
            th.K_lowest + m.eps * float(np.mean(th.G(np.linspace(-np.pi, np.pi, 4096, endpoint=False))))
        )
    return CriticalCurve(
        K0=float(K_pass),
        K_min=float(np.min(res.K[0])),
        K_max=float(np.max(res.K[0])),
        rotation=float(rho_w),
        rotation_mean=float(rho_m),
        digits=float(dig[0]),
        K_pred=float(K_pred),
        rotation_pred=float(rho_pred),
        K_fail=float(K_fail),
        phi=res.phi[0],
        K=res.K[0],
        line=line,
        hovers=bool(th.hovers),
        note=th.note,
    )


def _search(test, K_a, K_b, grid, tol, search, regions, line, n_steps, digits, hover_search, th):
    """The grid scan and the bisection of :func:`critical_curve`: ``(K_pass, K_fail, res, digits)``
    of the passing start found (``res``: its orbit's IterateResult)."""
    K_grid = np.linspace(K_a, K_b, grid)
    ok, _, _ = test(K_grid)
    if not ok.any():
        why = f"; {th.note}" if hover_search and not th.hovers else "; widen K_range"
        raise RuntimeError(
            f"no invariant curve in regions {tuple(regions)} found on {line} for K0 in [{K_a}, {K_b}] "
            f"with {n_steps} steps and {digits} digits{why}"
        )
    if search == "lowest":
        j = int(np.argmax(ok))
        K_pass = K_grid[j]
        K_fail = K_grid[j - 1] if j > 0 else K_a
    else:  # the highest passing start: an invariant curve, so nothing below it gets out
        j = int(np.flatnonzero(ok)[-1])
        K_pass = K_grid[j]
        K_fail = K_grid[j + 1] if j + 1 < grid else K_b
    if K_fail != K_pass:
        while abs(K_pass - K_fail) > tol:
            mid = 0.5 * (K_pass + K_fail)
            if test([mid])[0][0]:
                K_pass = mid
            else:
                K_fail = mid
    _, res, dig = test([K_pass])
    return K_pass, K_fail, res, dig
