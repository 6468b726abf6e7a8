"""Running independent pieces of a sweep on other processes: a local process pool, a Dask
``LocalCluster``, or an existing Dask cluster, behind one small interface.

A *piece* is a picklable function call (maps, systems and results pickle: tests/test_pickle.py).
:func:`run_pieces` submits them all, yields each result as it arrives (so the caller checkpoints
it at once) and cancels what is left on Ctrl-C. The pieces of one computation are cut so that
their union is exactly the single-process computation: the answer does not depend on where, or in
which order, the pieces ran.
"""

from __future__ import annotations

import concurrent.futures as cf
import multiprocessing
import os
from contextlib import contextmanager
from typing import Callable, Iterable, Iterator, Optional

from ._checks import integer

__all__ = ["executor", "run_pieces"]


class _Local:
    """concurrent.futures on spawned processes (no fork: the core's thread pool does not survive it)."""

    def __init__(self, workers: int):
        self.pool = cf.ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"))
        self.workers = workers
        self.threads_per_piece = _share(workers)

    def submit(self, fn, *args):
        return self.pool.submit(fn, *args)

    def as_completed(self, futures):
        return cf.as_completed(futures)

    def cancel(self, futures):
        for f in futures:
            f.cancel()

    def close(self):
        self.pool.shutdown(wait=True, cancel_futures=True)


class _Dask:
    """A distributed.Client (given, or on a LocalCluster / scheduler address made here)."""

    def __init__(self, client, own: bool, cluster=None):
        self.client, self.own, self.cluster = client, own, cluster
        self.workers = max(1, len(client.scheduler_info().get("workers", {})))
        # A LocalCluster made here shares this machine's cores; a given cluster's workers run on
        # machines whose cores the core's own default (all of them) fits.
        self.threads_per_piece = _share(self.workers) if cluster is not None else 0

    def submit(self, fn, *args):
        # pure=False: two pieces with equal arguments are still two pieces (no result sharing)
        return self.client.submit(fn, *args, pure=False)

    def as_completed(self, futures):
        from distributed import as_completed

        return as_completed(futures)

    def cancel(self, futures):
        self.client.cancel(list(futures))

    def close(self):
        if self.own:
            self.client.close()
            if self.cluster is not None:
                self.cluster.close()


def _share(workers: int) -> int:
    """Core threads per piece when ``workers`` processes share this machine (>= 1): without it each
    piece's iteration would start a thread per core and oversubscribe the cores workers-fold."""
    return max(1, (os.cpu_count() or 1) // workers)


@contextmanager
def executor(workers: Optional[int] = None, client=None, scheduler: Optional[str] = None, dask: bool = False):
    """Where pieces run.

    Parameters
    ----------
    workers : int, optional
        Worker processes (>= 1): a local process pool, or with ``dask`` a Dask LocalCluster of that
        many single-threaded workers.
    client : distributed.Client, optional
        An existing Dask client (its cluster runs the pieces; not closed here).
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:8786``).
    dask : bool, optional
        With ``workers``: a Dask LocalCluster instead of a process pool.

    Yields
    ------
    object
        ``submit(fn, *args)``, ``as_completed(futures)``, ``cancel(futures)``, ``workers``,
        ``threads_per_piece`` (core threads a piece should use: this machine's cores shared among
        local workers; 0, all of a worker's cores, on a given cluster).

    Raises
    ------
    ValueError
        For a bad worker count, or more than one of client / scheduler / workers-with-dask.
    """
    if sum(x is not None for x in (client, scheduler)) > 1:
        raise ValueError("give at most one of client and scheduler")
    if client is not None or scheduler is not None or dask:
        try:
            import distributed
        except ImportError:  # pragma: no cover - distributed is a dependency
            raise ValueError("Dask execution needs dask[distributed] (pip install 'dask[distributed]')") from None
        if client is not None:
            if not isinstance(client, distributed.Client):
                raise ValueError(f"client must be a distributed.Client, got {client!r}")
            ex = _Dask(client, own=False)
        elif scheduler is not None:
            if not isinstance(scheduler, str) or not scheduler:
                raise ValueError(f"scheduler must be an address such as 'tcp://host:8786', got {scheduler!r}")
            ex = _Dask(distributed.Client(scheduler), own=True)
        else:
            n = integer("workers", workers if workers is not None else 2, 1, 4096)
            cluster = distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                               dashboard_address=":0")
            ex = _Dask(distributed.Client(cluster), own=True, cluster=cluster)
    else:
        ex = _Local(integer("workers", workers if workers is not None else 2, 1, 4096))
    try:
        yield ex
    finally:
        ex.close()


def run_pieces(ex, fn: Callable, pieces: Iterable[tuple], on_result: Optional[Callable] = None) -> Iterator:
    """Submit ``fn(*args)`` for each piece and yield ``(index, result)`` as pieces finish.

    Parameters
    ----------
    ex : object
        From :func:`executor`.
    fn : callable
        A picklable module-level function.
    pieces : iterable of tuple
        The arguments of each piece.
    on_result : callable, optional
        Called as ``on_result(index, result)`` before the pair is yielded (a checkpoint write).

    Yields
    ------
    (int, object)
        Index of the piece in ``pieces`` and its result, in completion order.

    Raises
    ------
    KeyboardInterrupt
        After cancelling every piece not yet finished (the finished ones were yielded).
    """
    futures = {}
    for i, args in enumerate(pieces):
        futures[ex.submit(fn, *args)] = i
    try:
        for f in ex.as_completed(list(futures)):
            i = futures.pop(f)
            res = f.result()
            if on_result is not None:
                on_result(i, res)
            yield i, res
    except BaseException:
        ex.cancel(list(futures))
        raise
