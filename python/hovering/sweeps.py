"""Checkpointed sweeps: every finished point is on disk at once, an interrupted sweep resumes.

A :class:`Checkpoint` is an append-only JSON-lines file. Each finished sweep point is one line
``{"key": ..., "provenance": ..., "row": ...}`` (provenance: what computed that row, see
:func:`hovering.show_versions`; files without it read the same), appended under an exclusive lock
on the file and fsync'd before the sweep moves on, so an interruption (Ctrl-C, a killed job, a full
disk) loses at most the point being computed and two processes sharing a file never mix their
lines. A rerun with the same file skips every point whose key (all parameters that determine the
result) is already there.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, Optional

from ._output import append_line, locked
from ._provenance import provenance

__all__ = ["Checkpoint"]


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
        self.dropped = 0
        if self.path.exists():
            # Under the appenders' lock: a line another process is writing is not mistaken for a
            # torn one and cut.
            with locked(self.path) as f:
                data = f.read()
                if data and not data.endswith(b"\n"):
                    # Killed mid-write: the last line is incomplete. Cut it off, or the next put()
                    # would be glued onto it and both points lost.
                    keep = data.rfind(b"\n") + 1
                    f.truncate(keep)
                    f.flush()
                    os.fsync(f.fileno())
                    data = data[:keep]
                    self.dropped += 1
            for line in data.decode("utf-8", errors="replace").splitlines():
                try:
                    rec = json.loads(line)
                    self._rows[_canonical(rec["key"])] = rec["row"]
                except (ValueError, KeyError, TypeError):
                    self.dropped += 1  # a damaged line: its point is recomputed

    def __len__(self) -> int:
        return len(self._rows)

    def get(self, key: Any) -> Optional[Any]:
        """The stored row for ``key``, or None.

        Parameters
        ----------
        key : JSON-serialisable
            The point's parameters.

        Returns
        -------
        object or None
        """
        return self._rows.get(_canonical(key))

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
