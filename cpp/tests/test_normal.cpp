// The bridge: trigonometric interpolation, the tangential curve measured on the flow, and the flow
// map's iteration (statuses, early exit, visited regions, reproducibility, batch returns).
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include "hovering/normal/flow_map.hpp"
#include "hovering/normal/tangential_curve.hpp"
#include "testing.hpp"

using namespace hovering;

namespace {

const double kPi = 3.14159265358979323846;

FlowSystem issue_system(double eps, Geometry g = Geometry::Step) {
    return hovering_test::step_system(std::make_shared<Harmonic>(1.0), std::make_shared<Tan>(1.4, 0.7), g, eps);
}

FlowOptions tight() {
    FlowOptions o;
    o.rtol = 1e-12;
    o.atol = 1e-12;
    return o;
}

}  // namespace

TEST_CASE("trigonometric interpolant is exact on trigonometric polynomials", "[normal]") {
    // f = 0.3 + cos(s + pi) - 0.2 sin(3 (s + pi)) has degree 3 < 16 / 2: the interpolant from 16
    // samples is f itself (to rounding), and so is its derivative.
    std::vector<double> v(16);
    auto f = [](double s) { return 0.3 + std::cos(s + kPi) - 0.2 * std::sin(3 * (s + kPi)); };
    auto df = [](double s) { return -std::sin(s + kPi) - 0.6 * std::cos(3 * (s + kPi)); };
    for (int k = 0; k < 16; ++k) v[std::size_t(k)] = f(-kPi + 2 * kPi * k / 16);
    const TrigInterpolant p(v);
    for (double s : {-3.0, -1.1, 0.0, 0.77, 2.9}) {
        const auto [val, der] = p.with_derivative(s);
        CHECKF(std::fabs(val - f(s)) < 1e-14 && std::fabs(der - df(s)) < 1e-13, "s=%g: %g vs %g", s, val, f(s));
    }
    CHECK_INVALID(TrigInterpolant(std::vector<double>(7, 1.0)), "even number");
}

TEST_CASE("tangential curve at eps = 0 is the tangent circle", "[normal]") {
    // At eps = 0 partial energies are conserved: I_tan(theta) = H2^{-1}(h - V1(qw1)) for every
    // theta, and theta(s) = s - Omega0/2-like rotation is increasing (slope 1).
    const FlowSystem s = issue_system(0.0);
    const TangentialCurve c = TangentialCurve::measure(s, 1.0, 32, tight(), 4);
    const double I0 = s.V2->action(1.0 - s.V1->V(s.qw1));
    CHECKF(std::fabs(c.I_tan0() - I0) < 1e-15, "I_tan0 %.17g vs %.17g", c.I_tan0(), I0);
    for (double th : {-3.1, -1.0, 0.0, 0.5, 3.0}) CHECKF(std::fabs(c.I_tan(th) - I0) < 1e-12, "theta %g", th);
    CHECK(c.is_graph());
    CHECKF(std::fabs(c.min_slope() - 1.0) < 1e-9, "min slope %g", c.min_slope());
}

TEST_CASE("tangential curve: the flow touches q1 = qw1 exactly there", "[normal]") {
    // Independent of how the curve was built: starting 1e-9 below I_tan(theta) the wall system
    // reaches the line (impact 'R'), 1e-9 above it turns back ('u'). Also the interpolant's own
    // error estimate (direct traces at off-grid wall angles) is at rounding level at eps = 0.05.
    const FlowSystem s = issue_system(0.05);
    const TangentialCurve c = TangentialCurve::measure(s, 1.0, 64, tight(), 4);
    CHECKF(c.interpolation_error().second < 1e-12, "interpolation error %g", c.interpolation_error().second);
    const FlowSystem w = issue_system(0.05, Geometry::Wall);
    FlowOptions o = tight();
    o.rtol = 1e-13;
    o.atol = 1e-15;
    for (double th : {-2.5, -0.4, 1.0, 2.7}) {
        const double I = c.I_tan(th);
        CHECKF(return_map(w, section_point(w, 1.0, th, I - 1e-9), o).itinerary == "R", "below at %g", th);
        CHECKF(return_map(w, section_point(w, 1.0, th, I + 1e-9), o).itinerary == "u", "above at %g", th);
    }
}

