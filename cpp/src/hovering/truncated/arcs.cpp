// Arc models and forcings of the truncated family: the closed-form arcs of F_eps with their band,
// GSL natural cubic splines and tabulated arcs (|J_1| splined in sqrt(-K)), Fourier forcings.

#include "hovering/truncated/arcs.hpp"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_spline.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "hovering/detail/common.hpp"
#include "hovering/truncated/classify.hpp"
#include "hovering/truncated/forcing.hpp"
#include "hovering/truncated/map.hpp"

namespace hovering {

using detail::bad;
using detail::fmt;
using detail::gsl_quiet;
using detail::kInf;
using detail::kPi;
using detail::kTwoPi;
using detail::require_finite;

double wrap_angle(double x) {
    return detail::wrap(x);
}

// ---------------------------------------------------------------------------------------------
// Analytic arcs

void AnalyticArcs::validate() const {
    require_finite(Omega0, "Omega0");
    // The rotation of a step must be wrappable: Omega0 = -2.4e39 iterated to phi = 3e23 "OK".
    if (!(std::fabs(Omega0) <= detail::kMaxAngle))
        bad("Omega0 must lie in [-1e6, 1e6] (a larger rotation per step cannot be wrapped to [-pi, pi) "
            "accurately), got " +
            fmt(Omega0));
    require_finite(theta_w, "theta_w");
    require_finite(tau0, "tau0");
    require_finite(tau1, "tau1");
    require_finite(lam, "lam");
    if (!(theta_w > 0.0 && theta_w < kPi))
        bad("theta_w must lie in (0, pi) = (0, 3.141592653589793), got " + fmt(theta_w));
    if (!(lam > 0.0)) bad("lam must be > 0, got " + fmt(lam));
}

ArcLengths AnalyticArcs::at(double K) const {
    if (!(K < 0.0)) return {Omega0 + tau0 * K, 0.0, 0.0};
    return {Omega0 + tau0 * K, 2.0 * (kPi - theta_w) + tau1 * K, 2.0 * lam * std::sqrt(-K)};
}

ArcSlopes AnalyticArcs::slopes(double K) const {
    if (!(K < 0.0)) return {tau0, 0.0, 0.0};
    return {tau0, tau1, -lam / std::sqrt(-K)};
}

double AnalyticArcs::band_lo() const {
    // With K = -s^2 the three lengths are |J_1| = 2 lam s, |J_R| = 2(pi - theta_w) - tau1 s^2 and
    // |J_0| = 2 pi - |J_1| - |J_R|; all lie in (0, 2 pi) iff |J_R| > 0 and |J_0| > 0.
    double lo = -kInf;
    // |J_0| > 0  <=>  g(s) = tau1 s^2 - 2 lam s + 2 theta_w > 0; g(0) > 0, first root (if any) is
    // 2 theta_w / (lam + sqrt(lam^2 - 2 tau1 theta_w)), written this way to avoid cancellation.
    const double disc = lam * lam - 2.0 * tau1 * theta_w;
    if (disc >= 0.0) {
        const double s1 = 2.0 * theta_w / (lam + std::sqrt(disc));
        lo = std::max(lo, -s1 * s1);
    }
    if (tau1 > 0.0) lo = std::max(lo, -2.0 * (kPi - theta_w) / tau1);  // |J_R| > 0
    return lo;
}

// ---------------------------------------------------------------------------------------------
// Splines and tabulated arcs

Spline::Spline(std::vector<double> x, std::vector<double> y, const char* name)
    : x_(std::move(x)), y_(std::move(y)), name_(name), spline_(nullptr) {
    gsl_quiet();
    const std::string n(name);
    if (x_.size() != y_.size())
        bad(n + ": grid and values differ in length (" + std::to_string(x_.size()) + " vs " +
            std::to_string(y_.size()) + ")");
    if (x_.size() < 3) bad(n + ": needs at least 3 grid points, got " + std::to_string(x_.size()));
    for (std::size_t i = 0; i < x_.size(); ++i) {
        require_finite(x_[i], n + " grid[" + std::to_string(i) + "]");
        require_finite(y_[i], n + " value[" + std::to_string(i) + "]");
        if (i > 0 && !(x_[i] > x_[i - 1]))
            bad(n + ": grid must be strictly increasing, but grid[" + std::to_string(i) + "] = " + fmt(x_[i]) +
                " <= grid[" + std::to_string(i - 1) + "] = " + fmt(x_[i - 1]));
    }
    gsl_spline* s = gsl_spline_alloc(gsl_interp_cspline, x_.size());
    if (!s) throw std::bad_alloc();
    if (gsl_spline_init(s, x_.data(), y_.data(), x_.size()) != GSL_SUCCESS) {
        gsl_spline_free(s);
        bad(n + ": GSL could not build the cubic spline");
    }
    spline_ = s;
}

Spline::Spline(const Spline& o) : Spline(o.x_, o.y_, o.name_) {}

Spline::~Spline() {
    if (spline_) gsl_spline_free(static_cast<gsl_spline*>(spline_));
}

double Spline::operator()(double x) const {
    // Clamp rounding-level excursions; callers keep x inside the grid (the band is inside it).
    x = std::min(std::max(x, x_.front()), x_.back());
    return gsl_spline_eval(static_cast<const gsl_spline*>(spline_), x, nullptr);
}

double Spline::derivative(double x) const {
    x = std::min(std::max(x, x_.front()), x_.back());
    return gsl_spline_eval_deriv(static_cast<const gsl_spline*>(spline_), x, nullptr);
}

namespace {

std::vector<double> nonpositive_part(const std::vector<double>& K, const std::vector<double>& v, bool in_s) {
    // Points with K <= 0; in s = sqrt(-K) they must be reversed to stay increasing.
    std::vector<double> out;
    for (std::size_t i = 0; i < K.size(); ++i)
        if (K[i] <= 0.0) out.push_back(in_s ? std::sqrt(-K[i]) : v[i]);
    if (in_s) std::reverse(out.begin(), out.end());
    return out;
}

std::vector<double> nonpositive_values_reversed(const std::vector<double>& K, const std::vector<double>& v) {
    std::vector<double> out;
    for (std::size_t i = 0; i < K.size(); ++i)
        if (K[i] <= 0.0) out.push_back(v[i]);
    std::reverse(out.begin(), out.end());
    return out;
}

void check_table(const std::vector<double>& K, const std::vector<double>& Omega, const std::vector<double>& JR,
                 const std::vector<double>& J1) {
    if (Omega.size() != K.size() || JR.size() != K.size() || J1.size() != K.size())
        bad("K, Omega, JR and J1 must have the same length, got " + std::to_string(K.size()) + ", " +
            std::to_string(Omega.size()) + ", " + std::to_string(JR.size()) + ", " + std::to_string(J1.size()));
    bool has_zero = false;
    std::size_t n_nonpos = 0;
    // Checked here with the caller's indices: the splines see reordered copies.
    for (std::size_t i = 0; i < K.size(); ++i) {
        require_finite(K[i], "K[" + std::to_string(i) + "]");
        require_finite(Omega[i], "Omega[" + std::to_string(i) + "]");
        require_finite(JR[i], "JR[" + std::to_string(i) + "]");
        require_finite(J1[i], "J1[" + std::to_string(i) + "]");
        if (!(std::fabs(Omega[i]) <= detail::kMaxAngle))
            bad("Omega[" + std::to_string(i) +
                "] must lie in [-1e6, 1e6] (a larger rotation per step cannot be "
                "wrapped accurately), got " +
                fmt(Omega[i]));
        // Before the K = 0 and band checks, whose messages would mislead for a reversed grid.
        if (i > 0 && !(K[i] > K[i - 1]))
            bad("the K grid must be strictly increasing, but K[" + std::to_string(i) + "] = " + fmt(K[i]) + " <= K[" +
                std::to_string(i - 1) + "] = " + fmt(K[i - 1]));
    }
    for (std::size_t i = 0; i < K.size(); ++i) {
        if (K[i] == 0.0) {
            has_zero = true;
            // |J_1| = O(sqrt(-K)) closes at the tangency circle; a table that says otherwise is not
            // a near-tangency model.
            if (std::abs(J1[i]) > 1e-9)
                bad("J1 must vanish at K = 0 (|J_1| closes on the tangency circle), got " + fmt(J1[i]));
        }
        if (K[i] <= 0.0) ++n_nonpos;
    }
    if (!has_zero) bad("the K grid must contain K = 0 exactly (the tangency circle)");
    // Nearly coincident circles: a cubic spline's slopes are differences of values over the
    // spacing, so it amplifies the values' rounding (or measurement error) by range / spacing,
    // and its second derivatives by (range / spacing)^2; K = [..., 0, 1e-14, 0.05] gave
    // Omega'(0) = -8e11 instead of 3. 1e-9 of the range keeps rounding of 1e-16 below 1e-7 in the
    // slopes while admitting any grid a measurement would use (geometric grids toward K = 0
    // included, down to spacings 1e-9 of their range). The same bound holds, halved, for the
    // sqrt(-K) grid of |J_1|: its spacing ds = dK / (s_i + s_j) >= dK / (2 sqrt(-K_min)).
    const double range = K.back() - K.front();
    for (std::size_t i = 1; i < K.size(); ++i)
        if (!(K[i] - K[i - 1] >= 1e-9 * range))
            bad("the K grid's points must be at least 1e-9 of its range (" + fmt(range) + ") apart, but K[" +
                std::to_string(i - 1) + "] = " + fmt(K[i - 1]) + " and K[" + std::to_string(i) + "] = " + fmt(K[i]) +
                " are " + fmt(K[i] - K[i - 1]) +
                " apart (a cubic spline through nearly coincident points amplifies "
                "their rounding by range / spacing)");
    if (n_nonpos < 3) bad("the K grid needs at least 3 points with K <= 0, got " + std::to_string(n_nonpos));
    if (!(K.back() > 0.0)) bad("the K grid must extend above K = 0, got max K = " + fmt(K.back()));
}

}  // namespace

TabulatedArcs::TabulatedArcs(const std::vector<double>& K, const std::vector<double>& Omega_v,
                             const std::vector<double>& JR_v, const std::vector<double>& J1_v)
    : Omega((check_table(K, Omega_v, JR_v, J1_v), K), Omega_v, "Omega"),
      JR(nonpositive_part(K, K, false), nonpositive_part(K, JR_v, false), "JR"),
      J1s(nonpositive_part(K, K, true), nonpositive_values_reversed(K, J1_v), "J1") {}

ArcLengths TabulatedArcs::at(double K) const {
    if (!(K < 0.0)) return {Omega(K), 0.0, 0.0};
    return {Omega(K), JR(K), J1s(std::sqrt(-K))};
}

ArcSlopes TabulatedArcs::slopes(double K) const {
    if (!(K < 0.0)) return {Omega.derivative(K), 0.0, 0.0};
    const double s = std::sqrt(-K);
    return {Omega.derivative(K), JR.derivative(K), -J1s.derivative(s) / (2.0 * s)};
}

double TabulatedArcs::band_lo() const {
    auto ok = [this](double s) {
        const ArcLengths a = at(-s * s);
        return a.J1 > 0.0 && a.JR > 0.0 && a.J1 + a.JR < kTwoPi;
    };
    const double smax = J1s.xmax();
    const std::size_t n = 64 * J1s.x().size();
    double good = 0.0;
    for (std::size_t i = 1; i <= n; ++i) {
        const double s = smax * double(i) / double(n);
        if (ok(s)) {
            good = s;
            continue;
        }
        if (good == 0.0)
            bad("the tabulated arcs give no valid band below K = 0: at K = " + fmt(-s * s) +
                " the arc lengths (|J_R|, |J_1|) = (" + fmt(at(-s * s).JR) + ", " + fmt(at(-s * s).J1) +
                ") are not all in (0, 2 pi)");
        double badv = s;  // bisect the first failure between the last good and first bad sample
        for (int it = 0; it < 200 && badv - good > 1e-15 * badv; ++it) {
            const double mid = 0.5 * (good + badv);
            (ok(mid) ? good : badv) = mid;
        }
        return -good * good;
    }
    return -smax * smax;
}

double TabulatedArcs::omega_limit(double direction) const {
    // The tabulated values obey |Omega| <= kMaxAngle (check_table), but the spline between them
    // can overshoot; the band stops where it first exceeds the bound, as for the analytic arcs.
    const std::vector<double>& k = Omega.x();
    std::vector<double> nodes;  // from K = 0 outwards
    for (double x : k)
        if (direction > 0 ? x >= 0.0 : x <= 0.0) nodes.push_back(x);
    if (direction < 0) std::reverse(nodes.begin(), nodes.end());
    auto ok = [this](double x) { return std::fabs(Omega(x)) <= detail::kMaxAngle; };
    double good = 0.0;
    for (std::size_t i = 1; i < nodes.size(); ++i)
        for (int j = 1; j <= 64; ++j) {
            const double x = nodes[i - 1] + (nodes[i] - nodes[i - 1]) * (double(j) / 64.0);
            if (ok(x)) {
                good = x;
                continue;
            }
            double badv = x;  // bisect between the last sample within the bound and the first beyond
            for (int it = 0; it < 200 && std::fabs(badv - good) > 1e-15 * std::fabs(badv); ++it) {
                const double mid = 0.5 * (good + badv);
                (ok(mid) ? good : badv) = mid;
            }
            return good;
        }
    return direction > 0 ? kInf : -kInf;
}

// ---------------------------------------------------------------------------------------------
// Forcings

double SineForcing::at(double phi) const {
    return std::sin(phi);
}

double SineForcing::slope(double phi) const {
    return std::cos(phi);
}

double FourierForcing::slope(double phi) const {
    double f = 0.0;
    for (std::size_t k = 0; k < b.size(); ++k)
        if (b[k] != 0.0) f += double(k + 1) * b[k] * std::cos(double(k + 1) * phi);
    return f;
}

double FourierForcing::at(double phi) const {
    double f = 0.0;
    for (std::size_t k = 0; k < b.size(); ++k)
        if (b[k] != 0.0) f += b[k] * std::sin(double(k + 1) * phi);
    return f;
}

}  // namespace hovering
