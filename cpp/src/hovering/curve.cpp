// Curve: the periodic cubic spline through uniform samples (see curve.hpp).

#include "hovering/curve.hpp"

#include <algorithm>
#include <string>

#include "hovering/detail/common.hpp"

namespace hovering {

using detail::bad;
using detail::fmt;

static_assert(Curve::kPi == detail::kPi, "the curve wraps and evaluates with the core's pi");

namespace {

// Second derivatives (per cell, in the cell variable s) of the periodic cubic spline through y:
// M_{i-1} + 4 M_i + M_{i+1} = 6 (y_{i-1} - 2 y_i + y_{i+1}), indices mod n (n >= 3), solved as a
// tridiagonal system plus a rank-one correction for the two corner entries (Sherman-Morrison).
std::vector<double> second_derivatives(const std::vector<double>& y) {
    const std::size_t n = y.size();
    std::vector<double> r(n);
    for (std::size_t i = 0; i < n; ++i) r[i] = 6.0 * (y[(i + n - 1) % n] - 2.0 * y[i] + y[(i + 1) % n]);
    // Tridiagonal part with diagonal bb (the corners 1 at (0, n-1) and (n-1, 0) moved into u v^T,
    // u = (gamma, 0, ..., 0, 1), v = (1, 0, ..., 0, 1 / gamma)).
    const double gamma = -4.0;
    std::vector<double> bb(n, 4.0);
    bb[0] = 4.0 - gamma;
    bb[n - 1] = 4.0 - 1.0 / gamma;
    auto solve = [&](std::vector<double> rhs) {  // Thomas algorithm, sub- and super-diagonal 1
        std::vector<double> c(n), x(n);
        double beta = bb[0];
        x[0] = rhs[0] / beta;
        for (std::size_t i = 1; i < n; ++i) {
            c[i] = 1.0 / beta;
            beta = bb[i] - c[i];
            x[i] = (rhs[i] - x[i - 1]) / beta;
        }
        for (std::size_t i = n - 1; i-- > 0;) x[i] -= c[i + 1] * x[i + 1];
        return x;
    };
    std::vector<double> u(n, 0.0);
    u[0] = gamma;
    u[n - 1] = 1.0;
    std::vector<double> x = solve(r), z = solve(u);
    const double fact = (x[0] + x[n - 1] / gamma) / (1.0 + z[0] + z[n - 1] / gamma);
    for (std::size_t i = 0; i < n; ++i) x[i] -= fact * z[i];
    return x;
}

double horner(const double* c, double s) {
    return c[0] + s * (c[1] + s * (c[2] + s * c[3]));
}

}  // namespace

Curve::Curve(std::vector<double> K) : n_(std::int64_t(K.size())), samples_(std::move(K)) {
    if (n_ == 0) bad("a curve needs samples: one (a constant) or at least 3, got none");
    if (n_ > kMaxSamples)
        bad("a curve takes at most " + std::to_string(kMaxSamples) + " samples, got " + std::to_string(n_));
    if (n_ == 2) bad("a curve needs one sample (a constant) or at least 3 (a periodic cubic spline), got 2");
    for (std::int64_t j = 0; j < n_; ++j)
        detail::require_finite(samples_[std::size_t(j)], "curve sample K[" + std::to_string(j) + "]");
    scale_ = double(n_) * detail::kInvTwoPi;
    if (n_ == 1) {
        cells_ = {samples_[0], 0.0, 0.0, 0.0};
        lower_ = upper_ = samples_[0];
        return;
    }
    const std::vector<double> M = second_derivatives(samples_);
    cells_.resize(std::size_t(4 * n_));
    double lo = detail::kInf, hi = -detail::kInf, size = 0;
    for (std::int64_t i = 0; i < n_; ++i) {
        const std::size_t a = std::size_t(i), b = std::size_t((i + 1) % n_);
        double* c = &cells_[4 * a];
        c[0] = samples_[a];
        c[1] = (samples_[b] - samples_[a]) - (2.0 * M[a] + M[b]) / 6.0;
        c[2] = M[a] / 2.0;
        c[3] = (M[b] - M[a]) / 6.0;
        // Extremes of the cell polynomial: its ends and the zeros of its derivative b + 2 c s + 3 d s^2 in (0, 1).
        // The roots in the cancellation-free form q / (3 d), b / q: (-c +- sq) / (3 d) loses every
        // digit when d is rounding noise (a cell whose two ends have equal M), and put the
        // maximum of such a cell anywhere; the SIMD kernel's stop test trusts these bounds.
        double cand[4] = {0.0, 1.0, -1.0, -1.0};
        const double disc = c[2] * c[2] - 3.0 * c[1] * c[3];
        if (disc >= 0) {
            const double q = -(c[2] + std::copysign(std::sqrt(disc), c[2]));
            if (c[3] != 0.0) cand[2] = q / (3.0 * c[3]);
            if (q != 0.0) cand[3] = c[1] / q;
        }
        for (double s : cand) {
            if (!(s >= 0.0 && s <= 1.0)) continue;
            const double v = horner(c, s);
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
        size = std::max(size, std::fabs(c[0]) + std::fabs(c[1]) + std::fabs(c[2]) + std::fabs(c[3]));
    }
    if (!(std::isfinite(lo) && std::isfinite(hi) && std::isfinite(size)))
        bad("curve samples too large for a spline (its coefficients overflow); the largest |K| is " +
            fmt(*std::max_element(samples_.begin(), samples_.end(),
                                  [](double x, double y) { return std::fabs(x) < std::fabs(y); })));
    // Horner rounds each of its 6 operations; the extremes are found to within their rounding too
    // (the polynomial is flat there): 1e-12 of the coefficients' size covers both many times over.
    const double margin = 1e-12 * (1.0 + size);
    lower_ = lo - margin;
    upper_ = hi + margin;
}

double Curve::operator()(double phi) const {
    if (std::isnan(phi)) return detail::kNaN;
    detail::require_angle(phi, "phi");
    return value(detail::wrap(phi));
}

void StopCondition::validate() const {
    if (side != StopSide::None && side != StopSide::Above && side != StopSide::Below)
        bad("stop side must be None, Above or Below, got code " + std::to_string(int(side)));
    if (active() && !curve) bad("a stop condition needs a curve");
}

}  // namespace hovering
