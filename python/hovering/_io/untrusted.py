"""Reading files from elsewhere: every size a file declares is checked against a stated limit first.

A result (NPZ: a zip archive of ``.npy`` members plus one JSON document, :mod:`hovering._serial`)
or a checkpoint (JSON lines, :mod:`hovering.sweeps`) may come from anyone. What reading one costs
is bounded by the limits below, each checked against what the file *declares* (the zip directory,
a member's uncompressed size, a ``.npy`` header's shape and dtype, the JSON text's length and
nesting) before the data it describes is read or decompressed; a member the JSON tree does not
name is never read. Arrays are read with ``allow_pickle=False``, and only plain dtypes are read at
all. Every refusal is a ValueError naming the file and the entry. The threat model is
docs/threat-model.md.
"""

from __future__ import annotations

import io
import json
import math
import os
import re
import stat
import struct
import tokenize
import zipfile
import zlib

import numpy as np

from .._checks import physical_memory

__all__ = [
    "MAX_TREE_CHARS",
    "MAX_TREE_DEPTH",
    "MAX_STRING_CHARS",
    "MAX_INT_BITS",
    "MAX_MEMBERS",
    "MAX_DIRECTORY_BYTES",
    "MAX_NPY_HEADER",
    "TREE_BYTES_PER_CHAR",
    "memory_budget",
    "regular_file",
    "json_cost",
    "json_nesting",
    "parse_json",
    "safe_member_name",
    "plain_dtype",
    "Archive",
]

#: Longest JSON document read (characters). The largest tree hovering writes is a scene's: 36
#: portrait panels of 10,000 orbits, each with its label, colour and kind (~32 characters), about
#: 12 MB of text; everything bulky is an array (a member of its own), so 64 Mi leave ample room.
MAX_TREE_CHARS = 1 << 26
#: Deepest JSON nesting read (arrays and objects). hovering's own trees are at most ~15 levels deep
#: (measured: 12 for a flow result with its map, its system and their potentials, and for a scene
#: result); the rebuild takes about one Python frame per level, so 100 stays far from Python's
#: recursion limit (1000).
MAX_TREE_DEPTH = 100
#: Longest string (or dict key) in a JSON document. A string there is data (names, labels, paths
#: and notes of results are below 4096 characters; a dict key may be anything :func:`hovering.save`
#: takes); texts drawn on a figure have the scene schema's much tighter limit
#: (:data:`hovering.scenes.schema.MAX_TEXT`). 1 Mi characters bound one string to 4 MiB.
MAX_STRING_CHARS = 1 << 20
#: Largest integer in a JSON document, in bits (:func:`hovering.save` refuses larger ones): its
#: decimal text (~3000 digits) converts in microseconds and stays below Python's 4300-digit limit.
MAX_INT_BITS = 10_000
#: Most members of an archive: a result has one per array (a scene's, a few hundred).
MAX_MEMBERS = 100_000
#: Largest zip central directory read (bytes). Python's zipfile reads it whole and makes an object
#: of ~300 bytes per entry (>= 46 bytes each), so 8 MiB bounds that to ~60 MB.
MAX_DIRECTORY_BYTES = 8 << 20
#: Longest ``.npy`` header read (numpy's own default ``max_header_size``).
MAX_NPY_HEADER = 10_000
#: Memory the Python objects made from one character of JSON can take, at most (measured: a run
#: of ``[],`` makes a 56-byte list per 3 characters, ``{},`` a 64-byte dict; strings and floats
#: less), plus the text itself and the rebuilt objects.
TREE_BYTES_PER_CHAR = 64
#: Memory a Python string of an object array (text arrays: itineraries) takes besides its characters.
_OBJECT_BYTES_PER_ITEM = 64
#: The dtypes an array member may have: booleans, integers, floats, complex numbers and text.
_PLAIN_KINDS = "biufcU"

try:
    from lzma import LZMAError
except ImportError:  # a Python without lzma: zipfile cannot open an LZMA member either (NotImplementedError)
    LZMAError = zlib.error
