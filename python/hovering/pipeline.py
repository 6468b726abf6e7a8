"""The one place that computes, saves and draws: a scene run end to end, a saved result redrawn, a
phase portrait in one call. Above both the scene pipeline (computing, results) and the figures
(pure functions of results), so neither of those knows of the other.
"""

from __future__ import annotations

import io
import logging
import os
import time
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from ._io.output import is_ours, output_path, refuse_foreign, savefig, write_bytes, write_error
from .plot.figures import render
from .plot.primitives import draw_geometry as draw_geometry_lines
from .plot.primitives import plot_orbits
from .scenes import compute, registry
from .scenes.compute import map_geometry
from .scenes.results import Geometry, load_result
from .scenes.schema import output_dirs
from .scenes.spec import SceneSpec

__all__ = ["run_scene", "redraw", "phase_portrait", "draw_geometry"]

_log = logging.getLogger(__name__)


def run_scene(
    scene: SceneSpec,
    out: os.PathLike | None = None,
    quick: bool = False,
    keep_figure: bool = False,
    progress=False,
    force: bool = False,
    executor=None,
    **where,
) -> dict:
    """Compute a scene, save its result (NPZ + JSON), draw its figure and write the PNG.

    Where it writes: ``out`` if given, else the scene's ``output``, which must lie under the scene
    file's folder or the working directory. It replaces only files hovering wrote (results,
    sidecars, checkpoints, and figures beside them; see :mod:`hovering._io.output`): any other file
    in the way is refused before anything is computed, unless ``force``. Every file is written
    atomically (a kill or a full disk leaves the previous ones intact); the figure is written last.

    Parameters
    ----------
    scene : SceneSpec
        From :func:`load_scene`.
    out : path-like, optional
        PNG path (default ``scene.output``); the result is written next to it as ``.npz`` and
        ``.json`` (and a sweep's checkpoint as ``.sweep.jsonl``).
    quick : bool, optional
        Divide iterate counts (and samples) by :data:`QUICK_FACTOR` for a fast check; titles say so.
    keep_figure : bool, optional
        Return the figure in the summary (key ``"figure"``) and the result (key ``"result"``)
        instead of closing the figure.
    progress : bool or callable, optional
        Progress bars on stderr for the long computations.
    force : bool, optional
        Replace existing files that hovering did not write.
    executor : None, int, str, distributed.Client or hovering.parallel.Executor, optional
        Where a sweep scene's points run (see :func:`hovering.scenes.compute`).
    **where
        Deprecated (removed in 0.4.0): ``workers``, ``client``, ``scheduler``, ``dask``; each warns.

    Returns
    -------
    dict
        :func:`summarize` of the result plus ``output`` (PNG), ``npz`` and ``json`` paths, and
        ``files``: every file written (with the checkpoint of a sweep).

    Raises
    ------
    ValueError
        For an output path outside the allowed folders, a file in the way that hovering did not
        write, or a failed write (:class:`hovering._io.output.WriteError`, e.g. ``no space left``).
    """
    t0 = time.perf_counter()
    png = (
        output_path("out", out)
        if out is not None
        else output_path("output", scene.output, within=output_dirs(scene.path))
    )
    npz, side, ckpt = png.with_suffix(".npz"), png.with_suffix(".json"), png.with_suffix(".sweep.jsonl")
    sweep = registry.get(scene.kind).sweep
    refuse_foreign([png, npz, side] + ([ckpt] if sweep else []), force)
    try:
        png.parent.mkdir(parents=True, exist_ok=True)
        if force and sweep and ckpt.exists() and not is_ours(ckpt):
            ckpt.unlink()  # replaced by this run's checkpoint (it is appended to, not rewritten)
    except OSError as e:
        raise write_error(png.parent, e, previous=False) from None
    result = compute(scene, quick=quick, progress=progress, checkpoint=ckpt, executor=executor, **where)
    result.meta["output"] = str(png)
    t = time.perf_counter()
    fig = render(result)
    try:
        # Drawn in memory, written after the result: a figure on disk always has its result beside it.
        buf = io.BytesIO()
        fig.savefig(buf, format=png.suffix[1:].lower(), dpi=result.scene.dpi)
        result.meta["timings"]["render"] = time.perf_counter() - t
        npz_path, json_path = result.save(npz)
        write_bytes(png, buf.getvalue())
    finally:
        if not keep_figure:
            plt.close(fig)
    _log.info(
        "scene %s: figure drawn and %s, %s, %s written, %.1f s", scene.name, npz_path, json_path, png,
        time.perf_counter() - t,
    )  # fmt: skip
    summary = result.summary()
    summary["runtime_s"] = time.perf_counter() - t0
    summary.update(
        output=str(png),
        npz=npz_path,
        json=json_path,
        files=[npz_path, json_path, str(png)] + ([result.meta["checkpoint"]] if "checkpoint" in result.meta else []),
    )
    if keep_figure:
        summary["figure"] = fig
        summary["result"] = result
    return summary


