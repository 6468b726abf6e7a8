// The smooth flow's return map against exact results (eps = 0) and time reversal (eps != 0).
#include <cmath>
#include <memory>

#include "check.hpp"
#include "hovering/flow.hpp"

using namespace hovering;

namespace {
const double kPi = 3.14159265358979323846;
double wrap(double x) { return x - 2 * kPi * std::floor((x + kPi) / (2 * kPi)); }
}  // namespace

int main() {
    FlowSystem s;
    s.V1 = std::make_shared<Harmonic>(1.0);
    s.V2 = std::make_shared<Tan>(1.4, 0.7);
    s.coupling = Coupling::bilinear();
    s.qw1 = -1.0;
    s.qw2 = -0.5;
    const double h = 1.0;
    FlowOptions o;
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
            CHECK(r.status == FlowStatus::Ok, "status");
            CHECK(std::fabs(c[1] - I) < 1e-10, "I=%g th=%g: action %.15g changed", I, th, c[1]);
            CHECK(std::fabs(wrap(c[0] - th - Om)) < 1e-9, "I=%g th=%g: angle %.15g vs %.15g", I, th, c[0], wrap(th + Om));
            CHECK(std::fabs(r.time - T1) < 1e-9, "return time %.15g vs T1 %.15g", r.time, T1);
            CHECK(r.energy_error < 1e-10, "energy error %.3g", r.energy_error);
            CHECK(std::fabs(r.z[1]) < 1e-12 && r.z[0] > 0, "returned onto Sigma_h");
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
        CHECK(std::fabs(back[2] - x[2]) < 1e-8 && std::fabs(back[3] + x[3]) < 1e-8 && std::fabs(back[0] - x[0]) < 1e-8,
              "time reversal at th=%g: (%.12g, %.12g) vs (%.12g, %.12g)", th, back[2], back[3], x[2], -x[3]);
    }

    // Bad input.
    CHECK_THROWS(section_point(s, h, 0.3, 5.0), "no point of Sigma_h");
    CHECK_THROWS(section_point(s, h, 4.0, 0.3), "theta must lie in [-pi, pi]");
    FlowOptions bad = o;
    bad.stepper = "euler";
    CHECK_THROWS(return_map(s, section_point(s, h, 0.3, 0.3), bad), "stepper must be one of");
    bad = o;
    bad.rtol = 0;
    CHECK_THROWS(return_map(s, section_point(s, h, 0.3, 0.3), bad), "rtol must lie in (0, 1)");
    FlowSystem w = s;
    w.geometry = Geometry::Step;
    CHECK_THROWS(return_map(w, section_point(s, h, 0.3, 0.3), o), "not implemented yet");
    return test_summary("test_flow");
}
