"""TOML -> validated spec: every key at every level checked, before anything is computed.

One generic reader for every kind: the document's limits (size, nesting, key and string lengths,
integers) first, then the kind (:mod:`hovering.scenes.registry`), then each key of the file read
as its kind's spec declares it (:mod:`hovering.scenes.fields`: default, range and choices kept in
each field), then the figure's canvas. An unknown, missing or out-of-range key is a
``ValueError`` naming it (as ``panels[1].zoom.of``), the value and what is allowed. Values may be
expressions of numbers, ``pi`` and ``OMEGA_G`` (:mod:`hovering.scenes.values`: a whitelisted
arithmetic evaluator over the parsed syntax tree, never ``eval``). Output paths are checked here
too (format, writable directory), so a scene that cannot be written fails in a second, not after
its simulation.
"""

from __future__ import annotations

import dataclasses
import math
import os
import re
import tomllib
from pathlib import Path

from . import fields, kinds, registry  # noqa: F401 (kinds: every kind of the package registered)
from .base import SceneSpec, check_canvas, output_dirs
from .values import (  # noqa: F401 (re-exported: the limits and checks were defined here)
    _MAX_INT_BITS,
    MAX_CANVAS_PIXELS,
    MAX_KEY_PARTS,
    MAX_PANELS,
    MAX_PATH_CHARS,
    MAX_SCENE_BYTES,
    MAX_SCENE_DEPTH,
    MAX_SCENE_STRING,
    MAX_SERIES_POINTS,
    MAX_TEXT,
    boolean,
    check_keys,
    color,
    distinct_reals,
    evaluate,
    integer,
    pair,
    real,
    size,
    table,
    tables,
    text,
)

__all__ = [
    "load_scene",
    "parse_scene",
    "check_spec",
    "scene_table",
    "output_dirs",
    "MAX_PANELS",
    "MAX_SERIES_POINTS",
    "MAX_SCENE_BYTES",
    "MAX_TEXT",
    "MAX_PATH_CHARS",
    "MAX_SCENE_STRING",
    "MAX_SCENE_DEPTH",
    "MAX_KEY_PARTS",
    "MAX_CANVAS_PIXELS",
]

# One value's checks live in .values (the kinds call them too); the old private names stay here.
_eval_expr, _real, _int, _bool, _str, _color, _pair, _table, _tables, _eps_list, _check_keys, _size = (
    evaluate,
    real,
    integer,
    boolean,
    text,
    color,
    pair,
    table,
    tables,
    distinct_reals,
    check_keys,
    size,
)


def parse_scene(data: dict, path: os.PathLike | None = None, check_output: bool = True) -> SceneSpec:
    """Validate a scene given as a dict (the parsed TOML) and build its spec.

    Parameters
    ----------
    data : dict
        The parsed TOML document.
    path : path-like, optional
        Where it came from (used in messages and as the scene name).
    check_output : bool, optional
        Check that ``output`` can be written (format, writable directory, under the scene's
        folder or the working directory: :func:`output_dirs`); off for uses that write nothing
        (the explorer) or write elsewhere (``--out``).

    Returns
    -------
    SceneSpec
        The spec of the scene's kind (:attr:`hovering.scenes.registry.Kind.spec`).

    Raises
    ------
    ValueError
        For an unknown key (at any level), a missing required key or a bad value; the message
        names the key (as ``panels[1].zoom.of``), the value and the allowed keys or range.
    """
    p = Path(path) if path is not None else None
    where = p.name if p is not None else "scene"
    _check_document(where, data)
    spec = _parse_scene(data, p, where, check_output)
    check_canvas(where, spec)
    return spec


def _check_document(where: str, data) -> None:
    """Limits of the parsed document as a whole, before any field: nesting depth, string and key
    lengths, integers of 64 bits (TOML's). Iterative, so a deep document cannot exhaust the stack."""
    stack = [(data, where, 0)]
    while stack:
        node, at, depth = stack.pop()
        if isinstance(node, (dict, list)):
            if depth > MAX_SCENE_DEPTH:
                raise ValueError(
                    f"{at}: tables and arrays nested more than {MAX_SCENE_DEPTH} deep; allowed: at most "
                    f"{MAX_SCENE_DEPTH} levels"
                )
            items = node.items() if isinstance(node, dict) else enumerate(node)
            for k, v in items:
                if isinstance(k, str) and len(k) > MAX_SCENE_STRING:
                    raise ValueError(f"{at}: a key of {len(k)} characters; allowed: at most {MAX_SCENE_STRING}")
                stack.append((v, f"{at}.{k}" if isinstance(node, dict) else f"{at}[{k}]", depth + 1))
        elif isinstance(node, str) and len(node) > MAX_SCENE_STRING:
            raise ValueError(f"{at}: a string of {len(node)} characters; allowed: at most {MAX_SCENE_STRING}")
        elif isinstance(node, int) and not isinstance(node, bool) and node.bit_length() > _MAX_INT_BITS:
            raise ValueError(
                f"{at} = (an integer of {node.bit_length()} bits) is out of range; allowed: integers in "
                f"[-2**63, 2**63 - 1] (TOML's 64-bit integers)"
            )


