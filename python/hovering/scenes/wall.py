"""The flow near the step's corner: the corner's incoming directions and the wall section.

The appendix of the paper (sec:constructret, sec:proofofcornersing) studies the return map
through the wall section ``Sigma_h^{w,-} = {q1 = qw1, p1 < 0, H = h}`` in the wall coordinates
``(theta, rho_w)``: theta the angle of (q2, p2) under the unperturbed action-angle map S2 (theta = 0
at p2 = 0, q2 maximal; sign(theta) = -sign(p2)), ``rho_w = I_tan^{eps,-}(theta) - I`` (eq:rhow),
where ``I = I_tan^{eps,-}(theta)`` is the tangency line on which p1 = 0 (eq:XiwallepsI). The corner
is reached from three directions only (eq:p2corner): ``p_R0 = (-p1w, P2)``, ``p_01 = (p1w, -P2)``,
``p_1R = (-p1w, -P2)``.

Here: those states, and the two flow operations the scene kinds ``corner_directions``,
``wall_tangency`` and ``wall_section`` are built of, on the core's batch return map:

* :meth:`WallFlow.preimage`: the point of Sigma_h whose smooth-flow segment passes through a given
  state (a corner state, a point of the wall section), by time reversal (lem:timerevgen);
* :meth:`WallFlow.labels`: the region (J_R, J_0, J_1, ...) of the step system's return through
  each point of the wall section (the wall images ``J_a^{eps,-}`` of the regions).
"""

from __future__ import annotations

import math

import numpy as np

from .._core import flow as _core_flow
from .._enums import FlowStatus, Region
from ..flow.section import flow_options
from ..flow.system import StepSystem
from ..interface import trajectory_arguments

__all__ = [
    "DIRECTIONS",
    "corner_energy",
    "corner_speed",
    "corner_states",
    "tangent_action",
    "rho_w_max",
    "wall_tangency_action",
    "wall_states",
    "WallFlow",
]

#: The incoming directions of the corner (Def:corner_curve), in the paper's order.
DIRECTIONS = ("R0", "01", "1R")
#: Signs of (p1, p2) of each direction: p_R0 = (-p1w, P2), p_01 = (p1w, -P2), p_1R = (-p1w, -P2).
_SIGNS = {"R0": (-1.0, 1.0), "01": (1.0, -1.0), "1R": (-1.0, -1.0)}
#: Time reversal of a state (q1, p1, q2, p2).
_REVERSE = np.array([1.0, -1.0, 1.0, -1.0])


def corner_energy(sys: StepSystem) -> float:
    """``h_eps^w = V1(qw1) + V2(qw2) + eps Vc(qw1, qw2)`` (def:heps): the energy at rest at the corner.

    Parameters
    ----------
    sys : StepSystem
        The system.

    Returns
    -------
    float
        The core's energy of the state ``(qw1, 0, qw2, 0)``.
    """
    return float(sys.core.energy(np.array([[sys.qw1, 0.0, sys.qw2, 0.0]]))[0])


def corner_speed(sys: StepSystem, h: float) -> float:
    """``p1w_max = sqrt(2 (h - h_eps^w))``: the largest horizontal speed at the corner (eq:p2corner).

    Parameters
    ----------
    sys : StepSystem
        The system.
    h : float
        Energy, above :func:`corner_energy`.

    Returns
    -------
    float
    """
    return math.sqrt(2.0 * (h - corner_energy(sys)))


def corner_states(sys: StepSystem, h: float, direction: str, p1w) -> np.ndarray:
    """States at the corner with the incoming momentum ``p_ab`` of ``direction`` (eq:p2corner).

    Parameters
    ----------
    sys : StepSystem
        The system.
    h : float
        Energy.
    direction : {"R0", "01", "1R"}
        Which direction.
    p1w : array_like
        Horizontal speeds in ``[0, p1w_max]``.

    Returns
    -------
    ndarray
        Shape (n, 4): ``(qw1, +-p1w, qw2, +-P2)``.
    """
    s1, s2 = _SIGNS[direction]
    p1 = np.atleast_1d(np.asarray(p1w, dtype=float))
    P2 = np.sqrt(np.maximum(corner_speed(sys, h) ** 2 - p1**2, 0.0))
    return np.column_stack([np.full_like(p1, sys.qw1), s1 * p1, np.full_like(p1, sys.qw2), s2 * P2])


