"""How results show themselves in a terminal and in Jupyter: a short ``repr`` (the shapes, the
status counts and the key numbers, never whole arrays) and an HTML table (``_repr_html_``).

A result class inherits :class:`Summarized` and says what matters in ``_summary()``: a list of
``(name, value)`` pairs; :func:`short` turns each value into a few characters.
"""

from __future__ import annotations

import html
import math

import numpy as np

__all__ = ["Summarized", "short", "status_counts"]


def short(value) -> str:
    """A value in a few characters: an array as its shape and dtype, a float to 6 digits.

    Parameters
    ----------
    value : object
        Anything.

    Returns
    -------
    str
    """
    if isinstance(value, np.ndarray):
        if value.ndim == 0:
            return short(value.item())
        return f"array{tuple(value.shape)} {value.dtype}"
    if isinstance(value, (bool, np.bool_)):
        return str(bool(value))
    if isinstance(value, (float, np.floating)):
        v = float(value)
        return f"{v:.6g}" if math.isfinite(v) else str(v)
    if isinstance(value, (list, tuple)) and len(value) > 6:
        return f"{type(value).__name__} of {len(value)}"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}: {short(v)}" for k, v in value.items()) + "}"
    if isinstance(value, (list, tuple)):
        inner = ", ".join(short(v) for v in value)
        return f"({inner})" if isinstance(value, tuple) else f"[{inner}]"
    text = str(value)
    return text if len(text) <= 80 else text[:77] + "..."


def status_counts(status, names) -> dict:
    """How many orbits have each status, by name, in code order (only the statuses present).

    Parameters
    ----------
    status : array_like of int
        Per-orbit status codes.
    names : enum class
        The codes' enum (``Status``, ``FlowStatus``).

    Returns
    -------
    dict
        ``{name: count}``.
    """
    codes, counts = np.unique(np.asarray(status), return_counts=True)
    out = {}
    for c, n in zip(codes.tolist(), counts.tolist()):
        try:
            out[names(c).name] = n
        except ValueError:
            out[str(c)] = n
    return out


class Summarized:
    """Mixin: ``repr`` and ``_repr_html_`` from ``self._summary()`` (a list of ``(name, value)``).

    A dataclass using it is declared with ``repr=False`` (else the dataclass writes its own repr,
    with every array in full).
    """

    __slots__ = ()

    def _summary(self) -> list:  # pragma: no cover - every user defines it
        raise NotImplementedError

    def __repr__(self) -> str:
        items = ", ".join(f"{k}={short(v)}" for k, v in self._summary())
        return f"<{type(self).__name__} {items}>"

    def _repr_html_(self) -> str:
        """An HTML table of the key numbers (Jupyter shows it in place of the repr)."""
        rows = "".join(
            f"<tr><th style='text-align:left'>{html.escape(str(k))}</th>"
            f"<td style='text-align:left'>{html.escape(short(v))}</td></tr>"
            for k, v in self._summary()
        )
        return (
            f"<table><caption style='text-align:left'><b>{html.escape(type(self).__name__)}</b></caption>{rows}</table>"
        )
