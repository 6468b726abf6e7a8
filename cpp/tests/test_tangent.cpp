// Tangent dynamics in the core: the QR-renormalised product, the truncated map's exact Jacobian,
// the action-angle chart's slope, and the flow map's Jacobian by variational equations.
#include <array>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "hovering/normal/flow_map.hpp"
#include "hovering/tangent.hpp"
#include "hovering/truncated/map.hpp"
#include "testing.hpp"

using namespace hovering;

namespace {

const double kPi = 3.14159265358979323846;

double wrapd(double x) {
    return x - 2 * kPi * std::floor((x + kPi) / (2 * kPi));
}

// Central difference of a map (x, y) -> (x1, y1) at step h in direction k (0: x, 1: y).
template <class F>
std::array<double, 2> central(F f, double x, double y, double h, int k) {
    const auto a = f(x + (k == 0 ? h : 0), y + (k == 1 ? h : 0));
    const auto b = f(x - (k == 0 ? h : 0), y - (k == 1 ? h : 0));
    return {wrapd(a.first - b.first) / (2 * h), (a.second - b.second) / (2 * h)};
}

}  // namespace

TEST_CASE("the QR-renormalised product is the product, and its logs are its stretches", "[tangent]") {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-2, 2);
    TangentProduct t;
    double M[4] = {1, 0, 0, 1};
    for (int n = 0; n < 30; ++n) {
        const double w = u(rng), g = u(rng);
        const double J[4] = {1, w, g, 1 + g * w};  // det 1, as the truncated map's
        t.multiply(J);
        const double N[4] = {J[0] * M[0] + J[1] * M[2], J[0] * M[1] + J[1] * M[3], J[2] * M[0] + J[3] * M[2],
                             J[2] * M[1] + J[3] * M[3]};
        for (int k = 0; k < 4; ++k) M[k] = N[k];
    }
    double P[4];
    t.matrix(P);
    double scale = 0;
    for (double m : M) scale = std::max(scale, std::fabs(m));
    for (int k = 0; k < 4; ++k) CHECKF(std::fabs(P[k] - M[k]) <= 1e-12 * scale, "entry %d: %g vs %g", k, P[k], M[k]);
    CHECK(t.factors == 30);
    // det M = e^(L1 + L2) = 1.
    CHECK(std::fabs(t.L1 + t.L2) < 1e-12);
}

TEST_CASE("the truncated map's Jacobian is its derivative, with determinant 1", "[tangent]") {
    const TruncatedMap m = make_truncated_map(0.3, 2 * kPi * 0.618, 3 * kPi / 4, 1.0, 0.5, 0.5);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> ph(-kPi, kPi), kk(-0.4, 0.6);
    int checked = 0;
    for (int i = 0; i < 400; ++i) {
        const double phi = ph(rng), K = kk(rng);
        const StepJacobian sj = m.step_jacobian(phi, K);
        const auto img = m.step(phi, K);
        CHECK(sj.phi == img.first);
        CHECK(sj.K == img.second);
        CHECK(std::fabs(sj.J[0] * sj.J[3] - sj.J[1] * sj.J[2] - 1) < 1e-14 * (1 + std::fabs(sj.J[1] * sj.J[2])));
        // A central difference whose stencil stays on the point's arc: error h^2 |F'''| + ulp / h.
        const double h = 1e-6;
        bool same = true;
        for (int s = -1; s <= 1; s += 2)
            for (int k = 0; k < 2; ++k)
                same = same && m.region(phi + (k == 0 ? s * h : 0), K + (k == 1 ? s * h : 0)) == sj.region;
        if (!same || (K < 0 && K > -1e-3)) continue;  // a stencil across an arc end, or at the sqrt(-K) singularity
        ++checked;
        auto f = [&](double x, double y) { return m.step(x, y); };
        for (int k = 0; k < 2; ++k) {
            const auto d = central(f, phi, K, h, k);
            const double scale = 1 + std::fabs(sj.J[1]);
            CHECKF(std::fabs(d[0] - sj.J[k]) < 1e-7 * scale, "phi %g K %g col %d", phi, K, k);
            CHECKF(std::fabs(d[1] - sj.J[2 + k]) < 1e-7 * scale, "phi %g K %g col %d", phi, K, k);
        }
    }
    CHECK(checked > 300);
    // A point on an arc start: the derivative there is one-sided (status Corner).
    const std::vector<double> s = m.arc_starts(-0.2);
    for (double a : s) CHECK(m.step_jacobian(a, -0.2).status == Status::Corner);
}