#: What reading a zip archive and its ``.npy`` members raises, ValueError aside, for a file that is
#: not one or is damaged: EOFError, OSError (bz2's errors too) and zipfile's BadZipFile (no zip, a
#: bad CRC), said as they are; and, said to be damage (hovering never writes what causes them),
#: NotImplementedError (a compression method or zip version zipfile lacks), RuntimeError (a member
#: marked encrypted), the decompressors' zlib.error and LZMAError, struct.error (a short record),
#: numpy's header parser's SyntaxError and tokenize.TokenError.
_UNREADABLE = (EOFError, OSError, zipfile.BadZipFile)
_DAMAGED = (NotImplementedError, RuntimeError, zlib.error, LZMAError, struct.error, SyntaxError, tokenize.TokenError)
_DECODE_ERRORS = (ValueError, *_UNREADABLE, *_DAMAGED)


def _decode_error(where: str, e: Exception) -> ValueError:
    """The one ValueError for a failure to read or decode part of an archive at ``where``."""
    if isinstance(e, (ValueError, *_UNREADABLE)):
        return ValueError(f"{where}: {e}")
    return ValueError(f"{where}: damaged or not written by hovering: {e}")


def memory_budget() -> int:
    """Bytes a file may make the reader hold: half of this machine's physical memory.

    The same budget as a computed result (:func:`hovering._checks.check_memory`): a result this
    machine could have computed can be read back; a file cannot make it hold more.

    Returns
    -------
    int
    """
    return physical_memory() // 2


def regular_file(path: str) -> int:
    """The size of ``path``, refused (ValueError) unless it is a regular file.

    A device (``/dev/zero``), a FIFO or a directory would be read forever or not at all.

    Parameters
    ----------
    path : str
        The file.

    Returns
    -------
    int
        Its size in bytes.
    """
    try:
        st = os.stat(path)
    except OSError as e:
        raise ValueError(f"cannot read {path}: {e.strerror or e}") from None
    if not stat.S_ISREG(st.st_mode):
        raise ValueError(f"cannot read {path}: not a regular file")
    return st.st_size


# ------------------------------------------------------------------------------------------------
# JSON

# A JSON string literal (the unrolled form: linear, no backtracking).
_JSON_STRING = re.compile(r'"[^"\\]*(?:\\.[^"\\]*)*"', re.S)


def _nesting(text: str) -> int:
    """Deepest nesting of ``[ {`` in JSON text, strings skipped (numpy over chunks: linear, bounded memory)."""
    b = np.frombuffer(_JSON_STRING.sub("", text).encode("ascii", "replace"), dtype=np.uint8)
    depth = top = 0
    chunk = 1 << 20
    for i in range(0, b.size, chunk):
        c = b[i : i + chunk]
        d = (
            depth
            + np.cumsum((c == 91).view(np.int8) | (c == 123).view(np.int8), dtype=np.int64)
            - np.cumsum((c == 93).view(np.int8) | (c == 125).view(np.int8), dtype=np.int64)
        )
        if d.size:
            top, depth = max(top, int(d.max())), int(d[-1])
    return top


def _refuse_constant(name: str):
    raise ValueError(
        f"the JSON holds {name}, which hovering never writes (non-finite numbers are written as {{'__float__': 'nan'}})"
    )


def _finite_float(text: str) -> float:
    x = float(text)
    if not math.isfinite(x):
        raise ValueError(f"the JSON number {text[:40]} is beyond the range of a double")
    return x


def _bounded_int(text: str) -> int:
    # More digits than any integer of MAX_INT_BITS bits has: refused before converting.
    if len(text.lstrip("-")) > math.ceil(MAX_INT_BITS * math.log10(2)):
        raise ValueError(
            f"the JSON integer {text[:40]}... has {len(text)} digits; allowed: integers of at most {MAX_INT_BITS} bits"
        )
    v = int(text)
    if v.bit_length() > MAX_INT_BITS:
        raise ValueError(f"the JSON integer {text[:40]}... has {v.bit_length()} bits; allowed: at most {MAX_INT_BITS}")
    return v


