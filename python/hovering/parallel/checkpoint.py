"""Checkpoints: every finished point of a sweep on disk at once, shared by Python and hovering_sweep.

One format (docs/sweep-plan.md), which ``hovering_sweep`` (C++) reads and writes too, so either
program resumes what the other began. A checkpoint is a file of JSON lines:

* the header, first: ``{"format":"hovering-checkpoint","version":1}``;
* provenance lines ``{"provenance":{...}}``: what wrote the points after it (:func:`hovering.show_versions`'
  record, or the core's build facts for hovering_sweep, with the program's name);
* one line ``{"key":{...},"row":{...}}`` per finished point.

A key is the canonical record of the point's parameters (a plan point's fields, or a piece of
:func:`hovering.hovering_area`): keys are compared as parsed values, never as text, so two programs
need not print numbers alike. Numbers are JSON numbers; one that is not finite is written as the
string ``"NaN"``, ``"Infinity"`` or ``"-Infinity"`` (JSON has no such numbers) and read back as
that float.

Each line is appended under an exclusive ``flock`` on the file and fsync'd before the sweep moves
on, so an interruption (Ctrl-C, a killed job, a full disk) loses at most the point being computed.
Lines another process appended meanwhile are read first, under the same lock, and a point it
finished is not written again: two runs sharing a file never duplicate a point. A last line
without its newline (a writer killed mid-line) is cut off and its point recomputed; any other line
that is not one of these records, or a file whose first line is not the header (another program's
file, or a checkpoint of an older hovering), is refused untouched with a ValueError naming the file
and the line.

A checkpoint is read as untrusted input (docs/threat-model.md): it must be a regular file whose
parsed size (estimated from its text) fits in half of this machine's memory, a line nested deeper
than :data:`hovering._untrusted.MAX_TREE_DEPTH` is damaged, and a row is used only after its
user's check (:meth:`Checkpoint.get`, ``check``) has passed.
"""

from __future__ import annotations

import fcntl
import json
import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from .. import _untrusted
from .._output import write_error
from .._provenance import provenance

__all__ = ["FORMAT", "VERSION", "Checkpoint", "check_row", "canonical", "encode"]

#: The header's ``format`` and ``version``: what this reader takes.
FORMAT = "hovering-checkpoint"
VERSION = 1

_NONFINITE = {"NaN": math.nan, "Infinity": math.inf, "-Infinity": -math.inf}


