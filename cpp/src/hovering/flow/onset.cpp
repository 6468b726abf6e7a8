// Onset parameters (sec:parametersdef) from their definitions, and the appendix's closed forms
// (sec:calculationofparam) with the two corrections the definitions require.

#include <cmath>
#include <functional>
#include <memory>
#include <string>

#include "hovering/detail/common.hpp"
#include "hovering/flow/system.hpp"

namespace hovering {

using detail::bad;
using detail::fmt;
using detail::kPi;

namespace {

void require_positive(double v, const char* name) {
    if (!std::isfinite(v) || !(v > 0)) bad(std::string(name) + " must be finite and > 0, got " + fmt(v));
}

}  // namespace

namespace {

void check_walls(const Potential& V1, const Potential& V2, double qw1, double qw2, double h) {
    if (!std::isfinite(qw1) || !(qw1 < 0) || !(std::fabs(qw1) < V1.q_limit()))
        bad("qw1 must be < 0 and inside the well of V1 (|qw1| < " + fmt(V1.q_limit()) + "), got " + fmt(qw1));
    if (!std::isfinite(qw2) || !(qw2 < 0) || !(std::fabs(qw2) < V2.q_limit()))
        bad("qw2 must be < 0 and inside the well of V2 (|qw2| < " + fmt(V2.q_limit()) + "), got " + fmt(qw2));
    const double hw = V1.V(qw1) + V2.V(qw2);
    if (!std::isfinite(h) || !(h > hw))
        bad("h must exceed the step energy h_0^w = V1(qw1) + V2(qw2) = " + fmt(hw) + ", got " + fmt(h));
}

// Central difference with one Richardson step: O(d^4) truncation, ~1e-12 / d rounding.
double derivative(const std::function<double(double)>& f, double x, double d) {
    const double D1 = (f(x + d) - f(x - d)) / (2 * d);
    const double D2 = (f(x + 0.5 * d) - f(x - 0.5 * d)) / d;
    return (4 * D2 - D1) / 3;
}

}  // namespace

OnsetParameters onset_parameters(const Potential& V1, const Potential& V2, double qw1, double qw2, double h) {
    check_walls(V1, V2, qw1, qw2, h);
    const double h1w = V1.V(qw1);
    const double h2 = h - h1w;  // energy of oscillator 2 on the tangent torus
    const double I_tan = V2.action(h2);
    auto Omega0 = [&](double I) {
        const double e2 = V2.energy(I);
        return V2.frequency(e2) * V1.period(h - e2);  // eq:omega0ofI
    };
    auto theta_w = [&](double I) { return V2.angle_of(qw2, V2.energy(I)); };  // eq:thw
    // Step: 1e-3 of the distance to the nearest singular action (I where H2 = V2(qw2) or H2 = h).
    const double I_lo = V2.action(V2.V(qw2)), I_hi = V2.action(h);
    const double d = 1e-3 * std::min(I_tan - I_lo, I_hi - I_tan);
    OnsetParameters p;
    p.I_tan = I_tan;
    p.Omega0 = Omega0(I_tan);
    p.tau0 = derivative(Omega0, I_tan, d);
    p.theta_w = theta_w(I_tan);
    p.tau1 = -2 * derivative(theta_w, I_tan, d);
    const double w2 = V2.frequency(h2);
    p.lam = std::sqrt(2 * w2 * w2 * w2) / std::fabs(V1.dV(qw1));
    return p;
}

OnsetParameters onset_parameters_closed_form(double omega1, double alpha1, double omega2, double alpha2,
                                             double qw1, double qw2, double h) {
    require_positive(omega1, "omega1");
    require_positive(omega2, "omega2");
    if (!std::isfinite(alpha1) || alpha1 < 0) bad("alpha1 must be finite and >= 0 (0: harmonic), got " + fmt(alpha1));
    if (!std::isfinite(alpha2) || alpha2 < 0) bad("alpha2 must be finite and >= 0 (0: harmonic), got " + fmt(alpha2));
    auto pot = [](double w, double a) -> std::unique_ptr<Potential> {
        if (a > 0) return std::make_unique<Tan>(w, a);
        return std::make_unique<Harmonic>(w);
    };
    check_walls(*pot(omega1, alpha1), *pot(omega2, alpha2), qw1, qw2, h);
    // sin(alpha q) / alpha and its alpha -> 0 limit q; likewise tan.
    auto sa = [](double a, double q) { return a > 0 ? std::sin(a * q) / a : q; };
    auto ta = [](double a, double q) { return a > 0 ? std::tan(a * q) / a : q; };
    const double h1w = 0.5 * omega1 * omega1 * ta(alpha1, qw1) * ta(alpha1, qw1);
    const double h2 = h - h1w;
    const double W1 = std::sqrt(omega1 * omega1 + 2 * alpha1 * alpha1 * h1w);
    const double W2 = std::sqrt(omega2 * omega2 + 2 * alpha2 * alpha2 * h2);
    const double c1 = std::cos(alpha1 * qw1), c2 = std::cos(alpha2 * qw2);
    const double s2 = sa(alpha2, qw2);
    OnsetParameters p;
    p.Omega0 = 2 * kPi * W2 / W1;
    p.tau0 = 2 * kPi * (alpha2 * alpha2 / W1 + alpha1 * alpha1 * W2 * W2 / (W1 * W1 * W1));
    p.lam = std::sqrt(2.0) * std::pow(W2, 1.5) / (omega1 * omega1 * std::fabs(ta(alpha1, qw1)) / (c1 * c1));
    p.theta_w = std::acos(std::sqrt(alpha2 * alpha2 + omega2 * omega2 / (2 * h2)) * s2);
    p.tau1 = -s2 * omega2 * omega2 / (h2 * std::sqrt(2 * h2 * c2 * c2 - omega2 * omega2 * s2 * s2));
    p.I_tan = alpha2 > 0 ? 2 * h2 / (omega2 + W2) : h2 / omega2;
    return p;
}

}  // namespace hovering
