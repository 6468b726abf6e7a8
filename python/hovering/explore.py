"""Interactive phase portraits: click a point of (phi, K), see its orbit.

:func:`explore` opens a phase portrait of any return map (:class:`~hovering.TruncatedMap`,
:class:`~hovering.TruncatedFamily`, :class:`~hovering.FlowMap`, or the map of a scene file) on
which a left click launches an orbit from the clicked point. Each orbit is drawn as points
coloured by the region each step was taken from (J_0u, J_0, J_1, J_R and, for the flow, several
impacts), its start marked with a black ``+``. An orbit that stops (left the band, hit a corner,
grazed, ...) is drawn up to where it stopped, that point marked with a black ``x``, and its status
shown in the title and the legend.

Mouse and keys
--------------
* left click in the axes: launch an orbit from the clicked point;
* right click in the axes, ``u`` or ``delete``: remove the last orbit;
* ``x``: remove every orbit.

Clicks outside the axes, or while the toolbar's zoom or pan mode is on, do nothing. A click on a
point where the map has no point (outside the band of a truncated map, or off Sigma_h for the flow:
status ``ESCAPED`` / ``OFF_SECTION`` before the first step) adds no orbit; the title says why.

In a script, call ``matplotlib.pyplot.show()`` after :func:`explore` to open the window; from the
command line, :func:`main` (``python -m hovering explore SCENE``) does both.

Note that ``hovering.explore`` is the function; this module's other names are imported with
``from hovering.explore import Explorer, Orbit, default_K_range, main``.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from dataclasses import dataclass, field

import numpy as np

from ._checks import integer, real_number, require_angles, require_type
from ._enums import Region, Status, wrap
from ._style import REGION_COLORS
from .interface import require_map
from .normal.flowmap import FlowMap
from .plot.primitives import break_seam

__all__ = [
    "explore",
    "Explorer",
    "Orbit",
    "default_K_range",
    "default_n_steps",
    "main",
    "COLORS",
    "DEFAULT_N_STEPS",
    "MAX_N_STEPS",
]

#: Default steps per orbit: a truncated-map step costs ~10 ns, a return of the flow ~10 us, so
#: these keep a click's answer well under a tenth of a second for either.
DEFAULT_N_STEPS = {"truncated": 2000, "flow": 500}

#: Most steps per orbit :func:`explore` accepts (one orbit of the flow at 1e7 returns is ~100 s).
MAX_N_STEPS = 10**7

#: Colour of the points of each region (the flow's Region.MULTI included): the package's one table,
#: :data:`hovering._style.REGION_COLORS`, under the name this module has always exported.
COLORS = REGION_COLORS
_NO_REGION_COLOR = "0.5"

# Status names are terse; the title says what they mean for a clicked orbit.
_WHY = {
    Status.ESCAPED: "left the band where the map is defined",
    Status.EXITED: "left the watched regions",
    Status.INTERRUPTED: "interrupted",
    Status.CORNER: "hit a corner of the step",
    Status.GRAZING: "grazing impact",
    Status.STEP_LIMIT: "integrator step limit reached",
    Status.NON_FINITE: "the state became non-finite",
    Status.IMPACT_LIMIT: "too many impacts in one return",
    Status.OFF_SECTION: "left Sigma_h",
    Status.OUTSIDE_WELL: "reached the edge of a bounded well",
    Status.IMPRECISE: "a return's error could not be verified within rtol",
}
_WHY_AT_START = {
    Status.ESCAPED: "the point lies outside the band where the map is defined",
    Status.OFF_SECTION: "no point of Sigma_h there",
}

_KEYS_REMOVE = ("u", "delete")
_KEYS_CLEAR = ("x",)
_LEGEND_STOPPED = 5  # stopped orbits listed in the legend (the most recent)


def _is_flow(m) -> bool:
    return isinstance(m, FlowMap)


def _in_section_coordinates(m) -> bool:
    return getattr(m, "coordinates", "normal") == "section"


def default_n_steps(m) -> int:
    """Steps per orbit :func:`explore` uses when none are given.

    Parameters
    ----------
    m : ReturnMap
        The map.

    Returns
    -------
    int
        ``DEFAULT_N_STEPS["flow"]`` (500) for a :class:`~hovering.FlowMap`, else
        ``DEFAULT_N_STEPS["truncated"]`` (2000).
    """
    return DEFAULT_N_STEPS["flow" if _is_flow(m) else "truncated"]


def default_K_range(m) -> tuple:
    """Heights shown by :func:`explore` when no ``K_range`` is given.

    In normal coordinates the range is ``(2 K_crit, s)`` when the leading-order theory predicts a
    hovering set (``K_crit < 0``, the height of the critical curve on L1), else ``(-2 s, s)``, with
    ``s = |eps| max_k |b_k| / |sin(Omega0 / 2)|`` the size of the invariant curves' O(eps)
    oscillation (the scale :func:`hovering.critical_curve` searches on); so the critical curve, the
    hovering set between it and K = 0 and the impacting orbits below it are in view. The range is
    cut to the map's :meth:`valid_band`. Without a theory (a FlowMap in section coordinates, or
    below the step energy) it is the band itself when that is finite; at ``eps = 0`` (nothing to
    scale by) ``(-1, 0.5)`` cut to the band.

    Parameters
    ----------
    m : ReturnMap
        The map.

    Returns
    -------
    (float, float)
        ``(K_lo, K_hi)`` with ``K_lo < K_hi``.
    """
    require_map("m", m)
    band_lo, band_hi = (float(v) for v in m.valid_band())
    band_finite = math.isfinite(band_lo) and math.isfinite(band_hi)
    th, K_lo = None, None
    if not _in_section_coordinates(m):
        try:
            th = m.theory()
        except ValueError:  # no onset parameters (FlowMap below the step energy)
            th = None
    if th is None:
        if band_finite:
            return band_lo, band_hi
        scale = 0.5
    else:
        b = max(abs(float(x)) for x in th.forcing)
        scale = abs(m.eps) * b / max(abs(math.sin(0.5 * th.Omega0)), 1e-3)
        if not (math.isfinite(scale) and scale > 0):  # eps = 0: nothing to scale by
            scale = 0.5
        if th.hovers and math.isfinite(th.K_crit) and th.K_crit < 0:
            K_lo = 2.0 * th.K_crit
    if K_lo is None:
        K_lo = -2.0 * scale
    lo, hi = max(K_lo, band_lo), min(scale, band_hi)
    if not lo < hi:  # a band entirely above or below the scale: show the band (or a unit window in it)
        lo, hi = (band_lo, band_hi) if band_finite else (max(band_lo, -1.0), max(band_lo, -1.0) + 1.5)
    return float(lo), float(hi)


@dataclass
class Orbit:
    """One orbit launched by a click (or :meth:`Explorer.launch`).

    Attributes
    ----------
    number : int
        Its number in the explorer (1, 2, ...: counts every launch, removed ones included).
    phi0, K0 : float
        The start as given (clicked); ``phi[0]`` is ``phi0`` wrapped to [-pi, pi).
    phi, K : ndarray
        The orbit's points ``0 .. steps_done`` (the map's coordinates: theta, I for a FlowMap in
        section coordinates). For an orbit that stopped, the last point is where it stopped (for
        ``ESCAPED``, the image outside the band).
    region : ndarray of int8
        Region code (:class:`~hovering.Region`) of the point each of the ``steps_done`` steps was
        taken from.
    status : Status
        ``Status.OK`` if all ``n_steps`` steps were taken, else why the orbit stopped.
    steps_done : int
        Steps taken.
    result : IterateResult
        The one-orbit result of ``map.iterate(phi0, K0, n_steps, record=("orbit", "regions"))``.
    """

    number: int
    phi0: float
    K0: float
    phi: np.ndarray
    K: np.ndarray
    region: np.ndarray
    status: Status
    steps_done: int
    result: object = field(repr=False)
    artists: list = field(default_factory=list, repr=False)

    def __repr__(self) -> str:
        return (
            f"Orbit(#{self.number}, start=({self.phi0:.6g}, {self.K0:.6g}), steps_done={self.steps_done}, "
            f"status={self.status.name})"
        )

    @property
    def stopped(self) -> bool:
        """Whether the orbit stopped before ``n_steps`` steps."""
        return self.status != Status.OK

    @property
    def impacts(self) -> int:
        """Steps taken from an impacting region (J_1, J_R, or several impacts for the flow)."""
        return int(np.count_nonzero(np.isin(self.region, (int(Region.UPPER), int(Region.RIGHT), int(Region.MULTI)))))


class Explorer:
    """An interactive phase portrait of a return map (see :func:`explore`, which builds it).

    Parameters
    ----------
    m : ReturnMap
        TruncatedMap, TruncatedFamily or FlowMap (anything with the ReturnMap protocol).
    n_steps : int, optional
        Steps per orbit, an integer in [1, 10**7] (default: :func:`default_n_steps`, 2000 for
        truncated maps and 500 returns for the flow, whose returns cost ~10 us each).
    K_range : (float, float), optional
        Heights shown (default: :func:`default_K_range`). May reach beyond the map's
        :meth:`valid_band`, which is then shaded: a truncated map has no point there, the flow's
        band is approximate (a click just outside it may still find a point of Sigma_h).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (default: a new figure). :meth:`close` closes only a figure it made.
    marker_size : float, optional
        Scatter marker size of the orbit points, in (0, 100].
    max_points : int, optional
        Most points drawn per orbit, in [1, 10**8]: longer orbits are thinned uniformly for
        drawing only (:attr:`orbits` keeps every point).

    Attributes
    ----------
    fig : matplotlib.figure.Figure
    ax : matplotlib.axes.Axes
    map : ReturnMap
    n_steps : int
    K_range : (float, float)
    orbits : list of Orbit
        The orbits drawn, in launch order.
    message : str
        What the last action did (also the axes title).

    Raises
    ------
    ValueError
        Naming the argument and its allowed range, before anything is drawn.
    """

    def __init__(
        self,
        m,
        n_steps: int | None = None,
        K_range=None,
        ax=None,
        marker_size: float = 2.0,
        max_points: int = 1_000_000,
    ):
        require_map("m", m)
        self.n_steps = default_n_steps(m) if n_steps is None else integer("n_steps", n_steps, 1, MAX_N_STEPS)
        self.K_range = default_K_range(m) if K_range is None else _K_range(K_range)
        self.marker_size = real_number("marker_size", marker_size, lo=0.0, hi=100.0, hi_open=False)
        self.max_points = integer("max_points", max_points, 1, 10**8)
        import matplotlib.pyplot as plt
        from matplotlib.axes import Axes

        if ax is not None:
            require_type("ax", ax, Axes, "a matplotlib Axes")
        self.map = m
        self.orbits: list = []
        self.message = ""
        self._count = 0
        self._own_figure = ax is None
        if ax is None:
            self.fig, self.ax = plt.subplots(figsize=(10, 6), layout="constrained")
        else:
            self.fig, self.ax = ax.figure, ax
        self._rgba = self._region_rgba()
        self._setup_axes()
        canvas = self.fig.canvas
        self._cids = [
            canvas.mpl_connect("button_press_event", self._on_press),
            canvas.mpl_connect("key_press_event", self._on_key),
        ]
        self._say(f"left click: launch an orbit ({self.n_steps} steps)")

    def __repr__(self) -> str:
        return (
            f"Explorer({type(self.map).__name__}(eps={self.map.eps:g}), n_steps={self.n_steps}, "
            f"K_range={self.K_range}, {len(self.orbits)} orbit(s))"
        )

    # ------------------------------------------------------------------ actions

    def launch(self, phi, K) -> Orbit | None:
        """Iterate an orbit from ``(phi, K)`` and draw it: what a left click does.

        Parameters
        ----------
        phi, K : float
            The start, in the map's coordinates (|phi| <= 1e6; it is wrapped to [-pi, pi)).

        Returns
        -------
        Orbit or None
            The orbit added, or None when the map has no point at ``(phi, K)`` (it could not take
            a single step: ``ESCAPED`` outside a truncated map's band, ``OFF_SECTION`` off
            Sigma_h); then :attr:`message` says why and nothing is drawn.

        Raises
        ------
        ValueError
            For a non-finite start or an angle beyond 1e6.
        KeyboardInterrupt
            On Ctrl-C during a long orbit, after drawing the part computed (status INTERRUPTED).
        """
        phi = real_number("phi", phi)
        require_angles("phi", np.asarray(phi))
        K = real_number("K", K)
        try:
            res = self.map.iterate(phi, K, self.n_steps, record=("orbit", "regions"), n_threads=1)
        except KeyboardInterrupt as exc:
            partial = getattr(exc, "partial", None)
            if partial is not None:
                self._add(phi, K, partial)
            raise
        return self._add(phi, K, res)

    def remove_last(self) -> Orbit | None:
        """Remove the most recent orbit (what a right click does).

        Returns
        -------
        Orbit or None
            The orbit removed, or None if there was none.
        """
        if not self.orbits:
            self._say("no orbit to remove")
            return None
        o = self.orbits.pop()
        self._remove_artists(o)
        self._update_legend()
        self._say(f"removed orbit #{o.number}; {len(self.orbits)} left")
        return o

    def clear(self) -> None:
        """Remove every orbit (what the ``x`` key does)."""
        n = len(self.orbits)
        for o in self.orbits:
            self._remove_artists(o)
        self.orbits.clear()
        self._update_legend()
        self._say(f"cleared {n} orbit(s)")

    def close(self) -> None:
        """Stop listening to the mouse and keys, and close the figure if the explorer made it."""
        import matplotlib.pyplot as plt

        for cid in self._cids:
            self.fig.canvas.mpl_disconnect(cid)
        self._cids = []
        if self._own_figure:
            plt.close(self.fig)

    # ------------------------------------------------------------------ events

    def _on_press(self, event) -> None:
        if event.inaxes is not self.ax or event.xdata is None or event.dblclick:
            return  # a double click's second press would launch the same orbit twice
        toolbar = getattr(self.fig.canvas, "toolbar", None)
        # Zoom and pan own the mouse while active (they take the widget lock); a click then is theirs.
        if (toolbar is not None and getattr(toolbar, "mode", "")) or self.fig.canvas.widgetlock.locked():
            return
        if event.button == 1:
            try:
                self.launch(event.xdata, event.ydata)
            except ValueError as e:  # a GUI callback has nobody to raise to: say it instead
                self._say(f"no orbit: {e}")
        elif event.button == 3:
            self.remove_last()

    def _on_key(self, event) -> None:
        if event.key in _KEYS_REMOVE:
            self.remove_last()
        elif event.key in _KEYS_CLEAR:
            self.clear()

    # ------------------------------------------------------------------ drawing

    def _add(self, phi0: float, K0: float, res) -> Orbit | None:
        n = int(res.steps_done[0])
        status = Status(int(res.status[0]))
        if n == 0:
            why = _WHY_AT_START.get(status, _WHY.get(status, ""))
            self._say(f"no orbit from ({phi0:.6g}, {K0:.6g}): {status.name} ({why})")
            return None
        self._count += 1
        o = Orbit(
            number=self._count,
            phi0=phi0,
            K0=K0,
            phi=res.phi[0, : n + 1].copy(),
            K=res.K[0, : n + 1].copy(),
            region=res.region[0, :n].copy(),
            status=status,
            steps_done=n,
            result=res,
        )
        stride = max(1, -(-n // self.max_points))
        ax = self.ax
        # Points 0..n-1 are those a step was taken from, so each has the region that step used.
        o.artists.append(
            ax.scatter(
                o.phi[:n:stride],
                o.K[:n:stride],
                s=self.marker_size,
                c=self._rgba[o.region[::stride].astype(int) + 1],
                lw=0,
                zorder=3,
                rasterized=n > 20_000,
            )
        )
        o.artists += ax.plot([o.phi[0]], [o.K[0]], ls="none", marker="+", ms=11, mew=1.6, color="k", zorder=5)
        if o.stopped:
            o.artists += ax.plot(
                [o.phi[n]],
                [o.K[n]],
                ls="none",
                marker="x",
                ms=8,
                mew=1.6,
                color="k",
                zorder=5,
                label=f"#{o.number}: {status.name} after {n}",
            )
        self.orbits.append(o)
        self._update_legend()
        start = f"#{o.number} from ({phi0:.6g}, {K0:.6g})"
        if o.stopped:
            self._say(f"{start}: stopped after {n} of {self.n_steps} steps, {status.name} ({_WHY.get(status, '')})")
        else:
            self._say(f"{start}: {n} steps, {o.impacts} with an impact")
        return o

    def _remove_artists(self, o: Orbit) -> None:
        for a in o.artists:
            a.remove()
        o.artists.clear()

    def _say(self, text: str) -> None:
        self.message = text
        self.ax.set_title(text, fontsize=9, loc="left")
        self.fig.canvas.draw_idle()

    def _regions_shown(self) -> list:
        regions = [Region.BESIDE, Region.ABOVE, Region.UPPER, Region.RIGHT]
        return regions + [Region.MULTI] if _is_flow(self.map) else regions

    def _region_rgba(self) -> np.ndarray:
        from matplotlib.colors import to_rgba

        # Indexed by region code + 1, so Region.NONE (-1) is row 0.
        table = np.empty((len(Region), 4))
        for r in Region:
            table[int(r) + 1] = to_rgba(COLORS.get(r, _NO_REGION_COLOR))
        return table

    def _setup_axes(self) -> None:
        from matplotlib.lines import Line2D

        m, ax = self.map, self.ax
        lo, hi = self.K_range
        section = _in_section_coordinates(m)
        band_lo, band_hi = (float(v) for v in m.valid_band())
        outside = [
            ax.axhspan(a, b, color="0.9", zorder=0, lw=0, label="outside valid_band()")
            for a, b in ((lo, min(band_lo, hi)), (max(band_hi, lo), hi))
            if a < b
        ]
        if not section:
            if lo < 0 < hi:
                ax.axhline(0.0, color="0.45", lw=0.8, zorder=1)
            K = np.linspace(max(lo, band_lo), min(hi, band_hi), 400)
            K = K[(K > band_lo) & (K < band_hi)]
            self._draw_lines(K)
        ax.set_xlim(-np.pi, np.pi)
        ax.set_ylim(lo, hi)
        ax.set_autoscale_on(False)  # an orbit that escapes must not move the view
        ax.set_xlabel(r"$\theta$" if section else r"$\phi$")
        ax.set_ylabel(r"$I$" if section else r"$K$")
        proxy = dict(ls="none", marker="o", ms=5)
        self._legend_base = [
            Line2D([], [], color=COLORS[r], label=f"from J_{r.label}", **proxy) for r in self._regions_shown()
        ]
        self._legend_base.append(Line2D([], [], ls="none", marker="+", ms=9, mew=1.6, color="k", label="start"))
        self._legend_base += outside[:1]
        self._update_legend()
        if self._own_figure:  # a figure the caller made keeps its own title
            self.fig.suptitle(
                f"{type(m).__name__}, eps = {m.eps:g}: {self.n_steps} steps per orbit   |   left "
                f"click: launch   right click / u / delete: remove last   x: clear",
                fontsize=9,
            )

    def _draw_lines(self, K: np.ndarray) -> None:
        """L1, L2 (grey) and, for truncated maps, the corner-singularity curves (dotted) over heights K."""
        if K.size == 0:
            return
        for fn, ls in (("L1", "-"), ("L2", "--")):
            try:
                phi = wrap(getattr(self.map, fn)(K))
            except (ValueError, AttributeError):  # no onset parameters: no lines
                return
            self.ax.plot(break_seam(phi), K, color="0.6", lw=0.8, ls=ls, zorder=1)
            self.ax.annotate(
                fn,
                (phi[-1], K[-1]),
                fontsize=7,
                color="0.45",
                xytext=(2, -8),
                textcoords="offset points",
                annotation_clip=True,
            )
        Kn = K[K < 0]
        if hasattr(self.map, "corner_curves") and Kn.size:
            for phi in self.map.corner_curves(Kn).values():
                self.ax.plot(break_seam(phi), Kn, color="k", lw=0.6, ls=":", zorder=2)

    def _update_legend(self) -> None:
        from matplotlib.lines import Line2D

        handles = list(self._legend_base)
        stopped = [a for o in self.orbits if o.stopped for a in o.artists[-1:]]
        handles += stopped[-_LEGEND_STOPPED:]
        if len(stopped) > _LEGEND_STOPPED:
            handles.append(Line2D([], [], ls="none", label=f"... {len(stopped) - _LEGEND_STOPPED} more stopped"))
        self.ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, fontsize=7)


def _K_range(value) -> tuple:
    """A K_range argument: two finite increasing numbers, or a ValueError naming it."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != 2:
        raise ValueError(f"K_range must be a pair (K_lo, K_hi) of finite numbers with K_lo < K_hi, got {value!r}")
    lo, hi = (real_number(f"K_range[{i}]", v) for i, v in enumerate(value))
    if not lo < hi:
        raise ValueError(f"K_range must be increasing (K_lo < K_hi), got ({lo}, {hi})")
    return lo, hi