def encode(value: Any) -> Any:
    """``value`` with every non-finite float replaced by its string (``"NaN"``, ``"Infinity"``,
    ``"-Infinity"``), tuples as lists: what a checkpoint line holds.

    Parameters
    ----------
    value : JSON-able
        Numbers, strings, booleans, None, lists, tuples and dicts with string keys.

    Returns
    -------
    object
    """
    if isinstance(value, float) and not math.isfinite(value):
        return "NaN" if math.isnan(value) else "Infinity" if value > 0 else "-Infinity"
    if isinstance(value, dict):
        return {k: encode(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [encode(v) for v in value]
    return value


def _decode(value: Any) -> Any:
    if isinstance(value, str):
        return _NONFINITE.get(value, value)
    if isinstance(value, dict):
        return {k: _decode(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_decode(v) for v in value]
    return value


def _dumps(value: Any) -> str:
    return json.dumps(encode(value), sort_keys=True, separators=(",", ":"), allow_nan=False, ensure_ascii=False)


def canonical(key: Any) -> str:
    """The canonical text of a key: sorted keys, compact, numbers as Python prints them.

    Keys read from a file are parsed first, so two keys are equal exactly when their values are,
    whichever program printed them.

    Parameters
    ----------
    key : JSON-able
        A key as built (floats) or as read (non-finite numbers as their strings).

    Returns
    -------
    str
    """
    return _dumps(key)


def _reject_constant(name: str):
    raise ValueError(f'the number {name} is not JSON (a non-finite number is written as the string "{name}")')


class Checkpoint:
    """A checkpoint file: finished points by key (see the module docstring).

    Parameters
    ----------
    path : path-like
        The JSON-lines file (created, with its header, on the first :meth:`put`). Opening it reads
        every line under the file's lock: a torn last line is cut off, anything else that is not a
        record of this format is refused.

    Attributes
    ----------
    path : Path
        The file.
    dropped : int
        Torn last lines cut off on opening (0 or 1).

    Raises
    ------
    ValueError
        For a file that is not a checkpoint of this format (naming the file and the line), too big
        for this machine, or not a regular file.
    """

    def __init__(self, path: os.PathLike):
        self.path = Path(path)
        self._rows: dict = {}
        self._line: dict = {}
        self._offset = 0
        self._lines = 0
        self._provenance_written = False
        self.dropped = 0
        if self.path.exists():
            _untrusted.regular_file(str(self.path))
            self._read(cut=True)

    # ------------------------------------------------------------ reading

    def _open(self, write: bool):
        flags = (os.O_RDWR | os.O_APPEND | os.O_CREAT) if write else os.O_RDONLY
        try:
            return os.open(self.path, flags | os.O_CLOEXEC, 0o666)
        except OSError as e:
            if write:
                raise write_error(self.path, e, previous=False) from None
            raise ValueError(f"cannot read {self.path}: {e.strerror or e}") from None

    def _read(self, cut: bool) -> None:
        """Read the lines appended since the last read (exclusive lock when ``cut``: a torn tail is
        cut off; else shared). A file this process may only read is read under a shared lock."""
        try:
            fd = self._open(write=cut)
        except ValueError:
            if not cut:
                raise
            fd, cut = self._open(write=False), False  # read-only: read, never cut
        try:
            fcntl.flock(fd, fcntl.LOCK_EX if cut else fcntl.LOCK_SH)
            self._scan(fd, cut)
        finally:
            os.close(fd)

    def _check_size(self, nbytes: int, need: int) -> None:
        budget = _untrusted.memory_budget()
        if need > budget:
            raise ValueError(
                f"{self.path}: a checkpoint of {nbytes} bytes, whose rows would take up to "
                f"{need / 2**30:.3g} GiB, more than half of this machine's memory "
                f"({2 * budget / 2**30:.3g} GiB)"
            )

    def _scan(self, fd: int, cut: bool) -> None:
        size = os.fstat(fd).st_size
        # Checked before the text is read, then before it is parsed (see _untrusted.json_cost).
        self._check_size(size, _untrusted.json_cost(b"") + 6 * size)
        if size <= self._offset:
            return
        data = os.pread(fd, size - self._offset, self._offset)
        self._check_size(size, _untrusted.json_cost(data))
        end = data.rfind(b"\n") + 1
        if end < len(data) and cut:
            # Killed mid-write: the last line is incomplete. Cut it off, or the next line would be
            # glued onto it and both points lost.
            os.ftruncate(fd, self._offset + end)
            os.fsync(fd)
            self.dropped += 1
        for raw in data[:end].split(b"\n")[:-1]:
            self._lines += 1
            self._take(raw)
            self._offset += len(raw) + 1

    def _damaged(self, why: str) -> ValueError:
        if self._lines == 1:
            return ValueError(f"{self.path} line 1: {why}; use another checkpoint file, or move this one away")
        return ValueError(
            f"{self.path} line {self._lines}: {why}: the file was edited or damaged; fix or remove "
            "that line (its point is recomputed), or use another checkpoint file"
        )

    def _take(self, raw: bytes) -> None:
        try:
            text = raw.decode("utf-8")
            if _untrusted.json_nesting(text) > _untrusted.MAX_TREE_DEPTH:
                raise ValueError(f"nested deeper than {_untrusted.MAX_TREE_DEPTH}")
            rec = json.loads(text, parse_constant=_reject_constant)
        except (ValueError, RecursionError) as e:
            raise self._damaged(f"not a line of JSON ({str(e)[:80]})") from None
        if not isinstance(rec, dict):
            raise self._damaged("not a JSON object")
        if self._lines == 1:
            if set(rec) != {"format", "version"} or rec.get("format") != FORMAT:
                old = "key" in rec and "row" in rec
                raise self._damaged(
                    "a checkpoint of an older hovering (no format header): its points were keyed otherwise and "
                    "cannot be reused"
                    if old
                    else f'the first line is not the header {{"format":"{FORMAT}","version":{VERSION}}}: another '
                    "program's file"
                )
            if not (type(rec["version"]) is int and rec["version"] == VERSION):
                raise self._damaged(
                    f"a checkpoint of version {rec['version']!r}; this hovering reads version {VERSION}"
                )
            return
        if set(rec) == {"provenance"} and isinstance(rec["provenance"], dict):
            return
        if set(rec) == {"key", "row"} and isinstance(rec["key"], dict) and isinstance(rec["row"], dict):
            k = canonical(rec["key"])
            if k not in self._rows:  # the first line of a point wins (a later one cannot differ but in timing)
                self._rows[k], self._line[k] = rec["row"], self._lines
            return
        raise self._damaged(
            'neither a point {"key": {...}, "row": {...}} nor a provenance record {"provenance": {...}}'
        )

    def refresh(self) -> None:
        """Read the lines other processes appended since the last look (under a shared lock)."""
        if self.path.exists():
            self._read(cut=False)

    def __len__(self) -> int:
        return len(self._rows)

    def __contains__(self, key: Any) -> bool:
        return canonical(key) in self._rows

    def get(self, key: Any, check: Callable | None = None) -> Any | None:
        """The stored row for ``key`` (non-finite numbers as floats again), or None.

        Parameters
        ----------
        key : JSON-serialisable
            The point's parameters.
        check : callable, optional
            ``check(row)`` raises a ValueError naming the field of a row its user cannot take (the
            file is untrusted); the error then also names the file and the line.

        Returns
        -------
        object or None

        Raises
        ------
        ValueError
            If ``check`` refuses the row.
        """
        k = canonical(key)
        row = self._rows.get(k)
        if row is None:
            return None
        row = _decode(row)
        if check is not None:
            try:
                check(row)
            except ValueError as e:
                raise ValueError(
                    f"{self.path} line {self._line.get(k, '?')}: {e} (the file was edited or damaged: "
                    "remove that line to recompute the point)"
                ) from None
        return row

    # ------------------------------------------------------------ writing

    def put(self, key: Any, row: Any, threads: int | None = None) -> bool:
        """Store a finished point durably (locked append, fsync) before returning.

        Lines appended by others since the last read are read first, under the same lock: if one
        of them holds this key, nothing is written (the point is not duplicated).

        Parameters
        ----------
        key : JSON-serialisable
            The point's parameters.
        row : JSON-serialisable
            Its result.
        threads : int, optional
            Core threads of the run, for the provenance line.

        Returns
        -------
        bool
            Whether this call wrote the point (False: another process had).

        Raises
        ------
        hovering._output.WriteError
            (a ValueError) When the line cannot be written (e.g. ``no space left``); the file is
            left as it was.
        """
        k = canonical(key)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd = self._open(write=True)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)
            self._scan(fd, cut=True)
            if k in self._rows:
                return False
            lines = []
            if self._lines == 0:
                lines.append(_dumps({"format": FORMAT, "version": VERSION}))
            if not self._provenance_written:
                lines.append(_dumps({"provenance": dict(provenance(threads=threads), program="python")}))
            lines.append('{"key":' + k + ',"row":' + _dumps(row) + "}")
            data = ("\n".join(lines) + "\n").encode("utf-8")
            size = os.fstat(fd).st_size
            try:
                view = memoryview(data)
                while view:
                    view = view[os.write(fd, view) :]
                os.fsync(fd)
            except OSError:
                try:
                    os.ftruncate(fd, size)  # no half line left behind
                except OSError:
                    pass
                raise
        except OSError as e:
            raise write_error(self.path, e, previous=False) from None
        finally:
            os.close(fd)
        self._provenance_written = True
        self._rows[k] = json.loads(_dumps(row))
        self._lines += len(lines)
        self._line[k] = self._lines
        self._offset += len(data)
        return True


def check_row(row, fields: dict, where: str = "row") -> None:
    """Check a checkpoint row against the fields its user reads.

    Parameters
    ----------
    row : object
        The row as read.
    fields : dict
        Field name -> ``float`` (a real number: int or float, NaN and infinities included, not a
        bool), ``int`` (an integer, not a bool), ``bool``, or a dict (a nested row of these fields)
        or a tuple ``(names, dict)`` (a mapping whose keys include ``names``, each value such a
        nested row).
    where : str, optional
        The row's name, for the messages.

    Raises
    ------
    ValueError
        Naming the first field that is missing or of another type.
    """
    if not isinstance(row, dict):
        raise ValueError(f"{where} must be a mapping, got {type(row).__name__}")
    for name, kind in fields.items():
        at = f"{where}.{name}"
        if name not in row:
            raise ValueError(f"{at} is missing")
        v = row[name]
        if kind is float:
            if isinstance(v, bool) or not isinstance(v, (int, float)) or (isinstance(v, int) and v.bit_length() > 1023):
                raise ValueError(f"{at} must be a number (within the range of a double), got {_clip(v)}")
        elif kind is int:
            if isinstance(v, bool) or not isinstance(v, int) or v.bit_length() > 63:
                raise ValueError(f"{at} must be an integer, got {_clip(v)}")
        elif kind is bool:
            if not isinstance(v, bool):
                raise ValueError(f"{at} must be true or false, got {_clip(v)}")
        elif isinstance(kind, tuple):
            names, sub = kind
            if not isinstance(v, dict):
                raise ValueError(f"{at} must be a mapping, got {type(v).__name__}")
            for m in names:
                check_row(v.get(m), sub, f"{at}.{m}")
        else:
            check_row(v, kind, at)


def _clip(value) -> str:
    r = (
        repr(value)
        if not isinstance(value, int) or value.bit_length() < 256
        else f"an integer of {value.bit_length()} bits"
    )
    return r if len(r) <= 60 else r[:57] + "..."
