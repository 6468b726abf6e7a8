"""Results as NPZ files: a tree of dataclasses, arrays and plain values, saved without pickle.

An object is written as arrays (each under a path-like key) plus one JSON document that records
the tree's shape and every non-array value. Reading rebuilds the same types. Only types of this
package are rebuilt (a file names the classes it holds, so reading an untrusted file must not
import or call anything else: a name must resolve to a class defined in a ``hovering`` module, of
the kind the file says it is), and arrays are loaded with ``allow_pickle=False``.

Types take part by defining ``_to_record(self) -> dict`` and a classmethod
``_from_record(cls, record)`` (maps, systems and potentials: their constructor arguments, so that
reading runs the constructor's checks again), by being dataclasses (results: their fields), or
enums. A type with a record is written by its record even when it is a dataclass.

Reading treats the file as untrusted (:mod:`hovering._untrusted`, docs/threat-model.md): every size
it declares is checked against a stated limit before it is read, only the arrays the tree names
are read, records are rebuilt from their stored parameters without computing, and every dataclass
field is checked against its declared type (and the class's own ``_validate_loaded`` checks).

The public entry points are :func:`hovering.save`, :func:`hovering.load` and the ``save`` method
that :class:`Saveable` gives the result types.
"""

from __future__ import annotations

import dataclasses
import enum
import functools
import importlib
import json
import math
import os
import re
import typing
import zipfile
from pathlib import Path, PurePath
from typing import Any

import numpy as np

from .._version import __version__
from . import untrusted as _untrusted
from .output import replacing
from .provenance import provenance
from .untrusted import _META_KEY, FORMAT, is_result_file  # noqa: F401 (the format's names, re-exported)

__all__ = ["FORMAT", "Saveable", "from_tree", "load", "record_key", "save", "saved_as", "to_tree"]

_MAX_INT_BITS = _untrusted.MAX_INT_BITS


def saved_as(name: str):
    """Class decorator: the name files give a class that moved after files were written naming it.

    A file names each class ``module:QualName``; a class that moved keeps the name it was written
    under (its old module re-exports it), so files written before and after the move are the same
    and each version reads the other's. Only the class itself carries the name (a subclass is
    written under its own).

    Parameters
    ----------
    name : str
        ``"hovering.module:QualName"``, where the class can still be imported from.

    Returns
    -------
    callable
        The decorator (returns the class unchanged but for the name).
    """

    def mark(cls):
        cls._saved_as = name
        return cls

    return mark


def _type_name(cls) -> str:
    return cls.__dict__.get("_saved_as") or f"{cls.__module__}:{cls.__qualname__}"


def _resolve(name, kind: str = "any"):
    """The class a file names, refused (ValueError) unless it is one of hovering's own of that kind.

    ``kind``: ``"enum"``, ``"dataclass"``, ``"record"`` (has ``_from_record``) or ``"any"``.
    """
    if not isinstance(name, str) or name.count(":") != 1:
        raise ValueError(f"malformed result file: a type name must be 'module:QualName', got {name!r}")
    module, _, qual = name.partition(":")
    if not (module == "hovering" or module.startswith("hovering.")):
        raise ValueError(f"refusing to rebuild type {name!r}: only hovering's own types are read from a file")
    parts = module.split(".") + qual.split(".")
    if not all(p.isidentifier() and not p.startswith("__") for p in parts):
        raise ValueError(f"refusing to rebuild type {name!r}: not the name of a hovering class")
    try:
        obj = importlib.import_module(module)
        for part in qual.split("."):
            obj = getattr(obj, part)
    except (ImportError, AttributeError):
        raise ValueError(f"cannot rebuild type {name!r}: this version of hovering has no such class") from None
    # The name must lead to a class defined where the name says, or to one that says it was written
    # under this name (saved_as), not, e.g., to a function that a hovering module imported from elsewhere.
    if not (isinstance(obj, type) and _type_name(obj) == name):
        raise ValueError(f"refusing to rebuild type {name!r}: it does not name a class defined in hovering")
    ok = {
        "enum": lambda c: issubclass(c, enum.Enum),
        "dataclass": dataclasses.is_dataclass,
        "record": lambda c: callable(getattr(c, "_from_record", None)),
        "any": lambda c: True,
    }[kind]
    if not ok(obj):
        raise ValueError(f"refusing to rebuild type {name!r} as a {kind}: it is not one")
    return obj


