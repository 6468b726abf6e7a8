// The smooth flow's return map against exact results (eps = 0) and time reversal (eps != 0).
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <vector>

#include "hovering/flow/return_map.hpp"
#include "hovering/detail/poly_roots.hpp"
#include "hovering/flow/taylor.hpp"
#include "testing.hpp"

using namespace hovering;

namespace {
const double kPi = 3.14159265358979323846;
double wrap(double x) {
    return x - 2 * kPi * std::floor((x + kPi) / (2 * kPi));
}
}  // namespace

TEST_CASE("return map: exact eps = 0 answers, time reversal, regions, grazing, msadams", "[flow]") {
    FlowSystem s;
    s.V1 = std::make_shared<Harmonic>(1.0);
    s.V2 = std::make_shared<Tan>(1.4, 0.7);
    s.coupling = Coupling::bilinear();
    s.qw1 = -1.0;
    s.qw2 = -0.5;
    const double h = 1.0;
    FlowOptions o;
    o.stepper = Stepper::Rk8pd;  // the GSL path (the default, "auto", is taylor here): its errors below
    o.rtol = 1e-12;
    o.atol = 1e-14;

    // eps = 0: oscillator 2 keeps its action, the return takes one period of oscillator 1, and the
    // angle advances by Omega0(I) = omega2(H2(I)) T1(h - H2(I)) (eq:omega0ofI). rk8pd at rtol 1e-12
    // over ~6 time units: ~1e-10 in the angle.
    s.eps = 0.0;
    for (double I : {0.1, 0.3, 0.45}) {
        const double e2 = s.V2->energy(I);
        const double T1 = s.V1->period(h - e2), Om = s.V2->frequency(e2) * T1;
        for (double th : {-2.5, -0.4, 0.0, 1.1, 3.0}) {
            const auto z0 = section_point(s, h, th, I);
            const ReturnResult r = return_map(s, z0, o);
            const auto c = section_coordinates(s, r.z.data());
            CHECKF(r.status == FlowStatus::Ok, "status");
            CHECKF(std::fabs(c[1] - I) < 1e-10, "I=%g th=%g: action %.15g changed", I, th, c[1]);
            CHECKF(std::fabs(wrap(c[0] - th - Om)) < 1e-9, "I=%g th=%g: angle %.15g vs %.15g", I, th, c[0],
                   wrap(th + Om));
            CHECKF(std::fabs(r.time - T1) < 1e-9, "return time %.15g vs T1 %.15g", r.time, T1);
            CHECKF(r.energy_error < 1e-10, "energy error %.3g", r.energy_error);
            CHECKF(std::fabs(r.z[1]) < 1e-12 && r.z[0] > 0, "returned onto Sigma_h");
        }
    }

    // eps != 0: time reversal R2 F R2 = F^{-1} (lem:timerevgen), i.e. F(R2 F(x)) = R2 x with R2
    // flipping p2. Two returns at rtol 1e-12: 1e-8.
    s.eps = 0.05;
    for (double th : {-1.0, 0.7, 2.2}) {
        const auto x = section_point(s, h, th, 0.3);
        auto y = return_map(s, x, o).z;
        y[3] = -y[3];
        const auto back = return_map(s, y, o).z;
        CHECKF(std::fabs(back[2] - x[2]) < 1e-8 && std::fabs(back[3] + x[3]) < 1e-8 && std::fabs(back[0] - x[0]) < 1e-8,
               "time reversal at th=%g: (%.12g, %.12g) vs (%.12g, %.12g)", th, back[2], back[3], x[2], -x[3]);
    }

    // Bad input.
    CHECK_INVALID(section_point(s, h, 0.3, 5.0), "no point of Sigma_h");
    CHECK_INVALID(section_point(s, h, 4.0, 0.3), "theta must lie in [-pi, pi]");
    FlowOptions bad = o;
    CHECK_INVALID(parse_stepper("euler"), "stepper must be one of");
    CHECK(parse_stepper("rk8pd") == Stepper::Rk8pd);
    CHECK(std::string(stepper_name(Stepper::Exact)) == "exact");
    for (const char* name : kSteppers) CHECK(std::string(stepper_name(parse_stepper(name))) == name);
    // The default "auto" is taylor on a polynomial field (Harmonic x Tan), and never reaches a tracer
    // unresolved; any other stepper is itself.
    CHECK((FlowOptions{}.stepper == Stepper::Auto && std::string(kSteppers[0]) == "auto"));
    CHECK(resolve_stepper(Stepper::Auto, s) == Stepper::Taylor);
    CHECK(FlowOptions{}.resolved(s).stepper == Stepper::Taylor);
    CHECK((resolve_stepper(Stepper::Rk8pd, s) == Stepper::Rk8pd && resolve_stepper(Stepper::Exact, s) == Stepper::Exact));
    bad.rtol = 0;
    CHECK_INVALID(return_map(s, section_point(s, h, 0.3, 0.3), bad), "rtol must lie in (0, 1)");
    bad = o;
    bad.max_impacts = 0;
    CHECK_INVALID(return_map(s, section_point(s, h, 0.3, 0.3), bad), "max_impacts must be in");

    // ---- walls, eps = 0: each itinerary has an exact oracle (partial energies are conserved).
    s.eps = 0.0;
    const double h1w = s.V1->V(s.qw1), I_tan = s.V2->action(h - h1w);
    auto oracle_wall_time = [&](double I) {  // harmonic V1: q1 = A cos(t), reflected at qw1
        const double h1 = h - s.V2->energy(I), A = std::sqrt(2 * h1);
        return 2 * std::acos(s.qw1 / A);
    };
    // Infinite wall: every orbit with I < I_tan reflects once ('R'), the others never.
    FlowSystem wl = s;
    wl.geometry = Geometry::Wall;
    for (double I : {0.2 * I_tan, 0.7 * I_tan, 1.2 * I_tan}) {
        const double e2 = s.V2->energy(I);
        for (double th : {-2.0, 0.5, 2.9}) {
            const ReturnResult r = return_map(wl, section_point(wl, h, th, I), o);
            const auto c = section_coordinates(wl, r.z.data());
            const bool hits = I < I_tan;
            const double T = hits ? oracle_wall_time(I) : s.V1->period(h - e2);
            // The infinite wall: an orbit that reaches q1 = qw1 reflects ('R'); the others never cross it ('u').
            CHECKF(r.status == FlowStatus::Ok && r.itinerary == (hits ? "R" : "u"), "wall I=%g: itinerary '%s'", I,
                   r.itinerary.c_str());
            CHECKF(std::fabs(r.time - T) < 1e-9, "wall I=%g th=%g: time %.15g vs %.15g", I, th, r.time, T);
            CHECKF(std::fabs(c[1] - I) < 1e-10 && std::fabs(wrap(c[0] - th - s.V2->frequency(e2) * T)) < 1e-9,
                   "wall I=%g th=%g: (theta, I) off", I, th);
            CHECKF(r.energy_error < 1e-10, "wall energy error %.3g", r.energy_error);
        }
    }
    // Step: the three regions J_R, J_1, J_0 of thm:regionsJdyn on one circle I < I_tan.
    FlowSystem sp = s;
    sp.geometry = Geometry::Step;
    const double I = 0.7 * I_tan, e2 = s.V2->energy(I), T1 = s.V1->period(h - e2), w2 = s.V2->frequency(e2);
    const double thw = s.V2->angle_of(s.qw2, e2);
    int seen_R = 0, seen_1 = 0, seen_0 = 0;
    for (int k = 0; k < 120; ++k) {
        const double th = -kPi + (k + 0.5) * 2 * kPi / 120;
        const ReturnResult r = return_map(sp, section_point(sp, h, th, I), o);
        if (r.status != FlowStatus::Ok) continue;
        const auto c = section_coordinates(sp, r.z.data());
        CHECKF(std::fabs(c[1] - I) < 1e-10, "step: I changed at th=%g ('%s')", th, r.itinerary.c_str());
        double T = T1, dth = w2 * T1;
        if (r.itinerary == "R") {
            T = oracle_wall_time(I);
            dth = w2 * T;
            ++seen_R;
        } else if (r.itinerary == "1") {
            dth = w2 * T1 + 2 * (kPi - thw);  // eq:Thetaj1
            ++seen_1;
        } else {
            // I < I_tan: every orbit reaches q1 = qw1, so a return without impact crossed it above the step.
            CHECKF(r.itinerary == "0", "unexpected itinerary '%s'", r.itinerary.c_str());
            CHECKF(region_of(r.itinerary) == Region::Above, "region of '0'");
            ++seen_0;
        }
        CHECKF(std::fabs(r.time - T) < 1e-9 && std::fabs(wrap(c[0] - th - dth)) < 1e-9,
               "step th=%g '%s': time %.12g vs %.12g, dtheta %.12g vs %.12g", th, r.itinerary.c_str(), r.time, T,
               wrap(c[0] - th), wrap(dth));
    }
    CHECKF(seen_R > 5 && seen_1 > 1 && seen_0 > 5, "regions seen: R %d, 1 %d, 0 %d", seen_R, seen_1, seen_0);

    // Grazing: on the tangent circle I = I_tan the orbit touches q1 = qw1; 1e-9 below it every orbit
    // dips ~1e-9 through the wall inside a step (a sign test at step ends misses such dips) and must
    // reflect; 1e-9 above it none may.
    int graze = 0, below = 0, above = 0;
    for (int k = 0; k < 100; ++k) {
        const double th = -kPi + (k + 0.5) * 2 * kPi / 100;
        graze += return_map(wl, section_point(wl, h, th, I_tan), o).status == FlowStatus::Grazing;
        below += return_map(wl, section_point(wl, h, th, I_tan - 1e-9), o).itinerary == "R";
        above += return_map(wl, section_point(wl, h, th, I_tan + 1e-9), o).itinerary == "u";
    }
    CHECKF(graze == 100 && below == 100 && above == 100, "grazing %d, 1e-9 below reflected %d, above free %d (of 100)",
           graze, below, above);

    // msadams (GSL's variable-order Adams): the same exact wall answers and near-grazing dips, its
    // events located on an rk8pd extension of each step. Adams' global error runs ~400x its local
    // tolerance here (measured max 3.8e-10 over 200 returns at rtol = atol = 1e-12), hence 5e-9.
    FlowOptions ms = o;
    ms.stepper = Stepper::Msadams;
    ms.atol = 1e-12;
    // Its own traces: verified, that ~400x error at 1e-12 is IMPRECISE (its floor, 1e-14, is too
    // close to bring it within rtol).
    ms.verify_steps = 0;
    int ms_below = 0, ms_above = 0;
    for (int k = 0; k < 40; ++k) {
        const double th = -kPi + (k + 0.5) * 2 * kPi / 40;
        for (double I : {0.5 * I_tan, 1.1 * I_tan}) {
            const double e2 = wl.V2->energy(I), A1 = std::sqrt(2 * (h - e2));
            const bool hits = I < I_tan;
            const double dth = s.V2->frequency(e2) * (hits ? 2 * std::acos(wl.qw1 / A1) : s.V1->period(h - e2));
            const ReturnResult r = return_map(wl, section_point(wl, h, th, I), ms);
            const auto c = section_coordinates(wl, r.z.data());
            CHECKF(r.status == FlowStatus::Ok && r.itinerary == (hits ? "R" : "u"), "msadams th=%g I=%g: '%s'", th, I,
                   r.itinerary.c_str());
            CHECKF(std::fabs(wrap(c[0] - th - dth)) < 5e-9, "msadams th=%g I=%g: dtheta error %.3g", th, I,
                   wrap(c[0] - th - dth));
        }
        ms_below += return_map(wl, section_point(wl, h, th, I_tan - 1e-9), ms).itinerary == "R";
        ms_above += return_map(wl, section_point(wl, h, th, I_tan + 1e-9), ms).itinerary == "u";
    }
    CHECKF(ms_below == 40 && ms_above == 40, "msadams: 1e-9 below reflected %d, above free %d (of 40)", ms_below,
           ms_above);
}

