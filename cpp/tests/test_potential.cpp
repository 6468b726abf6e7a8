// Potentials and onset parameters: closed forms vs GSL quadrature, definitions vs the appendix.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "hovering/flow/system.hpp"
#include "testing.hpp"

using namespace hovering;

namespace {
const double kPi = 3.14159265358979323846;
using hovering_test::msg;
double rel(double a, double b) {
    return std::fabs(a - b) / std::max(1.0, std::fabs(b));
}
}  // namespace

TEST_CASE("potentials: closed forms vs quadrature; onset parameters three ways", "[flow][potential]") {
    // Closed forms against the generic quadrature/root-finding path on the same V: QAWS reaches
    // ~1e-13 here, so 1e-10 relative leaves margin while catching any formula error.
    for (auto base : {std::shared_ptr<const Potential>(std::make_shared<Harmonic>(1.3)),
                      std::shared_ptr<const Potential>(std::make_shared<Tan>(1.4, 0.7)),
                      std::shared_ptr<const Potential>(std::make_shared<Tan>(0.8, 1.9))}) {
        Numerical num(base);
        for (double h : {0.05, 0.7, 2.5}) {
            auto [a, b] = base->turning_points(h);
            auto [na, nb] = num.turning_points(h);
            CHECKF(rel(a, na) < 1e-12 && rel(b, nb) < 1e-12, "%s turning points at h=%g", base->name().c_str(), h);
            CHECKF(rel(base->period(h), num.period(h)) < 1e-10, "%s period at h=%g: %.15g vs %.15g",
                   base->name().c_str(), h, base->period(h), num.period(h));
            CHECKF(rel(base->action(h), num.action(h)) < 1e-10, "%s action at h=%g: %.15g vs %.15g",
                   base->name().c_str(), h, base->action(h), num.action(h));
            CHECKF(rel(num.energy(num.action(h)), h) < 1e-10, "%s energy(action(h))", base->name().c_str());
            for (double f : {-0.9, -0.3, 0.0, 0.5}) {
                const double q = f * b;
                CHECKF(std::fabs(base->angle_of(q, h) - num.angle_of(q, h)) < 1e-10,
                       "%s angle_of(%g, %g): %.15g vs %.15g", base->name().c_str(), q, h, base->angle_of(q, h),
                       num.angle_of(q, h));
            }
            // angle_of_point inverts point_at to rounding, including at the turning points.
            for (double th : {-3.0, -1.0, 0.0, 1e-9, 2.0, 3.14}) {
                const auto [q, p] = base->point_at(th, h);
                CHECKF(std::fabs(base->angle_of_point(q, p, h) - th) < 1e-12, "%s angle_of_point(point_at(%g))",
                       base->name().c_str(), th);
                const auto [nq, np] = num.point_at(th, h);
                CHECKF(std::fabs(nq - q) < 1e-9 && std::fabs(np - p) < 1e-9, "%s generic point_at(%g)",
                       base->name().c_str(), th);
            }
            // dH/dI = omega(h): the frequency is the derivative of the energy in the action.
            const double I = base->action(h), dI = 1e-4 * I;
            const double dHdI = (base->energy(I + dI) - base->energy(I - dI)) / (2 * dI);
            CHECKF(rel(dHdI, base->frequency(h)) < 1e-7, "%s dH/dI vs omega", base->name().c_str());
        }
    }

    // Onset parameters: (1) definitions with closed-form potentials, (2) definitions with pure
    // quadrature, (3) the appendix closed forms (corrected). Derivatives by Richardson central
    // differences carry ~1e-9 error, so 1e-7 relative.
    struct Case {
        double w1, a1, w2, a2, qw1, qw2, h;
    };
    for (Case c : {Case{1.0, 0.0, 1.4, 0.7, -1.0, -0.5, 1.0}, Case{1.0, 0.6, 1.4, 0.7, -0.8, -0.4, 1.2},
                   Case{1.2, 0.9, 1.0, 0.0, -0.7, -0.6, 1.5}, Case{1.0, 0.0, 1.0, 0.0, -1.0, -0.5, 1.0}}) {
        auto mk = [](double w, double a) -> std::shared_ptr<const Potential> {
            if (a > 0) return std::make_shared<Tan>(w, a);
            return std::make_shared<Harmonic>(w);
        };
        auto V1 = mk(c.w1, c.a1), V2 = mk(c.w2, c.a2);
        const OnsetParameters d = onset_parameters(*V1, *V2, c.qw1, c.qw2, c.h);
        const OnsetParameters q = onset_parameters(Numerical(V1), Numerical(V2), c.qw1, c.qw2, c.h);
        const OnsetParameters f = onset_parameters_closed_form(c.w1, c.a1, c.w2, c.a2, c.qw1, c.qw2, c.h);
        const double dv[] = {d.Omega0, d.tau0, d.tau1, d.lam, d.theta_w, d.I_tan};
        const double qv[] = {q.Omega0, q.tau0, q.tau1, q.lam, q.theta_w, q.I_tan};
        const double fv[] = {f.Omega0, f.tau0, f.tau1, f.lam, f.theta_w, f.I_tan};
        const char* names[] = {"Omega0", "tau0", "tau1", "lam", "theta_w", "I_tan"};
        for (int k = 0; k < 6; ++k) {
            CHECKF(rel(dv[k], qv[k]) < 1e-7, "case a1=%g a2=%g: %s definitions %.12g vs quadrature %.12g", c.a1, c.a2,
                   names[k], dv[k], qv[k]);
            CHECKF(rel(dv[k], fv[k]) < 1e-7, "case a1=%g a2=%g: %s definitions %.12g vs closed form %.12g", c.a1, c.a2,
                   names[k], dv[k], fv[k]);
        }
        // Harmonic-harmonic: no twist (tau0 = 0), Omega0 = 2 pi omega2 / omega1 (appendix limits).
        if (c.a1 == 0 && c.a2 == 0) {
            CHECKF(std::fabs(d.tau0) < 1e-7 && rel(d.Omega0, 2 * kPi * c.w2 / c.w1) < 1e-12, "harmonic limits");
        }
        // The appendix as printed: tau0's last term over W1^4 and theta_w = arccos(-...). Where
        // the two differ from the definitions by a clear margin, the definitions win (README).
        if (c.a1 > 0) {
            const double h1w = V1->V(c.qw1), W1 = std::sqrt(c.w1 * c.w1 + 2 * c.a1 * c.a1 * h1w);
            const double W2 = std::sqrt(c.w2 * c.w2 + 2 * c.a2 * c.a2 * (c.h - h1w));
            const double tau0_printed =
                (2 * kPi * c.a2 * c.a2 * std::pow(W1, 3) + 2 * kPi * c.a1 * c.a1 * W2 * W2) / std::pow(W1, 4);
            CHECKF(rel(tau0_printed, d.tau0) > 1e-3, "printed tau0 unexpectedly matches");
        }
        CHECKF(std::fabs((kPi - d.theta_w) - d.theta_w) > 1e-3, "printed theta_w (= pi - theta_w) distinguishable");
        CHECKF(d.theta_w > kPi / 2 && d.tau1 > 0,
               "qw2 < 0: theta_w in (pi/2, pi) and tau1 > 0 (sign tau1 = -sign qw2)");
    }

    // Bad input.
    Harmonic H(1.0);
    Tan T(1.4, 0.7);
    CHECK_INVALID(onset_parameters(H, T, -1.0, -0.5, 0.5), "h must exceed the step energy");
    CHECK_INVALID(onset_parameters(H, T, 1.0, -0.5, 2.0), "qw1 must be < 0");
    CHECK_INVALID(onset_parameters(H, T, -1.0, -3.0, 2.0), "qw2 must be < 0 and inside the well of V2");
    CHECK_INVALID(Harmonic(-1.0), "omega must lie in [1e-100, 1e100], got -1");
    CHECK_INVALID(Tan(1.0, NAN), "alpha must lie in [1e-100, 1e100], got nan");
    // omega^2 = 1e-600 underflows: the period was 2 pi / sqrt(0 + 2e600) = 0 without a word.
    CHECK_INVALID(Tan(1e-300, 1e300), "omega must lie in [1e-100, 1e100], got 1e-300");
    CHECK_INVALID(H.period(-1.0), "energy must be finite and > 0");

    // A point of another level is bad input, not an angle (atan2 would answer anything).
    for (const Potential* pot : {static_cast<const Potential*>(&H), static_cast<const Potential*>(&T)}) {
        CHECK_INVALID(pot->angle_of_point(0.9, 0.0, 0.1), "not on the level h = 0.1 ");
        CHECK_INVALID(pot->angle_of_point(0.1, NAN, 1.0), "q and p must be finite");
    }
    Numerical NH(std::make_shared<Harmonic>(1.0));
    CHECK_INVALID(NH.angle_of_point(0.5, NAN, 1.0), "q and p must be finite");
    // ... but the energy drift of an accurate orbit (1e-12) passes and gives the exact angle.
    CHECKF(std::fabs(H.angle_of_point(1.0, -1e-12, 0.5) - 1e-12) < 1e-15, "level check tolerates a 1e-12 drift");

    // Tan beyond its wall is outside the well, not a periodic copy of it.
    CHECKF(std::isinf(T.V(3.0)) && T.V(3.0) > 0 && std::isinf(T.V(-3.0)), "Tan.V = +inf beyond q_limit = %g",
           T.q_limit());
    CHECKF(T.dV(3.0) == INFINITY && T.dV(-3.0) == -INFINITY, "Tan.dV = sign(q) inf beyond q_limit");
    CHECKF(std::isnan(T.V(NAN)), "Tan.V(nan) is nan");

    // Small energies: the turning points are bracketed geometrically, so the generic path keeps
    // full accuracy down to h = 1e-300 (it used to stop converging below h ~ 1e-63).
    for (double h : {1e-70, 1e-150, 1e-300}) {
        CHECKF(std::fabs(NH.period(h) - 2 * kPi) < 1e-13, "Numerical period at h = %g", h);
        CHECKF(std::fabs(NH.action(h) / h - 1) < 1e-13, "Numerical action at h = %g", h);
    }
    // A quadrature failure (here V = h on the interval [1, 2]: a plateau at the level) is a named
    // bad energy, not an internal error.
    struct Plateau final : Potential {
        double V(double q) const override {
            const double a = std::fabs(q);
            return a < 1 ? 0.5 * a * a : a <= 2 ? 0.5 : 0.5 + 0.5 * (a - 2) * (a - 2);
        }
        double dV(double q) const override {
            const double a = std::fabs(q);
            return a < 1 ? q : a <= 2 ? 0.0 : std::copysign(a - 2, q);
        }
        std::string name() const override { return "Plateau"; }
    } plateau;
    CHECK_INVALID(plateau.period(0.5), "Plateau.period: the quadrature over the level h = 0.5 did not converge");
}