def _text(s: str, where: str) -> None:
    if len(s) > MAX_STRING_CHARS:
        raise ValueError(f"{where}: a string of {len(s)} characters; allowed: at most {MAX_STRING_CHARS}")


def json_cost(text: bytes) -> int:
    """An upper bound of the memory (bytes) ``json.loads`` makes of ``text``, counted from its characters.

    Each ``[``/``{`` a container (<= 96 bytes with its slot), each pair of quotes a string (<= 64 plus
    its characters), each value after a comma or colon a number or literal (<= 40), and the text
    itself (bytes, then str). Characters inside strings are counted too: an overestimate.

    Parameters
    ----------
    text : bytes
        JSON text (one document or JSON lines).

    Returns
    -------
    int
    """
    return (
        96 * (text.count(b"[") + text.count(b"{"))
        + 32 * text.count(b'"')
        + 40 * (text.count(b",") + text.count(b":") + text.count(b"\n") + 1)
        + 6 * len(text)
    )


def json_nesting(text: str) -> int:
    """Deepest nesting of arrays and objects in JSON text (strings skipped; linear time, bounded memory).

    Parameters
    ----------
    text : str
        JSON text.

    Returns
    -------
    int
    """
    return _nesting(text)


def parse_json(text: str, what: str = "the JSON document"):
    """Parse untrusted JSON after checking its length and nesting, refusing what hovering never writes.

    Checked before parsing: at most :data:`MAX_TREE_CHARS` characters, nesting at most
    :data:`MAX_TREE_DEPTH`. While parsing: no ``NaN``/``Infinity`` constants, no number beyond a
    double, integers of at most :data:`MAX_INT_BITS` bits. After: every string and key at most
    :data:`MAX_STRING_CHARS` characters (a string is data: any str :func:`hovering.save` takes,
    lone surrogates included; texts that are shown are checked where they are shown).

    Parameters
    ----------
    text : str
        The document.
    what : str, optional
        What it is, for the messages.

    Returns
    -------
    object

    Raises
    ------
    ValueError
        Naming the limit, or where in the document the bad value is.
    """
    if len(text) > MAX_TREE_CHARS:
        raise ValueError(f"{what} has {len(text)} characters; allowed: at most {MAX_TREE_CHARS}")
    depth = _nesting(text)
    if depth > MAX_TREE_DEPTH:
        raise ValueError(f"{what} is nested {depth} levels deep; allowed: at most {MAX_TREE_DEPTH}")
    try:
        doc = json.loads(text, parse_constant=_refuse_constant, parse_float=_finite_float, parse_int=_bounded_int)
    except RecursionError:  # the pre-scan bounds the depth; kept for a text it misjudged
        raise ValueError(f"{what} is nested too deeply; allowed: at most {MAX_TREE_DEPTH} levels") from None
    except ValueError as e:
        raise ValueError(f"{what} is not valid JSON: {e}") from None
    stack = [(doc, "the document")]
    while stack:
        node, where = stack.pop()
        if isinstance(node, str):
            _text(node, f"{what}, at {where}")
        elif isinstance(node, list):
            stack.extend((v, f"{where}[{i}]") for i, v in enumerate(node))
        elif isinstance(node, dict):
            for k, v in node.items():
                _text(k, f"{what}, a key at {where}")
                stack.append((v, f"{where}.{k[:40]}"))
    return doc


# ------------------------------------------------------------------------------------------------
# Zip archives of .npy members

_EOCD = struct.Struct("<4s4H2LH")  # end of central directory record (APPNOTE 4.3.16)
_LOCATOR = struct.Struct("<4sLQL")  # ZIP64 end of central directory locator (4.3.15)
_EOCD64 = struct.Struct("<4sQ2H2L4Q")  # ZIP64 end of central directory record (4.3.14)


