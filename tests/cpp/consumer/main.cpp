// Uses the installed core as a downstream program would: the truncated map's batch iteration
// (which runs the SIMD lane kernel the library selects) against its own single steps, the flow's
// build facts, and the version header. Exit status 0 only if every check holds.
#include <hovering/build_info.hpp>
#include <hovering/hovering.hpp>
#include <hovering/version.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

int main() {
    int failures = 0;
    auto check = [&](bool ok, const std::string& what) {
        std::printf("%s: %s\n", ok ? "ok" : "FAILED", what.c_str());
        failures += !ok;
    };

    check(std::strcmp(hovering::kVersion, EXPECTED_VERSION) == 0,
          std::string("version.hpp says ") + hovering::kVersion + ", the package " + EXPECTED_VERSION);
    const std::vector<hovering::BuildFact> facts = hovering::build_info();
    check(!facts.empty() && facts[0].name == "hovering" && facts[0].value == hovering::kVersion,
          "build_info() names the same version");

    const double pi = 3.14159265358979323846;
    const hovering::TruncatedMap m =
        hovering::make_truncated_map(0.3, pi * (std::sqrt(5.0) - 1.0), 3 * pi / 4, 1.0, 0.5, 0.5);
    const int n = 37;  // not a multiple of any packet width
    std::vector<double> phi(n), K(n), pf(n), kf(n);
    std::vector<std::int8_t> status(n);
    for (int i = 0; i < n; ++i) {
        phi[i] = -3.0 + 6.0 * i / n;
        K[i] = -0.5 + 0.9 * i / n;
    }
    hovering::IterateOptions opt;
    opt.n_steps = 1;
    hovering::IterateOutput out;
    out.phi_final = pf.data();
    out.K_final = kf.data();
    out.status = status.data();
    m.iterate(phi.data(), K.data(), n, opt, out);
    // One step's phi is step()'s bit for bit (no sin enters it); K within the two sins' few ulp.
    int phi_differ = 0;
    double k_worst = 0.0;
    for (int i = 0; i < n; ++i) {
        const auto [p1, k1] = m.step(phi[i], K[i]);
        phi_differ += pf[i] != p1;
        k_worst = std::fmax(k_worst, std::fabs(kf[i] - k1));
    }
    check(phi_differ == 0, "iterate() phi equals step() at all " + std::to_string(n) + " points (" +
                               std::to_string(phi_differ) + " differ), SIMD level " + hovering::simd_level());
    check(k_worst < 1e-15, "iterate() K within 1e-15 of step(): " + std::to_string(k_worst));

    bool rejected = false;
    try {
        hovering::set_simd_level("no-such-level");
    } catch (const std::invalid_argument& e) {
        rejected = std::string(e.what()).find("no-such-level") != std::string::npos;
    }
    check(rejected, "an unknown SIMD level is std::invalid_argument naming it");
    return failures == 0 ? 0 : 1;
}
