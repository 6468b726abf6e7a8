#pragma once
// Helpers shared by the core's translation units (not installed, not public API).

#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>

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

/// A double with all 17 significant digits, for error messages that name the offending value.
inline std::string fmt(double v) {
    std::ostringstream s;
    s.precision(17);
    s << v;
    return s.str();
}

/// Throw the bad-input exception (pybind11 turns it into ValueError).
[[noreturn]] inline void bad(const std::string& msg) { throw std::invalid_argument(msg); }

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
        if (gsl_root_test_interval(gsl_root_fsolver_x_lower(s), gsl_root_fsolver_x_upper(s), 0.0, rel_tol) == GSL_SUCCESS) break;
    }
    gsl_root_fsolver_free(s);
    return x;
}

}  // namespace hovering::detail
