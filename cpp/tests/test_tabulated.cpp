// The general family with tabulated arcs: reproduces F_eps, keeps reversibility for nonlinear
// tables and several Fourier modes, and rejects malformed tables.
#include <algorithm>
#include <random>
#include <vector>

#include "testing.hpp"
#include "hovering/truncated/map.hpp"

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
        if (fam.region(phi, k) != ref.region(phi, k)) { ++disagree; continue; }
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
        worst_rev = std::max({worst_rev, std::fabs(wrap_angle(-rp - phi)), std::fabs(rk - 0.4 * g.forcing().at(rp) - k)});
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
    CHECK_INVALID(TruncatedFamily(0.1, TabulatedArcs(K, Om, JRneg, J1), FourierForcing{{1.0}}, INFINITY), "no valid band");
    CHECK_INVALID(TruncatedFamily(0.1, TabulatedArcs(K, Om, JR, J1), FourierForcing{{}}, INFINITY), "at least one sine coefficient");
}