def tangent_action(sys: StepSystem, h: float) -> float:
    """The unperturbed tangent action ``I_tan(h) = H2^{-1}(h - V1(qw1))`` (eq:Itan).

    Parameters
    ----------
    sys : StepSystem
        The system.
    h : float
        Energy.

    Returns
    -------
    float
    """
    return float(sys.V2.action(h - sys.V1.V(sys.qw1)))


def rho_w_max(sys: StepSystem, h: float) -> float:
    """``rho_max(h) = min(I_tan(h) - H2^{-1}(h2^w), H2^{-1}(h) - I_tan(h)) / 2`` (eq:rhomaxh).

    Circles ``rho_w = const`` with ``0 < rho_w <= rho_max`` cross the line q2 = qw2 transversely,
    twice (the paper's factor 1/2 is its margin).

    Parameters
    ----------
    sys : StepSystem
        The system.
    h : float
        Energy, above the step energy.

    Returns
    -------
    float
    """
    It = tangent_action(sys, h)
    return 0.5 * min(It - float(sys.V2.action(sys.V2.V(sys.qw2))), float(sys.V2.action(h)) - It)


def wall_tangency_action(sys: StepSystem, h: float, theta) -> np.ndarray:
    """``I_tan^{eps,-}(theta)``: the action of the wall's tangency line at angle theta (eq:XiwallepsI).

    The root of ``H2(I) + eps Vc(qw1, q2(theta, I)) = h - V1(qw1)``: ``I_tan(h)`` itself at eps = 0;
    otherwise found by bisection in ``I in [I_tan / 2, 3 I_tan / 2]`` (to 1e-15 relative).

    Parameters
    ----------
    sys : StepSystem
        The system.
    h : float
        Energy.
    theta : array_like
        Angles in [-pi, pi].

    Returns
    -------
    ndarray

    Raises
    ------
    ValueError
        If the root is not bracketed at some angle (eps too large for a tangency line near the
        unperturbed one).
    """
    th = np.atleast_1d(np.asarray(theta, dtype=float))
    It = tangent_action(sys, h)
    if sys.eps == 0 or sys.coupling is None:
        return np.full(th.shape, It)
    E = h - sys.V1.V(sys.qw1)

    def G(I):
        out = np.empty(th.shape)
        for k, (t, i) in enumerate(zip(th, I)):
            e2 = sys.V2.energy(float(i))
            q2 = sys.V2.point_at(float(t), e2)[0]
            out[k] = e2 + sys.eps * sys.coupling(sys.qw1, q2) - E
        return out

    lo, hi = np.full(th.shape, 0.5 * It), np.full(th.shape, 1.5 * It)
    bad = ~((G(lo) < 0) & (G(hi) > 0))
    if bad.any():
        t = float(th[np.argmax(bad)])
        raise ValueError(
            f"the wall's tangency line has no action in [I_tan/2, 3 I_tan/2] at theta = {t:.6g} "
            f"(eps = {sys.eps:g}); allowed: an eps small enough for the line to stay near the unperturbed "
            f"one"
        )
    while True:
        mid = 0.5 * (lo + hi)
        if not np.any((mid > lo) & (mid < hi) & (hi - lo > 1e-15 * It)):
            return mid
        up = G(mid) > 0
        hi = np.where(up, mid, hi)
        lo = np.where(up, lo, mid)


