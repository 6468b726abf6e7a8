#pragma once
// Helpers shared by the core's translation units (not installed, not public API).

#include <gsl/gsl_errno.h>

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

}  // namespace hovering::detail
