"""Accuracy targets: the fastest integrator setting measured to reach a requested error.

An accuracy target is resolved here, above the models: :func:`accurate_flow_map` measures
(:func:`choose_setting`), then builds the :class:`~hovering.FlowMap` with the setting chosen. The
model takes a stepper and tolerances and never imports the measuring harness.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from .._checks import integer, real_number
from ..flow.section import EVENT_OPTIONS, flow_options
from ..normal.flowmap import FlowMap
from .work_precision import _EXACT_ERROR, _best_time, _default_actions, _flow, exact_available, stepper_applies

__all__ = ["choose_setting", "accurate_flow_map"]


def _target(accuracy, returns) -> tuple:
    """The target and its number of returns, checked (before anything is measured)."""
    return real_number("accuracy", accuracy, 0, True, 1, True), integer("returns", returns, 1, 100_000)


def choose_setting(
    section,
    accuracy: float,
    returns: int = 1,
    steppers: Sequence[str] | None = None,
    n_points: int = 16,
    seed: int = 0,
    options: dict | None = None,
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
    options : dict, optional
        Event options of the map the setting is for (``event_tol``, ``max_steps``, ``max_impacts``,
        ``grazing_tol``, ``corner_tol``, ``verify_steps``): every run measured uses them, so the
        cost and error measured are that map's (the reference takes the grazing and corner bands).

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
    accuracy, returns = _target(accuracy, returns)
    options = dict(options or {})
    unknown = sorted(set(options) - set(EVENT_OPTIONS))
    if unknown:
        raise ValueError(f"unknown option(s) {unknown}; allowed: {', '.join(EVENT_OPTIONS)}")
    flow_options(**options)  # each value checked (named, with its range) before anything is measured
    if exact_available(section) and accuracy >= _EXACT_ERROR:
        t, _ = _best_time(
            lambda: section.return_map(
                np.zeros(n_points),
                _default_actions(section, n_points, np.random.default_rng(seed)),
                stepper="exact",
                n_threads=1,
                **options,
            ),
            2,
        )
        return {
            "method": "exact",
            "tolerance": 1e-10,
            "error": _EXACT_ERROR,
            "seconds": t / n_points,
            "unit": "return",
            "options": {"stepper": "exact", **options},
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
        options=options,
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
    out["options"] = {"stepper": best["method"], "rtol": best["tolerance"], "atol": best["tolerance"], **options}
    out["reference"] = wp.reference["method"]
    return out


def accurate_flow_map(
    sys, h: float = 1.0, accuracy: float = 1e-9, returns: int = 1, coordinates: str = "normal", curve=None, **options
) -> FlowMap:
    """The flow's return map at the fastest integrator setting measured to reach an accuracy target.

    The setting is chosen by :func:`choose_setting` on this system and energy (the closed-form flow
    where it applies, else a work-precision ladder); the map is then built with it, as
    ``FlowMap(sys, h, stepper=..., rtol=tol, atol=tol)`` (what was chosen, with its measured error
    and cost per return, is in the map's :attr:`~hovering.FlowMap.accuracy_choice`).

    Parameters
    ----------
    sys : StepSystem
        The system.
    h : float, optional
        Energy of the section.
    accuracy : float, optional
        Target: the largest section-coordinate error of a return allowed, in (0, 1) (default 1e-9).
    returns : int, optional
        After how many returns the target holds (1 .. 1e5; errors grow as m^2 with the number m of
        returns, so a 1e4-return portrait needs a much tighter setting).
    coordinates : {"normal", "section"}, optional
        The map's coordinates (see :class:`~hovering.FlowMap`).
    curve : TangentialCurve, optional
        The tangential curve of this section (measured once if not given).
    **options
        ``event_tol``, ``max_steps``, ``max_impacts``, ``grazing_tol``, ``corner_tol``,
        ``verify_steps`` (not ``stepper``, ``rtol``, ``atol``: the target chooses them).

    Returns
    -------
    FlowMap
        With :attr:`~hovering.FlowMap.accuracy_choice` set (``method``, ``tolerance``, ``error``,
        ``seconds``, ``options``, ``reference``, ``returns``).

    Raises
    ------
    ValueError
        For bad parameters (named, with the allowed range), a stepper or tolerance given with the
        target, or a target no candidate reaches (naming the best error measured).

    Examples
    --------
    >>> import hovering
    >>> sys = hovering.StepSystem(hovering.Harmonic(1.0), hovering.Tan(1.4, 0.7), hovering.Bilinear(), eps=0.0)
    >>> fm = hovering.diagnostics.accurate_flow_map(sys, 1.0, accuracy=1e-9, coordinates="section")
    >>> fm.accuracy_choice["method"]       # eps = 0 with Harmonic and Tan: the closed-form flow
    'exact'
    """
    chosen_by_hand = sorted({"stepper", "rtol", "atol"} & set(options))
    if chosen_by_hand:
        raise ValueError(f"accuracy picks the stepper and tolerances itself; remove {chosen_by_hand} or use FlowMap")
    _target(accuracy, returns)
    # The map at the core's defaults first: every argument checked, and the tangential curve (which
    # does not depend on the integrator setting) measured once, before the measurement of settings.
    plain = FlowMap(sys, h, coordinates=coordinates, curve=curve, **options)
    choice = choose_setting(plain.section, accuracy, returns, options=options)
    tol = choice["tolerance"]
    fm = FlowMap(
        sys, h, coordinates=coordinates, curve=plain.curve, stepper=choice["method"], rtol=tol, atol=tol, **options
    )
    fm.accuracy_choice = choice
    return fm