TEST_CASE("every compiled kind: the registry builds it, and its closed forms match quadrature", "[flow][potential]") {
    // The registry (CompiledPotentials) is what scene files, plans and the bindings read: each kind
    // builds through make_potential with its parameters in order, refuses a wrong count and an
    // out-of-range value, and, like the classes above, agrees with the generic quadrature path.
    CHECK(potential_kinds().size() >= 2);
    std::string kinds;
    for (const PotentialKind& k : potential_kinds()) kinds += std::string(kinds.empty() ? "'" : ", '") + k.kind + "'";
    CHECK(kinds.rfind("'harmonic', 'tan'", 0) == 0);
    CHECK_INVALID(potential_kind("no-such-kind"), "potential kind must be one of " + kinds + ", got 'no-such-kind'");
    for (const PotentialKind& k : potential_kinds()) {
        CHECK(&potential_kind(k.kind) == &k);
        CHECK_INVALID(make_potential(k.kind, std::vector<double>(k.params.size() + 1, 1.0)), "parameter(s)");
        std::vector<double> bad(k.params.size(), 1.0);
        bad[0] = k.params[0].hi * 2;
        CHECK_INVALID(make_potential(k.kind, bad), std::string(k.cls) + ": " + k.params[0].name + " must lie in [");
        // Two wells per kind: each parameter 1, or alternately 0.8 and 1.9 (clamped into its range).
        for (const std::array<double, 2>& pattern :
             {std::array<double, 2>{1.0, 1.0}, std::array<double, 2>{0.8, 1.9}}) {
            std::vector<double> params;
            for (std::size_t i = 0; i < k.params.size(); ++i)
                params.push_back(std::clamp(pattern[i % 2], k.params[i].lo, k.params[i].hi));
            const std::shared_ptr<const Potential> base = make_potential(k.kind, params);
            CHECKF(base->name().rfind(k.cls + "(", 0) == 0, "%s named %s", k.kind.c_str(), base->name().c_str());
            const Numerical num(base);
            for (double h : {0.05, 0.7, 2.5}) {
                CHECKF(rel(base->period(h), num.period(h)) < 1e-10, "%s period at h=%g", base->name().c_str(), h);
                CHECKF(rel(base->action(h), num.action(h)) < 1e-10, "%s action at h=%g", base->name().c_str(), h);
                const double qm = base->turning_points(h).second;
                CHECKF(std::fabs(base->angle_of(0.5 * qm, h) - num.angle_of(0.5 * qm, h)) < 1e-10, "%s angle at h=%g",
                       base->name().c_str(), h);
            }
        }
    }
}

