"""Plain-NumPy reference implementation of the truncated hovering map.

This module is an *independent* reference for cross-checking a fast
implementation of the truncated return map ``F_eps`` (paper labels
``eq:truncatedmap``, ``eq:Jdeftrunc``, ``eq:omegaofalead``) and of the more
general symmetric family ``F_{eps1, eps2}`` (``eq:trunceps1eps2`` with the
interval placement ``eq:phi1rsymmetric``).  It is written for clarity, not
speed.

State and regions
-----------------
The state is ``(phi, K)`` with ``phi`` on the circle, represented in
``[-pi, pi)``.  For ``K >= 0`` the whole circle is one region, BESIDE (the
paper's ``J_0u``).  For ``K < 0`` the circle is cut into three arcs which, in
increasing ``phi`` (mod 2 pi), are

* UPPER (``J_1``), starting at ``phi_01`` with length ``L1``;
* RIGHT (``J_R``), starting at ``phi_01 + L1`` with length ``LR``;
* ABOVE (``J_0``), starting at ``phi_01 + L1 + LR`` with length
  ``L0 = 2 pi - L1 - LR`` (so it ends at ``phi_01 + 2 pi``).

Boundary convention
-------------------
The paper uses open arcs, so the arc end points (a measure-zero set) are not
assigned.  Here the forward map uses half-open arcs ``[left, right)``: an end
point belongs to the arc that *starts* there.  The inverse map uses the
mirrored convention (it tests ``-phi1`` against ``(left, right]``), which is
exactly the image of the forward convention, so ``F^{-1}(F(x)) = x`` holds at
boundary points as well (up to round-off).  Cross-checks against another
implementation should avoid points within round-off of an arc end point; see
:func:`boundary_distance`.

Points outside the band of validity
-----------------------------------
For ``K < 0`` with arc lengths that do not describe a partition of the circle
(a negative length, or a length above ``2 pi``) the map is undefined.  Such
points get region code ``INVALID = -1`` and every map returns ``nan`` for
them; :func:`iterate` keeps propagating ``nan`` once an orbit leaves the band.

Region codes: ``BESIDE = 0``, ``ABOVE = 1``, ``UPPER = 2``, ``RIGHT = 3``,
``INVALID = -1``.

Parameter dictionary ``p`` (truncated map): keys ``eps, Omega0, theta_w,
tau0, tau1, lam``.
"""

import numpy as np

__all__ = [
    "BESIDE",
    "ABOVE",
    "UPPER",
    "RIGHT",
    "INVALID",
    "TWO_PI",
    "wrap",
    "forcing",
    "arcs",
    "region",
    "rotation",
    "step",
    "step_inverse",
    "reversal",
    "boundary_distance",
    "valid_band",
    "iterate",
    "arcs_general",
    "region_general",
    "rotation_general",
    "step_general",
    "step_inverse_general",
    "reversal_general",
    "boundary_distance_general",
    "valid_band_general",
]

BESIDE = 0
ABOVE = 1
UPPER = 2
RIGHT = 3
INVALID = -1

TWO_PI = 2.0 * np.pi


# ---------------------------------------------------------------------------
# small helpers
# ---------------------------------------------------------------------------


def _cmod(x):
    """Reduce ``x`` modulo 2 pi into ``[0, 2 pi)`` (guarding the round-off case)."""
    y = np.mod(x, TWO_PI)
    # np.mod can return exactly 2 pi for tiny negative inputs
    return np.where(y >= TWO_PI, y - TWO_PI, y)


def wrap(x):
    """Wrap angles to the half-open interval ``[-pi, pi)``.

    Parameters
    ----------
    x : array_like
        Angles in radians (any real values).

    Returns
    -------
    numpy.ndarray
        ``x`` shifted by an integer multiple of ``2 pi`` into ``[-pi, pi)``.
    """
    x = np.asarray(x, dtype=float)
    y = np.mod(x + np.pi, TWO_PI) - np.pi
    # round-off guard: np.mod may return 2 pi, giving y == pi
    y = np.where(y >= np.pi, y - TWO_PI, y)
    y = np.where(y < -np.pi, -np.pi, y)
    return y


