// Potentials and their action-angle variables. Generic quantities use GSL: QAWS
// quadrature (its Chebyshev moments absorb the (q - a)^(-1/2) (b - q)^(-1/2) endpoint behaviour,
// so the smooth remainder is integrated to ~1e-13) and Brent root finding.

#include "hovering/flow/potential.hpp"

#include "hovering/detail/common.hpp"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>

#include <cmath>
#include <functional>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>

namespace hovering {

namespace {

using detail::bad;
using detail::fmt;
using detail::gsl_quiet;
using detail::kInf;
using detail::kPi;

double call(double x, void* p) { return (*static_cast<const std::function<double(double)>*>(p))(x); }

// int_a^b (x - a)^al (b - x)^be f(x) dx by GSL QAWS. A failure is bad input, not a bug: the level
// h is too small for the well's width to be resolved, or V has a plateau (V = h on an interval).
double qaws(const std::function<double(double)>& f, double a, double b, double al, double be, const Potential& pot,
            const char* who, double h) {
    gsl_quiet();
    gsl_integration_qaws_table* t = gsl_integration_qaws_table_alloc(al, be, 0, 0);
    gsl_integration_workspace* w = gsl_integration_workspace_alloc(200);
    gsl_function F{&call, const_cast<std::function<double(double)>*>(&f)};
    double r = 0, err = 0;
    const int st = gsl_integration_qaws(&F, a, b, t, 1e-14, 1e-12, 200, w, &r, &err);
    gsl_integration_workspace_free(w);
    gsl_integration_qaws_table_free(t);
    if (st != GSL_SUCCESS && st != GSL_EROUND && !(err <= 1e-10 * std::fabs(r)))
        bad(pot.name() + "." + who + ": the quadrature over the level h = " + fmt(h) + " did not converge (" +
            gsl_strerror(st) + "); the turning points [" + fmt(a) + ", " + fmt(b) +
            "] are too close to resolve, or V is flat there; allowed: a level the quadrature resolves (a larger h) or a "
            "closed-form potential");
    return r;
}

// Root of f on [lo, hi] (f(lo), f(hi) of opposite signs) to ~1 ulp.
double brent(const std::function<double(double)>& f, double lo, double hi) {
    return detail::brent(f, lo, hi, 4 * std::numeric_limits<double>::epsilon());
}

// The quadrature rules evaluate the smooth factor at the turning points, where its formula is
// 0/0, and just inside them h - V cancels; there the factor is its limit, from V' at the end.
// tol: 1e-9 of the level's width (the caller's turning points).
template <class F>
double near_end(double q, double a, double b, double at_a, double at_b, double tol, F f) {
    if (q - a <= tol) return at_a;
    if (b - q <= tol) return at_b;
    return f();
}

// Parameters whose square (and the ratios omega^2 / alpha^2 of Tan) stay normal doubles: outside,
// V underflows to 0 or the period to 0 and every answer would be silently wrong.
void require_scale(double v, const char* name) {
    if (!(v >= 1e-100 && v <= 1e100)) bad(std::string(name) + " must lie in [1e-100, 1e100], got " + fmt(v));
}

}  // namespace

// ------------------------------------------------------------------------------- generic paths

double Potential::q_limit() const { return kInf; }

void Potential::check_energy(double h, const char* who) const {
    if (!std::isfinite(h) || !(h > 0))
        bad(name() + "." + who + ": energy must be finite and > 0 (the minimum is V(0) = 0), got " + fmt(h));
}

std::pair<double, double> Potential::turning_points(double h) const {
    check_energy(h, "turning_points");
    // Subnormal levels: h - V(q) has too few significant bits for any quadrature.
    if (h < 1e-300) bad(name() + ": energy must be >= 1e-300 on the quadrature path (no closed form), got " + fmt(h));
    auto side = [&](double sgn) {
        // Bracket V = h on one side: expand outward (or toward the edge of a bounded well).
        const double lim = q_limit();
        double inner = 0, outer = std::isfinite(lim) ? 0.5 * lim : 1.0;
        for (int k = 0; V(sgn * outer) < h; ++k) {
            if (k > 200) bad(name() + ": V never reaches the energy " + fmt(h) + " (not a single well?)");
            inner = outer;
            outer = std::isfinite(lim) ? lim - 0.5 * (lim - outer) : 2 * outer;
        }
        // For small h, halve toward 0 first: a bracket [x/2, x] lets Brent reach full relative
        // accuracy; [0, 1] around a root 1e-35 exhausted its iterations at a point 1e-31.
        while (inner == 0 && outer > 1e-300 && V(sgn * 0.5 * outer) >= h) outer *= 0.5;
        if (inner == 0) inner = 0.5 * outer;
        return sgn * brent([&](double x) { return V(sgn * x) - h; }, inner, outer);
    };
    return {side(-1.0), side(1.0)};
}

double Potential::period(double h) const {
    const auto [a, b] = turning_points(h);
    // 2 int dq / sqrt(2(h - V)) = 2 int w(q) r(q) dq, w = ((q-a)(b-q))^-1/2, r = sqrt((q-a)(b-q) / (2(h-V)))
    const double ra = std::sqrt((b - a) / (2 * -dV(a))), rb = std::sqrt((b - a) / (2 * dV(b)));
    return 2 * qaws([&](double q) { return near_end(q, a, b, ra, rb, 1e-9 * (b - a), [&] { return std::sqrt((q - a) * (b - q) / (2 * (h - V(q)))); }); },
                    a, b, -0.5, -0.5, *this, "period", h);
}

double Potential::action(double h) const {
    const auto [a, b] = turning_points(h);
    const double ra = std::sqrt(2 * -dV(a) / (b - a)), rb = std::sqrt(2 * dV(b) / (b - a));
    return qaws([&](double q) { return near_end(q, a, b, ra, rb, 1e-9 * (b - a), [&] { return std::sqrt(2 * (h - V(q)) / ((q - a) * (b - q))); }); },
                a, b, 0.5, 0.5, *this, "action", h) / kPi;
}

double Potential::energy(double I) const {
    if (!std::isfinite(I) || !(I > 0)) bad(name() + ".energy: action must be finite and > 0, got " + fmt(I));
    // Bracket by doubling / halving from h = 1 (action is increasing in h).
    double lo = 1, hi = 1;
    for (int k = 0; action(hi) < I; ++k) {
        if (k > 1000) bad(name() + ".energy: no energy has action " + fmt(I));
        lo = hi;
        hi *= 2;
    }
    for (int k = 0; lo == hi || action(lo) >= I; ++k) {
        if (k > 1000) bad(name() + ".energy: no energy has action " + fmt(I));
        hi = lo;
        lo *= 0.5;
    }
    return brent([&](double h) { return action(h) - I; }, lo, hi);
}

double Potential::frequency(double h) const { return 2 * kPi / period(h); }

double Potential::angle_of(double q, double h) const {
    const auto [a, b] = turning_points(h);
    if (!(q >= a && q <= b))
        bad(name() + ".angle_of: q = " + fmt(q) + " is outside the level h = " + fmt(h) + ", [" + fmt(a) + ", " + fmt(b) + "]");
    const double w = frequency(h);
    // Integrate from the nearer turning point, where the weight takes the 1/sqrt; within 1e-12 of
    // it the time is its square-root asymptote sqrt(2 d / |V'|).
    if (q >= 0.5 * (a + b)) {
        if (b - q <= 1e-12 * (b - a)) return w * std::sqrt(2 * (b - q) / dV(b));
        const double rb = std::sqrt(1 / (2 * dV(b)));
        return w * qaws([&](double x) { return near_end(x, -kInf, b, 0.0, rb, 1e-9 * (b - a), [&] { return std::sqrt((b - x) / (2 * (h - V(x)))); }); },
                        q, b, 0.0, -0.5, *this, "angle_of", h);
    }
    if (q - a <= 1e-12 * (b - a)) return kPi - w * std::sqrt(2 * (q - a) / -dV(a));
    const double ra = std::sqrt(1 / (2 * -dV(a)));
    return kPi - w * qaws([&](double x) { return near_end(x, a, kInf, ra, 0.0, 1e-9 * (b - a), [&] { return std::sqrt((x - a) / (2 * (h - V(x)))); }); },
                          a, q, -0.5, 0.0, *this, "angle_of", h);
}

std::pair<double, double> Potential::point_at(double theta, double h) const {
    if (!std::isfinite(theta) || std::fabs(theta) > kPi) bad(name() + ".point_at: theta must lie in [-pi, pi], got " + fmt(theta));
    const auto [a, b] = turning_points(h);
    const double th = std::fabs(theta), w = frequency(h), sg = theta > 0 ? -1.0 : 1.0;
    // Within 1e-6 of a turning point, q - q_turn ~ theta^2 is below double resolution and
    // sqrt(2(h - V)) would return rounding noise: use the local expansion (relative error
    // O(theta^2) = 1e-12): time t to the turning point, p = V'(q_turn) t, q = q_turn - V' t^2 / 2.
    if (th < 1e-6) {
        const double t = th / w;
        return {b - 0.5 * dV(b) * t * t, sg * dV(b) * t};
    }
    if (kPi - th < 1e-6) {
        const double t = (kPi - th) / w;
        return {a - 0.5 * dV(a) * t * t, -sg * dV(a) * t};
    }
    const double q = brent([&](double x) { return angle_of(x, h) - th; }, a, b);
    return {q, sg * std::sqrt(std::max(0.0, 2 * (h - V(q))))};
}

double Potential::angle_of_point(double q, double p, double h) const {
    check_energy(h, "angle_of_point");
    if (!std::isfinite(q) || !std::isfinite(p))
        bad(name() + ".angle_of_point: q and p must be finite, got q = " + fmt(q) + ", p = " + fmt(p));
    // 1e-8 relative: the energy drift of an accurate orbit passes, a point of another level does not.
    const double e = 0.5 * p * p + V(q);
    if (!(std::fabs(e - h) <= 1e-8 * h))
        bad(name() + ".angle_of_point: (q, p) = (" + fmt(q) + ", " + fmt(p) + ") has energy p^2/2 + V(q) = " + fmt(e) +
            ", not on the level h = " + fmt(h) + " (allowed: within 1e-8 h)");
    return angle_on_level(q, p, h);
}

double Potential::angle_on_level(double q, double p, double h) const {
    const auto [a, b] = turning_points(h);
    const double th = angle_of(std::min(std::max(q, a), b), h);
    return p > 0 ? -th : th;
}

// ------------------------------------------------------------------------------- closed forms

Harmonic::Harmonic(double omega) : omega_(omega) { require_scale(omega, "Harmonic: omega"); }
double Harmonic::V(double q) const { return 0.5 * omega_ * omega_ * q * q; }
double Harmonic::dV(double q) const { return omega_ * omega_ * q; }
std::string Harmonic::name() const { return "Harmonic(omega=" + fmt(omega_) + ")"; }
std::pair<double, double> Harmonic::turning_points(double h) const {
    check_energy(h, "turning_points");
    const double A = std::sqrt(2 * h) / omega_;
    return {-A, A};
}
double Harmonic::period(double h) const {
    check_energy(h, "period");
    return 2 * kPi / omega_;
}
double Harmonic::action(double h) const {
    check_energy(h, "action");
    return h / omega_;
}
double Harmonic::energy(double I) const {
    if (!std::isfinite(I) || !(I > 0)) bad(name() + ".energy: action must be finite and > 0, got " + fmt(I));
    return omega_ * I;
}
double Harmonic::angle_of(double q, double h) const {
    const double A = turning_points(h).second;
    if (!(std::fabs(q) <= A)) bad(name() + ".angle_of: q = " + fmt(q) + " is outside the level h = " + fmt(h));
    return std::acos(q / A);
}

std::pair<double, double> Harmonic::point_at(double theta, double h) const {
    if (!std::isfinite(theta) || std::fabs(theta) > kPi) bad(name() + ".point_at: theta must lie in [-pi, pi], got " + fmt(theta));
    const double A = turning_points(h).second;
    return {A * std::cos(theta), -A * omega_ * std::sin(theta)};
}

double Harmonic::angle_on_level(double q, double p, double) const {
    return std::atan2(-p / omega_, q);  // (q, p) = A (cos theta, -omega sin theta): no arccos near +-1
}

Tan::Tan(double omega, double alpha) : omega_(omega), alpha_(alpha) {
    require_scale(omega, "Tan: omega");
    require_scale(alpha, "Tan: alpha");
}
double Tan::V(double q) const {
    // tan is periodic: without this, a q beyond the wall would land in another copy of the well.
    if (!(std::fabs(q) < q_limit())) return std::isnan(q) ? q : kInf;
    const double t = std::tan(alpha_ * q);
    return 0.5 * omega_ * omega_ / (alpha_ * alpha_) * t * t;
}
double Tan::dV(double q) const {
    // tan / cos^2 = tan (1 + tan^2): one transcendental call per force evaluation, the flow's
    // dominant cost.
    if (!(std::fabs(q) < q_limit())) return std::isnan(q) ? q : std::copysign(kInf, q);
    const double t = std::tan(alpha_ * q);
    return omega_ * omega_ / alpha_ * t * (1 + t * t);
}
std::string Tan::name() const { return "Tan(omega=" + fmt(omega_) + ", alpha=" + fmt(alpha_) + ")"; }
double Tan::q_limit() const { return 0.5 * kPi / alpha_; }
std::pair<double, double> Tan::turning_points(double h) const {
    check_energy(h, "turning_points");
    const double b = std::atan(alpha_ * std::sqrt(2 * h) / omega_) / alpha_;
    return {-b, b};
}
double Tan::period(double h) const {
    check_energy(h, "period");
    return 2 * kPi / std::sqrt(omega_ * omega_ + 2 * alpha_ * alpha_ * h);
}
double Tan::action(double h) const {
    check_energy(h, "action");
    // Inverse of H = omega I + alpha^2 I^2 / 2, written without cancellation for small h.
    return 2 * h / (omega_ + std::sqrt(omega_ * omega_ + 2 * alpha_ * alpha_ * h));
}
double Tan::energy(double I) const {
    if (!std::isfinite(I) || !(I > 0)) bad(name() + ".energy: action must be finite and > 0, got " + fmt(I));
    return omega_ * I + 0.5 * alpha_ * alpha_ * I * I;
}
double Tan::angle_of(double q, double h) const {
    const auto [a, b] = turning_points(h);
    if (!(q >= a && q <= b)) bad(name() + ".angle_of: q = " + fmt(q) + " is outside the level h = " + fmt(h));
    const double c = std::sqrt(alpha_ * alpha_ + omega_ * omega_ / (2 * h)) * std::sin(alpha_ * q) / alpha_;
    return std::acos(std::max(-1.0, std::min(1.0, c)));
}

std::pair<double, double> Tan::point_at(double theta, double h) const {
    if (!std::isfinite(theta) || std::fabs(theta) > kPi) bad(name() + ".point_at: theta must lie in [-pi, pi], got " + fmt(theta));
    check_energy(h, "point_at");
    // q = asin(k cos theta) / alpha and p = omega(h) dq/dtheta: no sqrt(h - V) near the turning
    // points, where it would turn a rounding of V into an O(1e-8) momentum.
    const double k = alpha_ / std::sqrt(alpha_ * alpha_ + omega_ * omega_ / (2 * h));
    const double kc = k * std::cos(theta);
    const double q = std::asin(kc) / alpha_;
    const double w = std::sqrt(omega_ * omega_ + 2 * alpha_ * alpha_ * h);
    const double p = -w * k * std::sin(theta) / (alpha_ * std::sqrt(1 - kc * kc));
    return {q, p};
}

double Tan::angle_on_level(double q, double p, double h) const {
    // cos theta = sin(alpha q) / k and sin theta = -p alpha cos(alpha q) / (omega(h) k), k > 0.
    const double w = std::sqrt(omega_ * omega_ + 2 * alpha_ * alpha_ * h);
    return std::atan2(-p * alpha_ * std::cos(alpha_ * q) / w, std::sin(alpha_ * q));
}

Numerical::Numerical(std::shared_ptr<const Potential> base) : base_(std::move(base)) {
    if (!base_) bad("Numerical: needs a potential");
}

}  // namespace hovering
