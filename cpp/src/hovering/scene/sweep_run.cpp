// Running sweep scenes without Python; see sweep_run.hpp. Each point is built as Python's
// scenes/compute.py builds it (_truncated_point, _flow_point): the same maps, the same default box
// and the same numpy sample stream, so a truncated point is Python's to the bit and a flow point
// differs only by the rounding of its measured forcing (a least-squares fit there, the equivalent
// discrete sine transform here), which moves the box by ulps and the estimate within its error bar.
#include "hovering/scene/sweep_run.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "hovering/analysis/hovering_area.hpp"
#include "hovering/analysis/theory.hpp"
#include "hovering/flow/potential.hpp"
#include "hovering/flow/system.hpp"
#include "hovering/normal/flow_map.hpp"
#include "hovering/normal/tangential_curve.hpp"
#include "hovering/truncated/map.hpp"

namespace hovering::scene {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Shortest text that reads back as exactly this double (the resume key compares these).
std::string num(double x) {
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, x);
    return std::string(buf, r.ptr);
}

bool has_model(const SweepScene& s, const char* name) {
    return std::find(s.models.begin(), s.models.end(), name) != s.models.end();
}

std::shared_ptr<const Potential> potential(const PotentialSpec& p) {
    if (p.kind == "tan") return std::make_shared<Tan>(p.omega, p.alpha);
    return std::make_shared<Harmonic>(p.omega);
}

/// The scene's system at eps (Python's SystemSpec.build: repeated (i, j) terms keep the first
/// place and the last coefficient, as the dict Polynomial({(i, j): c}) does).
FlowSystem build_system(const SystemSpec& sp, double eps) {
    FlowSystem s;
    s.V1 = potential(sp.V1);
    s.V2 = potential(sp.V2);
    for (const auto& t : sp.coupling) {
        auto it = std::find_if(s.coupling.terms.begin(), s.coupling.terms.end(),
                               [&](const std::array<double, 3>& u) { return u[1] == t[1] && u[2] == t[2]; });
        if (it != s.coupling.terms.end())
            (*it)[0] = t[0];
        else
            s.coupling.terms.push_back(t);
    }
    s.eps = eps;
    s.qw1 = sp.qw1;
    s.qw2 = sp.qw2;
    s.geometry = sp.geometry == "step" ? Geometry::Step : sp.geometry == "wall" ? Geometry::Wall : Geometry::None;
    s.validate();
    return s;
}

/// Python's TangentialCurve(Section(sys, h), rtol=1e-13): 64 wall points, doubled up to 1024 until
/// the measured interpolation error in I is below 1e-12.
std::shared_ptr<const TangentialCurve> measure_curve(const FlowSystem& s, double h) {
    FlowOptions o;
    o.rtol = 1e-13;
    o.atol = 1e-13 * 1e-2;
    int n = 64;
    auto c = TangentialCurve::measure(s, h, n, o, 4);
    while (n < 1024 && !(c.interpolation_error().second < 1e-12)) {
        n *= 2;
        c = TangentialCurve::measure(s, h, n, o, 4);
    }
    if (!c.is_graph()) throw std::invalid_argument(c.not_graph_reason());
    return std::make_shared<const TangentialCurve>(std::move(c));
}

/// A flow scene's map at one eps, as Python's FlowMap(sys, h, **integrator): its curve, onset
/// parameters (none when they cannot be computed accurately) and the flow map on (phi, K).
struct Flow {
    FlowSystem sys;
    std::shared_ptr<const TangentialCurve> curve;
    bool has_onset = false;
    OnsetParameters onset{};
    std::string onset_error;
    std::unique_ptr<FlowMap> map;
};

Flow build_flow(const SweepScene& sc, double eps) {
    Flow f;
    f.sys = build_system(sc.system, eps);
    FlowOptions opt;
    opt.stepper = sc.integrator.stepper;
    opt.rtol = sc.integrator.rtol;
    opt.atol = sc.integrator.atol;
    try {
        f.onset = onset_estimate(*f.sys.V1, *f.sys.V2, f.sys.qw1, f.sys.qw2, sc.h, 1e-6).value;
        f.has_onset = true;
    } catch (const std::invalid_argument& e) {
        f.onset_error = e.what();
    }
    f.curve = measure_curve(f.sys, sc.h);
    std::shared_ptr<const AnalyticArcs> lift;
    if (f.has_onset)
        lift = std::make_shared<const AnalyticArcs>(
            AnalyticArcs{f.onset.Omega0, f.onset.theta_w, f.onset.tau0, f.onset.tau1, f.onset.lam});
    f.map = std::make_unique<FlowMap>(f.sys, sc.h, opt, f.curve, lift);
    return f;
}

