"""Where work runs: :class:`Executor` (the one ``executor=`` argument of the functions that can
split their work) and the machinery behind it: local threads, a Dask ``LocalCluster``, or an
existing Dask cluster, behind one small interface.

``executor=`` takes what scipy's ``workers=`` would, and a little more: ``None`` (this process,
the core's threads), an ``int`` (that many pieces at a time on threads of this process), a
scheduler address (``str``),
a ``distributed.Client``, a :class:`concurrent.futures.Executor` of the caller's (not shut down
here), or an :class:`Executor` for the rest (a Dask ``LocalCluster``, the number
of pieces, a checkpoint file that keeps finished pieces).

Local runs (``executor=2``, ``Executor(workers=2)``) run their pieces on threads of this process:
the core releases the GIL, so they run in parallel, and no process is started. A process pool's
workers would import the caller's script again (spawn and forkserver both do, to find
``__main__``), so a top-level script without an ``if __name__ == "__main__":`` guard would run its
own parallel call again in each worker and die with BrokenProcessPool; fork copies the parent's
threads' locks in whatever state they are in (unsafe, and deprecated by Python 3.12 in a threaded
process). Threads need no guard and no pickling. Ctrl-C reaches only the main thread: it sets the
run's stop event, which each piece's core calls poll (:func:`hovering._progress.stoppable`).

A *piece* is a picklable function call (maps, systems and results pickle: tests/package/test_pickle.py).
:func:`run_pieces` submits them all, yields each result as it arrives (so the caller checkpoints
it at once) and cancels what is left on Ctrl-C. The pieces of one computation are cut so that
their union is exactly the single-process computation: the answer does not depend on where, or in
which order, the pieces ran.
"""

from __future__ import annotations

import concurrent.futures as cf
import logging
import os
import threading
import weakref
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass

from .._checks import integer
from .._deprecated import renamed_argument
from .._extras import require
from .._progress import stoppable

__all__ = ["Executor", "as_executor", "executor", "run_pieces"]

_log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Executor:
    """Where a splittable computation runs, and how its finished pieces are kept.

    Parameters
    ----------
    workers : int, optional
        Local workers (1 to 4096): that many pieces at a time on threads of this process (no
        ``__main__`` guard needed), or with ``dask`` a Dask LocalCluster of that many
        single-threaded worker processes. Default 2 when neither ``client`` nor ``scheduler`` is
        given.
    dask : bool, optional
        With ``workers``: a Dask LocalCluster (worker processes) instead of local threads.
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
    ImportError
        For a Dask run (``client``, ``scheduler`` or ``dask``) without Dask installed, naming
        ``pip install 'hovering[distributed]'``.
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
        if self.client is not None or self.scheduler is not None or self.dask:
            # before any work: a run that needs Dask says which extra installs it
            distributed = require("distributed", "a Dask run (client=, scheduler= or dask=True)")
            if self.client is not None and not isinstance(self.client, distributed.Client):
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
        ``None`` (this process), a number of local workers (threads), a Dask scheduler address, a
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


_exit_began = threading.Event()  # set by _at_exit: the main thread has ended, the interpreter exits
_daemon_runs: weakref.WeakSet = weakref.WeakSet()  # the runs on local threads that daemon threads started
_hooked = False  # whether _at_exit is registered


def _at_exit() -> None:
    """The interpreter exits: threading's exit hooks run in the main thread once it has ended, this
    one before concurrent.futures' (registered earlier: hooks run last first), which runs every
    queued piece to the end and joins the pool threads. The runs of daemon threads are stopped:
    their running pieces end within ~0.1 s, their queued pieces never start, and their callers park
    (:func:`_park_if_exiting`). Else the exit waited for all their pieces, and then each caller went
    on with its work (its Python code, NumPy's, the core's) as the interpreter finalised, where
    CPython ends a daemon thread at its next taking of the GIL: inside a C++ frame that aborted the
    process (python/src/gil.hpp)."""
    _exit_began.set()
    for run in list(_daemon_runs):
        run.cancel(run.submitted)


def _hook_exit() -> None:
    """Register _at_exit once, after concurrent.futures' own exit hook (so that it runs first)."""
    global _hooked
    if _hooked:
        return
    _hooked = True
    try:
        import concurrent.futures.thread  # noqa: F401  registers concurrent.futures' hook, if not yet

        threading._register_atexit(_at_exit)  # as concurrent.futures does (CPython >= 3.9)
    except RuntimeError:  # "can't register atexit after shutdown": the exit has begun
        _exit_began.set()


def _park_if_exiting() -> None:
    """On a daemon thread once the interpreter exits: sleep until the process ends (a blocked wait
    never takes the GIL again), as the core parks a call that outlives the interpreter. A non-daemon
    thread goes on: the exit waits for it."""
    if _exit_began.is_set() and threading.current_thread().daemon:
        threading.Event().wait()


def _stoppable_call(stop: threading.Event, fn, args):
    """fn(*args) on a pool thread, its core calls stopped once ``stop`` is set (see the module docstring)."""
    with stoppable(stop):
        return fn(*args)


