"""The flow's hovering verdicts against its truncated models', point by point.

:func:`hovering_area` on a FlowMap judges each sample of its box; :func:`compare_hovering` judges
the same samples with each truncated model of the flow (:meth:`hovering.FlowMap.truncated`): the
same (phi, K), the same N, the same definition (impacts under F_0, never under F_eps), so every
difference is the models' and not the sampling's.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._checks import flag, integer, is_choice, random_seed, thread_count
from .._core import analysis as _core_analysis
from .._deprecated import renamed_keywords
from .._io.serial import Saveable
from .._progress import check_progress, progress_bar
from ..normal import FlowMap
from .hovering import HoveringArea, _outcomes, hovering_area

__all__ = ["HoveringComparison", "ModelVerdicts", "compare_hovering"]

#: The models compare_hovering knows, and the forcing of FlowMap.truncated that builds each: the
#: paper's F_eps with the measured first mode (amplitude eps b1), and every measured mode.
MODELS = {"onset": "first_mode", "measured": "measured"}


@dataclass(frozen=True)
class ModelVerdicts:
    """One model's verdicts on the flow's samples (an entry of :class:`HoveringComparison`).

    Attributes
    ----------
    model : str
        ``"onset"`` (the first-mode TruncatedMap) or ``"measured"`` (the TruncatedFamily).
    agreement : float
        Fraction of the samples on which the model and the flow agree (both hover or neither).
    confusion : ndarray of int, shape (2, 2)
        ``confusion[f, m]``: samples where the flow hovers (f = 1) or not (0) and the model hovers
        (m = 1) or not (0). It sums to the number of samples.
    area : float
        The model's hovering area on these samples (the flow's box and N).
    outside_band : int
        Samples below the model's band (no point of the model there: it cannot hover).
    phi, K : ndarray
        The samples where the verdicts differ.
    flow_hovers : ndarray of bool
        For each of them: True where the flow hovers and the model does not, False the reverse.

    Examples
    --------
    >>> import hovering
    >>> fm = hovering.paper.flow_map(eps=-0.05)
    >>> v = hovering.compare_hovering(fm, ("onset",), 200, 100)["onset"]   # 200 samples, N = 100
    >>> v.model, v.confusion.shape, bool(v.agreement > 0.9)
    ('onset', (2, 2), True)
    >>> n_disagree = int(v.confusion[0, 1] + v.confusion[1, 0])
    >>> v.phi.shape == v.K.shape == v.flow_hovers.shape == (n_disagree,)
    True
    """

    model: str
    agreement: float
    confusion: np.ndarray
    area: float
    outside_band: int
    phi: np.ndarray = field(repr=False)
    K: np.ndarray = field(repr=False)
    flow_hovers: np.ndarray = field(repr=False)

    def _validate_loaded(self) -> None:
        """A file's verdicts (untrusted): a 2x2 count table and matching disagreement arrays."""
        c = np.asarray(self.confusion)
        if c.shape != (2, 2) or c.dtype.kind not in "iu" or (c < 0).any():
            raise ValueError(f"confusion must be a 2x2 table of counts >= 0, got {c.dtype} of shape {c.shape}")
        n = int(c[0, 1] + c[1, 0])
        for name in ("phi", "K", "flow_hovers"):
            if np.shape(getattr(self, name)) != (n,):
                raise ValueError(
                    f"{name} must hold the {n} disagreeing samples, got shape {np.shape(getattr(self, name))}"
                )


@dataclass(frozen=True)
class HoveringComparison(Saveable):
    """The flow's and its models' hovering verdicts on the same samples (see :func:`compare_hovering`).

    Attributes
    ----------
    flow : HoveringArea
        The flow's measurement, with its samples and verdicts (``keep_points``).
    models : tuple of ModelVerdicts
        Each model's verdicts, in the order asked for; also ``comparison["onset"]``.
    n_steps : int
        N of every verdict.

    Examples
    --------
    >>> import hovering
    >>> fm = hovering.paper.flow_map(eps=-0.05)
    >>> cmp = hovering.compare_hovering(fm, ("onset",), 200, 100)   # 200 samples, N = 100
    >>> cmp.n_steps, [v.model for v in cmp.models]
    (100, ['onset'])
    >>> bool(cmp.flow.area > 0), bool(cmp["onset"].area > 0)   # the flow and its model both hover
    (True, True)
    """

    flow: HoveringArea
    models: tuple
    n_steps: int

    def __getitem__(self, name: str) -> ModelVerdicts:
        """The verdicts of the model ``name``.

        Parameters
        ----------
        name : str
            A model of this comparison.

        Returns
        -------
        ModelVerdicts
        """
        for v in self.models:
            if v.model == name:
                return v
        raise KeyError(f"no model {name!r} in this comparison; it has {[v.model for v in self.models]}")

    def __repr__(self) -> str:
        box = self.flow.box
        parts = [
            f"{v.model}: agree {v.agreement:.4f} (flow only {int(v.confusion[1, 0])}, model only "
            f"{int(v.confusion[0, 1])}, area {v.area:.4g})"
            for v in self.models
        ]
        return (
            f"HoveringComparison({self.flow.n_samples} samples of K in [{box[2]:.4g}, 0), N = {self.n_steps}; "
            f"flow area {self.flow.area:.4g} +- {self.flow.error:.2g}; " + "; ".join(parts) + ")"
        )


