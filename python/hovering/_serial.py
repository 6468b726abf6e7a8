"""Results as NPZ files: a tree of dataclasses, arrays and plain values, saved without pickle.

An object is written as arrays (each under a path-like key) plus one JSON document that records
the tree's shape and every non-array value. Reading rebuilds the same types. Only types of this
package are rebuilt (a file names the classes it holds, so reading an untrusted file must not
import arbitrary modules), and arrays are loaded with ``allow_pickle=False``.

Types take part by being dataclasses, enums, or by defining ``_to_record(self) -> dict`` and a
classmethod ``_from_record(cls, record)`` (maps, systems and potentials: their constructor
arguments).
"""

from __future__ import annotations

import dataclasses
import enum
import importlib
import json
import math
import os
from pathlib import Path, PurePath
from typing import Any

import numpy as np

__all__ = ["save", "load", "to_tree", "from_tree", "FORMAT"]

FORMAT = "hovering-npz-1"
_META_KEY = "__meta__"


def _type_name(cls) -> str:
    return f"{cls.__module__}:{cls.__qualname__}"


def _resolve(name: str):
    module, _, qual = name.partition(":")
    if not (module == "hovering" or module.startswith("hovering.")):
        raise ValueError(f"refusing to rebuild type {name!r}: only hovering's own types are read from a file")
    obj = importlib.import_module(module)
    for part in qual.split("."):
        obj = getattr(obj, part)
    return obj


def to_tree(obj: Any, arrays: dict, key: str = "root"):
    """JSON-able description of ``obj``; its arrays go into ``arrays`` under path-like keys."""
    if obj is None or isinstance(obj, (bool, str)):
        return obj
    if isinstance(obj, PurePath):
        return {"__path__": str(obj)}
    if isinstance(obj, enum.Enum):
        return {"__enum__": _type_name(type(obj)), "value": obj.value}
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        x = float(obj)
        return x if math.isfinite(x) else {"__float__": repr(x)}
    if isinstance(obj, np.ndarray):
        a = obj
        if a.dtype == object:
            # Object arrays would need pickle; string arrays (itineraries) become fixed-width text.
            if all(isinstance(v, str) for v in a.flat):
                a = a.astype(str)
            else:
                raise TypeError(f"{key}: arrays of Python objects cannot be saved without pickle")
        arrays[key] = a
        return {"__array__": key, "object": obj.dtype == object}
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        fields = {f.name: to_tree(getattr(obj, f.name), arrays, f"{key}.{f.name}") for f in dataclasses.fields(obj)}
        return {"__dataclass__": _type_name(type(obj)), "fields": fields}
    if hasattr(obj, "_to_record"):
        return {"__record__": _type_name(type(obj)), "data": to_tree(obj._to_record(), arrays, f"{key}@")}
    if isinstance(obj, dict):
        if all(isinstance(k, str) for k in obj):
            return {"__dict__": {k: to_tree(v, arrays, f"{key}.{k}") for k, v in obj.items()}}
        items = list(obj.items())
        return {"__items__": [[to_tree(k, arrays, f"{key}#k{i}"), to_tree(v, arrays, f"{key}#{i}")]
                              for i, (k, v) in enumerate(items)]}
    if isinstance(obj, (list, tuple)):
        tag = "__tuple__" if isinstance(obj, tuple) else "__list__"
        return {tag: [to_tree(v, arrays, f"{key}[{i}]") for i, v in enumerate(obj)]}
    raise TypeError(f"{key}: cannot save a {type(obj).__name__} to NPZ (not an array, number, string, "
                    "dataclass or hovering object)")


def from_tree(tree, arrays):
    """Inverse of :func:`to_tree`."""
    if tree is None or isinstance(tree, (bool, str, int, float)):
        return tree
    if isinstance(tree, list):
        raise ValueError("malformed result file: a bare list in the tree")
    if "__float__" in tree:
        return float(tree["__float__"])
    if "__path__" in tree:
        return Path(tree["__path__"])
    if "__enum__" in tree:
        return _resolve(tree["__enum__"])(tree["value"])
    if "__array__" in tree:
        a = arrays[tree["__array__"]]
        return a.astype(object) if tree.get("object") else a
    if "__dataclass__" in tree:
        cls = _resolve(tree["__dataclass__"])
        obj = object.__new__(cls)  # bypasses __post_init__ checks: the values were valid when saved
        for name, sub in tree["fields"].items():
            object.__setattr__(obj, name, from_tree(sub, arrays))
        return obj
    if "__record__" in tree:
        return _resolve(tree["__record__"])._from_record(from_tree(tree["data"], arrays))
    if "__dict__" in tree:
        return {k: from_tree(v, arrays) for k, v in tree["__dict__"].items()}
    if "__items__" in tree:
        return {from_tree(k, arrays): from_tree(v, arrays) for k, v in tree["__items__"]}
    if "__tuple__" in tree:
        return tuple(from_tree(v, arrays) for v in tree["__tuple__"])
    if "__list__" in tree:
        return [from_tree(v, arrays) for v in tree["__list__"]]
    raise ValueError(f"malformed result file: unknown node {sorted(tree)}")


def save(obj: Any, path: os.PathLike, meta: dict | None = None) -> str:
    """Write ``obj`` to ``path`` (``.npz`` appended if missing); returns the path written.

    ``meta`` (JSON-able) is stored beside the tree and returned by :func:`load` with ``meta=True``.
    """
    from . import __version__

    path = os.fspath(path)
    if not path.endswith(".npz"):
        path += ".npz"
    arrays: dict = {}
    tree = to_tree(obj, arrays)
    doc = {"format": FORMAT, "version": __version__, "meta": meta or {}, "tree": tree}
    text = json.dumps(doc, allow_nan=False)
    with open(path, "wb") as fh:
        np.savez_compressed(fh, **{_META_KEY: np.array(text)}, **arrays)
    return path


def load(path: os.PathLike, meta: bool = False):
    """Read an object written by :func:`save` (``meta=True``: also return its metadata dict)."""
    path = os.fspath(path)
    try:
        with np.load(path, allow_pickle=False) as z:
            if _META_KEY not in z.files:
                raise ValueError(f"{path} is not a hovering result file (no {_META_KEY} entry)")
            doc = json.loads(str(z[_META_KEY]))
            arrays = {k: z[k] for k in z.files if k != _META_KEY}
    except (OSError, EOFError) as exc:
        raise ValueError(f"cannot read {path}: {exc}") from None
    if doc.get("format") != FORMAT:
        raise ValueError(f"{path}: unknown result format {doc.get('format')!r} (this version reads {FORMAT})")
    obj = from_tree(doc["tree"], arrays)
    return (obj, doc.get("meta", {})) if meta else obj
