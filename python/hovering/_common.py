"""Vocabulary shared by both models: region labels, outcomes, angle wrapping.

The enums are the core's own (bound from C++ as :class:`enum.IntEnum`, so their values cannot
drift from the kernels'); this module only adds the paper's labels and a parser.
"""

from __future__ import annotations

import math
import numbers
import operator
import os

import numpy as np

from ._core import FlowStatus, Geometry, Kernel, Region, Status, TrajectoryPoint

__all__ = ["Region", "Status", "FlowStatus", "Geometry", "Kernel", "region_mask", "wrap", "REGION_LABELS",
           "iterate_arguments", "real_number", "integer", "real_array", "require_finite", "require_angles",
           "check_memory", "point_pair", "thread_count", "is_choice", "status_code", "require_map", "flag", "require_type", "forcing_array", "MAX_MODES", "output_path", "MAX_ANGLE",
           "TrajectoryPoint", "MAX_TRAJECTORY_POINTS", "trajectory_arguments", "trajectory_rows"]

#: Largest |angle| that can be wrapped to [-pi, pi) accurately (2 pi floor(x / 2 pi) loses a turn
#: beyond ~1e15; 1e6 keeps the wrapping error below 1e-9).
MAX_ANGLE = 1e6

#: The paper's label of each region code (``'m'``: more than one impact, the flow only).
REGION_LABELS = {-1: "-", 0: "0u", 1: "0", 2: "1", 3: "R", 4: "m"}


def _label(self) -> str:
    """The paper's label of the region: ``'0u'``, ``'0'``, ``'1'``, ``'R'`` (``'m'``: several impacts)."""
    return REGION_LABELS[int(self)]


def _parse(cls, value) -> "Region":
    """Convert a Region, its name (``'ABOVE'``), paper label (``'0'``) or code (1) to a Region.

    Parameters
    ----------
    value : Region, str or int
        What to convert.

    Returns
    -------
    Region

    Raises
    ------
    ValueError
        If the value names no region.
    """
    if isinstance(value, cls):
        return value
    if isinstance(value, str):
        key = value.strip()
        if key == "u":  # the itinerary's letter for a return beside the step
            return cls.BESIDE
        for r in cls:
            if r is not cls.NONE and key in (r.name, r.name.lower(), REGION_LABELS[int(r)]):
                return r
    elif isinstance(value, (int, np.integer)) and not isinstance(value, bool) and 0 <= value < len(REGION_LABELS) - 1:
        return cls(int(value))
    allowed = ", ".join(f"{r.name} ('{REGION_LABELS[int(r)]}')" for r in cls if r is not cls.NONE)
    raise ValueError(f"unknown region {value!r}; allowed: {allowed}")


Region.label = property(_label)
Region.parse = classmethod(_parse)


def region_mask(regions) -> int:
    """Bit mask (bit r = Region r) of a collection of regions (or of one region).

    Parameters
    ----------
    regions : Region, str, int or iterable of them
        Regions in any form accepted by ``Region.parse``; a single label such as ``"0u"`` is one
        region, not the characters of its name.

    Returns
    -------
    int
        The mask, 0 for an empty collection.
    """
    if isinstance(regions, (str, int, np.integer, Region)):
        regions = (regions,)
    try:
        items = list(regions)
    except TypeError:
        raise ValueError(f"regions must be a region or a collection of regions, got {regions!r}") from None
    mask = 0
    for r in items:
        if isinstance(r, Region) and r is Region.NONE:
            raise ValueError("Region.NONE (no return) is not a region an orbit can be in; allowed: "
                             + ", ".join(f"{x.name} ('{REGION_LABELS[int(x)]}')" for x in Region if x is not Region.NONE))
        mask |= 1 << int(Region.parse(r))
    return mask


def real_number(name: str, value, lo=None, lo_open=True, hi=None, hi_open=True) -> float:
    """A finite real number (not a bool, string or complex) in an optional interval, or a ValueError naming it.

    Parameters
    ----------
    name : str
        The parameter's name (for the message).
    value : object
        What was passed.
    lo, hi : float, optional
        Interval ends (None: unbounded).
    lo_open, hi_open : bool, optional
        Whether the ends are excluded.

    Returns
    -------
    float
    """
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf":
        value = value.item()  # a 0-d array is a number, as numpy scalars are
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise ValueError(f"{name} must be a real number, got {_short(value)}")
    try:
        v = float(value)
    except OverflowError:
        raise ValueError(f"{name} must be a real number within the range of a double, got {_short(value)}") from None
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite, got {v}")
    if (lo is not None and (v <= lo if lo_open else v < lo)) or (hi is not None and (v >= hi if hi_open else v > hi)):
        rng = f"{'(' if lo_open else '['}{'-inf' if lo is None else lo}, {'inf' if hi is None else hi}{')' if hi_open else ']'}"
        raise ValueError(f"{name} must lie in {rng}, got {v}")
    return v


