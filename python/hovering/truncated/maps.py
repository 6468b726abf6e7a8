"""The truncated near-tangency map F_eps and the general family F_{eps1,eps2}.

Thin Python layers over the compiled classes of :mod:`hovering._core.truncated`: argument
conversion, broadcasting, enums and result objects. All numerics run in C++. :class:`IterateResult`
is shared with :class:`hovering.FlowMap`, whose iterations add the flow's own records.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable, Sequence

import numpy as np

from .._checks import (
    MAX_ANGLE,
    _real_value,
    check_memory,
    forcing_array,
    is_choice,
    plain_point,
    point_pair,
    real_array,
    real_number,
    require_angles,
    require_finite,
    thread_count,
)
from .._core import truncated as _core_truncated
from .._enums import Region
from .._io.records import reduce_record
from .._progress import check_progress, progress_bar
from ..interface import (
    IterateResult,
    MapAnalyses,
    StepJacobian,
    iterate_arguments,
    recorded_counts,
    transport_arguments,
)
from . import theory as _geo

__all__ = ["TruncatedMap", "TruncatedFamily", "IterateResult"]

_RECORD_KEYS = ("orbit", "regions", "rotation", "visited", "extrema", "residence", "jacobian")

#: Most points of a :class:`TruncatedFamily`'s K grid: the sweep plans' limit on a model's tables
#: (the core's plan reader, kMaxTable), so every family a plan can hold can be built here and no
#: other. The core samples the splines ~200 times per grid point to find the band, holding the GIL,
#: at ~7-14 us a point: 1e5 points take ~1 s (2 shared cores), 1e6 took 12 s and 0.5 GB.
MAX_GRID = 100_000

#: Narrowest J_1 the band below K = 0 must open, in rad: 2^10 roundings of an angle in [-pi, pi)
#: (ulp(pi) = 2^-51). J_1 is the arc that opens below the tangency (|J_1| = 2 lam sqrt(-K) for
#: TruncatedMap); one that never holds more than a few doubles is an arc no point can be placed in,
#: the model's impacting part below double-precision resolution.
_MIN_J1 = 2.0**-41

#: A step K + eps f(phibar) rounds K by up to 2^-53 |eps| max|f|; the band must be at least 2^10
#: such roundings tall (2^-43 |eps| max|f|), else a K in it keeps no digits through one step.
_KICK_ROUNDINGS = 2.0**-43


def _band_top(value) -> float:
    """The ``K_max`` argument: a real number > 0 or ``inf`` (no cap), checked as every parameter is
    (no strings, bools or None: :func:`hovering._checks.real_number`'s types), or a ValueError
    naming it and the range (0, inf]."""
    v = _real_value("K_max", value)
    if not v > 0:  # NaN too
        raise ValueError(f"K_max must be > 0 (or inf: no cap), got {v}")
    return v


class _MapAPI(MapAnalyses):
    """Methods shared by every member of the truncated family (mixed into the compiled classes)."""

    def _require_resolved(self, who: str, widest_J1: float, f_max: float, explain) -> None:
        """Refuse a band below double-precision resolution (both classes' constructors, after the core
        has found the band): J_1 must open to ``_MIN_J1`` inside it, and the band must be
        ``_KICK_ROUNDINGS`` of a kick ``|eps| f_max`` tall (``f_max`` bounds ``|f|``).
        ``explain()`` gives, for the message, what sets the band's floor and what would let J_1 open."""
        lo, hi = self.valid_band()
        if not widest_J1 >= _MIN_J1:
            floor, fix = explain()
            depth = 0.0 if lo == 0 else -lo
            where = (
                f"the band has no part below K = 0 (its lower end {lo!r} is set by {floor})"
                if depth == 0
                else f"the band below K = 0 is {depth:.3g} deep (its floor {lo!r} is set by {floor}), and J_1 "
                f"opens to at most {widest_J1:.3g} rad in it"
            )
            raise ValueError(
                f"{who}: {where}: J_1, the arc that opens below the tangency, must reach {_MIN_J1:.3g} rad (2^-41: "
                f"2^10 roundings of an angle) somewhere in the band, or no point can ever lie in it (the map's "
                f"impacting part is below double-precision resolution); allowed: {fix}"
            )
        kick = abs(self.eps) * f_max  # may overflow to inf: refused below, as it should be
        height = hi - lo
        if kick * _KICK_ROUNDINGS > height:
            floor = explain()[0]
            raise ValueError(
                f"{who}: eps = {self.eps!r} with the forcing's max|f| <= {f_max:.6g} kicks K by up to {kick:.3g} per "
                f"step, and a step rounds K by ~2^-53 of the kick, but the band ({lo!r}, {hi!r}) is only "
                f"{height:.3g} tall: below double-precision resolution (it must hold 2^10 roundings of a kick); "
                f"allowed: |eps| max|f| <= {height / _KICK_ROUNDINGS:.6g} for this band (2^43 x its height), i.e. "
                f"|eps| <= {height / _KICK_ROUNDINGS / f_max:.6g} with this forcing, or a taller band (its floor is "
                f"set by {floor})"
            )

    def step(self, phi, K):
        """One forward step ``(phi, K) -> (phibar, Kbar)``.

        Parameters
        ----------
        phi, K : array_like or float
            Points (broadcast together). ``K`` must lie in :meth:`valid_band`; ``|phi| <= 1e6``
            (wrapped to [-pi, pi) first).

        Returns
        -------
        phi1, K1 : ndarray or float
            Image points; ``phi1`` in ``[-pi, pi)``. Floats when both inputs are scalars.

        Raises
        ------
        ValueError
            For a non-finite value or a K outside the band (the message names it and the band).

        Notes
        -----
        Arcs are half-open and own their left ends: ``J_1 = [start_1, start_R)``,
        ``J_R = [start_R, start_0)``, ``J_0 = [start_0, start_1)`` on the circle, with the starts
        exactly the doubles :meth:`arcs` and :meth:`corner_curves` return; a point is placed by
        comparing it with them, so ``region(corner_curves(K)["1R"], K)`` is ``RIGHT``. (An arc
        shorter than the rounding of its ends - within ~1e-15 of the band floor, or |J_1| for
        ``|K| < ~1e-30`` - can hold no double; its start then lies in the next arc.) The SIMD
        kernel of :meth:`iterate` follows the same convention bit for bit.
        """
        if plain_point(phi, K):  # one point: a tuple from the core, no arrays (the same numbers)
            return self._step1(phi, K)
        p, k, scalar = point_pair(phi, K, "step")
        a, b = self._step(p, k)
        return (float(a), float(b)) if scalar else (a, b)

    def step_inverse(self, phi, K):
        """One backward step: the inverse of :meth:`step`, with the same boundary convention.

        Parameters
        ----------
        phi, K : array_like or float
            Image points; the preimage height ``K - eps f(phi)`` must lie in the band (up to the
            rounding of the forward step: every image :meth:`step` makes of a band point is
            accepted, also when ``K - eps f(phi)`` rounds onto the band's edge).

        Returns
        -------
        phi0, K0 : ndarray or float
            Preimages, ``phi0`` in ``[-pi, pi)``.

        Raises
        ------
        ValueError
            For a non-finite value or an image of no band height.

        Notes
        -----
        The image arcs ``F(J_a)`` are half-open like the arcs, each owning the image of its arc's
        start, so every start goes back to its arc: for a start ``s`` of :meth:`corner_curves`,
        ``step_inverse(*step(s, K))`` is ``(s, K)`` bit for bit unless step merges K with other
        heights. For step rounds ``phi + omega`` and ``K + eps f(phibar)``, so distinct doubles can
        share an image, and the inverse can return only one of them: at a height within ulp(Kbar)
        of K, and in phi within ~2 ulps of ``|phi| + |omega|`` plus what phi moves with that
        change of K (a lot near K = 0, where ``|J_1| = 2 lam sqrt(-K)``). For a start that is a
        point of the same arc - the start at its own height whenever one has exactly this image
        (searched for). A point within that rounding of
        an arc's *end* can share its image with the start of the next image arc, and comes back
        as that start; arcs shorter than the rounding (within ~1e-15 of the band floor, J_1 for
        ``|K| < ~1e-28``) can share their starts' images, and one of those starts comes back.
        """
        if plain_point(phi, K):  # one point: as step()
            return self._step_inverse1(phi, K)
        p, k, scalar = point_pair(phi, K, "step_inverse")
        a, b = self._step_inverse(p, k)
        return (float(a), float(b)) if scalar else (a, b)

    def jacobian(self, phi, K) -> StepJacobian:
        """One step of each point with its exact Jacobian ``d(phibar, Kbar) / d(phi, K)``.

        On the arc ``J_a`` that a point lies in, the map is ``phibar = phi + omega_a(K)``,
        ``Kbar = K + eps f(phibar)``, so ``J = [[1, w], [g, 1 + g w]]`` with ``w = omega_a'(K)`` and
        ``g = eps f'(phibar)``; ``det J = 1`` (area preservation) to rounding. The arc slopes:
        ``Omega' = tau0`` (J_0u, J_0), ``+ tau1`` (J_1), ``+ lam / sqrt(-K)`` (J_R: |J_1| =
        2 lam sqrt(-K) shrinks as K grows, a square-root singularity at the tangency K = 0-);
        a TruncatedFamily's are its splines' derivatives (|J_1|'s through sqrt(-K)).

        Parameters
        ----------
        phi, K : array_like or float
            Points (broadcast together), K in :meth:`valid_band`.

        Returns
        -------
        StepJacobian
            ``phi, K`` (the images, bit for bit :meth:`step`'s), ``J`` (shape ``(..., 2, 2)``),
            ``status`` (OK, or CORNER for a point exactly on an arc start: the map jumps there and
            ``J`` is the one-sided derivative of the arc that owns the start), ``region``.

        Raises
        ------
        ValueError
            As :meth:`step`: a non-finite value or a K outside the band.

        Examples
        --------
        >>> import numpy as np, hovering
        >>> m = hovering.TruncatedMap(eps=0.3, Omega0=hovering.OMEGA_G, theta_w=3 * np.pi / 4)
        >>> t = m.jacobian(0.3, -0.2)            # J_0: the standard map's Jacobian, twist tau0 = 1
        >>> t.region, t.status
        (<Region.ABOVE: 1>, <Status.OK: 0>)
        >>> np.round(t.J, 4)
        array([[ 1.    ,  1.    ],
               [-0.1999,  0.8001]])
        >>> print(f"{t.det:.15f}")
        1.000000000000000
        """
        p, k, scalar = point_pair(phi, K, "jacobian")
        shape = () if scalar else p.shape
        return StepJacobian.from_core(
            self._jacobian(np.ascontiguousarray(p.ravel()), np.ascontiguousarray(k.ravel())), shape
        )

    def region(self, phi, K):
        """Region of each point: which arc of the circle K it lies on.

        Parameters
        ----------
        phi, K : array_like or float
            Points in the band.

        Returns
        -------
        Region or ndarray of int8
            A :class:`Region` for scalar input, else an int8 array of region codes: BESIDE, ABOVE,
            UPPER or RIGHT (never ``Region.NONE``: every point of the band has its arc).

        Raises
        ------
        ValueError
            For a non-finite value or a K outside :meth:`valid_band`, as :meth:`step` (the map is
            not defined there; :meth:`hovering.FlowMap.region` answers ``Region.NONE`` instead,
            as its steps answer a status).
        """
        p, k, scalar = point_pair(phi, K, "region")
        r, _ = self._region_rotation(p, k, "region")
        return Region(int(r)) if scalar else r

    def rotation(self, phi, K):
        """The rotation ``omega_a(K)`` applied to each point (eq:omegaofadef), not reduced mod 2 pi.

        Parameters
        ----------
        phi, K : array_like or float
            Points in the band.

        Returns
        -------
        ndarray or float

        Raises
        ------
        ValueError
            For a non-finite value or a K outside :meth:`valid_band`, as :meth:`region`.
        """
        p, k, scalar = point_pair(phi, K, "rotation")
        _, w = self._region_rotation(p, k, "rotation")
        return float(w) if scalar else w

    def reversal(self, phi, K):
        """The time-reversal involution ``R_eps(phi, K) = (-phi, K - eps f(phi))`` (thm:reversalinkphi).

        ``R_eps F R_eps = F^{-1}`` holds for every member of the family (lem:truncreturnmap).

        Parameters
        ----------
        phi, K : array_like or float
            Points.

        Returns
        -------
        phi_r, K_r : ndarray or float
        """
        p, k, scalar = point_pair(phi, K, "reversal")
        require_angles("reversal: phi", p)
        require_finite("reversal: K", k)
        out = (_geo.wrap(-p), k - self.eps * self.forcing_at(p))
        return (float(out[0]), float(out[1])) if scalar else out

    def arcs(self, K):
        """Arc lengths and left ends of J_1, J_R, J_0 on the circles K (eq:Jdeftrunc, corrected).

        Parameters
        ----------
        K : array_like or float
            Heights in the band.

        Returns
        -------
        dict of ndarray
            ``len_1, len_R, len_0`` (|J_1|, |J_R|, |J_0|; 0, 0, 2 pi for K >= 0) and ``start_1,
            start_R, start_0`` (left ends in [-pi, pi), NaN for K >= 0). The left ends are the
            corner-singularity curves: ``start_1 = phi_01``, ``start_R = phi_1R``, ``start_0 = phi_R0``.
            Each arc owns its left end, and these are the exact doubles :meth:`step`,
            :meth:`region` and :meth:`iterate` compare with (see :meth:`step`).
        """
        k = np.ascontiguousarray(real_array("K", K).ravel())
        a = self._arcs(k)
        shape = np.shape(K)
        keys = ("len_1", "len_R", "len_0", "start_1", "start_R", "start_0")
        return {key: a[:, j].reshape(shape) for j, key in enumerate(keys)}

    def corner_curves(self, K):
        """The corner-singularity curves ``phi_01, phi_1R, phi_R0`` at heights K < 0 (thm:cornersing).

        Parameters
        ----------
        K : array_like
            Heights in the band (NaN is returned for K >= 0, where the arcs do not exist).

        Returns
        -------
        dict of ndarray
            Keys ``'01'``, ``'1R'``, ``'R0'``: angles in ``[-pi, pi)``, the left ends of J_1, J_R,
            J_0, each owned by that arc (``region(cc["1R"], K)`` is ``RIGHT``; see :meth:`step`).
        """
        a = self.arcs(K)
        return {"01": a["start_1"], "1R": a["start_R"], "R0": a["start_0"]}

    def iterate(
        self,
        phi0,
        K0,
        n_steps: int,
        record: Sequence[str] = ("orbit", "regions", "rotation"),
        exit_regions: Iterable | None = None,
        stop_on_exit: bool = False,
        n_threads: int = 0,
        kernel: str = "simd",
        sin_ulp: float = 1.0,
        progress=False,
        every: int = 1,
        stop=None,
    ) -> IterateResult:
        """Iterate many orbits at once in C++ (multi-threaded, GIL released).

        Parameters
        ----------
        phi0, K0 : array_like
            Initial points, broadcast together and flattened to ``n_orbits`` orbits; phi0 (|phi0| <= 1e6)
            is wrapped to [-pi, pi).
        n_steps : int
            Steps per orbit (>= 0).
        record : sequence of str, optional
            What to keep besides the final state and status: any of ``"orbit"`` (the states),
            ``"regions"`` (itinerary), ``"rotation"`` (rho = mean omega_a), ``"visited"`` (the set
            of regions each orbit went through, one byte per orbit), ``"extrema"`` (per orbit the
            least and greatest K reached, ``K_min``, ``K_max``), ``"residence"`` (per orbit the
            returns taken from each region, ``residence``), ``"jacobian"`` (per orbit the product
            of its steps' Jacobians, QR-renormalised: ``jacobian_q``, ``jacobian_log``,
            ``jacobian_r12``, ``jacobian_status``; see :class:`IterateResult` and
            :meth:`IterateResult.jacobian`). Nothing else is stored; the last four stream (a few
            numbers per orbit, whatever ``n_steps``), and none changes the orbit.
        exit_regions : iterable of Region or str, optional
            A set of regions (e.g. ``{"0u", "0"}``, the no-impact set) to watch: ``exit_step`` is
            the first n at which an orbit point lies outside it.
        stop_on_exit : bool, optional
            Stop an orbit (status ``EXITED``) when it first leaves ``exit_regions``: at the point
            ``x_{exit_step}``, whose return (the one that leaves the set) is recorded in
            ``region`` and ``residence`` but not taken.
        n_threads : int, optional
            Worker threads; 0 uses every core.
        kernel : {"simd", "scalar"}, optional
            ``"simd"``: Eigen arrays + SLEEF vector sin over chunks of orbits. ``"scalar"``: one
            orbit at a time with libm sin (the reference the SIMD path is tested against).
        sin_ulp : {1.0, 3.5}, optional
            Maximum error of the SIMD kernel's sin (SLEEF): 1.0 ulp (default) or 3.5 ulp, about
            20% faster per step. Either error (<4e-16 in K per step) is far below what the chaotic
            dynamics amplifies from any other rounding; the scalar kernel always uses libm.
        progress : bool or callable, optional
            ``True``: a tqdm bar on stderr (unit: step, total ``n_orbits * n_steps``; an orbit
            that stops early counts its remaining steps). A callable ``progress(done, total)`` is
            called every ~0.1 s and at the end. ``False`` (default): none, at no cost. See
            :mod:`hovering._progress`.
        every : int, optional
            Record every k-th state (default 1: all): ``phi``, ``K`` hold ``x_0, x_k, x_2k, ...``
            (``n_steps // k + 1`` columns) and ``region`` the returns from them (``ceil(n_steps /
            k)`` columns). The orbit is the same; only what is stored is thinned (the memory check
            before the run counts what is kept).
        stop : hovering.Above or hovering.Below, optional
            Stop each orbit the first time a state ``x_n`` lies in the set (``K >= curve(phi)``,
            resp. ``<=``, the curve a :class:`hovering.Curve` or a number): status ``STOPPED``,
            ``stop_step = n`` (-1 if never), final state ``x_n``. The start counts (``stop_step =
            0``). A state is tested as soon as it is reached, so a stop at n comes before an exit
            at the same n (an orbit takes no return from ``x_{stop_step}``); an image outside the
            band is ``ESCAPED``, never ``STOPPED``. Both kernels test it with the curve's own
            arithmetic (:meth:`hovering.Curve.__call__`), bit for bit.

        Returns
        -------
        IterateResult

        Raises
        ------
        ValueError
            For non-finite initial points, a negative ``n_steps``, an unknown ``record`` key,
            region or kernel, an ``every`` below 1, or a ``stop`` that is not Above / Below; and,
            before anything is allocated, for more starts (after broadcasting phi0 with K0) or
            records than half of this machine's memory holds, naming the count and the limit.
        KeyboardInterrupt
            On Ctrl-C during a long run; its ``partial`` attribute holds the IterateResult with
            every orbit's state at the interruption (status ``INTERRUPTED``).

        Notes
        -----
        An orbit whose image leaves the band stops with status ``ESCAPED`` and keeps that image
        as its final state; an initial point outside the band is ``ESCAPED`` after 0 steps. The
        band is where the rotation stays within |Omega| <= 1e6, so an orbit driven to larger
        rotations (huge K) is ``ESCAPED`` too, never an ``OK`` orbit with a meaningless phi.
        Both kernels compute phi and the region of every step as :meth:`step` does, bit for bit;
        K differs only through the sin implementation (SLEEF vs libm, ~1 ulp).

        Examples
        --------
        Four orbits started on the line L1 (where the invariant curves have their minima),
        1000 steps each:

        >>> import numpy as np, hovering
        >>> m = hovering.TruncatedMap(eps=0.3, Omega0=hovering.OMEGA_G, theta_w=3 * np.pi / 4)
        >>> K0 = np.array([-0.2, -0.1, 0.0, 0.1])
        >>> res = m.iterate(m.L1(K0), K0, 1000)
        >>> res.phi.shape, res.count(hovering.Status.OK)
        ((4, 1001), 4)
        >>> print(np.round(res.rotation, 3))     # rho, the mean rotation per step
        [3.852 3.954 4.056 4.154]

        Stop each orbit when it first reaches K >= 0.05 (only the state is kept, no orbit):

        >>> up = m.iterate(m.L1(K0), K0, 1000, record=(), stop=hovering.Above(0.05))
        >>> up.stop_step.tolist()                # the start counts: the last one starts above
        [1, 1, 1, 0]
        >>> up.count(hovering.Status.STOPPED)
        4
        """
        record, n_steps, mask = iterate_arguments(record, _RECORD_KEYS, n_steps, exit_regions, stop_on_exit)
        every, stop_side, stop_curve = transport_arguments(every, stop)
        progress = check_progress(progress)
        if not is_choice(kernel, ("simd", "scalar")):
            raise ValueError(f"kernel must be 'simd' or 'scalar', got {kernel!r}")
        if (
            isinstance(sin_ulp, (bool, np.bool_))
            or not isinstance(sin_ulp, numbers.Real)
            or float(sin_ulp) not in (1.0, 3.5)
        ):
            raise ValueError(f"sin_ulp must be 1.0 or 3.5 (max error of the SIMD sin in ulp), got {sin_ulp!r}")
        n_threads = thread_count(n_threads)
        p, k, _ = point_pair(phi0, K0, names=("phi0", "K0"))
        # point_pair checked |phi0| <= 1e6; both kernels wrap phi0 with the core's one wrap before
        # anything reads or records it (a wrap here too cost 6 of a one-step call's 24 us).
        p = np.asarray(p, dtype=float)
        n_states, n_returns = recorded_counts(n_steps, every)
        thinned = f" (every {every})" if every > 1 else ""
        check_memory(
            f"recording {record} for {p.size} orbits x {n_steps} steps{thinned}",
            16 * p.size * n_states * ("orbit" in record) + p.size * n_returns * ("regions" in record),
        )
        with progress_bar(progress, p.size * n_steps, desc=f"{type(self).__name__}.iterate", unit="step") as bar:
            d = self._iterate(
                np.ascontiguousarray(p.ravel()),
                np.ascontiguousarray(k.ravel()),
                n_steps,
                "orbit" in record,
                "regions" in record,
                "rotation" in record,
                mask,
                bool(stop_on_exit),
                int(n_threads),
                kernel,
                float(sin_ulp),
                "visited" in record,
                bar.part(0) or None,
                every,
                stop_side,
                stop_curve,
                "extrema" in record,
                "residence" in record,
                "jacobian" in record,
            )
        return IterateResult.from_core(d, self, n_steps, every)


class TruncatedMap(_MapAPI, _core_truncated.TruncatedMap):
    """The paper's truncated map F_eps (eq:truncatedmap), corrected as on the errata page (docs/guide/errata.md).

    ``Kbar = K + eps sin(phibar)``, ``phibar = phi + omega_a(K)`` for ``phi`` in the arc ``J_a(K)``;
    for ``K < 0`` the circle is cut into J_1 (length ``2 lam sqrt(-K)``), J_R (``2(pi - theta_w) +
    tau1 K``) and J_0, placed by eq:phi1rsymmetric so that the map is reversible.

    Parameters
    ----------
    eps : float
        Perturbation amplitude: any finite value with ``|eps| <= 2^43 (K_hi - K_lo)`` for the band
        ``(K_lo, K_hi)`` of :meth:`valid_band` (see Notes; the paper studies |eps| <= 0.92).
        0 is F_0.
    Omega0 : float
        Rotation at the tangency circle, ``|Omega0| <= 1e6``. The band also ends where
        ``|Omega0 + tau0 K|`` reaches 1e6: one step rounds phi + Omega, and the 2 pi n it
        subtracts, to ulps of |Omega|, so at 1e6 phi keeps ~2e-10 rad per step (4e-16 at
        |Omega| ~ 1); each decade of rotation beyond costs a decade of phi, and at 1e16 none is left.
    theta_w : float
        Wall angle, in the open interval (0, pi).
    tau0 : float, optional
        Twist (default 1): any finite value (0: no twist) for which the band below K = 0 is
        resolved (see Notes): with the rotation bound setting the band's floor at
        ``-(1e6 +- Omega0) / |tau0|``, ``|tau0| <~ 2e31 lam^2``.
    tau1 : float, optional
        Twist of the upper-wall reflection (default 0.5): any finite value for which the band
        below K = 0 is resolved (see Notes); where |J_R| closes first, at ``K = -2 (pi -
        theta_w) / tau1``, ``tau1 <~ 4e25 (pi - theta_w) lam^2``.
    lam : float, optional
        Square-root coefficient, > 0 (default 0.5), large enough that J_1 opens in the band (see
        Notes): ``lam >= 2^-42 / sqrt(-K_lo)``; and small enough that J_0, which closes near
        ``sqrt(-K) = theta_w / lam``, leaves a band below K = 0 that does.
    K_max : float, optional
        Upper end of the band, in (0, inf] (default inf: F_eps is the shifted standard map for
        K >= 0).

    Raises
    ------
    ValueError
        Naming the parameter, its value and the allowed range, for a value that is not a real
        number (a string, bool or None), non-finite parameters (K_max may be inf), |Omega0| > 1e6,
        theta_w outside (0, pi), lam <= 0, K_max <= 0, or a band below double-precision
        resolution (Notes; the message names the parameter that sets the band's floor and the
        bound it must meet).

    Notes
    -----
    The map is defined on the band of :meth:`valid_band`, where all three arcs have lengths in
    (0, 2 pi) and the rotation stays within 1e6. Two things must be resolvable in double
    precision there, or every analysis of the model would report rounding as structure:

    * J_1, the arc that opens below the tangency, must reach ``2^-41`` rad (``4.5e-13``: 2^10
      roundings of an angle in [-pi, pi)) inside the band, i.e. ``2 lam sqrt(-K_lo) >= 2^-41``
      (``-K_lo``: the band's depth below 0). A band that ends before (e.g. ``tau0 = 1e308``:
      depth 1e-302, J_1 at most 1e-151 rad), or a J_1 too thin for any band (``lam = 5e-324``),
      is an impacting part no point can lie in.
    * A step ``K + eps sin(phibar)`` rounds K by up to ``2^-53 |eps|``; the band must be at
      least 2^10 such roundings tall, ``K_hi - K_lo >= 2^-43 |eps|``, or no K in it keeps a digit
      through one step (``eps = 1e308``).

    Both are invariant under the rescaling ``K -> c K`` (eps -> c eps, tau0 -> tau0 / c, tau1 ->
    tau1 / c, lam -> lam / sqrt(c)), as the map is: they bound the parameters together, not in
    units of K. Denormal eps, tau0 or tau1 are accepted, as 0 is (F_0, no twist): they differ from
    it only by the roundings they cause.

    Examples
    --------
    The map of the paper's figures at eps = 0.3 (the sign that hovers):

    >>> import numpy as np, hovering
    >>> m = hovering.TruncatedMap(eps=0.3, Omega0=hovering.OMEGA_G, theta_w=3 * np.pi / 4)
    >>> m.region(0.3, -0.2)                  # J_0: passes above the step, no impact
    <Region.ABOVE: 1>
    >>> phi1, K1 = m.step(0.3, -0.2)
    >>> print(f"{phi1:.4f} {K1:.4f}")
    -2.3000 -0.4237
    >>> th = m.theory()                      # leading order: eq:hovsetsize, eq:kcrit, eq:rhocrit
    >>> th.hovers, round(th.area, 4), round(th.K_crit, 4), round(th.rho_crit, 4)
    (True, 0.7639, -0.2747, 3.7694)
    """

    def __init__(self, eps, Omega0, theta_w, tau0=1.0, tau1=0.5, lam=0.5, K_max=math.inf):
        vals = {"eps": eps, "Omega0": Omega0, "theta_w": theta_w, "tau0": tau0, "tau1": tau1, "lam": lam}
        vals = {name: real_number(name, v) for name, v in vals.items()}
        K_max = _band_top(K_max)
        _core_truncated.TruncatedMap.__init__(self, **vals, K_max=K_max)
        depth = -self.valid_band()[0]
        self._require_resolved("TruncatedMap", 2 * self.lam * math.sqrt(max(depth, 0.0)), 1.0, self._floor)

    def _floor(self) -> tuple:
        """What sets the band's lower end, in words, and what would let J_1 reach _MIN_J1 above it
        (for the message of :meth:`_require_resolved`; the core computes the band itself)."""
        Om, th, t0, t1, lam = self.Omega0, self.theta_w, self.tau0, self.tau1, self.lam
        half = _MIN_J1 / (2 * lam)
        need = half * half  # the depth at which 2 lam sqrt(-K) reaches _MIN_J1 (inf, not an error, on overflow)
        bound = (lambda x: x / need) if need > 0 else (lambda x: math.inf)  # noqa: E731 - lam ~1e300: need underflows
        cands = []  # (floor, what sets it, the bound that would move it below -need)
        if t0 != 0:
            room = MAX_ANGLE + Om if t0 > 0 else MAX_ANGLE - Om
            cands.append(
                (
                    -room / abs(t0),
                    f"tau0 = {t0!r}: the rotation bound |Omega0 + tau0 K| <= 1e6",
                    f"|tau0| <= {bound(room):.3g} with these Omega0 and lam"
                    if room > 0
                    else f"|Omega0| < 1e6 (Omega0 = {Om!r} leaves no rotation below K = 0), or tau0 = 0",
                )
            )
        if t1 > 0:
            cands.append(
                (
                    -2 * (math.pi - th) / t1,
                    f"tau1 = {t1!r}: |J_R| = 2 (pi - theta_w) + tau1 K closes",
                    f"tau1 <= {bound(2 * (math.pi - th)):.3g} with these theta_w and lam",
                )
            )
        disc = lam * lam - 2 * t1 * th
        if disc >= 0:
            s1 = 2 * th / (lam + math.sqrt(disc))
            cands.append(
                (
                    -s1 * s1,
                    f"|J_0| = 2 theta_w - tau1 K - 2 lam sqrt(-K) closing (theta_w = {th!r}, tau1 = {t1!r}, lam = {lam!r})",
                    "a larger theta_w, or a smaller lam or |tau1|",
                )
            )
        what, fix = ("the arcs", "a deeper band") if not cands else max(cands, key=lambda c: c[0])[1:]
        depth = -self.valid_band()[0]
        if depth > 0 and not what.startswith("|J_0|"):  # (where J_0 closes first, lam moves the floor)
            lam_fix = f"lam >= {_MIN_J1 / (2 * math.sqrt(depth)):.3g} with this band"
            # lam so small that J_1 stays thinner than _MIN_J1 in any band: only lam helps
            fix = lam_fix if math.isinf(need) else f"{fix}, or {lam_fix}"
        return what, fix

    def __repr__(self) -> str:
        return (
            f"TruncatedMap(eps={self.eps!r}, Omega0={self.Omega0!r}, theta_w={self.theta_w!r}, "
            f"tau0={self.tau0!r}, tau1={self.tau1!r}, lam={self.lam!r})"
        )

    @property
    def params(self) -> dict:
        """The six parameters as a dict (``eps, Omega0, theta_w, tau0, tau1, lam``)."""
        return dict(
            eps=self.eps, Omega0=self.Omega0, theta_w=self.theta_w, tau0=self.tau0, tau1=self.tau1, lam=self.lam
        )

    def forcing_at(self, phi):
        """The forcing ``f(phi) = sin(phi)``.

        Parameters
        ----------
        phi : array_like
            Angles.

        Returns
        -------
        ndarray or float
        """
        return np.sin(_angles("phi", phi))

    def L1(self, K):
        """Angle of the line L1 at heights K (def:L1L2); see :func:`hovering.truncated.theory.L1`."""
        return _geo.L1(K, self.Omega0, self.tau0)

    def L2(self, K):
        """Angle of the line L2 at heights K (def:L1L2); see :func:`hovering.truncated.theory.L2`."""
        return _geo.L2(K, self.Omega0, self.tau0)

    def K_crit(self) -> float:
        """eq:kcrit evaluated formally: the critical curve's height on L1 when ``eps sin(Omega0/2) > 0``.

        That is the hovering case at every Omega0 (f = sin, so b_1 = 1): for Omega0 in (2 pi, 4 pi)
        it is eps < 0 that hovers (the rule has period 4 pi in Omega0). For the other sign the value is positive and no hovering critical curve exists (thm:hovering);
        :meth:`theory` says so (``hovers``, ``note``) and gives NaN for ``K_crit`` there.
        """
        return float(_geo.K_crit(self.eps, self.theta_w, self.Omega0))

    def rho_crit(self) -> float:
        """eq:rhocrit evaluated formally (meaningful in the hovering case, see :meth:`K_crit`)."""
        return float(_geo.rho_crit(self.eps, self.theta_w, self.Omega0, self.tau0))

    def theory(self) -> _geo.Theory:
        """Leading-order predictions for every Omega0: hovering sign, |HOV|, K_c, rho_c (:func:`hovering.theory`)."""
        return _geo.theory(self.eps, self.Omega0, self.theta_w, self.tau0)

    def k_eps1(self, phi, K0=0.0):
        """Leading-order invariant curve through L1 at height K0 (eq:keps1)."""
        return _geo.k_eps1(phi, K0, self.eps, self.Omega0, self.tau0)

    def k_eps2(self, phi, K0=0.0):
        """Leading-order invariant curve through L2 at height K0 (eq:keps2)."""
        return _geo.k_eps2(phi, K0, self.eps, self.Omega0, self.tau0)

    def with_eps(self, eps) -> TruncatedMap:
        """The same map with another eps (e.g. the mirror map F_{-eps}).

        Parameters
        ----------
        eps : float
            New perturbation amplitude.

        Returns
        -------
        TruncatedMap
        """
        p = self.params
        p["eps"] = eps
        return TruncatedMap(**p, K_max=self.valid_band()[1])

    def __reduce__(self):
        """Pickle as the record (the parameters, K_max: the band's upper end) and the instance dict."""
        return reduce_record(self, self.__dict__)

    def _to_record(self) -> dict:
        """What :func:`hovering.save` writes: the six parameters and ``K_max`` (the band's upper end)."""
        return dict(self.params, K_max=self.valid_band()[1])

    @classmethod
    def _from_record(cls, record: dict) -> TruncatedMap:
        """Inverse of :meth:`_to_record` (validated again; the same doubles give the same map bit for bit).
        A subclass is rebuilt through this class's constructor (its own may take other arguments)."""
        obj = cls.__new__(cls)
        TruncatedMap.__init__(obj, **record)
        return obj


def _angles(name: str, phi):
    """Finite angles with |phi| <= 1e6 (beyond, sin(k phi) is rounding noise), as an array or float."""
    a = real_array(name, phi)
    require_angles(name, a)
    return a if a.ndim else float(a)


def _as_table(name: str, values, K: np.ndarray) -> np.ndarray:
    if callable(values):
        values = _sampled(values, K)
    a = real_array(name, values)
    if a.shape != K.shape:
        raise ValueError(f"{name} must have the shape of K {K.shape}, got {a.shape}")
    return a


def _sampled(fn, K: np.ndarray):
    """``fn`` on the grid: one call with the whole grid when fn works on arrays (returns real numbers
    of the grid's shape), else one call per point (a function of one float, e.g. with ``if k < 0``
    or ``math.sqrt``, which fails on an array). Three tables called per point took ~0.3 s of a
    1.1-1.4 s build at MAX_GRID points."""
    try:
        out = np.asarray(fn(K.copy()))  # a copy: fn must not see (or change) the tables' own grid
    except Exception:  # noqa: BLE001 - any failure on an array means: call it per point
        out = None
    if out is not None and out.shape == K.shape and out.dtype.kind in "iuf":
        return out
    return [fn(k) for k in K]


class TruncatedFamily(_MapAPI, _core_truncated.TruncatedFamily):
    """The general truncated family F_{eps1,eps2} (eq:trunceps1eps2) with tabulated arcs.

    ``Kbar = K + eps f(phibar)`` with ``f(phi) = sum_k b_k sin(k phi)``, and an interval exchange
    built from Omega(K), |J_R|(K), |J_1|(K) placed by eq:phi1rsymmetric, so that every member is
    reversible (lem:truncreturnmap). Omega and |J_R| are splined in K, |J_1| in ``sqrt(-K)``
    (it is smooth in ``sqrt(-K)``, not in K: thm:cornersing); GSL natural cubic splines.

    Parameters
    ----------
    eps : float
        Forcing amplitude eps_1: finite, with ``|eps| sum_k |b_k| <= 2^43 (K_hi - K_lo)`` for the
        band ``(K_lo, K_hi)`` (the kick a step resolves, see :class:`TruncatedMap`).
    K : array_like
        Strictly increasing grid containing 0, with >= 3 points K <= 0 and max K > 0, and at most
        100,000 points (``MAX_GRID``): the sweep plans' limit; the core builds ~1e5 points a
        second, holding the GIL (Ctrl-C waits for it).
    Omega, JR, J1 : array_like or callable
        Values on the grid, or functions of K: one called with the whole grid (an array) when it
        returns an array of the grid's shape, else once per grid point. JR and J1 are used only
        for K <= 0; J1 must vanish at K = 0 and reach ``2^-41`` rad inside the band (J_1 is
        resolved, see :class:`TruncatedMap`). ``|Omega| <= 1e6`` (see :class:`TruncatedMap`); the
        band also ends where the spline through Omega first exceeds it between the grid points.
    forcing : sequence of float, optional
        Sine coefficients ``b_1, b_2, ...`` of f (default ``(1.0,)``: f = sin).
    K_max : float, optional
        Upper end of the band, in (0, inf] (default inf: the top of the grid).

    Raises
    ------
    ValueError
        For malformed tables (naming the offending entry), more than 100,000 grid points
        (before anything is sampled or built), tables with no valid band below 0 or one below
        double-precision resolution, or a K_max that is not a real number in (0, inf].
    """

    def __init__(self, eps, K, Omega, JR, J1, forcing=(1.0,), K_max=math.inf):
        eps = real_number("eps", eps)
        Kg = real_array("K", K)
        if Kg.ndim != 1:
            raise ValueError(f"K must be a 1-D grid, got shape {Kg.shape}")
        if Kg.size > MAX_GRID:  # before the tables are sampled and the core builds (GIL held, ~10 us a point)
            raise ValueError(
                f"K has {Kg.size} grid points; allowed: at most MAX_GRID = {MAX_GRID} (the sweep plans' limit; "
                "the core's build takes ~10 us a point and cannot be interrupted)"
            )
        b = forcing_array(forcing)
        K_max = _band_top(K_max)
        tabs = [_as_table(n, v, Kg) for n, v in (("Omega", Omega), ("JR", JR), ("J1", J1))]
        # Lists of Python floats: what the binding's std::vector<double> converts fastest (list(K)'s
        # NumPy scalars took ~20% longer, an ndarray ~50%: both go element by element).
        _core_truncated.TruncatedFamily.__init__(self, eps, Kg.tolist(), *(t.tolist() for t in tabs), b.tolist(), K_max)
        self._tables = (Kg.copy(), *(t.copy() for t in tabs))
        self._K_max = K_max
        lo = self.valid_band()[0]
        inside = (Kg > lo) & (Kg < 0)
        near_floor = lo * (1 - 2**-20) if lo * (1 - 2**-20) > lo else float(np.nextafter(lo, 0.0))
        # J_1's widest in the band from the table's values inside it and the spline just above the
        # floor: a lower bound of the spline's maximum, so only a J_1 thin everywhere is refused.
        widest = max(float(np.max(np.abs(tabs[2][inside]), initial=0.0)), float(self.arcs(near_floor)["len_1"]))
        self._require_resolved(
            "TruncatedFamily",
            widest,
            float(np.sum(np.abs(b))),
            lambda: ("the tables' arcs", "J1 tables that open J_1 wider before the band's floor"),
        )

    def forcing_at(self, phi):
        """The forcing ``f(phi) = sum_k b_k sin(k phi)``.

        Parameters
        ----------
        phi : array_like
            Angles.

        Returns
        -------
        ndarray or float
        """
        phi = np.asarray(_angles("phi", phi), dtype=float)
        out = sum(b * np.sin((k + 1) * phi) for k, b in enumerate(self.forcing))
        return float(out) if out.ndim == 0 else out

    def onset(self) -> tuple:
        """``(Omega0, theta_w, tau0)`` of the tables at the tangency: ``Omega(0)``, ``pi - |J_R|(0)/2``
        and ``Omega'(0)`` (one-sided difference above 0, 1e-7 wide: Omega is splined in K)."""
        d = 1e-7
        Om0 = float(self.rotation(0.0, 0.0))
        tau0 = (float(self.rotation(0.0, d)) - Om0) / d
        theta_w = math.pi - 0.5 * float(self.arcs(-1e-300)["len_R"])
        return Om0, theta_w, tau0

    def theory(self) -> _geo.Theory:
        """Leading-order predictions with the tables' onset values and this family's forcing (:func:`hovering.theory`)."""
        Om0, theta_w, tau0 = self.onset()
        return _geo.theory(self.eps, Om0, theta_w, tau0, forcing=tuple(self.forcing))

    def L1(self, K):
        """Angle of the line L1 at heights K (def:L1L2) with the tables' Omega(0) and Omega'(0)."""
        Om0, _, tau0 = self.onset()
        return _geo.L1(K, Om0, tau0)

    def L2(self, K):
        """Angle of the line L2 at heights K (def:L1L2) with the tables' Omega(0) and Omega'(0)."""
        Om0, _, tau0 = self.onset()
        return _geo.L2(K, Om0, tau0)

    def with_eps(self, eps) -> TruncatedFamily:
        """The same tables and forcing with another forcing amplitude (e.g. F_0).

        Parameters
        ----------
        eps : float
            New amplitude eps_1.

        Returns
        -------
        TruncatedFamily
        """
        K, Om, JR, J1 = self._tables
        return TruncatedFamily(eps, K, Om, JR, J1, forcing=tuple(self.forcing), K_max=self._K_max)

    def __reduce__(self):
        """Pickle as the record (the tables as given, forcing, K_max) and the rest of the instance dict."""
        return reduce_record(self, {k: v for k, v in self.__dict__.items() if k not in ("_tables", "_K_max")})

    def _to_record(self) -> dict:
        """What :func:`hovering.save` writes: eps, the tables as given, the forcing and K_max."""
        K, Om, JR, J1 = self._tables
        return {
            "eps": self.eps,
            "K": K,
            "Omega": Om,
            "JR": JR,
            "J1": J1,
            "forcing": np.array(self.forcing, dtype=float),
            "K_max": self._K_max,
        }

    @classmethod
    def _from_record(cls, record: dict) -> TruncatedFamily:
        """Inverse of :meth:`_to_record` (validated again; the same tables give the same map bit for bit)."""
        r = dict(record)
        obj = cls.__new__(cls)
        TruncatedFamily.__init__(
            obj,
            r.pop("eps"),
            r.pop("K"),
            r.pop("Omega"),
            r.pop("JR"),
            r.pop("J1"),
            forcing=tuple(r.pop("forcing")),
            **r,
        )
        return obj

    @classmethod
    def from_map(cls, m: TruncatedMap, K, forcing=(1.0,)) -> TruncatedFamily:
        """Tabulate the arcs of a :class:`TruncatedMap` on a grid (useful as a starting point).

        Parameters
        ----------
        m : TruncatedMap
            Map whose Omega, |J_R|, |J_1| are sampled.
        K : array_like
            Grid (see the class parameters).
        forcing : sequence of float, optional
            Sine coefficients of the forcing.

        Returns
        -------
        TruncatedFamily
        """
        Kg = real_array("K", K)
        neg = np.minimum(Kg, 0.0)
        s = np.sqrt(-neg)
        Omega = m.Omega0 + m.tau0 * Kg
        JR = np.where(Kg <= 0, 2 * (np.pi - m.theta_w) + m.tau1 * neg, 0.0)
        J1 = 2 * m.lam * s
        return cls(m.eps, Kg, Omega, JR, J1, forcing=forcing)