def _map_from_scene(path):
    """The map of a scene file (:func:`hovering.scenes.compute.scene_map`): an orbit scene's first
    panel's, a hovering-area scene's first series at its first eps, a flow scene's FlowMap.

    Parameters
    ----------
    path : path-like
        The scene's TOML file.

    Returns
    -------
    TruncatedMap, TruncatedFamily or FlowMap

    Raises
    ------
    ValueError
        For an invalid scene (see :func:`hovering.scenes.load_scene`) or one with no map.
    FileNotFoundError
        If the file does not exist.
    """
    from .scenes import load_scene
    from .scenes.compute import scene_map

    # Exploring writes nothing: the scene's output path is not checked.
    return scene_map(load_scene(path, check_output=False))


def explore(
    map_or_scene,
    n_steps: int | None = None,
    K_range=None,
    *,
    ax=None,
    marker_size: float = 2.0,
    max_points: int = 1_000_000,
) -> Explorer:
    """Open a phase portrait of a return map where a click launches an orbit from the clicked point.

    The orbit is ``map.iterate(phi, K, n_steps, record=("orbit", "regions"))`` from the clicked
    ``(phi, K)`` (``(theta, I)`` for a FlowMap in section coordinates), drawn as points coloured by
    the region each step was taken from. Left click: launch; right click, ``u`` or ``delete``:
    remove the last orbit; ``x``: remove all. An orbit that stops early is drawn up to where it
    stopped (marked ``x``) and its status is shown in the title and legend; a click where the map
    has no point adds no orbit and the title says why. Call ``matplotlib.pyplot.show()`` to open
    the window from a script.

    Parameters
    ----------
    map_or_scene : ReturnMap or path-like
        A TruncatedMap, TruncatedFamily or FlowMap, or the path of a scene TOML file (its first
        panel's map).
    n_steps : int, optional
        Steps per orbit, an integer in [1, 10**7]. Default 2000 for truncated maps, 500 for a
        FlowMap (a return of the flow costs ~10 us, a truncated step ~10 ns).
    K_range : (float, float), optional
        Heights shown (default :func:`default_K_range`: from twice the critical height K_crit, or
        -2 s, up to s, the scale of the O(eps) invariant curves; cut to the map's band).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (default: a new figure).
    marker_size : float, optional
        Marker size of the orbit points, in (0, 100].
    max_points : int, optional
        Most points drawn per orbit (longer orbits are thinned for drawing only).

    Returns
    -------
    Explorer
        ``.fig``, ``.ax``, ``.orbits``, ``.launch(phi, K)``, ``.remove_last()``, ``.clear()``,
        ``.close()``.

    Raises
    ------
    ValueError
        For a map_or_scene that is neither a map nor a path, an invalid scene, or an argument out
        of range (named, with its range), before any figure is made.
    FileNotFoundError
        For a scene path that does not exist.
    """
    if isinstance(map_or_scene, (str, os.PathLike)):
        m = _map_from_scene(map_or_scene)
    else:
        m = require_map("map_or_scene", map_or_scene)
    return Explorer(m, n_steps=n_steps, K_range=K_range, ax=ax, marker_size=marker_size, max_points=max_points)


