// The build's facts: versions are the compile-time macros of the headers this core was compiled
// against (what it links may only differ in patch level for GSL and SLEEF, which are shared
// libraries); the commit comes from the header CMake regenerates at every build.
#include "hovering/build_info.hpp"

#include <gsl/gsl_version.h>
#include <sleef.h>
#include <sys/utsname.h>

#include <Eigen/Core>
#include <cstdio>
#include <thread>

#include "hovering/truncated/map.hpp"
#include "hovering/version.hpp"
#include "hovering_git.h"

namespace hovering {

namespace {

std::string compiler() {
#if defined(__clang__)
    return __VERSION__;  // "Clang 14.0.6 ..." names the compiler itself
#elif defined(__GNUC__)
    return std::string("GCC ") + __VERSION__;
#else
    return "unknown";
#endif
}

std::string platform() {
    struct utsname u;
    if (uname(&u) != 0) return "unknown";
    return std::string(u.sysname) + "-" + u.release + "-" + u.machine;
}

std::string json_string(const std::string& s) {
    std::string out = "\"";
    for (unsigned char c : s) {
        if (c == '"' || c == '\\') {
            out += '\\';
            out += char(c);
        } else if (c < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\u%04x", c);
            out += buf;
        } else {
            out += char(c);
        }
    }
    return out + "\"";
}

}  // namespace

std::vector<BuildFact> build_info() {
    auto n = [](long v) { return std::to_string(v); };
    return {
        {"hovering", kVersion},
        {"git", HOVERING_GIT_COMMIT},
        {"compiler", compiler()},
        {"gsl", GSL_VERSION},
        {"eigen", n(EIGEN_WORLD_VERSION) + "." + n(EIGEN_MAJOR_VERSION) + "." + n(EIGEN_MINOR_VERSION)},
        {"sleef", n(SLEEF_VERSION_MAJOR) + "." + n(SLEEF_VERSION_MINOR) + "." + n(SLEEF_VERSION_PATCHLEVEL)},
        {"simd_width", n(simd_width()), true},
        {"platform", platform()},
        {"hardware_threads", n(long(std::thread::hardware_concurrency())), true},
    };
}

std::string facts_json(const std::vector<BuildFact>& facts) {
    std::string s = "{";
    for (const auto& f : facts) {
        if (s.size() > 1) s += ", ";
        s += json_string(f.name) + ": " + (f.number ? f.value : json_string(f.value));
    }
    return s + "}";
}

}  // namespace hovering
