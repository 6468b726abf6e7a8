// F_eps: band, input validation, exact inverse, reversibility and the eps = 0 interval exchange.
#include <algorithm>
#include <random>
#include <vector>

#include "hovering/truncated/map.hpp"
#include "testing.hpp"

using namespace hovering;
namespace {
const double kPi = 3.14159265358979323846;
const double OmegaG = kPi * (std::sqrt(5.0) - 1.0);

// Distance from phi to the nearest arc end on circle K (infinite for K >= 0).
double boundary_distance(const TruncatedMap& m, double phi, double K) {
    if (K >= 0) return 1e300;
    double best = 1e300;
    for (double s : m.arc_starts(K)) {
        double d = std::fabs(wrap_angle(phi - s));
        best = std::min(best, d);
    }
    return best;
}

// Brute-force lower band end: scan K downward until an arc length leaves (0, 2 pi).
double band_by_scan(double tw, double tau1, double lam) {
    double last = 0;
    for (int i = 1; i < 2000000; ++i) {
        double K = -1e-5 * i;
        double s = std::sqrt(-K);
        double L1 = 2 * lam * s, LR = 2 * (kPi - tw) + tau1 * K, L0 = 2 * kPi - L1 - LR;
        if (!(L1 > 0 && LR > 0 && L0 > 0 && L1 < 2 * kPi && LR < 2 * kPi && L0 < 2 * kPi)) return last;
        last = K;
    }
    return last;
}
}  // namespace

