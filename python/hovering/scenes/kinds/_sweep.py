"""The sweep of the two hovering-area kinds: each point of a resolved plan (:mod:`hovering.scenes.plan`)
measured, checkpointed as it arrives, reused from the checkpoint on a rerun, here or as pieces on
an executor.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable

import numpy as np

from ..._checks import real_number
from ...analysis.hovering import check_estimate, hovering_area
from ...normal.flowmap import FlowMap
from ...parallel.checkpoint import check_row
from ...parallel.executor import Executor, run_pieces
from ...parallel.executor import executor as open_executor
from ...truncated.maps import TruncatedFamily, TruncatedMap
from ..plan import build_system, point_key

__all__ = ["run_point", "sweep", "sweep_size"]

# The scene computations log under one name (what ``hovering -v`` shows and the docs quote).
_log = logging.getLogger("hovering.scenes.compute")


def run_point(kind: str, point: dict, n_threads: int = 0) -> dict:
    """Measure one point of a resolved sweep plan (:func:`hovering.scenes.plan.plan_points`).

    The same core functions, on the same numbers, as ``hovering_sweep`` (cpp/src/hovering/sweep/
    run.cpp): the rows of the two programs are the same doubles (but ``seconds``), and each
    resumes the other's checkpoint. A piece: it runs in any process.

    Parameters
    ----------
    kind : {"hovering_area", "flow_hovering_area"}
        The plan's kind.
    point : dict
        A plan point.
    n_threads : int, optional
        Core threads (0 = all cores).

    Returns
    -------
    dict
        The row: the estimate's fields (``area``, ``error``, ``sampling_error``,
        ``iteration_error``, ``area_N4``, ``area_N2``, ``area_both_sides``, ``impact_fraction_F0``,
        ``floor_touched``, ``unresolved``, ``n_samples``, ``K_low``), ``theory`` (carried),
        ``seconds``; a flow point also ``b1`` (carried) and ``models`` (per model: ``area``,
        ``error``, ``agree``, ``K_low``).
    """
    t = time.perf_counter()
    # A row holds the estimate, not its split: the split's orbit classes and the flow's floor search
    # would cost a sweep point up to 1.5 s for nothing it shows.
    kw = dict(
        n_steps=point["n_steps"], n_samples=point["samples"], rng=point["seed"], n_threads=n_threads, components=False
    )
    if kind == "hovering_area":
        h = hovering_area(TruncatedMap(**point["map"]), K_low=point["K_low"], **kw)
        row = _area_row(h)
    else:
        fm = FlowMap(build_system(point["system"]), h=point["h"], **point["integrator"])
        h = hovering_area(fm, K_low=point["K_low"], keep_points=bool(point["models"]), **kw)
        row = _area_row(h)
        row["b1"] = point["b1"]
        row["models"] = {}
        for m in point["models"]:
            tm = TruncatedFamily._from_record({k: m[k] for k in ("eps", "K", "Omega", "JR", "J1", "forcing", "K_max")})
            mh = hovering_area(tm, K_low=m["K_low"], keep_points=True, **kw)
            # A model sampling another box (its band is shallower) classifies other points: no agreement.
            agree = float(np.mean(mh.hovering == h.hovering)) if m["K_low"] == point["K_low"] else float("nan")
            row["models"][m["name"]] = dict(area=mh.area, error=mh.error, agree=agree, K_low=m["K_low"])
    row["theory"] = point["theory"]
    row["seconds"] = time.perf_counter() - t
    return row


def _area_row(h) -> dict:
    N = sorted(h.areas)
    return dict(
        area=h.area,
        error=h.error,
        sampling_error=h.sampling_error,
        iteration_error=h.iteration_error,
        area_N4=h.areas[N[0]],
        area_N2=h.areas[N[1]],
        area_both_sides=h.area_both_sides,
        impact_fraction_F0=h.impact_fraction_F0,
        floor_touched=bool(h.floor_touched),
        unresolved=int(h.unresolved),
        n_samples=int(h.n_samples),
        K_low=float(h.box[2]),
    )


#: The fields of a point's row that the sweeps read (what a checkpointed row must have).
_ROW = dict(
    area=float,
    error=float,
    sampling_error=float,
    iteration_error=float,
    area_N4=float,
    area_N2=float,
    area_both_sides=float,
    impact_fraction_F0=float,
    floor_touched=bool,
    unresolved=int,
    n_samples=int,
    K_low=float,
    theory=float,
    seconds=float,
)
_MODEL_ROW = dict(area=float, error=float, agree=float, K_low=float)


def _row_check(kind: str, point: dict) -> Callable:
    """A check of a checkpointed row (untrusted): the fields its reader takes, the point's own box (and
    each model's), the estimates' numbers within what those boxes allow
    (:func:`hovering.analysis.hovering.check_estimate`)."""
    fields = dict(_ROW)
    models = point["models"] if kind == "flow_hovering_area" else ()
    if kind == "flow_hovering_area":
        fields.update(b1=float, models=(tuple(m["name"] for m in models), _MODEL_ROW))

    def check(row):
        check_row(row, fields)
        estimates = [("row", row, point["K_low"])]
        estimates += [(f"row.models.{m['name']}", row["models"][m["name"]], m["K_low"]) for m in models]
        for where, est, K_low in estimates:
            if est["K_low"] != K_low:
                raise ValueError(f"{where}.K_low = {est['K_low']!r} is not the point's K_low = {K_low!r}")
            try:
                check_estimate(est, 2 * math.pi * -K_low)  # the box [-pi, pi) x [K_low, 0)
                if "agree" in est and not math.isnan(est["agree"]):  # NaN: the model sampled another box
                    real_number("agree", est["agree"], lo=0.0, lo_open=False, hi=1.0, hi_open=False)
            except ValueError as e:
                raise ValueError(f"{where}.{e}") from None
        real_number("row.seconds", row["seconds"], lo=0.0, lo_open=False)

    return check


def sweep_size(points: list, where) -> str:
    """What a sweep computes, for its log line: points, samples x steps per point, where.

    Parameters
    ----------
    points : list of dict
        The plan's points.
    where : hovering.parallel.Executor or None
        Where they run.

    Returns
    -------
    str
    """
    p = points[0]
    models = f" + {len(p['models'])} model(s)" if p.get("models") else ""
    if where is None:
        place = "in this process"
    elif where.scheduler is not None:
        place = f"on the Dask scheduler at {where.scheduler}"
    elif where.client is not None:
        place = "on a Dask client"
    elif where.pool is not None:
        place = "on the caller's pool"
    else:
        place = f"{where.workers} at a time on {'a Dask LocalCluster' if where.dask else 'threads'}"
    return f"{len(points)} points of {p['samples']} samples x {p['n_steps']} steps{models}, {place}"


def _point_label(point: dict) -> str:
    eps = point["map"]["eps"] if "map" in point else point["system"]["eps"]
    return f"eps = {eps:g}"


def sweep(kind: str, points: list, ckpt, bar, where: Executor | None, name: str = "") -> tuple:
    """Rows of a plan's points in order: from the checkpoint (each row checked first: the file is
    untrusted), or computed (here, or as pieces on the executor ``where``) and checkpointed as each
    arrives (a point another process wrote meanwhile is not written again). Each point is logged at
    INFO as it arrives.

    Parameters
    ----------
    kind : str
        The plan's kind.
    points : list of dict
        The plan's points (:func:`hovering.scenes.plan.plan_points`).
    ckpt : hovering.parallel.checkpoint.Checkpoint
        The checkpoint.
    bar : progress bar
        Advanced once per point.
    where : hovering.parallel.Executor or None
        Where the points run (None: here, one after another).
    name : str, optional
        The scene's name, for the log lines.

    Returns
    -------
    tuple
        ``(rows, reused)``: one row per point, and one bool per point (True where the checkpoint
        had it).
    """
    keys = [point_key(kind, p) for p in points]
    rows = [ckpt.get(k, _row_check(kind, p)) for k, p in zip(keys, points)]
    reused = [r is not None for r in rows]
    bar.advance(sum(reused))
    todo = [i for i, r in enumerate(rows) if r is None]
    _log.info(
        "scene %s: %d of %d points from the checkpoint %s, %d to compute", name, sum(reused), len(points),
        ckpt.path, len(todo),
    )  # fmt: skip

    def done(j, row):
        i = todo[j]
        ckpt.put(keys[i], row)
        rows[i] = ckpt.get(keys[i]) if keys[i] in ckpt else row  # another process's row, if it was first
        bar.advance(1)
        _log.info(
            "scene %s: point %d/%d (%s) area %.4g +- %.2g, %.1f s", name, i + 1, len(points),
            _point_label(points[i]), rows[i]["area"], rows[i]["error"], rows[i]["seconds"],
        )  # fmt: skip

    if where is not None:
        with open_executor(**where.where()) as ex:
            # Each point keeps the core's threads (all cores): sweep points differ in cost (1-25 s per
            # eps of the flow scene), and one thread per point on a shared machine left the costliest
            # point alone at the end (66 s vs 50 s for flow_hov_vs_eps on 2 workers here).
            for _ in run_pieces(ex, _call, [(run_point, (kind, points[i])) for i in todo], on_result=done):
                pass
    else:
        for j, i in enumerate(todo):
            ckpt.refresh()
            if keys[i] in ckpt:  # finished by another process meanwhile (hovering_sweep on the same file)
                rows[i] = ckpt.get(keys[i], _row_check(kind, points[i]))
                reused[i] = True
                bar.advance(1)
                continue
            done(j, run_point(kind, points[i]))
    return rows, reused


def _call(fn, args):
    return fn(*args)