TEST_CASE("section coordinates at the bottom of well 2; section points next to the turning points", "[flow]") {
    FlowSystem s;
    s.V1 = std::make_shared<Harmonic>(1.0);
    s.coupling = Coupling::bilinear();
    s.eps = 0.05;
    s.qw1 = -1.0;
    s.qw2 = -0.5;
    // H2 = 0 (q2 = p2 = 0): the centre of the polar-like (theta, I), I = 0 exactly and theta = 0
    // by convention, for closed-form and quadrature V2 alike (it was "Tan.action: energy must be
    // finite and > 0, got 0").
    const std::array<double, 4> rest{1.2, 0.0, 0.0, 0.0};
    for (auto V2 : {std::shared_ptr<const Potential>(std::make_shared<Tan>(1.4, 0.7)),
                    std::shared_ptr<const Potential>(std::make_shared<Harmonic>(1.3)),
                    std::shared_ptr<const Potential>(std::make_shared<Numerical>(std::make_shared<Tan>(1.4, 0.7)))}) {
        s.V2 = V2;
        const auto c = section_coordinates(s, rest.data());
        CHECKF(c[0] == 0.0 && c[1] == 0.0, "%s: (theta, I) = (%g, %g) at H2 = 0", V2->name().c_str(), c[0], c[1]);
    }
    // A finite state whose H2 overflows (a runaway orbit's last state, NON_FINITE) has no
    // coordinates: NaN, not an action error (it made Section.return_map raise for the batch).
    s.V2 = std::make_shared<Harmonic>(0.2);
    const std::array<double, 4> runaway{1.8e307, 1.2e307, 1.8e307, 1.2e307};
    const auto nc = section_coordinates(s, runaway.data());
    CHECKF(std::isnan(nc[0]) && std::isnan(nc[1]), "(theta, I) = (%g, %g) at H2 = inf", nc[0], nc[1]);
    // A V2 below its minimum V2(0) = 0 is not a single well: named, not an action error.
    struct Negative final : Potential {
        double V(double q) const override { return -0.5 * q * q; }
        double dV(double q) const override { return -q; }
        std::string name() const override { return "Negative"; }
    };
    s.V2 = std::make_shared<Negative>();
    const std::array<double, 4> z{1.2, 0.0, 0.5, 0.0};
    CHECK_INVALID(section_coordinates(s, z.data()),
                  "H2 = p2^2/2 + V2(q2) = -0.125 at (q2, p2) = (0.5, 0) must be >= 0");

    // Points of Sigma_h with a quadrature V2 next to its turning points (theta = pi - 2e-6 raised
    // "quadrature ... did not converge" in point_at): the same point as the closed form's to the
    // accuracy of point_at (1e-11, test_potential).
    FlowSystem c = s, n = s;
    c.V2 = std::make_shared<Tan>(1.4, 0.7);
    n.V2 = std::make_shared<Numerical>(c.V2);
    for (double th : {kPi - 2e-6, kPi - 1e-6, -kPi + 3e-7, 2e-6, -1e-6, 1e-12}) {
        const auto zc = section_point(c, 1.0, th, 0.3), zn = section_point(n, 1.0, th, 0.3);
        CHECKF(std::fabs(zc[0] - zn[0]) < 1e-11 && std::fabs(zc[2] - zn[2]) < 1e-11 && std::fabs(zc[3] - zn[3]) < 1e-11,
               "theta = %.17g: (%.17g, %.17g, %.17g) vs (%.17g, %.17g, %.17g)", th, zn[0], zn[2], zn[3], zc[0], zc[2],
               zc[3]);
    }
}

