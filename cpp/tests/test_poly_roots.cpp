// Root isolation on (0, 1] (detail/poly_roots.hpp), the guarantee behind every event search:
// polynomials built from known roots, in the power basis as a Taylor step or a Hermite
// interpolant hands them over.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "hovering/detail/poly_roots.hpp"
#include "testing.hpp"

using hovering::detail::at_most_one_root;
using hovering::detail::isolate_roots;
using hovering::detail::RootBracket;

namespace {

// Coefficients (lowest first) of scale * prod (s - r_i) * (1 + c s^2)^m (the last factor has no
// real root: it makes the degree high, as a Taylor step's, without adding sign changes).
std::vector<double> from_roots(const std::vector<double>& roots, double scale, double c, int m) {
    std::vector<double> p{scale};
    auto times = [&](const std::vector<double>& f) {
        std::vector<double> q(p.size() + f.size() - 1, 0.0);
        for (std::size_t i = 0; i < p.size(); ++i)
            for (std::size_t j = 0; j < f.size(); ++j) q[i + j] += p[i] * f[j];
        p = q;
    };
    for (double r : roots) times({-r, 1.0});
    for (int k = 0; k < m; ++k) times({1.0, 0.0, c});
    return p;
}

}  // namespace

TEST_CASE("isolate_roots: every sign change in (0, 1], in order, each bracket holding its root", "[roots]") {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    for (int trial = 0; trial < 2000; ++trial) {
        const int k = int(rng() % 5);          // 0..4 roots inside
        const int outside = int(rng() % 3);    // and some outside (0, 1]
        std::vector<double> inside, all;
        for (int i = 0; i < k; ++i) inside.push_back(U(rng));
        std::sort(inside.begin(), inside.end());
        // Roots closer than 1e-9 are a tangency to the isolation (and to any event search): keep
        // them apart by more, and away from the ends, so that the count is well defined.
        bool spaced = true;
        for (int i = 0; i < k; ++i) spaced = spaced && inside[i] > 1e-6 && inside[i] < 1 - 1e-6;
        for (int i = 1; i < k; ++i) spaced = spaced && inside[i] - inside[i - 1] > 1e-6;
        if (!spaced) continue;
        all = inside;
        for (int i = 0; i < outside; ++i) all.push_back(U(rng) < 0.5 ? -U(rng) - 1e-3 : 1 + 1e-3 + U(rng));
        const int m = int(rng() % 8);
        const std::vector<double> p = from_roots(all, U(rng) < 0.5 ? -3.0 : 0.7, 0.5 + U(rng), m);
        RootBracket br[8];
        const int n = isolate_roots(p.data(), int(p.size()) - 1, br, 8);
        INFO(hovering_test::msg("trial %d: %d roots inside, degree %d", trial, k, int(p.size()) - 1));
        REQUIRE(n == k);
        // the O(n) bounds in front of the isolation never claim one root where there are two
        CHECK(at_most_one_root(p.data(), int(p.size()) - 1) == (k <= 1));
        for (int i = 0; i < n; ++i) {
            CHECK(br[i].lo <= inside[std::size_t(i)]);
            CHECK(br[i].hi >= inside[std::size_t(i)]);
            if (i > 0) CHECK(br[i].lo >= br[i - 1].hi);
        }
    }
}

TEST_CASE("isolate_roots: a root at 0 is not counted; two close roots are two; max_out stops early", "[roots]") {
    // s (s - 0.5): the start sits on the root (a reflection off a wall, a start on the section).
    const std::vector<double> at0 = from_roots({0.0, 0.5}, 1.0, 1.0, 3);
    RootBracket br[4];
    REQUIRE(isolate_roots(at0.data(), int(at0.size()) - 1, br, 4) == 1);
    CHECK(br[0].lo <= 0.5);
    CHECK(br[0].hi >= 0.5);
    // A shallow dip: two roots 1e-5 apart, the signature of a skipped event.
    const std::vector<double> dip = from_roots({0.4, 0.40001}, 1.0, 2.0, 6);
    REQUIRE(isolate_roots(dip.data(), int(dip.size()) - 1, br, 4) == 2);
    CHECK(br[0].hi <= br[1].lo);
    CHECK(br[0].hi >= 0.4);
    CHECK(br[1].lo <= 0.40001);
    const std::vector<double> three = from_roots({0.1, 0.2, 0.3}, 1.0, 1.0, 0);
    CHECK(isolate_roots(three.data(), 3, br, 2) == 2);
    // No sign change: a positive quadratic with its minimum inside.
    const double pos[3] = {1.0, -2.0, 1.5};
    CHECK(isolate_roots(pos, 2, br, 4) == 0);
}