@renamed_keywords(seed="rng")
def compare_hovering(
    flow_map,
    models=("onset", "measured"),
    n_samples: int = 20_000,
    n_steps: int = 2000,
    K_low: float | None = None,
    rng: int | np.random.Generator | None = 0,
    n_threads: int = 0,
    progress=False,
    *,
    components: bool = False,
    executor=None,
) -> HoveringComparison:
    """Hovering verdicts of the flow and of its truncated models on the same sample points.

    The flow's :func:`hovering_area` draws its box (the default one deepens itself while its floor
    is touched) and judges each sample; each model (:meth:`FlowMap.truncated`) judges the same
    samples with the same N by the same definition (the core's outcomes and estimate), so the
    table of verdicts compares the models and nothing else. A sample below a model's band escapes
    it at once and counts as "model does not hover" (``outside_band`` counts them).

    Parameters
    ----------
    flow_map : FlowMap
        The flow's return map, in normal coordinates, with onset parameters (its models need them).
    models : sequence of str, optional
        Among ``"onset"`` (the paper's F_eps with amplitude eps b1: ``truncated("first_mode")``)
        and ``"measured"`` (every measured mode: ``truncated("measured")``), no repeats.
    n_samples : int, optional
        Samples of the box (rounded up to fill the grid), >= 1.
    n_steps : int, optional
        N: iterates (returns of the flow) that count as "never", >= 4.
    K_low : float, optional
        Bottom of the box (default: the flow's default box, deepened while its floor is touched).
    rng : int, numpy.random.Generator or None, optional
        The jitter's randomness, as for :func:`hovering_area` (default 0; the seed used is
        ``comparison.flow.seed``). Formerly ``seed=`` (deprecated, still accepted with a
        DeprecationWarning; giving both is a TypeError).
    n_threads : int, optional
        Worker threads (0 = all cores).
    progress : bool or callable, optional
        As for :func:`hovering_area`: one report per measurement (the flow's box, each model).
    components : bool, optional
        Also split the flow's area into its parts (:attr:`HoveringArea.components`; costs a floor
        search and a few recorded orbits of the flow). Default False.
    executor : optional
        Where the flow's measurement runs (as for :func:`hovering_area`); the models run here.

    Returns
    -------
    HoveringComparison

    Raises
    ------
    TypeError
        For an ``rng`` that is not None, an int or a Generator, or both ``rng`` and ``seed``.
    ValueError
        Before any computation: for a map that is not a FlowMap in normal coordinates with onset
        parameters, unknown or repeated models, or counts out of range (each names the value and
        what is allowed).
    KeyboardInterrupt
        On Ctrl-C, within ~0.1 s.

    Examples
    --------
    The README's flow at eps = -0.05 against its first-mode model, on 200 samples followed for
    N = 100 returns (the docs' numbers use 5152 samples and N = 1000):

    >>> import hovering
    >>> fm = hovering.paper.flow_map(eps=-0.05)
    >>> cmp = hovering.compare_hovering(fm, ("onset",), 200, 100)
    >>> v = cmp["onset"]
    >>> bool(v.agreement > 0.9), int(v.confusion.sum()) == cmp.flow.phi.size   # every sample judged
    (True, True)
    """
    if not isinstance(flow_map, FlowMap):
        raise ValueError(f"flow_map must be a hovering.FlowMap, got {type(flow_map).__name__}")
    if isinstance(models, str) or not hasattr(models, "__iter__"):
        raise ValueError(f"models must be a sequence of names among {sorted(MODELS)}, got {models!r}")
    models = tuple(models)
    if not models:
        raise ValueError(f"models must name at least one of {sorted(MODELS)}, got none")
    for name in models:
        if not is_choice(name, tuple(MODELS)):
            raise ValueError(f"unknown model {name!r}; allowed: {', '.join(repr(k) for k in MODELS)}")
    if len(set(models)) != len(models):
        raise ValueError(f"models must not repeat a name, got {models!r}")
    n_samples = integer("n_samples", n_samples, 1, 2**53)
    n_steps = integer("n_steps", n_steps, 4, 2**53)
    seed = random_seed(rng)
    n_threads = thread_count(n_threads)
    progress = check_progress(progress)
    components = flag("components", components)
    # The models first: building them checks the map (normal coordinates, onset parameters) and
    # measures the forcing, before the long flow run.
    maps = {name: flow_map.truncated(forcing=MODELS[name]) for name in models}
    flow = hovering_area(
        flow_map,
        n_steps=n_steps,
        n_samples=n_samples,
        K_low=K_low,
        rng=seed,
        n_threads=n_threads,
        keep_points=True,
        progress=progress,
        components=components,
        executor=executor,
    )
    phi, K, flow_hv = flow.phi, flow.K, flow.hovering
    K_box = float(flow.box[2])
    verdicts = []
    for name in models:
        m = maps[name]
        with progress_bar(progress, 2 * phi.size * n_steps, desc=f"compare_hovering {name}") as bar:
            s0, s1, steps_done, visited = _outcomes(m, phi, K, n_steps, n_threads, bar.part(0))
        e = _core_analysis.hovering_estimate(s0, s1, steps_done, visited, K, int(n_steps), K_box, True)
        model_hv = e["hovering"]
        confusion = np.array(
            [[np.count_nonzero(~flow_hv & ~model_hv), np.count_nonzero(~flow_hv & model_hv)],
             [np.count_nonzero(flow_hv & ~model_hv), np.count_nonzero(flow_hv & model_hv)]],
            dtype=np.int64,
        )  # fmt: skip
        differ = flow_hv != model_hv
        verdicts.append(
            ModelVerdicts(
                model=name,
                agreement=float(1.0 - np.count_nonzero(differ) / phi.size),
                confusion=confusion,
                area=float(e["area"]),
                outside_band=int(np.count_nonzero(K <= m.valid_band()[0])),
                phi=phi[differ],
                K=K[differ],
                flow_hovers=flow_hv[differ],
            )
        )
    return HoveringComparison(flow=flow, models=tuple(verdicts), n_steps=n_steps)