TEST_CASE("generic turning points at every level", "[flow][potential]") {
    const double eps = std::numeric_limits<double>::epsilon();
    auto tan = std::make_shared<Tan>(1.4, 0.7);
    Numerical num(tan);
    // Tan's closed form q_max = atan(alpha sqrt(2h) / omega) / alpha. Brent stops at 4 eps relative
    // and the closed form rounds to ~1 ulp: 8 eps relative. Tan's V reaches only ~8e30 at the last
    // double before its wall (V = +inf from q_limit on), so above that the answer is that double,
    // the largest q with V(q) <= h: q_limit to 1 ulp (the bracket used to end on V = inf, and
    // Brent returned (-0, 1e-313)).
    for (double h : {1e-300, 1e-10, 1.0, 1e10, 1e33, 1e100, 1e300}) {
        const auto [a, b] = num.turning_points(h);
        const double B = tan->turning_points(h).second;
        CHECKF(std::fabs(b - B) <= 8 * eps * B && std::fabs(a + B) <= 8 * eps * B, "h = %g: [%.17g, %.17g] vs +-%.17g",
               h, a, b, B);
        CHECKF(num.V(b) <= h && num.V(-b) <= h, "h = %g: V(q_max) = %g <= h", h, num.V(b));
        if (h >= 1e33) {
            CHECKF(b == std::nextafter(tan->q_limit(), 0.0) && a == -b,
                   "h = %g: q_max %.17g is the last double before q_limit %.17g", h, b, tan->q_limit());
        }
    }
    // Unbounded wells: the bracket doubles up to the largest double (it stopped at 2^200 ~ 1.6e60).
    Numerical nh(std::make_shared<Harmonic>(1.0));
    for (double h : {1e-300, 1e-10, 1.0, 1e100, 1e300}) {
        const double B = std::sqrt(2 * h);
        const auto [a, b] = nh.turning_points(h);
        CHECKF(std::fabs(b - B) <= 8 * eps * B && std::fabs(a + B) <= 8 * eps * B, "Harmonic h = %g: %.17g vs %.17g", h,
               b, B);
    }
    // Above that value the level has hard walls (h - V ~ h at the turning points), which the
    // quadratures cannot resolve: a named error, not garbage.
    CHECK_INVALID(num.period(1e100),
                  "the level h = 1e+100 lies above the largest value V reaches inside the wall q_limit");
    CHECK_INVALID(num.point_at(1.0, 1e100), "point_at: the level h = 1e+100 lies above");
    // ... and a bounded well that never reaches h before its wall is not a single well.
    struct Shallow final : Potential {
        double V(double q) const override { return 0.5 * q * q; }
        double dV(double q) const override { return q; }
        std::string name() const override { return "Shallow"; }
        double q_limit() const override { return 1.0; }
    } shallow;
    CHECK_INVALID(shallow.turning_points(2.0),
                  "Shallow: V never reaches the energy 2 (V(-1) = 0.5 at the wall q_limit");
}

