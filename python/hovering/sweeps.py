"""Checkpointed sweeps: every finished point is on disk at once, an interrupted sweep resumes.

A :class:`Checkpoint` is an append-only JSON-lines file. Each finished sweep point is one line
``{"key": ..., "provenance": ..., "row": ...}`` (provenance: what computed that row, see
:func:`hovering.show_versions`; files without it read the same), appended under an exclusive lock
on the file and fsync'd before the sweep moves on, so an interruption (Ctrl-C, a killed job, a full
disk) loses at most the point being computed and two processes sharing a file never mix their
lines. A rerun with the same file skips every point whose key (all parameters that determine the
result) is already there.

A checkpoint is read as untrusted input (docs/threat-model.md): it must be a regular file whose
parsed size (estimated from its text) fits in half of this machine's memory, a line nested deeper
than :data:`hovering._untrusted.MAX_TREE_DEPTH` is damaged, and a row is used only after its
user's check (:meth:`Checkpoint.get`, ``check``) has passed.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, Callable, Optional

from . import _untrusted
from ._output import append_line, locked
from ._provenance import provenance

__all__ = ["Checkpoint", "check_row"]


def _canonical(key: Any) -> str:
    return json.dumps(key, sort_keys=True, separators=(",", ":"), allow_nan=True)


class Checkpoint:
    """Append-only store of finished sweep points, keyed by their parameters.

    Parameters
    ----------
    path : path-like
        The JSON-lines file (created on the first :meth:`put`). A last line cut short by an
        interruption (no final newline) is removed from the file, and any line that is not a
        complete record is ignored: their points are recomputed.

    Attributes
    ----------
    dropped : int
        How many torn or damaged lines were found on opening.
    """

    def __init__(self, path: os.PathLike):
        self.path = Path(path)
        self._rows: dict = {}
        self._line: dict = {}
        self.dropped = 0
        if self.path.exists():
            # Untrusted: a regular file (a FIFO or a device would be read forever), whose text and
            # the rows parsed from it fit in the memory budget, checked before it is read and then
            # before it is parsed (see _untrusted.json_cost).
            budget = _untrusted.memory_budget()
            size = _untrusted.regular_file(str(self.path))
            self._check_size(size, _untrusted.json_cost(b"") + 6 * size, budget)
            # Under the appenders' lock: a line another process is writing is not mistaken for a
            # torn one and cut.
            with locked(self.path) as f:
                data = f.read()
                self._check_size(len(data), _untrusted.json_cost(data), budget)
                if data and not data.endswith(b"\n"):
                    # Killed mid-write: the last line is incomplete. Cut it off, or the next put()
                    # would be glued onto it and both points lost.
                    keep = data.rfind(b"\n") + 1
                    f.truncate(keep)
                    f.flush()
                    os.fsync(f.fileno())
                    data = data[:keep]
                    self.dropped += 1
            for n, line in enumerate(data.decode("utf-8", errors="replace").splitlines(), 1):
                try:
                    if _untrusted.json_nesting(line) > _untrusted.MAX_TREE_DEPTH:
                        raise ValueError("nested too deeply")
                    rec = json.loads(line)
                    k = _canonical(rec["key"])
                    self._rows[k], self._line[k] = rec["row"], n
                except (ValueError, KeyError, TypeError, RecursionError):
                    self.dropped += 1  # a damaged line: its point is recomputed

    def _check_size(self, nbytes: int, need: int, budget: int) -> None:
        if need > budget:
            raise ValueError(f"{self.path}: a checkpoint of {nbytes} bytes, whose rows would take up to "
                             f"{need / 2**30:.3g} GiB, more than half of this machine's memory "
                             f"({2 * budget / 2**30:.3g} GiB)")

    def __len__(self) -> int:
        return len(self._rows)

    def get(self, key: Any, check: Optional[Callable] = None) -> Optional[Any]:
        """The stored row for ``key``, or None.

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
        k = _canonical(key)
        row = self._rows.get(k)
        if row is not None and check is not None:
            try:
                check(row)
            except ValueError as e:
                raise ValueError(f"{self.path} line {self._line.get(k, '?')}: {e} (the file was edited or damaged: "
                                 "remove that line to recompute the point)") from None
        return row

    def put(self, key: Any, row: Any) -> None:
        """Store a finished point durably (locked append, flush + fsync) before returning.

        Parameters
        ----------
        key : JSON-serialisable
            The point's parameters (its ``seed``, if it is a dict with one, goes into the record's
            provenance too).
        row : JSON-serialisable
            Its result.

        Raises
        ------
        hovering._output.WriteError
            (a ValueError) When the line cannot be written (e.g. ``no space left``); the file is
            left as it was.
        """
        self.path.parent.mkdir(parents=True, exist_ok=True)
        seed = key.get("seed") if isinstance(key, dict) else None
        prov = provenance(seed=seed if isinstance(seed, int) and not isinstance(seed, bool) else None)
        # sort_keys: "key" comes first, which is how a scene run recognises the file as a checkpoint
        line = json.dumps({"key": key, "provenance": prov, "row": row}, sort_keys=True, allow_nan=True)
        append_line(self.path, line)
        self._rows[_canonical(key)] = row


def check_row(row, fields: dict, where: str = "row") -> None:
    """Check a checkpoint row against the fields its user reads.

    Parameters
    ----------
    row : object
        The row as read.
    fields : dict
        Field name -> ``float`` (a real number: int or float, NaN and infinities included, not a
        bool), ``bool``, or a dict (a nested row of these fields) or a tuple ``(names, dict)`` (a
        mapping whose keys include ``names``, each value such a nested row).
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
    r = repr(value) if not isinstance(value, int) or value.bit_length() < 256 else f"an integer of {value.bit_length()} bits"
    return r if len(r) <= 60 else r[:57] + "..."