TEST_CASE("stepper taylor: the series of the exact solution, and exact eps = 0 returns", "[flow]") {
    FlowSystem s;
    s.V1 = std::make_shared<Harmonic>(1.3);
    s.V2 = std::make_shared<Tan>(1.4, 0.7);
    s.coupling = Coupling::bilinear();
    s.qw1 = -1.0;
    s.qw2 = -0.5;
    s.geometry = Geometry::Step;
    FlowOptions o;
    o.stepper = Stepper::Taylor;
    o.rtol = o.atol = 1e-13;
    o.validate(s);

    // eps = 0, one step of the expansion: q1 is exactly q0 cos(w t) + (p0 / w) sin(w t), and the
    // Tan oscillator keeps u = tan(alpha q2) and its energy. Over a step of <= 0.3 time units at
    // tol 1e-13 the truncation error is ~1e-13 relative (Jorba-Zou), rounding ~1e-15.
    s.eps = 0.0;
    detail::Field f(s);
    detail::Taylor T(f, s, o.rtol, o.atol);
    double y0[detail::kMaxDim] = {0.4, -0.9, 0.3, 0.8, 0.0, 0.0};
    f.sync_aux(y0);
    double hstep = 0;
    CHECKF(T.expand(y0, HUGE_VAL, &hstep) && hstep > 0.05 && std::isfinite(hstep), "expansion and step %g", hstep);
    const double w = 1.3, E2 = 0.5 * y0[3] * y0[3] + s.V2->V(y0[2]);
    for (double t : {0.0, 0.05, 0.5 * hstep, hstep}) {
        double y[detail::kMaxDim];
        T.eval(t, y);
        const double q1 = y0[0] * std::cos(w * t) + y0[1] / w * std::sin(w * t);
        CHECKF(std::fabs(y[0] - q1) < 1e-13, "t=%g: q1 %.17g vs exact %.17g", t, y[0], q1);
        CHECKF(std::fabs(y[4] - std::tan(0.7 * y[2])) < 1e-12, "t=%g: u %.17g vs tan(alpha q2) %.17g", t, y[4],
               std::tan(0.7 * y[2]));
        CHECKF(std::fabs(0.5 * y[3] * y[3] + s.V2->V(y[2]) - E2) < 1e-13, "t=%g: H2 drifted", t);
    }

    // Whole returns at eps = 0 against the closed form (stepper "exact"), impacts on the infinite
    // wall included (q1's amplitude exceeds |qw1| for I < ~0.1): 5e-12.
    s.geometry = Geometry::Wall;
    FlowOptions ex;
    ex.stepper = Stepper::Exact;
    const double h = 1.0;
    int impacts = 0;
    for (double I : {0.02, 0.06, 0.3}) {
        for (double th : {-2.5, -0.4, 0.0, 1.1, 3.0}) {
            const auto z0 = section_point(s, h, th, I);
            const ReturnResult a = return_map(s, z0, o), b = return_map(s, z0, ex);
            CHECKF(a.status == b.status && a.itinerary == b.itinerary, "I=%g th=%g: status/itinerary differ", I, th);
            impacts += a.itinerary != "u" && a.itinerary != "0";
            for (int k = 0; k < 4; ++k)
                CHECKF(std::fabs(a.z[std::size_t(k)] - b.z[std::size_t(k)]) < 5e-12, "I=%g th=%g: z[%d] %.15g vs %.15g",
                       I, th, k, a.z[std::size_t(k)], b.z[std::size_t(k)]);
        }
    }
    CHECKF(impacts >= 3, "only %d returns with impacts", impacts);

    // A Numerical wrapper has its base's force, hence its recurrences.
    FlowSystem c = s;
    c.V1 = std::make_shared<Numerical>(s.V1);
    CHECKF(detail::taylor_unsupported(c).empty(), "Numerical(Harmonic) has the recurrences of its base");
}

