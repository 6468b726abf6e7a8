// Onset parameters (sec:parametersdef) from their definitions, and the appendix's closed forms
// (sec:calculationofparam) with the two corrections the definitions require, each parameter with
// an estimate of its error.
//
// Error model. The inputs h, qw1, qw2 are exact doubles; everything else is rounded: V1(qw1) and
// V2(qw2) by a few ulps plus the rounding of q inside V, amplified by q V'/V (2 for a harmonic
// well, ~1e8 for a Tan wall 1e-8 from its singularity); h2 = h - V1(qw1) and
// delta = h - h_w = h2 - V2(qw2) inherit those absolute errors. The parameters are smooth in
// h2 and h1w on the scale of the energies themselves except theta_w and tau1, which have a
// square-root branch point at delta = 0 (the corner energy, where I_tan reaches the action of
// the level through the corner): there the relative error of tau1 is ~ E_delta / (2 delta), which
// is what makes the step energy's neighbourhood unresolvable, not the differencing.

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "hovering/detail/common.hpp"
#include "hovering/flow/system.hpp"

namespace hovering {

using detail::bad;
using detail::fmt;
using detail::kPi;

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

void require_positive(double v, const char* name) {
    if (!std::isfinite(v) || !(v > 0)) bad(std::string(name) + " must be finite and > 0, got " + fmt(v));
}

void require_rtol(double rtol) {
    if (!(rtol >= 1e-15 && rtol <= 1)) bad("rtol must lie in [1e-15, 1], got " + fmt(rtol));
}

// Rounding error of V(q) in double: 4 ulps of V plus one ulp of q inside V times q V'/V.
double value_rounding(const Potential& P, double q) {
    return kEps * (4 * std::fabs(P.V(q)) + std::fabs(q * P.dV(q)));
}

void check_walls(const Potential& V1, const Potential& V2, double qw1, double qw2, double h) {
    if (!std::isfinite(qw1) || !(qw1 < 0) || !(std::fabs(qw1) < V1.q_limit()))
        bad("qw1 must be < 0 and inside the well of V1 (|qw1| < " + fmt(V1.q_limit()) + "), got " + fmt(qw1));
    if (!std::isfinite(qw2) || !(qw2 < 0) || !(std::fabs(qw2) < V2.q_limit()))
        bad("qw2 must be < 0 and inside the well of V2 (|qw2| < " + fmt(V2.q_limit()) + "), got " + fmt(qw2));
    // A corner at the bottom of a well: V underflows and T1(V1(qw1)) (or the level through the
    // corner) is no level at all; 1e-300 is where the quadrature path stops too.
    const double h1w = V1.V(qw1), h2w = V2.V(qw2);
    if (!(h1w >= 1e-300))
        bad("qw1 = " + fmt(qw1) + " is too close to the bottom of V1: V1(qw1) = " + fmt(h1w) +
            " (allowed: V1(qw1) >= 1e-300)");
    if (!(h2w >= 1e-300))
        bad("qw2 = " + fmt(qw2) + " is too close to the bottom of V2: V2(qw2) = " + fmt(h2w) +
            " (allowed: V2(qw2) >= 1e-300)");
    const double hw = h1w + h2w;
    if (!std::isfinite(h) || !(h > hw))
        bad("h must exceed the step energy h_0^w = V1(qw1) + V2(qw2) = " + fmt(hw) + ", got " + fmt(h));
}

// The inputs' rounding (see the file comment).
struct Inputs {
    double h, h1w, h2w, h2, delta;  // delta = h - h_w, the distance to the corner energy
    double E1, Eh2, Ed;             // absolute errors of h1w, h2, delta
};

Inputs inputs(const Potential& V1, const Potential& V2, double qw1, double qw2, double h) {
    Inputs in;
    in.h = h;
    in.h1w = V1.V(qw1);
    in.h2w = V2.V(qw2);
    in.h2 = h - in.h1w;
    in.delta = in.h2 - in.h2w;
    in.E1 = value_rounding(V1, qw1);
    in.Eh2 = kEps * std::fabs(in.h2) + in.E1;
    in.Ed = in.Eh2 + value_rounding(V2, qw2) + kEps * in.delta;
    return in;
}

// One parameter: its value, and its error split into the part propagated from the inputs' rounding
// (which decides near the corner energy) and the part of the computation itself.
struct Part {
    const char* name;
    double value, input, own;
    double scale;  // > 0: a value below its error (and the error below rtol * scale) is reported as 0
};

bool is_angle(const Part& p) {
    return std::string(p.name) == "tau1" || std::string(p.name) == "theta_w";
}

[[noreturn]] void unresolved(const Part& p, const Inputs& in, double rtol, const std::string& how) {
    const double E = p.input + p.own;
    std::string why;
    if (!std::isfinite(p.value) || !std::isfinite(E)) {
        why = "it is not finite (" + fmt(p.value) + " +- " + fmt(E) + ")";
    } else if (p.input >= p.own && is_angle(p) && in.Ed / in.delta >= in.Eh2 / in.h2) {
        why = "h - h_w = " + fmt(in.delta) +
              " is below the resolution of the step energy: the rounding of h, V1(qw1) = " + fmt(in.h1w) +
              " and V2(qw2) = " + fmt(in.h2w) + " leaves h - h_w uncertain by " + fmt(in.Ed) + ", and " + p.name +
              " has a square-root singularity at h = h_w; allowed: h - h_w well above E / (2 rtol) = " +
              fmt(in.Ed / (2 * rtol)) + " (or a larger rtol)";
    } else if (p.input >= p.own) {
        why = "h2 = h - V1(qw1) = " + fmt(in.h2) +
              ", the energy of oscillator 2 on the tangent torus, is known only to " + fmt(in.Eh2) +
              " (the rounding of h and V1(qw1) = " + fmt(in.h1w) +
              "); allowed: h - V1(qw1) well above that (or a larger rtol)";
    } else {
        why = std::string("the computation of ") + p.name + " itself has error " + fmt(p.own) + " (" + how +
              "); allowed: a larger rtol" +
              (how.find("quadrature") != std::string::npos ? " or a closed-form potential" : "");
    }
    bad("onset_parameters: " + std::string(p.name) + " = " + fmt(p.value) + " at h = " + fmt(in.h) +
        " (h - h_w = " + fmt(in.delta) + ") has estimated error " + fmt(E) + ", relative " +
        fmt(E / std::fabs(p.value)) + " > rtol = " + fmt(rtol) + ": " + why);
}

// The level through the corner must lie strictly below h2 even after rounding: otherwise theta_w
// and the slopes would be asked for a q outside the level.
void require_resolved(const Inputs& in, double rtol) {
    if (!(in.delta > 2 * in.Ed))
        bad("onset_parameters: theta_w and tau1 at h = " + fmt(in.h) + ": h - h_w = " + fmt(in.delta) +
            " is below the resolution of the step energy: the rounding of h, V1(qw1) = " + fmt(in.h1w) +
            " and V2(qw2) = " + fmt(in.h2w) + " leaves h - h_w uncertain by " + fmt(in.Ed) +
            "; allowed: h - h_w well above E / (2 rtol) = " + fmt(in.Ed / (2 * rtol)));
}

// Check each parameter against rtol and assemble the estimate.
OnsetEstimate finish(Part (&parts)[6], const Inputs& in, double rtol, const std::string& how) {
    for (Part& p : parts) {
        const double E = p.input + p.own;
        if (!std::isfinite(p.value) || !std::isfinite(E)) unresolved(p, in, rtol, how);
        if (E <= rtol * std::fabs(p.value)) continue;
        if (p.scale > 0 && std::fabs(p.value) <= E && E <= rtol * p.scale) {
            p.value = 0;  // zero within its error: the sign is not known, the magnitude is
            continue;
        }
        unresolved(p, in, rtol, how);
    }
    auto pick = [&](bool err) {
        double v[6];
        for (int i = 0; i < 6; ++i) v[i] = err ? parts[i].input + parts[i].own : parts[i].value;
        return OnsetParameters{v[0], v[1], v[2], v[3], v[4], v[5]};
    };
    return {pick(false), pick(true)};
}

}  // namespace

