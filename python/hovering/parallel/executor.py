"""Where work runs: :class:`Executor` (the one ``executor=`` argument of the functions that can
split their work) and the machinery behind it: a local process pool, a Dask ``LocalCluster``, or an
existing Dask cluster, behind one small interface.

``executor=`` takes what scipy's ``workers=`` would, and a little more: ``None`` (this process,
the core's threads), an ``int`` (that many local worker processes), a scheduler address (``str``),
a ``distributed.Client``, a :class:`concurrent.futures.Executor` of the caller's (not shut down
here), or an :class:`Executor` for the rest (a Dask ``LocalCluster``, the number
of pieces, a checkpoint file that keeps finished pieces).

A *piece* is a picklable function call (maps, systems and results pickle: tests/package/test_pickle.py).
:func:`run_pieces` submits them all, yields each result as it arrives (so the caller checkpoints
it at once) and cancels what is left on Ctrl-C. The pieces of one computation are cut so that
their union is exactly the single-process computation: the answer does not depend on where, or in
which order, the pieces ran.
"""

from __future__ import annotations

import concurrent.futures as cf
import multiprocessing
import os
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass

from .._checks import integer
from .._deprecated import renamed_argument

__all__ = ["Executor", "as_executor", "executor", "run_pieces"]


@dataclass(frozen=True)
class Executor:
    """Where a splittable computation runs, and how its finished pieces are kept.

    Parameters
    ----------
    workers : int, optional
        Local worker processes (1 to 4096): a process pool, or with ``dask`` a Dask LocalCluster
        of that many single-threaded workers. Default 2 when neither ``client`` nor ``scheduler``
        is given.
    dask : bool, optional
        With ``workers``: a Dask LocalCluster instead of a process pool.
    client : distributed.Client, optional
        An existing Dask client: its cluster runs the pieces (the client is not closed).
    scheduler : str, optional
        Address of a running Dask scheduler (``"tcp://host:8786"``).
    pieces : int, optional
        Number of pieces the work is cut into (default 4 per worker); the answer does not depend on it.
    checkpoint : path-like, optional
        A checkpoint file (:mod:`hovering.parallel.checkpoint`): each finished piece is written as it
        arrives, keyed by every parameter that changes it; a rerun computes only the missing pieces.
    pool : concurrent.futures.Executor, optional
        The caller's own pool (a ``ProcessPoolExecutor``, or a ``ThreadPoolExecutor``: the core
        releases the GIL); it is used, not shut down.

    Raises
    ------
    ValueError
        For a worker or piece count out of range, a client that is not a ``distributed.Client``, a
        pool that is not a ``concurrent.futures.Executor``, an empty scheduler address, more than one
        of ``client``, ``scheduler`` and ``pool``, or ``dask`` with one of them.
    """

    workers: int | None = None
    dask: bool = False
    client: object = None
    scheduler: str | None = None
    pieces: int | None = None
    checkpoint: object = None
    pool: object = None

    def __post_init__(self):
        if sum(x is not None for x in (self.client, self.scheduler, self.pool)) > 1:
            raise ValueError("give at most one of client, scheduler and pool")
        if self.pool is not None and not isinstance(self.pool, cf.Executor):
            raise ValueError(f"pool must be a concurrent.futures.Executor, got {self.pool!r}")
        if self.pool is not None and (self.workers is not None or self.dask):
            raise ValueError("a pool brings its own workers: give pool without workers and dask")
        if not isinstance(self.dask, bool):
            raise ValueError(f"dask must be True or False, got {self.dask!r}")
        if self.dask and (self.client is not None or self.scheduler is not None):
            raise ValueError("dask=True makes a LocalCluster of `workers` processes: not with a client or scheduler")
        if self.workers is not None:
            object.__setattr__(self, "workers", integer("workers", self.workers, 1, 4096))
        if self.pieces is not None:
            object.__setattr__(self, "pieces", integer("pieces", self.pieces, 1, 2**31 - 1))
        if self.scheduler is not None and (not isinstance(self.scheduler, str) or not self.scheduler):
            raise ValueError(f"scheduler must be an address such as 'tcp://host:8786', got {self.scheduler!r}")
        if self.client is not None:
            try:
                import distributed
            except ImportError:  # pragma: no cover - distributed is a dependency
                raise ValueError("a Dask client needs dask[distributed] (pip install 'dask[distributed]')") from None
            if not isinstance(self.client, distributed.Client):
                raise ValueError(f"client must be a distributed.Client, got {self.client!r}")

    def where(self) -> dict:
        """The arguments of :func:`executor` (where the pieces run)."""
        return dict(workers=self.workers, client=self.client, scheduler=self.scheduler, dask=self.dask, pool=self.pool)


