// See theory.hpp. Expressions follow Python's order so that the single-mode cases (every truncated
// map scene) give the same doubles; the multi-mode integral differs from NumPy's pairwise sums by
// rounding only.
#include "hovering/analysis/theory.hpp"

#include <algorithm>
#include <cmath>

#include "hovering/detail/common.hpp"

namespace hovering {

using detail::kPi;

double theory_G(const std::vector<double>& b, double Omega0, double psi) {
    double g = 0.0;
    for (std::size_t k = 0; k < b.size(); ++k) {
        if (b[k] == 0) continue;
        const double m = double(k + 1);
        g = g + b[k] * (1 - std::cos(m * psi)) / (2 * std::sin(0.5 * m * Omega0));
    }
    return g;
}

namespace {

/// numpy.linspace(a, b, n)[i].
double linspace(double a, double b, int n, int i) {
    if (i == n - 1) return b;
    const double step = (b - a) / double(n - 1);
    return double(i) * step + a;
}

}  // namespace

double hovering_area_theory(double eps, double Omega0, double theta_w, const std::vector<double>& b, int n_grid) {
    if (!std::isfinite(Omega0) || std::abs(Omega0) > 1e6)
        detail::bad("Omega0 must lie in [-1e6, 1e6] (a larger rotation cannot be reduced mod 2 pi accurately), got " +
                    detail::fmt(Omega0));
    if (!(theta_w > 0 && theta_w < kPi)) return detail::kNaN;
    bool single = true;
    for (std::size_t k = 0; k < b.size(); ++k) {
        if (b[k] == 0) continue;
        if (std::abs(std::sin(0.5 * double(k + 1) * Omega0)) < 1e-9) return detail::kNaN;
        single = single && k == 0;
    }
    if (single) {
        const double e = eps * (b.empty() ? 0.0 : b[0]);
        const double s = std::sin(0.5 * Omega0);
        return e * s > 0 ? std::abs(e) * (std::sin(theta_w) - theta_w * std::cos(theta_w)) / std::abs(s) : 0.0;
    }
    // The lowest curve K_low + eps G >= 0 outside J_0 = {|psi| < theta_w}; the area between it and
    // K = 0 inside J_0.
    double g_min = detail::kInf;
    for (int i = 0; i < n_grid; ++i) {
        const double psi = linspace(theta_w, kPi, n_grid, i);
        g_min = std::min({g_min, eps * theory_G(b, Omega0, psi), eps * theory_G(b, Omega0, -psi)});
    }
    const double K_low = -g_min;
    const double step = linspace(-theta_w, theta_w, n_grid, 1) - linspace(-theta_w, theta_w, n_grid, 0);
    double sum = 0, prev = 0;
    for (int i = 0; i < n_grid; ++i) {
        const double d = std::max(0.0, -(K_low + eps * theory_G(b, Omega0, linspace(-theta_w, theta_w, n_grid, i))));
        if (i > 0) sum += 0.5 * (d + prev);
        prev = d;
    }
    return sum * step;
}

double default_depth(double eps, double Omega0, const std::vector<double>& b) {
    double g = 0;
    for (int i = 0; i < 4001; ++i) {
        const double a = std::abs(theory_G(b, Omega0, linspace(-kPi, kPi, 4001, i)));
        g = std::isnan(a) || std::isnan(g) ? a + g : std::max(g, a);  // NaN propagates, as np.max
    }
    const double d = b.empty() ? detail::kNaN : 2.0 * std::abs(eps) * g;
    return std::isfinite(d) && d > 0 ? d : detail::kInf;
}

}  // namespace hovering