def _saveable_name(cls, kind: str, key: str) -> str:
    """The name under which ``cls`` is written; a TypeError unless reading it back gives ``cls``."""
    name = _type_name(cls)
    try:
        back = _resolve(name, kind)
    except ValueError:
        back = None
    if back is not cls:
        raise TypeError(
            f"{key}: cannot save a {cls.__module__}.{cls.__qualname__} to NPZ: only hovering's own classes "
            "(importable by name) are written, so that reading a file never imports anything else"
        )
    return name


#: Longest array member name (UTF-8 bytes) taken from a tree path; a longer path, or one a zip
#: name cannot hold exactly (NUL and other control characters, lone surrogates), gets a short name.
_MAX_NAME = 200
_UNSAFE_NAME = re.compile(r"[\x00-\x1f\x7f\ud800-\udfff]")


def _put(arrays: dict, key: str, a: np.ndarray) -> str:
    """Store ``a`` under a member name made from ``key`` and return that name (unique: dict keys may
    contain the separators of another path). The tree records the name, so any name reads back; a
    path a zip member name cannot hold exactly (zip readers cut names at NUL) gets ``#n`` instead."""
    if (
        _UNSAFE_NAME.search(key)
        or len(key.encode("utf-8", "surrogatepass")) > _MAX_NAME
        or not _untrusted.safe_member_name(f"{key}.npy")
    ):  # e.g. a dict key "a/../b": load refuses it
        key = f"#{len(arrays)}"
    k, i = key, 1
    while k in arrays or k == _META_KEY:
        k, i = f"{key}~{i}", i + 1
    arrays[k] = a
    return k


def to_tree(obj: Any, arrays: dict, key: str = "root"):
    """JSON-able description of ``obj``; its arrays go into ``arrays`` under path-like keys.

    Parameters
    ----------
    obj : object
        None, bool, str, int, float (NumPy scalars included), an enum, an ndarray, a dataclass, an
        object with ``_to_record``, or a dict, list or tuple of these.
    arrays : dict
        Receives the arrays (key -> ndarray).
    key : str, optional
        Path of ``obj`` in the tree (array keys and messages).

    Returns
    -------
    object
        A JSON-able tree.

    Raises
    ------
    TypeError
        For anything else, naming its path and type.
    """
    if obj is None or isinstance(obj, (bool, str)):
        return obj
    if isinstance(obj, PurePath):
        return {"__path__": str(obj)}
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, enum.Enum):
        return {"__enum__": _saveable_name(type(obj), "enum", key), "value": obj.value}
    if isinstance(obj, (int, np.integer)):
        v = int(obj)
        if v.bit_length() > _MAX_INT_BITS:  # beyond what str(int) and JSON read back (sys.get_int_max_str_digits)
            raise ValueError(
                f"{key}: an integer of {v.bit_length()} bits cannot be saved (at most {_MAX_INT_BITS}); "
                "save it as a string"
            )
        return v
    if isinstance(obj, (float, np.floating)):
        x = float(obj)
        return x if math.isfinite(x) else {"__float__": repr(x)}
    if isinstance(obj, np.ndarray):
        a = obj
        if a.dtype == object:
            # Object arrays would need pickle; string arrays (itineraries) become fixed-width text.
            if all(isinstance(v, str) for v in a.flat):
                # NumPy's fixed-width text drops trailing NULs: such a string would not read back.
                if any(v.endswith("\0") for v in a.flat):
                    raise ValueError(
                        f"{key}: a string ending in NUL ('\\0') cannot be saved in an array of "
                        "strings (fixed-width text drops trailing NULs)"
                    )
                a = a.astype(str)
            else:
                raise TypeError(f"{key}: arrays of Python objects cannot be saved without pickle")
        elif a.dtype.hasobject:  # a structured dtype with object fields: pickled, which load refuses
            raise TypeError(
                f"{key}: arrays whose dtype holds Python objects ({a.dtype}) cannot be saved without pickle"
            )
        elif not _untrusted.plain_dtype(a.dtype):  # load reads plain dtypes only
            raise TypeError(
                f"{key}: arrays of dtype {a.dtype} cannot be saved; allowed: booleans, integers, floats, "
                "complex numbers and text"
            )
        return {"__array__": _put(arrays, key, a), "object": obj.dtype == object}
    if hasattr(obj, "_to_record"):
        try:  # first: it may refuse with a message of its own (Python code)
            record = obj._to_record()
        except TypeError as e:
            raise TypeError(f"{key}: {e}") from None
        name = _saveable_name(type(obj), "record", key)
        if not isinstance(record, dict):
            raise TypeError(f"{key}: {type(obj).__name__}._to_record() must return a dict, got {type(record).__name__}")
        return {"__record__": name, "data": to_tree(record, arrays, f"{key}@")}
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        name = _saveable_name(type(obj), "dataclass", key)
        fields = {f.name: to_tree(getattr(obj, f.name), arrays, f"{key}.{f.name}") for f in dataclasses.fields(obj)}
        return {"__dataclass__": name, "fields": fields}
    if isinstance(obj, dict):
        if all(isinstance(k, str) for k in obj):
            return {"__dict__": {k: to_tree(v, arrays, f"{key}.{k}") for k, v in obj.items()}}
        items = list(obj.items())
        return {
            "__items__": [
                [to_tree(k, arrays, f"{key}#k{i}"), to_tree(v, arrays, f"{key}#{i}")] for i, (k, v) in enumerate(items)
            ]
        }
    if isinstance(obj, (list, tuple)):
        tag = "__tuple__" if isinstance(obj, tuple) else "__list__"
        return {tag: [to_tree(v, arrays, f"{key}[{i}]") for i, v in enumerate(obj)]}
    raise TypeError(
        f"{key}: cannot save a {type(obj).__name__} to NPZ (not an array, number, string, dataclass or hovering object)"
    )


