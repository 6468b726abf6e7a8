"""The ``hovering_area`` kind: |HOV| of the truncated map against eps, with error bars and the
theory eq:hovsetsize (a sweep: each point checkpointed, resumable, runnable by ``hovering_sweep``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._io.serial import saved_as
from ..._progress import progress_bar
from ..._style import orbit_color
from ...analysis.hovering import default_K_low
from ...parallel.checkpoint import Checkpoint
from ...truncated.theory import golden_family, hovering_area_theory
from ..base import SceneResult, check_array, fmt
from ..fields import Reading, color, custom, distinct_reals, integer, read_values, real, text, write
from ..plan import sweep_counts
from ..registry import Kind, register
from ..values import color as color_value
from ..values import tables
from ..values import text as text_value
from ._sweep import sweep, sweep_size
from ._truncated import MapSpec, TruncatedScene, map_key

__all__ = [
    "SeriesSpec",
    "HoveringAreaScene",
    "SeriesResult",
    "HoveringAreaResult",
    "plan",
    "compute",
    "summarize",
    "report",
    "KIND",
]


@saved_as("hovering.scenes.spec:SeriesSpec")
@dataclass(frozen=True)
class SeriesSpec:
    """One curve of a ``hovering_area`` scene: a map family over the scene's eps values.

    Attributes
    ----------
    label : str
        Legend label.
    Omega0, theta_w, tau0, tau1, lam : float or None
        Fixed parameters (``Omega0, theta_w`` None when ``golden_c`` is set).
    golden_c : float or None
        Use the golden family of thm:hoveringc: ``(Omega0, theta_w)`` recomputed at each eps.
    color : str or None
        Matplotlib colour.
    K_low : float or None
        Bottom of the sampled box ``[-pi, pi) x [K_low, 0)`` (default: the analysis module's,
        ``-2|eps|/|sin(Omega0/2)|``, which holds the critical band of eq:hovsetsize); set it near
        the band floor to measure HOV by its definition over the whole band.
    """

    label: str = text(drawn=True)
    Omega0: float | None = map_key("Omega0")
    theta_w: float | None = map_key("theta_w")
    tau0: float = map_key("tau0")
    tau1: float = map_key("tau1")
    lam: float = map_key("lam")
    golden_c: float | None = real(None)
    color: str | None = color()
    K_low: float | None = real(None, hi=0.0, hi_open=True)

    def map_at(self, eps: float) -> MapSpec:
        """The map of this series at one eps.

        Parameters
        ----------
        eps : float
            Perturbation amplitude.

        Returns
        -------
        MapSpec
        """
        if self.golden_c is not None:
            O, tw = golden_family(eps, self.golden_c, self.tau0)
            return MapSpec(eps, O, tw, self.tau0, self.tau1, self.lam, self.golden_c, eps)
        return MapSpec(eps, self.Omega0, self.theta_w, self.tau0, self.tau1, self.lam)


def _read_series(where: str, value, reading) -> tuple:
    """The curves: each a map family (fixed, or the golden family) checked at every eps of the scene."""
    eps = reading.values["eps"]
    series = []
    for i, st in enumerate(tables(where, value, "series")):
        sw = f"{where}[{i}]"
        vals = read_values(SeriesSpec, sw, st, Reading(sw, {}, parent=reading))
        if vals["golden_c"] is not None:
            for k in ("Omega0", "theta_w"):
                if k in st:
                    raise ValueError(f"{sw}: give either 'golden_c' or {k!r}, not both")
            if not abs(vals["golden_c"]) < abs(vals["tau0"]):
                raise ValueError(
                    f"{sw}.golden_c = {st['golden_c']!r} is out of range; allowed: |c| < |tau0| = {abs(vals['tau0'])}"
                )
            vals["Omega0"] = vals["theta_w"] = None
        else:
            for k in ("Omega0", "theta_w"):
                if k not in vals:
                    raise ValueError(f"{sw}: missing required key {k!r} (in [map] or the series), or 'golden_c'")
        s = SeriesSpec(**vals)
        for e in eps:
            try:
                m = s.map_at(e).build()
            except ValueError as err:
                raise ValueError(f"{sw} at eps = {e}: {err}") from None
            if s.K_low is not None and not s.K_low > m.valid_band()[0]:
                raise ValueError(
                    f"{sw}.K_low = {st['K_low']!r} lies below the band floor {m.valid_band()[0]:.6g} "
                    f"of the map at eps = {e}; allowed: ({m.valid_band()[0]:.6g}, 0)"
                )
        series.append(s)
    return tuple(series)


def _series_value(series: tuple, kind) -> list:
    return [write(s, kind) for s in series]


@saved_as("hovering.scenes.spec:HoveringAreaScene")
@dataclass(frozen=True, kw_only=True)
class HoveringAreaScene(TruncatedScene):
    """``hovering_area`` scene of the truncated map: |HOV| against eps.

    Attributes
    ----------
    n_steps : int
        The N of "never impacts within N steps".
    eps : tuple of float
        The eps values.
    samples : int
        Sample points per eps.
    seed : int
        Sampling seed.
    series : tuple of SeriesSpec
        The curves.
    """

    eps: tuple = distinct_reals((), required=True)
    samples: int = integer(100_000, lo=1, hi=100_000_000)
    seed: int = integer(0, lo=0, hi=2**63 - 1)
    series: tuple = custom((), read=_read_series, write=_series_value, required=True, allowed="1 to 36 series")


# ------------------------------------------------------------------------------------------------
# Results


@saved_as("hovering.scenes.results:SeriesResult")
@dataclass
class SeriesResult:
    """One curve of |HOV| against eps.

    Attributes
    ----------
    label, color : str
        Legend label and colour.
    eps, area, error, theory : ndarray
        Measured points and eq:hovsetsize at them.
    floor_touched : ndarray of bool
        Hovering points reached the lowest tenth of the sampled box.
    K_low, Omega0, theta_w : ndarray
        The box floor and the map at each point.
    theory_eps, theory_curve : ndarray
        The theory drawn as a line (empty when another series with the same map family drew it).
    golden_c : float or None
        Golden-family parameter.
    reused : int
        Points read from the checkpoint instead of computed.
    """

    label: str
    color: str
    eps: np.ndarray
    area: np.ndarray
    error: np.ndarray
    theory: np.ndarray
    floor_touched: np.ndarray
    K_low: np.ndarray
    Omega0: np.ndarray
    theta_w: np.ndarray
    theory_eps: np.ndarray
    theory_curve: np.ndarray
    golden_c: float | None = None
    reused: int = 0

    def _validate_loaded(self) -> None:

        text_value("label", self.label)
        color_value("color", self.color)
        check_array("eps", self.eps, 1)
        for name in ("area", "error", "theory", "K_low", "Omega0", "theta_w"):
            check_array(name, getattr(self, name), 1, shape=self.eps.shape)
        check_array("floor_touched", self.floor_touched, 1, "b", shape=self.eps.shape)
        check_array("theory_eps", self.theory_eps, 1)
        check_array("theory_curve", self.theory_curve, 1, shape=self.theory_eps.shape)


@saved_as("hovering.scenes.results:HoveringAreaResult")
@dataclass(repr=False)
class HoveringAreaResult(SceneResult):
    """Result of a ``hovering_area`` scene.

    Attributes
    ----------
    series : list of SeriesResult
        One per curve.
    """

    series: list = field(default_factory=list)

    def _summary(self) -> list:
        eps = [float(e) for x in self.series for e in x.eps]
        rng = f"{min(eps):g}..{max(eps):g}" if eps else "none"
        return super()._summary() + [("series", [x.label for x in self.series]), ("eps", rng), ("points", len(eps))]

    def to_pandas(self):
        """The sweep as a :class:`pandas.DataFrame` (needs ``hovering[pandas]``): one row per
        (series label, eps), indexed by both; columns ``area``, ``error``, ``theory``,
        ``floor_touched``, ``K_low``, ``Omega0``, ``theta_w``.

        Returns
        -------
        pandas.DataFrame

        Raises
        ------
        ImportError
            Without pandas, naming ``pip install pandas`` and the extra ``.[pandas]``.
        """
        from ..._io.interop import series_frame

        return series_frame(self)

    def to_xarray(self):
        """The sweep as an :class:`xarray.Dataset` (needs ``hovering[xarray]``): dimensions
        ``series`` (the labels) and ``eps`` (NaN where a series has no point at that eps), the
        columns of :meth:`to_pandas` as variables; units, the scene and provenance in attrs.

        Returns
        -------
        xarray.Dataset

        Raises
        ------
        ImportError
            Without xarray, naming ``pip install xarray`` and the extra ``.[xarray]``.
        """
        from ..._io.interop import series_dataset

        return series_dataset(self)

    def _validate_loaded(self) -> None:
        super()._validate_loaded()
        for i, x in enumerate(self.series):
            if not isinstance(x, SeriesResult):
                raise ValueError(f"series[{i}] must be a SeriesResult, got {type(x).__name__}")


# ------------------------------------------------------------------------------------------------
# The plan and the computation


def plan(scene: HoveringAreaScene, quick: bool = False) -> list:
    """The resolved points of the sweep, series-major: each series at each eps, its map evaluated
    (the golden family at that eps), its box (the default: the critical band, cut to the map's
    band) and the theory value (:mod:`hovering.scenes.plan`).

    Parameters
    ----------
    scene : HoveringAreaScene
        The scene.
    quick : bool, optional
        A quick run's counts.

    Returns
    -------
    list of dict
    """
    n_steps, samples = sweep_counts(scene, quick)
    out = []
    for s in scene.series:
        for e in scene.eps:
            ms = s.map_at(e)
            m = ms.build()
            # The default box is hovering_area's: the critical band, cut to the map's band.
            K_low = float(s.K_low) if s.K_low is not None else default_K_low(m)
            mp = {k: float(getattr(ms, k)) for k in ("eps", "Omega0", "theta_w", "tau0", "tau1", "lam")}
            out.append(
                {
                    "label": s.label,
                    "n_steps": int(n_steps),
                    "samples": int(samples),
                    "seed": int(scene.seed),
                    "K_low": float(K_low),
                    "theory": float(m.theory().area),
                    "map": mp,
                }
            )
    return out


def _theory_line(spec, eps_all: np.ndarray) -> tuple:
    e_hi = max(float(eps_all.max()), 0.0)
    e_lo = min(float(eps_all.min()), 0.0)
    eg = np.linspace(0.0, e_hi, 200)[1:]
    if spec.golden_c is not None:
        tg = np.array(
            [hovering_area_theory(x, tw, O) for x in eg for O, tw in [golden_family(x, spec.golden_c, spec.tau0)]]
        )
    else:
        tg = np.asarray(hovering_area_theory(eg, spec.theta_w, spec.Omega0), dtype=float)
    return np.concatenate([[e_lo, 0.0], eg]), np.concatenate([[0.0, 0.0], tg])


def compute(scene: HoveringAreaScene, ctx) -> HoveringAreaResult:
    """Measure every point of the plan (or read it from the checkpoint), then gather the curves
    and draw each map family's theory once.

    Parameters
    ----------
    scene : HoveringAreaScene
        The scene.
    ctx : hovering.scenes.base.Context
        Quick run, progress, meta, checkpoint and executor.

    Returns
    -------
    HoveringAreaResult
    """
    meta, progress, where = ctx.meta, ctx.progress, ctx.executor
    points = plan(scene, ctx.quick)
    meta.update(n_steps=points[0]["n_steps"], samples=points[0]["samples"])
    # Each measured point is on disk at once; a rerun resumes where an interrupted one stopped and
    # recomputes nothing already measured (keys hold every parameter that changes a point).
    ckpt = Checkpoint(ctx.checkpoint)
    meta["checkpoint"] = str(ckpt.path)
    eps_all = np.array(scene.eps)
    stages = ctx.stages(1)
    stages.start("sweep", sweep_size(points, where))
    with progress_bar(progress, total=len(points), desc=scene.name, unit="point") as bar:
        all_rows, from_ckpt = sweep(scene.kind, points, ckpt, bar, where, scene.name)
    stages.end()
    drawn = set()
    out = []
    ne = len(scene.eps)
    for k, s in enumerate(scene.series):
        rows = all_rows[k * ne : (k + 1) * ne]
        pts = points[k * ne : (k + 1) * ne]
        reused = sum(from_ckpt[k * ne : (k + 1) * ne])
        fam = (s.golden_c, s.Omega0, s.theta_w, s.tau0)
        te, tc = _theory_line(s, eps_all) if fam not in drawn else (np.zeros(0), np.zeros(0))
        drawn.add(fam)
        col = lambda c, dt=float: np.array([r[c] for r in rows], dtype=dt)  # noqa: E731
        par = lambda c: np.array([p["map"][c] for p in pts], dtype=float)  # noqa: E731
        out.append(
            SeriesResult(
                label=s.label,
                color=s.color or orbit_color(k),
                eps=par("eps"),
                area=col("area"),
                error=col("error"),
                theory=col("theory"),
                floor_touched=col("floor_touched", bool),
                K_low=col("K_low"),
                Omega0=par("Omega0"),
                theta_w=par("theta_w"),
                theory_eps=te,
                theory_curve=tc,
                golden_c=s.golden_c,
                reused=reused,
            )
        )
    meta["points_reused"] = sum(from_ckpt)
    return HoveringAreaResult(scene=scene, meta=meta, series=out)


# ------------------------------------------------------------------------------------------------
# Summary and report


def summarize(result: HoveringAreaResult) -> dict:
    """Each series' points: eps, area, error, theory, box floor, the map.

    Parameters
    ----------
    result : HoveringAreaResult
        The result.

    Returns
    -------
    dict
        ``series``.
    """
    return {
        "series": [
            dict(
                label=r.label,
                golden_c=r.golden_c,
                points=[
                    dict(
                        eps=float(e),
                        area=float(a),
                        error=float(er),
                        theory=float(t),
                        floor_touched=bool(f),
                        K_low=float(kl),
                        Omega0=float(O),
                        theta_w=float(tw),
                    )
                    for e, a, er, t, f, kl, O, tw in zip(
                        r.eps, r.area, r.error, r.theory, r.floor_touched, r.K_low, r.Omega0, r.theta_w
                    )
                ],
            )
            for r in result.series
        ]
    }


def report(summary: dict) -> list:
    """One line per measured point of each series.

    Parameters
    ----------
    summary : dict
        From :func:`summarize` (with the common numbers).

    Returns
    -------
    list of str
    """
    f, lines = fmt, []
    for s in summary.get("series", []):
        lines.append(f"  {s['label']}:")
        for r in s["points"]:
            flag = "  (box floor touched)" if r["floor_touched"] else ""
            lines.append(
                f"    eps = {f(r['eps'], '+.3f')}: |HOV| = {f(r['area'], '.4f')} +- {f(r['error'], '.4f')}, "
                f"theory {f(r['theory'], '.4f')}{flag}"
            )
    return lines


def scene_map(scene: HoveringAreaScene):
    """The map of the first series at the first eps.

    Parameters
    ----------
    scene : HoveringAreaScene
        The scene.

    Returns
    -------
    TruncatedMap
    """
    return scene.series[0].map_at(scene.eps[0]).build()


KIND = register(
    Kind(
        "hovering_area",
        HoveringAreaScene,
        HoveringAreaResult,
        compute,
        summarize,
        report,
        family="truncated",
        doc="|HOV| of the truncated map against eps with the theory eq:hovsetsize (fig:hov_vs_eps)",
        figsize=(13.0, 5.2),
        scene_map=scene_map,
        plan=plan,
        quick_floor=(100, 400),
    )
)
