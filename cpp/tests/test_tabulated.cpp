// The general family with tabulated arcs: reproduces F_eps, keeps reversibility for nonlinear
// tables and several Fourier modes, and rejects malformed tables.
#include <algorithm>
#include <random>
#include <vector>

#include "hovering/truncated/map.hpp"
#include "testing.hpp"

using namespace hovering;
namespace {
const double kPi = 3.14159265358979323846;
}

TEST_CASE("tabulated family equals F_eps on linear tables; any table + odd forcing is reversible", "[truncated]") {
    const double OmegaG = kPi * (std::sqrt(5.0) - 1.0), tw = 3 * kPi / 4, tau0 = 1, tau1 = 0.5, lam = 0.5;
    // Omega and |J_R| are linear in K and |J_1| is linear in sqrt(-K): a natural cubic spline
    // reproduces linear data exactly, so the tabulated family must equal F_eps to rounding.
    std::vector<double> K, Om, JR, J1;
    for (int i = -40; i <= 20; ++i) {
        double k = -3.2 * (i < 0 ? double(i * i) / 1600.0 : 0.0) + (i > 0 ? 0.05 * i : 0.0);
        K.push_back(k);
        Om.push_back(OmegaG + tau0 * k);
        JR.push_back(k <= 0 ? 2 * (kPi - tw) + tau1 * k : 0.0);
        J1.push_back(k <= 0 ? 2 * lam * std::sqrt(-k) : 0.0);
    }
    TruncatedFamily fam(0.3, TabulatedArcs(K, Om, JR, J1), FourierForcing{{1.0}}, INFINITY);
    TruncatedMap ref = make_truncated_map(0.3, OmegaG, tw, tau0, tau1, lam);
    CHECKF(std::fabs(fam.band().lo - ref.band().lo) < 1e-9, "band lo %.15g vs %.15g", fam.band().lo, ref.band().lo);
    CHECKF(fam.band().hi == 1.0, "band hi is the top of the table, got %g", fam.band().hi);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> uphi(-kPi, kPi), uK(-3.1, 0.99);
    double worst = 0;
    int disagree = 0;
    for (int i = 0; i < 20000; ++i) {
        double phi = uphi(rng), k = uK(rng);
        if (fam.region(phi, k) != ref.region(phi, k)) {
            ++disagree;
            continue;
        }
        auto [a, b] = fam.step(phi, k);
        auto [c, d] = ref.step(phi, k);
        worst = std::max({worst, std::fabs(wrap_angle(a - c)), std::fabs(b - d)});
    }
    // Regions can differ only within rounding of an arc end: a handful in 20000 at most.
    CHECKF(disagree <= 2, "regions disagree at %d points", disagree);
    CHECKF(worst < 1e-12, "tabulated vs analytic step differ by %.3g", worst);

    // A nonlinear table and three Fourier modes: the lemma says any such family is reversible.
    std::vector<double> Om2, JR2, J12;
    for (double k : K) {
        Om2.push_back(2.0 + 0.8 * k + 0.3 * k * k);
        JR2.push_back(k <= 0 ? 1.5 + 0.2 * k + 0.05 * std::sin(3 * k) : 0.0);
        double s = std::sqrt(std::max(0.0, -k));
        J12.push_back(k <= 0 ? 0.9 * s + 0.1 * s * s : 0.0);
    }
    TruncatedFamily g(0.4, TabulatedArcs(K, Om2, JR2, J12), FourierForcing{{1.0, -0.3, 0.1}}, INFINITY);
    double worst_inv = 0, worst_rev = 0;
    for (int i = 0; i < 20000; ++i) {
        double phi = uphi(rng), k = std::uniform_real_distribution<double>(g.band().lo * 0.99, 0.9)(rng);
        auto [p1, k1] = g.step(phi, k);
        auto [p0, k0] = g.step_inverse(p1, k1);
        worst_inv = std::max({worst_inv, std::fabs(wrap_angle(p0 - phi)), std::fabs(k0 - k)});
        double f1 = g.forcing().at(p1);
        auto [rp, rk] = g.step(-p1, k1 - 0.4 * f1);
        worst_rev =
            std::max({worst_rev, std::fabs(wrap_angle(-rp - phi)), std::fabs(rk - 0.4 * g.forcing().at(rp) - k)});
    }
    CHECKF(worst_inv < 1e-12, "nonlinear family: F^-1 F error %.3g", worst_inv);
    CHECKF(worst_rev < 1e-12, "nonlinear family: R F R error %.3g", worst_rev);

    // Malformed tables.
    std::vector<double> Kbad = K;
    std::swap(Kbad[3], Kbad[4]);
    CHECK_INVALID(TabulatedArcs(Kbad, Om, JR, J1), "strictly increasing");
    std::vector<double> J1bad = J1;
    J1bad[40] = 0.1;  // K = 0 entry
    CHECK_INVALID(TabulatedArcs(K, Om, JR, J1bad), "J1 must vanish at K = 0");
    std::vector<double> Kshort(K.begin(), K.end() - 1), Omshort(Om.begin(), Om.end() - 2);
    CHECK_INVALID(TabulatedArcs(K, Omshort, JR, J1), "same length");
    std::vector<double> Omnan = Om;
    Omnan[5] = NAN;
    CHECK_INVALID(TabulatedArcs(K, Omnan, JR, J1), "Omega[5] must be finite");
    std::vector<double> JRneg = JR;
    for (auto& v : JRneg) v = -1.0;
    CHECK_INVALID(TruncatedFamily(0.1, TabulatedArcs(K, Om, JRneg, J1), FourierForcing{{1.0}}, INFINITY),
                  "no valid band");
    CHECK_INVALID(TruncatedFamily(0.1, TabulatedArcs(K, Om, JR, J1), FourierForcing{{}}, INFINITY),
                  "at least one sine coefficient");
}

