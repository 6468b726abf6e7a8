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
than :data:`hovering._io.untrusted.MAX_TREE_DEPTH` is damaged, and a row is used only after its
user's check (:meth:`Checkpoint.get`, ``check``) has passed.
"""

from __future__ import annotations

import fcntl
import json
import math
import os
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

from .._io import untrusted as _untrusted
from .._io.output import write_error
from .._io.provenance import provenance

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


# ------------------------------------------------------------------------------------------------
# Reading one line: every refusal names the field (the path to the value, as ``key.map.eps`` or
# ``row.outcomes[2]``), so that a person can find it in the file.

#: Integers a checkpoint holds: 64-bit ones (hovering_sweep's reader has no wider ones, and no
#: key or row needs them), i.e. in [-2**63, 2**64 - 1].
INT_RANGE = (-(2**63), 2**64 - 1)
#: Longest field path a message shows (a deep one is cut in the middle).
_MAX_FIELD = 120

# The tokens that move the path (strings, brackets, colons, and runs of values ending in commas).
_TOKENS = re.compile(r'"(?:[^"\\]|\\.)*"|[\[\]{}:]|(?:[^"\[\]{},:]*,)+')
# What can make a value the reader refuses, once parsed: 19 digits or more (an integer beyond 64
# bits, or a mantissa beyond a double's range), an exponent of three digits (beyond a double), an
# escape of a UTF-16 surrogate (a lone one is no Unicode text).
_SUSPECT = re.compile(r"[0-9]{19}|[eE][+-]?0*[1-9][0-9]{2}|\\u[dD][89a-fA-F]")
# A run of digits Python may refuse to convert (its int_max_str_digits is at least 640).
_LONG_NUMBER = re.compile(r"-?[0-9]{640,}")


class _Bad:
    """A value the reader refuses, left in the parsed tree by a parse hook, so that the walk that
    finds it names its field (``sub``: a name to append, for a repeated one)."""

    __slots__ = ("why", "sub")

    def __init__(self, why: str, sub: str | None = None):
        self.why, self.sub = why, sub


def _join(at: str, name: str) -> str:
    return f"{at}.{name[:40]}" if at else name[:40]


def _field(at: str) -> str:
    """A field path as a message shows it: ``the line`` for the line itself, long ones cut."""
    if not at:
        return "the line"
    return at if len(at) <= _MAX_FIELD else at[: _MAX_FIELD // 2] + " ... " + at[-_MAX_FIELD // 2 :]


def _path_at(text: str, end: int, depth_limit: int | None = None) -> tuple:
    """``(field, position)``: the path to the value being read at character ``end`` of a JSON
    line, found by following its structure (strings skipped; linear time). With ``depth_limit``,
    it stops at the first bracket that opens one level more, and returns that bracket's path and
    position instead (the place where a line nests too deeply)."""
    stack: list = []  # per open container: [is_object, key or index, expecting a key]
    for m in _TOKENS.finditer(text, 0, end):
        t = m.group()
        c = t[0]
        if c == '"':
            if stack and stack[-1][0] and stack[-1][2]:
                try:
                    stack[-1][1] = json.loads(t)
                except ValueError:
                    stack[-1][1] = t[1:-1]
                stack[-1][2] = False
        elif c in "{[":
            stack.append([c == "{", None if c == "{" else 0, c == "{"])
            if depth_limit is not None and len(stack) > depth_limit:
                return _stack_path(stack[:-1]), m.start()
        elif c in "}]":
            if stack:
                stack.pop()
        elif c != ":":  # values ending in commas
            if stack:
                f = stack[-1]
                if f[0]:
                    f[1], f[2] = None, True
                else:
                    f[1] += t.count(",")
    return _stack_path(stack), end


def _stack_path(stack: list) -> str:
    at = ""
    for is_object, k, _ in stack:
        if is_object:
            if k is None:
                break
            at = _join(at, str(k))
        else:
            at = f"{at}[{k}]"
    return at


def _parse_line(raw: bytes) -> Any:
    """The JSON value of one checkpoint line, or a ValueError naming the field and what is wrong.

    Refused: bytes that are not UTF-8, nesting deeper than
    :data:`hovering._io.untrusted.MAX_TREE_DEPTH`, a syntax error, the tokens ``NaN`` / ``Infinity``,
    a number beyond a double, an integer beyond 64 bits (:data:`INT_RANGE`), a name twice in one
    object, a lone UTF-16 surrogate in a string. The same lines ``hovering_sweep`` refuses.
    The parser runs at C speed (hooks only where they cost nothing); the tree is walked only when
    the text holds what could be refused.
    """
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        before = raw[: e.start].decode("utf-8", "replace")
        raise ValueError(
            f"not a line of JSON: invalid UTF-8 at byte {e.start + 1}, in {_field(_path_at(before, len(before))[0])}"
        ) from None
    if _untrusted.json_nesting(text) > _untrusted.MAX_TREE_DEPTH:
        at, pos = _path_at(text, len(text), _untrusted.MAX_TREE_DEPTH)
        raise ValueError(
            f"not a line of JSON: nested deeper than {_untrusted.MAX_TREE_DEPTH} levels, at character {pos + 1}, "
            f"in {_field(at)}"
        )
    bad: list = []

    def constant(name: str):
        bad.append(1)
        return _Bad(f'the token {name} is not a JSON number (a non-finite number is written as the string "{name}")')

    def obj(pairs: list):
        d = dict(pairs)
        if len(d) == len(pairs):
            return d
        seen: set = set()
        name = next(k for k, _ in pairs if k in seen or seen.add(k))
        bad.append(1)
        return _Bad(f"the name {name[:40]!r} twice in one object", sub=name)

    try:
        rec = json.loads(text, parse_constant=constant, object_pairs_hook=obj)
    except json.JSONDecodeError as e:
        msg = e.msg[:-3] if e.msg.endswith(" at") else e.msg  # "Invalid control character at"
        raise ValueError(
            f"not a line of JSON: {msg} at character {e.pos + 1}, in {_field(_path_at(text, e.pos)[0])}"
        ) from None
    except ValueError:  # an integer of more digits than Python converts (int_max_str_digits)
        m = _LONG_NUMBER.search(text)
        pos = m.start() if m else len(text)
        raise ValueError(
            f"{_field(_path_at(text, pos)[0])}: an integer of {len(m.group()) if m else 'too many'} digits, "
            "beyond 64 bits"
        ) from None
    except RecursionError:  # the nesting is checked first; kept for a text the check misjudged
        raise ValueError(f"not a line of JSON: nested deeper than {_untrusted.MAX_TREE_DEPTH} levels") from None
    # Only a number of 19 digits or more, or an exponent of 3, can be beyond 64 bits or a double, and
    # only a \\uD8xx escape can make a lone surrogate: the tree is walked only then (or if a hook
    # left a refusal in it).
    if bad or _SUSPECT.search(text):
        _refuse_bad(rec)
    return rec


def _refuse_bad(rec: Any) -> None:
    """Raise a ValueError naming the first field that holds a refused value (a :class:`_Bad`, or a
    string or name with a lone surrogate)."""
    stack = [(rec, "")]
    while stack:
        node, at = stack.pop()
        if isinstance(node, _Bad):
            raise ValueError(f"{_field(_join(at, node.sub) if node.sub is not None else at)}: {node.why}")
        if type(node) is float and not math.isfinite(node):  # JSON has no inf: a number that overflowed
            raise ValueError(f"{_field(at)}: a number beyond the range of a double (it reads as {node})")
        if type(node) is int and not INT_RANGE[0] <= node <= INT_RANGE[1]:
            what = (
                f"the integer {_clip(node)}" if node.bit_length() < 256 else f"an integer of {node.bit_length()} bits"
            )
            raise ValueError(f"{_field(at)}: {what} is beyond 64 bits")
        if isinstance(node, str):
            _unicode(node, at)
        elif isinstance(node, dict):
            for k, v in node.items():
                _unicode(k, _join(at, k))
                stack.append((v, _join(at, k)))
        elif isinstance(node, list):
            stack.extend((v, f"{at}[{i}]") for i, v in enumerate(node))


def _unicode(s: str, at: str) -> None:
    if not s.isascii():
        try:
            s.encode("utf-8")
        except UnicodeEncodeError as e:
            raise ValueError(
                f"{_field(at)}: a lone surrogate \\u{ord(s[e.start]):04x} (character {e.start + 1} of the "
                "string), which is not Unicode text"
            ) from None


def _header_line() -> bytes:
    """The header line, as both programs write it (without its newline)."""
    return _dumps({"format": FORMAT, "version": VERSION}).encode()


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
        For a file that is not a checkpoint of this format (naming the file, the line and the
        field: see :func:`_parse_line` for what a line may not hold), too big for this machine, or
        not a regular file. A file without a complete line is cut (a torn write) only when it is a
        piece of the header; else it is another program's, refused untouched.
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
        if end < len(data) and cut and self._offset + end == 0 and not _header_line().startswith(data):
            # No complete line, and not a piece of the header (a run writes its header, provenance
            # and first point at once): another program's file of one line without its newline,
            # which must not be cut to nothing.
            self._lines = 1
            raise self._damaged(
                f"the first line is not the header {_header_line().decode()}: another program's file (one line "
                f"of {len(data)} bytes without its newline)"
            )
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
            rec = _parse_line(raw)
        except ValueError as e:
            raise self._damaged(str(e)) from None
        if not isinstance(rec, dict):
            raise self._damaged(f"not a JSON object: the line is {_kind(rec)}")
        if self._lines == 1:
            if set(rec) != {"format", "version"} or rec.get("format") != FORMAT:
                old = "key" in rec and "row" in rec
                fields = ", ".join(repr(k[:40]) for k in list(rec)[:8])
                raise self._damaged(
                    "a checkpoint of an older hovering (no format header): its points were keyed otherwise and "
                    "cannot be reused"
                    if old
                    else f'the first line is not the header {{"format":"{FORMAT}","version":{VERSION}}}: another '
                    f"program's file (fields: {fields or 'none'}"
                    + (f"; format = {_clip(rec['format'])}" if "format" in rec else "")
                    + ")"
                )
            if not (type(rec["version"]) is int and rec["version"] == VERSION):
                raise self._damaged(
                    f"a checkpoint of version {_clip(rec['version'])} (its header's 'version'); this hovering reads "
                    f"version {VERSION}"
                )
            return
        if "provenance" in rec:
            if set(rec) != {"provenance"}:
                raise self._damaged(f"a provenance record with other fields: {_names(set(rec) - {'provenance'})}")
            if not isinstance(rec["provenance"], dict):
                raise self._damaged(f"provenance must be an object, got {_kind(rec['provenance'])}")
            return
        if "key" in rec or "row" in rec:
            for name in ("key", "row"):
                if name not in rec:
                    raise self._damaged(f"a point without its {name!r} field")
                if not isinstance(rec[name], dict):
                    raise self._damaged(f"{name} must be an object, got {_kind(rec[name])}")
            if set(rec) != {"key", "row"}:
                raise self._damaged(f"a point with other fields: {_names(set(rec) - {'key', 'row'})}")
            k = canonical(rec["key"])
            if k not in self._rows:  # the first line of a point wins (a later one cannot differ but in timing)
                self._rows[k], self._line[k] = rec["row"], self._lines
            return
        raise self._damaged(
            'neither a point {"key": {...}, "row": {...}} nor a provenance record {"provenance": {...}}: '
            f"fields {_names(rec) or 'none'}"
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
        hovering._io.output.WriteError
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
                lines.append(_header_line().decode())
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


def _kind(value) -> str:
    """What a JSON value is, for a message: its type and, clipped, the value."""
    name = {dict: "an object", list: "an array", str: "a string", bool: "a boolean", type(None): "null"}.get(
        type(value), "a number"
    )
    return f"{name} {_clip(value)}" if not isinstance(value, (dict, list)) else name


def _names(names) -> str:
    return ", ".join(repr(k[:40]) for k in sorted(names)[:8]) + (", ..." if len(names) > 8 else "")


def _clip(value) -> str:
    r = (
        repr(value)
        if not isinstance(value, int) or value.bit_length() < 256
        else f"an integer of {value.bit_length()} bits"
    )
    return r if len(r) <= 60 else r[:57] + "..."
