"""Writing outputs so that nothing is lost: the one place where hovering writes a file.

* A whole file (PNG, JSON, NPZ, ...) is written to a temporary file in the same directory, flushed
  and fsync'd, then renamed over the target (:func:`replacing`, :func:`write_bytes`,
  :func:`write_text`, :func:`savefig`). A kill, Ctrl-C or a full disk at any moment leaves either
  the previous file or the new one, never a mix; a failure removes the temporary file (a SIGKILL
  can leave one behind, named ``.NAME.XXXXXXXX.tmp``). A replaced file keeps its permission bits.
* A line appended to a shared file (a checkpoint) is written under an exclusive ``flock`` on that
  file and fsync'd (:func:`append_line`), so two processes never interleave lines; a write that
  fails is cut back off, so a full disk leaves no half line.
* Any ``OSError`` of a write becomes one :class:`WriteError` naming the file (``no space left`` for
  a full disk, a quota or a file-size limit).

Which existing files a scene may replace (:func:`refuse_foreign`): only files hovering wrote,
recognised by their content, never by their name alone:

* an NPZ whose ``__meta__`` document has hovering's format (:func:`hovering._untrusted.is_result_file`);
* a JSON file whose first key is ``"format"`` with a value starting ``hovering-`` (scene sidecars,
  accuracy tables), or a scene sidecar of a version before that key (starts with the scene's typed
  tree);
* a checkpoint (``.jsonl``) that is empty, starts with its header ``{"format":"hovering-checkpoint",...``
  or (written before the header) with a record ``{"key": ...``;
* any other file (a figure) whose JSON or NPZ of the same name beside it is hovering's.
"""

from __future__ import annotations

import errno
import fcntl
import os
import re
import secrets
import stat
from contextlib import contextmanager
from pathlib import Path

from .untrusted import is_result_file

__all__ = [
    "output_path",
    "WriteError",
    "replacing",
    "write_bytes",
    "write_text",
    "savefig",
    "append_line",
    "locked",
    "refuse_foreign",
    "is_ours",
]

_NO_SPACE = {
    errno.ENOSPC: "no space left on device",
    errno.EDQUOT: "no space left (disk quota exceeded)",
    errno.EFBIG: "no space left (the file would exceed the file system's or the process's file size limit)",
}


class WriteError(OSError, ValueError):
    """An output could not be written; the message names the file, and the previous file is intact.

    Both an ``OSError`` (what failed is the system's write) and a ``ValueError`` (what hovering's
    functions raise for a path they cannot use), like :class:`io.UnsupportedOperation`.
    ``errno`` and ``filename`` are those of the failed write.
    """

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


def write_error(path, e: OSError, previous: bool = True) -> WriteError:
    """The :class:`WriteError` of a failed write of ``path`` (``previous``: say the old file is intact)."""
    why = _NO_SPACE.get(e.errno) or e.strerror or str(e)
    tail = " (the previous file, if any, is unchanged)" if previous else ""
    err = WriteError(f"cannot write {os.fspath(path)}: {why}{tail}")
    err.errno, err.filename = e.errno, os.fspath(path)
    return err


def _fsync_dir(directory: str) -> None:
    # The rename is durable only once the directory is on disk too.
    try:
        fd = os.open(directory, os.O_RDONLY | os.O_DIRECTORY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:  # some file systems cannot sync a directory; the data itself is synced
        pass
    finally:
        os.close(fd)


@contextmanager
def replacing(path: os.PathLike, text: bool = False):
    """Write a whole file atomically: yields a file object; on a clean exit it replaces ``path``.

    Parameters
    ----------
    path : path-like
        The file to (re)place; its directory must exist.
    text : bool, optional
        Yield a text file (UTF-8) instead of a binary one.

    Yields
    ------
    file object
        A temporary file in ``path``'s directory.

    Raises
    ------
    WriteError
        For any ``OSError`` (a full disk: ``no space left``); ``path`` is left as it was.
    """
    path = os.fspath(path)
    directory = os.path.dirname(path) or "."
    tmp = os.path.join(directory, f".{os.path.basename(path)}.{secrets.token_hex(4)}.tmp")
    try:
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o666)
    except OSError as e:
        raise write_error(path, e) from None
    try:
        with os.fdopen(fd, "w" if text else "wb", **({"encoding": "utf-8"} if text else {})) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        try:
            os.chmod(tmp, stat.S_IMODE(os.stat(path).st_mode))
        except FileNotFoundError:
            pass
        os.replace(tmp, path)
    except BaseException as e:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        if isinstance(e, OSError) and not isinstance(e, WriteError):
            raise write_error(path, e) from None
        raise
    _fsync_dir(directory)


