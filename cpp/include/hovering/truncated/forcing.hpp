#pragma once
// Odd forcing functions f(phi) of the truncated family (eq:trunceps1eps2): odd keeps it reversible.

#include <vector>

namespace hovering {

/// f(phi) = sin(phi): the first Fourier mode, the paper's choice for F_eps.
struct SineForcing {
    /// f at one angle.
    double at(double phi) const;
    /// f'(phi) = cos(phi).
    double slope(double phi) const;
};

/// f(phi) = sum_k b_k sin(k phi), k = 1..n: any odd forcing, which keeps the map reversible.
struct FourierForcing {
    std::vector<double> b;  ///< b[0] multiplies sin(phi), b[1] sin(2 phi), ...
    /// f at one angle.
    double at(double phi) const;
    /// f'(phi) = sum_k k b_k cos(k phi).
    double slope(double phi) const;
};

}  // namespace hovering
