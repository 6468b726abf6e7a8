// Hard cases of the truncated map in the C++ API: the half-open arcs (each owns its start) in
// region, step, step_inverse and both kernels; images at the band floor; the rotation bound.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "hovering/truncated/map.hpp"
#include "testing.hpp"

using namespace hovering;
namespace {
const double kPi = 3.14159265358979323846;
const Region kOwner[3] = {Region::Upper, Region::Right, Region::Above};
}  // namespace

TEST_CASE("arc starts are owned by their arcs and come back from step_inverse", "[truncated][hard]") {
    for (double eps : {0.0, 0.5, -0.3}) {
        TruncatedMap m = make_truncated_map(eps, 1.0, 1.0, 1.0, 0.5, 0.5);
        std::mt19937_64 rng(11);
        std::uniform_real_distribution<double> uK(m.band().lo, 0.0);
        int same = 0, merged = 0;
        for (int i = 0; i < 3000; ++i) {
            const double K = uK(rng);
            if (!(K > m.band().lo && K < -1e-6)) continue;  // away from the floor's and K = 0's short arcs
            const auto st = m.arc_starts(K);
            for (int j = 0; j < 3; ++j) {
                CHECKF(m.region(st[j], K) == kOwner[j], "eps=%g K=%.17g: start %d not in its own arc", eps, K, j);
                const auto [p1, k1] = m.step(st[j], K);
                const auto [p0, k0] = m.step_inverse(p1, k1);
                // step merges the heights within ulp(Kbar) of K: the inverse may pick another of them
                // (the start of the same arc there); at K itself it must be the start, bit for bit.
                const double ulpK1 = std::nextafter(std::fabs(k1), INFINITY) - std::fabs(k1);
                CHECKF(std::fabs(k0 - K) <= ulpK1, "eps=%g K=%.17g start %d: K came back as %.17g", eps, K, j, k0);
                CHECKF(m.region(p0, k0) == kOwner[j], "eps=%g K=%.17g start %d: back in another arc", eps, K, j);
                if (k0 == K) {
                    CHECKF(p0 == st[j], "eps=%g K=%.17g start %d: %.17g came back as %.17g", eps, K, j, st[j], p0);
                    ++same;
                } else {
                    CHECKF(p0 == m.arc_starts(k0)[j], "eps=%g start %d: not the start at the merged height", eps, j);
                    ++merged;
                }
            }
        }
        if (eps == 0.0) CHECKF(merged == 0, "eps = 0 rounds no height, yet %d starts moved", merged);
        CHECKF(same > 3 * merged, "eps=%g: %d bit for bit, %d at merged heights", eps, same, merged);
    }
}

TEST_CASE("images of points at the band floor are inverted, not refused", "[truncated][hard]") {
    for (double eps : {0.5, -0.3}) {
        TruncatedMap m = make_truncated_map(eps, 1.0, 1.0, 1.0, 0.5, 0.5);
        const double lo = m.band().lo;
        std::mt19937_64 rng(5);
        std::uniform_real_distribution<double> uphi(-kPi, kPi);
        int n = 0;
        for (double K : {std::nextafter(lo, 0.0), lo + 1e-15, lo + 1e-14, lo + 1e-13})
            for (int i = 0; i < 2000; ++i, ++n) {
                const auto [p1, k1] = m.step(uphi(rng), K);
                const auto [p0, k0] = m.step_inverse(p1, k1);  // threw for ~1 in 100 before
                CHECKF(k0 > lo, "eps=%g: preimage height %.17g not inside the band", eps, k0);
            }
        CHECKF(n == 8000, "%d points", n);
    }
}

TEST_CASE("the SIMD kernel computes phi and regions as step() does, bit for bit", "[truncated][hard]") {
    TruncatedMap m = make_truncated_map(0.3, kPi * (std::sqrt(5.0) - 1.0), 3 * kPi / 4, 1.0, 0.5, 0.5);
    std::vector<double> phi, K;
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<double> uphi(-kPi, kPi), uK(m.band().lo, 1.5);
    for (int i = 0; i < 20000; ++i) {
        phi.push_back(uphi(rng));
        K.push_back(uK(rng));
    }
    // On the starts and within rounding of them (the kernel's exact path).
    for (double k : {-0.01, -0.5, -2.0, -3.0})
        for (double s : m.arc_starts(k))
            for (double d : {0.0, 1e-300, -1e-300, 1e-16, -1e-16, 1e-9, -1e-9}) {
                phi.push_back(wrap_angle(s + d));
                K.push_back(k);
            }
    const std::size_t n = phi.size();
    std::vector<double> pf(n), kf(n);
    std::vector<std::int8_t> reg(n), st(n);
    IterateOptions o;
    o.n_steps = 1;
    IterateOutput out;
    out.phi_final = pf.data();
    out.K_final = kf.data();
    out.regions = reg.data();
    out.status = st.data();
    // Every build of the lane kernel this CPU runs (the run-time choice and each forced level).
    const std::string chosen = simd_level();
    for (const std::string& level : simd_levels()) {
        set_simd_level(level);
        CHECKF(simd_level() == level, "forced %s, selected %s", level.c_str(), simd_level().c_str());
        m.iterate(phi.data(), K.data(), std::int64_t(n), o, out);
        int differ = 0;
        for (std::size_t i = 0; i < n; ++i) {
            if (!(K[i] > m.band().lo && K[i] < m.band().hi)) continue;
            differ += pf[i] != m.step(phi[i], K[i]).first || reg[i] != static_cast<std::int8_t>(m.region(phi[i], K[i]));
        }
        CHECKF(differ == 0, "%s: SIMD phi or region differs from step()/region() at %d of %zu points", level.c_str(),
               differ, n);
    }
    set_simd_level(chosen);
}

TEST_CASE("one rotation bound, |Omega| <= 1e6, for parameters and points", "[truncated][hard]") {
    CHECK_INVALID(make_truncated_map(0.1, 1e6 + 1.0, 1.0, 1.0, 0.5, 0.5), "Omega0 must lie in [-1e6, 1e6]");
    TruncatedMap m = make_truncated_map(0.1, 2.0, 1.0, 1.0, 0.5, 0.5);
    CHECKF(m.band().hi == 1e6 - 2.0, "band top %.17g", m.band().hi);
    CHECK_INVALID(m.step(0.3, 1e16), "outside the band");  // stepped to phi = 0.0 once
    const double K0[2] = {1e16, 0.5}, phi0[2] = {0.3, 0.3};
    double pf[2], kf[2];
    std::int8_t st[2];
    IterateOptions o;
    o.n_steps = 10;
    IterateOutput out;
    out.phi_final = pf;
    out.K_final = kf;
    out.status = st;
    m.iterate(phi0, K0, 2, o, out);
    CHECKF(st[0] == static_cast<std::int8_t>(Status::Escaped) && st[1] == static_cast<std::int8_t>(Status::Ok),
           "statuses %d %d", st[0], st[1]);
    CHECKF(pf[1] >= -kPi && pf[1] < kPi, "phi %.17g", pf[1]);
}