def forcing(phi, b=(1.0,)):
    """Odd forcing function ``f(phi) = sum_k b_k sin(k phi)``, ``k = 1, 2, ...``.

    Parameters
    ----------
    phi : array_like
        Angles.
    b : sequence of float, optional
        Sine coefficients ``b_1, b_2, ...``; the default ``(1.0,)`` gives
        ``f = sin``, the forcing of the truncated map ``F_eps``.

    Returns
    -------
    numpy.ndarray
        ``f(phi)``, same shape as ``phi``.
    """
    phi = np.asarray(phi, dtype=float)
    out = np.zeros_like(phi)
    for k, bk in enumerate(b, start=1):
        out = out + bk * np.sin(k * phi)
    return out


def _bcast(phi, K):
    phi, K = np.broadcast_arrays(np.asarray(phi, dtype=float), np.asarray(K, dtype=float))
    return phi.copy(), K.copy()


def _lengths_partition_ok(L1, LR, L0):
    """Arc lengths usable as a partition of the circle (empty arcs allowed)."""
    ok = np.isfinite(L1) & np.isfinite(LR) & np.isfinite(L0)
    for L in (L1, LR, L0):
        ok &= (L >= 0.0) & (L <= TWO_PI)
    return ok


def _lengths_strict_ok(L1, LR, L0):
    """All three arc lengths in the open interval ``(0, 2 pi)``."""
    ok = np.isfinite(L1) & np.isfinite(LR) & np.isfinite(L0)
    for L in (L1, LR, L0):
        ok &= (L > 0.0) & (L < TWO_PI)
    return ok


def _in_arc(x, left, length, closed_side):
    """Membership of angle ``x`` in the circle arc starting at ``left``.

    ``closed_side='left'`` tests ``[left, left+length)``, ``'right'`` tests
    ``(left, left+length]``; ``length`` is assumed to lie in ``[0, 2 pi]``.
    """
    d = _cmod(x - left)  # counter-clockwise offset of x from the left end
    if closed_side == "left":
        return d < length
    # right-closed: offset 0 means x sits on the left end -> excluded, unless
    # the arc is the whole circle
    return ((d > 0.0) & (d <= length)) | ((d == 0.0) & (length >= TWO_PI))


def _classify(phi, K, phi01, L1, LR, L0, closed_side):
    """Region codes from the arc data (arrays of phi's shape, used where K<0)."""
    reg = np.full(phi.shape, BESIDE, dtype=int)
    neg = K < 0.0
    ok = _lengths_partition_ok(L1, LR, L0)
    x = phi
    left1 = phi01
    leftR = phi01 + L1
    left0 = phi01 + L1 + LR
    m1 = _in_arc(x, left1, L1, closed_side)
    mR = _in_arc(x, leftR, LR, closed_side)
    m0 = _in_arc(x, left0, L0, closed_side)
    count = m1.astype(int) + mR.astype(int) + m0.astype(int)
    r = np.where(m1, UPPER, np.where(mR, RIGHT, ABOVE))
    # Round-off at an end point can put a point in zero or two arcs.  Resolve
    # those by the cumulative offset from phi_01 (which is a true partition).
    amb = count != 1
    if np.any(amb):
        d = _cmod(x - phi01)
        if closed_side == "left":
            rf = np.where(d < L1, UPPER, np.where(d < L1 + LR, RIGHT, ABOVE))
        else:
            rf = np.where(d == 0.0, ABOVE, np.where(d <= L1, UPPER, np.where(d <= L1 + LR, RIGHT, ABOVE)))
        r = np.where(amb, rf, r)
    reg = np.where(neg, np.where(ok, r, INVALID), reg)
    reg = np.where(np.isfinite(K) & np.isfinite(phi), reg, INVALID)
    return reg.astype(int)


def _omega_from_region(reg, Om, L1, LR):
    """Rotation per region: ABOVE/BESIDE Om, UPPER Om+LR, RIGHT Om-L1."""
    om = np.full(reg.shape, np.nan)
    om = np.where(reg == BESIDE, Om, om)
    om = np.where(reg == ABOVE, Om, om)
    om = np.where(reg == UPPER, Om + LR, om)
    om = np.where(reg == RIGHT, Om - L1, om)
    return om