def record_key(obj: Any) -> Any:
    """The canonical record of ``obj`` as plain JSON values: what a checkpoint keys it by.

    The tree :func:`to_tree` writes to NPZ (each class by its one record, ``_to_record``), with
    every array inline (its dtype, shape and values) and a record's caches left out: a class names
    in ``_RECORD_CACHE`` the entries of its record that are derived from the others (kept in a
    file only to spare the work), which must not make two equal objects two keys.

    Parameters
    ----------
    obj : object
        Anything :func:`to_tree` takes.

    Returns
    -------
    object
        JSON-able (floats may be non-finite: a checkpoint writes those as strings).
    """
    arrays: dict = {}
    tree = to_tree(obj, arrays)

    def inline(t):
        if isinstance(t, list):
            return [inline(v) for v in t]
        if not isinstance(t, dict):
            return t
        if "__array__" in t and set(t) == {"__array__", "object"}:
            a = arrays[t["__array__"]]
            return {"__array__": str(a.dtype), "shape": list(a.shape), "values": a.ravel().tolist()}
        if "__record__" in t:
            cache = getattr(_resolve(t["__record__"], "record"), "_RECORD_CACHE", ())
            data = t["data"]
            if cache and isinstance(data, dict) and "__dict__" in data:
                data = {"__dict__": {k: v for k, v in data["__dict__"].items() if k not in cache}}
            return {"__record__": t["__record__"], "data": inline(data)}
        return {k: inline(v) for k, v in t.items()}

    return inline(tree)


@functools.cache
def _field_types(cls) -> dict:
    try:
        return typing.get_type_hints(cls)
    except Exception:  # an annotation that does not resolve: its fields are not type-checked
        return {}


def _type_name_of(hint) -> str:
    args = typing.get_args(hint)
    if typing.get_origin(hint) is typing.Union:
        return " or ".join("None" if a is type(None) else _type_name_of(a) for a in args)
    return getattr(hint, "__name__", str(hint))


