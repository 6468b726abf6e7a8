#pragma once
// Shared by the C++ tests (Catch2 v2 from Debian): printf-style context for checks that run in
// loops, and "throws std::invalid_argument whose message names ..." for the bad-input tests.

#include <catch2/catch.hpp>

#include <cstdarg>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

#include "hovering/flow/system.hpp"

namespace hovering_test {

/// The step system shape: V1, V2, bilinear coupling eps q1 q2, walls at qw = (-1, -0.5).
inline hovering::FlowSystem step_system(std::shared_ptr<const hovering::Potential> V1,
                                        std::shared_ptr<const hovering::Potential> V2, hovering::Geometry g,
                                        double eps) {
    hovering::FlowSystem s;
    s.V1 = std::move(V1);
    s.V2 = std::move(V2);
    s.coupling = hovering::Coupling::bilinear();
    s.eps = eps;
    s.qw1 = -1.0;
    s.qw2 = -0.5;
    s.geometry = g;
    return s;
}

/// printf into a std::string (the context a failing check prints).
inline std::string msg(const char* fmt, ...) {
    char buf[512];
    va_list ap;
    va_start(ap, fmt);
    std::vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    return buf;
}

/// Matches an exception whose what() contains a substring.
class MessageContains : public Catch::MatcherBase<std::invalid_argument> {
public:
    explicit MessageContains(std::string needle) : needle_(std::move(needle)) {}
    bool match(const std::invalid_argument& e) const override {
        return std::string(e.what()).find(needle_) != std::string::npos;
    }
    std::string describe() const override { return "message contains \"" + needle_ + "\""; }

private:
    std::string needle_;
};

}  // namespace hovering_test

/// CHECK(cond) with printf-style context printed when it fails.
#define CHECKF(cond, ...)                      \
    do {                                       \
        INFO(hovering_test::msg(__VA_ARGS__)); \
        CHECK((cond));                         \
    } while (0)

/// expr throws std::invalid_argument whose message contains needle (bad input names itself).
#define CHECK_INVALID(expr, needle) \
    CHECK_THROWS_MATCHES(expr, std::invalid_argument, hovering_test::MessageContains(needle))
