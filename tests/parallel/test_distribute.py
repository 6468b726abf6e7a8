"""Distributed hovering-area runs (issue: sweeps past one machine): local workers (threads), a Dask
LocalCluster and an existing client give the single-process answer bit for bit (the samples are
drawn once and cut into contiguous pieces), and finished pieces are checkpointed as they arrive.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import hovering
from hovering import paper
from hovering.analysis.hovering import hovering_area
from hovering.parallel import Executor

M = paper.truncated_map(0.3)
KW = dict(n_steps=800, n_samples=6000, rng=7)


def same(a, b):
    assert a.area == b.area and a.areas == b.areas and a.error == b.error
    assert a.area_both_sides == b.area_both_sides and a.unresolved == b.unresolved
    assert a.impact_fraction_F0 == b.impact_fraction_F0


@pytest.fixture(scope="module")
def single():
    return hovering_area(M, **KW)


@pytest.fixture(scope="module")
def cluster():
    import distributed

    c = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0")
    client = distributed.Client(c)
    yield client
    client.close()
    c.close()


@pytest.mark.parametrize("pieces", [1, 3, 8])
def test_local_workers_give_the_single_process_answer(single, pieces):
    same(single, hovering_area(M, **KW, executor=Executor(workers=2, pieces=pieces)))


@pytest.mark.e2e  # starts a Dask LocalCluster (seconds)
def test_dask_local_cluster_and_an_existing_client_give_the_same_answer(single, cluster):
    same(single, hovering_area(M, **KW, executor=Executor(workers=2, dask=True, pieces=5)))
    same(single, hovering_area(M, **KW, executor=Executor(client=cluster, pieces=4)))
    same(single, hovering_area(M, **KW, executor=Executor(scheduler=cluster.scheduler.address, pieces=3)))


def test_the_callers_own_pools_give_the_same_answer_and_stay_open(single):
    # A thread pool works too (the core releases the GIL); a process pool of the caller's is used,
    # not shut down: it takes more work afterwards.
    import concurrent.futures as cf
    import multiprocessing

    with cf.ThreadPoolExecutor(2) as pool:
        same(single, hovering_area(M, **KW, executor=pool))
        assert pool.submit(abs, -1).result() == 1
    with cf.ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn")) as pool:
        same(single, hovering_area(M, **KW, executor=Executor(pool=pool, pieces=3)))
        assert pool.submit(abs, -2).result() == 2


def test_flow_map_pieces_give_the_single_process_answer():
    fm = paper.flow_map(-0.1)
    kw = dict(n_steps=40, n_samples=64, rng=1)
    same(hovering_area(fm, **kw), hovering_area(fm, **kw, executor=Executor(workers=2, pieces=3)))


def _python_flow_map(picklable: bool):
    """A FlowMap whose V1 is a CustomPotential (the harmonic well q^2): of lambdas, or of stdlib
    callables that pickle by name (a process pool's worker can import them)."""
    import functools
    import operator

    from hovering import Bilinear, CustomPotential, FlowMap, StepSystem, Tan

    if picklable:
        V1 = CustomPotential(functools.partial(pow, exp=2), functools.partial(operator.mul, 2.0), name="sq")
    else:
        V1 = CustomPotential(lambda q: q * q, lambda q: 2.0 * q, name="sq")
    return FlowMap(StepSystem(V1, Tan(1.4, 0.7), coupling=Bilinear(), eps=0.05), 1.5, rtol=1e-6, atol=1e-6)


def test_a_python_defined_potential_runs_on_threads_and_pools_or_is_refused_at_once(tmp_path):
    # Before: every executor= run of such a map died on the pieces' checkpoint key (a TypeError
    # about NPZ files), with or without a checkpoint; a process pool pickled the lambdas piece by
    # piece after the pool had started.
    import concurrent.futures as cf
    import multiprocessing

    kw = dict(n_steps=8, n_samples=16, rng=2, components=False)
    fm = _python_flow_map(picklable=False)
    single = hovering_area(fm, **kw)
    same(single, hovering_area(fm, **kw, executor=2))  # threads: no pickling needed
    with cf.ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn")) as pool:
        with pytest.raises(ValueError, match=r"the map cannot be sent to the caller's pool: it does not pickle"):
            hovering_area(fm, **kw, executor=pool)
        fm2 = _python_flow_map(picklable=True)
        same(hovering_area(fm2, **kw), hovering_area(fm2, **kw, executor=Executor(pool=pool, pieces=2)))
    # A checkpoint keys pieces by the map's record, which code has not: refused before any work.
    with pytest.raises(ValueError, match=r"checkpoint= keys each piece by the map's record, and this map has none"):
        hovering_area(fm, **kw, executor=Executor(workers=2, checkpoint=tmp_path / "c.jsonl"))
    assert not (tmp_path / "c.jsonl").exists()


def _points(path) -> list:
    """The point records of a checkpoint (its header and provenance lines left out)."""
    return [json.loads(x) for x in path.read_text().splitlines() if x.startswith('{"key":')]


def test_checkpoint_keeps_finished_pieces_and_keys_every_parameter(tmp_path):
    ck = tmp_path / "hov.jsonl"
    seen = []
    # One box (deepen=0; the default box of this map would deepen once, a second box of pieces):
    # four pieces per box measured.
    kw = dict(KW, deepen=0)
    single = hovering_area(M, **kw)
    first = hovering_area(M, **kw, executor=Executor(workers=2, pieces=4, checkpoint=ck))
    same(single, first)
    assert len(_points(ck)) == 4
    # The key is the canonical record: the map's parameters, the counts, the box, the seed, the range.
    key = _points(ck)[0]["key"]["hovering_area_piece"]
    assert key["map"]["data"]["__dict__"]["eps"] == M.eps and key["n_steps"] == kw["n_steps"]
    assert sorted(p["key"]["hovering_area_piece"]["lo"] for p in _points(ck))[0] == 0
    # a rerun reads all four pieces back: the progress callback sees every unit done, no new line
    again = hovering_area(
        M, **kw, executor=Executor(workers=2, pieces=4, checkpoint=ck), progress=lambda d, t: seen.append((d, t))
    )
    same(single, again)
    assert len(_points(ck)) == 4 and seen[-1][0] == seen[-1][1]
    # another parameter (n_steps) is another key: four new pieces
    hovering_area(M, **{**kw, "n_steps": 400}, executor=Executor(workers=2, pieces=4, checkpoint=ck))
    assert len(_points(ck)) == 8
    # a torn last line (a killed run) is dropped and that piece alone recomputed
    text = ck.read_text()
    lines = text.splitlines()
    ck.write_text("\n".join(lines[:-1]) + "\n" + lines[-1][: len(lines[-1]) // 2])
    redo = hovering_area(M, **{**kw, "n_steps": 400}, executor=Executor(workers=2, pieces=4, checkpoint=ck))
    assert len(_points(ck)) == 8
    assert redo.area == hovering_area(M, **{**kw, "n_steps": 400}).area


@pytest.mark.parametrize(
    "bad, match",
    [
        (0, r"workers must be an integer in \[1, 4096\], got 0"),
        (True, "executor must be None, a worker count, .* got True"),
        (2.0, "executor must be None, a worker count, .* got 2.0"),
        ("", "scheduler must be an address"),
        (dict(client="tcp://nowhere"), "client must be a distributed.Client, got 'tcp://nowhere'"),
        (dict(workers=2, pieces=0), "pieces must be an integer"),
        (dict(client=None, scheduler="tcp://a:1", dask=True), "dask=True makes a LocalCluster"),
        (dict(workers=2, dask="yes"), "dask must be True or False, got 'yes'"),
        (dict(pool="threads"), "pool must be a concurrent.futures.Executor, got 'threads'"),
        (
            dict(pool=__import__("concurrent.futures").futures.ThreadPoolExecutor(1), workers=2),
            "brings its own workers",
        ),
        (
            dict(pool=__import__("concurrent.futures").futures.ThreadPoolExecutor(1), scheduler="tcp://a:1"),
            "at most one of client, scheduler and pool",
        ),
    ],
)
def test_bad_executors_are_named_before_any_work(bad, match):
    with pytest.raises(ValueError, match=match):
        hovering_area(M, **KW, executor=Executor(**bad) if isinstance(bad, dict) else bad)


def test_the_six_old_arguments_still_work_and_warn_naming_executor_and_the_release(single, tmp_path):
    # Every old argument: the same answer as its executor=, one DeprecationWarning each, pointing at
    # this file (the user's line, not the package's), naming executor= and hovering 0.4.0.
    with pytest.warns(DeprecationWarning) as w:
        old = hovering_area(M, **KW, workers=2, pieces=3, checkpoint=tmp_path / "old.jsonl")
    same(single, old)
    msgs = [str(x.message) for x in w]
    assert len(msgs) == 3 and all("executor=hovering.parallel.Executor(" in m and "0.4.0" in m for m in msgs)
    assert {x.filename for x in w} == {__file__}
    # through the map's method (one more frame of ours between): still attributed to this file
    with pytest.warns(DeprecationWarning) as w:
        same(single, hovering.hovering_area(M, **KW, workers=2))
    assert [x.filename for x in w] == [__file__]
    with pytest.raises(ValueError, match="not both"):
        hovering_area(M, **KW, executor=2, workers=2)
    with pytest.warns(DeprecationWarning), pytest.raises(ValueError, match="checkpoint apply to runs on workers"):
        hovering_area(M, **KW, checkpoint="x.jsonl")


def test_an_int_executor_is_a_local_pool_and_a_string_a_scheduler():
    from hovering.parallel import as_executor

    assert as_executor(3) == Executor(workers=3) and as_executor("tcp://h:1") == Executor(scheduler="tcp://h:1")
    assert as_executor(None) is None


def _scene_copy(tmp_path, name, **changes):
    import tomllib

    from hovering.scenes import parse_scene

    root = __import__("pathlib").Path(__file__).resolve().parents[2]
    path = root / "examples" / "scenes" / name
    data = tomllib.loads(path.read_text())
    data.update(changes)
    data["output"] = str(tmp_path / (path.stem + ".png"))
    return parse_scene(data, tmp_path / path.name)  # a scene in tmp_path may write there


@pytest.mark.e2e
def test_sweep_scenes_on_workers_give_the_one_process_rows(tmp_path):
    from hovering.scenes.compute import compute

    sc = _scene_copy(tmp_path, "fig_hov_vs_eps.toml")
    one = compute(sc, quick=True, checkpoint=tmp_path / "one.jsonl")
    pool = compute(sc, quick=True, checkpoint=tmp_path / "pool.jsonl", executor=2)
    for a, b in zip(one.series, pool.series):
        assert np.array_equal(a.area, b.area) and np.array_equal(a.error, b.error) and np.array_equal(a.eps, b.eps)
    # every point is in the checkpoint, and a rerun (on a Dask LocalCluster) computes none
    again = compute(sc, quick=True, checkpoint=tmp_path / "pool.jsonl", executor=Executor(workers=2, dask=True))
    assert again.meta["points_reused"] == sum(len(s.eps) for s in again.series)


@pytest.mark.e2e
def test_flow_sweep_scene_on_workers(tmp_path):
    from hovering.scenes.compute import compute

    sc = _scene_copy(tmp_path, "flow_hov_vs_eps.toml", eps=[-0.1, 0.1])
    one = compute(sc, quick=True, checkpoint=tmp_path / "one.jsonl")
    pool = compute(sc, quick=True, checkpoint=tmp_path / "pool.jsonl", executor=2)
    assert np.array_equal(one.flow_area, pool.flow_area) and np.array_equal(one.eps, pool.eps)
    for name in one.models:
        assert np.array_equal(one.models[name]["area"], pool.models[name]["area"])


@pytest.mark.e2e
def test_cli_workers_flags(tmp_path):
    import subprocess
    import sys

    root = __import__("pathlib").Path(__file__).resolve().parents[2]
    scene = root / "examples" / "scenes" / "fig_hov_vs_eps.toml"
    p = subprocess.run(
        [
            sys.executable,
            "-m",
            "hovering",
            "scene",
            str(scene),
            "--quick",
            "--workers",
            "2",
            "--out",
            str(tmp_path / "h.png"),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "h.sweep.jsonl").exists()
    bad = subprocess.run(
        [sys.executable, "-m", "hovering", "scene", str(scene), "--dask"], capture_output=True, text=True, timeout=60
    )
    assert bad.returncode == 2 and "--dask needs --workers" in bad.stderr