OnsetEstimate onset_estimate(const Potential& V1, const Potential& V2, double qw1, double qw2, double h, double rtol) {
    require_rtol(rtol);
    check_walls(V1, V2, qw1, qw2, h);
    const Inputs in = inputs(V1, V2, qw1, qw2, h);
    require_resolved(in, rtol);
    const double a1 = V1.relative_accuracy(), a2 = V2.relative_accuracy();

    // At I_tan, h - H2(I) = h1w exactly: T1 and its slope are taken there, not at h - H2(I_tan)
    // (which cancels to nothing for h >> h1w).
    const double T1 = V1.period(in.h1w);
    const Estimate dT1 = V1.period_slope(in.h1w);
    const double T2 = V2.period(in.h2), w2 = 2 * kPi / T2;
    const Estimate dT2 = V2.period_slope(in.h2);
    const double dw2 = -w2 * dT2.value / T2;  // omega = 2 pi / T
    // Errors of the building blocks: own (accuracy, slope estimates) + inputs (smooth on the
    // scale of the energy: relative sensitivity <= 3 E / h).
    const double ET1 = a1 * T1 + std::fabs(dT1.value) * in.E1;
    const double Ew2 = a2 * w2 + std::fabs(dw2) * in.Eh2;
    const double EdT1 = dT1.error + std::fabs(dT1.value) * 3 * in.E1 / in.h1w;
    const double Edw2 = w2 / T2 * dT2.error + std::fabs(dw2) * (2 * a2 + 3 * in.Eh2 / in.h2);

    // Omega0(I) = omega2(H2(I)) T1(h - H2(I)), dH2/dI = omega2.
    const double Omega0 = w2 * T1;
    const double A = w2 * dw2 * T1, B = w2 * w2 * dT1.value;
    const double tau0 = A - B;
    const double I_tan = V2.action(in.h2);
    const double theta = V2.angle_of(qw2, in.h2);
    const Estimate dth = V2.angle_slope(qw2, in.h2);
    const double tau1 = -2 * w2 * dth.value;
    const double lam = std::sqrt(2 * w2 * w2 * w2) / std::fabs(V1.dV(qw1));

    Part parts[6] = {
        {"Omega0", Omega0, std::fabs(dw2) * in.Eh2 * T1 + w2 * std::fabs(dT1.value) * in.E1,
         (a1 + a2 + 2 * kEps) * Omega0, 0},
        {"tau0", tau0, (std::fabs(A) + std::fabs(B)) * 3 * (in.Eh2 / in.h2 + in.E1 / in.h1w),
         std::fabs(A) * (Ew2 / w2 + ET1 / T1) + std::fabs(w2 * T1) * Edw2 + 2 * std::fabs(B) * Ew2 / w2 +
             w2 * w2 * EdT1 + 4 * kEps * (std::fabs(A) + std::fabs(B)),
         Omega0 / I_tan},
        // d theta / dh ~ (h2 - V2(qw2))^(-1/2): relative sensitivity 1 / (2 delta) to the level.
        {"tau1", tau1, std::fabs(tau1) * in.Ed * (1 / (2 * in.delta) + 3 / in.h2),
         2 * w2 * dth.error + std::fabs(tau1) * (Ew2 / w2 + 4 * kEps), 1 / I_tan},
        {"lam", lam, lam * 1.5 * std::fabs(dw2) * in.Eh2 / w2,
         lam * (1.5 * a2 + 2 * value_rounding(V1, qw1) / in.h1w + 4 * kEps), 0},
        // acos-type rounding near theta = pi: 8 ulps of cos theta over sin theta, at most
        // 2 sqrt(8 ulps) (acos(-1 + x) = pi - sqrt(2 x)); and the level's.
        {"theta_w", theta, std::fabs(dth.value) * 2 * in.Ed,
         a2 * kPi + std::min(8 * kEps / std::fabs(std::sin(theta)), 2 * std::sqrt(8 * kEps)) + 2 * kEps * theta, 0},
        // The action's quadrature: up to 3.9e-11 relative measured on 40,000 random Tan levels 1e-3 .. 1e45
        // (omega 0.1 .. 10, alpha 1e-6 .. 10; turning points ulps from the wall), above the tolerance that
        // bounds the periods and angles: 100x (a closed form keeps its 10 x 8 eps).
        {"I_tan", I_tan, in.Eh2 / w2, ((a2 > 1e-14 ? 100 : 10) * a2 + 2 * kEps) * I_tan, 0},
    };
    const std::string how =
        "the potentials' " +
        std::string(a1 > 1e-14 || a2 > 1e-14
                        ? "quadratures (relative accuracy " + fmt(std::max(a1, a2)) + ") and their difference quotients"
                        : "closed forms' rounding");
    return finish(parts, in, rtol, how);
}

