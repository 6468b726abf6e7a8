// A tangential curve rebuilt from its measured samples (what pickled and saved curves are): bit
// for bit the measured one, for graphs and non-graphs, and bad samples named.
#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

#include "hovering/normal/flow_map.hpp"
#include "hovering/normal/tangential_curve.hpp"
#include "testing.hpp"

using namespace hovering;

namespace {

FlowSystem issue_system(double eps) {
    FlowSystem s;
    s.V1 = std::make_shared<Harmonic>(1.0);
    s.V2 = std::make_shared<Tan>(1.4, 0.7);
    s.coupling = Coupling::bilinear();
    s.eps = eps;
    s.qw1 = -1.0;
    s.qw2 = -0.5;
    s.geometry = Geometry::Step;
    return s;
}

FlowOptions tight() {
    FlowOptions o;
    o.rtol = 1e-12;
    o.atol = 1e-12;
    return o;
}

bool same_bits(double a, double b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

TangentialCurve rebuilt(const TangentialCurve& c) {
    const auto [et, eI] = c.interpolation_error();
    return TangentialCurve::from_samples(c.h(), c.eps(), c.I_tan0(), c.theta(), c.I(), et, eI);
}

}  // namespace

TEST_CASE("tangential curve from its samples is the measured curve bit for bit", "[normal]") {
    for (double eps : {0.0, -0.05, 0.3}) {
        const TangentialCurve c = TangentialCurve::measure(issue_system(eps), 1.0, 64, tight(), 4);
        const TangentialCurve r = rebuilt(c);
        CHECK(r.s() == c.s());
        CHECK(r.is_graph() == c.is_graph());
        CHECKF(same_bits(r.min_slope(), c.min_slope()) && same_bits(r.min_slope_at(), c.min_slope_at()), "eps %g", eps);
        CHECK(r.interpolation_error() == c.interpolation_error());
        CHECK(r.not_graph_reason() == c.not_graph_reason());
        for (int k = 0; k < 101; ++k) {
            const double th = -3.14159 + 6.28318 * k / 100;
            const auto [a1, b1] = c.at(th);
            const auto [a2, b2] = r.at(th);
            CHECKF(same_bits(a1, a2) && same_bits(b1, b2), "eps %g at s = %g", eps, th);
            if (c.is_graph()) CHECKF(same_bits(c.I_tan(th), r.I_tan(th)), "eps %g at theta = %g", eps, th);
        }
    }
    // The flow map on a rebuilt curve steps bit for bit as on the measured one.
    const FlowSystem s = issue_system(-0.05);
    auto c = std::make_shared<TangentialCurve>(TangentialCurve::measure(s, 1.0, 64, tight(), 0));
    auto r = std::make_shared<TangentialCurve>(rebuilt(*c));
    const FlowMap a(s, 1.0, tight(), c), b(s, 1.0, tight(), r);
    for (double x : {-2.5, -0.4, 1.0, 2.7}) {
        const FlowStep p = a.step(x, -0.02), q = b.step(x, -0.02);
        CHECKF(same_bits(p.x, q.x) && same_bits(p.y, q.y) && p.region == q.region, "x = %g", x);
    }
}

TEST_CASE("tangential curve from bad samples is refused with the reason", "[normal]") {
    const std::vector<double> th(16, 0.5), I(16, 0.3);
    CHECK_INVALID(
        TangentialCurve::from_samples(1.0, 0.0, 0.3, std::vector<double>(7, 0.0), std::vector<double>(7, 0.3), 0, 0),
        "even number in [8, 4096] of samples, got 7");
    CHECK_INVALID(TangentialCurve::from_samples(1.0, 0.0, 0.3, th, std::vector<double>(14, 0.3), 0, 0), "same length");
    std::vector<double> bad = I;
    bad[3] = std::nan("");
    CHECK_INVALID(TangentialCurve::from_samples(1.0, 0.0, 0.3, th, bad, 0, 0), "I[3] must be finite");
    CHECK_INVALID(TangentialCurve::from_samples(std::nan(""), 0.0, 0.3, th, I, 0, 0), "h must be finite");
    CHECK_INVALID(TangentialCurve::from_samples(1.0, 0.0, 0.3, th, I, -1.0, 0), "err_theta must be >= 0");
    // theta constant while s runs once around: theta(s) - s winds -1 times, no interpolant.
    CHECK_INVALID(TangentialCurve::from_samples(1.0, 0.0, 0.3, th, I, 0, 0), "extra times around the cylinder");
}