TEST_CASE("stepper taylor: lane groups own their coefficients until the next round", "[flow]") {
    // The README system at eps = 0.05; eight different states, tolerance 1e-12.
    FlowSystem s;
    s.V1 = std::make_shared<Harmonic>(1.0);
    s.V2 = std::make_shared<Tan>(1.4, 0.7);
    s.coupling = Coupling::bilinear();
    s.eps = 0.05;
    s.qw1 = -1.0;
    s.qw2 = -0.5;
    s.geometry = Geometry::Step;
    detail::Field f(s);
    const int n = detail::kMaxTaylorGroup;
    std::vector<std::unique_ptr<detail::Taylor>> t;
    std::vector<std::array<double, detail::kMaxDim>> y(static_cast<std::size_t>(n));
    for (int l = 0; l < n; ++l) {
        t.push_back(std::make_unique<detail::Taylor>(f, s, 1e-12, 1e-12));
        auto& v = y[std::size_t(l)];
        v = {0.3 - 0.1 * l, -0.5 + 0.13 * l, 0.2 + 0.05 * l, 0.4 - 0.07 * l, 0.0, 0.0};
        f.sync_aux(v.data());
    }
    detail::Taylor* tp[detail::kMaxTaylorGroup];
    const double* yp[detail::kMaxTaylorGroup];
    double hmax[detail::kMaxTaylorGroup];
    for (int l = 0; l < n; ++l) {
        tp[l] = t[std::size_t(l)].get();
        yp[l] = y[std::size_t(l)].data();
        hmax[l] = 0.5;
    }
    detail::TaylorLanes lanes;
    detail::Taylor::expand_group(tp, yp, hmax, lanes, n);

    // A lone expansion of the same state is bit for bit what the group gave each lane: the step,
    // the state at the step's end, and the polynomial at other times.
    detail::Taylor alone(f, s, 1e-12, 1e-12);
    for (int l = 0; l < n; ++l) {
        double hg = 0, ha = 0;
        CHECKF(tp[l]->expanded_at(yp[l], &hg), "lane %d: expanded at its state after the round", l);
        CHECKF(alone.expand(yp[l], hmax[l], &ha) && ha == hg, "lane %d: step %.17g alone, %.17g in the group", l, ha, hg);
        for (double tau : {std::min(hg, hmax[l]), 0.37 * hg, 0.0}) {
            double a[detail::kMaxDim], g[detail::kMaxDim];
            alone.eval(tau, a);
            tp[l]->eval(tau, g);
            for (int i = 0; i < f.dim; ++i)
                CHECKF(a[i] == g[i], "lane %d tau %g: y[%d] %.17g alone, %.17g in the group", l, tau, i, a[i], g[i]);
        }
    }
    // A step's end comes from the lanes' Estrin, any other time from the scalar one: the same bits
    // (b's step end, set by its bound hmax = h / 2, is a time a evaluates in scalar).
    {
        detail::Taylor a(f, s, 1e-12, 1e-12), b(f, s, 1e-12, 1e-12);
        double ha = 0, hb = 0;
        CHECKF(a.expand(yp[2], HUGE_VAL, &ha) && b.expand(yp[2], 0.5 * ha, &hb) && ha == hb, "steps %g, %g", ha, hb);
        double ya[detail::kMaxDim], yb[detail::kMaxDim];
        a.eval(0.5 * ha, ya);
        b.eval(0.5 * ha, yb);
        for (int i = 0; i < f.dim; ++i) CHECKF(ya[i] == yb[i], "y[%d]: scalar %.17g, lanes %.17g", i, ya[i], yb[i]);
    }
    // Expanding lane 0 alone moves it to its own buffer and leaves the group's lanes valid.
    double h = 0;
    CHECKF(tp[0]->expand(yp[1], 0.5, &h), "lane 0 re-expanded alone");
    CHECKF(!tp[0]->expanded_at(yp[0]) && tp[0]->expanded_at(yp[1]), "lane 0 follows its own expansion");
    CHECKF(tp[5]->expanded_at(yp[5]), "lane 5 still holds its round's coefficients");
    // A new round of lanes 0-2 overwrites the group's buffer: lanes 3-7, not in it, must see that
    // their coefficients are gone, lane 3 too, whose state the buffer holds again (in another slot).
    const double* yq[3] = {yp[3], yp[1], yp[2]};
    detail::Taylor::expand_group(tp, yq, hmax, lanes, 3);
    CHECKF(tp[0]->expanded_at(yp[3]) && tp[1]->expanded_at(yp[1]), "the new round's lanes hold it");
    for (int l = 0; l < 3; ++l) {  // a round of four lanes (one register) is bit for bit a lone expansion too
        double hg = 0, ha = 0;
        CHECKF(tp[l]->expanded_at(yq[l], &hg) && alone.expand(yq[l], hmax[l], &ha) && ha == hg, "lane %d of 3", l);
        for (double tau : {std::min(hg, hmax[l]), 0.61 * hg}) {
            double a[detail::kMaxDim], g[detail::kMaxDim];
            alone.eval(tau, a);
            tp[l]->eval(tau, g);
            for (int i = 0; i < f.dim; ++i) CHECKF(a[i] == g[i], "lane %d of 3, tau %g: y[%d] differs", l, tau, i);
        }
    }
    for (int l = 3; l < n; ++l) {
        CHECKF(!tp[l]->expanded_at(yp[l]), "lane %d: stale coefficients reported current", l);
        double g[detail::kMaxDim];
        tp[l]->eval(0.1, g);  // what another orbit's round left there is never evaluated
        for (int i = 0; i < f.dim; ++i) CHECKF(std::isnan(g[i]), "lane %d: stale eval y[%d] = %g", l, i, g[i]);
    }
}