TEST_CASE("tangential curve that is not a graph is refused with the reason", "[normal]") {
    const TangentialCurve c = TangentialCurve::measure(issue_system(0.6), 1.0, 64, tight(), 0);
    CHECK_FALSE(c.is_graph());
    CHECK_INVALID(c.I_tan(0.0), "not a graph over theta");
    CHECK_INVALID(FlowMap(issue_system(0.6), 1.0, tight(), std::make_shared<TangentialCurve>(c)), "not a graph");
    CHECK_INVALID(TangentialCurve::measure(issue_system(1.0), 1.0, 64, tight(), 0), "not a minimum of q1");
}

TEST_CASE("flow map iteration: reproducible, statuses per orbit, early exit, visited", "[normal]") {
    const FlowSystem s = issue_system(-0.05);
    auto curve = std::make_shared<TangentialCurve>(TangentialCurve::measure(s, 1.0, 64, tight(), 0));
    const FlowMap fm(s, 1.0, tight(), curve);
    // orbit 1 has no point of Sigma_h (K = 5: H2 > h)
    std::vector<double> x = {0.3, 0.3, -1.0, 2.0, -2.5}, y = {0.01, 5.0, -0.03, -0.02, 0.04};
    const std::int64_t n = std::int64_t(x.size()), ns = 6;
    auto run = [&](int threads, unsigned mask, bool stop) {
        struct R {
            std::vector<double> xf, yf, ox, oy;
            std::vector<std::int8_t> st, reg, vis;
            std::vector<std::int64_t> done, ex;
        } r;
        r.xf.resize(x.size());
        r.yf.resize(x.size());
        r.st.resize(x.size());
        r.done.resize(x.size());
        r.ex.resize(x.size());
        r.vis.resize(x.size());
        r.ox.resize(x.size() * (ns + 1));
        r.oy.resize(x.size() * (ns + 1));
        r.reg.resize(x.size() * ns);
        FlowIterateOptions o;
        o.n_steps = ns;
        o.n_threads = threads;
        o.exit_mask = mask;
        o.stop_on_exit = stop;
        FlowIterateOutput out;
        out.x_final = r.xf.data();
        out.y_final = r.yf.data();
        out.status = r.st.data();
        out.steps_done = r.done.data();
        out.orbit_x = r.ox.data();
        out.orbit_y = r.oy.data();
        out.regions = r.reg.data();
        out.exit_step = r.ex.data();
        out.visited = r.vis.data();
        fm.iterate(x.data(), y.data(), n, o, out);
        return r;
    };
    const auto a = run(1, 0, false), b = run(2, 0, false);
    // Orbits are independent: thread counts change nothing, bit for bit (NaN tails included).
    CHECK(std::memcmp(a.ox.data(), b.ox.data(), a.ox.size() * sizeof(double)) == 0);
    CHECK(a.st[1] == static_cast<std::int8_t>(Status::OffSection));
    CHECK(a.done[1] == 0);
    CHECK(std::isnan(a.ox[1 * (ns + 1) + 1]));
    for (int i : {0, 2, 3, 4}) CHECKF(a.st[std::size_t(i)] == 0 && a.done[std::size_t(i)] == ns, "orbit %d", i);
    // iterate = repeated step, bit for bit (each return starts on Sigma_h solved from coordinates)
    double px = x[2], py = y[2];
    for (int k = 0; k < ns; ++k) {
        const FlowStep st = fm.step(px, py);
        px = st.x;
        py = st.y;
        CHECKF(px == a.ox[std::size_t(2 * (ns + 1) + k + 1)] && py == a.oy[std::size_t(2 * (ns + 1) + k + 1)],
               "step %d", k);
        CHECKF(st.region == Region(a.reg[std::size_t(2 * ns + k)]), "region of step %d", k);
    }
    // Early exit: watch {Beside, Above}; the first return outside it ends the orbit, Exited.
    const unsigned no_impact = (1u << int(Region::Beside)) | (1u << int(Region::Above));
    const auto e = run(2, no_impact, true);
    for (std::size_t i = 0; i < x.size(); ++i) {
        if (i == 1) continue;
        std::int64_t first = -1;
        for (std::int64_t k = 0; k < ns && first < 0; ++k)
            if (!((no_impact >> a.reg[i * ns + std::size_t(k)]) & 1u)) first = k;
        CHECKF(e.ex[i] == first, "orbit %zu: exit %lld vs %lld", i, (long long)e.ex[i], (long long)first);
        CHECKF(e.st[i] == static_cast<std::int8_t>(first >= 0 ? Status::Exited : Status::Ok), "status %zu", i);
        int vis = 0;
        for (std::int64_t k = 0; k < ns; ++k) vis |= 1 << a.reg[i * ns + std::size_t(k)];
        CHECKF(a.vis[i] == vis, "visited %zu: %d vs %d", i, a.vis[i], vis);
    }
    FlowIterateOptions bad;
    bad.n_steps = 1;
    bad.exit_mask = no_impact;
    const FlowMap smooth(issue_system(-0.05, Geometry::None), 1.0, tight(), nullptr);
    FlowIterateOutput none;
    CHECK_INVALID(smooth.iterate(x.data(), y.data(), 1, bad, none), "regions need walls");
    bad.exit_mask = 1u << kRegionCount;
    CHECK_INVALID(fm.iterate(x.data(), y.data(), 1, bad, none), "exit_mask");
    std::vector<double> nan_x = {std::nan("")};
    bad.exit_mask = 0;
    CHECK_INVALID(fm.iterate(nan_x.data(), y.data(), 1, bad, none), "x0[0] must be finite");
}