def _boundary_distance(phi, K, phi01, L1, LR):
    ends = (phi01, phi01 + L1, phi01 + L1 + LR)
    dist = np.full(phi.shape, np.inf)
    for e in ends:
        d = _cmod(phi - e)
        dist = np.minimum(dist, np.minimum(d, TWO_PI - d))
    return np.where(K < 0.0, dist, np.inf)


# ---------------------------------------------------------------------------
# truncated map F_eps
# ---------------------------------------------------------------------------


def arcs(K, p):
    """Arc data of the truncated map on the circle of height ``K``.

    Parameters
    ----------
    K : array_like
        Action values.
    p : dict
        Parameters with keys ``eps, Omega0, theta_w, tau0, tau1, lam``.

    Returns
    -------
    phi01 : numpy.ndarray
        Left end of the UPPER arc ``J_1``,
        ``theta_w - Omega0/2 - (tau0+tau1) K/2 - lam s`` with
        ``s = sqrt(max(0, -K))`` (not wrapped).
    L1, LR, L0 : numpy.ndarray
        Lengths of UPPER, RIGHT and ABOVE arcs: ``2 lam s``,
        ``2 (pi - theta_w) + tau1 K`` and ``2 theta_w - tau1 K - 2 lam s``.
        Only meaningful for ``K < 0`` (for ``K >= 0`` the map has the single
        region BESIDE and these values are not used).
    """
    K = np.asarray(K, dtype=float)
    s = np.sqrt(np.maximum(0.0, -K))
    tw, lam = p["theta_w"], p["lam"]
    phi01 = tw - 0.5 * p["Omega0"] - 0.5 * (p["tau0"] + p["tau1"]) * K - lam * s
    L1 = 2.0 * lam * s
    LR = 2.0 * (np.pi - tw) + p["tau1"] * K
    L0 = 2.0 * tw - p["tau1"] * K - 2.0 * lam * s
    return phi01, L1, LR, L0


def _omegas(K, p):
    """(omega_ABOVE, omega_UPPER, omega_RIGHT) of eq:omegaofalead for K<0."""
    K = np.asarray(K, dtype=float)
    s = np.sqrt(np.maximum(0.0, -K))
    base = p["Omega0"] + p["tau0"] * K
    om_above = base
    om_upper = base + p["tau1"] * K + 2.0 * (np.pi - p["theta_w"])
    om_right = base - 2.0 * p["lam"] * s
    return om_above, om_upper, om_right


def region(phi, K, p):
    """Region code of points under the truncated map ``F_eps``.

    Parameters
    ----------
    phi, K : array_like
        Points (broadcast against each other).
    p : dict
        Parameters ``eps, Omega0, theta_w, tau0, tau1, lam``.

    Returns
    -------
    numpy.ndarray of int
        ``BESIDE=0`` for ``K >= 0``; for ``K < 0`` one of ``ABOVE=1``,
        ``UPPER=2``, ``RIGHT=3`` (half-open arcs ``[left, right)``), or
        ``INVALID=-1`` where the arc lengths do not partition the circle.
    """
    phi, K = _bcast(phi, K)
    phi01, L1, LR, L0 = arcs(K, p)
    return _classify(phi, K, phi01, L1, LR, L0, "left")


def _rotation_of_region(reg, K, p):
    om_a, om_u, om_r = _omegas(K, p)
    base = p["Omega0"] + p["tau0"] * K
    om = np.full(reg.shape, np.nan)
    om = np.where(reg == BESIDE, base, om)
    om = np.where(reg == ABOVE, om_a, om)
    om = np.where(reg == UPPER, om_u, om)
    om = np.where(reg == RIGHT, om_r, om)
    return om


def rotation(phi, K, p):
    """Rotation ``omega_a(K)`` applied at ``(phi, K)`` by ``F_eps``.

    Parameters
    ----------
    phi, K : array_like
        Points (broadcast against each other).
    p : dict
        Parameters ``eps, Omega0, theta_w, tau0, tau1, lam``.

    Returns
    -------
    numpy.ndarray
        ``Omega0 + tau0 K`` (BESIDE, ABOVE),
        ``Omega0 + tau0 K + tau1 K + 2 (pi - theta_w)`` (UPPER),
        ``Omega0 + tau0 K - 2 lam sqrt(-K)`` (RIGHT); ``nan`` if INVALID.
        Not reduced modulo ``2 pi``.
    """
    phi, K = _bcast(phi, K)
    return _rotation_of_region(region(phi, K, p), K, p)