def _parse_scene(data, p: Path | None, where: str, check_output: bool) -> SceneSpec:
    data = table(where, data)
    if "kind" not in data:
        raise ValueError(
            f"{where}: missing required key 'kind'; allowed: {', '.join(repr(k) for k in registry.names())}"
        )
    kind = registry.get(text(f"{where}.kind", data["kind"], registry.names()))
    name = p.stem if p is not None else "scene"
    known = dict(path=p, name=name, kind=kind.name, **kind.sets)
    reading = fields.Reading(where, data, known, kind=kind, options=dict(check_output=check_output, path=p))
    return kind.spec(**fields.read_values(kind.spec, where, data, reading, hook=kind.check))


def load_scene(path: os.PathLike, check_output: bool = True) -> SceneSpec:
    """Read and validate a scene file (TOML).

    Parameters
    ----------
    path : path-like
        The ``.toml`` file.
    check_output : bool, optional
        Check the scene's output path (see :func:`parse_scene`).

    Returns
    -------
    SceneSpec

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    ValueError
        For a TOML syntax error, an unknown key (at any level), a missing required key or a bad
        value: the message names the key, the value and the allowed keys or range.
    """
    p = Path(path)
    if p.exists() and not p.is_file():
        raise ValueError(f"{p}: not a regular file (a scene is a .toml file)")
    with open(p, "rb") as f:
        raw = f.read(MAX_SCENE_BYTES + 1)
    if len(raw) > MAX_SCENE_BYTES:
        raise ValueError(f"{p.name}: larger than {MAX_SCENE_BYTES} bytes; a scene file is a few hundred")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise ValueError(f"{p.name}: not UTF-8 text (TOML files are UTF-8): byte {e.start}") from None
    _check_toml_text(p.name, text)
    try:
        data = tomllib.loads(text)
    except ValueError as e:  # TOMLDecodeError, or a number Python will not convert
        raise ValueError(f"{p.name}: not valid TOML: {e}") from None
    except RecursionError:  # _check_toml_text bounds the nesting; kept for a text it misjudged
        raise ValueError(
            f"{p.name}: arrays or tables nested too deeply; allowed: at most {MAX_SCENE_DEPTH} levels"
        ) from None
    return parse_scene(data, p, check_output=check_output)


# TOML strings and comments, skipped when counting brackets and dots (multi-line strings first).
_TOML_SKIP = re.compile(
    r'"""(?:[^"\\]|\\.|"(?!""))*"""|\'\'\'[\s\S]*?\'\'\'|"(?:[^"\\\n]|\\.)*"|\'[^\'\n]*\'|#[^\n]*', re.S
)
# A dotted key of more than MAX_KEY_PARTS parts, where a key can start (possessive: linear time).
_KEY_PART = r'(?:[A-Za-z0-9_-]++|"")'
_LONG_KEY = re.compile(rf"(?:^|[\[{{,])\[?[ \t]*+{_KEY_PART}(?:[ \t]*+\.[ \t]*+{_KEY_PART}){{{MAX_KEY_PARTS},}}", re.M)


# A run of digits longer than any number a double holds (2**1024 has 309); Python's own integer
# conversion refuses beyond 4300 digits with a message that names no key.
_MAX_DIGITS = 400
_LONG_NUMBER = re.compile(rf"[0-9][0-9_]{{{_MAX_DIGITS},}}")