/// Sine coefficients b_1..b_8 of the measured forcing f (eq:defoff) from 256 midpoint angles: the
/// discrete sine transform, which is the least-squares fit Python computes (the modes are
/// orthogonal on that grid).
std::vector<double> forcing_of(const TangentialCurve& c, double eps) {
    constexpr int n_modes = 8, n_phi = 256;
    std::vector<double> f(n_phi), b(n_modes, 0.0);
    for (int j = 0; j < n_phi; ++j) {
        const double ph = -kPi + 2 * kPi * (double(j) + 0.5) / n_phi;
        f[std::size_t(j)] = (c.I_tan(-ph) - c.I_tan(ph)) / eps;
        for (int k = 0; k < n_modes; ++k) b[std::size_t(k)] += f[std::size_t(j)] * std::sin(double(k + 1) * ph);
    }
    for (auto& x : b) x *= 2.0 / n_phi;
    return b;
}

/// Python's FlowMap.forcing_coefficients(): at eps = 0 the eps -> 0 limit, measured at eps = 1e-6.
std::vector<double> flow_forcing(const SweepScene& sc, const Flow& f, double eps) {
    if (eps != 0) return forcing_of(*f.curve, eps);
    if (f.sys.coupling.terms.empty()) return std::vector<double>(8, 0.0);
    return forcing_of(*measure_curve(build_system(sc.system, 1e-6), sc.h), 1e-6);
}

/// numpy.linspace(a, b, n).
std::vector<double> linspace(double a, double b, int n) {
    std::vector<double> y(static_cast<std::size_t>(n));
    const double step = (b - a) / double(n - 1);
    for (int i = 0; i < n; ++i) y[std::size_t(i)] = double(i) * step + a;
    y.back() = b;
    return y;
}

/// Python's FlowMap.truncated(): the onset model with the measured forcing (a TruncatedFamily on
/// the onset parameters' arcs tabulated on 121 + 40 heights).
TruncatedFamily onset_family(const Flow& f, double eps, const std::vector<double>& b) {
    const OnsetParameters& p = f.onset;
    const TruncatedMap m = make_truncated_map(eps * b[0], p.Omega0, p.theta_w, p.tau0, p.tau1, p.lam);
    const double depth = std::min(0.95 * -m.band().lo, 1.0);
    std::vector<double> K;
    for (double s : linspace(std::sqrt(depth), 0.0, 121)) K.push_back(-(s * s));
    for (double k : linspace(depth / 60, depth, 40)) K.push_back(k);
    std::vector<double> Om(K.size()), JR(K.size()), J1(K.size());
    for (std::size_t i = 0; i < K.size(); ++i) {
        const double neg = std::min(K[i], 0.0);
        Om[i] = p.Omega0 + p.tau0 * K[i];
        JR[i] = K[i] <= 0 ? 2 * (kPi - p.theta_w) + p.tau1 * neg : 0.0;
        J1[i] = 2 * p.lam * std::sqrt(-neg);
    }
    return TruncatedFamily(eps, TabulatedArcs(K, Om, JR, J1), FourierForcing{b},
                           std::numeric_limits<double>::infinity());
}

double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

void add_area(SweepRow& row, const char* prefix, const HoveringAreaResult& h) {
    const std::string p(prefix);
    row.values.emplace_back(p + "area", h.area);
    row.values.emplace_back(p + "error", h.error);
    row.values.emplace_back(p + "sampling_error", h.sampling_error);
    row.values.emplace_back(p + "iteration_error", h.iteration_error);
    row.values.emplace_back(p + "area_N4", h.area_quarter);
    row.values.emplace_back(p + "area_N2", h.area_half);
    row.values.emplace_back(p + "area_both_sides", h.area_both_sides);
    row.values.emplace_back(p + "impact_fraction_F0", h.impact_fraction_F0);
    row.values.emplace_back(p + "floor_touched", h.floor_touched ? 1.0 : 0.0);
    row.values.emplace_back(p + "unresolved", double(h.unresolved));
    row.values.emplace_back(p + "n_samples", double(h.n_samples));
    row.values.emplace_back(p + "K_low", h.K_low);
}

/// hovering_area's options of a point (its box is set by the caller).
HoveringAreaOptions area_options(const SweepScene& sc, const SweepCounts& c, int n_threads,
                                 const std::atomic<bool>* cancel, std::atomic<std::int64_t>* progress) {
    HoveringAreaOptions o;
    o.n_steps = c.n_steps;
    o.samples = c.samples;
    o.seed = sc.seed;
    o.n_threads = n_threads;
    o.cancel = cancel;
    o.progress = progress;
    return o;
}