TEST_CASE("generic angles next to the turning points", "[flow][potential]") {
    const double eps = std::numeric_limits<double>::epsilon();
    auto tan = std::make_shared<Tan>(1.4, 0.7);

    // point_at and angle_of against the closed forms on a dense grid of angles and at 10^-k of
    // 0 and pi (point_at raised "did not converge" for pi - theta in (5e-7, 5e-6)). Tolerances:
    // (q, p) to 1e-11: period and times are QAWS quadratures (asked for 1e-12 relative, measured
    // ~1e-15) and the inversion stops at 1e-14 relative; 1e-11 is 10x the requested accuracy.
    // angle_of to 1e-11 plus its conditioning: the closed form's q is a double, good to ~1 ulp,
    // and near a turning point theta ~ sqrt(q_max - q), dtheta/dq = omega / |p|, so 8 ulps of q
    // (the turning point's 4 eps, the closed form's rounding) move theta by 8 eps |q| omega / |p|
    // (1e-8 at theta = 1e-8: no method can do better from a double q).
    std::vector<double> thetas{0.0, kPi, -kPi};
    for (int k = 1; k <= 16; ++k)
        for (double t : {std::pow(10.0, -k), kPi - std::pow(10.0, -k)}) {
            thetas.push_back(t);
            thetas.push_back(-t);
        }
    for (int i = 0; i <= 200; ++i) thetas.push_back(-kPi + 2 * kPi * i / 200);
    for (auto base :
         {std::shared_ptr<const Potential>(std::make_shared<Harmonic>(1.0)), std::shared_ptr<const Potential>(tan)}) {
        Numerical n(base);
        for (double h : {1e-6, 1.0, 100.0}) {
            const double w = base->frequency(h), qm = base->turning_points(h).second;
            double worst_qp = 0, worst_angle = 0;
            for (double th : thetas) {
                const auto [Q, P] = base->point_at(th, h);
                const auto [q, p] = n.point_at(th, h);
                worst_qp = std::max({worst_qp, std::fabs(q - Q), std::fabs(p - P)});
                const double err = std::fabs(n.angle_of(Q, h) - std::fabs(th));
                worst_angle = std::max(worst_angle, err / (1e-11 + 8 * eps * qm * w / std::fabs(P)));
                CHECKF(
                    std::fabs(q - Q) <= 1e-11 * std::max(1.0, qm) && std::fabs(p - P) <= 1e-11 * std::max(1.0, qm * w),
                    "%s h = %g theta = %.17g: point_at (%.17g, %.17g) vs (%.17g, %.17g)", base->name().c_str(), h, th,
                    q, p, Q, P);
                CHECKF(err <= 1e-11 + 8 * eps * qm * w / std::fabs(P), "%s h = %g theta = %.17g: angle_of %.17g",
                       base->name().c_str(), h, th, n.angle_of(Q, h));
            }
            INFO(msg("%s h = %g: worst |dq|, |dp| %.3g, worst angle error / tolerance %.3g", base->name().c_str(), h,
                     worst_qp, worst_angle));
            CHECK(worst_qp < 1e-11);
        }
    }
}