class _Local:
    """Pieces on threads of this process (see the module docstring: why not processes)."""

    name = "threads of this process"

    def __init__(self, workers: int):
        self.pool = cf.ThreadPoolExecutor(max_workers=workers, thread_name_prefix="hovering-piece")
        self.workers = workers
        self.threads_per_piece = _share(workers)
        self.stop = threading.Event()
        self._watch_exit()

    def _watch_exit(self) -> None:
        """Be stopped by _at_exit if the caller is a daemon thread (nothing waits for it at exit)."""
        self.submitted = []
        if threading.current_thread().daemon:
            _hook_exit()
            _daemon_runs.add(self)

    def submit(self, fn, *args):
        _park_if_exiting()
        try:
            if self.stop is None:
                f = self.pool.submit(fn, *args)
            else:
                f = self.pool.submit(_stoppable_call, self.stop, fn, args)
        except RuntimeError:  # "cannot schedule new futures after interpreter shutdown"
            _park_if_exiting()
            raise
        self.submitted.append(f)
        return f

    def as_completed(self, futures):
        # Waits of 0.1 s, not one long wait: the main thread runs Python between them, so Ctrl-C
        # (also one that does not interrupt a blocking wait: _thread.interrupt_main) is seen at once.
        pending = set(futures)
        while pending:
            done, pending = cf.wait(pending, timeout=0.1, return_when=cf.FIRST_COMPLETED)
            _park_if_exiting()  # before the caller sees a piece that _at_exit cancelled
            yield from done

    def cancel(self, futures):
        self.left = list(futures)
        if self.stop is not None:
            self.stop.set()  # the running pieces end within ~0.1 s
        for f in self.left:
            f.cancel()

    def close(self):
        self.pool.shutdown(wait=True, cancel_futures=True)

    def check_sendable(self, obj, what: str) -> None:
        """Nothing to check: a thread of this process takes ``obj`` as it is (no pickling)."""


class _Given(_Local):
    """The caller's concurrent.futures pool: used, never shut down here."""

    name = "the caller's pool"

    def __init__(self, pool):
        self.pool = pool
        # concurrent.futures keeps the size private; 4 pieces per worker only sets the default piece count.
        self.workers = max(1, int(getattr(pool, "_max_workers", 0) or (os.cpu_count() or 1)))
        self.threads_per_piece = _share(self.workers)
        # Threads of this process can be told to stop; another process's cannot (an Event does not pickle).
        self.stop = threading.Event() if isinstance(pool, cf.ThreadPoolExecutor) else None
        self._watch_exit()

    def check_sendable(self, obj, what: str) -> None:
        """Refuse at once (ValueError) an ``obj`` that another process's pool could not receive.

        A process pool pickles each piece in a feeder thread: an object that does not pickle (a
        CustomPotential of lambdas) would fail there, one piece at a time, after the pool started.
        """
        if self.stop is None:  # not threads of this process: the pieces are pickled
            from multiprocessing.reduction import ForkingPickler

            _sendable(ForkingPickler.dumps, obj, what, self.name)

    def close(self):
        if self.stop is not None and self.stop.is_set():
            # Ctrl-C or a failed piece: wait for the pieces that were running (they stop within
            # ~0.1 s), so none is left computing behind the caller's back; the pool stays open.
            cf.wait(self.left)


class _Dask:
    """A distributed.Client (given, or on a LocalCluster / scheduler address made here)."""

    name = "a Dask cluster"

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

    def check_sendable(self, obj, what: str) -> None:
        """Refuse at once (ValueError) an ``obj`` Dask could not send to its workers (cloudpickle)."""
        try:
            import cloudpickle

            dumps = cloudpickle.dumps
        except ImportError:  # pragma: no cover - distributed depends on cloudpickle
            import pickle

            dumps = pickle.dumps
        _sendable(dumps, obj, what, self.name)

    def close(self):
        if self.own:
            self.client.close()
            if self.cluster is not None:
                self.cluster.close()


def _sendable(dumps: Callable, obj, what: str, where: str) -> None:
    """``dumps(obj)``, or a ValueError naming what cannot be sent to ``where`` and why."""
    try:
        dumps(obj)
    except Exception as e:  # PicklingError, TypeError, AttributeError: whatever the pickler raises
        raise ValueError(
            f"{what} cannot be sent to {where}: it does not pickle ({type(e).__name__}: {str(e)[:300]}); "
            "use executor=<number of threads> (threads of this process need no pickling), or define "
            "the potential's V and dV at module level"
        ) from None


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
        Local workers (>= 1): a pool of that many threads of this process, or with ``dask`` a Dask
        LocalCluster of that many single-threaded worker processes.
    client : distributed.Client, optional
        An existing Dask client (its cluster runs the pieces; not closed here).
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:8786``).
    dask : bool, optional
        With ``workers``: a Dask LocalCluster instead of local threads.
    pool : concurrent.futures.Executor, optional
        The caller's pool (used, not shut down).

    Yields
    ------
    object
        ``submit(fn, *args)``, ``as_completed(futures)``, ``cancel(futures)``,
        ``check_sendable(obj, what)`` (a ValueError, before any piece is submitted, for an object
        the workers could not receive: it does not pickle for a process pool or Dask), ``workers``,
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
    n = 0
    try:
        # Submitting is inside the try: a Ctrl-C that lands while the pieces are handed out must
        # stop the ones already running too. Else they never saw the stop event and the executor's
        # close() waited for each to finish in full (hours for a long run: the interrupt "never
        # landed").
        for i, args in enumerate(pieces):
            futures[ex.submit(fn, *args)] = i
        n = len(futures)
        _log.info(
            "%d pieces of %s on %s (%d workers)",
            n,
            getattr(fn, "__qualname__", fn),
            getattr(ex, "name", type(ex).__name__),
            ex.workers,
        )
        for f in ex.as_completed(list(futures)):
            i = futures.pop(f)
            res = f.result()
            if on_result is not None:
                on_result(i, res)
            _log.debug("piece %d done (%d of %d)", i, n - len(futures), n)
            yield i, res
    except BaseException as e:
        if futures:
            n = n or len(futures)
            _log.info("%s: %d of %d pieces not finished, cancelled", type(e).__name__, len(futures), n)
        ex.cancel(list(futures))
        raise
