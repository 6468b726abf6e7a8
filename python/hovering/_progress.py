"""Progress reporting: the ``progress`` argument of long calls, turned into a reporter.

Every long computation (``iterate`` of both models, :meth:`hovering.Section.return_map`,
:func:`hovering.hovering_area`, :func:`hovering.critical_curve`) takes ``progress``:

* ``False`` (default): no reporting, and no cost;
* ``True``: a `tqdm <https://tqdm.github.io>`_ bar (``tqdm.auto``: a widget in Jupyter, text on
  stderr elsewhere) when tqdm is installed (``hovering[progress]``), else a plain-text line on
  stderr every few seconds;
* a callable ``progress(done, total)``: called with the work done so far (non-decreasing) and
  the total it ends at, every ~0.1 s and once at the end (``done == total`` unless interrupted).

The compiled core counts its work (steps or returns) in an atomic counter, and the thread waiting
for it calls the callback with the GIL. Code that runs several core calls under one bar (the
analyses, sweeps, scenes) opens a :func:`progress_bar` for the whole and hands each call a
:meth:`Progress.part`, which reports that call's work at an offset::

    with progress_bar(progress, total=2 * n * N, desc="hovering_area", unit="step") as bar:
        m0.iterate(..., progress=bar.part(0))        # reports 0 .. n N
        m.iterate(..., progress=bar.part(n * N))     # reports n N .. 2 n N

A :class:`Progress` is also callable with an absolute value (``bar(done)``) and has
:meth:`Progress.advance` for increments, :meth:`Progress.set_total` for a total learnt on the
way. The bar is closed when the ``with`` block ends, also by an exception (KeyboardInterrupt).

Ctrl-C reaches only Python's main thread. A piece of a parallel run that runs on another thread
(:mod:`hovering.parallel.executor`) is stopped through the same callback instead: inside
:func:`stoppable`, every core call's reporter (also a disabled one) raises KeyboardInterrupt once
the run's stop event is set, and the core ends its orbits as it does on Ctrl-C.
"""

from __future__ import annotations

import contextlib
import sys
import threading
import time
from collections.abc import Callable, Iterator

import numpy as np

__all__ = ["Progress", "progress_bar", "check_progress", "ProgressArg", "stoppable", "stop_hook", "TextBar"]

#: What a ``progress`` argument may be.
ProgressArg = bool | Callable[[int, int], object]


def check_progress(value, name: str = "progress"):
    """The ``progress`` argument, validated: ``True``, ``False`` or a callable ``(done, total)``.

    Parameters
    ----------
    value : object
        What was passed.
    name : str, optional
        The parameter's name (for the message).

    Returns
    -------
    bool or callable
        ``value`` (a NumPy bool as a bool).

    Raises
    ------
    ValueError
        Naming the parameter and what it may be.
    """
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if callable(value):
        return value
    r = repr(value)
    r = r if len(r) <= 60 else r[:57] + "..."
    raise ValueError(
        f"{name} must be True (a progress bar on stderr), False (none) or a callable progress(done, total), got {r}"
    )


_piece = threading.local()  # .stop: the stop event of the piece this thread runs, if any


@contextlib.contextmanager
def stoppable(stop: threading.Event) -> Iterator[None]:
    """Make the core calls of this thread stop (KeyboardInterrupt) once ``stop`` is set.

    Parameters
    ----------
    stop : threading.Event
        Set by whoever runs the pieces (on Ctrl-C in the main thread, or a failed piece).
    """
    before = getattr(_piece, "stop", None)
    _piece.stop = stop
    try:
        yield
    finally:
        _piece.stop = before


def stop_hook():
    """The ``progress`` callback a core call needs to be stoppable from another thread.

    Returns
    -------
    callable or None
        Inside :func:`stoppable`: ``f(done, total)`` that raises KeyboardInterrupt once the stop
        event is set (the core polls it every ~0.1 s). Elsewhere None: the main thread's core calls
        see Ctrl-C themselves.
    """
    stop = getattr(_piece, "stop", None)
    if stop is None:
        return None

    def check(done, total=None):
        if stop.is_set():
            raise KeyboardInterrupt("stopped: another piece of this run failed or was interrupted")

    return check


