#pragma once
// Helpers shared by the core's translation units (not installed, not public API): messages that
// name the bad value, GSL error handling, and the root finders of event location and potentials.

#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>

#include <charconv>
#include <cmath>
#include <functional>

#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>

namespace hovering::detail {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kInf = std::numeric_limits<double>::infinity();
inline constexpr double kTwoPi = 2.0 * kPi;
inline constexpr double kInvTwoPi = 1.0 / kTwoPi;
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Wrap to [-pi, pi): the one definition (hovering::wrap_angle, the truncated map, the flow map,
/// the tangential curve, the exact flow); idempotent on [-pi, pi).
inline double wrap(double x) {
    double y = x - kTwoPi * std::floor((x + kPi) * kInvTwoPi);
    // For |x| < 1e15 the line above lands within one turn of [-pi, pi); these corrections are
    // exact (Sterbenz: y -/+ 2 pi for |y| in [pi, 4 pi]). Without the second, x one ulp below pi
    // (x + pi rounds up to 2 pi) became one ulp below -pi.
    if (y >= kPi) y -= kTwoPi;
    if (y < -kPi) y += kTwoPi;
    return y;
}

/// A double in its shortest round-trip form (1e+200, not 9.9999999999999997e+199; "nan", "inf",
/// "-inf"): the one formatter of every message of the core, the plan reader and the sweep, which
/// name the offending value exactly as the user typed it (std::to_string prints six decimals: a
/// tiny band's edge read "-0.000000").
inline std::string fmt(double v) {
    if (std::isnan(v)) return "nan";  // to_chars writes "-nan" for a NaN with its sign bit set
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
}

/// Throw the bad-input exception (pybind11 turns it into ValueError).
[[noreturn]] inline void bad(const std::string& msg) {
    throw std::invalid_argument(msg);
}

/// Throw unless v is finite, naming it.
inline void require_finite(double v, const std::string& name) {
    if (!std::isfinite(v)) bad(name + " must be finite, got " + fmt(v));
}

/// Beyond this, 2 pi floor(phi / 2 pi) is off by more than one turn in double precision, so an
/// angle cannot be wrapped meaningfully; 1e6 keeps the wrapping error below 1e-9.
inline constexpr double kMaxAngle = 1e6;

/// Throw unless v is a finite angle that can be wrapped accurately (|v| <= kMaxAngle), naming it.
inline void require_angle(double v, const std::string& name) {
    require_finite(v, name);
    if (!(std::fabs(v) <= kMaxAngle))
        bad(name + " must be an angle with |" + name +
            "| <= 1e6 (larger angles cannot be wrapped to [-pi, pi) "
            "accurately in double precision), got " +
            fmt(v));
}

/// Turn GSL's abort-on-error handler off once: every GSL call here validates its inputs first,
/// and a library must never abort its host process.
inline void gsl_quiet() {
    static std::once_flag once;
    std::call_once(once, [] { gsl_set_error_handler_off(); });
}

/// Root of f on [lo, hi] (f(lo), f(hi) of opposite signs) by GSL's Brent solver; stops when the
/// bracket is below rel_tol relative or |f| <= ftol at the current estimate. The last evaluation is
/// cached, so f is called once per iteration (it may be an integrator step).
inline double brent(const std::function<double(double)>& f, double lo, double hi, double rel_tol, double ftol = 0.0) {
    gsl_quiet();
    struct Ctx {
        const std::function<double(double)>* f;
        double x, fx;
    } ctx{&f, std::nan(""), std::nan("")};
    gsl_function F{[](double x, void* p) {
                       auto* c = static_cast<Ctx*>(p);
                       c->x = x;
                       c->fx = (*c->f)(x);
                       return c->fx;
                   },
                   &ctx};
    gsl_root_fsolver* s = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
    gsl_root_fsolver_set(s, &F, lo, hi);
    double x = 0.5 * (lo + hi);
    for (int it = 0; it < 200; ++it) {
        gsl_root_fsolver_iterate(s);
        x = gsl_root_fsolver_root(s);
        if (x == ctx.x && std::fabs(ctx.fx) <= ftol) break;
        if (gsl_root_test_interval(gsl_root_fsolver_x_lower(s), gsl_root_fsolver_x_upper(s), 0.0, rel_tol) ==
            GSL_SUCCESS)
            break;
    }
    gsl_root_fsolver_free(s);
    return x;
}

/// Root of a function on [lo, hi] (values of opposite signs at the ends) by Newton's method
/// (GSL's fdfsolver) from the guess x0, safeguarded: every evaluation shrinks the bracket, and an
/// iterate outside it, a zero derivative or 10 iterations without convergence hand over to Brent
/// on the current bracket (f(lo) has the sign f_lo_positive, f(hi) the other). fdf(x, &f, &df)
/// evaluates both at once (one integrator step each), so from a good guess this costs 2-3
/// evaluations where bisection-type methods need ~8. Returns the last evaluated point x once the
/// next Newton correction -f/f' (stored in *delta) is below x_tol: the caller applies it to its
/// state linearly (error ~ delta^2) instead of paying for another evaluation.
inline double newton_bracketed(const std::function<void(double, double*, double*)>& fdf, double lo, bool f_lo_positive,
                               double hi, double x0, double x_tol, double* delta) {
    gsl_quiet();
    struct Ctx {
        const std::function<void(double, double*, double*)>* fdf;
        double x, fx, dfx;
        double lo, hi;
        int sign_lo;  // sign of f at lo
        void (*eval)(double, void*, double*, double*);
    } ctx{&fdf, std::nan(""), std::nan(""), std::nan(""), lo, hi, f_lo_positive ? 1 : -1, nullptr};
    // GSL's Newton init asks for f and f' separately: all three callbacks share one cached
    // evaluation, so each point costs one integrator step.
    auto eval = [](double x, void* p, double* f, double* df) {
        auto* c = static_cast<Ctx*>(p);
        if (!(x == c->x)) {
            (*c->fdf)(x, &c->fx, &c->dfx);
            c->x = x;
            if (x >= c->lo && x <= c->hi && c->fx != 0) ((c->fx > 0 ? 1 : -1) == c->sign_lo ? c->lo : c->hi) = x;
        }
        *f = c->fx;
        *df = c->dfx;
    };
    gsl_function_fdf F{[](double x, void* p) {
                           double f, df;
                           auto* c = static_cast<Ctx*>(p);
                           c->eval(x, p, &f, &df);
                           return f;
                       },
                       [](double x, void* p) {
                           double f, df;
                           auto* c = static_cast<Ctx*>(p);
                           c->eval(x, p, &f, &df);
                           return df;
                       },
                       eval, &ctx};
    ctx.eval = eval;
    x0 = std::min(std::max(x0, lo), hi);
    gsl_root_fdfsolver* s = gsl_root_fdfsolver_alloc(gsl_root_fdfsolver_newton);
    bool ok = gsl_root_fdfsolver_set(s, &F, x0) == GSL_SUCCESS;
    for (int it = 0; ok; ++it) {
        if (ctx.fx == 0) {
            *delta = 0;
            break;
        }
        if (it == 10 || ctx.dfx == 0 || !std::isfinite(ctx.dfx) || !std::isfinite(ctx.fx)) {
            ok = false;
            break;
        }
        const double xn = ctx.x - ctx.fx / ctx.dfx;
        if (!(xn >= ctx.lo && xn <= ctx.hi)) {  // Newton would leave the bracket
            ok = false;
            break;
        }
        *delta = xn - ctx.x;
        if (std::fabs(*delta) <= x_tol) break;
        if (gsl_root_fdfsolver_iterate(s) != GSL_SUCCESS) ok = false;
    }
    gsl_root_fdfsolver_free(s);
    if (ok) return ctx.x;
    // Brent on the shrunken bracket, then one evaluation at its root.
    double f, df, flo, fhi;
    *delta = 0;
    fdf(ctx.lo, &flo, &df);
    fdf(ctx.hi, &fhi, &df);
    if (flo == 0 || fhi == 0 || (flo > 0) == (fhi > 0)) {  // rounding at an end: take the better end
        const double r = std::fabs(flo) <= std::fabs(fhi) ? ctx.lo : ctx.hi;
        fdf(r, &f, &df);
        return r;
    }
    const double r = brent(
        [&](double t) {
            fdf(t, &f, &df);
            return f;
        },
        ctx.lo, ctx.hi, 1e-15);
    fdf(r, &f, &df);
    return r;
}

/// Root in [0, h] of the cubic Hermite interpolant of values f0, f1 and derivatives d0, d1 at
/// 0 and h (f0, f1 of opposite signs): the first guess of an event time inside a step.
inline double hermite_root(double f0, double d0, double f1, double d1, double h) {
    auto H = [&](double s, double* dh) {  // s in [0, 1]
        const double s2 = s * s, s3 = s2 * s;
        const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
        *dh =
            (6 * s2 - 6 * s) * f0 + (3 * s2 - 4 * s + 1) * h * d0 + (-6 * s2 + 6 * s) * f1 + (3 * s2 - 2 * s) * h * d1;
        return h00 * f0 + h10 * h * d0 + h01 * f1 + h11 * h * d1;
    };
    double lo = 0, hi = 1, s = f0 / (f0 - f1);  // secant start
    const bool neg_lo = f0 < 0;
    for (int it = 0; it < 30; ++it) {
        double dh;
        const double v = H(s, &dh);
        if (v == 0) break;
        ((v < 0) == neg_lo ? lo : hi) = s;
        double sn = dh != 0 ? s - v / dh : 0.5 * (lo + hi);
        if (!(sn > lo && sn < hi)) sn = 0.5 * (lo + hi);
        if (std::fabs(sn - s) < 1e-12) {
            s = sn;
            break;
        }
        s = sn;
    }
    return s * h;
}

}  // namespace hovering::detail