def write_bytes(path: os.PathLike, data: bytes) -> str:
    """Write ``data`` to ``path`` atomically (see :func:`replacing`); returns the path as str."""
    with replacing(path) as fh:
        fh.write(data)
    return os.fspath(path)


def write_text(path: os.PathLike, text: str) -> str:
    """Write ``text`` (UTF-8) to ``path`` atomically (see :func:`replacing`); returns the path as str."""
    with replacing(path, text=True) as fh:
        fh.write(text)
    return os.fspath(path)


def savefig(fig, path: os.PathLike, **kwargs) -> str:
    """``fig.savefig(path, **kwargs)`` written atomically (the format from ``path``'s suffix).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    path : path-like
        The file; its suffix names the format (``.png``, ``.pdf``, ``.svg``, ...).
    **kwargs
        Passed to ``savefig`` (``dpi``, ...).

    Returns
    -------
    str
        The path written.
    """
    fmt = Path(path).suffix[1:].lower() or "png"
    with replacing(path) as fh:
        fig.savefig(fh, format=fmt, **kwargs)
    return os.fspath(path)


def _write_all(fd: int, data: bytes) -> None:
    while data:
        n = os.write(fd, data)
        data = data[n:]


def append_line(path: os.PathLike, line: str) -> None:
    """Append ``line`` and a newline to ``path`` (created if missing) under an exclusive lock, durably.

    Another process appending to the same file waits for the lock, so lines never interleave. A
    last line left without its newline (a writer killed mid-line) is closed first, so this line is
    not glued to it (the torn line stays a damaged line that readers skip). A failed write is cut
    back off: the file ends as it was.

    Parameters
    ----------
    path : path-like
        The file.
    line : str
        One line of text, without newline.

    Raises
    ------
    WriteError
        For any ``OSError`` (a full disk: ``no space left``).
    """
    data = (line + "\n").encode("utf-8")
    try:
        fd = os.open(path, os.O_RDWR | os.O_APPEND | os.O_CREAT | os.O_CLOEXEC, 0o666)
    except OSError as e:
        raise write_error(path, e, previous=False) from None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        size = os.fstat(fd).st_size
        if size and os.pread(fd, 1, size - 1) != b"\n":
            data = b"\n" + data
        try:
            _write_all(fd, data)
            os.fsync(fd)
        except OSError:
            try:
                os.ftruncate(fd, size)
            except OSError:  # not a regular file (a device): nothing to cut
                pass
            raise
    except OSError as e:
        raise write_error(path, e, previous=False) from None
    finally:
        os.close(fd)  # releases the lock


@contextmanager
def locked(path: os.PathLike):
    """An existing file opened for reading and writing (``r+b``) under the exclusive lock that
    :func:`append_line` takes: what is read and cut there cannot race an append. A file this
    process may only read is opened ``rb`` under a shared lock (readable, not cut).

    Parameters
    ----------
    path : path-like
        The file.

    Yields
    ------
    file object
    """
    try:
        fh, lock = open(path, "r+b"), fcntl.LOCK_EX
    except OSError as e:
        if e.errno not in (errno.EACCES, errno.EPERM, errno.EROFS):
            raise
        fh, lock = open(path, "rb"), fcntl.LOCK_SH
    with fh:
        fcntl.flock(fh.fileno(), lock)
        yield fh


# ------------------------------------------------------------------------------------------------
# Which files are hovering's

_SNIFF = 4096
_JSON_MARK = re.compile(rb'\A\s*\{\s*"format"\s*:\s*"hovering-')
# A scene sidecar written before the "format" key: it starts with the scene's typed tree.
_OLD_SIDECAR = re.compile(rb'\A\s*\{\s*"scene"\s*:\s*\{\s*"__dataclass__"\s*:\s*"hovering\.scenes\.spec:')


def _head(path: Path) -> bytes:
    with open(path, "rb") as f:
        return f.read(_SNIFF)


def is_ours(path: os.PathLike) -> bool:
    """Whether an existing file was written by hovering (see the module's list); False if unsure.

    Parameters
    ----------
    path : path-like
        The file.

    Returns
    -------
    bool
    """
    p = Path(path)
    try:
        if not p.is_file():
            return False
        if p.suffix.lower() == ".npz":
            return is_result_file(p)
        if p.suffix.lower() == ".jsonl":
            head = _head(p)
            # a checkpoint (its format header; before it, a first record {"key": ...})
            return head == b"" or head.startswith(b'{"key": ') or bool(_JSON_MARK.match(head))
        if p.suffix.lower() == ".json":
            head = _head(p)
            return bool(_JSON_MARK.match(head) or _OLD_SIDECAR.match(head))
        return any(p.with_suffix(s).is_file() and is_ours(p.with_suffix(s)) for s in (".json", ".npz"))
    except OSError:
        return False


