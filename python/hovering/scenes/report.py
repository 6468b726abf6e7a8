"""Text of scene results: the JSON-able summary of the numbers shown, and its printed form.

Pure functions of a result (the iminuit ``_repr_text`` role): nothing here computes. The lines of
each kind are its own (:attr:`hovering.scenes.registry.Kind.report`); the head, the integrator's
accuracy and the files written are every kind's.
"""

from __future__ import annotations

from . import kinds, registry  # noqa: F401 (kinds: every kind of the package registered)
from .base import fmt, summarize

__all__ = ["summarize", "format_summary"]  # summarize: re-exported from .base, its home


def format_summary(summary: dict) -> str:
    """Human-readable text of a scene summary (what the CLI prints).

    Every number goes through one formatter: a value that is not a finite number (NaN, stored as
    None in the JSON-able summary, e.g. the theory at Omega0 = 2 pi or a checkpoint row without an
    area) prints as ``nan`` (``inf``), never an error.

    Parameters
    ----------
    summary : dict
        From :func:`summarize` (plus ``output``, ``npz``, ``json`` and ``files`` when the result
        was written).

    Returns
    -------
    str
    """
    f = fmt
    head = f"scene {summary['scene']} ({summary['kind']})"
    if "n_steps" in summary:
        head += f", {summary['n_steps']} iterates"
    lines = [head + (" [quick]" if summary["quick"] else "")]
    acc = summary.get("accuracy")
    if acc:
        it = ", ".join(
            f"{k} {f(v, 'g')}" if isinstance(v, float) or v is None else f"{k} {v}"
            for k, v in acc["integrator"].items()
            if k in ("stepper", "rtol", "atol")
        )
        lines.append(
            f"  integrator: {it}; reversal error after {acc['reversal_returns']} returns "
            f"({acc['reversal_orbits']} orbits): {f(acc['reversal_error'], '.2g')} (grows as m^2)"
        )
    if summary["kind"] in registry.names():
        lines += registry.get(summary["kind"]).report(summary)
    if "output" in summary:
        files = summary.get("files") or [summary["output"], summary["npz"]]
        lines.append(f"wrote {', '.join(str(x) for x in files)} in {f(summary['runtime_s'], '.2f')} s")
    return "\n".join(lines)


# The old private names of the formatters (their home is .base).
_f = fmt
