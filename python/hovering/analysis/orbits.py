"""Orbit classes that need no smoothness across the corner curves: a rotational invariant circle,
an island chain (with its period) or a chaotic layer, told apart from the recorded points alone by
order statistics; and a converse-KAM (MacKay-Percival) non-existence test where the map is smooth
and twist.

The weighted Birkhoff averages of :func:`hovering.regularity` assume a smooth observable on a smooth
invariant curve; the rotation omega_a of the truncated map jumps across the corner curves, so every
impacting orbit scores a few digits whatever it is (docs/orbit-classes.md measures it). The tests
here use only the cyclic order of the points, which a rotational invariant circle that is a graph
over phi preserves under any orientation-preserving map, smooth or not.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._arrays import unique
from .._checks import check_points, integer, real_array, real_number
from .._enums import Region
from ..interface import IterateResult
from ..truncated import TruncatedMap

__all__ = [
    "OrbitClasses",
    "classify_orbits",
    "cyclic_order_violations",
    "rank_rotation",
    "ConeCrossing",
    "cone_crossing",
    "converse_kam",
]

_TWO_PI = 2.0 * math.pi
#: The classes :func:`classify_orbits` gives, in the order its tests try them.
KINDS = ("circle", "islands", "chaotic", "undecided")


# ------------------------------------------------------------------------------------------------
# Order statistics of one orbit


def cyclic_order_violations(x, tol: float = 1e-9) -> int:
    """How often the step ``x_j -> x_{j+1}`` of an orbit breaks the cyclic order of its points.

    The points ``x_0 .. x_{n-2}`` are sorted; their images read in that order form a cyclic
    sequence. A map that preserves the cyclic order on the orbit (a circle homeomorphism restricted
    to it) leaves exactly one cyclic descent (where the images wrap around); every further descent
    is a violation. A descent smaller than ``tol`` is a tie, not a violation.

    Parameters
    ----------
    x : array_like
        1-D orbit of an angle, any range (only the order matters), finite.
    tol : float, optional
        Differences below ``tol`` are ties (rounding), >= 0.

    Returns
    -------
    int
        Number of descents beyond the one a cyclic-order-preserving map has (0 for a rigid rotation).
    """
    a = np.asarray(x, dtype=float)
    if a.ndim != 1 or a.size < 3:
        raise ValueError(f"x must be a 1-D orbit of >= 3 points, got shape {a.shape}")
    tol = real_number("tol", tol, lo=0.0, lo_open=False)
    y = a[1:][np.argsort(a[:-1], kind="stable")]
    descents = int(np.count_nonzero(y[1:] < y[:-1] - tol)) + int(y[0] < y[-1] - tol)
    return max(descents - 1, 0)


def rank_rotation(x) -> float:
    """Rotation number (turns per step, in [0, 1)) of an angle orbit from the ranks of its points.

    The rank of a point among the orbit's n points, divided by n, is the empirical conjugacy of a
    circle map to a rotation; each step advances it by ``d_j / n`` with
    ``d_j = (rank(x_{j+1}) - rank(x_j)) mod n``. The mean advance is the rotation number, with an
    error at most twice the orbit's discrepancy divided by n - 1 (O(log n / n^2) for a
    badly approximable rotation). Meaningful on an orbit whose map preserves the cyclic order
    (see :func:`cyclic_order_violations`); no smoothness is needed.

    Parameters
    ----------
    x : array_like
        1-D orbit of an angle in radians (any branch), >= 2 finite points.

    Returns
    -------
    float
        The rotation number mod 1.
    """
    a = np.mod(np.asarray(x, dtype=float), _TWO_PI)
    if a.ndim != 1 or a.size < 2 or not np.all(np.isfinite(a)):
        raise ValueError(f"x must be a 1-D finite orbit of >= 2 points, got shape {np.shape(x)}")
    n = a.size
    rank = np.empty(n, dtype=np.int64)
    rank[np.argsort(a, kind="stable")] = np.arange(n)
    d = np.mod(np.diff(rank), n)
    return float(d.sum() / (n * (n - 1.0))) % 1.0


def _local_slope(phi, K, group: int = 4) -> float:
    """Median of (K-spread / phi-width) over groups of ``group`` points adjacent in phi."""
    o = np.argsort(phi, kind="stable")
    m = (phi.size // group) * group
    p, k = phi[o][:m].reshape(-1, group), K[o][:m].reshape(-1, group)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (k.max(axis=1) - k.min(axis=1)) / (p[:, -1] - p[:, 0])
    return float(np.median(s))


def _graph_exponent(phi, K) -> float:
    """gamma in slope ~ n^gamma between n/16 and n points: 0 on a Lipschitz graph (the local slope
    tends to the derivative), 1 on an area or an island chain (a finite K-spread over a phi-width
    ~ 1/n). Scale-free, so clustered points of a near-resonant circle do not fool it (a
    thickness-scaling version measured 0.08 on a circle of the truncated map at eps = 0.1)."""
    n = phi.size
    s_all, s_part = _local_slope(phi, K), _local_slope(phi[: n // 16], K[: n // 16])
    if s_all == 0.0 and s_part == 0.0:
        return 0.0
    if s_part == 0.0 or not math.isfinite(s_all):
        return math.inf
    if s_all == 0.0 or not math.isfinite(s_part):
        return -math.inf
    return math.log(s_all / s_part) / math.log(16.0)


def _box_dimension(phi, K, span) -> float:
    """Box-counting dimension of the orbit between grids of g and 2g cells per side (2g ~ sqrt(n/8),
    so an area-filling orbit puts ~8 points in each fine cell), in the orbit's own box."""
    n = phi.size
    g2 = max(4, int(math.sqrt(n / 8.0)) // 2 * 2)
    u = np.mod(phi + math.pi, _TWO_PI) / _TWO_PI
    v = (K - K.min()) / span
    counts = []
    for g in (g2 // 2, g2):
        i = np.minimum((u * g).astype(np.int64), g - 1)
        j = np.minimum((v * g).astype(np.int64), g - 1)
        counts.append(unique(i * g + j).size)
    return math.log2(counts[1] / counts[0])


def _arc_hull(a):
    """Smallest arc holding the angles a: (start in [0, 2 pi), length)."""
    s = np.sort(np.mod(a, _TWO_PI))
    gaps = np.diff(np.concatenate([s, [s[0] + _TWO_PI]]))
    i = int(np.argmax(gaps))
    return float(s[(i + 1) % s.size]), float(_TWO_PI - gaps[i])


def _allowed(pieces: int) -> int:
    """Cyclic-order violations a map that keeps the order on each of ``pieces`` arcs can show: each
    piece's images form at most two increasing runs (one wrap), the cut at -pi can split one more
    piece, so <= 2 (pieces + 1) descents; one descent is always there. A homeomorphism: none."""
    return 0 if pieces == 1 else 2 * pieces + 1


def _island_test(phi, K, q, tol, min_points, allowed):
    """Whether the orbit lies on q islands visited in turn: the q sub-orbits z_{c+kq} have pairwise
    disjoint phi-hulls, each winds around its centroid (largest angular gap < pi/2) and the q-th
    return preserves the cyclic order of the angles about it. Returns (ok, violations, rotation)."""
    n = phi.size
    subs = [np.arange(c, n, q) for c in range(q)]
    if min(s.size for s in subs) < min_points:
        return False, -1, math.nan
    hulls = []
    for s in subs:  # one at a time: a circle's or a chaotic orbit's first hull already fails
        hulls.append(_arc_hull(phi[s]))
        if hulls[-1][1] >= _TWO_PI * (1.0 - 1.0 / (4 * q)):
            return False, -1, math.nan
    order = np.argsort([h[0] for h in hulls], kind="stable")
    for a, b in zip(order, np.roll(order, -1)):
        sep = (hulls[b][0] - hulls[a][0]) % _TWO_PI if q > 1 else _TWO_PI
        if sep <= hulls[a][1]:
            return False, -1, math.nan
    worst = 0
    for s in subs:
        p, k = phi[s], K[s]
        c = math.atan2(np.mean(np.sin(p)), np.mean(np.cos(p)))
        dp = np.mod(p - c + math.pi, _TWO_PI) - math.pi
        # Islands of a chain bend along the resonant curve (bananas), and their centroid can fall
        # outside them; removing a quadratic K(phi) trend straightens them about a centre inside.
        dk = k - np.polyval(np.polyfit(dp, k, 2), dp) if np.ptp(dp) > 0 else k - k.mean()
        sp, sk = dp.std(), dk.std()
        if sp == 0.0 or sk == 0.0:
            return False, -1, math.nan
        theta = np.arctan2(dk / sk, dp / sp)
        ts = np.sort(theta)
        if np.max(np.diff(np.concatenate([ts, [ts[0] + _TWO_PI]]))) >= 0.5 * math.pi:
            return False, -1, math.nan
        worst = max(worst, cyclic_order_violations(theta, tol))
        if worst > allowed:
            return False, worst, math.nan
    rank = np.empty(q, dtype=np.int64)
    rank[order] = np.arange(q)
    return True, worst, float((rank[1 % q] - rank[0]) % q) / q


# ------------------------------------------------------------------------------------------------
# Classification


@dataclass
class OrbitClasses:
    """Per-orbit classes from :func:`classify_orbits`.

    Attributes
    ----------
    kind : ndarray of str
        ``"circle"`` (rotational invariant circle), ``"islands"`` (island chain), ``"chaotic"``
        (fills an area) or ``"undecided"`` (too few points, or the tests disagree).
    period : ndarray of int
        Number of islands of the chain (0 unless ``kind == "islands"``).
    rotation : ndarray
        Turns per step mod 1: the rank rotation (:func:`rank_rotation`) of a circle, ``p/q`` of an
        island chain (q = period, p the island shift per step); NaN otherwise.
    K_min, K_max : ndarray
        Extremes of K over the orbit's points (NaN for an orbit with no finite point).
    n_points : ndarray of int
        Points used (the finite prefix of each row).
    decided_by : ndarray of str
        The test that decided: ``"order+graph"``, ``"islands"``, ``"box-dimension"``, or why not:
        ``"too few points"``, ``"order kept, not a graph"``, ``"no test decided"``.
    order_violations : ndarray of int
        :func:`cyclic_order_violations` of phi (0 on a circle); -1 if not computed.
    graph_exponent : ndarray
        gamma of the graph test: the median local slope (K-spread over phi-width of 4 points
        adjacent in phi) grows as n^gamma between n/16 and n points; ~0 on a graph (0 for constant
        K), ~1 on an area or an island chain.
    dimension : ndarray
        Box-counting dimension estimate (~1 on curves, ~2 on an area); NaN if not computed.
    """

    kind: np.ndarray
    period: np.ndarray
    rotation: np.ndarray
    K_min: np.ndarray
    K_max: np.ndarray
    n_points: np.ndarray
    decided_by: np.ndarray
    order_violations: np.ndarray
    graph_exponent: np.ndarray
    dimension: np.ndarray

    def __len__(self) -> int:
        return int(self.kind.size)

    def counts(self) -> dict:
        """Number of orbits of each kind.

        Returns
        -------
        dict
            ``{"circle": n, "islands": n, "chaotic": n, "undecided": n}``.
        """
        return {k: int(np.count_nonzero(self.kind == k)) for k in KINDS}


def _rows(name, a) -> np.ndarray:
    arr = np.asarray(a, dtype=float) if not isinstance(a, np.ndarray) else a.astype(float, copy=False)
    if arr.ndim == 1:
        arr = arr[None, :]
    if arr.ndim != 2:
        raise ValueError(f"{name} must have shape (n_orbits, n_points) or (n_points,), got {np.shape(a)}")
    return arr


def classify_orbits(
    phi,
    K=None,
    *,
    pieces: int = 3,
    tol: float = 1e-9,
    min_points: int = 256,
    max_period: int = 64,
    graph_max: float = 0.5,
    chaos_dimension: float = 1.5,
) -> OrbitClasses:
    """Classify recorded orbits as rotational circles, island chains or chaotic layers by order statistics.

    No smoothness is needed: the tests use the cyclic order of the points, so they hold for
    piecewise-smooth maps (TruncatedMap, TruncatedFamily, FlowMap) across corner curves. Per orbit,
    in this order (the first that holds decides):

    1. **circle**: the step keeps the cyclic phi-order of the orbit's points up to the few
       violations a map made of ``pieces`` order-preserving pieces can show (none for a
       homeomorphism, ``2 pieces + 1`` otherwise; a chaotic orbit or an island chain shows ~n/2 and
       hundreds): on a rotational invariant circle that is a graph over phi, the map is a circle
       homeomorphism (smooth map) or a piecewise isometry-like exchange of arcs (the truncated map
       at eps = 0 swaps J_1 and J_R: 1 violation) - *and* the points form a graph K(phi) (graph
       exponent <= ``graph_max``). The rotation is :func:`rank_rotation`. If the order is kept but
       the points are no graph, ``"undecided"``.
    2. **islands**: for the smallest q <= ``max_period`` (with >= 32 points per island): the q
       sub-orbits ``z_{c + k q}`` have pairwise disjoint phi-hulls, each winds around its centroid
       and the q-th return keeps the cyclic order of the angles about it.
    3. **chaotic**: box-counting dimension >= ``chaos_dimension`` (the points fill an area).
    4. otherwise **undecided** (e.g. an island chain of period > max_period, or a chaotic layer
       thinner than the grid resolves with this many points).

    Parameters
    ----------
    phi : array_like or IterateResult
        Angles, shape ``(n_orbits, n_points)`` or ``(n_points,)``; each row is used up to its first
        non-finite entry (stopped orbits are NaN-padded). An IterateResult recorded with
        ``"orbit"`` may be passed instead of ``phi, K``.
    K : array_like, optional
        Actions, same shape as phi (omit when phi is an IterateResult).
    pieces : int, optional
        Number of arcs on which the map restricted to an invariant circle keeps the order (default
        3: J_1, J_R, J_0 of the truncated map and of the flow's return map; 1 for a smooth map,
        which then allows no violation at all).
    tol : float, optional
        Angle differences below ``tol`` (rad) are ties in the order tests (default 1e-9: a
        recorded orbit carries rounding errors ~1e-16 per step, grown at most linearly along an
        invariant circle, so < 1e-10 over 1e5 steps).
    min_points : int, optional
        Below this many points an orbit is ``"undecided"`` (default 256, >= 16).
    max_period : int, optional
        Largest island-chain period tried (default 64, >= 1).
    graph_max : float, optional
        Largest graph exponent that counts as a graph (default 0.5, halfway between 0 for a
        graph and 1 for an area).
    chaos_dimension : float, optional
        Smallest box dimension that counts as area-filling (default 1.5, halfway between 1 and 2).

    Returns
    -------
    OrbitClasses

    Raises
    ------
    ValueError
        For mismatched shapes or out-of-range options.
    KeyboardInterrupt
        On Ctrl-C; its ``partial`` attribute holds the OrbitClasses with the orbits done so far
        (the others ``"undecided"``, decided_by ``"interrupted"``).
    """
    if isinstance(phi, IterateResult):
        if K is not None:
            raise ValueError("pass either an IterateResult or the arrays phi, K, not both")
        if phi.phi is None or phi.K is None:
            raise ValueError("this needs a result recorded with record=('orbit', ...)")
        phi, K = phi.phi, phi.K
    if K is None:
        raise ValueError("K is required with an array phi")
    P, Q = _rows("phi", phi), _rows("K", K)
    if P.shape != Q.shape:
        raise ValueError(f"phi and K must have the same shape, got {np.shape(phi)} and {np.shape(K)}")
    pieces = integer("pieces", pieces, 1, 64)
    tol = real_number("tol", tol, lo=0.0, lo_open=False, hi=0.1)
    min_points = integer("min_points", min_points, 16, 10**9)
    max_period = integer("max_period", max_period, 1, 10**6)
    graph_max = real_number("graph_max", graph_max, lo=0.0, hi=1.0)
    chaos_dimension = real_number("chaos_dimension", chaos_dimension, lo=1.0, hi=2.0)

    n_orbits = P.shape[0]
    out = OrbitClasses(
        kind=np.full(n_orbits, "undecided", dtype=object),
        period=np.zeros(n_orbits, dtype=np.int64),
        rotation=np.full(n_orbits, np.nan),
        K_min=np.full(n_orbits, np.nan),
        K_max=np.full(n_orbits, np.nan),
        n_points=np.zeros(n_orbits, dtype=np.int64),
        decided_by=np.full(n_orbits, "too few points", dtype=object),
        order_violations=np.full(n_orbits, -1, dtype=np.int64),
        graph_exponent=np.full(n_orbits, np.nan),
        dimension=np.full(n_orbits, np.nan),
    )
    i = 0
    try:
        for i in range(n_orbits):
            bad = ~(np.isfinite(P[i]) & np.isfinite(Q[i]))
            n = int(np.argmax(bad)) if bad.any() else P.shape[1]
            p, k = P[i, :n], Q[i, :n]
            out.n_points[i] = n
            if n == 0:
                continue
            out.K_min[i], out.K_max[i] = k.min(), k.max()
            if n < min_points:
                continue
            _classify_one(out, i, p, k, _allowed(pieces), tol, max_period, graph_max, chaos_dimension)
    except KeyboardInterrupt as exc:
        out.kind[i:], out.decided_by[i:], out.period[i:], out.rotation[i:] = "undecided", "interrupted", 0, np.nan
        out.kind, out.decided_by = out.kind.astype(str), out.decided_by.astype(str)
        exc.partial = out  # the orbits classified before Ctrl-C keep their verdicts
        raise
    out.kind = out.kind.astype(str)
    out.decided_by = out.decided_by.astype(str)
    return out


def _classify_one(out, i, p, k, allowed, tol, max_period, graph_max, chaos_dimension):
    span = float(k.max() - k.min())
    flat = span <= 1e-12 * max(1.0, float(np.abs(k).max()))
    viol = cyclic_order_violations(p, tol)
    out.order_violations[i] = viol
    gamma = 0.0 if flat else _graph_exponent(p, k)
    out.graph_exponent[i] = gamma
    if viol <= allowed:
        if gamma <= graph_max:
            out.kind[i], out.decided_by[i] = "circle", "order+graph"
            out.rotation[i] = rank_rotation(p)
        else:
            out.decided_by[i] = "order kept, not a graph"
        return
    for q in range(1, min(max_period, p.size // 32) + 1):
        ok, _, rot = _island_test(p, k, q, tol, 32, allowed)
        if ok:
            out.kind[i], out.decided_by[i], out.period[i], out.rotation[i] = "islands", "islands", q, rot
            return
    dim = math.nan if flat else _box_dimension(p, k, span)
    out.dimension[i] = dim
    if dim >= chaos_dimension:
        out.kind[i], out.decided_by[i] = "chaotic", "box-dimension"
    else:
        out.decided_by[i] = "no test decided"


# ------------------------------------------------------------------------------------------------
# Converse KAM


@dataclass
class ConeCrossing:
    """Outcome of :func:`cone_crossing` / :func:`converse_kam` per orbit.

    Attributes
    ----------
    status : ndarray of str
        ``"crossing"``: the pushed-forward vertical left the twist cone at ``step`` - no rotational
        invariant circle (inside the domain) passes through the start; ``"left_domain"``: the orbit
        left the smooth twist domain at ``step`` before a crossing (so it lies on no invariant
        circle *inside* the domain either, but one that leaves the domain is not excluded);
        ``"not_twist"``: the twist entry of the Jacobian had the wrong sign or vanished at
        ``step``; ``"none"``: nothing found in ``n_steps`` (inconclusive).
    step : ndarray of int
        Step at which the status was reached (-1 for ``"none"``).
    phi, K : ndarray
        Start points.
    n_steps : int
        Steps tried.
    """

    status: np.ndarray
    step: np.ndarray
    phi: np.ndarray
    K: np.ndarray
    n_steps: int

    @property
    def crossed(self) -> np.ndarray:
        """Boolean per orbit: a cone crossing was found (non-existence proven, up to rounding)."""
        return self.status == "crossing"


def cone_crossing(
    step: Callable,
    jacobian: Callable,
    phi,
    K,
    n_steps: int,
    twist: float = 1.0,
    in_domain: Callable | None = None,
    tol: float = 1e-9,
) -> ConeCrossing:
    """MacKay-Percival cone crossing for any map that is smooth and twist on a domain.

    Push the vertical vector (0, 1) forward along the orbit by the Jacobian. On a rotational
    invariant circle of a twist map (a Lipschitz graph, by Birkhoff's theorem) the image
    ``DF^n (0, 1)`` stays, for every n >= 1, strictly between the circle's tangent and the vertical,
    so its phi-component keeps the sign of the twist ``dphi'/dK``. If it ever has the other sign,
    no rotational invariant circle (of the smooth twist map on the domain) passes through the start.

    Parameters
    ----------
    step : callable
        ``step(phi, K) -> (phi1, K1)`` on arrays.
    jacobian : callable
        ``jacobian(phi, K) -> (a, b, c, d)`` arrays: ``a = dphi1/dphi, b = dphi1/dK,
        c = dK1/dphi, d = dK1/dK`` at the points.
    phi, K : array_like
        Start points (broadcast, flattened), finite.
    n_steps : int
        Steps to try (>= 1).
    twist : float, optional
        Sign of the twist ``b`` (+1 or -1).
    in_domain : callable, optional
        ``in_domain(phi, K) -> bool array``: where the map is the smooth twist map. An orbit that
        reaches a point outside stops with ``"left_domain"``. Default: everywhere.
    tol : float, optional
        A crossing counts when the normalised vector's phi-component is below ``-tol`` (times the
        twist sign); default 1e-9, far above the ~1e-15 rounding per step of a direction, which
        does not accumulate (the direction is attracted to the unstable one).

    Returns
    -------
    ConeCrossing

    Raises
    ------
    ValueError
        For non-finite starts, n_steps < 1, a twist other than +-1 or tol outside [0, 0.1], or
        phi and K that broadcast to more points than half of this machine's memory holds
        (checked before they are copied).
    KeyboardInterrupt
        On Ctrl-C; its ``partial`` attribute holds the ConeCrossing found so far.
    """
    n_steps = integer("n_steps", n_steps, 1, 10**9)
    tw = real_number("twist", twist)
    if tw not in (1.0, -1.0):
        raise ValueError(f"twist must be +1 or -1 (the sign of dphi'/dK), got {twist!r}")
    tol = real_number("tol", tol, lo=0.0, lo_open=False, hi=0.1)
    p, k = real_array("phi", phi), real_array("K", K)
    check_points(("phi", "K"), (p.shape, k.shape))  # before the copies below
    p, k = np.broadcast_arrays(p, k)
    p, k = p.ravel().copy(), k.ravel().copy()
    if not (np.all(np.isfinite(p)) and np.all(np.isfinite(k))):
        raise ValueError("phi and K must be finite")
    phi0, K0 = p.copy(), k.copy()
    m = p.size
    status = np.full(m, "none", dtype=object)
    when = np.full(m, -1, dtype=np.int64)
    vp, vk = np.zeros(m), np.ones(m)
    alive = np.arange(m)
    try:
        _push_cone(step, jacobian, in_domain, tw, tol, n_steps, p, k, vp, vk, alive, status, when)
    except KeyboardInterrupt as exc:
        # what was found so far stands; the rest is inconclusive ("none")
        exc.partial = ConeCrossing(status=status.astype(str), step=when, phi=phi0, K=K0, n_steps=n_steps)
        raise
    return ConeCrossing(status=status.astype(str), step=when, phi=phi0, K=K0, n_steps=n_steps)


def _push_cone(step, jacobian, in_domain, tw, tol, n_steps, p, k, vp, vk, alive, status, when):
    """The loop of cone_crossing, filling status and when in place."""
    for n in range(n_steps):
        if alive.size == 0:
            break
        pa, ka = p[alive], k[alive]
        if in_domain is not None:
            out = ~np.asarray(in_domain(pa, ka), dtype=bool)
            if out.any():
                status[alive[out]], when[alive[out]] = "left_domain", n
                alive, pa, ka = alive[~out], pa[~out], ka[~out]
        if alive.size == 0:
            break
        a, b, c, d = (np.broadcast_to(np.asarray(t, dtype=float), pa.shape) for t in jacobian(pa, ka))
        bad = ~(tw * b > 0)
        if bad.any():
            status[alive[bad]], when[alive[bad]] = "not_twist", n
            keep = ~bad
            alive, pa, ka, a, b, c, d = alive[keep], pa[keep], ka[keep], a[keep], b[keep], c[keep], d[keep]
            if alive.size == 0:
                break
        x, y = vp[alive], vk[alive]
        x, y = a * x + b * y, c * x + d * y
        r = np.hypot(x, y)
        vp[alive], vk[alive] = x / r, y / r
        p[alive], k[alive] = step(pa, ka)
        hit = tw * vp[alive] < -tol
        if hit.any():
            status[alive[hit]], when[alive[hit]] = "crossing", n + 1
            alive = alive[~hit]


def converse_kam(m, phi, K, n_steps: int, tol: float = 1e-9) -> ConeCrossing:
    """Converse KAM for the truncated map where it is smooth and twist: no-impact points.

    On the no-impact regions J_0u (K >= 0) and J_0 (K < 0, above the step) the truncated map is
    the shifted standard map ``G: phibar = phi + Omega0 + tau0 K, Kbar = K + eps sin(phibar)``, a
    smooth twist map of the whole cylinder (twist ``dphibar/dK = tau0``). An invariant circle of F
    inside these regions is an invariant circle of G, so :func:`cone_crossing` with G's Jacobian
    ``[[1, tau0], [eps cos(phibar), 1 + eps tau0 cos(phibar)]]`` (closed form) proves that no
    rotational invariant circle of F *lying in the no-impact set* - e.g. any above the critical
    curve - passes through a start with a crossing. An orbit that impacts stops with
    ``"left_domain"``: it lies on no circle of the no-impact set either, but an impacting circle
    is not excluded (the map is not smooth there; use :func:`classify_orbits`).

    Parameters
    ----------
    m : TruncatedMap
        The map (TruncatedFamily and FlowMap are refused: see Raises).
    phi, K : array_like
        Start points, in the no-impact regions (J_0u or J_0) of the band.
    n_steps : int
        Steps to try (>= 1).
    tol : float, optional
        See :func:`cone_crossing`.

    Returns
    -------
    ConeCrossing

    Raises
    ------
    ValueError
        For a map other than TruncatedMap (TruncatedFamily: Omega(K) is a spline whose derivative is
        not exposed; FlowMap: no closed-form Jacobian - use :func:`cone_crossing` with your own),
        for tau0 = 0 (no twist), or for a start point in an impacting region (J_1, J_R: the map
        is not smooth twist there) or outside the band, or phi and K that broadcast to more points
        than half of this machine's memory holds.
    """
    if not isinstance(m, TruncatedMap):
        raise ValueError(
            f"converse_kam needs a TruncatedMap (smooth twist map with a closed-form Jacobian on its "
            f"no-impact regions), got {type(m).__name__}; for other maps call cone_crossing with "
            f"your own step and Jacobian"
        )
    if m.tau0 == 0:
        raise ValueError("converse_kam needs a twist map: tau0 must be nonzero, got 0")
    p, k = real_array("phi", phi), real_array("K", K)
    check_points(("phi", "K"), (p.shape, k.shape))
    p, k = np.broadcast_arrays(p, k)
    lo, hi = m.valid_band()
    if not (np.all(np.isfinite(p)) and np.all(np.isfinite(k))):
        raise ValueError("phi and K must be finite")
    if np.any((k <= lo) | (k >= hi)):
        raise ValueError(f"K must lie in the map's band ({lo}, {hi}), got {k[(k <= lo) | (k >= hi)].ravel()[0]}")
    smooth = (int(Region.BESIDE), int(Region.ABOVE))
    reg = np.asarray(m.region(p.ravel(), k.ravel()))
    if not np.all(np.isin(reg, smooth)):
        j = int(np.argmax(~np.isin(reg, smooth)))
        raise ValueError(
            f"start point (phi, K) = ({p.ravel()[j]}, {k.ravel()[j]}) lies in region "
            f"{Region(int(reg[j])).name}, where the map impacts and is not a smooth twist map; "
            f"converse_kam applies on J_0u and J_0 only"
        )
    eps, Om, t0 = float(m.eps), float(m.Omega0), float(m.tau0)

    def jac(ph, kk):
        c = eps * np.cos(ph + Om + t0 * kk)
        return np.ones_like(ph), np.full_like(ph, t0), c, 1.0 + t0 * c

    def dom(ph, kk):
        return np.isin(np.asarray(m.region(ph, kk)), smooth) & (kk > lo) & (kk < hi)

    return cone_crossing(m.step, jac, p, k, n_steps, twist=math.copysign(1.0, t0), in_domain=dom, tol=tol)