def integer(name: str, value, lo: int, hi: int) -> int:
    """An integer (not a bool, float or string) in [lo, hi], or a ValueError naming it and the range."""
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iu":
        value = value.item()
    try:
        v = operator.index(value)
    except TypeError:
        raise ValueError(f"{name} must be an integer in [{lo}, {hi}], got {value!r}") from None
    if isinstance(value, (bool, np.bool_)) or not lo <= v <= hi:
        raise ValueError(f"{name} must be an integer in [{lo}, {hi}], got {value!r}")
    return v


def flag(name: str, value) -> bool:
    """A True/False argument (not 'yes', None or 1), or a ValueError naming it."""
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be True or False, got {_short(value)}")
    return bool(value)


def require_type(name: str, value, cls, what: str):
    """``value`` if it is an instance of cls, else a ValueError naming the parameter and what it must be."""
    if not isinstance(value, cls):
        raise ValueError(f"{name} must be {what}, got {_short(value)}")
    return value


def status_code(cls, value) -> int:
    """The code of a status in the enum ``cls`` (Status or FlowStatus) from a member of either enum
    (by name: their numbers differ), its name (``"OFF_SECTION"``, any case) or its code."""
    if isinstance(value, (Status, FlowStatus)) or isinstance(value, str):
        name = value.name if not isinstance(value, str) else value.strip().upper()
        if name in cls.__members__:
            return int(cls.__members__[name])
    elif isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_)):
        if int(value) in {int(m) for m in cls}:
            return int(value)
    raise ValueError(f"status must be one of {', '.join(cls.__members__)} ({cls.__name__}), got {_short(value)}")


def require_map(name: str, m):
    """``m`` if it is a return map (TruncatedMap, TruncatedFamily, FlowMap: the ReturnMap protocol)."""
    from ._protocols import ReturnMap

    if not isinstance(m, ReturnMap):
        raise ValueError(f"{name} must be a map (hovering.TruncatedMap, TruncatedFamily or FlowMap), got {_short(m)}")
    return m


def is_choice(value, choices) -> bool:
    """Whether value is one of the string choices (False, not an error, for arrays and other types)."""
    return isinstance(value, str) and value in choices


def thread_count(value) -> int:
    """The ``n_threads`` argument every parallel call takes: an integer in [0, 4096], 0 = all cores."""
    try:
        v = operator.index(value)
    except TypeError:
        v = None
    if v is None or isinstance(value, (bool, np.bool_)) or not 0 <= v <= 4096:
        raise ValueError(f"n_threads must be an integer in [0, 4096] (0 = all cores), got {value!r}")
    return v


#: Most sine coefficients of a forcing f: the theory's cost grows with each (1000 took 20 s) and the
#: measured f of the flow needs ~8.
MAX_MODES = 64


def forcing_array(value) -> np.ndarray:
    """Sine coefficients ``b_1, b_2, ...`` of a forcing: 1 to MAX_MODES finite real numbers."""
    if isinstance(value, str):
        raise ValueError(f"forcing must be a sequence of sine coefficients, got {value!r}")
    b = np.atleast_1d(real_array("forcing", value))
    if b.ndim != 1 or not 1 <= b.size <= MAX_MODES:
        raise ValueError(f"forcing must be a 1-D sequence of 1 to {MAX_MODES} sine coefficients, got shape {b.shape}")
    require_finite("forcing", b)
    return b


def point_pair(phi, K, who: str = "", names=("phi", "K")) -> tuple:
    """Points (phi, K) of a map: real, finite, |phi| <= 1e6, broadcast together (C-ordered); and
    whether both were scalars. Messages name ``who: phi`` (or the given names, e.g. phi0, K0)."""
    na, nb = (f"{who}: {n}" if who else n for n in names)
    scalar = np.ndim(phi) == 0 and np.ndim(K) == 0
    p, k = real_array(na, phi), real_array(nb, K)  # type errors first, named
    require_angles(na, p)
    require_finite(nb, k)
    try:
        p, k = np.broadcast_arrays(p, k)
    except ValueError:
        raise ValueError(f"{who + ': ' if who else ''}{names[0]} and {names[1]} must have broadcastable shapes, got "
                         f"{np.shape(phi)} and {np.shape(K)}") from None
    # np.ascontiguousarray would turn 0-d into 1-d; the bindings copy non-contiguous views themselves.
    return np.asarray(p, order="C"), np.asarray(k, order="C"), scalar