TEST_CASE("the action-angle chart's slope is the derivative of point_at", "[tangent]") {
    const std::shared_ptr<const Potential> pots[] = {std::make_shared<Harmonic>(1.3), std::make_shared<Tan>(1.4, 0.7),
                                                     std::make_shared<Numerical>(std::make_shared<Tan>(1.4, 0.7))};
    for (const auto& V : pots)
        for (double th : {-2.5, -0.3, 0.0, 1.1, 3.0})
            for (double e : {0.2, 1.0}) {
                const auto d = V->point_slope(th, e);
                const double h = 1e-5 * e;
                const auto a = V->point_at(th, e + h), b = V->point_at(th, e - h);
                CHECKF(std::fabs(d[0] - (a.first - b.first) / (2 * h)) < 1e-7, "%s th %g e %g", V->name().c_str(), th, e);
                CHECKF(std::fabs(d[1] - (a.second - b.second) / (2 * h)) < 1e-7, "%s th %g e %g", V->name().c_str(), th,
                       e);
            }
}

TEST_CASE("the flow map's Jacobian is the derivative of its return, every stepper", "[tangent]") {
    // The README's system on section coordinates at eps = -0.05 and the linear flow: one return's
    // central difference at h = 1e-5 (error ~ h^2 |F'''| + 1e3 rtol / h ~ 1e-7) against the
    // variational equations; the return is step()'s bit for bit for the explicit steppers.
    const FlowSystem tan_sys =
        hovering_test::step_system(std::make_shared<Harmonic>(1.0), std::make_shared<Tan>(1.4, 0.7), Geometry::Step, -0.05);
    const FlowSystem lin_sys = hovering_test::step_system(std::make_shared<Harmonic>(1.0),
                                                          std::make_shared<Harmonic>(1.3), Geometry::Step, 0.1);
    struct Case {
        const FlowSystem* s;
        const char* stepper;
    };
    const Case cases[] = {{&tan_sys, "rk8pd"}, {&tan_sys, "taylor"}, {&tan_sys, "rk4imp"},
                          {&lin_sys, "exact"}, {&lin_sys, "msadams"}};
    const double starts[][2] = {{0.3, 0.35}, {1.0, 0.45}, {-2.0, 0.3}, {2.6, 0.2}};
    for (const Case& c : cases) {
        FlowOptions o;
        o.stepper = parse_stepper(c.stepper);
        o.rtol = o.atol = 1e-12;
        const FlowMap fm(*c.s, 1.0, o);
        for (const auto& st : starts) {
            const FlowJacobian fj = fm.jacobian(st[0], st[1]);
            if (fj.step.ret.status != FlowStatus::Ok) continue;
            const FlowStep plain = fm.step(st[0], st[1]);
            if (std::string(c.stepper) != "msadams" && std::string(c.stepper) != "rk4imp") {
                CHECK(plain.x == fj.step.x);
                CHECK(plain.y == fj.step.y);
            }
            const double det = fj.J[0] * fj.J[3] - fj.J[1] * fj.J[2];
            CHECKF(std::fabs(det - 1) < 1e-8, "%s det %g", c.stepper, det);
            auto f = [&](double x, double y) {
                const FlowStep r = fm.step(x, y);
                return std::make_pair(r.x, r.y);
            };
            const double h = 1e-5;
            for (int k = 0; k < 2; ++k) {
                const auto d = central(f, st[0], st[1], h, k);
                const double scale = 1 + std::fabs(fj.J[1]);
                CHECKF(std::fabs(d[0] - fj.J[k]) < 1e-6 * scale, "%s start (%g, %g) col %d: %g vs %g", c.stepper, st[0],
                       st[1], k, d[0], fj.J[k]);
                CHECKF(std::fabs(d[1] - fj.J[2 + k]) < 1e-6 * scale, "%s start (%g, %g) col %d: %g vs %g", c.stepper,
                       st[0], st[1], k, d[1], fj.J[2 + k]);
            }
        }
    }
}
