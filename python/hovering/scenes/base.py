"""What every scene kind shares: the spec's common fields, the result's common part and its
checks, the lines under orbits (:class:`Geometry`, :class:`OrbitSet`), the summary's common
numbers and the context a kind's computation runs in.

Below every kind (:mod:`hovering.scenes.kinds`) and above the value checks and the registry: a
kind's module imports what it needs from here, and the generic front (``schema``, ``compute``,
``results``, ``report``) reaches each kind through :mod:`hovering.scenes.registry`.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import math
import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._display import Summarized
from .._enums import FlowStatus, Region, Status
from .._io import serial as _serial
from .._io.output import output_path, write_text
from .._io.provenance import provenance
from .._io.serial import saved_as
from . import registry
from .fields import PARAM, custom, integer, size, text
from .values import MAX_CANVAS_PIXELS, MAX_PATH_CHARS, MAX_TEXT
from .values import color as _color
from .values import text as _text

__all__ = [
    "QUICK_FACTOR",
    "SIDECAR_FORMAT",
    "SceneSpec",
    "SceneResult",
    "Geometry",
    "OrbitSet",
    "Context",
    "Stages",
    "scaled",
    "figure_inches",
    "check_canvas",
    "output_dirs",
    "summarize",
    "jsonable",
    "orbit_rows",
    "region_counts",
    "check_array",
    "check_texts",
    "check_same_length",
    "check_trajectory",
    "check_status",
    "fmt",
    "fmt_pair",
]

#: Iterate counts (and hovering-area samples) are divided by this in ``quick`` runs.
QUICK_FACTOR = 50

#: The ``format`` of a scene result's sidecar JSON.
SIDECAR_FORMAT = "hovering-scene-1"

# The scene computations log under one name, whichever module holds a kind's stages (what
# ``hovering -v`` shows and the docs quote).
_log = logging.getLogger("hovering.scenes.compute")


def output_dirs(path: os.PathLike | None) -> tuple:
    """Where a scene's own ``output`` may lie: under the scene file's folder or the working
    directory (a scene from elsewhere cannot make hovering write anywhere else; ``--out`` can).

    Parameters
    ----------
    path : path-like or None
        The scene file (None: a scene without a file, the working directory only).

    Returns
    -------
    tuple of Path
    """
    return (Path.cwd(),) + ((Path(path).parent,) if path is not None else ())


def _read_kind(where: str, value, reading) -> str:
    return _text(where, value, registry.names())


def _read_output(where: str, value, reading) -> Path:
    """The figure's path, checked (format, writable directory, under the scene's folder or the
    working directory) unless the scene is read for something that writes elsewhere or nothing."""
    s = _text(where, value, limit=MAX_PATH_CHARS)
    if reading.options.get("check_output"):
        return output_path(where, s, within=output_dirs(reading.options.get("path")))
    return Path(s)


@saved_as("hovering.scenes.spec:SceneSpec")
@dataclass(frozen=True, kw_only=True)
class SceneSpec:
    """What every scene has (see :func:`hovering.scenes.load_scene`).

    Attributes
    ----------
    path : Path or None
        The file it was read from.
    name : str
        The file's stem (or ``"scene"``).
    kind : str
        One of :data:`~hovering.scenes.KINDS`.
    title : str
        Figure title (default: the name).
    output : Path
        PNG path (relative paths are relative to the working directory).
    dpi : int
        PNG resolution.
    figsize : tuple of float or None
        Figure size in inches (default from the kind or the layout).
    """

    path: Path | None = None
    name: str = "scene"
    kind: str = custom(read=_read_kind, allowed="a registered kind")
    title: str = text(default_from="name", drawn=True)
    output: Path = custom(read=_read_output, write=lambda p, kind: str(p), allowed="a .png, .pdf, .svg, ... path")
    dpi: int = integer(130, lo=30, hi=1200)
    figsize: tuple | None = size()

    def _validate_loaded(self) -> None:
        """A spec read from a file (:func:`hovering.load`): its own bounds, the ones that size what
        a figure allocates (``dpi``, ``figsize`` as declared here, and the canvas). Every other check
        a scene file gets (the schema's, a layer above) is run by whoever loads a scene result
        (:func:`hovering.scenes.load_result`: ``check_spec``)."""
        where = self.path.name if isinstance(self.path, Path) else "scene"
        for f in dataclasses.fields(SceneSpec):
            value = getattr(self, f.name)
            if f.name in ("dpi", "figsize") and value is not None:
                f.metadata[PARAM].read(f"{where}.{f.name}", list(value) if f.name == "figsize" else value, None)
        check_canvas(where, self)


def figure_inches(scene, n_panels: int = 1) -> tuple:
    """Width and height (inches) of a scene's figure: its ``figsize``, or its kind's and layout's default.

    Parameters
    ----------
    scene : SceneSpec
        The scene.
    n_panels : int, optional
        Its number of panels (orbit scenes without a layout: one column of them).

    Returns
    -------
    tuple of float
    """
    if scene.figsize is not None:
        return tuple(scene.figsize)
    kind = registry.get(scene.kind)
    if kind.figsize is not None:
        return tuple(kind.figsize)
    layout = getattr(scene, "layout", None)
    rows, cols = layout if layout is not None else (n_panels, 1)
    return (6.0 * cols + 1.0, 4.6 * rows + 0.6)


def check_canvas(where: str, spec: SceneSpec) -> None:
    """The figure's canvas (dpi and its size in inches, given or its kind's default) within
    :data:`~hovering.scenes.values.MAX_CANVAS_PIXELS`: a spec's own bound, checked by the schema
    for a scene file and by the spec itself for one read back from a saved result.

    Parameters
    ----------
    where : str
        What the spec is, for the message (the file's name).
    spec : SceneSpec
        The spec.

    Raises
    ------
    ValueError
        Naming dpi and the size that make the canvas too large, and the limit.
    """

    w, h = figure_inches(spec, len(getattr(spec, "panels", ())))
    pixels = (spec.dpi * w) * (spec.dpi * h)
    if pixels > MAX_CANVAS_PIXELS:
        given = (
            "figsize"
            if spec.figsize is not None
            else "layout"
            if getattr(spec, "layout", None) is not None
            else "the default figure size"
        )
        raise ValueError(
            f"{where}: dpi = {spec.dpi} and {given} make a figure of {w:g} x {h:g} inches, a canvas of "
            f"{pixels / 1e6:.0f} million pixels; allowed: at most {MAX_CANVAS_PIXELS / 1e6:.0f} million "
            f"(lower dpi or figsize)"
        )


# ------------------------------------------------------------------------------------------------
# Results


def jsonable(x):
    """``x`` with numpy scalars as Python numbers and non-finite floats as None (JSON-safe).

    Parameters
    ----------
    x : object
        Nested dicts, lists, tuples and numbers.

    Returns
    -------
    object
    """
    if isinstance(x, dict):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return jsonable(x.tolist())
    if isinstance(x, (np.floating, float)):
        return None if not math.isfinite(float(x)) else float(x)
    if isinstance(x, np.bool_):
        return bool(x)
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, Path):
        return str(x)
    return x


# ------------------------------------------------------------------------------------------------
# Checks of a result read from a file (hovering._io.serial calls ``_validate_loaded`` after checking
# each field's declared type): what the figure draws is what a computation could have made. Texts
# and colours get the scene schema's checks.


def check_texts(where: str, values, n: int | None = None, color: bool = False) -> None:
    """A list of ``n`` texts (or colours), each as a scene file's would be checked.

    Parameters
    ----------
    where : str
        The field, for the message.
    values : object
        The field's value.
    n : int, optional
        Its length.
    color : bool, optional
        Each must be a matplotlib colour.

    Raises
    ------
    ValueError
        Naming the field and what is wrong.
    """
    if not isinstance(values, list) or (n is not None and len(values) != n):
        raise ValueError(
            f"{where} must be a list of {n if n is not None else 'some'} strings, got "
            f"{'a list of ' + str(len(values)) if isinstance(values, list) else type(values).__name__}"
        )
    for i, x in enumerate(values):
        (_color if color else _text)(f"{where}[{i}]", x)


def check_array(where: str, a, ndim: int, kinds: str = "iuf", shape: tuple | None = None) -> None:
    """An array of numbers of ``ndim`` dimensions (of ``shape``, if given).

    Parameters
    ----------
    where : str
        The field, for the message.
    a : object
        The field's value.
    ndim : int
        Its number of dimensions.
    kinds : str, optional
        Allowed dtype kinds (``"iuf"``: integers and floats; ``"b"``: bools).
    shape : tuple, optional
        Its shape (that of the arrays it goes with).

    Raises
    ------
    ValueError
        Naming the field, its shape and dtype.
    """
    if not isinstance(a, np.ndarray) or a.ndim != ndim or a.dtype.kind not in kinds:
        got = f"shape {a.shape} dtype {a.dtype}" if isinstance(a, np.ndarray) else type(a).__name__
        raise ValueError(f"{where} must be a {ndim}-D array of numbers, got {got}")
    if shape is not None and a.shape != shape:
        raise ValueError(f"{where} has shape {a.shape}; it must have shape {shape} (as the arrays it goes with)")


def check_same_length(where: str, d: dict, keys, kinds: str = "iuf") -> None:
    """A dict of 1-D arrays under exactly ``keys``, all of one length (``reached``: bools).

    Parameters
    ----------
    where : str
        The field, for the message.
    d : object
        The field's value.
    keys : sequence of str
        Its keys.
    kinds : str, optional
        Allowed dtype kinds of the arrays.

    Raises
    ------
    ValueError
        Naming the field and what is wrong.
    """
    if not isinstance(d, dict) or set(d) != set(keys):
        got = sorted(map(str, d)) if isinstance(d, dict) else type(d).__name__
        raise ValueError(f"{where} must hold the arrays {sorted(keys)}, got {got}")
    n = None
    for k in keys:
        check_array(f"{where}.{k}", d[k], 1, "b" if k in ("reached",) else kinds)
        if n is None:
            n = d[k].shape
        elif d[k].shape != n:
            raise ValueError(f"{where}.{k} has shape {d[k].shape}; it must have shape {n} (as the arrays it goes with)")


def check_trajectory(where: str, a) -> None:
    """Rows ``t, q1, p1, q2, p2`` of a trajectory.

    Parameters
    ----------
    where : str
        The field, for the message.
    a : object
        The field's value.

    Raises
    ------
    ValueError
        For another shape.
    """
    check_array(where, a, 2)
    if a.shape[1] != 5:
        raise ValueError(f"{where} has shape {a.shape}; it must be (m, 5): t, q1, p1, q2, p2")


def check_status(where: str, value) -> None:
    """The name of a :class:`~hovering.FlowStatus`.

    Parameters
    ----------
    where : str
        The field, for the message.
    value : object
        The field's value.

    Raises
    ------
    ValueError
        For another value, naming the statuses.
    """
    _text(where, value, tuple(s.name for s in FlowStatus))


@saved_as("hovering.scenes.results:Geometry")
@dataclass
class Geometry:
    """The lines a phase portrait on (phi, K) draws: K = 0, L1, L2 and the corner curves.

    Attributes
    ----------
    K : ndarray
        Heights of the lines L1, L2.
    L1, L2 : ndarray or None
        Their angles at ``K`` (None: not drawn).
    K_corner : ndarray
        Heights (K < 0) of the corner-singularity curves.
    corners : dict
        ``"01"``, ``"1R"``, ``"R0"`` -> angles at ``K_corner`` (empty: not drawn; NaN where a curve
        was not found).
    measured : bool
        Whether the corner curves were measured on the flow (else closed forms of the model).
    """

    K: np.ndarray
    L1: np.ndarray | None
    L2: np.ndarray | None
    K_corner: np.ndarray
    corners: dict
    measured: bool = False

    def _validate_loaded(self) -> None:
        check_array("K", self.K, 1)
        for name in ("L1", "L2"):
            if getattr(self, name) is not None:
                check_array(name, getattr(self, name), 1, shape=self.K.shape)
        check_array("K_corner", self.K_corner, 1)
        for k, v in self.corners.items():
            if k not in ("01", "1R", "R0"):
                raise ValueError(f"corners has the key {str(k)[:40]!r}; allowed: '01', '1R', 'R0'")
            check_array(f"corners.{k}", v, 1, shape=self.K_corner.shape)


@saved_as("hovering.scenes.results:OrbitSet")
@dataclass
class OrbitSet:
    """Orbits of one panel, with what each one is.

    Attributes
    ----------
    phi, K : ndarray
        Shape ``(n_orbits, n_steps + 1)``; NaN after an orbit stopped.
    region : ndarray of int8 or None
        Region of the point each step was taken from, ``(n_orbits, n_steps)``.
    status : ndarray of int8
        Per-orbit :class:`~hovering.Status`.
    steps_done : ndarray of int64
        Steps each orbit took.
    labels, colors, kinds : list of str
        Legend label, colour and kind (``"fan"``, a special orbit's name, ``"extra"``,
        ``"critical"``) of each orbit.
    rho : ndarray or None
        Rotation numbers.
    """

    phi: np.ndarray
    K: np.ndarray
    region: np.ndarray | None
    status: np.ndarray
    steps_done: np.ndarray
    labels: list
    colors: list
    kinds: list
    rho: np.ndarray | None = None

    def _validate_loaded(self) -> None:
        check_array("phi", self.phi, 2)
        n, m = self.phi.shape
        check_array("K", self.K, 2, shape=(n, m))
        if self.region is not None:
            check_array("region", self.region, 2, "iu", shape=(n, max(m - 1, 0)))
        check_array("status", self.status, 1, "iu", shape=(n,))
        check_array("steps_done", self.steps_done, 1, "iu", shape=(n,))
        check_texts("labels", self.labels, n)
        check_texts("colors", self.colors, n, color=True)
        check_texts("kinds", self.kinds, n)
        if self.rho is not None:
            check_array("rho", self.rho, 1, shape=(n,))

    @classmethod
    def of(cls, res, labels, colors, kinds, rho=None) -> OrbitSet:
        """From an :class:`~hovering.IterateResult` (``"orbit"`` recorded).

        Parameters
        ----------
        res : IterateResult
            The orbits.
        labels, colors, kinds : list of str
            Per orbit.
        rho : ndarray, optional
            Rotation numbers.

        Returns
        -------
        OrbitSet
        """
        return cls(
            np.asarray(res.phi),
            np.asarray(res.K),
            None if res.region is None else np.asarray(res.region),
            np.asarray(res.status),
            np.asarray(res.steps_done),
            list(labels),
            list(colors),
            list(kinds),
            None if rho is None else np.asarray(rho, dtype=float),
        )

    @property
    def n_orbits(self) -> int:
        """Number of orbits."""
        return int(self.phi.shape[0])


@saved_as("hovering.scenes.results:SceneResult")
@dataclass(repr=False)
class SceneResult(Summarized):
    """What every scene result has.

    Attributes
    ----------
    scene : SceneSpec
        The validated scene.
    meta : dict
        ``version``, ``quick``, ``timings`` (seconds per stage), what was recorded and run.
    """

    scene: SceneSpec
    meta: dict

    @staticmethod
    def _summarize_kind(result) -> dict:
        """The kind's own numbers: :func:`~hovering.scenes.registry.register` binds the kind's
        ``summarize`` here, on the kind's result class."""
        raise ValueError(f"a {type(result).__name__} is the result of no registered scene kind")

    def _validate_loaded(self) -> None:
        # What the figure and the summary take from meta (the scene itself was checked as it was read).

        for key, kind in (("quick", bool), ("n_steps", int), ("samples", int), ("timings", dict), ("version", str)):
            v = self.meta.get(key)
            if v is not None and (not isinstance(v, kind) or (kind is int and isinstance(v, bool))):
                raise ValueError(f"meta.{key} must be of type {kind.__name__}, got {type(v).__name__}")
        if len(self.meta.get("version") or "") > MAX_TEXT:
            raise ValueError(
                f"meta.version: a string of {len(self.meta['version'])} characters; allowed: at most {MAX_TEXT}"
            )
        for k, v in (self.meta.get("timings") or {}).items():
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise ValueError(f"meta.timings.{k} must be a number of seconds, got {type(v).__name__}")

    def _summary(self) -> list:
        out = [("scene", self.scene.name), ("kind", self.scene.kind)]
        out += [(k, self.meta[k]) for k in ("quick", "n_steps", "samples", "version") if self.meta.get(k) is not None]
        timings = self.meta.get("timings") or {}
        if timings:
            out.append(("seconds", sum(v for v in timings.values() if isinstance(v, (int, float)))))
        return out

    def summary(self) -> dict:
        """The numbers shown, as a JSON-able dict (what the CLI prints and the sidecar JSON holds).

        Returns
        -------
        dict
        """
        return summarize(self)

    def save(self, path: os.PathLike) -> tuple:
        """Write the result as NPZ (arrays + the typed tree) and a sidecar JSON (scene, meta, summary).

        Both record what made them (``provenance``: versions, build, machine, seed) and are
        written atomically: a failure leaves the previous files as they were.

        Parameters
        ----------
        path : path-like
            The ``.npz`` file (the JSON gets the same name with ``.json``).

        Returns
        -------
        tuple of str
            The two paths written.

        Raises
        ------
        hovering._io.output.WriteError
            (a ValueError) When a file cannot be written (e.g. ``no space left``).
        """

        npz = _serial.save(self, path, meta=jsonable(self.meta))
        side = str(Path(npz).with_suffix(".json"))
        # "format" first: it is how a later run recognises the file as one it may replace.
        doc = dict(
            format=SIDECAR_FORMAT,
            provenance=provenance(seed=getattr(self.scene, "seed", None)),
            scene=jsonable(_serial.to_tree(self.scene, {})),
            meta=jsonable(self.meta),
            summary=jsonable(self.summary()),
        )
        write_text(side, json.dumps(doc, indent=1, allow_nan=False))
        return npz, side


def summarize(result) -> dict:
    """The numbers a scene result shows, as a JSON-able dict.

    Parameters
    ----------
    result : SceneResult
        Any scene result.

    Returns
    -------
    dict
        ``scene``, ``kind``, ``title``, ``quick``, ``runtime_s``, what ``meta`` recorded of
        ``n_steps``, ``samples``, ``points_reused``, ``checkpoint``, ``grid``, ``accuracy``, then
        the kind's own numbers (its :attr:`~hovering.scenes.registry.Kind.summarize`, which
        :func:`~hovering.scenes.registry.register` binds to the kind's result class: the panels of
        an orbit scene, the points of a sweep, ...).
    """
    sc, meta = result.scene, result.meta
    s = dict(
        scene=sc.name,
        kind=sc.kind,
        title=sc.title,
        quick=bool(meta.get("quick")),
        runtime_s=float(meta.get("timings", {}).get("total", float("nan"))),
    )
    for k in ("n_steps", "samples", "points_reused", "checkpoint", "grid", "accuracy"):
        if k in meta:
            s[k] = meta[k]
    s.update(type(result)._summarize_kind(result))  # the kind's numbers (bound to its result class by register)
    return jsonable(s)


def orbit_rows(o: OrbitSet) -> list:
    """One summary row per orbit: label, kind, start, K range, status, steps; its rotation number,
    impacts and whether it hovers when recorded.

    Parameters
    ----------
    o : OrbitSet
        The orbits.

    Returns
    -------
    list of dict
    """
    out = []
    for i, lab in enumerate(o.labels):
        K = o.K[i]
        d = dict(
            label=lab,
            kind=o.kinds[i],
            phi0=float(o.phi[i, 0]),
            K0=float(K[0]),
            K_min=float(np.nanmin(K)),
            K_max=float(np.nanmax(K)),
            status=Status(int(o.status[i])).name,
            steps=int(o.steps_done[i]),
        )
        if o.rho is not None:
            d["rho"] = float(o.rho[i])
        if o.region is not None:
            reg = o.region[i]
            d["impacts"] = int(
                np.count_nonzero((reg == int(Region.UPPER)) | (reg == int(Region.RIGHT)) | (reg == int(Region.MULTI)))
            )
            d["hovering"] = bool(d["impacts"] == 0 and d["K_min"] < 0 and o.status[i] == int(Status.OK))
        out.append(d)
    return out


def region_counts(region) -> dict:
    """How many points lie in each region (by its label), for a summary.

    Parameters
    ----------
    region : ndarray or None
        Region codes (None: nothing recorded).

    Returns
    -------
    dict
    """
    if region is None:
        return {}
    return {Region(r).label: int(np.count_nonzero(region == int(r))) for r in Region if r != Region.NONE}


def fmt(x, spec: str) -> str:
    """A number of a summary as report text: ``x`` formatted with ``spec``; ``nan`` for None (how the
    JSON-able summary holds a NaN), ``str(x)`` for what is no number.

    Parameters
    ----------
    x : object
        The value.
    spec : str
        A format spec (``".4f"``).

    Returns
    -------
    str
    """
    if x is None:
        return "nan"
    if isinstance(x, bool) or not isinstance(x, (int, float, np.integer, np.floating)):
        return str(x)
    return format(float(x), spec)


def fmt_pair(p) -> str:
    """Two numbers as ``[a, b]``, three decimals each (a zoom window).

    Parameters
    ----------
    p : sequence
        The two values.

    Returns
    -------
    str
    """
    return f"[{fmt(p[0], '.3f')}, {fmt(p[1], '.3f')}]"


# ------------------------------------------------------------------------------------------------
# The context of a kind's computation


class Stages:
    """The stages of one scene's computation: each timed into ``meta["timings"]`` and logged at INFO
    (what ``hovering -v`` shows) when it starts, with what it computes and how much, and when it
    ends, with its time: ``scene impact-zone: stage 2/3 flow: barrier scan 480 orbits x 10000
    returns, transits 2 x 64 orbits x 10000 returns`` ... ``scene impact-zone: stage 2/3 flow done,
    12.3 s``. The library only logs; the command line decides what is shown.


    Parameters
    ----------
    meta : dict
        The result's ``meta`` (its ``name`` names the scene; ``timings`` gets each stage's time).
    total : int
        How many stages there are.
    """

    def __init__(self, meta: dict, total: int):
        self.meta, self.total, self.number = meta, total, 0
        self.name, self.t = "", 0.0

    def start(self, name: str, what: str = "") -> None:
        """Start the next stage (logged).

        Parameters
        ----------
        name : str
            The stage (its key in ``meta["timings"]``).
        what : str, optional
            What it computes and how much, for the log line.
        """
        self.number, self.name, self.t = self.number + 1, name, time.perf_counter()
        _log.info(
            "scene %s: stage %d/%d %s%s", self.meta["name"], self.number, self.total, name, f": {what}" if what else ""
        )

    def end(self) -> float:
        """End the stage: its time goes to ``meta["timings"]`` and the log.

        Returns
        -------
        float
            Its seconds.
        """
        dt = time.perf_counter() - self.t
        self.meta["timings"][self.name] = dt
        _log.info("scene %s: stage %d/%d %s done, %.1f s", self.meta["name"], self.number, self.total, self.name, dt)
        return dt


def scaled(n: int, quick: bool, floor: int = 100) -> int:
    """An iterate count divided by :data:`QUICK_FACTOR` in quick runs (at least ``floor``).

    Parameters
    ----------
    n : int
        The scene's count.
    quick : bool
        Quick run.
    floor : int, optional
        Smallest count of a quick run.

    Returns
    -------
    int
    """
    return max(n // QUICK_FACTOR, min(floor, n)) if quick else n


@dataclass
class Context:
    """What a kind's ``compute(spec, ctx)`` is given beside its spec.

    Attributes
    ----------
    quick : bool
        A quick run: counts divided by :data:`QUICK_FACTOR` (:meth:`scaled`).
    progress : callable or bool
        Progress bars (checked: :func:`hovering._progress.check_progress`).
    meta : dict
        The result's ``meta`` (version, quick, kind, name, timings), which the kind adds to.
    checkpoint : path-like or None
        Sweep kinds: the file every finished point is written to.
    executor : hovering.parallel.Executor or None
        Sweep kinds: where the points run (None: in this process).
    """

    quick: bool
    progress: object
    meta: dict
    checkpoint: os.PathLike | None = None
    executor: object = None

    def stages(self, total: int) -> Stages:
        """The timed, logged stages of this computation.

        Parameters
        ----------
        total : int
            How many there are.

        Returns
        -------
        Stages
        """
        return Stages(self.meta, total)

    def scaled(self, n: int, floor: int = 100) -> int:
        """A count divided by :data:`QUICK_FACTOR` in quick runs (at least ``floor``): :func:`scaled`.

        Parameters
        ----------
        n : int
            The scene's count.
        floor : int, optional
            Smallest count of a quick run.

        Returns
        -------
        int
        """
        return scaled(n, self.quick, floor)

    @property
    def progress_kw(self) -> dict:
        """``{"progress": ...}`` when asked for, else nothing (a map without a progress argument
        then still runs silently)."""
        return {"progress": self.progress} if self.progress else {}