def refuse_foreign(paths, force: bool = False) -> None:
    """Refuse (ValueError) to go on if any of ``paths`` exists and is not a file hovering wrote.

    Parameters
    ----------
    paths : iterable of path-like
        Every file a run is about to write.
    force : bool, optional
        Replace them anyway (``--force``).

    Raises
    ------
    ValueError
        Naming the first such file and how to proceed.
    """
    if force:
        return
    for p in paths:
        if os.path.lexists(p) and not is_ours(p):
            raise ValueError(
                f"{os.fspath(p)} exists and was not written by hovering: refusing to replace it. Move or "
                "delete it, choose another output path, or pass --force (force=True) to replace it"
            )


#: Longest file or directory name, in bytes (NAME_MAX of Linux's and macOS's file systems).
_NAME_MAX = 255


def output_path(where: str, path, within=None) -> os.PathLike:
    """A figure path checked before any computation: its format is one matplotlib writes and its
    directory exists (or can be created) and is writable.

    Parameters
    ----------
    where : str
        What the path is (``"--out"``, ``"scene.output"``) for the message.
    path : path-like
        The requested file. Without a suffix, ``.png`` is added (what ``savefig`` would write), so
        the path reported afterwards is the file that exists.
    within : sequence of path-like, optional
        Directories the file must lie under (symbolic links resolved), checked before anything
        else touches the path: where a file from elsewhere (a scene) may make hovering write.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    ValueError
        Naming the path and the allowed formats, or the directory that cannot be written.
    """

    from matplotlib.backend_bases import FigureCanvasBase

    if not isinstance(path, (str, os.PathLike)) or not str(path).strip() or "\0" in str(path):
        raise ValueError(f"{where} must be a file path (non-empty, no NUL byte), got {path!r}")
    p = Path(path)
    if p.suffix == "":
        if p.exists():  # "out" meaning out.png would silently write next to an existing out/ or /dev/null
            raise ValueError(
                f"{where} = {str(path)!r} exists and is not a figure file; give a name with a suffix "
                f"(.png, .pdf, .svg, ...)"
            )
        p = p.with_suffix(".png")
    # Each name in the path at most NAME_MAX bytes (255 on Linux and macOS file systems): else
    # the first open says "[Errno 36] File name too long", naming no key.
    for part in p.parts:
        if len(os.fsencode(part)) > _NAME_MAX:
            raise ValueError(
                f"{where}: the name {part[:40]!r}... is {len(os.fsencode(part))} bytes long; allowed: at most "
                f"{_NAME_MAX} bytes per file or directory name"
            )
    if within is not None:
        real = p.resolve()
        bases = list(dict.fromkeys(Path(b).resolve() for b in within))
        if not any(real.is_relative_to(b) for b in bases):
            raise ValueError(
                f"{where} = {str(path)!r} is outside {' and '.join(str(b) for b in bases)}: a scene "
                "writes only under its own folder or the working directory; give --out (out=) to write "
                "elsewhere"
            )
    formats = FigureCanvasBase.get_supported_filetypes()
    if p.suffix[1:].lower() not in formats:
        raise ValueError(
            f"{where} = {str(path)!r}: matplotlib cannot write {p.suffix!r} files; "
            f"allowed suffixes: {', '.join('.' + f for f in sorted(formats))}"
        )
    if p.exists() and not p.is_file():
        raise ValueError(f"{where} = {str(path)!r} exists and is not a regular file")
    parent = p.parent if str(p.parent) else Path(".")
    anc = parent
    while not anc.exists() and anc != anc.parent:
        anc = anc.parent
    if not anc.is_dir():
        raise ValueError(f"{where} = {str(path)!r}: {anc} is not a directory")
    if not os.access(anc, os.W_OK | os.X_OK):
        raise ValueError(f"{where} = {str(path)!r}: the directory {anc} is not writable")
    if anc == parent:
        # os.access says yes to root everywhere (/proc, read-only mounts): try it, leaving no trace.
        existed = p.exists()
        try:
            with open(p, "ab"):
                pass
        except OSError as e:
            raise ValueError(f"{where} = {str(path)!r} cannot be written: {e.strerror}") from None
        if not existed:
            p.unlink()
    return p
