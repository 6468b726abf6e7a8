"""Measuring the product itself: what accuracy costs (work-precision diagrams), accuracy targets
(the fastest setting that reaches an error), and independent reference implementations of one
return (scipy's ``solve_ivp``, heyoka.py's Taylor integrator). Sits above the models and analyses.
"""

from .references import heyoka_return_map, scipy_return_map
from .tolerance import accurate_flow_map, choose_setting
from .work_precision import FLOW_STEPPERS_DEFAULT, WorkPrecision, exact_available, stepper_applies, work_precision

__all__ = [
    "WorkPrecision",
    "work_precision",
    "choose_setting",
    "accurate_flow_map",
    "exact_available",
    "FLOW_STEPPERS_DEFAULT",
    "stepper_applies",
    "scipy_return_map",
    "heyoka_return_map",
]
