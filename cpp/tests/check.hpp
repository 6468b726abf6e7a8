#pragma once
// Minimal test harness: CHECK records a failure and continues; main returns the failure count.

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace hovering_test {
inline int& failures() { static int n = 0; return n; }
inline int& checks() { static int n = 0; return n; }
}  // namespace hovering_test

/// Record a failure (with file:line and message) when cond is false.
#define CHECK(cond, ...)                                                                 \
    do {                                                                                 \
        ++hovering_test::checks();                                                       \
        if (!(cond)) {                                                                   \
            ++hovering_test::failures();                                                 \
            std::fprintf(stderr, "%s:%d: CHECK(%s) failed: ", __FILE__, __LINE__, #cond); \
            std::fprintf(stderr, __VA_ARGS__);                                           \
            std::fprintf(stderr, "\n");                                                  \
        }                                                                                \
    } while (0)

/// Check that expr throws std::invalid_argument whose message contains `needle`.
#define CHECK_THROWS(expr, needle)                                                           \
    do {                                                                                     \
        ++hovering_test::checks();                                                           \
        std::string msg_;                                                                    \
        try { (void)(expr); } catch (const std::invalid_argument& e) { msg_ = e.what(); }   \
        if (msg_.find(needle) == std::string::npos) {                                        \
            ++hovering_test::failures();                                                     \
            std::fprintf(stderr, "%s:%d: %s did not throw invalid_argument containing '%s' (got '%s')\n", \
                         __FILE__, __LINE__, #expr, needle, msg_.c_str());                   \
        }                                                                                    \
    } while (0)

/// Print the summary line and return the process exit code.
inline int test_summary(const char* name) {
    std::printf("%s: %d checks, %d failed\n", name, hovering_test::checks(), hovering_test::failures());
    return hovering_test::failures() == 0 ? 0 : 1;
}