TEST_CASE("onset: energy slopes and error estimates, near the step energy and far above it",
          "[flow][potential][onset]") {
    // Closed-form slopes (Tan, Harmonic) against the generic path (Ridders differences of the
    // quadratures) on the same V: the two share nothing but V, so their difference must lie within
    // the sum of the two error estimates, and that sum must be small (the estimates are useful).
    for (auto base : {std::shared_ptr<const Potential>(std::make_shared<Harmonic>(1.3)),
                      std::shared_ptr<const Potential>(std::make_shared<Tan>(1.4, 0.7))}) {
        Numerical num(base);
        for (double h : {1e-3, 0.7, 50.0}) {
            const Estimate a = base->period_slope(h), b = num.period_slope(h);
            CHECKF(std::fabs(a.value - b.value) <= a.error + b.error && a.error + b.error < 1e-8 * base->period(h) / h,
                   "%s period_slope(%g): %.15g +- %.3g vs %.15g +- %.3g", base->name().c_str(), h, a.value, a.error,
                   b.value, b.error);
            const double qmax = base->turning_points(h).second;
            for (double f : {-0.999, -0.5, 0.3}) {
                const Estimate c = base->angle_slope(f * qmax, h), d = num.angle_slope(f * qmax, h);
                CHECKF(
                    std::fabs(c.value - d.value) <= c.error + d.error && c.error + d.error < 1e-6 * std::fabs(c.value),
                    "%s angle_slope(%g, %g): %.15g +- %.3g vs %.15g +- %.3g", base->name().c_str(), f * qmax, h,
                    c.value, c.error, d.value, d.error);
            }
        }
        CHECK_INVALID(base->angle_slope(2 * base->turning_points(1.0).second, 1.0),
                      "must lie strictly inside the level");
    }

    // The system of the README: the old single Richardson step gave tau0 = 5.736 (closed form
    // 3.0788) at h_w + 1e-12, tau1 = -0.0 at 1e8, NaN with a wall 1e-8 from the Tan singularity.
    Harmonic H(1.0);
    Tan T(1.4, 0.7);
    const double hw = H.V(-1.0) + T.V(-0.5);
    CHECK_INVALID(onset_parameters(H, T, -1.0, -0.5, hw + 1e-12), "below the resolution of the step energy");
    CHECK_INVALID(onset_parameters(H, T, -1.0, -0.5, std::nextafter(hw, 1.0)),
                  "below the resolution of the step energy");
    CHECK_INVALID(onset_parameters(H, T, -1.0, -0.5, hw, 1e-6), "h must exceed the step energy");
    CHECK_INVALID(onset_parameters(H, T, -1.0, -0.5, 1.0, 0.0), "rtol must lie in [1e-15, 1]");
    for (double h : {hw + 1e-6, 1.0, 1e8, 1e100}) {
        const OnsetEstimate d = onset_estimate(H, T, -1.0, -0.5, h),
                            c = onset_estimate_closed_form(1.0, 0.0, 1.4, 0.7, -1.0, -0.5, h);
        const double dv[] = {d.value.Omega0, d.value.tau0, d.value.tau1, d.value.lam, d.value.theta_w, d.value.I_tan};
        const double de[] = {d.error.Omega0, d.error.tau0, d.error.tau1, d.error.lam, d.error.theta_w, d.error.I_tan};
        const double cv[] = {c.value.Omega0, c.value.tau0, c.value.tau1, c.value.lam, c.value.theta_w, c.value.I_tan};
        const double ce[] = {c.error.Omega0, c.error.tau0, c.error.tau1, c.error.lam, c.error.theta_w, c.error.I_tan};
        for (int k = 0; k < 6; ++k)
            CHECKF(std::fabs(dv[k] - cv[k]) <= de[k] + ce[k] && de[k] <= 1e-6 * std::fabs(dv[k]),
                   "h = %.17g field %d: definitions %.17g +- %.3g vs closed form %.17g +- %.3g", h, k, dv[k], de[k],
                   cv[k], ce[k]);
        // Appendix: tau0 = 2 pi alpha2^2 / W1 with a harmonic V1, for every h; sign tau1 = -sign qw2.
        CHECKF(std::fabs(d.value.tau0 - 2 * kPi * 0.49) <= 1e-13 * 2 * kPi * 0.49, "tau0 at h = %g: %.17g", h,
               d.value.tau0);
        CHECKF(d.value.tau1 > 0, "tau1 at h = %g: %.17g", h, d.value.tau1);
    }
    // The wall 1e-8 of q_limit from the Tan singularity: finite, or an error; never NaN.
    const double qw2 = -(1 - 1e-8) * T.q_limit();
    const OnsetEstimate w = onset_estimate(H, T, -1.0, qw2, 1.5 * (0.5 + T.V(qw2)));
    CHECKF(std::isfinite(w.value.tau0) && std::isfinite(w.value.tau1) && w.value.tau1 > 0, "wall: tau0 %g tau1 %g",
           w.value.tau0, w.value.tau1);
    CHECKF(w.error.theta_w <= 1e-6 * w.value.theta_w && w.value.theta_w < kPi, "wall: theta_w %.17g +- %g",
           w.value.theta_w, w.error.theta_w);
}