TEST_CASE("stepper taylor: the lanes' sign test is the scalar one; per-lane step rules in one round", "[flow]") {
    // Tan x Tan with a degree-4 coupling. Lanes 0-3 at rtol 1e-10; lanes 4-7 are verifiers of the
    // same states (rtol 1e-12 at lanes 0-3's order, as Tracer::verify_at builds them), expanded
    // in the same kernel call. The lanes' keeps_sign verdict (TaylorStep) must be exactly the
    // scalar keeps_sign of the coefficients taylor_cut scales (else a step with two sign changes
    // of p1 or p2 could go unsearched), and every lane must be bit for bit its lone expansion.
    FlowSystem s;
    s.V1 = std::make_shared<Tan>(1.0, 0.6);
    s.V2 = std::make_shared<Tan>(1.4, 0.7);
    s.coupling = Coupling{{{1.0, 2.0, 1.0}, {1.0, 1.0, 3.0}}};
    s.eps = 0.05;
    s.qw1 = -1.0;
    s.qw2 = -0.5;
    s.geometry = Geometry::Step;
    detail::Field f(s);
    detail::Taylor base(f, s, 1e-10, 1e-10);
    const int p = base.order();
    std::vector<std::unique_ptr<detail::Taylor>> t;
    for (int l = 0; l < detail::kMaxTaylorGroup; ++l)
        t.push_back(l < 4 ? std::make_unique<detail::Taylor>(f, s, 1e-10, 1e-10)
                          : std::make_unique<detail::Taylor>(f, s, 1e-12, 1e-12, p));
    detail::Taylor alone(f, s, 1e-10, 1e-10), alone_v(f, s, 1e-12, 1e-12, p);
    CHECKF(alone_v.order() == p, "the verifier keeps order %d (got %d)", p, alone_v.order());
    std::uint64_t seed = 12345;
    auto uniform = [&seed](double a, double b) {
        seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
        return a + (b - a) * double(seed >> 11) * 0x1.0p-53;
    };
    int kept[2] = {0, 0}, changed[2] = {0, 0};
    detail::TaylorLanes lanes;
    for (int round = 0; round < 200; ++round) {
        std::vector<std::array<double, detail::kMaxDim>> y(detail::kMaxTaylorGroup);
        for (int l = 0; l < 4; ++l) {
            auto& v = y[std::size_t(l)];
            // Velocities near 0 in some rounds: steps whose p1 or p2 polynomial changes sign.
            const double small = round % 3 == 0 ? 1e-3 : 1.0;
            v = {uniform(-0.8, 0.8), small * uniform(-1, 1), uniform(-0.6, 0.6), small * uniform(-1, 1), 0.0, 0.0};
            f.sync_aux(v.data());
            y[std::size_t(l + 4)] = v;
        }
        detail::Taylor* tp[detail::kMaxTaylorGroup];
        const double* yp[detail::kMaxTaylorGroup];
        double hmax[detail::kMaxTaylorGroup];
        for (int l = 0; l < detail::kMaxTaylorGroup; ++l) {
            tp[l] = t[std::size_t(l)].get();
            yp[l] = y[std::size_t(l)].data();
            hmax[l] = round % 2 ? 0.2 : HUGE_VAL;
        }
        detail::Taylor::expand_group(tp, yp, hmax, lanes, detail::kMaxTaylorGroup);
        for (int l = 0; l < detail::kMaxTaylorGroup; ++l) {
            double hg = 0, ha = 0;
            detail::Taylor& a = l < 4 ? alone : alone_v;
            CHECKF(tp[l]->expanded_at(yp[l], &hg) && a.expand(yp[l], hmax[l], &ha) && ha == hg,
                   "round %d lane %d: step %.17g alone, %.17g in the round", round, l, ha, hg);
            const double step = std::min(hg, hmax[l]);
            for (int w = 0; w < 2; ++w) {
                double b[detail::kMaxTaylorOrder + 1];
                CHECKF(tp[l]->scaled_coefficients(2 * w + 1, step, b), "round %d lane %d: coefficients", round, l);
                const bool scalar = detail::keeps_sign(b, p);
                CHECKF(tp[l]->keeps_sign(w, step) == scalar && a.keeps_sign(w, step) == scalar,
                       "round %d lane %d w %d: lanes say %d, alone %d, scalar %d", round, l, w,
                       int(tp[l]->keeps_sign(w, step)), int(a.keeps_sign(w, step)), int(scalar));
                ++(scalar ? kept : changed)[w];
            }
        }
        // The verifier's tighter rule takes shorter steps from the same state, in the same call.
        for (int l = 0; l < 4; ++l) {
            double h0 = 0, h1 = 0;
            tp[l]->expanded_at(yp[l], &h0);
            tp[l + 4]->expanded_at(yp[l + 4], &h1);
            CHECKF(h1 < h0, "round %d lane %d: verifier step %.17g, return's %.17g", round, l, h1, h0);
        }
    }
    // Both verdicts occurred for both velocities, else the comparison tested one branch only.
    CHECKF(kept[0] > 0 && changed[0] > 0 && kept[1] > 0 && changed[1] > 0, "verdicts p1 %d/%d, p2 %d/%d", kept[0],
           changed[0], kept[1], changed[1]);
}
