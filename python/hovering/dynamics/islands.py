"""The periodic orbit at the centre of an island chain: the link from the order statistics of
:func:`hovering.classify_orbits` and :func:`hovering.barrier_scan` (which see a chain of q islands
in the recorded points) to :func:`hovering.periodic_orbit` (which finds the elliptic orbit of
period q the chain surrounds, with its residue)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._checks import _short
from .._display import Summarized
from .._enums import wrap
from ..analysis import BarrierScan, OrbitClasses, classify_orbits
from ..interface import IterateResult, require_map
from .periodic import periodic_orbit

__all__ = ["IslandCentres", "island_centres"]


@dataclass(frozen=True, repr=False)
class IslandCentres(Summarized):
    """The periodic orbit at the centre of each island chain (:func:`island_centres`).

    Attributes
    ----------
    index : ndarray of int
        The orbits (rows of the input) that are island chains.
    orbits : list of PeriodicOrbit
        The periodic orbit found for each (same order as ``index``): converged, of the chain's
        period, and normally elliptic (its residue in (0, 1)); a chain whose centre Newton did not
        reach keeps the failed search's status.
    period : ndarray of int
        The chains' periods (number of islands).
    rotation : ndarray
        The chains' rotation numbers (turns per step mod 1) from the order statistics.
    """

    index: np.ndarray
    orbits: list
    period: np.ndarray
    rotation: np.ndarray

    def __len__(self) -> int:
        return len(self.orbits)

    @property
    def residues(self) -> np.ndarray:
        """Residue of each centre (NaN where none was found)."""
        return np.array([o.residue if o.converged else math.nan for o in self.orbits])

    def _summary(self) -> list:
        found = sum(o.converged for o in self.orbits)
        elliptic = sum(o.converged and o.stability == "elliptic" for o in self.orbits)
        return [("chains", len(self.orbits)), ("centres found", found), ("elliptic", elliptic)]


def _centre_seed(phi, K, q):
    """The centroid of the first island: the points z_{k q} of the orbit (phi unwrapped about their
    circular mean)."""
    p, k = phi[::q], K[::q]
    ok = np.isfinite(p) & np.isfinite(k)
    p, k = p[ok], k[ok]
    c = math.atan2(float(np.mean(np.sin(p))), float(np.mean(np.cos(p))))
    return float(wrap(c + np.mean(wrap(p - c)))), float(np.mean(k))


def island_centres(m, orbits, classes: OrbitClasses | None = None, **kwargs) -> IslandCentres:
    """The periodic orbit at the centre of every island chain among recorded orbits.

    For each orbit classified as a chain of q islands, Newton's general search
    (:func:`periodic_orbit`, period q) starts from the centroid of its first island (the points
    ``z_{k q}``): inside a chain of KAM islands the nearest periodic orbit of period q is the
    elliptic one the islands surround.

    Parameters
    ----------
    m : TruncatedMap, TruncatedFamily or FlowMap
        The map the orbits were computed with.
    orbits : IterateResult or BarrierScan
        Orbits with their points: an IterateResult recorded with ``"orbit"`` (every point:
        ``every=1``; the chain's islands are read from the points ``k q``), or a BarrierScan (its
        classes; each chain's start is iterated again for 256 q steps to read its islands).
    classes : OrbitClasses, optional
        The orbits' classes (default: :func:`hovering.classify_orbits` of an IterateResult).
    **kwargs
        Passed to :func:`periodic_orbit` (``tol``, ``max_iter``, ``n_threads``).

    Returns
    -------
    IslandCentres

    Raises
    ------
    ValueError
        For an IterateResult without recorded points or recorded with ``every != 1``, or classes
        of another number of orbits.

    Examples
    --------
    >>> import numpy as np, hovering
    >>> m = hovering.TruncatedMap(eps=0.5, Omega0=0.3, theta_w=2.0)
    >>> res = m.iterate(np.pi, [1.05, 1.3, 2.0], 4000, record=("orbit",))
    >>> hovering.classify_orbits(res).kind.tolist()
    ['chaotic', 'islands', 'circle']
    >>> found = hovering.dynamics.island_centres(m, res)
    >>> found.index.tolist(), found.period.tolist()          # orbit 1 is a chain of 5 islands ...
    ([1], [5])
    >>> o = found.orbits[0]                                  # ... around the elliptic 1/5 orbit
    >>> o.stability, f"{o.winding}/{o.period}", round(o.residue, 4)
    ('elliptic', '1/5', 0.0255)
    """
    require_map("m", m)
    if isinstance(orbits, BarrierScan):
        # The scan keeps few points, unevenly strided: each chain's start is iterated again for 256
        # turns of its period, every point recorded, and its first island read from that.
        kind, period, rotation = np.asarray(orbits.kind), np.asarray(orbits.period), np.asarray(orbits.rotation)
        idx = np.flatnonzero(kind == "islands")
        rows = {}
        for i in idx:
            q = int(period[i])
            r = m.iterate(orbits.phi0[i], orbits.K0[i], 256 * q, record=("orbit",))
            rows[int(i)] = (r.phi[0], r.K[0])
    elif isinstance(orbits, IterateResult):
        if orbits.phi is None:
            raise ValueError("the IterateResult has no orbit: iterate with record=('orbit',)")
        if orbits.every != 1:
            raise ValueError(
                f"island_centres reads the islands from every point: iterate with every=1, got {orbits.every}"
            )
        classes = classify_orbits(orbits) if classes is None else classes
        if not isinstance(classes, OrbitClasses) or len(classes) != orbits.phi.shape[0]:
            raise ValueError(
                f"classes must be the OrbitClasses of these {orbits.phi.shape[0]} orbits, got {_short(classes)}"
            )
        kind, period, rotation = classes.kind, classes.period, classes.rotation
        idx = np.flatnonzero(kind == "islands")
        rows = {int(i): (orbits.phi[i], orbits.K[i]) for i in idx}
    else:
        raise ValueError(f"orbits must be an IterateResult (record 'orbit') or a BarrierScan, got {_short(orbits)}")
    found = []
    for i in idx:
        q = int(period[i])
        seed = _centre_seed(*rows[int(i)], q)
        found.append(periodic_orbit(m, seed[0], seed[1], q, **kwargs))
    return IslandCentres(index=idx, orbits=found, period=np.asarray(period)[idx], rotation=np.asarray(rotation)[idx])
