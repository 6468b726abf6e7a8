"""One value of a scene file, checked: numbers (or expressions of them), integers, flags, texts,
colours, pairs, tables, and the limits a scene file keeps. Every failure is a ``ValueError`` naming
the key (as ``panels[1].zoom.of``), the value and what is allowed.

The readers of every table and every kind call these (:mod:`hovering.scenes.fields` for a declared
field, a kind's own reader for a nested table); :mod:`hovering.scenes.schema` reads the document.
Values may be expressions of numbers, ``pi`` and ``OMEGA_G``: a whitelisted arithmetic evaluator
over the parsed syntax tree, never ``eval``.
"""

from __future__ import annotations

import ast
import math
import operator

from ..truncated.theory import OMEGA_G

__all__ = [
    "MAX_PANELS",
    "MAX_SERIES_POINTS",
    "MAX_SCENE_BYTES",
    "MAX_TEXT",
    "MAX_PATH_CHARS",
    "MAX_SCENE_STRING",
    "MAX_SCENE_DEPTH",
    "MAX_KEY_PARTS",
    "MAX_CANVAS_PIXELS",
    "evaluate",
    "real",
    "integer",
    "boolean",
    "text",
    "color",
    "pair",
    "size",
    "table",
    "tables",
    "distinct_reals",
    "check_keys",
]

_NAMES = {"pi": math.pi, "OMEGA_G": OMEGA_G}
_BINOPS = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.Pow: operator.pow,
}
_UNOPS = {ast.USub: operator.neg, ast.UAdd: operator.pos}
_FUNCS = {"sqrt": math.sqrt, "sin": math.sin, "cos": math.cos, "acos": math.acos}


def evaluate(node):
    """The value of a parsed arithmetic expression: numbers, ``pi``, ``OMEGA_G``, ``+ - * / **``,
    unary signs and ``sqrt``, ``sin``, ``cos``, ``acos``; any other node is refused.

    Parameters
    ----------
    node : ast.AST
        ``ast.parse(text, mode="eval")`` or a node of it.

    Returns
    -------
    float

    Raises
    ------
    ValueError
        For any other syntax (a name, an attribute, a call of another function, ...).
    """
    if isinstance(node, ast.Expression):
        return evaluate(node.body)
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) and not isinstance(node.value, bool):
        return float(node.value)
    if isinstance(node, ast.Name) and node.id in _NAMES:
        return _NAMES[node.id]
    if isinstance(node, ast.BinOp) and type(node.op) in _BINOPS:
        return _BINOPS[type(node.op)](evaluate(node.left), evaluate(node.right))
    if isinstance(node, ast.UnaryOp) and type(node.op) in _UNOPS:
        return _UNOPS[type(node.op)](evaluate(node.operand))
    if (
        isinstance(node, ast.Call)
        and isinstance(node.func, ast.Name)
        and node.func.id in _FUNCS
        and len(node.args) == 1
        and not node.keywords
    ):
        return _FUNCS[node.func.id](evaluate(node.args[0]))
    raise ValueError("unsupported expression")


#: Most panels (or hovering-area series) in one figure: a scene is a figure, not a sweep; 200
#: panels took 4 minutes and 300 MB.
MAX_PANELS = 36
#: Most eps values of one hovering-area scene.
MAX_SERIES_POINTS = 200
#: Largest scene file read (a scene is a few hundred bytes; /dev/zero must not be read forever).
MAX_SCENE_BYTES = 1 << 20