def _directory(fh, size: int) -> tuple:
    """(members, directory bytes) an archive's end record declares, found as Python's zipfile finds it."""
    tail = min(size, _EOCD.size + 0xFFFF)
    fh.seek(size - tail)
    data = fh.read(tail)
    i = len(data) - _EOCD.size if data[-_EOCD.size : -_EOCD.size + 4] == b"PK\x05\x06" else data.rfind(b"PK\x05\x06")
    if i < 0 or len(data) - i < _EOCD.size:
        raise zipfile.BadZipFile("no zip end record")
    _, _, _, _, members, cd_size, _, _ = _EOCD.unpack_from(data, i)
    at = size - tail + i - _LOCATOR.size  # a ZIP64 locator right before the end record takes precedence
    if at >= 0:
        fh.seek(at)
        loc = fh.read(_LOCATOR.size)
        if len(loc) == _LOCATOR.size and loc[:4] == b"PK\x06\x07":
            fh.seek(at - _EOCD64.size)
            rec = fh.read(_EOCD64.size)
            if len(rec) != _EOCD64.size or rec[:4] != b"PK\x06\x06":
                raise zipfile.BadZipFile("a ZIP64 locator without its end record")
            _, _, _, _, _, _, _, members, cd_size, _ = _EOCD64.unpack(rec)
    return members, cd_size


def safe_member_name(name: str) -> bool:
    """Whether an archive member name is one :func:`hovering.save` writes (and reading accepts):
    relative, no ``..`` component, no backslash or control character.

    Parameters
    ----------
    name : str
        The member's name.

    Returns
    -------
    bool
    """
    parts = name.split("/")
    return (
        bool(name)
        and not name.startswith("/")
        and "\\" not in name
        and ".." not in parts
        and not any(ord(c) < 32 for c in name)
    )


def plain_dtype(dtype: np.dtype) -> bool:
    """Whether arrays of ``dtype`` are read from a file: booleans, integers, floats, complex numbers
    or text (no objects, records, sub-arrays, bytes or dates).

    Parameters
    ----------
    dtype : numpy.dtype
        The dtype.

    Returns
    -------
    bool
    """
    return dtype.kind in _PLAIN_KINDS and dtype.fields is None and dtype.subdtype is None


