"""Lyapunov exponents of a return map (both models): both exponents of the 2-D map with their
convergence and error, and the finite-time field over a grid (FTLE).

The tangent product comes from ``iterate(record=("jacobian",))`` (in C++, QR-renormalised); here
it is carried across blocks of steps (Benettin's method: the frame of the last block is the start
of the next), so each block's growth is that of the same evolving frame: the block exponents are
the terms of the time average, and their spread gives the error of the mean (batch means).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._checks import _short, check_memory, integer, is_choice, point_pair
from .._display import Summarized, status_counts
from .._enums import Status
from .._io.serial import Saveable
from ..interface import require_map
from . import _tangent as T

__all__ = ["LyapunovResult", "lyapunov", "FTLEField", "ftle_field"]

MAX_STEPS = 10**10
#: Angle of lyapunov()'s first tangent vector from the angle axis, in rad (any value away from
#: 0 and pi / 2 and pi: not a coordinate direction).
_FRAME_ANGLE = 1.0

#: Memory of one start of :func:`ftle_field`, counted at most: its meshgrid coordinates, the
#: iteration's records (final state, status, Jacobian product in QR form: ~100 bytes), and the
#: (n, 2, 2) arrays of the singular-value step and their temporaries, twice backward (the
#: reversor's Jacobians). Measured: 235 bytes (forward) and 290 (backward) at the peak.
FTLE_BYTES_PER_START = 512


@dataclass(frozen=True, repr=False)
class LyapunovResult(Summarized, Saveable):
    """Both Lyapunov exponents of each orbit (:func:`lyapunov`), per step of the map.

    Attributes
    ----------
    phi0, K0 : ndarray
        The starts (after the transient: where the measured steps begin).
    exponents : ndarray
        ``(n_orbits, 2)``: ``lambda_1 >= lambda_2``, the mean log stretch per step over the steps
        taken (per return of the flow).
    error : ndarray
        ``(n_orbits, 2)``: one standard error of each, from the spread of the block exponents
        (batch means; meaningful when a block is longer than the orbit's correlation time).
    sum : ndarray
        ``lambda_1 + lambda_2`` per orbit: the mean ``log det J`` per step, 0 for an
        area-preserving map (the measured value is the Jacobians' departure from it).
    history : ndarray
        ``(n_orbits, n_blocks)``: the running estimate of lambda_1 after each block (its
        convergence; ``history_steps`` gives the steps).
    history_steps : ndarray of int64
        Steps taken at the end of each block.
    blocks : ndarray
        ``(n_orbits, n_blocks, 2)``: each block's exponents.
    steps_done : ndarray of int64
        Measured steps per orbit (fewer than asked if the orbit stopped).
    status : ndarray of int8
        :class:`Status` of each orbit (an orbit that stops early keeps the exponents of the steps
        it took).
    n_steps, transient : int
        Steps asked for (after the transient) and the transient.
    """

    phi0: np.ndarray
    K0: np.ndarray
    exponents: np.ndarray
    error: np.ndarray
    sum: np.ndarray
    history: np.ndarray
    history_steps: np.ndarray
    blocks: np.ndarray
    steps_done: np.ndarray
    status: np.ndarray
    n_steps: int
    transient: int

    @property
    def largest(self) -> np.ndarray:
        """lambda_1 of each orbit."""
        return self.exponents[:, 0]

    def _summary(self) -> list:
        lam = self.exponents[:, 0]
        ok = np.isfinite(lam)
        out: list[tuple[str, object]] = [("n_orbits", lam.size), ("n_steps", self.n_steps)]
        if ok.any():
            out.append(("lambda_1", f"{np.min(lam[ok]):.4g}..{np.max(lam[ok]):.4g}"))
            out.append(("max |sum|", f"{np.nanmax(np.abs(self.sum)):.2g}"))
        out.append(("status", status_counts(self.status, Status)))
        return out


def _carry(Q, logs, seg_q, seg_log, seg_u):
    """Multiply the carried frame (rotations Q, accumulated logs) by the blocks' products
    M_b = Q_b diag(e^L1, e^L2) [[1, u], [0, 1]], scaled by e^-L1 (no overflow): the new frame and
    each block's two log stretches of the frame. Vectorised over orbits."""
    n = Q.shape[0]
    Rb = np.zeros((n, 2, 2))
    Rb[:, 0, 0] = 1.0
    Rb[:, 0, 1] = seg_u
    with np.errstate(over="ignore", under="ignore"):
        Rb[:, 1, 1] = np.exp(seg_log[:, 1] - seg_log[:, 0])
    A = np.einsum("nij,njk,nkl->nil", seg_q, Rb, Q)
    r11 = np.hypot(A[:, 0, 0], A[:, 1, 0])
    c, s = A[:, 0, 0] / r11, A[:, 1, 0] / r11
    Qn = np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)
    # r22 = det A / r11 and det A = e^(L2 - L1) exactly (rotations have determinant 1): the second
    # stretch from the logs, not from A's underflowing corner (L2 - L1 = -3000 in a chaotic block).
    with np.errstate(divide="ignore"):
        stretch = np.stack([seg_log[:, 0] + np.log(r11), seg_log[:, 1] - np.log(r11)], -1)
    return Qn, logs + stretch, stretch


def lyapunov(m, phi, K, n_steps: int, *, n_blocks: int = 20, transient: int = 0, n_threads: int = 0) -> LyapunovResult:
    """Both Lyapunov exponents of orbits of a map, with their convergence and error.

    The orbits are followed ``n_steps`` steps (after ``transient`` unmeasured ones) in
    ``n_blocks`` blocks; each block is one batched ``iterate`` with the Jacobian product (C++,
    threaded), carried on from the last block's frame (Benettin's QR method). lambda_1 is the
    growth rate of a tangent vector (started 1 rad off the axes: the angle axis is a regular
    orbit's neutral direction), lambda_2 that of areas minus lambda_1: their sum is the
    mean ``log det J``, 0 for an area-preserving map, reported as measured.

    Parameters
    ----------
    m : TruncatedMap, TruncatedFamily or FlowMap
        The map.
    phi, K : array_like or float
        Starts (broadcast together).
    n_steps : int
        Measured steps per orbit, >= n_blocks.
    n_blocks : int, optional
        Blocks (>= 2: the error estimate needs two), each of ``n_steps // n_blocks`` steps (the
        remainder joins the last).
    transient : int, optional
        Steps taken first and not measured (the frame starts aligned to nothing in particular:
        the first steps' exponents are biased; the transient also moves the start onto its
        attractor, for a dissipative perturbation).
    n_threads : int, optional
        Worker threads (0: all cores).

    Returns
    -------
    LyapunovResult

    Raises
    ------
    ValueError
        For a bad map, points, step counts or thread count.
    KeyboardInterrupt
        On Ctrl-C (from the core's iteration).

    Examples
    --------
    The standard map at k = 10 (the truncated map above K = 0, eps tau0 = 10): chaotic, lambda_1
    close to Chirikov's log(k / 2) = 1.609:

    >>> import numpy as np, hovering
    >>> sm = hovering.TruncatedMap(eps=10.0, Omega0=0.3, theta_w=2.0, K_max=1e5)
    >>> ly = hovering.lyapunov(sm, 0.5, 5000.0, 20_000)
    >>> lam1, lam2 = ly.exponents[0]
    >>> bool(abs(lam1 - 1.62) < 0.05), bool(abs(ly.sum[0]) < 1e-12)
    (True, True)
    """
    require_map("m", m)
    p, k, _ = point_pair(phi, K, "lyapunov")
    p, k = p.ravel().astype(float), k.ravel().astype(float)
    n_blocks = integer("n_blocks", n_blocks, 2, 100_000)
    n_steps = integer("n_steps", n_steps, n_blocks, MAX_STEPS)
    transient = integer("transient", transient, 0, MAX_STEPS)
    n_threads = integer("n_threads", n_threads, 0, 4096)
    n = p.size
    status = np.zeros(n, dtype=np.int8)
    if transient:
        r = m.iterate(p, k, transient, record=(), n_threads=n_threads)
        p, k, status = r.phi_final.copy(), r.K_final.copy(), np.asarray(r.status, dtype=np.int8).copy()
    phi0, K0 = p.copy(), k.copy()
    # The first tangent vector starts 1 rad off the axes, not along the angle's: in the maps'
    # action-angle coordinates that axis is a twist's neutral direction (J e1 = e1 where the orbit
    # is regular), whose growth a regular orbit's lambda_1 then reported: ~0 or below, under
    # lambda_2 (-0.0040 +- 0.0008 against +0.0040 over 500 returns of a flow map in section
    # coordinates), where any other start grows like the twist, log(n tau) / n.
    c, s_ = math.cos(_FRAME_ANGLE), math.sin(_FRAME_ANGLE)
    Q = np.broadcast_to(np.array([[c, -s_], [s_, c]]), (n, 2, 2)).copy()
    logs = np.zeros((n, 2))
    steps = np.zeros(n, dtype=np.int64)
    base = n_steps // n_blocks
    blocks = np.full((n, n_blocks, 2), np.nan)
    history = np.full((n, n_blocks), np.nan)
    hsteps = np.zeros(n_blocks, dtype=np.int64)
    for b in range(n_blocks):
        L = base + (n_steps - base * n_blocks if b == n_blocks - 1 else 0)
        live = status == int(Status.OK)
        if live.any():
            seg = m.iterate(p[live], k[live], L, record=("jacobian",), n_threads=n_threads)
            Qn, ln, stretch = _carry(Q[live], logs[live], seg.jacobian_q, seg.jacobian_log, seg.jacobian_r12)
            done = np.asarray(seg.steps_done)
            idx = np.flatnonzero(live)
            Q[idx], logs[idx] = Qn, ln
            steps[idx] += done
            with np.errstate(invalid="ignore", divide="ignore"):
                blocks[idx, b] = stretch / np.maximum(done, 1)[:, None]
            blocks[idx[done == 0], b] = np.nan
            p[idx], k[idx] = seg.phi_final, seg.K_final
            st = np.asarray(seg.status, dtype=np.int8)
            status[idx] = st
            bad = (seg.jacobian_status != int(Status.OK)) & (seg.jacobian_status != int(Status.CORNER))
            status[idx[bad & (st == int(Status.OK))]] = int(Status.NON_FINITE)
        hsteps[b] = hsteps[b - 1] + L if b else L
        with np.errstate(invalid="ignore", divide="ignore"):
            history[:, b] = np.where(steps > 0, logs[:, 0] / steps, np.nan)
    with np.errstate(invalid="ignore", divide="ignore"):
        exps = np.where(steps[:, None] > 0, logs / np.maximum(steps, 1)[:, None], np.nan)
        # Batch means: the standard error of the block exponents' mean (blocks an orbit took).
        fin = np.isfinite(blocks)
        nb = fin[:, :, 0].sum(axis=1)
        mean = np.where(fin, blocks, 0.0).sum(axis=1) / np.maximum(nb, 1)[:, None]
        var = np.where(fin, (blocks - mean[:, None, :]) ** 2, 0.0).sum(axis=1) / np.maximum(nb - 1, 1)[:, None]
        err = np.sqrt(var / np.maximum(nb, 1)[:, None])
    err[nb < 2] = np.nan
    return LyapunovResult(
        phi0=phi0,
        K0=K0,
        exponents=exps,
        error=err,
        sum=exps.sum(axis=1),
        history=history,
        history_steps=hsteps,
        blocks=blocks,
        steps_done=steps,
        status=status,
        n_steps=n_steps,
        transient=transient,
    )


def _reversor_jacobian(m, phi, K):
    """D R0 at each point, (n, 2, 2): [[-1, 0], [dK'/dphi, 1]], the K part's slope by a central
    difference of the reversor's closed form (smooth: error ~1e-12)."""
    phi = np.asarray(phi, dtype=float)
    K = np.asarray(K, dtype=float)
    h = 1e-6
    _, a = T.reversor(m, phi + h, K)
    _, b = T.reversor(m, phi - h, K)
    out = np.zeros((phi.size, 2, 2))
    out[:, 0, 0] = -1.0
    out[:, 1, 1] = 1.0
    out[:, 1, 0] = (np.asarray(a) - np.asarray(b)).ravel() / (2 * h)
    return out


@dataclass(frozen=True, repr=False)
class FTLEField(Summarized, Saveable):
    """The finite-time Lyapunov exponent over a grid of starts (:func:`ftle_field`).

    Attributes
    ----------
    phi, K : ndarray
        The grid's axes, shapes ``(n_phi,)`` and ``(n_K,)``.
    ftle : ndarray
        ``(n_K, n_phi)``: ``log sigma_1(D F^n) / n`` at each start (sigma_1 the largest singular
        value of the n-step Jacobian; the image's rows are K); NaN where the orbit stopped before
        n steps (see ``status``). Ridges mark the stable manifolds (forward) or the unstable ones
        (backward) of hyperbolic sets: the separatrices of the transport.
    status : ndarray of int8
        ``(n_K, n_phi)``: :class:`Status` of each orbit.
    n_steps : int
        The finite time n.
    direction : str
        ``"forward"`` (F^n) or ``"backward"`` (F^-n).
    """

    phi: np.ndarray
    K: np.ndarray
    ftle: np.ndarray
    status: np.ndarray
    n_steps: int
    direction: str

    def _summary(self) -> list:
        v = self.ftle[np.isfinite(self.ftle)]
        out: list[tuple[str, object]] = [
            ("grid", f"{self.K.size} x {self.phi.size}"),
            ("n_steps", self.n_steps),
            ("direction", self.direction),
        ]
        if v.size:
            out.append(("ftle", f"{v.min():.3g}..{v.max():.3g}"))
        out.append(("status", status_counts(self.status.ravel(), Status)))
        return out


def ftle_field(m, phi, K, n_steps: int, *, direction: str = "forward", n_threads: int = 0) -> FTLEField:
    """The finite-time Lyapunov exponent of every start of a grid: an image of the transport's
    skeleton.

    One batched ``iterate`` of all starts with the Jacobian product (C++, threaded):
    ``FTLE = log sigma_1(D F^n) / n``, sigma_1 the largest singular value, from the product's QR
    form (scaled: no overflow). Backward (``F^-n``): both models are reversible,
    ``F^-n = R0 F^n R0`` with ``R0(phi, K) = (-phi, K - eps f(phi))``, so the backward product at
    x is ``D R0 . D F^n(R0 x) . D R0``, computed from the forward iteration of ``R0(x)``.

    Parameters
    ----------
    m : TruncatedMap, TruncatedFamily or FlowMap
        The map.
    phi, K : array_like
        The grid's axes (1-D; the field is their product, K the rows).
    n_steps : int
        The finite time n >= 1.
    direction : {"forward", "backward"}, optional
        F^n (ridges: stable manifolds) or F^-n (ridges: unstable manifolds).
    n_threads : int, optional
        Worker threads (0: all cores).

    Returns
    -------
    FTLEField

    Raises
    ------
    ValueError
        For axes that are not 1-D finite arrays, a bad n_steps or direction, or a grid too large
        for this machine's memory (at 512 bytes a start, more than half of it), before anything is
        allocated.

    Examples
    --------
    >>> import numpy as np, hovering
    >>> sm = hovering.TruncatedMap(eps=0.9, Omega0=0.3, theta_w=2.0)
    >>> f = hovering.ftle_field(sm, np.linspace(-np.pi, np.pi, 64), np.linspace(5.0, 7.0, 48), 30)
    >>> f.ftle.shape, bool(np.all(f.status == hovering.Status.OK))
    ((48, 64), True)
    """
    require_map("m", m)
    ax_p, ax_k = np.asarray(phi, dtype=float), np.asarray(K, dtype=float)
    if ax_p.ndim != 1 or ax_k.ndim != 1 or ax_p.size < 1 or ax_k.size < 1:
        raise ValueError(f"phi and K must be 1-D axes of the grid, got shapes {ax_p.shape} and {ax_k.shape}")
    n_steps = integer("n_steps", n_steps, 1, MAX_STEPS)
    if not is_choice(direction, ("forward", "backward")):
        raise ValueError(f"direction must be 'forward' or 'backward', got {_short(direction)}")
    n_threads = integer("n_threads", n_threads, 0, 4096)
    # Before the meshgrid, the first allocation of the grid's size (1e5 x 1e5 asked for 75 GiB).
    check_memory(
        f"ftle_field over a {ax_k.size} x {ax_p.size} grid ({ax_k.size * ax_p.size} starts, at most "
        f"{FTLE_BYTES_PER_START} bytes each)",
        ax_k.size * ax_p.size * FTLE_BYTES_PER_START,
    )
    P, Kg = np.meshgrid(ax_p, ax_k)
    p, k, _ = point_pair(P.ravel(), Kg.ravel(), "ftle_field")
    if direction == "backward":
        B = _reversor_jacobian(m, p, k)
        p, k = T.reversor(m, p, k)
        p, k = np.asarray(p, dtype=float), np.asarray(k, dtype=float)
    r = m.iterate(p, k, n_steps, record=("jacobian",), n_threads=n_threads)
    # D F^n = Q e^L1 R' with R' = [[1, u], [0, e^(L2 - L1)]] (no overflow); backward, D F^-n(x) =
    # D R0(F^n R0 x) D F^n(R0 x) D R0(x). sigma_1 from the 2x2 Gram matrix.
    n = p.size
    Rs = np.zeros((n, 2, 2))
    Rs[:, 0, 0] = 1.0
    Rs[:, 0, 1] = r.jacobian_r12
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        Rs[:, 1, 1] = np.exp(r.jacobian_log[:, 1] - r.jacobian_log[:, 0])
        A = np.einsum("nij,njk->nik", r.jacobian_q, Rs)
        if direction == "backward":
            A = np.einsum("nij,njk,nkl->nil", _reversor_jacobian(m, r.phi_final, r.K_final), A, B)
        G = np.einsum("nji,njk->nik", A, A)
        tr, det = G[:, 0, 0] + G[:, 1, 1], G[:, 0, 0] * G[:, 1, 1] - G[:, 0, 1] * G[:, 1, 0]
        s1 = 0.5 * (tr + np.sqrt(np.maximum(tr * tr - 4 * det, 0.0)))
        val = (r.jacobian_log[:, 0] + 0.5 * np.log(s1)) / n_steps
    st = np.asarray(r.status, dtype=np.int8)
    val = np.where(st == int(Status.OK), val, np.nan)
    shape = (ax_k.size, ax_p.size)
    return FTLEField(
        phi=ax_p,
        K=ax_k,
        ftle=val.reshape(shape),
        status=st.reshape(shape),
        n_steps=n_steps,
        direction=direction,
    )
