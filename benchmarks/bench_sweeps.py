"""Sweep throughput on 1 vs 2 workers (local threads, as executor=N runs them, and a Dask LocalCluster) and the Dask
overhead per task, measured in one run.

* hovering_area of the truncated map (paper parameters, eps = 0.3), 200,000 samples x 20,000 steps,
  in 16 pieces: one process (the core's own 2 threads), then 1 and 2 local workers (threads of this
  process) and LocalCluster worker processes (each piece on 1 core thread);
* the flow's |HOV| at one eps (V1 = Harmonic(1), V2 = Tan(1.4, 0.7), eps = -0.1, h = 1), 400
  samples x 400 returns, in 8 pieces, same settings;
* Dask's overhead per task: 200 empty tasks on the 2-worker LocalCluster.

Cluster start-up is reported separately and not in the throughputs. Run: python benchmarks/bench_sweeps.py
"""

from __future__ import annotations

import time

from hovering import paper
from hovering.analysis.hovering import hovering_area
from hovering.parallel import Executor
from hovering.parallel.executor import executor, run_pieces


def _noop(x):
    return x


def timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def main():
    tm = paper.truncated_map(0.3)
    fm = paper.flow_map(-0.1)
    cases = [
        ("truncated |HOV|, 200000 x 20000", tm, dict(n_steps=20_000, n_samples=200_000), 16, "step"),
        ("flow |HOV|, 1600 x 1000", fm, dict(n_steps=1000, n_samples=1600), 8, "return"),
    ]
    with executor(workers=2) as ex:  # what starting the local workers costs, for reference
        t_pool, _ = timed(lambda: list(run_pieces(ex, _noop, [(0,), (1,)])))
    print(f"local workers start (2 threads, first tasks): {t_pool:.2f} s, included in the times below")
    import distributed

    for name, m, kw, pieces, unit in cases:
        work = 2 * kw["n_samples"] * kw["n_steps"]  # upper bound: orbits exit early
        print(f"\n## {name} ({pieces} pieces; throughput in {unit}s of the F_0 + F_eps work bound per second)")
        t1, ref = timed(lambda: hovering_area(m, **kw, n_threads=0))
        print(f"one process, core threads = all: {t1:8.2f} s  ({work / t1:.3g} {unit}s/s)")
        base = None
        for w in (1, 2):
            t, r = timed(lambda: hovering_area(m, **kw, n_threads=1, executor=Executor(workers=w, pieces=pieces)))
            assert r.area == ref.area
            base = base or t
            print(f"local threads, {w} worker(s):     {t:8.2f} s  speed-up vs 1 worker {base / t:.2f}x")
        for w in (1, 2):
            ts = time.perf_counter()
            cluster = distributed.LocalCluster(n_workers=w, threads_per_worker=1, dashboard_address=":0")
            client = distributed.Client(cluster)
            start = time.perf_counter() - ts
            t, r = timed(lambda: hovering_area(m, **kw, n_threads=1, executor=Executor(client=client, pieces=pieces)))
            assert r.area == ref.area
            print(
                f"Dask LocalCluster, {w} worker(s): {t:8.2f} s  speed-up vs 1 local worker {base / t:.2f}x "
                f"(cluster start {start:.1f} s, not included)"
            )
            client.close()
            cluster.close()
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=":0")
    client = distributed.Client(cluster)
    with executor(client=client) as ex:
        list(run_pieces(ex, _noop, [(i,) for i in range(20)]))  # warm-up
        t, _ = timed(lambda: list(run_pieces(ex, _noop, [(i,) for i in range(200)])))
    print(f"\nDask overhead: {1e3 * t / 200:.2f} ms per empty task (200 tasks, 2 workers)")
    with executor(workers=2) as ex:
        list(run_pieces(ex, _noop, [(i,) for i in range(20)]))
        t, _ = timed(lambda: list(run_pieces(ex, _noop, [(i,) for i in range(200)])))
    print(f"process pool overhead: {1e3 * t / 200:.2f} ms per empty task (200 tasks, 2 workers)")
    client.close()
    cluster.close()


if __name__ == "__main__":
    main()