class Archive:
    """An NPZ archive opened for reading untrusted members (a context manager).

    Opening checks that the file is a regular file and a zip archive whose directory (member
    count, size, names) is within the limits; nothing else is read until asked for.

    Parameters
    ----------
    path : str
        The file.
    """

    def __init__(self, path: str):
        self.path = path
        size = regular_file(path)
        self._fh = open(path, "rb")
        try:
            if self._fh.read(6) == b"\x93NUMPY":
                raise ValueError(f"{path} is not a hovering result file (a single .npy array, not an NPZ archive)")
            try:
                members, cd_size = _directory(self._fh, size)
            except _DECODE_ERRORS as e:
                raise _decode_error(f"{path} is not a hovering result file", e) from None
            if members > MAX_MEMBERS or cd_size > MAX_DIRECTORY_BYTES:
                raise ValueError(
                    f"{path}: an archive of {members} members and a directory of {cd_size} bytes; "
                    f"allowed: at most {MAX_MEMBERS} members and {MAX_DIRECTORY_BYTES} bytes"
                )
            self._fh.seek(0)
            try:
                self._zip = zipfile.ZipFile(self._fh)
            except _DECODE_ERRORS as e:
                raise _decode_error(f"{path} is not a hovering result file", e) from None
            names = [i.filename for i in self._zip.infolist()]
            bad = next((n for n in names if not safe_member_name(n)), None)
            if bad is not None:
                raise ValueError(
                    f"{path}: the archive has a member named {bad[:80]!r}; a hovering result file's "
                    "members are relative names without '..' (nothing is ever extracted)"
                )
            if len(set(names)) != len(names):
                dup = next(n for n in names if names.count(n) > 1)
                raise ValueError(f"{path}: the archive has two members named {dup[:80]!r}")
            self.files = {n[:-4]: n for n in names if n.endswith(".npy")}
        except BaseException:
            self._fh.close()
            raise

    def __enter__(self) -> Archive:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        """Close the file."""
        self._zip.close()
        self._fh.close()

    def header(self, key: str) -> tuple:
        """``(dtype, shape, nbytes)`` of the array ``key``, from its ``.npy`` header, checked.

        The header is at most :data:`MAX_NPY_HEADER` bytes, the dtype a plain one (no objects, no
        records), and the member's declared uncompressed size agrees with the header's shape and
        dtype. Only the header is decompressed.

        Parameters
        ----------
        key : str
            The array's name (its member without ``.npy``).

        Returns
        -------
        tuple
        """
        where = f"{self.path}: array {key[:80]!r}"
        info = self._zip.getinfo(self.files[key])
        try:
            with self._zip.open(info) as f:
                head = f.read(8)
                if len(head) < 8 or head[:6] != b"\x93NUMPY" or head[6] not in (1, 2):
                    raise ValueError("not a .npy array of format 1.0 or 2.0")
                width = 2 if head[6] == 1 else 4
                head += f.read(width)
                if len(head) != 8 + width:
                    raise ValueError("its header is cut short")
                n = int.from_bytes(head[8:], "little")
                if n > MAX_NPY_HEADER:
                    raise ValueError(f"a header of {n} bytes; allowed: at most {MAX_NPY_HEADER}")
                head += f.read(n)
            buf = io.BytesIO(head)
            version = np.lib.format.read_magic(buf)
            reader = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
            shape, _, dtype = reader(buf)
        except _DECODE_ERRORS as e:
            raise _decode_error(where, e) from None
        if not plain_dtype(dtype):
            raise ValueError(
                f"{where}: dtype {dtype.str!r} is refused; allowed: booleans, integers, floats, complex "
                "numbers and text (object arrays would need pickle)"
            )
        nbytes = math.prod(shape) * dtype.itemsize
        if info.file_size != len(head) + nbytes:
            raise ValueError(
                f"{where}: the archive declares {info.file_size} bytes, its header "
                f"{len(head)} + {nbytes} (shape {shape}, dtype {dtype.str})"
            )
        return dtype, shape, nbytes

    def read(self, key: str) -> np.ndarray:
        """The array ``key`` (its header checked by :meth:`header` first; never unpickled).

        Parameters
        ----------
        key : str
            The array's name.

        Returns
        -------
        ndarray
        """
        try:
            with self._zip.open(self.files[key]) as f:
                return np.lib.format.read_array(f, allow_pickle=False)
        except _DECODE_ERRORS as e:
            raise _decode_error(f"{self.path}: array {key[:80]!r}", e) from None


# The NPZ format of hovering.save: its name and the member holding the JSON tree. Here, not in
# _serial, because recognising a file as ours is reading an untrusted file, and the writers
# (hovering._output) need it without depending on the serializer.
FORMAT = "hovering-npz-1"
_META_KEY = "__meta__"
#: Largest ``__meta__`` member :func:`is_result_file` reads to recognise a result file.
_MAX_SNIFF_META = 64 << 20


def is_result_file(path: os.PathLike) -> bool:
    """Whether ``path`` is an NPZ written by :func:`hovering.save` (its ``__meta__`` document has this
    format); False for anything else or anything unreadable. Reads only that member (at most 64 MiB
    declared), never the arrays.

    Parameters
    ----------
    path : path-like
        The file.

    Returns
    -------
    bool
    """
    try:  # an untrusted file: read as load reads it, only its __meta__ member
        with Archive(os.fspath(path)) as z:
            if _META_KEY not in z.files:
                return False
            dtype, shape, nbytes = z.header(_META_KEY)
            if dtype.kind != "U" or shape != () or nbytes > _MAX_SNIFF_META:
                return False
            doc = parse_json(str(z.read(_META_KEY)))
    except Exception:  # noqa: BLE001 - any failure to read it means: not recognised as ours
        return False
    return isinstance(doc, dict) and doc.get("format") == FORMAT