TEST_CASE("batch return map: one status per orbit, cancellation marks the rest", "[flow]") {
    const FlowSystem s = issue_system(0.05);
    const auto z = section_point(s, 1.0, 0.3, 0.3);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    std::vector<double> z0 = {z[0], z[1], z[2], z[3], nan, 0, 0, 0, z[0], z[1], z[2], z[3]};
    std::vector<std::int8_t> st(3), reg(3);
    std::vector<double> zo(12);
    ReturnMapsOutput out;
    out.status = st.data();
    out.region = reg.data();
    out.z = zo.data();
    return_maps(s, z0.data(), 3, tight(), 2, nullptr, out);
    CHECK(st[0] == 0);
    CHECK(st[1] == static_cast<std::int8_t>(FlowStatus::OffSection));
    CHECK(st[2] == 0);
    CHECK(std::isnan(zo[4]));
    CHECK(zo[0] == zo[8]);
    CHECK(reg[0] == static_cast<std::int8_t>(region_of(return_map(s, z, tight()).itinerary)));
    std::atomic<bool> cancel{true};
    return_maps(s, z0.data(), 3, tight(), 1, &cancel, out);
    for (auto v : st) CHECK(v == static_cast<std::int8_t>(FlowStatus::Interrupted));
    CHECK_INVALID(return_maps(s, z0.data(), 3, tight(), -1, nullptr, out), "n_threads must be in");
}