def _conforms(value, hint) -> bool:
    """Whether a value read from a file has a field's declared type (numbers: int where float is declared)."""
    if hint is None or hint is Any or hint is object:
        return True
    if typing.get_origin(hint) is typing.Union:
        return any(_conforms(value, a) for a in typing.get_args(hint))
    if hint is type(None):
        return value is None
    if hint is float:
        return isinstance(value, (int, float)) and not isinstance(value, bool)
    if hint is int:
        return isinstance(value, int) and not isinstance(value, bool)
    if isinstance(hint, type):
        return isinstance(value, hint)
    return True  # a generic alias (list[str], ...): the class's _validate_loaded checks its items


def _dataclass_from_fields(cls, fields: dict, key: str = "root"):
    """A dataclass instance from its saved fields, without running ``__init__``/``__post_init__`` (no
    computation). Each field must have its declared type (None also where the default is None); a
    field missing from the file takes its default; a field without default missing, or a name that
    is not a field, is a ValueError. Then the class's ``_validate_loaded(self)``, if it has one,
    checks the values (a scene spec: the scene schema's checks)."""
    if not isinstance(fields, dict):
        raise ValueError(f"malformed result file: the fields of {cls.__qualname__} are not a mapping")
    known = {f.name: f for f in dataclasses.fields(cls)}
    unknown = sorted(set(fields) - set(known))
    if unknown:
        raise ValueError(
            f"the file's {cls.__qualname__} has fields {unknown} this version does not know (written by "
            "another version of hovering?)"
        )
    hints = _field_types(cls)
    obj = object.__new__(cls)
    for name, f in known.items():
        if name in fields:
            value = fields[name]
            if not (_conforms(value, hints.get(name)) or (value is None and f.default is None)):
                raise ValueError(
                    f"{key}.{name} must be of type {_type_name_of(hints[name])} (the type of "
                    f"{cls.__qualname__}.{name}), got {type(value).__name__}"
                )
        elif f.default is not dataclasses.MISSING:
            value = f.default
        elif f.default_factory is not dataclasses.MISSING:
            value = f.default_factory()
        else:
            raise ValueError(
                f"the file's {cls.__qualname__} lacks the field {name!r} (written by another version of hovering?)"
            )
        object.__setattr__(obj, name, value)
    check = getattr(cls, "_validate_loaded", None)
    if check is not None:
        try:
            check(obj)
        except ValueError as e:
            raise ValueError(f"{key}: {e}") from None
    return obj


def _array_refs(tree) -> dict:
    """The arrays a tree names (key -> its ``object`` flag), walked as :func:`from_tree` reads it."""
    refs, stack = {}, [tree]
    while stack:
        t = stack.pop()
        if isinstance(t, dict):
            if "__float__" in t or "__path__" in t or "__enum__" in t:
                continue
            if "__array__" in t:
                if isinstance(t["__array__"], str):
                    refs[t["__array__"]] = refs.get(t["__array__"], False) or t.get("object") is True
                continue
            for tag, part in (("__dataclass__", "fields"), ("__record__", "data"), ("__dict__", "__dict__")):
                if tag in t:
                    sub = t.get(part)
                    if part == "data":
                        stack.append(sub)
                    elif isinstance(sub, dict):
                        stack.extend(sub.values())
                    break
            else:
                for tag in ("__items__", "__tuple__", "__list__"):
                    if tag in t:
                        if isinstance(t[tag], list):
                            for v in t[tag]:
                                stack.extend(v if tag == "__items__" and isinstance(v, list) else [v])
                        break
    return refs


def _from_record(cls, name: str, data, key: str):
    """``cls._from_record(data)``, anything it raises a ValueError naming where the record is."""
    if not isinstance(data, dict):
        raise ValueError(f"{key}: malformed result file: the record of {name} is not a mapping")
    try:
        return cls._from_record(data)
    except ValueError as e:
        raise ValueError(f"{key}: {e}") from None
    except Exception as e:  # a missing or wrongly typed argument (TypeError, KeyError, OverflowError, ...)
        raise ValueError(f"{key}: malformed result file ({type(e).__name__}: {e})") from None