def redraw(path: os.PathLike, out: os.PathLike | None = None, keep_figure: bool = False, force: bool = False):
    """Redraw a saved scene result without computing anything.

    Parameters
    ----------
    path : path-like
        The ``.npz`` written by :func:`run_scene`.
    out : path-like, optional
        PNG path (default: the NPZ's name with ``.png``).
    keep_figure : bool, optional
        Return the figure instead of closing it.
    force : bool, optional
        Replace an existing file at the PNG path that hovering did not write (see :func:`run_scene`).

    Returns
    -------
    tuple
        ``(png_path, result, figure or None)``.

    Raises
    ------
    ValueError
        For a file that is not a scene result, or one whose values the scene schema or the result's
        own checks refuse (see :func:`load_result`), naming the file and the field.
    """
    result = load_result(path)  # checked as it is read: the scene schema's checks, each field's type
    png = output_path("--out", out) if out is not None else Path(os.fspath(path)).with_suffix(".png")
    refuse_foreign([png], force)
    try:
        png.parent.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise write_error(png.parent, e, previous=False) from None
    try:
        fig = render(result)
    except (ValueError, TypeError, KeyError, IndexError, AttributeError) as e:  # a combination the checks missed
        raise ValueError(f"{os.fspath(path)}: the result cannot be drawn ({type(e).__name__}: {e})") from None
    try:
        savefig(fig, png, dpi=result.scene.dpi)
    finally:
        if not keep_figure:
            plt.close(fig)
    return png, result, (fig if keep_figure else None)


def draw_geometry(ax, m, K_range, corner_curves=True, lines=True, n=400):
    """Draw K = 0, L1, L2 and the corner curves of a map (computes them, then draws).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Target axes.
    m : TruncatedMap, TruncatedFamily or a Geometry
        The map whose geometry is drawn (or precomputed lines).
    K_range : tuple of float
        ``(K_low, K_high)`` of the plot.
    corner_curves, lines : bool, optional
        What is drawn.
    n : int, optional
        Samples per curve.

    Returns
    -------
    list
        The artists added.
    """
    geom = m if isinstance(m, Geometry) else map_geometry(m, K_range, n, corner_curves, lines)
    return draw_geometry_lines(ax, geom, corner_curves=corner_curves, lines=lines)


def phase_portrait(m, n_orbits=30, n_steps=20_000, K_range=(-1.2, 0.6), ax=None, color_by="region", title=None):
    """Iterate orbits started evenly along L1 and draw them with the map's geometry.

    This is the construction of the paper's fig:smallepsmany: the iteration happens here, the
    drawing in :mod:`hovering.plot.primitives`.

    Parameters
    ----------
    m : TruncatedMap
        The map.
    n_orbits : int, optional
        Initial conditions, evenly spaced in K on L1.
    n_steps : int, optional
        Iterates per orbit.
    K_range : tuple of float, optional
        Range of initial K (and of the plot, padded).
    ax : matplotlib.axes.Axes, optional
        Target axes; a new figure is made if omitted.
    color_by : {"region", "orbit"}, optional
        See :func:`plot_orbits`.
    title : str, optional
        Axes title (default: the parameters).

    Returns
    -------
    ax : matplotlib.axes.Axes
    res : IterateResult
    """
    if ax is None:
        _, ax = plt.subplots(figsize=(8, 5))
    K0 = np.linspace(K_range[0], K_range[1], n_orbits)
    res = m.iterate(m.L1(K0), K0, n_steps, record=("orbit", "regions", "rotation"))
    plot_orbits(ax, res, color_by=color_by)
    pad = 0.1 * (K_range[1] - K_range[0])
    draw_geometry(ax, m, (K_range[0] - pad, K_range[1] + pad))
    ax.set_xlim(-np.pi, np.pi)
    ax.set_ylim(K_range[0] - pad, K_range[1] + pad)
    ax.set_xlabel(r"$\phi$")
    ax.set_ylabel(r"$K$")
    if title is None:
        title = (
            rf"$\varepsilon={m.eps:g},\ \Omega_0={m.Omega0:.4f},\ \theta_w={m.theta_w:.4f},\ "
            rf"\tau_0={m.tau0:g},\ \tau_1={m.tau1:g},\ \lambda={m.lam:g}$"
        )
    ax.set_title(title, fontsize=9)
    if color_by == "region":
        ax.legend(loc="upper right", markerscale=40, fontsize=7, framealpha=0.8)
    return ax, res
