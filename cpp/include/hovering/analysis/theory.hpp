#pragma once
// The leading-order hovering set of sec:truncinvcurves for any Omega0 and any odd forcing
// f = sum_k b_k sin(k phi): the C++ twin of python/hovering/truncated/theory.py's theory().area and of
// analysis/hovering.py's default_depth (the sweep executable's theory column and default box).

#include <vector>

namespace hovering {

/// First-order shape G(psi) = sum_k b_k (1 - cos(k psi)) / (2 sin(k Omega0 / 2)) of the invariant
/// curves through L1 (psi = phi + Omega0 / 2); b[0] multiplies sin(phi).
double theory_G(const std::vector<double>& b, double Omega0, double psi);

/// |HOV| to leading order (eq:hovsetsize generalised): the closed form for f = b_1 sin, else the
/// area between K = 0 and the lowest curve K_low + eps G avoiding the impacting arcs (trapezoid
/// rule on n_grid points); 0 for the sign of eps that does not hover, NaN at a resonance
/// (|sin(k Omega0 / 2)| < 1e-9 for a mode k of f) or for theta_w outside (0, pi). Throws
/// std::invalid_argument for |Omega0| > 1e6 as Python does.
double hovering_area_theory(double eps, double Omega0, double theta_w, const std::vector<double>& b,
                            int n_grid = 100001);

/// Depth of hovering_area's default box below K = 0: 2 |eps| max |G| over 4001 angles in [-pi, pi]
/// (2 |eps| / |sin(Omega0 / 2)| for f = sin); +inf when that is not finite and positive.
double default_depth(double eps, double Omega0, const std::vector<double>& b);

}  // namespace hovering