#: Longest expression string accepted: a parameter is a formula like "2 * pi * (sqrt(5) - 1) / 2",
#: never a program; a 50,000-deep one exhausted the parser's memory.
_MAX_EXPR = 200
#: Longest text drawn on a figure or naming something in it (title, panel id, orbit and series
#: labels, colour names), in characters: the paper's longest title has ~60; savefig took 0.4 s with
#: a 200-character title and two minutes with a 500,000-character one.
MAX_TEXT = 200
#: Longest path (``output``): Linux's PATH_MAX.
MAX_PATH_CHARS = 4096
#: Longest string or key anywhere in a scene file, checked before any field: a backstop so that no
#: message prints more (each field's own limit is smaller: MAX_TEXT, MAX_PATH_CHARS, 200 for an
#: expression).
MAX_SCENE_STRING = 1 << 16
#: Deepest nesting of tables and arrays in a scene file: its deepest is 4 (``[[panels]]``, ``zoom``,
#: ``xlim``); Python's TOML reader recurses once per level and fails near 500.
MAX_SCENE_DEPTH = 16
#: Most parts of one dotted key (``a.b.c = 1``; a scene's have at most 3): Python's TOML reader takes
#: time and memory quadratic in them (100,000 parts: 8 GB).
MAX_KEY_PARTS = 16
#: Largest figure canvas, in pixels (dpi^2 x width x height in inches): Agg holds 4 bytes per pixel,
#: so 150 million is 600 MB and ~10 s of savefig. The largest example figure has 3.9 million; the
#: limit allows 600 dpi at 19 x 12 inches, or 1200 dpi at 10 x 12.
MAX_CANVAS_PIXELS = 150_000_000
#: Integers beyond a double (TOML's are 64-bit; Python's reader takes any) are refused before any
#: field sees them: a field's own range check names its range, but no message should print a
#: 10,000-digit number (Python refuses to, beyond 4300 digits).
_MAX_INT_BITS = 1024


def real(where: str, value, lo=None, hi=None, lo_open=False, hi_open=False) -> float:
    """A finite real number (or an expression string of numbers, pi, OMEGA_G) inside a range.

    Parameters
    ----------
    where : str
        The key, for the message (``scene.panels[0].eps``).
    value : object
        What the file holds there.
    lo, hi : float, optional
        Bounds (None: unbounded).
    lo_open, hi_open : bool, optional
        Whether each bound is excluded.

    Returns
    -------
    float

    Raises
    ------
    ValueError
        Naming the key, the value and the allowed range.
    """
    if isinstance(value, bool):
        raise ValueError(f"{where} must be a number, got {value!r}")
    if isinstance(value, str):
        if len(value) > _MAX_EXPR:
            raise ValueError(f"{where}: expression of {len(value)} characters; allowed: at most {_MAX_EXPR}")
        try:
            v = float(evaluate(ast.parse(value, mode="eval")))
        except (SyntaxError, ValueError, ZeroDivisionError, OverflowError, TypeError, RecursionError, MemoryError) as e:
            # why, in a few words: "division by zero", "math domain error", a number too large, ...
            why = {
                SyntaxError: "not an expression",
                ZeroDivisionError: "division by zero",
                OverflowError: "a number too large for a double",
                RecursionError: "nested too deeply",
                MemoryError: "nested too deeply",
            }.get(type(e), str(e) or type(e).__name__)
            raise ValueError(
                f"{where}: cannot evaluate {value!r} ({why}); allowed: a number or an expression of numbers, "
                f"pi, OMEGA_G, + - * / ** and sqrt, sin, cos, acos"
            ) from None
    elif isinstance(value, (int, float)):
        try:
            v = float(value)
        except OverflowError:
            raise ValueError(
                f"{where} is an integer of {value.bit_length()} bits, beyond the range of a double; "
                f"allowed: a finite number"
            ) from None
    else:
        raise ValueError(f"{where} must be a number, got {value!r}")
    if not math.isfinite(v):
        raise ValueError(f"{where} must be finite, got {value!r}")
    bad_lo = lo is not None and (v <= lo if lo_open else v < lo)
    bad_hi = hi is not None and (v >= hi if hi_open else v > hi)
    if bad_lo or bad_hi:
        left = "(" if lo_open or lo is None else "["
        right = ")" if hi_open or hi is None else "]"
        rng = f"{left}{'-inf' if lo is None else lo}, {'inf' if hi is None else hi}{right}"
        raise ValueError(f"{where} = {value!r} is out of range; allowed: {rng}")
    return v