def from_tree(tree, arrays, key: str = "root"):
    """Inverse of :func:`to_tree`.

    Parameters
    ----------
    tree : object
        What :func:`to_tree` returned (after a JSON round trip).
    arrays : mapping
        The arrays it refers to.
    key : str, optional
        Path of ``tree`` (as :func:`to_tree` names it), for the messages.

    Returns
    -------
    object

    Raises
    ------
    ValueError
        For a malformed tree, a type that is not hovering's, a missing array, or a value a
        constructor or a field's type refuses, naming its path.
    """
    if tree is None or isinstance(tree, (bool, str, int, float)):
        return tree
    if not isinstance(tree, dict):
        raise ValueError(f"malformed result file: a bare {type(tree).__name__} in the tree at {key}")
    if "__float__" in tree:
        if tree["__float__"] not in ("nan", "inf", "-inf"):  # finite numbers are written as numbers
            raise ValueError(
                f"{key}: malformed result file: {{'__float__': {str(tree['__float__'])[:40]!r}}}; "
                "allowed: 'nan', 'inf', '-inf'"
            )
        return float(tree["__float__"])
    if "__path__" in tree:
        if not isinstance(tree["__path__"], str):
            raise ValueError(f"{key}: malformed result file: a path that is not a string")
        return Path(tree["__path__"])
    if "__enum__" in tree:
        cls = _resolve(tree["__enum__"], "enum")
        try:
            return cls(tree.get("value"))
        except (ValueError, TypeError):
            raise ValueError(
                f"{key}: {repr(tree.get('value'))[:40]} is not a {cls.__qualname__}; allowed: {[m.value for m in cls]}"
            ) from None
    if "__array__" in tree:
        k = tree["__array__"]
        if not isinstance(k, str) or k not in arrays:
            raise ValueError(f"malformed result file: the array {k!r} is missing")
        a, obj = arrays[k], tree.get("object", False)
        if not isinstance(obj, bool) or (obj and a.dtype.kind != "U"):
            raise ValueError(f"{key}: malformed result file: 'object' must be true only for an array of text")
        return a.astype(object) if obj else a
    if "__dataclass__" in tree:
        cls = _resolve(tree["__dataclass__"], "dataclass")
        fields = tree.get("fields")
        if not isinstance(fields, dict):
            raise ValueError(f"malformed result file: the fields of {tree['__dataclass__']} are not a mapping")
        return _dataclass_from_fields(
            cls, {name: from_tree(sub, arrays, f"{key}.{name}") for name, sub in fields.items()}, key
        )
    if "__record__" in tree:
        cls = _resolve(tree["__record__"], "record")
        return _from_record(cls, tree["__record__"], from_tree(tree.get("data"), arrays, f"{key}@"), key)
    if "__dict__" in tree:
        return {k: from_tree(v, arrays, f"{key}.{k}") for k, v in tree["__dict__"].items()}
    if "__items__" in tree:
        return {
            from_tree(k, arrays, f"{key}#k{i}"): from_tree(v, arrays, f"{key}#{i}")
            for i, (k, v) in enumerate(tree["__items__"])
        }
    if "__tuple__" in tree:
        return tuple(from_tree(v, arrays, f"{key}[{i}]") for i, v in enumerate(tree["__tuple__"]))
    if "__list__" in tree:
        return [from_tree(v, arrays, f"{key}[{i}]") for i, v in enumerate(tree["__list__"])]
    raise ValueError(f"malformed result file: unknown node {sorted(tree)[:10]} at {key}")


def _path(path, what: str) -> str:
    if not isinstance(path, (str, os.PathLike)):
        raise ValueError(f"{what} must be a file path (str or os.PathLike), got {path!r}")
    p = os.fspath(path)
    if isinstance(p, bytes):
        p = os.fsdecode(p)
    if not p.strip() or "\0" in p:
        raise ValueError(f"{what} must be a file path (non-empty, no NUL byte), got {path!r}")
    return p


def _check_meta(value, where: str = "meta") -> None:
    """JSON turns non-str dict keys into strings: refuse keys that would not read back."""
    if isinstance(value, dict):
        for k, v in value.items():
            if not isinstance(k, str):
                raise ValueError(
                    f"{where}: key {k!r} is a {type(k).__name__}; metadata keys must be str (JSON would "
                    "read it back as a string)"
                )
            _check_meta(v, f"{where}[{k!r}]")
    elif isinstance(value, (list, tuple)):
        for i, v in enumerate(value):
            _check_meta(v, f"{where}[{i}]")


