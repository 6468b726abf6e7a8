// The tangential curve measured on the flow: see tangential_curve.hpp.

#include "hovering/normal/tangential_curve.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "hovering/detail/common.hpp"
#include "hovering/flow/tracer.hpp"

namespace hovering {

using detail::bad;
using detail::fmt;
using detail::kPi;
using detail::kTwoPi;
using detail::wrap;

// ------------------------------------------------------------------ trigonometric interpolation

TrigInterpolant::TrigInterpolant(const std::vector<double>& v) {
    const std::size_t n = v.size();
    if (n < 4 || n % 2)
        bad("a trigonometric interpolant needs an even number >= 4 of samples, got " + std::to_string(n));
    const std::size_t m = n / 2;
    a_.assign(m + 1, 0.0);
    b_.assign(m + 1, 0.0);
    for (std::size_t j = 0; j <= m; ++j) {
        double a = 0, b = 0;
        for (std::size_t k = 0; k < n; ++k) {
            const double x = kTwoPi * double(j * k % n) / double(n);  // exact argument reduction
            a += v[k] * std::cos(x);
            b += v[k] * std::sin(x);
        }
        const double w = (j == 0 || j == m) ? 1.0 / double(n) : 2.0 / double(n);  // mean and Nyquist count once
        a_[j] = w * a;
        b_[j] = (j == 0 || j == m) ? 0.0 : w * b;
    }
    // Modes below 1e-15 of the largest value are noise at the level the samples are known to (a
    // trace at rtol 1e-13 and rounding): dropping the tail makes every evaluation (two per return
    // of the flow map) proportionally cheaper.
    double scale = 0;
    for (double x : v) scale = std::max(scale, std::fabs(x));
    std::size_t keep = a_.size();
    while (keep > 1 && std::fabs(a_[keep - 1]) + std::fabs(b_[keep - 1]) < 1e-15 * scale) --keep;
    a_.resize(keep);
    b_.resize(keep);
}

std::pair<double, double> TrigInterpolant::with_derivative(double s) const {
    // cos(j x), sin(j x) by the rotation recurrence: one sincos per evaluation.
    const double x = s + kPi;
    const double c1 = std::cos(x), s1 = std::sin(x);
    double c = 1, sn = 0, f = a_.empty() ? 0.0 : a_[0], df = 0;
    for (std::size_t j = 1; j < a_.size(); ++j) {
        const double cn = c * c1 - sn * s1;
        sn = sn * c1 + c * s1;
        c = cn;
        f += a_[j] * c + b_[j] * sn;
        df += double(j) * (b_[j] * c - a_[j] * sn);
    }
    return {f, df};
}

double TrigInterpolant::operator()(double s) const {
    return with_derivative(s).first;
}

// ------------------------------------------------------------------ the curve

namespace {

// The wall tangency point at wall angle s: the action I_w(s) with H2(I) + eps Vc(qw1, q2(s, I))
// = h - V1(qw1) (eq:XiwallepsI), required to be unique on (0, 4 I0], and its state (qw1, 0, q2, p2).
std::array<double, 4> wall_point(const FlowSystem& sys, double h, double s, double I0) {
    const double E1 = h - sys.V1->V(sys.qw1);
    auto G = [&](double I) {
        const double e2 = sys.V2->energy(I);
        const double q2 = sys.V2->point_at(s, e2).first;
        return e2 + (sys.eps != 0 ? sys.eps * sys.coupling.value(sys.qw1, q2) : 0.0) - E1;
    };
    const int m = 48;
    double lo = 0, hi = 0, g_prev = 0, I_prev = 0;
    int changes = 0;
    for (int k = 1; k <= m; ++k) {
        const double I = 4.0 * I0 * k / m;
        double g;
        try {
            g = G(I);
        } catch (const std::invalid_argument&) {
            break;  // beyond the well of V2 (e.g. a Tan potential's energy range): stop the scan
        }
        if (k > 1 && (g > 0) != (g_prev > 0)) {
            ++changes;
            lo = I_prev;
            hi = I;
        }
        g_prev = g;
        I_prev = I;
    }
    if (changes == 0)
        bad("the wall tangency curve has no point at wall angle " + fmt(s) +
            ": no action in (0, 4 I_tan] puts "
            "oscillator 2 on H2 + eps Vc(qw1, q2) = h - V1(qw1) (eps = " +
            fmt(sys.eps) + " too large?)");
    if (changes > 1)
        bad("the wall tangency curve is not a graph over the wall angle: at angle " + fmt(s) +
            " the level "
            "H2 + eps Vc(qw1, q2) = h - V1(qw1) is met at " +
            std::to_string(changes) + " actions (eps = " + fmt(sys.eps) + "); normal coordinates do not exist");
    const double I = detail::brent(G, lo, hi, 1e-15);
    const auto [q2, p2] = sys.V2->point_at(s, sys.V2->energy(I));
    std::array<double, 4> z{sys.qw1, 0.0, q2, p2};
    double dz[4];
    sys.rhs(z.data(), dz);
    if (!(dz[1] > 0))
        bad("at wall angle " + fmt(s) + " the point of q1 = qw1 with p1 = 0 is not a minimum of q1 (dp1/dt = " +
            fmt(dz[1]) + " <= 0): the coupling (eps = " + fmt(sys.eps) + ") overpowers the force of V1 there");
    return z;
}

// The Sigma_h point whose segment touches q1 = qw1 at the wall point of angle s: the time-reversed
// wall point traced forward to its first crossing of Sigma_h, reversed back.
std::pair<double, double> trace_back(detail::Tracer& tr, double h, double s, double I0) {
    const FlowSystem& sys = tr.system();
    const auto zw = wall_point(sys, h, s, I0);
    const ReturnResult r = tr.trace({zw[0], 0.0, zw[2], -zw[3]}, true);
    if (r.status == FlowStatus::OffSection)
        bad("the tangential curve is not a graph over (theta, I): traced back from wall angle " + fmt(s) +
            ", its point is a maximum of q1 (q1 = " + fmt(r.z[0]) + ", q2 = " + fmt(r.z[2]) +
            ") that Sigma_h's chart does not hold (q1 <= 0, H2 > h, or another root of H = h): the coupling (eps = " +
            fmt(sys.eps) + ") is too strong here");
    if (r.status != FlowStatus::Ok)
        bad("the tangential curve could not be traced back from wall angle " + fmt(s) + " at h = " + fmt(h) +
            ": the return, traced at rtol = " + fmt(tr.options().rtol) + ", ended " + describe(r.status));
    const double q2 = r.z[2], p2 = -r.z[3];
    const double e2 = 0.5 * p2 * p2 + sys.V2->V(q2);
    return {wrap(sys.V2->angle_on_level(q2, p2, e2)), sys.V2->action(e2)};
}

}  // namespace

TangentialCurve TangentialCurve::measure(const FlowSystem& s, double h, int n, const FlowOptions& opt, int n_check) {
    detail::gsl_quiet();
    s.validate();
    opt.validate();
    if (n < 8 || n % 2 || n > 4096) bad("n must be an even number in [8, 4096], got " + std::to_string(n));
    if (n_check < 0 || n_check > n) bad("n_check must be in [0, n], got " + std::to_string(n_check));
    if (!std::isfinite(h)) bad("h must be finite, got " + fmt(h));
    const double E1 = h - s.V1->V(s.qw1);
    if (!(E1 > 0))
        bad("h = " + fmt(h) + " does not reach the line q1 = qw1 (h must exceed V1(qw1) = " + fmt(s.V1->V(s.qw1)) +
            ")");
    FlowSystem smooth = s;  // the segment from Sigma_h to its touching point meets no wall
    smooth.geometry = Geometry::None;
    detail::Tracer tr(smooth, opt);
    TangentialCurve c;
    c.h_ = h;
    c.eps_ = s.eps;
    c.I0_ = s.V2->action(E1);
    c.s_.resize(std::size_t(n));
    c.theta_.resize(std::size_t(n));
    c.I_.resize(std::size_t(n));
    for (int k = 0; k < n; ++k) {
        const double sk = -kPi + kTwoPi * k / n;
        const auto [th, I] = trace_back(tr, h, sk, c.I0_);
        c.s_[std::size_t(k)] = sk;
        c.theta_[std::size_t(k)] = th;
        c.I_[std::size_t(k)] = I;
    }
    c.interpolate();
    for (int k = 0; k < n_check; ++k) {
        const double sk = -kPi + kTwoPi * (double(k) * n / n_check + 0.5) / n;  // midway between samples
        const auto [th, I] = trace_back(tr, h, sk, c.I0_);
        const auto [thi, Ii] = c.at(sk);
        c.err_theta_ = std::max(c.err_theta_, std::fabs(wrap(th - thi)));
        c.err_I_ = std::max(c.err_I_, std::fabs(I - Ii));
        if (c.is_graph()) c.err_I_ = std::max(c.err_I_, std::fabs(I - c.I_tan(th)));  // the theta-interpolant too
    }
    return c;
}

void TangentialCurve::interpolate() {
    const int n = int(s_.size());
    std::vector<double> u(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k) u[std::size_t(k)] = wrap(theta_[std::size_t(k)] - s_[std::size_t(k)]);
    // theta(s) - s must be continuous and periodic: unwrap it; a winding left over means theta(s)
    // is not a degree-one circle map, so no interpolant (and no graph) exists.
    double wind = 0;
    for (int k = 1; k <= n; ++k) {
        const double d = wrap(u[std::size_t(k % n)] - u[std::size_t(k - 1)]);
        if (k < n)
            u[std::size_t(k)] = u[std::size_t(k - 1)] + d;
        else
            wind = u[std::size_t(n - 1)] + d - u[0];
    }
    if (std::fabs(wind) > 1e-6)
        bad("the tangential curve winds " + fmt(wind / kTwoPi) + " extra times around the cylinder (eps = " +
            fmt(eps_) + "): it is not a graph over theta and normal coordinates do not exist");
    u_ = TrigInterpolant(u);
    Ifun_ = TrigInterpolant(I_);
    min_slope_ = 1e300;
    for (int k = 0; k < 8 * n; ++k) {
        const double sk = -kPi + kTwoPi * k / (8 * n);
        const double slope = 1 + u_.with_derivative(sk).second;
        if (slope < min_slope_) {
            min_slope_ = slope;
            min_slope_s_ = sk;
        }
    }
    if (is_graph()) {
        // I_tan(theta) is smooth and periodic in theta too: interpolate it directly, so normal
        // coordinates cost one interpolant evaluation instead of a Newton inversion of theta(s).
        std::vector<double> Ith(static_cast<std::size_t>(n));
        for (int k = 0; k < n; ++k) Ith[std::size_t(k)] = Ifun_(parameter_of(-kPi + kTwoPi * k / n));
        Itheta_ = TrigInterpolant(Ith);
    }
}

TangentialCurve TangentialCurve::from_samples(double h, double eps, double I_tan0, const std::vector<double>& theta,
                                              const std::vector<double>& I, double err_theta, double err_I) {
    const std::size_t n = theta.size();
    if (n < 8 || n % 2 || n > 4096)
        bad("a tangential curve needs an even number in [8, 4096] of samples, got " + std::to_string(n));
    if (I.size() != n)
        bad("theta and I of a tangential curve must have the same length, got " + std::to_string(n) + " and " +
            std::to_string(I.size()));
    for (std::size_t k = 0; k < n; ++k) {
        if (!std::isfinite(theta[k])) bad("theta[" + std::to_string(k) + "] must be finite, got " + fmt(theta[k]));
        if (!std::isfinite(I[k])) bad("I[" + std::to_string(k) + "] must be finite, got " + fmt(I[k]));
    }
    for (const auto& [name, v] : {std::pair<const char*, double>{"h", h}, {"eps", eps}, {"I_tan0", I_tan0}})
        if (!std::isfinite(v)) bad(std::string(name) + " must be finite, got " + fmt(v));
    for (const auto& [name, v] : {std::pair<const char*, double>{"err_theta", err_theta}, {"err_I", err_I}})
        if (!(v >= 0)) bad(std::string(name) + " must be >= 0, got " + fmt(v));
    TangentialCurve c;
    c.h_ = h;
    c.eps_ = eps;
    c.I0_ = I_tan0;
    c.theta_ = theta;
    c.I_ = I;
    c.s_.resize(n);
    for (std::size_t k = 0; k < n; ++k) c.s_[k] = -kPi + kTwoPi * int(k) / int(n);  // measure()'s grid, same rounding
    c.interpolate();
    c.err_theta_ = err_theta;
    c.err_I_ = err_I;
    return c;
}

std::pair<double, double> TangentialCurve::at(double s) const {
    return {wrap(s + u_(s)), Ifun_(s)};
}

std::string TangentialCurve::not_graph_reason() const {
    if (is_graph()) return "";
    return "the tangential curve is not a graph over theta at eps = " + fmt(eps_) +
           ": theta(s) turns back (dtheta/ds = " + fmt(min_slope_) + " at wall angle " + fmt(min_slope_s_) +
           "), so one theta has several tangency actions and "
           "normal coordinates (phi, K) do not exist; use section coordinates (theta, I)";
}

double TangentialCurve::parameter_of(double theta) const {
    if (!is_graph()) bad(not_graph_reason());
    // F(s) = s + u(s) - lift(theta) is increasing with F(s + 2 pi) = F(s) + 2 pi: from s0 with
    // |F(s0)| <= pi the root lies in [s0 - 2 pi, s0 + 2 pi]; Newton, kept in the bracket.
    double s = theta - u_.mean();
    const double target = s + u_(s) - wrap(s + u_(s) - theta);
    double lo = s - kTwoPi, hi = s + kTwoPi;
    for (int it = 0; it < 100; ++it) {
        const auto [uv, du] = u_.with_derivative(s);
        const double F = s + uv - target;
        if (F == 0) break;
        (F < 0 ? lo : hi) = s;
        double sn = s - F / (1 + du);
        if (!(sn > lo && sn < hi)) sn = 0.5 * (lo + hi);
        if (std::fabs(sn - s) <= 4e-16 * (1 + std::fabs(s))) {
            s = sn;
            break;
        }
        s = sn;
    }
    return s;
}

double TangentialCurve::I_tan(double theta) const {
    if (!is_graph()) bad(not_graph_reason());
    return Itheta_(theta);
}

double TangentialCurve::I_tan_slope(double theta) const {
    if (!is_graph()) bad(not_graph_reason());
    return Itheta_.with_derivative(theta).second;
}

TangentialCurve TangentialCurve::measure_refined(const FlowSystem& s, double h, const FlowOptions& opt, int n_check) {
    int n = 64;
    TangentialCurve c = measure(s, h, n, opt, n_check);
    while (n_check > 0 && n < 1024 && !(c.err_I_ < 1e-12)) {
        n *= 2;
        c = measure(s, h, n, opt, n_check);
    }
    return c;
}

TangentialCurve TangentialCurve::measure_default(const FlowSystem& s, double h) {
    FlowOptions o;
    o.rtol = 1e-13;
    o.atol = 1e-13 * 1e-2;
    return measure_refined(s, h, o, 4);
}

std::vector<double> forcing_angles(int n_phi) {
    if (n_phi < 1 || n_phi > 65536) bad("n_phi must be an integer in [1, 65536], got " + std::to_string(n_phi));
    std::vector<double> ph(static_cast<std::size_t>(n_phi));
    for (int j = 0; j < n_phi; ++j) ph[std::size_t(j)] = -kPi + 2 * kPi * (double(j) + 0.5) / n_phi;
    return ph;
}

std::vector<double> sine_coefficients(const std::vector<double>& f, int n_modes) {
    const int n_phi = int(f.size());
    if (n_modes < 1 || 2 * n_modes >= n_phi)
        bad("a sine fit of " + std::to_string(n_modes) + " modes needs more than " + std::to_string(2 * n_modes) +
            " samples (n_modes >= 1, n_phi > 2 n_modes), got " + std::to_string(n_phi));
    const std::vector<double> ph = forcing_angles(n_phi);
    std::vector<double> b(std::size_t(n_modes), 0.0);
    for (int j = 0; j < n_phi; ++j)
        for (int k = 0; k < n_modes; ++k)
            b[std::size_t(k)] += f[std::size_t(j)] * std::sin(double(k + 1) * ph[std::size_t(j)]);
    for (auto& x : b) x *= 2.0 / n_phi;
    return b;
}

std::vector<double> TangentialCurve::forcing_coefficients(int n_modes, int n_phi) const {
    if (eps_ == 0) bad("the forcing f(phi) is defined for eps != 0 (eq:defoff divides by eps)");
    const std::vector<double> ph = forcing_angles(n_phi);
    std::vector<double> f(ph.size());
    for (std::size_t j = 0; j < ph.size(); ++j) f[j] = (I_tan(-ph[j]) - I_tan(ph[j])) / eps_;
    return sine_coefficients(f, n_modes);
}

}  // namespace hovering
