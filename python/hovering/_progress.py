"""Progress reporting: the ``progress`` argument of long calls, turned into a reporter.

Every long computation (``iterate`` of both models, :meth:`hovering.Section.return_map`,
:func:`hovering.hovering_area`, :func:`hovering.critical_curve`) takes ``progress``:

* ``False`` (default): no reporting, and no cost;
* ``True``: a `tqdm <https://tqdm.github.io>`_ bar on stderr;
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
"""

from __future__ import annotations

import contextlib
import sys
from collections.abc import Callable, Iterator

import numpy as np

__all__ = ["Progress", "progress_bar", "check_progress", "ProgressArg"]

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
        f"{name} must be True (a tqdm bar on stderr), False (none) or a callable progress(done, total), got {r}"
    )


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
            or False when this reporter is disabled (so the sub-call does no reporting at all).
        """
        if self._sink is None:
            return False
        offset = int(offset)
        return lambda done, total=None: self(offset + int(done))


@contextlib.contextmanager
def progress_bar(progress, total: int, desc: str | None = None, unit: str = "step") -> Iterator[Progress]:
    """A :class:`Progress` for one long call, from the call's ``progress`` argument.

    Parameters
    ----------
    progress : bool or callable
        ``False``: a disabled reporter. ``True``: a tqdm bar on stderr (closed when the block
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
        from tqdm import tqdm

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