TEST_CASE("flow map iteration: labels only when read, dense output, work counters, progress", "[normal]") {
    const FlowSystem s = issue_system(-0.05);
    FlowOptions o = tight();
    o.rtol = o.atol = 1e-10;
    // Counting: one section search and one sample per point of each trace, so a single trace per
    // return (a verified return's extra traces are counted too: test_verified_returns.py).
    o.verify_steps = 0;
    const FlowMap fm(s, 1.0, o, nullptr);  // section coordinates (theta, I)
    std::vector<double> x = {0.3, -1.0, 2.0, -2.5, 1.1}, y = {0.30, 0.33, 0.31, 0.29, 50.0};  // the last: OffSection
    const std::int64_t n = std::int64_t(x.size()), ns = 5;
    struct R {
        std::vector<double> xf, yf;
        std::vector<std::int8_t> reg, trunc;
        std::vector<std::vector<double>> pts;
        std::vector<std::vector<std::int8_t>> kinds;
        FlowWork work;
        std::int64_t progress = 0;
    };
    auto run = [&](bool labels, double dt, std::int64_t max_points = 1000000) {
        R r;
        r.xf.resize(x.size());
        r.yf.resize(x.size());
        r.reg.resize(x.size() * ns);
        r.trunc.resize(x.size());
        r.pts.resize(x.size());
        r.kinds.resize(x.size());
        std::atomic<std::int64_t> progress{0};
        FlowIterateOptions opt;
        opt.n_steps = ns;
        opt.labels = labels;
        opt.progress = &progress;
        opt.n_threads = 2;
        FlowIterateOutput out;
        out.x_final = r.xf.data();
        out.y_final = r.yf.data();
        out.work = &r.work;
        if (labels) out.regions = r.reg.data();
        if (dt > 0) {
            out.trajectory.dt = dt;
            out.trajectory.max_points_per_orbit = max_points;
            out.trajectory.points = r.pts.data();
            out.trajectory.kinds = r.kinds.data();
            out.trajectory.truncated = r.trunc.data();
        }
        fm.iterate(x.data(), y.data(), n, opt, out);
        r.progress = progress.load();
        return r;
    };
    const R plain = run(false, 0), labelled = run(true, 0), dense = run(false, 0.05), cut = run(false, 0.05, 7);
    for (std::size_t i = 0; i < x.size(); ++i) {  // the same orbit whatever is recorded, bit for bit
        CHECK(std::memcmp(&plain.xf[i], &labelled.xf[i], sizeof(double)) == 0);
        CHECK(std::memcmp(&plain.yf[i], &dense.yf[i], sizeof(double)) == 0);
        CHECK(std::memcmp(&plain.yf[i], &cut.yf[i], sizeof(double)) == 0);
    }
    CHECK(plain.work.label_operations == 0);
    CHECK(labelled.work.label_operations >= 4 * ns);  // at least one label per return
    CHECK(plain.work.dense_samples == 0);
    CHECK(dense.work.dense_samples > 0);
    CHECK(cut.work.dense_samples < dense.work.dense_samples);
    CHECK(plain.work.steps == labelled.work.steps);
    CHECK(plain.work.field_evaluations == labelled.work.field_evaluations);
    CHECK(plain.work.coupling_evaluations == plain.work.field_evaluations);
    CHECK(plain.work.section_searches == 4 * ns);
    for (const R* r : {&plain, &labelled, &dense, &cut}) CHECK(r->progress == n * ns);  // the OffSection orbit credited
    std::int64_t samples = 0;
    for (std::size_t i = 0; i < 4; ++i) {
        const auto& p = dense.pts[i];
        const auto& k = dense.kinds[i];
        REQUIRE(p.size() == 5 * k.size());
        CHECK(dense.trunc[i] == 0);
        CHECK(cut.trunc[i] == 1);
        CHECK(cut.kinds[i].size() == 7);
        CHECK(std::memcmp(cut.pts[i].data(), p.data(), 35 * sizeof(double)) == 0);
        CHECK(std::count(k.begin(), k.end(), static_cast<std::int8_t>(TrajectoryPoint::Return)) == ns);
        std::int64_t next = 0;
        for (std::size_t j = 0; j < k.size(); ++j) {
            if (j > 0) CHECK(p[5 * j] >= p[5 * (j - 1)]);  // in time order
            if (k[j] != static_cast<std::int8_t>(TrajectoryPoint::Sample)) continue;
            CHECKF(p[5 * j] == double(next) * 0.05, "orbit %zu sample %lld", i, (long long)next);  // t = k dt exactly
            ++next;
            ++samples;
        }
        // the energy along the trajectory is h to the integrator's accuracy
        for (std::size_t j = 0; j < k.size(); ++j) CHECK(std::fabs(s.energy(&p[5 * j + 1]) - 1.0) < 2e-9);
    }
    CHECK(dense.pts[4].empty());  // no point of Sigma_h: nothing to record
    CHECK(samples == dense.work.dense_samples);
    FlowIterateOptions bad;
    bad.n_steps = 1;
    bad.labels = false;
    std::vector<std::int8_t> reg(x.size());
    FlowIterateOutput with_regions;
    with_regions.regions = reg.data();
    CHECK_INVALID(fm.iterate(x.data(), y.data(), n, bad, with_regions), "labels = false");
    FlowIterateOutput bad_dt;
    std::vector<std::vector<double>> pts(x.size());
    std::vector<std::vector<std::int8_t>> kinds(x.size());
    bad_dt.trajectory.points = pts.data();
    bad_dt.trajectory.kinds = kinds.data();
    bad_dt.trajectory.max_points_per_orbit = 10;
    CHECK_INVALID(fm.iterate(x.data(), y.data(), n, FlowIterateOptions{}, bad_dt),
                  "trajectory dt must be finite and > 0");
    // No walls: no wall search at all.
    const FlowMap smooth(issue_system(-0.05, Geometry::None), 1.0, o, nullptr);
    FlowWork w;
    FlowIterateOutput wo;
    wo.work = &w;
    FlowIterateOptions one;
    one.n_steps = 3;
    smooth.iterate(x.data(), y.data(), 4, one, wo);
    CHECK(w.wall_searches == 0);
    CHECK(w.label_operations == 0);  // labels on, but the smooth flow labels nothing
    CHECK(w.section_searches == 12);
}