def step(phi, K, p):
    """One forward step of the truncated map ``F_eps``.

    ``phibar = wrap(phi + omega_a(K))``, ``Kbar = K + eps sin(phibar)``.

    Parameters
    ----------
    phi, K : array_like
        Points (broadcast against each other).
    p : dict
        Parameters ``eps, Omega0, theta_w, tau0, tau1, lam``.

    Returns
    -------
    phi1, K1 : numpy.ndarray
        Image point; ``nan`` where the region is INVALID.
    """
    phi, K = _bcast(phi, K)
    reg = region(phi, K, p)
    om = _rotation_of_region(reg, K, p)
    phi1 = wrap(phi + om)
    K1 = K + p["eps"] * np.sin(phi1)
    bad = reg == INVALID
    return np.where(bad, np.nan, phi1), np.where(bad, np.nan, K1)


def step_inverse(phi1, K1, p):
    """One backward step, ``F_eps^{-1}``.

    Derivation: ``F = P o T`` with the vertical shear
    ``P(phi, K) = (phi, K + eps sin(phi))`` and the K-preserving interval
    exchange ``T``.  Hence ``K0 = K1 - eps sin(phi1)``.  On the circle ``K0``
    the image of each arc ``J_a(K0)`` under ``T`` is the reflected arc
    ``-J_a(K0)`` (eq:phi1rsymmetric), so the preimage lies in ``J_a`` with
    ``-phi1 in J_a(K0)`` and ``phi0 = wrap(phi1 - omega_a(K0))``.  The
    membership test uses ``(left, right]``, the mirror of the forward
    ``[left, right)`` convention.

    Parameters
    ----------
    phi1, K1 : array_like
        Points (broadcast against each other).
    p : dict
        Parameters ``eps, Omega0, theta_w, tau0, tau1, lam``.

    Returns
    -------
    phi0, K0 : numpy.ndarray
        Preimage point; ``nan`` where ``K0`` is outside the band.
    """
    phi1, K1 = _bcast(phi1, K1)
    K0 = K1 - p["eps"] * np.sin(phi1)
    phi01, L1, LR, L0 = arcs(K0, p)
    reg = _classify(wrap(-phi1), K0, phi01, L1, LR, L0, "right")
    om = _rotation_of_region(reg, K0, p)
    phi0 = wrap(phi1 - om)
    bad = reg == INVALID
    return np.where(bad, np.nan, phi0), np.where(bad, np.nan, K0)


def reversal(phi, K, p):
    """Time-reversal involution ``R_eps(phi, K) = (-phi, K - eps sin(phi))``.

    Parameters
    ----------
    phi, K : array_like
        Points.
    p : dict
        Parameters (only ``eps`` is used).

    Returns
    -------
    phi_r, K_r : numpy.ndarray
        ``(wrap(-phi), K - eps sin(phi))``; ``R o F o R = F^{-1}``.
    """
    phi, K = _bcast(phi, K)
    return wrap(-phi), K - p["eps"] * np.sin(phi)


def boundary_distance(phi, K, p):
    """Circular distance from ``phi`` to the nearest arc end point at ``K``.

    Useful to select test points away from the discontinuities.  For the
    inverse map the relevant quantity is
    ``boundary_distance(-phi1, K1 - eps sin(phi1), p)``.

    Parameters
    ----------
    phi, K : array_like
        Points.
    p : dict
        Parameters ``eps, Omega0, theta_w, tau0, tau1, lam``.

    Returns
    -------
    numpy.ndarray
        Distance in ``[0, pi]`` for ``K < 0``; ``inf`` for ``K >= 0``.
    """
    phi, K = _bcast(phi, K)
    phi01, L1, LR, _ = arcs(K, p)
    return _boundary_distance(phi, K, phi01, L1, LR)