def _seed_of(obj) -> int | None:
    """The random seed behind ``obj``: its own ``seed``, its scene's (scene results) or its flow
    measurement's (:class:`hovering.HoveringComparison`)."""
    for o in (obj, getattr(obj, "scene", None), getattr(obj, "flow", None)):
        seed = getattr(o, "seed", None)
        if isinstance(seed, int) and not isinstance(seed, bool):
            return seed
    return None


def save(obj: Any, path: os.PathLike, meta: dict | None = None) -> str:
    """Write ``obj`` (a result, map, system, ... or a dict/list/tuple of them) to an NPZ file.

    The file holds the arrays and one JSON document for everything else; nothing is pickled, so
    reading it (:func:`load`) never runs code from the file. The document also records what made
    the file (``provenance``: versions, build, machine; see :func:`hovering.show_versions`). The
    object is converted before the file is touched, and written to a temporary file that then
    replaces ``path``: an object that cannot be saved, or a failed write (a full disk, a kill),
    leaves an existing file as it was.

    Parameters
    ----------
    obj : object
        What to save: hovering's results, maps (TruncatedMap, TruncatedFamily, FlowMap), systems,
        sections, tangential curves, potentials (not those defined in Python), arrays, numbers,
        strings, and dicts, lists and tuples of these (dict keys of any of these types).
    path : str or os.PathLike
        The file; ``.npz`` is appended if missing.
    meta : dict, optional
        Metadata stored beside the object (returned by ``load(path, meta=True)``): dicts with str
        keys, lists, str, finite numbers, bool and None.

    Returns
    -------
    str
        The path written.

    Raises
    ------
    TypeError
        For an object that cannot be saved (e.g. a CustomPotential: Python code), naming where it is.
    ValueError
        For a path that is not a writable file path, metadata that is not JSON-able or has keys
        that would not read back (non-str keys), or a value that would not (a string ending in
        NUL in an array of strings, an integer beyond 10,000 bits), naming where it is.
    hovering._output.WriteError
        (a ValueError) When writing fails, e.g. ``no space left``; the previous file is intact.
    """
    path = _path(path, "path")
    if not path.endswith(".npz"):
        path += ".npz"
    if os.path.isdir(path):
        raise ValueError(f"path = {path!r} is a directory, not a file")
    if meta is not None and not isinstance(meta, dict):
        raise ValueError(f"meta must be a dict of JSON-able values, got {meta!r}")
    _check_meta(meta or {})
    arrays: dict = {}
    tree = to_tree(obj, arrays)
    doc = {
        "format": FORMAT,
        "version": __version__,
        "provenance": provenance(seed=_seed_of(obj)),
        "meta": meta or {},
        "tree": tree,
    }
    try:
        text = json.dumps(doc, allow_nan=False)
    except (TypeError, ValueError) as e:  # only the metadata can hold something else
        raise ValueError(f"meta must be JSON-able (str, finite numbers, bool, None, lists and dicts): {e}") from None
    try:  # what load will check (one owner: the reading limits), so that every file saved reads back
        _untrusted.parse_json(text, "the tree")
    except ValueError as e:
        raise ValueError(f"cannot save: the file would not read back: {e}") from None
    with replacing(path) as fh:
        _write_npz(fh, {_META_KEY: np.array(text), **arrays})
    return path


def _write_npz(fh, members: dict) -> None:
    """The archive ``np.savez_compressed`` writes (one deflated ``NAME.npy`` per array), closed on
    every path: numpy < 1.25 left its ZipFile open when a write failed (a full disk), and the
    finaliser then printed a second traceback after the one clear error."""
    with zipfile.ZipFile(fh, mode="w", compression=zipfile.ZIP_DEFLATED, allowZip64=True) as zf:
        for name, a in members.items():
            with zf.open(f"{name}.npy", mode="w", force_zip64=True) as f:
                np.lib.format.write_array(f, np.asanyarray(a), allow_pickle=False)


