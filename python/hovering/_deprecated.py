"""Old names and module paths, kept for one release: each warns with a DeprecationWarning naming its
replacement and the release that removes it. The one place deprecations live (CHANGELOG.md lists
them); an old module path is a two-line file that hands its attribute lookups to
:func:`moved_module`.

The new module is found by name at the moment an old name is used (``importlib``), as
scipy's ``_lib/deprecation.py`` does: an old path is a leaf that nothing imports, and resolving it
lazily keeps ``import hovering`` from loading what the old path points to.
"""

from __future__ import annotations

import functools
import importlib
import os
import sys
import warnings
from collections.abc import Callable
from types import FrameType
from typing import Any, TypeVar

_F = TypeVar("_F", bound=Callable[..., Any])

__all__ = ["REMOVED_IN", "message", "warn", "moved_module", "renamed_argument", "renamed_keywords"]

#: The release that removes every name deprecated in this one.
REMOVED_IN = "0.4.0"


_PACKAGE = os.path.dirname(os.path.abspath(__file__)) + os.sep


def _user_stacklevel() -> int:
    """The stacklevel of the first frame outside this package: a warning is attributed to the user's
    line (Python shows DeprecationWarnings of ``__main__`` by default), however many of our own
    frames lie between (``m.hovering_area`` -> hook -> ``hovering_area`` -> here)."""
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