OnsetParameters onset_parameters(const Potential& V1, const Potential& V2, double qw1, double qw2, double h,
                                 double rtol) {
    return onset_estimate(V1, V2, qw1, qw2, h, rtol).value;
}

OnsetEstimate onset_estimate_closed_form(double omega1, double alpha1, double omega2, double alpha2, double qw1,
                                         double qw2, double h, double rtol) {
    require_rtol(rtol);
    require_positive(omega1, "omega1");
    require_positive(omega2, "omega2");
    if (!std::isfinite(alpha1) || alpha1 < 0) bad("alpha1 must be finite and >= 0 (0: harmonic), got " + fmt(alpha1));
    if (!std::isfinite(alpha2) || alpha2 < 0) bad("alpha2 must be finite and >= 0 (0: harmonic), got " + fmt(alpha2));
    auto pot = [](double w, double a) -> std::unique_ptr<Potential> {
        if (a > 0) return std::make_unique<Tan>(w, a);
        return std::make_unique<Harmonic>(w);
    };
    const auto P1 = pot(omega1, alpha1), P2 = pot(omega2, alpha2);
    check_walls(*P1, *P2, qw1, qw2, h);
    const Inputs in = inputs(*P1, *P2, qw1, qw2, h);
    require_resolved(in, rtol);
    // sin(alpha q) / alpha and its alpha -> 0 limit q; likewise tan.
    auto sa = [](double a, double q) { return a > 0 ? std::sin(a * q) / a : q; };
    auto ta = [](double a, double q) { return a > 0 ? std::tan(a * q) / a : q; };
    const double h1w = in.h1w, h2 = in.h2, delta = in.delta;
    const double W1 = std::sqrt(omega1 * omega1 + 2 * alpha1 * alpha1 * h1w);
    const double W2 = std::sqrt(omega2 * omega2 + 2 * alpha2 * alpha2 * h2);
    const double x1 = alpha1 * qw1, x2 = alpha2 * qw2;
    const double c1 = std::cos(x1), c2 = std::cos(x2);
    const double s2 = sa(alpha2, qw2);
    const double Omega0 = 2 * kPi * W2 / W1;
    const double tau0 = 2 * kPi * (alpha2 * alpha2 / W1 + alpha1 * alpha1 * W2 * W2 / (W1 * W1 * W1));
    const double lam = std::sqrt(2.0) * std::pow(W2, 1.5) / (omega1 * omega1 * std::fabs(ta(alpha1, qw1)) / (c1 * c1));
    // The printed arccos(sqrt(alpha2^2 + omega2^2 / (2 h2)) sin(alpha2 qw2) / alpha2) and
    // sqrt(2 h2 c2^2 - omega2^2 s2^2) both cancel near the corner energy (and for walls near the
    // Tan singularity, where theta_w -> pi): 1 - cos^2 theta_w = c2^2 (h2 - h2w) / h2 and
    // 2 h2 c2^2 - omega2^2 s2^2 = 2 c2^2 (h2 - h2w), with h2 - h2w = delta.
    const double cos_th = std::sqrt(alpha2 * alpha2 + omega2 * omega2 / (2 * h2)) * s2;
    const double sin_th = c2 * std::sqrt(delta / h2);
    const double theta = std::atan2(sin_th, cos_th);
    const double tau1 = -s2 * omega2 * omega2 / (h2 * std::sqrt(2 * c2 * c2 * delta));
    const double I_tan = alpha2 > 0 ? 2 * h2 / (omega2 + W2) : h2 / omega2;
    // Errors: ~30 ulps of evaluation; the inputs' rounding through the formulas' own derivatives
    // in h2 and h1w (d W^2 = 2 alpha^2 dh), and through sqrt(delta) (relative 1 / (2 delta));
    // cos(alpha q) near the Tan wall carries |x tan x| ulps from x = alpha q.
    const double g2 = alpha2 * alpha2 / (W2 * W2), g1 = alpha1 * alpha1 / (W1 * W1);  // d ln W / dh
    const double cx1 = kEps * std::fabs(x1 * std::tan(x1)), cx2 = kEps * std::fabs(x2 * std::tan(x2));
    const double dlog_delta = in.Ed / (2 * delta);
    const double t0a = 2 * kPi * alpha2 * alpha2 / W1, t0b = 2 * kPi * alpha1 * alpha1 * W2 * W2 / (W1 * W1 * W1);
    Part parts[6] = {
        {"Omega0", Omega0, Omega0 * (g2 * in.Eh2 + g1 * in.E1), 16 * kEps * Omega0, 0},
        {"tau0", tau0, t0b * 2 * g2 * in.Eh2 + (t0a + 3 * t0b) * g1 * in.E1, 32 * kEps * tau0, Omega0 / I_tan},
        {"tau1", tau1, std::fabs(tau1) * (dlog_delta + in.Eh2 / h2), std::fabs(tau1) * (32 * kEps + cx2), 1 / I_tan},
        {"lam", lam, lam * 1.5 * g2 * in.Eh2, lam * (32 * kEps + 2 * cx1), 0},
        {"theta_w", theta, std::fabs(sin_th * cos_th) * (dlog_delta + in.Eh2 / h2),
         8 * kEps * theta + std::fabs(sin_th * cos_th) * (cx2 + 8 * kEps), 0},
        {"I_tan", I_tan, in.Eh2 / W2, 16 * kEps * I_tan, 0},
    };
    return finish(parts, in, rtol, "the closed forms' rounding");
}

OnsetParameters onset_parameters_closed_form(double omega1, double alpha1, double omega2, double alpha2, double qw1,
                                             double qw2, double h, double rtol) {
    return onset_estimate_closed_form(omega1, alpha1, omega2, alpha2, qw1, qw2, h, rtol).value;
}

}  // namespace hovering