def _band_lower_edge(lengths, k_start=1e-3, k_max=1e15, n_scan=1_000_001, tol=1e-13):
    """Numerical lower edge of the band where all arc lengths are in (0, 2 pi).

    ``lengths(K)`` returns ``(L1, LR, L0)`` for an array of ``K < 0``.
    """

    def ok(Kv):
        Kv = np.atleast_1d(np.asarray(Kv, dtype=float))
        L1, LR, L0 = lengths(Kv)
        return _lengths_strict_ok(
            np.broadcast_to(L1, Kv.shape), np.broadcast_to(LR, Kv.shape), np.broadcast_to(L0, Kv.shape)
        )

    # 1) find some depth Kfar < 0 at which the condition fails
    depth = k_start
    while depth <= k_max and ok(-depth)[0]:
        depth *= 2.0
    if depth > k_max:
        return -np.inf
    # 2) dense scan of [-depth, 0), uniform in s = sqrt(-K) (the lengths are
    #    smooth in s, not in K), to find the failure closest to K = 0
    u = np.linspace(1.0, 0.0, n_scan, endpoint=False)[::-1]  # increasing in (0,1]
    Ks = -depth * u * u  # from ~0 down to -depth
    good = ok(Ks)
    first_bad = int(np.argmin(good))  # first False
    if good[first_bad]:
        # no failure on the grid (cannot happen since -depth failed)
        first_bad = n_scan - 1
    K_bad = Ks[first_bad]
    K_good = Ks[first_bad - 1] if first_bad > 0 else -0.0
    # 3) bisection (K_good > K_bad)
    while K_good - K_bad > tol:
        mid = 0.5 * (K_good + K_bad)
        if mid == K_good or mid == K_bad:
            break
        if ok(mid)[0]:
            K_good = mid
        else:
            K_bad = mid
    return float(K_good)


def valid_band(p):
    """Band of ``K`` on which the truncated map is well defined.

    Computed numerically (dense scan in ``s = sqrt(-K)`` followed by bisection
    to ``1e-13``), not from the paper's closed form ``eq:kmindef``.

    Parameters
    ----------
    p : dict
        Parameters ``eps, Omega0, theta_w, tau0, tau1, lam``.

    Returns
    -------
    lo, hi : float
        ``lo < 0`` is the lowest ``K`` such that for every ``K`` in
        ``(lo, 0)`` the three arc lengths lie in ``(0, 2 pi)`` (the returned
        value is the last verified-good bisection point, within ``1e-13`` of
        the true edge, on its valid side).  ``hi = +inf``.
    """

    def lengths(Kv):
        _, L1, LR, L0 = arcs(Kv, p)
        return L1, LR, L0

    return _band_lower_edge(lengths), np.inf


def iterate(phi0, K0, n, p):
    """Iterate the truncated map ``F_eps`` ``n`` times.

    Parameters
    ----------
    phi0, K0 : array_like
        Initial conditions (broadcast and flattened into ``n_orbits``).
    n : int
        Number of steps.
    p : dict
        Parameters ``eps, Omega0, theta_w, tau0, tau1, lam``.

    Returns
    -------
    phi : numpy.ndarray, shape (n_orbits, n+1)
        Angles, ``phi[:, 0]`` being the wrapped initial angles.
    K : numpy.ndarray, shape (n_orbits, n+1)
        Actions.
    regions : numpy.ndarray of int, shape (n_orbits, n)
        Region code of ``(phi[:, j], K[:, j])`` used for step ``j``
        (``INVALID`` once an orbit has left the band).
    rho : numpy.ndarray, shape (n_orbits,)
        Rotation number, the mean of the (unreduced) rotations ``omega_a``
        over the ``n`` steps; ``nan`` if the orbit left the band or ``n == 0``.
    """
    ph, KK = _bcast(phi0, K0)
    ph = wrap(ph.ravel())
    KK = KK.ravel()
    m = ph.size
    n = int(n)
    phis = np.empty((m, n + 1))
    Ks = np.empty((m, n + 1))
    regs = np.empty((m, n), dtype=int)
    oms = np.empty((m, n))
    phis[:, 0] = ph
    Ks[:, 0] = KK
    for j in range(n):
        r = region(ph, KK, p)
        om = _rotation_of_region(r, KK, p)
        ph, KK = step(ph, KK, p)
        regs[:, j] = r
        oms[:, j] = om
        phis[:, j + 1] = ph
        Ks[:, j + 1] = KK
    rho = oms.mean(axis=1) if n > 0 else np.full(m, np.nan)
    return phis, Ks, regs, rho