TEST_CASE("tabulated arcs: nearly coincident circles are rejected, close but resolved ones kept", "[truncated]") {
    // Linear tables (Omega = 2 + 3.1 K, ...): a natural cubic spline reproduces them exactly, so
    // the fitted slope at K = 0 must be 3.1 to rounding amplified by range / spacing.
    auto table = [](const std::vector<double>& K) {
        std::vector<double> Om, JR, J1;
        for (double k : K) {
            Om.push_back(2.0 + 3.1 * k);
            JR.push_back(k <= 0 ? 1.5 + 0.5 * k : 0.0);
            J1.push_back(k <= 0 ? std::sqrt(-k) : 0.0);
        }
        return TabulatedArcs(K, Om, JR, J1);
    };
    // K = 1e-14 next to K = 0 (spacing 5e-15 of the range 2): the spline's slope at 0 carried the
    // rounding of Omega times 1e14 (measured 3.1086 for these linear tables; -8e11 for measured
    // ones). Now refused, naming both circles and the rule.
    CHECK_INVALID(table({-1.0, -0.5, -0.2, -0.04, 0.0, 1e-14, 0.05, 0.5, 1.0}),
                  "the K grid's points must be at least 1e-9 of its range (2) apart, but K[4] = 0 and K[5] = 1e-14 are "
                  "1e-14 apart");
    CHECK_INVALID(table({-1.0, -0.5, -0.5 + 1e-12, 0.0, 0.5, 1.0}), "K[1] = -0.5 and K[2] = -0.499999999999");
    // Just above the rule (spacing 2e-9 of the range) the grid is kept, and its slope at 0 is
    // still good to rounding x range / spacing = 1e-16 x 5e8 ~ 1e-7.
    const TabulatedArcs ok = table({-1.0, -0.5, -0.2, -0.04, 0.0, 4e-9, 0.05, 0.5, 1.0});
    const double slope = (ok.at(1e-3).Omega - ok.at(0.0).Omega) / 1e-3;
    CHECKF(std::fabs(slope - 3.1) < 1e-6, "Omega'(0) = %.12g on a grid with spacing 2e-9 of its range", slope);
}
