"""Invariant manifolds of hyperbolic periodic orbits (both models), grown to a stated length with
adaptive point insertion, their intersections and the lobes between them: the turnstile of a
partial barrier and the flux through it per return.

Growth (Hobson's scheme for maps): a fundamental domain of the local manifold, the points
``x0 + s v`` with ``s`` geometric in ``[delta, delta |lambda|]`` (v the eigenvector, lambda its
multiplier of G = F^n), is mapped by G generation after generation; wherever two neighbouring
images lie farther apart than ``max_gap`` or the curve bends by more than ``max_angle``, the
parameter between their preimages (geometric midpoint) is mapped from scratch by the same number of
generations and inserted. A gap that halving the parameter down to rounding does not close is a
jump of the map itself - a corner curve of the piecewise map cuts the manifold there - and is kept
as a break (NaN in the curve). The stable manifold is grown the same way under G^-1 (``step_inverse``).

Lobes: two curves (an unstable and a stable branch) cross at intersection points; between two
consecutive ones (along the unstable branch) they bound a lobe, whose signed area is the shoelace
formula of the closed curve. For a partial barrier made of the two manifolds between consecutive
primary intersection points, the area that crosses it per step of F is the area of one lobe (the
turnstile, MacKay-Meiss-Percival): consecutive lobes of one type are images of each other under G
and have equal areas, a built-in check.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._checks import _short, integer, is_choice, real_number
from .._display import Summarized
from .._enums import Status, wrap
from .._io.serial import Saveable
from ..interface import require_map
from . import _tangent as T
from .periodic import PeriodicOrbit

__all__ = ["Manifold", "manifold", "intersections", "Lobes", "lobes"]


@dataclass(frozen=True, repr=False)
class Manifold(Summarized, Saveable):
    """A branch of the stable or unstable manifold of a point of a hyperbolic periodic orbit.

    Attributes
    ----------
    phi, K : ndarray
        The curve from the orbit point outwards (phi in [-pi, pi)); NaN rows are breaks (a corner
        curve cut the manifold, or the map failed there).
    phi_lift : ndarray
        phi unwrapped along the curve (continuous across +-pi; restarted after a break): for
        drawing, for arc lengths and for intersections.
    s : ndarray
        Each point's parameter in the fundamental domain (its preimage ``x0 + s v``).
    generation : ndarray of int
        How many times G (or G^-1) maps the fundamental domain to the point.
    kind : str
        ``"unstable"`` or ``"stable"``.
    branch : int
        +1 or -1: the side of the eigenvector.
    point : tuple of float
        The orbit point ``(phi, K)`` the branch leaves.
    multiplier : float
        lambda of G along the branch (|lambda| > 1 unstable, < 1 stable).
    direction : ndarray
        The unit eigenvector v.
    length : float
        Arc length of the curve (breaks excluded).
    breaks : int
        Gaps that did not close (corner curves, failed steps).
    period : int
        The orbit's period n (G = F^n; F^{2n} for an inverse-hyperbolic orbit).
    map_steps : int
        Applications of F (or F^-1) spent.
    status : str
        ``"complete"`` (``length`` reached), ``"max_points"``, ``"stopped"`` (every end point's
        step failed: the branch left the band or hit a corner of the flow).
    """

    phi: np.ndarray
    K: np.ndarray
    phi_lift: np.ndarray
    s: np.ndarray
    generation: np.ndarray
    kind: str
    branch: int
    point: tuple
    multiplier: float
    direction: np.ndarray
    length: float
    breaks: int
    period: int
    map_steps: int
    status: str

    def _summary(self) -> list:
        return [
            ("kind", self.kind),
            ("branch", self.branch),
            ("points", int(np.isfinite(self.phi).sum())),
            ("length", f"{self.length:.4g}"),
            ("breaks", self.breaks),
            ("generations", int(np.nanmax(self.generation)) if self.generation.size else 0),
            ("status", self.status),
        ]


def _eig(orbit: PeriodicOrbit, kind: str):
    M = np.asarray(orbit.monodromy, dtype=float)
    if not np.all(np.isfinite(M)):
        raise ValueError("the orbit's monodromy is not finite (a hyperbolic orbit too long for its product)")
    w, v = np.linalg.eig(M)
    if np.iscomplexobj(w) and np.any(np.abs(w.imag) > 1e-12 * np.abs(w).max()):
        raise ValueError(f"the orbit is not hyperbolic (multipliers {w}, residue {orbit.residue:.4g}): no manifolds")
    w, v = w.real, v.real
    i = int(np.argmax(np.abs(w))) if kind == "unstable" else int(np.argmin(np.abs(w)))
    lam = float(w[i])
    if not abs(abs(lam) - 1.0) > 1e-10:
        raise ValueError(f"the orbit is parabolic (multiplier {lam}): no hyperbolic manifolds")
    d = v[:, i] / np.hypot(*v[:, i])
    return lam, d


def _apply(m, phi, K, times: int, inverse: bool, n_threads: int):
    """G^times of many points (G = F^n built by the caller's `times` = generations * n steps)."""
    p, k = np.asarray(phi, dtype=float).copy(), np.asarray(K, dtype=float).copy()
    ok = np.isfinite(p) & np.isfinite(k)
    for _ in range(times):
        if not ok.any():
            break
        idx = np.flatnonzero(ok)
        a, b = _step(m, p[idx], k[idx], inverse, n_threads)
        good = np.isfinite(a) & np.isfinite(b)
        p[idx], k[idx] = a, b
        ok[idx[~good]] = False
    p[~ok] = np.nan
    k[~ok] = np.nan
    return p, k


def _step(m, p, k, inverse, n_threads):
    lo, hi = m.valid_band()
    inside = (k > lo) & (k < hi)
    a, b = np.full(p.size, np.nan), np.full(p.size, np.nan)
    if not inside.any():
        return a, b
    if T.is_flow(m):
        r = m.returns(p[inside], k[inside], inverse=inverse, n_threads=n_threads)
        a[inside], b[inside] = r.phi, r.K
    else:
        try:
            a[inside], b[inside] = (m.step_inverse if inverse else m.step)(p[inside], k[inside])
        except ValueError:  # a preimage outside the band: point by point
            for j in np.flatnonzero(inside):
                try:
                    a[j], b[j] = (m.step_inverse if inverse else m.step)(float(p[j]), float(k[j]))
                except ValueError:
                    pass
    out = (b > lo) & (b < hi)
    a[~out], b[~out] = np.nan, np.nan
    return a, b


def _chord(p0, k0, p1, k1):
    return np.hypot(wrap(p1 - p0), k1 - k0)


def _lift(phi):
    """phi unwrapped along the curve, restarted after NaN breaks."""
    out = np.full(phi.shape, np.nan)
    prev = math.nan
    for i, x in enumerate(phi):
        if not math.isfinite(x):
            prev = math.nan
            continue
        out[i] = x if not math.isfinite(prev) else out[i - 1] + float(wrap(x - prev))
        prev = x
    return out


def manifold(
    m,
    orbit: PeriodicOrbit,
    kind: str = "unstable",
    branch: int = 1,
    length: float = 1.0,
    *,
    point: int = 0,
    delta: float | None = None,
    max_gap: float | None = None,
    max_angle: float = 0.3,
    max_points: int = 100_000,
    n_threads: int = 0,
) -> Manifold:
    """One branch of the stable or unstable manifold of a point of a hyperbolic periodic orbit,
    grown to a stated arc length with adaptive point insertion (see the module docstring).

    Parameters
    ----------
    m : TruncatedMap, TruncatedFamily or FlowMap
        The map.
    orbit : PeriodicOrbit
        A converged hyperbolic (or inverse hyperbolic) orbit of m.
    kind : {"unstable", "stable"}, optional
        Which manifold (stable: grown under the inverse map).
    branch : {1, -1}, optional
        The side of the eigenvector.
    length : float, optional
        Arc length to grow to (in (phi, K)), > 0.
    point : int, optional
        Which point of the orbit (index into ``orbit.phi``); its monodromy is the orbit's, carried
        there along the orbit.
    delta : float, optional
        Distance of the fundamental domain from the point (default 1e-6 for the truncated map,
        1e-4 for the flow: the local linear part's error ~delta^2 must stay below the map's own).
    max_gap : float, optional
        Largest chord between neighbouring points (default length / 2000).
    max_angle : float, optional
        Largest turn of the curve between neighbouring chords (radians).
    max_points : int, optional
        Points at most.
    n_threads : int, optional
        Worker threads of the flow's batched returns.

    Returns
    -------
    Manifold

    Raises
    ------
    ValueError
        For an orbit that is not converged or not hyperbolic, or bad parameters.

    Examples
    --------
    The standard map's hyperbolic fixed point at k = 1.2 and its unstable manifold, grown to
    length 6 (it winds along the separatrix of the main resonance):

    >>> import numpy as np, hovering
    >>> sm = hovering.TruncatedMap(eps=1.2, Omega0=0.3, theta_w=2.0)
    >>> x = hovering.periodic_orbit(sm, 0.0, 6.0, 1)
    >>> wu = hovering.dynamics.manifold(sm, x, "unstable", length=6.0)
    >>> wu.status, round(wu.length, 3) >= 6.0, wu.breaks
    ('complete', True, 0)
    """
    require_map("m", m)
    if not isinstance(orbit, PeriodicOrbit) or not orbit.converged:
        raise ValueError(f"orbit must be a converged PeriodicOrbit of the map, got {_short(orbit)}")
    if not is_choice(kind, ("unstable", "stable")):
        raise ValueError(f"kind must be 'unstable' or 'stable', got {_short(kind)}")
    if branch not in (1, -1) or isinstance(branch, bool):
        raise ValueError(f"branch must be 1 or -1, got {_short(branch)}")
    length = real_number("length", length, lo=0.0)
    point = integer("point", point, 0, orbit.period - 1)
    flow = T.is_flow(m)
    delta = (1e-4 if flow else 1e-6) if delta is None else real_number("delta", delta, lo=0.0, hi=1.0)
    max_gap = length / 2000 if max_gap is None else real_number("max_gap", max_gap, lo=0.0)
    max_angle = real_number("max_angle", max_angle, lo=0.0, hi=math.pi)
    max_points = integer("max_points", max_points, 16, 10_000_000)
    n_threads = integer("n_threads", n_threads, 0, 4096)
    lam, v = _eig(_at_point(m, orbit, point), kind)
    inverse = kind == "stable"
    n = orbit.period * (2 if lam < 0 else 1)  # an inverse-hyperbolic orbit flips the branch: G = F^2n
    grow = abs(lam) ** (2 if lam < 0 else 1)
    grow = grow if not inverse else 1.0 / grow
    x0 = (float(orbit.phi[point]), float(orbit.K[point]))

    def seed(s):
        s = np.asarray(s, dtype=float)
        return wrap(x0[0] + branch * s * v[0]), x0[1] + branch * s * v[1]

    steps = 0
    n0 = 16
    s_gen = np.geomspace(delta, delta * grow, n0 + 1)  # the fundamental domain [delta, delta |lambda|]
    P, Kk = seed(s_gen)
    curve_p, curve_k, curve_s, curve_g = [np.array([x0[0]])], [np.array([x0[1]])], [np.array([0.0])], [np.array([0])]
    total, breaks, status = 0.0, 0, "complete"
    g = 0
    while True:
        # refine this generation: insert geometric midpoints where the images are too far apart or
        # the curve turns too much
        for _ in range(60):
            d = _chord(P[:-1], Kk[:-1], P[1:], Kk[1:])
            turn = np.zeros(d.size, dtype=bool)
            if P.size >= 3:
                a = np.arctan2(Kk[1:] - Kk[:-1], wrap(P[1:] - P[:-1]))
                da = np.abs(wrap(a[1:] - a[:-1]))
                turn[1:] |= da > max_angle
                turn[:-1] |= da > max_angle
            need = np.flatnonzero(((d > max_gap) | turn) & np.isfinite(d))
            # a parameter interval at rounding cannot be split: that gap is a jump of the map
            resolvable = need[s_gen[need + 1] / s_gen[need] - 1 > 1e-13]
            if resolvable.size == 0 or P.size + resolvable.size > max_points:
                break
            s_mid = np.sqrt(s_gen[resolvable] * s_gen[resolvable + 1])
            sp, sk = seed(s_mid)
            mp, mk = _apply(m, sp, sk, g * n, inverse, n_threads)
            steps += g * n * s_mid.size
            s_gen = np.insert(s_gen, resolvable + 1, s_mid)
            P = np.insert(P, resolvable + 1, mp)
            Kk = np.insert(Kk, resolvable + 1, mk)
        d = _chord(P[:-1], Kk[:-1], P[1:], Kk[1:])
        jumps = np.isfinite(d) & (d > max_gap) & (s_gen[1:] / s_gen[:-1] - 1 <= 1e-13)
        # keep the generation, with a NaN row at each unresolved jump
        Pg, Kg, Sg = P.copy(), Kk.copy(), s_gen.copy()
        if jumps.any():
            at = np.flatnonzero(jumps) + 1
            Pg, Kg, Sg = np.insert(Pg, at, np.nan), np.insert(Kg, at, np.nan), np.insert(Sg, at, np.nan)
            breaks += int(jumps.sum())
        seg = _chord(Pg[:-1], Kg[:-1], Pg[1:], Kg[1:])
        # the first point of a generation is the last of the one before (s = delta |lambda|^g)
        keep = slice(1, None) if g > 0 else slice(None)
        curve_p.append(Pg[keep])
        curve_k.append(Kg[keep])
        curve_s.append(Sg[keep])
        curve_g.append(np.full(Pg[keep].size, g))
        total += float(np.nansum(seg))
        if total >= length:
            break
        if sum(c.size for c in curve_p) >= max_points:
            status = "max_points"
            break
        P, Kk = _apply(m, P, Kk, n, inverse, n_threads)
        steps += n * P.size
        g += 1
        if not np.any(np.isfinite(P)):
            status = "stopped"
            break
    phi = np.concatenate(curve_p)
    K = np.concatenate(curve_k)
    lifted = _lift(phi)
    # trim to the stated length
    seglen = np.hypot(np.diff(lifted), np.diff(K))
    cum = np.concatenate([[0.0], np.nancumsum(np.where(np.isfinite(seglen), seglen, 0.0))])
    if status == "complete" and cum[-1] > length:
        end = int(np.searchsorted(cum, length)) + 1
        phi, K, lifted = phi[:end], K[:end], lifted[:end]
        s_all, g_all = np.concatenate(curve_s)[:end], np.concatenate(curve_g)[:end]
        cum = cum[:end]
    else:
        s_all, g_all = np.concatenate(curve_s), np.concatenate(curve_g)
    return Manifold(
        phi=phi,
        K=K,
        phi_lift=lifted,
        s=s_all,
        generation=g_all,
        kind=kind,
        branch=branch,
        point=x0,
        multiplier=lam,
        direction=v,
        length=float(cum[-1]),
        breaks=breaks,
        period=orbit.period,
        map_steps=int(steps),
        status=status,
    )


def _at_point(m, orbit: PeriodicOrbit, j: int) -> PeriodicOrbit:
    """The orbit with its monodromy carried to point j (M_j = D F^j M_0 D F^-j, as the product of
    the Jacobians from x_j around the orbit)."""
    if j == 0:
        return orbit
    M = np.eye(2)
    for i in range(orbit.period):
        t = m.jacobian(orbit.phi[(j + i) % orbit.period], orbit.K[(j + i) % orbit.period])
        if t.status not in (Status.OK, Status.CORNER):
            raise ValueError(f"the orbit's step from point {(j + i) % orbit.period} has no Jacobian ({t.status.name})")
        M = t.J @ M
    from dataclasses import replace

    return replace(orbit, monodromy=M)


# ------------------------------------------------------------------------------- intersections


def _segments(c: Manifold, shift: float = 0.0):
    x, y = c.phi_lift + shift, c.K
    ok = np.isfinite(x[:-1]) & np.isfinite(x[1:])
    i = np.flatnonzero(ok)
    return i, x[i], y[i], x[i + 1], y[i + 1]


def intersections(a: Manifold, b: Manifold, shifts=(-2 * math.pi, 0.0, 2 * math.pi)):
    """Where two curves cross, in the order along ``a``.

    The curves are compared in lifted coordinates (``phi_lift``), ``b`` shifted by each of
    ``shifts`` (whole turns of phi: the cylinder's copies).

    Returns
    -------
    ndarray
        ``(n, 5)`` rows ``(phi, K, t_a, t_b, shift)``: the point (phi wrapped), its position along
        ``a`` (segment index + fraction) and along ``b``, and the shift of b.
    """
    ia, ax0, ay0, ax1, ay1 = _segments(a)
    rows = []
    for sh in shifts:
        ib, bx0, by0, bx1, by1 = _segments(b, sh)
        if not ib.size or not ia.size:
            continue
        # bounding boxes prune; then the exact segment test in blocks of a
        for lo in range(0, ia.size, 2048):
            sl = slice(lo, lo + 2048)
            X0, Y0, X1, Y1 = ax0[sl, None], ay0[sl, None], ax1[sl, None], ay1[sl, None]
            dxa, dya = X1 - X0, Y1 - Y0
            dxb, dyb = (bx1 - bx0)[None, :], (by1 - by0)[None, :]
            den = dxa * dyb - dya * dxb
            with np.errstate(divide="ignore", invalid="ignore"):
                t = ((bx0[None, :] - X0) * dyb - (by0[None, :] - Y0) * dxb) / den
                u = ((bx0[None, :] - X0) * dya - (by0[None, :] - Y0) * dxa) / den
            hit = (den != 0) & (t >= 0) & (t < 1) & (u >= 0) & (u < 1)
            for r, c in zip(*np.nonzero(hit)):
                x = X0[r, 0] + t[r, c] * dxa[r, 0]
                y = Y0[r, 0] + t[r, c] * dya[r, 0]
                rows.append((float(wrap(x)), float(y), ia[lo + r] + t[r, c], ib[c] + u[r, c], sh))
    out = np.array(rows, dtype=float).reshape(-1, 5)
    return out[np.argsort(out[:, 2])] if out.size else out


@dataclass(frozen=True, repr=False)
class Lobes(Summarized):
    """The lobes between an unstable and a stable branch (:func:`lobes`).

    Attributes
    ----------
    points : ndarray
        ``(n, 5)``: the intersection points used (see :func:`intersections`), in order along the
        unstable branch.
    areas : ndarray
        Signed area of the lobe between each two consecutive points (shoelace, lifted
        coordinates): the sign tells the side (lobes alternate); ``|areas|`` of lobes of one type
        are equal up to the manifolds' error (they are images of each other).
    flux : float
        The turnstile's flux per step of F: the median ``|area|`` of the lobes (an exit and an
        entry lobe carry equal areas, the map preserving area).
    spread : float
        Relative spread (max - min) / median of ``|areas|``: the check that the lobes are images of
        each other, ~0 when the manifolds are accurate and the lobes are primary.
    """

    points: np.ndarray
    areas: np.ndarray
    flux: float
    spread: float

    def _summary(self) -> list:
        return [("lobes", self.areas.size), ("flux", f"{self.flux:.4g}"), ("spread", f"{self.spread:.2g}")]


def _piece(c: Manifold, t0: float, t1: float, shift: float = 0.0):
    """The curve's points between positions t0 < t1 (segment index + fraction), end points included."""
    i0, i1 = int(math.floor(t0)), int(math.floor(t1))
    x, y = c.phi_lift + shift, c.K

    def at(t):
        i = int(math.floor(t))
        f = t - i
        j = min(i + 1, x.size - 1)
        return x[i] + f * (x[j] - x[i]), y[i] + f * (y[j] - y[i])

    xs = [at(t0)[0]] + list(x[i0 + 1 : i1 + 1]) + [at(t1)[0]]
    ys = [at(t0)[1]] + list(y[i0 + 1 : i1 + 1]) + [at(t1)[1]]
    return np.array(xs), np.array(ys)


def lobes(unstable: Manifold, stable: Manifold, n_lobes: int | None = None) -> Lobes:
    """The lobes between an unstable and a stable branch, and the turnstile flux per step.

    Between two consecutive intersection points (along the unstable branch) the unstable piece
    and the stable piece back bound a lobe; its signed area is the shoelace formula (in lifted
    coordinates, so a lobe across phi = +-pi is whole). A lobe whose stable piece is broken (a
    corner curve cuts it) is skipped.

    Parameters
    ----------
    unstable, stable : Manifold
        An unstable and a stable branch (of the same orbit or of neighbouring points of it: the
        curves of a partial barrier).
    n_lobes : int, optional
        Lobes to measure at most (from the first intersection along the unstable branch).

    Returns
    -------
    Lobes

    Raises
    ------
    ValueError
        For curves of the wrong kinds or fewer than two intersections.
    """
    if not (isinstance(unstable, Manifold) and unstable.kind == "unstable"):
        raise ValueError(f"unstable must be an unstable Manifold, got {_short(unstable)}")
    if not (isinstance(stable, Manifold) and stable.kind == "stable"):
        raise ValueError(f"stable must be a stable Manifold, got {_short(stable)}")
    pts = intersections(unstable, stable)
    # the orbit points themselves (where both branches start) are not lobe corners
    far = np.hypot(wrap(pts[:, 0] - unstable.point[0]), pts[:, 1] - unstable.point[1]) > 1e-9 if pts.size else pts
    pts = pts[far] if pts.size else pts
    if pts.shape[0] < 2:
        raise ValueError(
            f"the branches cross {pts.shape[0]} time(s): grow them longer to find two intersections and a lobe"
        )
    if n_lobes is not None:
        pts = pts[: integer("n_lobes", n_lobes, 1, 100_000) + 1]
    areas = []
    for a, b in zip(pts[:-1], pts[1:]):
        if a[4] != b[4]:
            continue  # the two intersections lie on different copies of the stable branch
        ux, uy = _piece(unstable, a[2], b[2])
        lo, hi = sorted((a[3], b[3]))
        sx, sy = _piece(stable, lo, hi, a[4])
        if not (np.all(np.isfinite(sx)) and np.all(np.isfinite(ux))):
            continue
        if a[3] < b[3]:
            sx, sy = sx[::-1], sy[::-1]
        x, y = np.concatenate([ux, sx]), np.concatenate([uy, sy])
        areas.append(0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)))
    areas = np.array(areas)
    if areas.size == 0:
        raise ValueError("no lobe is bounded by unbroken pieces of both branches")
    mag = np.abs(areas)
    med = float(np.median(mag))
    return Lobes(
        points=pts, areas=areas, flux=med, spread=float((mag.max() - mag.min()) / med) if med > 0 else math.inf
    )