# ---------------------------------------------------------------------------
# general symmetric family F_{eps1, eps2}
# ---------------------------------------------------------------------------


def _eval_on_negative(fn, K):
    """Evaluate a callable only where K < 0 (nan elsewhere)."""
    out = np.full(K.shape, np.nan)
    neg = K < 0.0
    if np.any(neg):
        out[neg] = np.broadcast_to(np.asarray(fn(K[neg]), dtype=float), K[neg].shape)
    return out


def arcs_general(K, Omega, JR, J1):
    """Arc data of the general family on the circle of height ``K``.

    Parameters
    ----------
    K : array_like
        Action values.
    Omega, JR, J1 : callable
        Vectorised functions of ``K``: ``Omega(K)``, ``|J_R|(K)``,
        ``|J_1|(K)``.  ``JR`` and ``J1`` are only evaluated at ``K < 0``.

    Returns
    -------
    phi01, L1, LR, L0, Om : numpy.ndarray
        ``phi01 = pi - Om/2 - LR/2 - L1/2`` (left end of UPPER), the three
        arc lengths (``L0 = 2 pi - L1 - LR``; ``nan`` for ``K >= 0``) and
        ``Om = Omega(K)``.
    """
    K = np.asarray(K, dtype=float)
    Om = np.broadcast_to(np.asarray(Omega(K), dtype=float), K.shape).copy()
    LR = _eval_on_negative(JR, K)
    L1 = _eval_on_negative(J1, K)
    L0 = TWO_PI - L1 - LR
    phi01 = np.pi - 0.5 * Om - 0.5 * LR - 0.5 * L1
    return phi01, L1, LR, L0, Om


def region_general(phi, K, Omega, JR, J1):
    """Region codes for the general family (arcs vanish for ``K >= 0``).

    Parameters
    ----------
    phi, K : array_like
        Points (broadcast against each other).
    Omega, JR, J1 : callable
        ``Omega(K)``, ``|J_R|(K)``, ``|J_1|(K)`` (vectorised).

    Returns
    -------
    numpy.ndarray of int
        ``BESIDE`` for ``K >= 0``, else ``UPPER``, ``RIGHT`` or ``ABOVE``
        (arcs ``[left, right)``), or ``INVALID`` where the lengths are
        negative / exceed ``2 pi`` (empty arcs are allowed here).
    """
    phi, K = _bcast(phi, K)
    phi01, L1, LR, L0, _ = arcs_general(K, Omega, JR, J1)
    return _classify(phi, K, phi01, L1, LR, L0, "left")


def rotation_general(phi, K, Omega, JR, J1):
    """Rotation of the general family at ``(phi, K)``.

    Parameters
    ----------
    phi, K : array_like
        Points.
    Omega, JR, J1 : callable
        ``Omega(K)``, ``|J_R|(K)``, ``|J_1|(K)`` (vectorised).

    Returns
    -------
    numpy.ndarray
        ``Omega`` (BESIDE, ABOVE), ``Omega + JR`` (UPPER), ``Omega - J1``
        (RIGHT), ``nan`` if INVALID.
    """
    phi, K = _bcast(phi, K)
    phi01, L1, LR, L0, Om = arcs_general(K, Omega, JR, J1)
    reg = _classify(phi, K, phi01, L1, LR, L0, "left")
    return _omega_from_region(reg, Om, L1, LR)


