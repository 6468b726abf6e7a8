// Curve: the periodic cubic spline through uniform samples, and the bounds the SIMD kernel's stop
// test relies on (no state beyond lower() / upper() can lie in the set, so packets there skip the
// spline).
#include <cmath>
#include <vector>

#include "hovering/curve.hpp"
#include "hovering/detail/common.hpp"
#include "testing.hpp"

using namespace hovering;
using hovering_test::MessageContains;

namespace {
const double kPi = Curve::kPi;

std::vector<double> sampled(int n, double (*f)(double)) {
    std::vector<double> K(static_cast<std::size_t>(n));
    for (int j = 0; j < n; ++j) K[std::size_t(j)] = f(-kPi + 2 * kPi * j / n);
    return K;
}
double smooth(double phi) {
    return 0.3 + 0.1 * std::cos(phi) + 0.05 * std::sin(3 * phi);
}
double kinked(double phi) {
    return std::fabs(phi - 0.3) < kPi ? std::fabs(phi - 0.3) : 2 * kPi - std::fabs(phi - 0.3);
}
}  // namespace

TEST_CASE("curve: exact at the samples, spline accuracy, periodicity", "[curve]") {
    const int n = 64;
    const Curve c(sampled(n, smooth));
    for (int j = 0; j < n; ++j) {
        const double phi = -kPi + 2 * kPi * j / n;
        CHECKF(std::fabs(c(phi) - smooth(phi)) <= 1e-15, "sample %d", j);
    }
    // 5/384 h^4 max|f''''| (max|f''''| <= 0.1 + 81 * 0.05) bounds the periodic spline's error
    const double h = 2 * kPi / n, bound = 5.0 / 384.0 * std::pow(h, 4) * (0.1 + 81 * 0.05) + 1e-15;
    double worst = 0;
    for (int i = 0; i < 20000; ++i) {
        const double phi = -kPi + 2 * kPi * (i + 0.37) / 20000;
        worst = std::max(worst, std::fabs(c(phi) - smooth(phi)));
    }
    CHECKF(worst <= bound, "error %g > bound %g", worst, bound);
    CHECK(c(kPi) == c(-kPi));  // pi wraps to -pi
    CHECK(c(0.4 + 2 * kPi) == c(detail::wrap(0.4 + 2 * kPi)));
    CHECK(std::isnan(c(std::nan(""))));
    const Curve k(std::vector<double>{0.7});
    CHECK(k.is_constant());
    CHECK(k(1.0) == 0.7);
    CHECK(k.lower() == 0.7);
    CHECK(k.upper() == 0.7);
}

TEST_CASE("curve: lower() and upper() bound every value, tightly", "[curve]") {
    for (auto f : {smooth, kinked}) {
        for (int n : {3, 7, 64, 301}) {
            const Curve c(sampled(n, f));
            double lo = INFINITY, hi = -INFINITY;
            for (int i = 0; i <= 200000; ++i) {
                const double phi = -kPi + 2 * kPi * i / 200000.0;
                const double v = c.value(phi < kPi ? phi : -kPi);
                lo = std::min(lo, v);
                hi = std::max(hi, v);
            }
            // bounds hold; and they are the spline's extremes (the dense grid finds them to
            // ~(2 pi / 2e5)^2 |K''| / 8 < 1e-6) plus a margin of 1e-12 of the coefficients
            CHECKF(c.lower() <= lo && hi <= c.upper(), "n = %d: [%g, %g] vs values [%g, %g]", n, c.lower(), c.upper(),
                   lo, hi);
            CHECKF(lo - c.lower() < 1e-6 && c.upper() - hi < 1e-6, "n = %d: loose bounds", n);
        }
    }
}

TEST_CASE("curve: bad samples and stop conditions are refused", "[curve]") {
    CHECK_THROWS_MATCHES(Curve(std::vector<double>{}), std::invalid_argument, MessageContains("got none"));
    CHECK_THROWS_MATCHES(Curve(std::vector<double>{1.0, 2.0}), std::invalid_argument, MessageContains("got 2"));
    CHECK_THROWS_MATCHES(Curve(std::vector<double>{1.0, std::nan(""), 2.0}), std::invalid_argument,
                         MessageContains("curve sample K[1]"));
    CHECK_THROWS_MATCHES(Curve(std::vector<double>{1.0, 2.0, 1e308, -1e308}), std::invalid_argument,
                         MessageContains("coefficients overflow"));
    CHECK_THROWS_AS(Curve(sampled(8, smooth))(INFINITY), std::invalid_argument);
    StopCondition s;
    s.side = StopSide::Above;  // a side without a curve
    CHECK_THROWS_MATCHES(s.validate(), std::invalid_argument, MessageContains("needs a curve"));
    s.curve = std::make_shared<const Curve>(std::vector<double>{0.5});
    s.validate();
    CHECK(s.reached(0.0, 0.5));
    CHECK_FALSE(s.reached(0.0, std::nextafter(0.5, 0.0)));
    s.side = StopSide::Below;
    CHECK(s.reached(0.0, 0.5));
    CHECK_FALSE(s.reached(0.0, std::nextafter(0.5, 1.0)));
}