def _check_toml_text(name: str, text: str) -> None:
    """Before Python's TOML reader sees the text: no number of more than _MAX_DIGITS digits, no
    dotted key of more than MAX_KEY_PARTS parts, no arrays or inline tables nested more than
    MAX_SCENE_DEPTH deep; each named by its line and key."""
    # Strings become "" (newlines kept, so line numbers stay): brackets and dots in them do not count.
    skel = _TOML_SKIP.sub(lambda m: "#" if m.group()[0] == "#" else '""' + "\n" * m.group().count("\n"), text)

    def line_of(pos: int) -> tuple:
        start = skel.rfind("\n", 0, pos) + 1
        key = re.match(r"\s*([^=\s][^=]*?)\s*=", skel[start:pos])
        return skel.count("\n", 0, pos) + 1, (key.group(1)[:60] if key else skel[start:pos].strip()[:60])

    m = _LONG_NUMBER.search(skel)
    if m:
        line, key = line_of(m.start())
        raise ValueError(
            f"{name}: line {line}: {key!r} has a number of {len(m.group())} digits; allowed: numbers "
            f"within the range of a double (at most {_MAX_DIGITS} digits)"
        )
    m = _LONG_KEY.search(skel)
    if m:
        line, _ = line_of(m.start())
        raise ValueError(
            f"{name}: line {line}: the key {m.group().lstrip('[{, ')[:60]!r}... has more than "
            f"{MAX_KEY_PARTS} dotted parts; allowed: at most {MAX_KEY_PARTS}"
        )
    depth = outer = 0
    for b in re.finditer(r"[\[\]{}]", skel):
        if b.group() in "[{":
            depth += 1
            outer = b.start() if depth == 1 else outer
            if depth > MAX_SCENE_DEPTH:
                line, key = line_of(outer)
                raise ValueError(
                    f"{name}: line {line}: {key!r} nests arrays or tables more than {MAX_SCENE_DEPTH} "
                    f"deep; allowed: at most {MAX_SCENE_DEPTH} levels"
                )
        else:
            depth = max(depth - 1, 0)


# ------------------------------------------------------------------------------------------------
# A spec read from elsewhere (a saved result): the same checks as a scene file's


def scene_table(spec: SceneSpec) -> dict:
    """The scene file (as the parsed TOML dict) that :func:`parse_scene` reads as ``spec``.

    Parameters
    ----------
    spec : SceneSpec
        A scene spec (e.g. one read from a saved result).

    Returns
    -------
    dict
        Every value written out (defaults included; the maps of panels and series resolved);
        expressions appear as their values.
    """
    return fields.write(spec, registry.get(spec.kind))


def _first_difference(a, b, where: str):
    """Where two specs first differ (None if they agree; floats within 1e-12 relative agree, so that a
    value derived again, e.g. a golden-family Omega0, may differ in its last bits on another machine)."""
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        if type(a) is not type(b):
            return where, a, b
        for f in dataclasses.fields(a):
            d = _first_difference(getattr(a, f.name), getattr(b, f.name), f"{where}.{f.name}")
            if d:
                return d
        return None
    if isinstance(a, (tuple, list)):
        if type(a) is not type(b) or len(a) != len(b):
            return where, a, b
        for i, (x, y) in enumerate(zip(a, b)):
            d = _first_difference(x, y, f"{where}[{i}]")
            if d:
                return d
        return None
    if isinstance(a, float) and isinstance(b, float):
        return None if a == b or math.isclose(a, b, rel_tol=1e-12, abs_tol=0.0) else (where, a, b)
    return None if type(a) is type(b) and a == b else (where, a, b)


def check_spec(spec: SceneSpec) -> SceneSpec:
    """Check a scene spec from elsewhere (a saved result) with the checks a scene file gets: called
    by whoever loads one (:func:`hovering.scenes.load_result`, and through it ``redraw``).

    The spec is written out as its scene file (:func:`scene_table`) and read by :func:`parse_scene`
    (the output path is not checked: nothing is written to it); the spec read must be ``spec``,
    so every value is in range and of its type, and no field holds what a scene file cannot give.

    Parameters
    ----------
    spec : SceneSpec
        The spec.

    Returns
    -------
    SceneSpec
        ``spec``.

    Raises
    ------
    ValueError
        Naming the field and the allowed values, as for a scene file.
    """
    if not isinstance(spec, SceneSpec) or spec.kind not in registry.names():
        raise ValueError(
            f"a scene spec of kind {getattr(spec, 'kind', None)!r}; allowed kinds: {', '.join(registry.names())}"
        )
    if spec.path is not None and not isinstance(spec.path, Path):
        raise ValueError(f"scene.path must be a path, got {spec.path!r}")
    try:
        table = scene_table(spec)
    except (AttributeError, TypeError) as e:  # a field of another type than the kind has
        raise ValueError(f"a {spec.kind} scene spec with a field of the wrong type ({e})") from None
    again = parse_scene(table, spec.path, check_output=False)
    d = _first_difference(spec, again, "scene")
    if d is not None:
        where, a, b = d
        raise ValueError(f"{where} = {_clip(a)} is not what a scene file can give (its other values give {_clip(b)})")
    return spec


def _clip(value) -> str:
    r = repr(value)
    return r if len(r) <= 80 else r[:77] + "..."