def load(path: os.PathLike, meta: bool = False):
    """Read an object written by :func:`save` (or a result's ``save`` method).

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    meta : bool, optional
        Also return the metadata dict stored with it.

    Returns
    -------
    object or (object, dict)
        The object, rebuilt with its own types (maps and systems through their constructors, so
        they compute bit for bit what the saved ones did).

    Raises
    ------
    ValueError
        For a file that does not exist, is not a hovering result file, is malformed, or names a
        type that is not hovering's (e.g. ``os:system``), values the constructors refuse, a field
        of another type than its class declares, or a size beyond a limit of
        :mod:`hovering._untrusted` (docs/threat-model.md); naming the file and the field.
    """
    path = _path(path, "path")
    not_ours = f"{path} is not a hovering result file"
    # Everything the file declares is checked before what it describes is read (module _untrusted).
    with _untrusted.Archive(path) as z:
        if _META_KEY not in z.files:
            raise ValueError(f"{not_ours} (no {_META_KEY} entry)")
        dtype, shape, _ = z.header(_META_KEY)
        if dtype.kind != "U" or shape != ():
            raise ValueError(f"{not_ours}: its {_META_KEY} entry is not a string")
        if dtype.itemsize // 4 > _untrusted.MAX_TREE_CHARS:
            raise ValueError(
                f"{not_ours}: its {_META_KEY} entry has {dtype.itemsize // 4} characters; allowed: at most "
                f"{_untrusted.MAX_TREE_CHARS}"
            )
        text = z.read(_META_KEY)
        try:
            text = str(text)
        except (ValueError, UnicodeError) as e:  # code points beyond Unicode
            raise ValueError(f"{not_ours}: its {_META_KEY} entry is not text: {e}") from None
        doc = _untrusted.parse_json(text, f"{not_ours}: its {_META_KEY} entry")
        if not isinstance(doc, dict) or doc.get("format") != FORMAT:
            found = doc.get("format") if isinstance(doc, dict) else None
            raise ValueError(f"{path}: unknown result format {found!r} (this version reads {FORMAT})")
        if "tree" not in doc:
            raise ValueError(f"{path}: malformed result file (no tree)")
        refs = _array_refs(doc["tree"])
        need = _untrusted.TREE_BYTES_PER_CHAR * len(text)
        for k, as_object in refs.items():
            if k not in z.files:
                raise ValueError(f"{path}: malformed result file: the array {k!r} is missing")
            dtype, shape, nbytes = z.header(k)
            need += nbytes + (math.prod(shape) * _untrusted._OBJECT_BYTES_PER_ITEM if as_object else 0)
        budget = _untrusted.memory_budget()
        if need > budget:
            raise ValueError(
                f"{path}: its arrays and tree need {need / 2**30:.3g} GiB (as its headers declare), more "
                f"than half of this machine's memory ({2 * budget / 2**30:.3g} GiB)"
            )
        arrays = {k: z.read(k) for k in refs}  # the only members read: unnamed ones stay compressed, unread
    try:
        obj = from_tree(doc["tree"], arrays)
    except ValueError as e:
        raise ValueError(f"{path}: {e}") from None
    except Exception as e:  # KeyError, TypeError, RecursionError, ...: a tree save never writes
        raise ValueError(f"{path}: malformed result file ({type(e).__name__}: {e})") from None
    extra = doc.get("meta", {})
    return (obj, extra if isinstance(extra, dict) else {}) if meta else obj


class Saveable:
    """Mixin of the result types: ``result.save(path)`` writes it to NPZ (read back by :func:`hovering.load`)."""

    __slots__ = ()

    def save(self, path: os.PathLike, meta: dict | None = None) -> str:
        """Write this result to an NPZ file (arrays + JSON, no pickle); see :func:`hovering.save`.

        Parameters
        ----------
        path : str or os.PathLike
            The file; ``.npz`` is appended if missing.
        meta : dict, optional
            JSON-able metadata stored beside it.

        Returns
        -------
        str
            The path written.

        Raises
        ------
        TypeError
            If part of the result cannot be saved (e.g. a map on a CustomPotential, whose V and V'
            are Python code), naming it.
        ValueError
            For a bad path or metadata.
        """
        return save(self, path, meta)