def integer(where: str, value, lo=None, hi=None) -> int:
    """An integer (not a bool) in ``[lo, hi]``.

    Parameters
    ----------
    where : str
        The key, for the message.
    value : object
        What the file holds there.
    lo, hi : int, optional
        Bounds, both included (None: unbounded).

    Returns
    -------
    int

    Raises
    ------
    ValueError
        Naming the key, the value and the allowed range.
    """
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"{where} must be an integer, got {value!r}")
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        raise ValueError(f"{where} = {value!r} is out of range; allowed: [{lo}, {'inf' if hi is None else hi}]")
    return int(value)


def boolean(where: str, value) -> bool:
    """``true`` or ``false``.

    Parameters
    ----------
    where : str
        The key, for the message.
    value : object
        What the file holds there.

    Returns
    -------
    bool

    Raises
    ------
    ValueError
        For anything else.
    """
    if not isinstance(value, bool):
        raise ValueError(f"{where} must be true or false, got {value!r}")
    return value


def text(where: str, value, choices=None, limit: int = MAX_TEXT) -> str:
    """A non-empty string of at most ``limit`` characters, one of ``choices`` if given.

    Parameters
    ----------
    where : str
        The key, for the message.
    value : object
        What the file holds there.
    choices : sequence of str, optional
        The allowed values.
    limit : int, optional
        Longest string (default :data:`MAX_TEXT`).

    Returns
    -------
    str

    Raises
    ------
    ValueError
        Naming the key, the value and the allowed values.
    """
    if not isinstance(value, str) or not value.strip():
        raise ValueError(f"{where} must be a non-empty string, got {value!r}")
    if len(value) > limit:
        raise ValueError(f"{where}: a string of {len(value)} characters; allowed: at most {limit}")
    if not value.isascii():  # a file from elsewhere (a result) may hold what no TOML file can
        try:
            value.encode("utf-8")
        except UnicodeEncodeError as e:
            raise ValueError(f"{where}: a lone surrogate at character {e.start}; allowed: Unicode text") from None
    if choices is not None and value not in choices:
        raise ValueError(f"{where} = {value!r} is not allowed; allowed: {', '.join(repr(c) for c in choices)}")
    return value


def drawn_text(where: str, value, limit: int = MAX_TEXT) -> str:
    """:func:`text` that matplotlib can draw: its ``$...$`` math parses (checked when the scene is
    read, not when the figure is drawn after the whole computation).

    Parameters
    ----------
    where : str
        The key, for the message.
    value : object
        What the file holds there.
    limit : int, optional
        Longest string (default :data:`MAX_TEXT`).

    Returns
    -------
    str

    Raises
    ------
    ValueError
        Naming the key, the value and why matplotlib's mathtext refuses it.
    """
    from matplotlib import cbook
    from matplotlib.mathtext import MathTextParser

    s = text(where, value, limit=limit)
    if cbook.is_math_text(s):  # an even number of unescaped $: matplotlib parses it as math
        try:
            MathTextParser("path").parse(s)
        except ValueError as e:
            why = next((line.strip() for line in reversed(str(e).splitlines()) if line.strip()), "")
            raise ValueError(
                f"{where} = {value!r}: its math ($...$) does not parse in matplotlib's mathtext ({why}); "
                "allowed: plain text, or mathtext between $ signs (a literal dollar as \\$)"
            ) from None
    return s


def color(where: str, value) -> str:
    """A colour matplotlib understands, checked when the scene is read (not at savefig time).

    Parameters
    ----------
    where : str
        The key, for the message.
    value : object
        What the file holds there.

    Returns
    -------
    str

    Raises
    ------
    ValueError
        Naming the key, the value and the colours allowed.
    """
    from matplotlib.colors import is_color_like

    v = text(where, value)
    if not is_color_like(v):
        raise ValueError(
            f"{where} = {value!r} is not a matplotlib colour; allowed: a name ('red'), 'C0'..'C9', or hex '#rrggbb'"
        )
    return v


