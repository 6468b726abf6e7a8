"""Old names and module paths, kept for one release: each warns with a DeprecationWarning naming its
replacement and the release that removes it. The one place deprecations live (CHANGELOG.md lists
them): the old module paths are the table :data:`OLD_MODULES`, served by a finder of the import
system (:func:`install`), so that no file of theirs lies at the package's root; each hands its
attribute lookups to :func:`moved_module`.

The new module is found by name at the moment an old name is used (``importlib``), as
scipy's ``_lib/deprecation.py`` does: an old path is a leaf that nothing imports, and resolving it
lazily keeps ``import hovering`` from loading what the old path points to.
"""

from __future__ import annotations

import functools
import importlib
import importlib.abc
import importlib.util
import os
import sys
import warnings
from collections.abc import Callable
from types import FrameType
from typing import Any, TypeVar

_F = TypeVar("_F", bound=Callable[..., Any])

__all__ = [
    "REMOVED_IN",
    "OLD_MODULES",
    "MOVED_PRIVATE",
    "install",
    "message",
    "warn",
    "moved_module",
    "moved_method",
    "moved_argument",
    "call_moved",
    "renamed_argument",
    "renamed_keywords",
]

#: The release that removes every name deprecated in this one.
REMOVED_IN = "0.4.0"


_PACKAGE = os.path.dirname(os.path.abspath(__file__)) + os.sep

#: The old module paths (deprecated in 0.3.0): ``{old: (new, {name: "module" of a name that moved
#: elsewhere than new})}``. ``import hovering.geometry`` and ``from hovering.maps import
#: TruncatedMap`` still work; each name warns as it is used (:func:`moved_module`).
OLD_MODULES = {
    "hovering.accuracy": (
        "hovering.diagnostics",
        {n: "hovering.diagnostics.work_precision" for n in ("_reference_run", "_best_time", "_reverse")},
    ),
    "hovering.references": ("hovering.diagnostics.references", {}),
    "hovering.fullmap": ("hovering.normal", {}),
    "hovering.geometry": ("hovering.truncated.theory", {}),
    "hovering.maps": ("hovering.truncated.maps", {}),
    "hovering.potentials": ("hovering.flow.potentials", {}),
    "hovering.system": (
        "hovering.flow",
        {
            n: "hovering.normal.coordinates"
            for n in ("forcing_function", "from_normal", "tangential_curve", "to_normal")
        },
    ),
    "hovering.plotting": (
        "hovering.pipeline",
        {"plot_orbits": "hovering.plot.primitives", "REGION_COLORS": "hovering._style"},
    ),
    "hovering.figures": (
        "hovering.plot.figures",
        {"SPECIAL_COLORS": "hovering._style", "SPECIAL_LABELS": "hovering._style"},
    ),
    "hovering.distribute": ("hovering.parallel.executor", {}),
    "hovering.sweeps": ("hovering.parallel.checkpoint", {}),
}

#: Private modules that moved into ``hovering._io``: the same module under its old name too, without
#: a warning, for what files written before name (a pickle names ``hovering._pickle.restore_record``).
MOVED_PRIVATE = {
    "hovering._serial": "hovering._io.serial",
    "hovering._untrusted": "hovering._io.untrusted",
    "hovering._output": "hovering._io.output",
    "hovering._provenance": "hovering._io.provenance",
    "hovering._interop": "hovering._io.interop",
    "hovering._pickle": "hovering._io.records",
}