def wall_states(sys: StepSystem, h: float, theta, rho_w, I_tan=None) -> np.ndarray:
    """States ``z_-^w(theta, rho_w) = (qw1, p1 < 0, q2, p2)`` of the wall section (eq:defqpstar).

    ``(q2, p2) = S2^{-1}(theta, I_tan^{eps,-}(theta) - rho_w)``, ``p1 = -sqrt(2 Upsilon)`` with
    ``Upsilon = h - V1(qw1) - H2 - eps Vc(qw1, q2)`` (eq:pstarex).

    Parameters
    ----------
    sys : StepSystem
        The system.
    h : float
        Energy.
    theta : array_like
        Angles in [-pi, pi].
    rho_w : float or array_like
        Action distances to the tangency line (broadcast with theta); > 0 inside the wall section.
    I_tan : array_like, optional
        ``I_tan^{eps,-}(theta)`` if already known (default: :func:`wall_tangency_action`).

    Returns
    -------
    ndarray
        Shape (n, 4); rows of NaN where ``Upsilon < 0`` or the action is not positive (no point of
        the wall section).
    """
    th, rho = np.broadcast_arrays(np.atleast_1d(np.asarray(theta, dtype=float)), np.asarray(rho_w, dtype=float))
    It = (
        wall_tangency_action(sys, h, th) if I_tan is None else np.broadcast_to(np.asarray(I_tan, dtype=float), th.shape)
    )
    z = np.full(th.shape + (4,), np.nan)
    E = h - sys.V1.V(sys.qw1)
    for k, (t, I) in enumerate(zip(th.ravel(), (It - rho).ravel())):
        if not I > 0:
            continue
        e2 = sys.V2.energy(float(I))
        q2, p2 = sys.V2.point_at(float(t), e2)
        ups = E - e2 - (sys.eps * sys.coupling(sys.qw1, q2) if sys.eps != 0 and sys.coupling is not None else 0.0)
        # On the tangency line (rho_w = 0) Upsilon is 0 up to the rounding of I_tan^{eps,-}.
        if ups >= -1e-12 * max(1.0, abs(E)):
            z.reshape(-1, 4)[k] = (sys.qw1, -math.sqrt(2.0 * max(ups, 0.0)), q2, p2)
    return z.reshape(-1, 4)