class TextBar:
    """The bar of ``progress=True`` without tqdm: one line on stderr at most every ``every`` seconds
    and one at the end (``desc: 42% (4200/10000 steps)``), readable in a log file too.

    Parameters
    ----------
    total : int
        Units of work at 100 %.
    desc : str, optional
        The label.
    unit : str, optional
        The unit's name (singular).
    every : float, optional
        Seconds between lines.
    """

    def __init__(self, total: int, desc: str | None = None, unit: str = "step", every: float = 2.0):
        self.total, self.n, self.desc, self.unit, self.every = int(total), 0, desc or "progress", unit, every
        self._last = time.monotonic()

    def _line(self) -> None:
        pct = 100.0 * self.n / self.total if self.total > 0 else 100.0
        sys.stderr.write(f"{self.desc}: {pct:.0f}% ({self.n}/{self.total} {self.unit}s)\n")
        sys.stderr.flush()

    def update(self, k: int) -> None:
        """Count ``k`` more units; a line if ``every`` seconds have passed since the last one.

        Parameters
        ----------
        k : int
            Units done since the last update.
        """
        self.n += int(k)
        now = time.monotonic()
        if now - self._last >= self.every:
            self._last = now
            self._line()

    def close(self) -> None:
        """The last line (where the work ended)."""
        self._line()


class Progress:
    """What :func:`progress_bar` yields: the reporter of one long call.

    Parameters
    ----------
    sink : callable or None
        ``sink(done, total)``, or None for a disabled reporter (every method is then a no-op and
        :meth:`part` returns False).
    total : int
        Units of work the call ends at.
    """

    def __init__(self, sink: Callable[[int, int], object] | None, total: int):
        self._sink = sink
        self.total = int(total)
        self.done = 0

    @property
    def enabled(self) -> bool:
        """Whether anything is reported."""
        return self._sink is not None

    def __call__(self, done, total=None) -> None:
        """Report ``done`` units of the whole (absolute; a smaller value than before is ignored, a
        larger one than the total raises the total).

        Parameters
        ----------
        done : int
            Work done so far.
        total : int, optional
            A new total (see :meth:`set_total`).
        """
        if total is not None:
            self.total = int(total)
        if self._sink is None:
            return
        done = int(done)
        if done < self.done:
            return
        self.done = done
        self.total = max(self.total, done)  # work beyond the announced total raises it
        self._sink(done, self.total)

    def advance(self, delta: int) -> None:
        """Report ``delta`` more units done.

        Parameters
        ----------
        delta : int
            Units of work finished since the last report.
        """
        self(self.done + int(delta))

    def set_total(self, total: int) -> None:
        """Change the total (when the work turns out larger or smaller than announced).

        Parameters
        ----------
        total : int
            The new total; the sink is told at once (with the work done so far).
        """
        self.total = int(total)
        if self._sink is not None:
            self._sink(min(self.done, self.total), self.total)

    def part(self, offset: int):
        """The ``progress`` argument for a sub-call whose work counts from ``offset`` in the whole.

        Parameters
        ----------
        offset : int
            Units of the whole done before the sub-call starts.

        Returns
        -------
        callable or False
            ``f(done, total)`` reporting ``offset + done`` (the sub-call's own total is ignored),
            or False when this reporter is disabled (so the sub-call does no reporting at all; inside
            :func:`stoppable`, the stop check of :func:`stop_hook` instead).
        """
        if self._sink is None:
            return stop_hook() or False
        offset = int(offset)
        hook = stop_hook()

        def report(done, total=None):
            if hook is not None:
                hook(done)
            self(offset + int(done))

        return report


@contextlib.contextmanager
def progress_bar(progress, total: int, desc: str | None = None, unit: str = "step") -> Iterator[Progress]:
    """A :class:`Progress` for one long call, from the call's ``progress`` argument.

    Parameters
    ----------
    progress : bool or callable
        ``False``: a disabled reporter. ``True``: a bar (tqdm.auto, or :class:`TextBar`) (closed when the block
        ends, also on KeyboardInterrupt). A callable: ``progress(done, total)`` is called.
    total : int
        Units of work the call ends at.
    desc : str, optional
        The bar's label.
    unit : str, optional
        The bar's unit (``"step"``, ``"return"``).

    Yields
    ------
    Progress

    Raises
    ------
    ValueError
        If ``progress`` is neither a bool nor a callable.
    """
    progress = check_progress(progress)
    if progress is False:
        yield Progress(None, total)
        return
    if progress is True:
        try:
            from tqdm.auto import tqdm
        except ImportError:  # tqdm is an extra (hovering[progress]): the plain-text bar then
            bar = TextBar(total=int(total), desc=desc, unit=unit)
        else:
            bar = tqdm(total=int(total), desc=desc, unit=unit, file=sys.stderr, unit_scale=True, dynamic_ncols=True)

        def sink(done, tot):
            if bar.total != tot:
                bar.total = tot
            bar.update(done - bar.n)

        try:
            yield Progress(sink, total)
        finally:
            bar.close()
        return
    yield Progress(progress, total)
