"""Scenes: one TOML file per figure, validated, computed, saved and drawn, arrows forward only.

::

    TOML --load_scene--> spec (one frozen class per kind) --compute--> typed result
         --save--> NPZ + JSON (scene, parameters, version, timings)
         --render--> Figure (pure function of the result)  /  --summarize--> text report

A scene names its effects; nothing else is simulated. The kinds:

``portrait``, ``critical_orbits``, ``hovering_area``
    The truncated map (sec:truncatedmapnum): orbits from L1, the paper's special orbits with
    critical curves and zooms, |HOV| against eps.
``flow_portrait``
    The full return map and its truncated model side by side, same starts, coloured by region,
    with the measured corner-singularity curves and K = 0.
``flow_hovering_area``
    |HOV| against eps for the flow, its truncated models (onset arcs; arcs measured on the flow)
    and eq:hovsetsize, both signs of eps, with error bars.
``tangent_tori``
    fig:two-tang computed: the two tangent tori of the unperturbed system with trajectories.
``sigma_structure``
    fig:structure_Sigma computed from the flow: regions J_R, J_0, J_1 and their images.

Flow scenes carry ``[system]`` (potentials ``harmonic`` / ``tan``, ``coupling`` = ``"bilinear"``,
``"none"`` or terms ``[[c, i, j], ...]``, ``eps``, ``qw1``, ``qw2``, ``geometry`` none / wall /
step), ``[section]`` (``h``), ``[integrator]`` (``stepper``, ``rtol``, ``atol``) and
``[outputs]`` (``record``: what is recorded; ``trajectory_dt``). See ``examples/scenes``.
"""

from __future__ import annotations

import os
from importlib import resources
from pathlib import Path
from typing import Optional

from .._output import output_path
from .compute import compute
from .report import format_summary, summarize
from .results import SceneResult, load_result
from .schema import MAX_PANELS, MAX_SCENE_BYTES, MAX_SERIES_POINTS, load_scene, output_dirs, parse_scene
from .spec import (FLOW_KINDS, KINDS, QUICK_FACTOR, SPECIAL_ORBITS, TRUNCATED_KINDS, CriticalSpec, MapSpec, OrbitSpec,
                   PanelSpec, Scene, SceneSpec, SeriesSpec, ZoomSpec)

#: The kinds that checkpoint their points (``<output>.sweep.jsonl``).
SWEEP_KINDS = ("hovering_area", "flow_hovering_area")

__all__ = [
    "KINDS", "TRUNCATED_KINDS", "FLOW_KINDS", "SPECIAL_ORBITS", "QUICK_FACTOR", "MAX_PANELS", "MAX_SERIES_POINTS",
    "MAX_SCENE_BYTES", "MapSpec", "OrbitSpec", "CriticalSpec", "ZoomSpec", "PanelSpec", "SeriesSpec", "Scene",
    "SceneSpec", "SceneResult", "load_scene", "parse_scene", "compute", "run_scene", "redraw", "load_result",
    "summarize", "format_summary", "packaged_scene",
]


def packaged_scene(name: str) -> Path:
    """Path of a scene file shipped with the package (``"demo"``).

    Parameters
    ----------
    name : str
        The scene's name.

    Returns
    -------
    Path
    """
    p = resources.files(__name__).joinpath("data", f"{name}.toml")
    if not p.is_file():
        raise ValueError(f"no packaged scene {name!r}; available: demo")
    return Path(str(p))


def run_scene(scene: SceneSpec, out: Optional[os.PathLike] = None, quick: bool = False, keep_figure: bool = False,
              progress=False, force: bool = False, **where) -> dict:
    """Compute a scene, save its result (NPZ + JSON), draw its figure and write the PNG.

    Where it writes: ``out`` if given, else the scene's ``output``, which must lie under the scene
    file's folder or the working directory. It replaces only files hovering wrote (results,
    sidecars, checkpoints, and figures beside them; see :mod:`hovering._output`): any other file
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
    **where
        ``workers``, ``client``, ``scheduler``, ``dask``: where a sweep scene's points run (see
        :func:`compute`).

    Returns
    -------
    dict
        :func:`summarize` of the result plus ``output`` (PNG), ``npz`` and ``json`` paths, and
        ``files``: every file written (with the checkpoint of a sweep).

    Raises
    ------
    ValueError
        For an output path outside the allowed folders, a file in the way that hovering did not
        write, or a failed write (:class:`hovering._output.WriteError`, e.g. ``no space left``).
    """
    import io
    import time

    from .._output import is_ours, refuse_foreign, write_bytes, write_error

    t0 = time.perf_counter()
    png = output_path("out", out) if out is not None else output_path("output", scene.output,
                                                                         within=output_dirs(scene.path))
    npz, side, ckpt = png.with_suffix(".npz"), png.with_suffix(".json"), png.with_suffix(".sweep.jsonl")
    sweep = scene.kind in SWEEP_KINDS
    refuse_foreign([png, npz, side] + ([ckpt] if sweep else []), force)
    try:
        png.parent.mkdir(parents=True, exist_ok=True)
        if force and sweep and ckpt.exists() and not is_ours(ckpt):
            ckpt.unlink()  # replaced by this run's checkpoint (it is appended to, not rewritten)
    except OSError as e:
        raise write_error(png.parent, e, previous=False) from None
    result = compute(scene, quick=quick, progress=progress, checkpoint=ckpt, **where)
    result.meta["output"] = str(png)
    t = time.perf_counter()
    fig = _render(result)
    try:
        # Drawn in memory, written after the result: a figure on disk always has its result beside it.
        buf = io.BytesIO()
        fig.savefig(buf, format=png.suffix[1:].lower(), dpi=result.scene.dpi)
        result.meta["timings"]["render"] = time.perf_counter() - t
        npz_path, json_path = result.save(npz)
        write_bytes(png, buf.getvalue())
    finally:
        if not keep_figure:
            import matplotlib.pyplot as plt

            plt.close(fig)
    summary = result.summary()
    summary["runtime_s"] = time.perf_counter() - t0
    summary.update(output=str(png), npz=npz_path, json=json_path,
                   files=[npz_path, json_path, str(png)] + ([result.meta["checkpoint"]] if "checkpoint" in result.meta
                                                             else []))
    if keep_figure:
        summary["figure"] = fig
        summary["result"] = result
    return summary


def _render(result: SceneResult):
    from ..plot.figures import render

    return render(result)


def redraw(path: os.PathLike, out: Optional[os.PathLike] = None, keep_figure: bool = False, force: bool = False):
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
    from .._output import refuse_foreign, savefig, write_error

    result = load_result(path)  # checked as it is read: the scene schema's checks, each field's type
    png = output_path("--out", out) if out is not None else Path(os.fspath(path)).with_suffix(".png")
    refuse_foreign([png], force)
    try:
        png.parent.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise write_error(png.parent, e, previous=False) from None
    try:
        fig = _render(result)
    except (ValueError, TypeError, KeyError, IndexError, AttributeError) as e:  # a combination the checks missed
        raise ValueError(f"{os.fspath(path)}: the result cannot be drawn ({type(e).__name__}: {e})") from None
    try:
        savefig(fig, png, dpi=result.scene.dpi)
    finally:
        if not keep_figure:
            import matplotlib.pyplot as plt

            plt.close(fig)
    return png, result, (fig if keep_figure else None)