def pair(where: str, value, increasing=True) -> tuple:
    """Two numbers ``[low, high]`` (increasing unless told otherwise).

    Parameters
    ----------
    where : str
        The key, for the message.
    value : object
        What the file holds there.
    increasing : bool, optional
        Require ``low < high``.

    Returns
    -------
    tuple of float

    Raises
    ------
    ValueError
        Naming the key and the value.
    """
    if not isinstance(value, list) or len(value) != 2:
        raise ValueError(f"{where} must be a list of two numbers [low, high], got {value!r}")
    a, b = real(f"{where}[0]", value[0]), real(f"{where}[1]", value[1])
    if increasing and not a < b:
        raise ValueError(f"{where} = {value!r} must be increasing (low < high)")
    return (a, b)


def size(where: str, value) -> tuple:
    """A figure size ``[width, height]`` in inches, each in [0.5, 60].

    Parameters
    ----------
    where : str
        The key, for the message.
    value : object
        What the file holds there.

    Returns
    -------
    tuple of float

    Raises
    ------
    ValueError
        Naming the key, the value and the allowed range.
    """
    if not isinstance(value, list) or len(value) != 2:
        raise ValueError(f"{where} must be [width, height] in inches, got {value!r}")
    return tuple(real(f"{where}[{i}]", v, lo=0.5, hi=60.0) for i, v in enumerate(value))


def table(where: str, value) -> dict:
    """A TOML table.

    Parameters
    ----------
    where : str
        The key, for the message.
    value : object
        What the file holds there.

    Returns
    -------
    dict

    Raises
    ------
    ValueError
        For anything else.
    """
    if not isinstance(value, dict):
        raise ValueError(f"{where} must be a table, got {value!r}")
    return value


def tables(where: str, value, what: str) -> list:
    """A non-empty array of tables (``[[what]]``) of at most :data:`MAX_PANELS` entries (one figure).

    Parameters
    ----------
    where : str
        The key, for the message.
    value : object
        What the file holds there.
    what : str
        What the entries are (``"panels"``), for the message.

    Returns
    -------
    list

    Raises
    ------
    ValueError
        For anything else, or too many entries.
    """
    if not isinstance(value, list) or not value:
        raise ValueError(f"{where} must be a non-empty array of tables ([[{what}]]), got {value!r}")
    if len(value) > MAX_PANELS:
        raise ValueError(f"{where}: {len(value)} {what}; allowed: at most {MAX_PANELS} (one figure)")
    return value


def distinct_reals(where: str, value, **bounds) -> tuple:
    """A non-empty list of distinct numbers (eps values), at most :data:`MAX_SERIES_POINTS` of them.

    Parameters
    ----------
    where : str
        The key, for the message.
    value : object
        What the file holds there.
    **bounds
        The range of each value (``lo``, ``hi``, ``lo_open``, ``hi_open`` of :func:`real`).

    Returns
    -------
    tuple of float

    Raises
    ------
    ValueError
        Naming the key, the value and what is allowed.
    """
    if not isinstance(value, list) or not value:
        raise ValueError(f"{where} must be a non-empty list of numbers, got {value!r}")
    if len(value) > MAX_SERIES_POINTS:
        raise ValueError(f"{where}: {len(value)} values; allowed: at most {MAX_SERIES_POINTS} (use a sweep for more)")
    eps = tuple(real(f"{where}[{i}]", e, **bounds) for i, e in enumerate(value))
    if len(set(eps)) != len(eps):
        raise ValueError(f"{where} = {value!r} lists a value twice")
    return eps


def check_keys(where: str, table: dict, allowed, required=()) -> None:
    """A table's keys: none unknown, every required one present.

    Parameters
    ----------
    where : str
        The table, for the message.
    table : dict
        The table.
    allowed : sequence of str
        Its keys, in the order the message lists them.
    required : sequence of str, optional
        The keys it must have.

    Raises
    ------
    ValueError
        Naming the unknown or missing key and the allowed keys.
    """
    unknown = [k for k in table if k not in allowed]
    if unknown:
        raise ValueError(
            f"{where}: unknown key(s) {', '.join(repr(k) for k in unknown)}; allowed keys: {', '.join(allowed)}"
        )
    for k in required:
        if k not in table:
            raise ValueError(f"{where}: missing required key {k!r}; allowed keys: {', '.join(allowed)}")