SweepRow truncated_point(const SweepScene& sc, const SweepPoint& pt, const SweepCounts& c, int n_threads,
                         const std::atomic<bool>* cancel, std::atomic<std::int64_t>* progress) {
    const auto t0 = std::chrono::steady_clock::now();
    const Series& s = sc.series[pt.series];
    const MapParams mp = s.at(pt.eps);
    const TruncatedMap m = make_truncated_map(pt.eps, mp.Omega0, mp.theta_w, mp.tau0, mp.tau1, mp.lam);
    const std::vector<double> sine{1.0};
    HoveringAreaOptions o = area_options(sc, c, n_threads, cancel, progress);
    if (s.has_K_low) {
        o.K_low = s.K_low;
    } else {  // Python's default box: the critical band of eq:hovsetsize, cut to the map's band
        const double depth = pt.eps != 0 ? default_depth(pt.eps, mp.Omega0, sine) : 0.1;
        o.K_low = std::max(-depth, m.band().lo * (1 - 1e-9));
    }
    const HoveringAreaResult h = hovering_area(m, o);
    SweepRow row;
    row.interrupted = h.interrupted;
    add_area(row, "", h);
    row.values.emplace_back("theory", hovering_area_theory(pt.eps, mp.Omega0, mp.theta_w, sine));
    row.values.emplace_back("seconds", seconds_since(t0));
    return row;
}

SweepRow flow_point(const SweepScene& sc, const SweepPoint& pt, const SweepCounts& c, int n_threads,
                    const std::atomic<bool>* cancel, std::atomic<std::int64_t>* progress) {
    check_runnable(sc);
    const auto t0 = std::chrono::steady_clock::now();
    const double e = pt.eps;
    const Flow f = build_flow(sc, e);
    const Flow f0 = build_flow(sc, 0.0);
    if (!f.has_onset)
        throw std::invalid_argument("no onset parameters at h = " + num(sc.h) + ": " + f.onset_error);
    const std::vector<double> b = flow_forcing(sc, f, e);
    std::vector<double> bth = b;
    if (std::all_of(b.begin(), b.end(), [](double x) { return x == 0; })) bth = {1.0};
    double band_lo = std::numeric_limits<double>::infinity();
    for (double I : f.curve->I()) band_lo = std::min(band_lo, I);
    band_lo = -band_lo;
    // One box for flow and onset model (Python's _flow_point): the default depth, cut to the band
    // every model is defined on.
    const double depth = e != 0 ? default_depth(e, f.onset.Omega0, bth) : 0.1;
    double K_low = std::max(-depth, band_lo * (1 - 1e-9));
    const bool onset = has_model(sc, "onset");
    std::unique_ptr<TruncatedFamily> fam;
    if (onset) {
        fam = std::make_unique<TruncatedFamily>(onset_family(f, e, b));
        K_low = std::max(K_low, fam->band().lo * (1 - 1e-9));
    }
    HoveringAreaOptions o = area_options(sc, c, n_threads, cancel, progress);
    o.K_low = K_low;
    o.keep_points = onset;
    const HoveringAreaResult h = hovering_area(*f.map, *f0.map, o);
    SweepRow row;
    row.interrupted = h.interrupted;
    add_area(row, "", h);
    row.values.emplace_back("theory", hovering_area_theory(e, f.onset.Omega0, f.onset.theta_w, bth));
    row.values.emplace_back("b1", bth[0]);
    double m_area = kNaN, m_err = kNaN, m_agree = kNaN, m_K = kNaN;
    if (onset && !h.interrupted) {
        HoveringAreaOptions om = o;
        om.K_low = std::max(K_low, fam->band().lo * (1 - 1e-9));
        const HoveringAreaResult mh = hovering_area(*fam, om);
        row.interrupted = mh.interrupted;
        m_area = mh.area;
        m_err = mh.error;
        m_K = om.K_low;
        if (om.K_low == K_low) {
            std::int64_t same = 0;
            for (std::size_t i = 0; i < mh.hovering.size(); ++i) same += mh.hovering[i] == h.hovering[i];
            m_agree = double(same) / double(mh.hovering.size());
        }
    }
    row.values.emplace_back("onset_area", m_area);
    row.values.emplace_back("onset_error", m_err);
    row.values.emplace_back("onset_agree", m_agree);
    row.values.emplace_back("onset_K_low", m_K);
    row.values.emplace_back("seconds", seconds_since(t0));
    return row;
}

}  // namespace