def step_general(phi, K, eps, Omega, JR, J1, b):
    """One forward step of the general family ``F_{eps, eps2}``.

    ``phibar = wrap(phi + omega_a(K))``, ``Kbar = K + eps f(phibar)`` with
    ``f(x) = sum_k b_k sin(k x)``.

    Parameters
    ----------
    phi, K : array_like
        Points (broadcast against each other).
    eps : float
        Forcing amplitude ``eps1``.
    Omega, JR, J1 : callable
        ``Omega(K)``, ``|J_R|(K)``, ``|J_1|(K)`` (vectorised).
    b : sequence of float
        Sine coefficients ``b_1, b_2, ...``.

    Returns
    -------
    phi1, K1 : numpy.ndarray
        Image point; ``nan`` where INVALID.
    """
    phi, K = _bcast(phi, K)
    phi01, L1, LR, L0, Om = arcs_general(K, Omega, JR, J1)
    reg = _classify(phi, K, phi01, L1, LR, L0, "left")
    om = _omega_from_region(reg, Om, L1, LR)
    phi1 = wrap(phi + om)
    K1 = K + eps * forcing(phi1, b)
    bad = reg == INVALID
    return np.where(bad, np.nan, phi1), np.where(bad, np.nan, K1)


def step_inverse_general(phi1, K1, eps, Omega, JR, J1, b):
    """One backward step of the general family.

    ``K0 = K1 - eps f(phi1)``; the preimage arc is the ``J_a(K0)`` with
    ``-phi1 in J_a(K0)`` (tested as ``(left, right]``) and
    ``phi0 = wrap(phi1 - omega_a(K0))``.

    Parameters
    ----------
    phi1, K1 : array_like
        Points (broadcast against each other).
    eps : float
        Forcing amplitude.
    Omega, JR, J1 : callable
        ``Omega(K)``, ``|J_R|(K)``, ``|J_1|(K)`` (vectorised).
    b : sequence of float
        Sine coefficients ``b_1, b_2, ...``.

    Returns
    -------
    phi0, K0 : numpy.ndarray
        Preimage point; ``nan`` where INVALID.
    """
    phi1, K1 = _bcast(phi1, K1)
    K0 = K1 - eps * forcing(phi1, b)
    phi01, L1, LR, L0, Om = arcs_general(K0, Omega, JR, J1)
    reg = _classify(wrap(-phi1), K0, phi01, L1, LR, L0, "right")
    om = _omega_from_region(reg, Om, L1, LR)
    phi0 = wrap(phi1 - om)
    bad = reg == INVALID
    return np.where(bad, np.nan, phi0), np.where(bad, np.nan, K0)


def reversal_general(phi, K, eps, b):
    """Involution ``R(phi, K) = (-phi, K - eps f(phi))`` for odd ``f``.

    Parameters
    ----------
    phi, K : array_like
        Points.
    eps : float
        Forcing amplitude.
    b : sequence of float
        Sine coefficients of ``f``.

    Returns
    -------
    phi_r, K_r : numpy.ndarray
        Reflected point.
    """
    phi, K = _bcast(phi, K)
    return wrap(-phi), K - eps * forcing(phi, b)


def boundary_distance_general(phi, K, Omega, JR, J1):
    """Circular distance to the nearest arc end point (general family).

    Parameters
    ----------
    phi, K : array_like
        Points.
    Omega, JR, J1 : callable
        ``Omega(K)``, ``|J_R|(K)``, ``|J_1|(K)`` (vectorised).

    Returns
    -------
    numpy.ndarray
        Distance for ``K < 0``; ``inf`` for ``K >= 0``.
    """
    phi, K = _bcast(phi, K)
    phi01, L1, LR, _, _ = arcs_general(K, Omega, JR, J1)
    return _boundary_distance(phi, K, phi01, L1, LR)


def valid_band_general(Omega, JR, J1):
    """Numerical band of validity for the general family.

    Parameters
    ----------
    Omega, JR, J1 : callable
        ``Omega(K)``, ``|J_R|(K)``, ``|J_1|(K)`` (vectorised).

    Returns
    -------
    lo, hi : float
        ``lo`` is the lowest ``K < 0`` such that on ``(lo, 0)`` all three
        arc lengths lie in ``(0, 2 pi)`` (``-inf`` if no failure is found
        down to ``K = -1e15``); ``hi = +inf``.  Note that a family with an
        identically empty arc (e.g. ``J1 = 0``) has ``lo`` within ``1e-13``
        of 0 here.
    """

    def lengths(Kv):
        _, L1, LR, L0, _ = arcs_general(Kv, Omega, JR, J1)
        return L1, LR, L0

    return _band_lower_edge(lengths), np.inf