def real_array(name: str, value) -> np.ndarray:
    """``value`` as a float array; a ValueError naming it for strings, objects, booleans or complex numbers."""
    try:
        a = np.asarray(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be real numbers, got {value!r}") from None
    if a.dtype.kind not in "iuf":
        raise ValueError(f"{name} must be real numbers, got dtype {a.dtype} ({_short(value)})")
    return a.astype(float, copy=False)


def require_finite(name: str, a) -> None:
    """Raise a ValueError naming the first non-finite entry of ``a``."""
    a = np.asarray(a)
    bad = ~np.isfinite(a)
    if bad.any():
        i = np.unravel_index(int(np.argmax(bad)), a.shape) if a.ndim else ()
        raise ValueError(f"{_entry(name, i)} must be finite, got {a[i]}")


def require_angles(name: str, a) -> None:
    """Raise unless every entry is a finite angle that can be wrapped accurately (|x| <= MAX_ANGLE)."""
    require_finite(name, a)
    a = np.asarray(a)
    if a.size and np.max(np.abs(a)) > MAX_ANGLE:
        i = np.unravel_index(int(np.argmax(np.abs(a.ravel()) > MAX_ANGLE)), a.shape)
        raise ValueError(f"{_entry(name, i)} must be an angle in [-1e6, 1e6] (larger ones cannot be wrapped to "
                         f"[-pi, pi) accurately in double precision), got {a[i]}")


def physical_memory() -> int:
    """Bytes of physical memory of this machine (64 GiB where the system does not say)."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return 2**36


def check_memory(what: str, nbytes: int) -> None:
    """Refuse, before any work, a result that would need more than half of this machine's memory."""
    total = physical_memory()
    if nbytes > total // 2:
        raise ValueError(f"{what} needs {nbytes / 2**30:.3g} GiB, more than half of this machine's "
                         f"{total / 2**30:.3g} GiB: record less, or fewer orbits or steps per call")


def output_path(where: str, path, within=None) -> "os.PathLike":
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
    from pathlib import Path

    from matplotlib.backend_bases import FigureCanvasBase

    if not isinstance(path, (str, os.PathLike)) or not str(path).strip() or "\0" in str(path):
        raise ValueError(f"{where} must be a file path (non-empty, no NUL byte), got {path!r}")
    p = Path(path)
    if p.suffix == "":
        if p.exists():  # "out" meaning out.png would silently write next to an existing out/ or /dev/null
            raise ValueError(f"{where} = {str(path)!r} exists and is not a figure file; give a name with a suffix "
                             f"(.png, .pdf, .svg, ...)")
        p = p.with_suffix(".png")
    if within is not None:
        real = p.resolve()
        bases = list(dict.fromkeys(Path(b).resolve() for b in within))
        if not any(real.is_relative_to(b) for b in bases):
            raise ValueError(f"{where} = {str(path)!r} is outside {' and '.join(str(b) for b in bases)}: a scene "
                             "writes only under its own folder or the working directory; give --out (out=) to write "
                             "elsewhere")
    formats = FigureCanvasBase.get_supported_filetypes()
    if p.suffix[1:].lower() not in formats:
        raise ValueError(f"{where} = {str(path)!r}: matplotlib cannot write {p.suffix!r} files; "
                         f"allowed suffixes: {', '.join('.' + f for f in sorted(formats))}")
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


def _entry(name: str, index: tuple) -> str:
    """``name[i]`` (or ``name[i, j]``, or ``name`` for a scalar): the entry a message is about."""
    return f"{name}[{', '.join(str(int(k)) for k in index)}]" if index else name


def _short(value) -> str:
    r = repr(value)
    return r if len(r) <= 60 else r[:57] + "..."


def wrap(x):
    """Wrap angles to ``[-pi, pi)``.

    Parameters
    ----------
    x : array_like
        Angles in radians, |x| <= 1e6 (NaN stays NaN: a missing value, e.g. of a stopped orbit).

    Returns
    -------
    ndarray or float
        ``x`` shifted by a multiple of ``2 pi`` into ``[-pi, pi)``.

    Raises
    ------
    ValueError
        For an infinite angle or one beyond 1e6, which cannot be wrapped accurately.
    """
    x = real_array("angle", x)
    with np.errstate(invalid="ignore"):
        if np.any(np.abs(x) > MAX_ANGLE):
            bad = x[np.abs(x) > MAX_ANGLE] if x.ndim else x
            raise ValueError(f"angles to wrap must satisfy |x| <= 1e6 (beyond, 2 pi floor(x / 2 pi) loses accuracy), "
                             f"got {np.ravel(bad)[0]}")
    y = x - 2 * np.pi * np.floor((x + np.pi) / (2 * np.pi))
    y = np.where(y >= np.pi, y - 2 * np.pi, y)
    y = np.where(y < -np.pi, y + 2 * np.pi, y)
    return y if np.ndim(y) else float(y)


def iterate_arguments(record, allowed, n_steps, exit_regions, stop_on_exit) -> tuple:
    """Check the arguments every map's ``iterate`` shares; ``(record tuple, n_steps, exit mask)``.

    Raises
    ------
    ValueError
        Naming the unknown record key, the bad step count or region, or an exit set that is
        empty or missing where ``stop_on_exit`` needs it.
    """
    if isinstance(record, str):
        record = (record,)
    try:
        record = tuple(record)
    except TypeError:
        raise ValueError(f"record must be a sequence of keys from {list(allowed)} (or () for none), got {record!r}") from None
    unknown = [r for r in record if not is_choice(r, allowed)]
    if unknown:
        raise ValueError(f"record: unknown key(s) {unknown}; allowed: {list(allowed)}")
    try:
        if isinstance(n_steps, (bool, np.bool_)):
            raise TypeError
        n_steps = operator.index(n_steps)
    except TypeError:
        raise ValueError(f"n_steps must be an integer >= 0, got {n_steps!r}") from None
    if n_steps < 0:
        raise ValueError(f"n_steps must be >= 0, got {n_steps}")
    if n_steps > 2**53:
        raise ValueError(f"n_steps must be <= 2**53, got {n_steps}")
    if isinstance(stop_on_exit, (bool, np.bool_)) is False:
        raise ValueError(f"stop_on_exit must be True or False, got {stop_on_exit!r}")
    try:
        mask = region_mask(exit_regions) if exit_regions is not None else 0
    except ValueError as e:
        raise ValueError(f"exit_regions: {e}") from None
    if exit_regions is not None and mask == 0:
        raise ValueError("exit_regions must name at least one region")
    if stop_on_exit and mask == 0:
        raise ValueError("stop_on_exit needs exit_regions (the regions an orbit must stay in)")
    return record, n_steps, mask


#: Default bound of the points a trajectory recording keeps in total (all orbits of one call):
#: 10 million points are ~410 MB (five float64 and one int8 each).
MAX_TRAJECTORY_POINTS = 10_000_000


def trajectory_arguments(trajectory_dt, max_trajectory_points, n_orbits: int) -> tuple:
    """Check the arguments of a trajectory recording before anything is computed.

    Parameters
    ----------
    trajectory_dt : float
        Sample spacing, > 0.
    max_trajectory_points : int
        Bound of the points of all orbits together.
    n_orbits : int
        Number of orbits of the call.

    Returns
    -------
    (float, int)
        The sample spacing and the points each orbit may keep (``max_trajectory_points //
        n_orbits``: an orbit that would record more stops recording and is flagged in
        ``trajectory_truncated``).

    Raises
    ------
    ValueError
        For a spacing that is not a finite number > 0, a bound below two points per orbit (the
        start and one more), or a bound whose worst case would not fit in memory.
    """
    dt = real_number("trajectory_dt", trajectory_dt, 0.0)
    least = 2 * max(n_orbits, 1)
    cap = integer(f"max_trajectory_points (at least 2 per orbit: {n_orbits} orbits)", max_trajectory_points, least,
                  2**62)
    per_orbit = cap // max(n_orbits, 1)
    # Per-orbit vectors (growing by doubling) and the flat arrays they are copied into: ~3x the
    # 41 bytes of a point in the worst case.
    check_memory(f"a trajectory of up to {cap} points (max_trajectory_points)", 3 * 41 * per_orbit * n_orbits)
    return dt, per_orbit


def trajectory_rows(res, i) -> np.ndarray:
    """Rows ``(t, q1, p1, q2, p2)`` of orbit i of a result with a recorded trajectory.

    Parameters
    ----------
    res : IterateResult or ReturnMapResult
        A result with ``trajectory`` and ``trajectory_index``.
    i : int
        Orbit index (negative counts from the end).

    Returns
    -------
    ndarray
        Shape ``(m_i, 5)``, a view into ``res.trajectory``.

    Raises
    ------
    ValueError
        If no trajectory was recorded or i is out of range.
    """
    if res.trajectory is None:
        raise ValueError("no trajectory was recorded: pass record=('trajectory',) (FlowMap.iterate) or "
                         "trajectory_dt (Section.return_map)")
    n = res.trajectory_index.size - 1
    i = integer("i (orbit index)", i, -n, n - 1) % n
    return res.trajectory[res.trajectory_index[i] : res.trajectory_index[i + 1]]
