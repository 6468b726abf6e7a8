"""The truncated near-tangency model (sec:truncatedmapnum): the paper's F_eps, the general family
F_{eps1,eps2} with tabulated arcs and any odd forcing, and the closed-form theory of both."""

from ..interface import IterateResult  # re-exported: hovering.truncated.IterateResult (its old home)
from .maps import TruncatedFamily, TruncatedMap
from .theory import (
    L1,
    L2,
    OMEGA_G,
    K_crit,
    Theory,
    golden_family,
    hovering_area_theory,
    k_eps1,
    k_eps2,
    rho1,
    rho2,
    rho_crit,
)

__all__ = [
    "TruncatedMap",
    "TruncatedFamily",
    "IterateResult",
    "OMEGA_G",
    "L1",
    "L2",
    "k_eps1",
    "k_eps2",
    "rho1",
    "rho2",
    "K_crit",
    "rho_crit",
    "hovering_area_theory",
    "golden_family",
    "Theory",
]
# The function hovering.theory lives in the module hovering.truncated.theory (not re-exported here,
# where the name would hide the module).