void check_runnable(const SweepScene& s) {
    if (s.kind == "flow_hovering_area" && s.integrator.accuracy == s.integrator.accuracy)
        throw std::invalid_argument(
            (s.path.empty() ? s.name : s.path) + ": [integrator] accuracy = " + num(s.integrator.accuracy) +
            ": hovering_sweep integrates with the stepper and tolerances given; an accuracy target is turned into "
            "them by the Python package's work-precision measurement (python -m hovering accuracy SCENE prints "
            "the setting it picks): give stepper and rtol instead");
}

SweepCounts sweep_counts(const SweepScene& s, bool quick) {
    if (!quick) return {s.n_steps, s.samples};
    const bool flow = s.kind == "flow_hovering_area";
    const std::int64_t floor = flow ? 50 : 100, min_samples = flow ? 100 : 400;
    return {std::max(s.n_steps / kQuickFactor, std::min(floor, s.n_steps)), std::max(s.samples / kQuickFactor, min_samples)};
}

std::vector<SweepPoint> sweep_points(const SweepScene& s) {
    std::vector<SweepPoint> out;
    const std::size_t n_series = s.kind == "hovering_area" ? s.series.size() : 1;
    for (std::size_t k = 0; k < n_series; ++k)
        for (double e : s.eps) out.push_back({k, e});
    return out;
}

std::vector<std::string> result_columns(const SweepScene& s) {
    SweepRow r;
    add_area(r, "", HoveringAreaResult{});
    std::vector<std::string> cols;
    for (const auto& v : r.values) cols.push_back(v.first);
    cols.push_back("theory");
    if (s.kind == "flow_hovering_area")
        for (const char* c : {"b1", "onset_area", "onset_error", "onset_agree", "onset_K_low"}) cols.push_back(c);
    cols.push_back("seconds");
    return cols;
}

std::vector<std::pair<std::string, std::string>> point_parameters(const SweepScene& s, const SweepPoint& p,
                                                                  const SweepCounts& c) {
    std::vector<std::pair<std::string, std::string>> out;
    out.emplace_back("eps", num(p.eps));
    if (s.kind == "hovering_area") {
        const Series& se = s.series[p.series];
        const MapParams m = se.at(p.eps);
        out.emplace_back("series", std::to_string(p.series));
        out.emplace_back("Omega0", num(m.Omega0));
        out.emplace_back("theta_w", num(m.theta_w));
        out.emplace_back("tau0", num(m.tau0));
        out.emplace_back("tau1", num(m.tau1));
        out.emplace_back("lam", num(m.lam));
        out.emplace_back("K_low_asked", se.has_K_low ? num(se.K_low) : "default");
    } else {
        const SystemSpec& y = s.system;
        const auto pot = [](const PotentialSpec& v) {
            return v.kind + ":" + num(v.omega) + (v.kind == "tan" ? ":" + num(v.alpha) : "");
        };
        out.emplace_back("V1", pot(y.V1));
        out.emplace_back("V2", pot(y.V2));
        std::string cp;
        for (const auto& t : y.coupling) cp += (cp.empty() ? "" : ";") + num(t[0]) + ":" + num(t[1]) + ":" + num(t[2]);
        out.emplace_back("coupling", cp.empty() ? "none" : cp);
        out.emplace_back("qw1", num(y.qw1));
        out.emplace_back("qw2", num(y.qw2));
        out.emplace_back("geometry", y.geometry);
        out.emplace_back("h", num(s.h));
        out.emplace_back("stepper", s.integrator.stepper);
        out.emplace_back("rtol", num(s.integrator.rtol));
        out.emplace_back("atol", num(s.integrator.atol));
        // The onset model's band can cut the box, so whether it is computed changes the flow's numbers.
        out.emplace_back("onset_model", has_model(s, "onset") ? "1" : "0");
    }
    out.emplace_back("n_steps", std::to_string(c.n_steps));
    out.emplace_back("samples", std::to_string(c.samples));
    out.emplace_back("seed", std::to_string(s.seed));
    return out;
}

SweepRow run_point(const SweepScene& s, const SweepPoint& p, const SweepCounts& c, int n_threads,
                   const std::atomic<bool>* cancel, std::atomic<std::int64_t>* progress) {
    if (s.kind == "hovering_area") return truncated_point(s, p, c, n_threads, cancel, progress);
    if (s.kind == "flow_hovering_area") return flow_point(s, p, c, n_threads, cancel, progress);
    throw std::invalid_argument("run_point: kind '" + s.kind + "' is not a sweep kind");
}

}  // namespace hovering::scene