class _OldPaths(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds the old module paths of :data:`OLD_MODULES` and :data:`MOVED_PRIVATE` (no file holds them)."""

    def find_spec(self, fullname, path=None, target=None):
        if fullname in OLD_MODULES or fullname in MOVED_PRIVATE:
            return importlib.util.spec_from_loader(fullname, self)
        return None

    def create_module(self, spec):
        if spec.name in MOVED_PRIVATE:  # the module itself, under its old name as well
            return importlib.import_module(MOVED_PRIVATE[spec.name])
        return None  # a new, empty module: exec_module fills it

    def exec_module(self, module) -> None:
        if module.__name__ in MOVED_PRIVATE.values():
            return
        new, names = OLD_MODULES[module.__name__]
        module.__doc__ = f"Old path of :mod:`{new}` (deprecated; removed in {REMOVED_IN})."
        module.__getattr__ = moved_module(module.__name__, new, names)  # type: ignore[method-assign]


_FINDER = _OldPaths()


def install() -> None:
    """Let the import system find the old module paths (``import hovering`` calls it once)."""
    if _FINDER not in sys.meta_path:
        sys.meta_path.append(_FINDER)


def _user_stacklevel() -> int:
    """The stacklevel of the first frame outside this package: a warning is attributed to the user's
    line (Python shows DeprecationWarnings of ``__main__`` by default), however many of our own
    frames lie between (``m.hovering_area`` -> ``hovering_area`` -> here)."""
    level = 1
    f: FrameType | None = sys._getframe(1)
    while f is not None and os.path.abspath(f.f_code.co_filename).startswith(_PACKAGE):
        level, f = level + 1, f.f_back
    return level


def message(old: str, new: str) -> str:
    """The one wording of a deprecation: what is deprecated, when it goes, what to use.

    Parameters
    ----------
    old, new : str
        What the caller used, and what to use instead.

    Returns
    -------
    str
        ``"<old> is deprecated and will be removed in hovering <REMOVED_IN>; use <new> instead"``
        (the command line logs it for an old flag; :func:`warn` warns with it).
    """
    return f"{old} is deprecated and will be removed in hovering {REMOVED_IN}; use {new} instead"


def warn(old: str, new: str, stacklevel: int | None = None) -> None:
    """Warn that ``old`` is deprecated in favour of ``new``.

    Parameters
    ----------
    old, new : str
        What the caller used, and what to use instead.
    stacklevel : int, optional
        Passed to :func:`warnings.warn`; default: the first frame outside the package (the user's line).
    """
    warnings.warn(
        message(old, new),
        DeprecationWarning,
        stacklevel=stacklevel if stacklevel is not None else _user_stacklevel(),
    )


def moved_module(old: str, new: str, names: dict | None = None) -> Callable[[str], object]:
    """The module ``__getattr__`` of an old path: every name it is asked for comes from ``new``
    (or, for a name in ``names``, from the module path given there), with a warning.

    Parameters
    ----------
    old : str
        The old module's name (``__name__``).
    new : str
        The module that holds its names now.
    names : dict, optional
        ``{name: "module.path"}`` for names that moved elsewhere than ``new``.

    Returns
    -------
    callable
        To assign to the old module's ``__getattr__``.
    """
    names = dict(names or {})

    def __getattr__(name: str):
        if name.startswith("__"):
            raise AttributeError(name)
        where = names.get(name, new)
        value = getattr(importlib.import_module(where), name)  # AttributeError: the old path never had it
        warn(f"{old}.{name}", f"{where}.{name}")
        return value

    return __getattr__


def moved_method(name: str, new: str) -> Callable:
    """A method that became the free function ``new`` (``"hovering.analysis.hovering_area"``): it
    warns and calls ``new(self, *args, **kwargs)``.

    The function is found by name when the method is called, as :func:`moved_module` finds an old
    path's names: the class's module, a layer below ``new``'s, imports nothing above it, and the
    call up exists only as long as the deprecation (``tests/package/test_layering.py`` allows it
    here alone, and only with its warning).

    Parameters
    ----------
    name : str
        The method's name (``"hovering_area"``).
    new : str
        The function that replaces it, ``"module.function"``, taking the object first.

    Returns
    -------
    callable
        To assign in the class body (``hovering_area = moved_method("hovering_area", "...")``).
    """
    public = f"hovering.{new.rpartition('.')[2]}"

    def method(self, *args, **kwargs):
        warn(f"{type(self).__name__}.{name}()", f"{public}(m, ...)")
        return call_moved(new, self, *args, **kwargs)

    method.__name__ = method.__qualname__ = name
    method.__doc__ = f"Deprecated (removed in hovering {REMOVED_IN}): use :func:`{public}` (``{public}(m, ...)``)."
    method.__moved_to__ = new  # type: ignore[attr-defined]  # the layering test reads it
    return method


def moved_argument(func: str, old: str, new: str, stacklevel: int | None = None) -> None:
    """Warn that ``func(old=...)`` is deprecated: what it did is ``new`` now (a phrase).

    Parameters
    ----------
    func : str
        The function or class (``"FlowMap"``).
    old, new : str
        The argument used, and what to use instead.
    stacklevel : int, optional
        Passed to :func:`warnings.warn`; default: the user's line (see :func:`warn`).
    """
    warn(f"{func}({old}=...)", new, stacklevel=stacklevel)


def call_moved(new: str, *args, **kwargs):
    """Call ``new`` (``"module.function"``), found by name now: what a deprecated form of a lower
    layer does for the function of a higher one that replaced it (the caller has warned).

    Parameters
    ----------
    new : str
        The function.
    *args, **kwargs
        Its arguments.

    Returns
    -------
    object
        What it returns.
    """
    module, _, func = new.rpartition(".")
    return getattr(importlib.import_module(module), func)(*args, **kwargs)


def renamed_argument(func: str, old: str, new: str, stacklevel: int | None = None) -> None:
    """Warn that argument ``old`` of ``func`` is deprecated in favour of ``new``.

    Parameters
    ----------
    func : str
        The function (``"hovering_area"``).
    old, new : str
        The argument used, and what to use instead (may be a short phrase).
    stacklevel : int, optional
        Passed to :func:`warnings.warn`; default: the user's line (see :func:`warn`).
    """
    warn(f"{func}({old}=...)", f"{func}({new})", stacklevel=stacklevel)


def renamed_keywords(**renames: str) -> Callable[[_F], _F]:
    """Decorator: the keyword ``old=`` of a function still works as ``new=``, with a
    DeprecationWarning naming ``new`` (one name per concept across the API: docs/guide/outcomes.md,
    "One name per concept").

    The signature shows only the new names (``inspect.signature`` follows ``__wrapped__``);
    ``renames`` stays on the function as ``__renamed_keywords__`` (``{old: new}``), where the test
    of the API's names finds the old ones. Passing both names is a TypeError, as passing one
    argument twice is.

    Parameters
    ----------
    **renames : str
        ``old="new"`` for each renamed keyword.

    Returns
    -------
    callable
        The decorator.

    Examples
    --------
    >>> @renamed_keywords(samples="n_samples")
    ... def area(n_samples=10):
    ...     return n_samples
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as w:
    ...     warnings.simplefilter("always")
    ...     area(samples=3), str(w[0].message).split(";")[1]
    (3, ' use area(n_samples=...) instead')
    """

    def decorate(func: _F) -> _F:
        name = func.__name__

        @functools.wraps(func)
        def wrapper(*args, **kwargs):
            for old, new in renames.items():
                if old in kwargs:
                    if new in kwargs:
                        raise TypeError(f"{name}() got both {old}= (deprecated) and {new}=; pass {new}= only")
                    renamed_argument(name, old, f"{new}=...")
                    kwargs[new] = kwargs.pop(old)
            return func(*args, **kwargs)

        wrapper.__renamed_keywords__ = dict(renames)  # type: ignore[attr-defined]
        return wrapper  # type: ignore[return-value]

    return decorate
