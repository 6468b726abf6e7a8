// hovering_area in C++: numpy's random stream reproduced, the stratified grid, the estimate against
// eq:hovsetsize, thread-count invariance and cancellation.
#include <atomic>
#include <cmath>
#include <vector>

#include "testing.hpp"
#include "hovering/analysis/hovering_area.hpp"
#include "hovering/analysis/theory.hpp"
#include "hovering/truncated/map.hpp"

using namespace hovering;
namespace {
const double kPi = 3.14159265358979323846;
const double kOmegaG = 3.883222077450933;
}  // namespace

TEST_CASE("NumpyRandom is numpy.random.default_rng(seed) to the bit") {
    // Reference values printed by numpy (np.random.PCG64(seed).random_raw(3), default_rng(seed).random()):
    // an independent implementation of SeedSequence + PCG64 whose stream numpy keeps stable across versions.
    struct Ref {
        std::uint64_t seed, raw[3];
        double first;
    };
    const Ref refs[] = {
        {0, {0xa30febcfd9c2825fULL, 0x4510bdf882d9d721ULL, 0x0a7d3da94ecde8b8ULL}, 0.6369616873214543},
        {7, {0xa00641a9f1e54a8bULL, 0xe5afcdbcaf266a95ULL, 0xc693565f940af962ULL}, 0.625095466604667},
        {1099511627779ULL, {0xc60e533fbbb0872cULL, 0xfef0825f71d66341ULL, 0x792240db6171ac88ULL}, 0.7736560850714245},
        {9223372036854775807ULL, {0x2ceb59116fb27514ULL, 0x784d3e7d390dc57cULL, 0xd335a7689ce43488ULL},
         0.1754661243027813},
    };
    for (const auto& r : refs) {
        NumpyRandom a(r.seed), b(r.seed);
        for (auto x : r.raw) CHECK(a.next_u64() == x);
        CHECK(b.random() == r.first);
    }
}

TEST_CASE("stratified_samples: Python's grid and jitter, one point per cell") {
    std::vector<double> phi, K;
    stratified_samples(1000, -0.3, 5, phi, K);
    // numpy: hovering.analysis.hovering._stratified(1000, -0.3, np.random.default_rng(5)).
    REQUIRE(phi.size() == 1015);
    CHECK(phi.front() == -3.106710015364182);
    CHECK(phi.back() == 3.108810020655066);
    CHECK(K.front() == -0.28693801016168813);
    CHECK(K.back() == -0.017027939140153214);
    // n_phi = round(sqrt(1000 * 2 pi / 0.3)) = 145 columns, ceil(1000 / 145) = 7 rows.
    const int n_phi = 145, n_K = 7;
    std::vector<int> hits(n_phi * n_K, 0);
    for (std::size_t i = 0; i < phi.size(); ++i) {
        const int c = int(std::floor((phi[i] + kPi) / (2 * kPi) * n_phi));
        const int r = int(std::floor((K[i] + 0.3) / 0.3 * n_K));
        REQUIRE(c >= 0);
        REQUIRE(c < n_phi);
        REQUIRE(r >= 0);
        REQUIRE(r < n_K);
        ++hits[c * n_K + r];
    }
    for (int h : hits) CHECK(h == 1);
    CHECK_THROWS_AS(stratified_samples(10, 0.0, 0, phi, K), std::invalid_argument);
}

TEST_CASE("hovering_area of F_eps agrees with eq:hovsetsize and ignores the thread count") {
    const double tw = 3 * kPi / 4;
    for (double eps : {0.05, 0.1}) {
        const TruncatedMap m = make_truncated_map(eps, kOmegaG, tw, 1.0, 0.5, 0.5);
        HoveringAreaOptions o;
        o.n_steps = 2000;
        o.samples = 20000;
        o.seed = 1;
        o.K_low = -default_depth(eps, kOmegaG, {1.0});
        const HoveringAreaResult a = hovering_area(m, o);
        o.n_threads = 1;
        const HoveringAreaResult b = hovering_area(m, o);
        CHECK(a.area == b.area);
        CHECK(a.n_samples == b.n_samples);
        const double theory = hovering_area_theory(eps, kOmegaG, tw, {1.0});
        CHECK(theory == Approx(eps * (std::sin(tw) - tw * std::cos(tw)) / std::sin(0.5 * kOmegaG)).epsilon(1e-15));
        // eq:hovsetsize is the leading order: the measured area differs by its error bar plus
        // O(eps^2) (Python measured 0.1269 vs 0.1273 at eps = 0.05 and 0.2512 vs 0.2546 at 0.1).
        CHECK(std::abs(a.area - theory) < a.error + 0.5 * eps * eps);
        CHECK(a.error > 0);
        CHECK(a.area_both_sides <= a.area);
        CHECK(a.area_half >= a.area);  // estimates only fall as orbits are followed longer
        CHECK(a.area_quarter >= a.area_half);
        CHECK(!a.interrupted);
    }
    // eps < 0 does not hover (sin(Omega_G / 2) > 0): theory 0, and the measured area is within its bar.
    const TruncatedMap m = make_truncated_map(-0.1, kOmegaG, tw, 1.0, 0.5, 0.5);
    HoveringAreaOptions o;
    o.n_steps = 2000;
    o.samples = 5000;
    o.K_low = -0.2;
    const HoveringAreaResult h = hovering_area(m, o);
    CHECK(hovering_area_theory(-0.1, kOmegaG, tw, {1.0}) == 0.0);
    CHECK(h.area <= h.error);
}

TEST_CASE("hovering_area: bad boxes are refused, a cancelled run says so") {
    const TruncatedMap m = make_truncated_map(0.1, kOmegaG, 3 * kPi / 4, 1.0, 0.5, 0.5);
    HoveringAreaOptions o;
    o.K_low = 0.1;
    CHECK_THROWS_AS(hovering_area(m, o), std::invalid_argument);
    o.K_low = -100;  // below the band
    CHECK_THROWS_AS(hovering_area(m, o), std::invalid_argument);
    o.K_low = -0.2;
    o.n_steps = 3;
    CHECK_THROWS_AS(hovering_area(m, o), std::invalid_argument);
    std::atomic<bool> cancel{true};
    o.n_steps = 100000;
    o.cancel = &cancel;
    CHECK(hovering_area(m, o).interrupted);
}

TEST_CASE("theory: resonances give NaN, a multi-mode forcing integrates the lowest curve") {
    CHECK(std::isnan(hovering_area_theory(0.1, 0.0, 1.0, {1.0})));
    CHECK(std::isnan(hovering_area_theory(0.1, 1.0, 4.0, {1.0})));
    CHECK_THROWS_AS(hovering_area_theory(0.1, 2e6, 1.0, {1.0}), std::invalid_argument);
    // A second mode of zero amplitude changes nothing: the grid integral equals the closed form
    // up to its n^-2 discretisation (1e-10 relative at 100001 points).
    const double closed = hovering_area_theory(0.1, kOmegaG, 2.0, {1.0});
    const double grid = hovering_area_theory(0.1, kOmegaG, 2.0, {1.0, 1e-300});
    CHECK(grid == Approx(closed).epsilon(1e-8));
    // Python: hv.TruncatedMap(0.1, OMEGA_G, 3 pi / 4).hovering_area(...).box[2] (its default box).
    CHECK(-default_depth(0.1, kOmegaG, {1.0}) == -0.2145848093800635);
    CHECK(-default_depth(0.05, kOmegaG, {1.0}) == -0.10729240469003175);
}