def _not_an_executor(value) -> ValueError:
    return ValueError(
        f"executor must be None, a worker count, a scheduler address, a distributed.Client, a "
        f"concurrent.futures.Executor or a hovering.parallel.Executor, got {value!r}"
    )


def as_executor(value) -> Executor | None:
    """The :class:`Executor` an ``executor=`` argument stands for (``None``: this process).

    Parameters
    ----------
    value : None, int, str, distributed.Client, concurrent.futures.Executor or Executor
        ``None`` (this process), a number of local worker processes, a Dask scheduler address, a
        Dask client, the caller's pool, or an :class:`Executor`.

    Returns
    -------
    Executor or None

    Raises
    ------
    ValueError
        For anything else, naming the value and the accepted kinds.
    """
    if value is None or isinstance(value, Executor):
        return value
    if isinstance(value, bool):
        raise _not_an_executor(value)
    if isinstance(value, int):
        return Executor(workers=value)
    if isinstance(value, str):
        return Executor(scheduler=value)
    if isinstance(value, cf.Executor):
        return Executor(pool=value)
    if type(value).__name__ == "Client" and type(value).__module__.startswith("distributed"):
        return Executor(client=value)
    raise _not_an_executor(value)


#: The "where it runs" arguments an ``executor=`` replaced (deprecated in 0.3.0).
OLD_ARGUMENTS = ("workers", "client", "scheduler", "dask", "pieces", "checkpoint")


def from_old_arguments(func: str, executor_value, old: dict, allowed=OLD_ARGUMENTS) -> Executor | None:
    """``executor=`` of a function that also still takes the old separate arguments.

    Each old argument that was given warns (DeprecationWarning naming ``executor=`` and the release
    that removes it); together they make the :class:`Executor` they described.

    Parameters
    ----------
    func : str
        The function's name, for the messages.
    executor_value : object
        The ``executor=`` argument (see :func:`as_executor`).
    old : dict
        The old arguments, with ``None`` (or ``False`` for ``dask``) where not given.
    allowed : tuple of str, optional
        The old arguments this function had.

    Returns
    -------
    Executor or None

    Raises
    ------
    ValueError
        For both ``executor`` and an old argument, or bad values (see :class:`Executor`).
    """
    given = {k: v for k, v in old.items() if k in allowed and v is not None and v is not False}
    if not given:
        return as_executor(executor_value)
    if executor_value is not None:
        raise ValueError(f"{func}: give executor= or the deprecated {', '.join(given)}, not both")
    for k in given:
        renamed_argument(func, k, f"executor=hovering.parallel.Executor({k}=...)")
    if not ({"workers", "client", "scheduler"} & given.keys()):
        raise ValueError(f"{func}: {', '.join(given)} apply to runs on workers (give workers, client or scheduler)")
    return Executor(**given)


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


class _Given(_Local):
    """The caller's concurrent.futures pool: used, never shut down here."""

    def __init__(self, pool):
        self.pool = pool
        # concurrent.futures keeps the size private; 4 pieces per worker only sets the default piece count.
        self.workers = max(1, int(getattr(pool, "_max_workers", 0) or (os.cpu_count() or 1)))
        self.threads_per_piece = _share(self.workers)

    def close(self):
        pass


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
def executor(workers: int | None = None, client=None, scheduler: str | None = None, dask: bool = False, pool=None):
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
    pool : concurrent.futures.Executor, optional
        The caller's pool (used, not shut down).

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
    spec = Executor(workers=workers, client=client, scheduler=scheduler, dask=dask, pool=pool)  # the checks
    if pool is not None:
        ex = _Given(pool)
    elif client is not None or scheduler is not None or dask:
        import distributed

        if client is not None:
            ex = _Dask(client, own=False)
        elif scheduler is not None:
            ex = _Dask(distributed.Client(scheduler), own=True)
        else:
            n = spec.workers if spec.workers is not None else 2
            cluster = distributed.LocalCluster(
                n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0"
            )
            ex = _Dask(distributed.Client(cluster), own=True, cluster=cluster)
    else:
        ex = _Local(spec.workers if spec.workers is not None else 2)
    try:
        yield ex
    finally:
        ex.close()


def run_pieces(ex, fn: Callable, pieces: Iterable[tuple], on_result: Callable | None = None) -> Iterator:
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