class WallFlow:
    """The flow operations of the corner and wall-section scenes, on the core's batch return map.

    Parameters
    ----------
    sys : StepSystem
        The step system (its returns give the region labels and the drawn trajectories).
    options : dict
        Integrator settings: keyword arguments of :func:`~hovering.flow.section.flow_options`
        (``stepper``, ``rtol``, ``atol``, ``event_tol``, ... as :attr:`FlowMap.integrator_options`).

    Attributes
    ----------
    work : dict
        The core's work counters summed per stage (``"smooth"``: the time-reversed traces, which
        meet no wall; ``"step"``: the step system's returns).
    """

    def __init__(self, sys: StepSystem, options: dict):
        self.sys = sys
        self.smooth = sys.replace(geometry="none")
        self.options = flow_options(**options)
        self.options.validate_for(sys.core)
        self.work = {"smooth": {}, "step": {}}

    def _run(self, sys: StepSystem, z, stage: str, trajectory_dt=None) -> dict:
        z = np.ascontiguousarray(np.asarray(z, dtype=float).reshape(-1, 4))
        dt, per_orbit = (
            (0.0, 0) if trajectory_dt is None else trajectory_arguments(trajectory_dt, 2_000_000, max(z.shape[0], 1))
        )
        d = _core_flow.return_maps(sys.core, z, self.options, 0, dt, per_orbit)
        w = self.work[stage]
        for k, v in d["work"].items():
            w[k] = w.get(k, 0) + int(v)
        if d["interrupted"]:
            raise KeyboardInterrupt("interrupted while tracing the flow near the step")
        return d

    def preimage(self, z) -> tuple:
        """The points of Sigma_h whose smooth-flow segments pass through the states z, and when.

        A state z with q1 = qw1 is reached from Sigma_h (q1's maximum) either directly, q1
        decreasing (p1 < 0: the right-incoming corner directions, the wall section), or after q1's
        minimum (p1 > 0: the direction p_01). Its time reversal, traced by the smooth flow, reaches
        Sigma_h at the reversal of that point; the core's return counts the crossing after q1's
        minimum, so for p1 < 0 the trace is reversed once more, one return back (lem:timerevgen).

        Parameters
        ----------
        z : array_like
            States (n, 4) with q1 = qw1 and p1 != 0.

        Returns
        -------
        z0 : ndarray
            Points of Sigma_h (n, 4) (NaN where a trace failed).
        T : ndarray
            Flight times from z0 to z.
        ok : ndarray of bool
            Where both traces returned.
        """
        z = np.asarray(z, dtype=float).reshape(-1, 4)
        a = self._run(self.smooth, z * _REVERSE, "smooth")
        z0, T = a["z"] * _REVERSE, a["time"].copy()
        ok = a["status"] == int(FlowStatus.OK)
        left = z[:, 1] < 0
        if left.any():
            b = self._run(self.smooth, a["z"][left] * _REVERSE, "smooth")
            z0[left], T[left] = b["z"], a["time"][left] - b["time"]
            ok[left] &= b["status"] == int(FlowStatus.OK)
        z0[~ok] = np.nan
        T[~ok] = np.nan
        return z0, T, ok

    def returns(self, z0, trajectory_dt=None, smooth: bool = False) -> dict:
        """One return of the step system from points z0 of Sigma_h (the core's per-orbit outcomes).

        Parameters
        ----------
        z0 : array_like
            Points of Sigma_h (n, 4).
        trajectory_dt : float or array_like, optional
            Record each return's flow at ``t = k dt``; an array gives each orbit its own spacing.
        smooth : bool, optional
            Follow the smooth flow instead (no walls: trajectories that only touch them).

        Returns
        -------
        dict
            The core's ``z``, ``time``, ``status``, ``region``, ``itinerary`` (and ``trajectories``:
            a list of (m, 5) arrays ``t, q1, p1, q2, p2`` with a spacing).
        """
        z0 = np.asarray(z0, dtype=float).reshape(-1, 4)
        sys, stage = (self.smooth, "smooth") if smooth else (self.sys, "step")
        if trajectory_dt is None:
            return self._run(sys, z0, stage)
        dts = np.broadcast_to(np.asarray(trajectory_dt, dtype=float), (z0.shape[0],))
        out = {k: [] for k in ("z", "time", "status", "region", "itinerary", "trajectories")}
        for i in range(z0.shape[0]):  # one spacing per call
            d = self._run(sys, z0[i], stage, float(dts[i]))
            for k in ("z", "time", "status", "region"):
                out[k].append(d[k][0])
            out["itinerary"].append(d["itinerary"][0])
            out["trajectories"].append(np.asarray(d["trajectory"]).reshape(-1, 5))
        return {k: (v if k in ("itinerary", "trajectories") else np.array(v)) for k, v in out.items()}

    def labels(self, zw) -> tuple:
        """Region label of the step system's return through each point of the wall section.

        Parameters
        ----------
        zw : array_like
            States (n, 4) of the wall section (NaN rows: no point; labelled ``"-"``).

        Returns
        -------
        labels : ndarray of str
            The return's itinerary (``"R"``, ``"0"``, ``"1"``, ``"11"``, ...), ``"?"`` where it did not
            return (a corner hit, grazing, a failed trace), ``"-"`` where there is no point.
        region : ndarray of int8
            The :class:`~hovering.Region` of each return (``NONE`` for ``"?"`` and ``"-"``).
        z0 : ndarray
            The points of Sigma_h the returns start from (NaN rows for ``"-"`` and failed traces).
        """
        zw = np.asarray(zw, dtype=float).reshape(-1, 4)
        lab = np.full(zw.shape[0], "-", dtype=object)
        region = np.full(zw.shape[0], int(Region.NONE), dtype=np.int8)
        z0 = np.full(zw.shape, np.nan)
        have = np.flatnonzero(np.isfinite(zw).all(axis=1))
        if have.size:
            p, _, ok = self.preimage(zw[have])
            lab[have] = "?"
            z0[have] = p
            if ok.any():
                r = self.returns(p[ok])
                done = r["status"] == int(FlowStatus.OK)
                idx = have[ok]
                lab[idx] = np.where(done, np.array(r["itinerary"], dtype=object), "?")
                region[idx] = np.where(done, r["region"], int(Region.NONE))
        return lab, region, z0