TEST_CASE("F_eps: band, bad input, exact inverse, reversibility, eps = 0 interval exchange", "[truncated]") {
    // Band: closed form against a scan (step 1e-5 in K, so agreement to 1e-5 is all a scan can give).
    struct P {
        double tw, tau1, lam;
    };
    for (P p : {P{3 * kPi / 4, 0.5, 0.5}, P{0.1, 0.5, 0.5}, P{2.0, -0.8, 1.3}, P{1.0, 0.0, 0.7}, P{2.5, 3.0, 0.2}}) {
        TruncatedMap m = make_truncated_map(0.1, 1.0, p.tw, 1.0, p.tau1, p.lam);
        double scan = band_by_scan(p.tw, p.tau1, p.lam);
        CHECKF(std::fabs(m.band().lo - scan) <= 1.01e-5, "tw=%g tau1=%g lam=%g: band lo %.12g vs scan %.12g", p.tw,
               p.tau1, p.lam, m.band().lo, scan);
        // The top is where the rotation Omega0 + tau0 K reaches 1e6 rad (wrapping stays accurate).
        CHECKF(m.band().hi == 1e6 - 1.0, "hi = (1e6 - Omega0) / tau0, got %.17g", m.band().hi);
    }
    CHECKF(std::isinf(make_truncated_map(0.1, 1.0, 2.0, 0.0, 0.5, 0.5).band().hi), "tau0 = 0: no top");
    CHECKF(make_truncated_map(0.1, 1.0, 2.0, -2.0, 0.5, 0.5).band().hi == (1e6 + 1.0) / 2.0, "tau0 < 0");
    CHECK_INVALID(make_truncated_map(0.1, -2.4e39, 2.0, 1.0, 0.5, 0.5), "Omega0 must lie in [-1e6, 1e6]");
    // ... and below 0 too: with tau0 = 4e20 the band is |K| < 2.3e-15 (phi stayed 0 before).
    const auto tb = make_truncated_map(0.1, 1.0, 2.0, 4e20, 0.5, 0.5).band();
    CHECKF(tb.lo == -(1e6 + 1.0) / 4e20 && tb.hi == (1e6 - 1.0) / 4e20, "band [%g, %g] for tau0 = 4e20", tb.lo, tb.hi);
    // eq:kmindef would give -min((pi/lam)^2, 2(pi - tw)/tau1) = -11.9 here; |J_0| closes first (typo 3).
    CHECKF(make_truncated_map(0.1, 1.0, 0.1, 1.0, 0.5, 0.5).band().lo > -0.06, "typo-3 case");

    // Bad input names the parameter and the allowed range.
    CHECK_INVALID(make_truncated_map(0.3, OmegaG, 0.0, 1, 0.5, 0.5), "theta_w must lie in (0, pi)");
    CHECK_INVALID(make_truncated_map(0.3, OmegaG, kPi, 1, 0.5, 0.5), "theta_w must lie in (0, pi)");
    CHECK_INVALID(make_truncated_map(0.3, OmegaG, 1.0, 1, 0.5, 0.0), "lam must be > 0");
    CHECK_INVALID(make_truncated_map(0.3, OmegaG, 1.0, 1, 0.5, -1.0), "lam must be > 0");
    CHECK_INVALID(make_truncated_map(std::nan(""), OmegaG, 1.0, 1, 0.5, 0.5), "eps must be finite");
    CHECK_INVALID(make_truncated_map(0.3, INFINITY, 1.0, 1, 0.5, 0.5), "Omega0 must be finite");
    CHECK_INVALID(make_truncated_map(0.3, OmegaG, 1.0, 1, 0.5, 0.5, -1.0), "K_max must be > 0");
    TruncatedMap m = make_truncated_map(0.3, OmegaG, 3 * kPi / 4, 1.0, 0.5, 0.5);
    CHECK_INVALID(m.step(0.0, -4.0), "outside the band");
    CHECK_INVALID(m.step(std::nan(""), -1.0), "phi must be finite");
    CHECK_INVALID(m.region(0.0, INFINITY), "K must be finite");

    // wrap_angle lands in [-pi, pi) even at the edges.
    for (double x : {kPi, -kPi, 3 * kPi, -3 * kPi, std::nextafter(kPi, 0.0), 1e6, -1e6}) {
        double y = wrap_angle(x);
        CHECKF(y >= -kPi && y < kPi, "wrap(%.17g) = %.17g", x, y);
        CHECKF(std::fabs(std::remainder(y - x, 2 * kPi)) < 1e-9, "wrap changed the angle");
    }

    // Exact inverse and reversibility R F R = F^{-1}, R(phi, K) = (-phi, K - eps sin phi), on random
    // band points at least 1e-9 from arc ends (a point closer than the rounding of the arc ends,
    // ~1e-15, may be assigned to either neighbour, so the margin is generous). Tolerance 1e-12:
    // a step adds a handful of roundings of O(4 pi) numbers, ~1e-14.
    std::mt19937_64 rng(42);
    for (double eps : {0.3, -0.3, 0.92}) {
        TruncatedMap f = make_truncated_map(eps, OmegaG, 3 * kPi / 4, 1.0, 0.5, 0.5);
        std::uniform_real_distribution<double> uphi(-kPi, kPi), uK(f.band().lo * 0.999, 1.0);
        double worst_inv = 0, worst_rev = 0;
        int tested = 0;
        for (int i = 0; i < 100000; ++i) {
            double phi = uphi(rng), K = uK(rng);
            if (boundary_distance(f, phi, K) < 1e-9) continue;
            auto [p1, k1] = f.step(phi, K);
            auto [p0, k0] = f.step_inverse(p1, k1);
            worst_inv = std::max({worst_inv, std::fabs(wrap_angle(p0 - phi)), std::fabs(k0 - K)});
            // R F R (x) must equal F^{-1}(x); take x = F(y) so that F^{-1}(x) = y is defined.
            auto [rp, rk] = f.step(-p1, k1 - eps * std::sin(p1));
            double back_phi = -rp, back_K = rk - eps * std::sin(rp);
            worst_rev = std::max({worst_rev, std::fabs(wrap_angle(back_phi - phi)), std::fabs(back_K - K)});
            ++tested;
        }
        CHECKF(tested > 99000, "too few points tested: %d", tested);
        CHECKF(worst_inv < 1e-12, "eps=%g: F^-1 F error %.3g", eps, worst_inv);
        CHECKF(worst_rev < 1e-12, "eps=%g: R F R error %.3g", eps, worst_rev);
    }

    // eps = 0: K is invariant and each circle K < 0 is a 3-interval exchange that reverses the
    // order of the arcs: the image of J_a is -J_a (midpoint of the image = -midpoint).
    TruncatedMap f0 = make_truncated_map(0.0, OmegaG, 3 * kPi / 4, 1.0, 0.5, 0.5);
    for (double K : {-0.01, -0.5, -2.0, -3.1}) {
        auto st = f0.arc_starts(K);
        ArcLengths a = f0.arc_lengths(K);
        double len[3] = {a.J1, a.JR, 2 * kPi - a.J1 - a.JR};
        Region want[3] = {Region::Upper, Region::Right, Region::Above};
        for (int r = 0; r < 3; ++r) {
            double mid = wrap_angle(st[r] + 0.5 * len[r]);
            CHECKF(f0.region(mid, K) == want[r], "K=%g arc %d midpoint region", K, r);
            auto [pm, km] = f0.step(mid, K);
            CHECKF(km == K, "eps=0 must keep K exactly");
            CHECKF(std::fabs(wrap_angle(pm + mid)) < 1e-12, "K=%g arc %d: image midpoint %.15g != -%.15g", K, r, pm,
                   mid);
            // Endpoints (just inside) map to the reflected endpoints, in reversed order.
            auto [pl, kl] = f0.step(wrap_angle(st[r] + 1e-9), K);
            CHECKF(std::fabs(wrap_angle(pl + st[r] + len[r])) < 1e-8, "left end of arc %d maps to -right end", r);
        }
    }
}
