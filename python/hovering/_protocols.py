"""The one interface both models share: a return map on (phi, K) (DynamicalSystemsBase's idea that a
flow's Poincare map *is* a map). Every analysis is written once against it.
"""

from __future__ import annotations

from typing import Iterable, Optional, Protocol, Sequence, Tuple, runtime_checkable

__all__ = ["ReturnMap", "MapAnalyses"]


@runtime_checkable
class ReturnMap(Protocol):
    """What :mod:`hovering.analysis` needs of a map: TruncatedMap, TruncatedFamily and FlowMap have it."""

    eps: float

    def step(self, phi, K):
        """One forward step."""

    def step_inverse(self, phi, K):
        """One backward step."""

    def region(self, phi, K):
        """Region of the return from each point."""

    def iterate(self, phi0, K0, n_steps: int, record: Sequence[str] = ..., exit_regions: Optional[Iterable] = None,
                stop_on_exit: bool = False, n_threads: int = 0, progress=False):
        """Many orbits at once -> IterateResult (progress: see hovering._progress)."""

    def with_eps(self, eps: float) -> "ReturnMap":
        """The same map at another eps (F_0 for the hovering set's definition)."""

    def valid_band(self) -> Tuple[float, float]:
        """Open interval of K on which the map is defined."""

    def theory(self):
        """Leading-order predictions (hovering.Theory) for this map's parameters."""

    def L1(self, K):
        """Angle of the line L1 at heights K (def:L1L2)."""

    def L2(self, K):
        """Angle of the line L2 at heights K (def:L1L2)."""


class MapAnalyses:
    """The analyses as methods, for every map (mixed into TruncatedMap, TruncatedFamily, FlowMap)."""

    def hovering_area(self, n_steps: int = 10_000, samples: int = 100_000, **kwargs):
        """Area of the hovering set HOV(eps), with error estimate and theory; see :func:`hovering.hovering_area`.

        Parameters
        ----------
        n_steps : int, optional
            Iterates that count as "never impacts".
        samples : int, optional
            Sample points (stratified over the box below K = 0).
        **kwargs
            ``K_low``, ``seed``, ``n_threads``, ``keep_points``, ``progress`` (True: a tqdm bar on
            stderr; a callable ``progress(done, total)``).

        Returns
        -------
        HoveringArea
            ``.area``, ``.error``, ``.theory`` and diagnostics.
        """
        from .analysis import hovering_area

        return hovering_area(self, n_steps=n_steps, samples=samples, **kwargs)

    def critical_curve(self, n_steps: int = 20_000, **kwargs):
        """Lowest invariant curve in the no-impact regions; see :func:`hovering.critical_curve`.

        Parameters
        ----------
        n_steps : int, optional
            Iterates per tested orbit.
        **kwargs
            ``K_range``, ``regions``, ``line``, ``grid``, ``digits``, ``tol``, ``n_threads``,
            ``search``, ``progress`` (True: a tqdm bar on stderr; a callable ``progress(done, total)``).

        Returns
        -------
        CriticalCurve
            ``.K_min``, ``.rotation``, ``.K_pred``, ``.rotation_pred``, ``.hovers``, ``.note``, ...
        """
        from .analysis import critical_curve

        return critical_curve(self, n_steps=n_steps, **kwargs)

    def hovers(self) -> bool:
        """Whether the leading-order theory predicts a hovering set for this map (see :meth:`theory`)."""
        return bool(self.theory().hovers)
