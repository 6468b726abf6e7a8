"""Accuracy targets: the fastest integrator setting measured to reach a requested error.

``FlowMap(sys, h, accuracy=1e-9)`` is resolved here, above the models: the map's constructor calls
the ``choose_setting`` hook this module registers (:mod:`hovering.interface`), so the model never
imports the measuring harness.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from .._checks import integer, real_number
from ..interface import register
from .work_precision import _EXACT_ERROR, _best_time, _default_actions, _flow, exact_available, stepper_applies

__all__ = ["choose_setting"]


@register("choose_setting")
def choose_setting(
    section,
    accuracy: float,
    returns: int = 1,
    steppers: Sequence[str] | None = None,
    n_points: int = 16,
    seed: int = 0,
) -> dict:
    """The fastest integrator setting measured to reach an accuracy target on this section.

    The closed-form flow (``stepper="exact"``) where the system has one and the target is not
    below 1e-13 (its documented error); otherwise a work-precision ladder (rtol = atol =
    1e-3 .. 1e-14 for each stepper, ``n_points`` starting points, errors against the reference of
    :func:`work_precision`) and the fastest row whose measured error after ``returns`` returns is
    within the target.

    Parameters
    ----------
    section : Section
        The system and energy.
    accuracy : float
        Target: the largest section-coordinate error allowed (in (0, 1)).
    returns : int, optional
        After how many returns (1 .. 1e5; the measurement iterates that far, 4 points).
    steppers : sequence of str, optional
        Candidates (default: taylor where it applies, rk8pd, rkck).
    n_points, seed : int, optional
        Starting points of the measurement.

    Returns
    -------
    dict
        The chosen row: ``method`` (stepper), ``tolerance`` (rtol = atol), ``error`` (measured),
        ``seconds`` (expected cost per return, one thread), ``options`` (keyword arguments of
        :meth:`Section.return_map` / :class:`FlowMap`), ``reference``.

    Raises
    ------
    ValueError
        For a bad target, or if no candidate reaches it (naming the best error measured).
    """
    accuracy = real_number("accuracy", accuracy, 0, True, 1, True)
    returns = integer("accuracy_returns", returns, 1, 100_000)
    if exact_available(section) and accuracy >= _EXACT_ERROR:
        t, _ = _best_time(
            lambda: section.return_map(
                np.zeros(n_points),
                _default_actions(section, n_points, np.random.default_rng(seed)),
                stepper="exact",
                n_threads=1,
            ),
            2,
        )
        return {
            "method": "exact",
            "tolerance": 1e-10,
            "error": _EXACT_ERROR,
            "seconds": t / n_points,
            "unit": "return",
            "options": {"stepper": "exact"},
            "reference": "exact (closed-form flow)",
            "returns": returns,
        }
    if steppers is None:
        steppers = tuple(st for st in ("taylor", "rk8pd", "rkck") if stepper_applies(section, st))
    tols = tuple(10.0**-k for k in range(3, 15))
    wp = _flow(
        section,
        tols,
        tuple(steppers),
        n_points,
        [1, returns] if returns > 1 else [1],
        2,
        seed,
        1,
        False,
        reversal=False,
    )
    best = wp.fastest(accuracy, None if returns == 1 else returns)
    if best is None:
        key = (lambda r: r["error"]) if returns == 1 else (lambda r: r["error_after"].get(returns, math.inf))
        top = min(wp.rows, key=key)
        raise ValueError(
            f"accuracy {accuracy:g} after {returns} return(s) is not reached by any of {list(steppers)} at "
            f"rtol 1e-3 .. 1e-14: the best measured is {key(top):.3g} ({top['method']} at "
            f"{top['tolerance']:g}; reference {wp.reference['method']}, own error "
            f"{wp.reference['error']:.2g})"
        )
    out = dict(best)
    if returns > 1:
        out["error"] = best["error_after"][returns]
    out["returns"] = returns
    out["options"] = {"stepper": best["method"], "rtol": best["tolerance"], "atol": best["tolerance"]}
    out["reference"] = wp.reference["method"]
    return out