def _backend_is_interactive() -> bool:
    """Whether matplotlib's backend can open a window (Agg, PDF, SVG, ... cannot)."""
    import matplotlib

    backend = matplotlib.get_backend().lower()
    try:
        from matplotlib.backends import BackendFilter, backend_registry

        non_interactive = backend_registry.list_builtin(BackendFilter.NON_INTERACTIVE)
    except ImportError:  # matplotlib < 3.9
        from matplotlib.rcsetup import non_interactive_bk as non_interactive
    return backend not in {b.lower() for b in non_interactive}


def _n_steps_arg(text: str) -> int:
    try:
        return integer("--n-steps", int(text), 1, MAX_N_STEPS)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be an integer in [1, {MAX_N_STEPS}], got {text!r}") from None


def main(argv=None) -> int:
    """``python -m hovering explore SCENE [--n-steps N] [--K-range LO HI]``: explore a scene's map.

    Opens the window and returns when it is closed. On a backend that cannot open windows (no
    display, or ``MPLBACKEND=Agg``) the scene and options are still checked and the explorer is
    built, then a hint is printed to stderr and nothing is written: the command has nothing to
    save, and matplotlib's own ``show()`` also returns quietly there.

    Parameters
    ----------
    argv : list of str, optional
        Arguments after ``explore`` (default ``sys.argv[1:]``).

    Returns
    -------
    int
        0, or 2 for a scene or option that is not valid (one line on stderr). Bad usage exits
        through argparse (status 2).
    """
    p = argparse.ArgumentParser(
        prog="python -m hovering explore",
        description="Phase portrait of a scene's map (its first panel's) where a left click launches an orbit. "
        "Right click, u or delete: remove the last orbit; x: remove all.",
    )
    p.add_argument("scene", help="scene file (TOML), e.g. examples/scenes/fig_smalleps.toml")
    p.add_argument(
        "--n-steps",
        type=_n_steps_arg,
        default=None,
        help=f"steps per orbit, 1..{MAX_N_STEPS} (default {DEFAULT_N_STEPS['truncated']} for a truncated "
        f"map, {DEFAULT_N_STEPS['flow']} for the flow)",
    )
    p.add_argument(
        "--K-range",
        nargs=2,
        type=float,
        metavar=("K_LO", "K_HI"),
        default=None,
        help="heights shown (default: from 2 K_crit to the O(eps) scale, inside the band)",
    )
    args = p.parse_args(argv)
    import matplotlib.pyplot as plt

    try:
        ex = explore(args.scene, n_steps=args.n_steps, K_range=args.K_range)
    except (OSError, ValueError) as e:
        print(f"{p.prog}: error: {e}", file=sys.stderr)
        return 2
    if not _backend_is_interactive():
        import matplotlib

        ex.close()
        print(
            f"{p.prog}: matplotlib's backend {matplotlib.get_backend()!r} cannot open a window (no display, or "
            f"MPLBACKEND names a file backend); nothing shown, nothing written. Run it where a display is "
            f"available (e.g. MPLBACKEND=TkAgg or QtAgg), or use hovering.explore(...) in Jupyter with "
            f"'%matplotlib widget'.",
            file=sys.stderr,
        )
        return 0
    print(
        f"{ex.map!r}: {ex.n_steps} steps per orbit. Left click: launch; right click, u or delete: remove the "
        f"last orbit; x: clear. Close the window to quit."
    )
    plt.show()
    return 0
