// HOV(eps) by its definition; see hovering_area.hpp. The floating-point expressions of the samples
// and the estimate are those hovering.hovering_area computed with NumPy before they moved here (in
// the same order), so no published number moved.
#include "hovering/analysis/hovering_area.hpp"

#include <algorithm>
#include <cmath>

#include "hovering/detail/common.hpp"
#include "hovering/detail/numpy_random.hpp"

namespace hovering {

using detail::bad;
using detail::fmt;
using detail::kPi;

SampleGrid sample_grid(std::int64_t samples, double K_low) {
    if (samples < 1) bad("samples must be >= 1, got " + std::to_string(samples));
    if (!(K_low < 0) || !std::isfinite(K_low)) bad("K_low must be a finite number < 0, got " + fmt(K_low));
    // Python's round() is round-half-even, as nearbyint in the default rounding mode.
    const double cols = std::nearbyint(std::sqrt(double(samples * 2) * kPi / -K_low));
    SampleGrid g;
    g.n_phi = std::int64_t(std::min(std::max(1.0, cols), double(samples)));
    g.n_K = std::max<std::int64_t>(1, std::int64_t(std::ceil(double(samples) / double(g.n_phi))));
    return g;
}

void stratified_samples(std::int64_t samples, double K_low, std::uint64_t seed, std::int64_t lo, std::int64_t hi,
                        double* phi, double* K) {
    const SampleGrid g = sample_grid(samples, K_low);
    const std::int64_t n = g.size();
    if (lo < 0 || hi < lo || hi > n)
        bad("the sample range [" + std::to_string(lo) + ", " + std::to_string(hi) + ") must lie in [0, " +
            std::to_string(n) + "]");
    const double dphi = 2 * kPi / double(g.n_phi), dK = -K_low / double(g.n_K);
    detail::NumpyRandom rng(seed);
    rng.advance(std::uint64_t(lo));
    for (std::int64_t i = lo; i < hi; ++i) phi[i - lo] = -kPi + (double(i / g.n_K) + rng.random()) * dphi;
    rng.advance(std::uint64_t(n - hi + lo));  // to output n + lo: the first K jitter of the range
    for (std::int64_t i = lo; i < hi; ++i) {
        const double k = K_low + (double(i % g.n_K) + rng.random()) * dK;
        K[i - lo] = std::min(k, -1e-300);  // the box is K < 0 (HOV lies in J_0)
    }
}

void stratified_samples(std::int64_t samples, double K_low, std::uint64_t seed, std::vector<double>& phi,
                        std::vector<double>& K) {
    const std::int64_t n = sample_grid(samples, K_low).size();
    phi.resize(std::size_t(n));
    K.resize(std::size_t(n));
    stratified_samples(samples, K_low, seed, 0, n, phi.data(), K.data());
}

namespace {

constexpr unsigned kNoImpact = (1u << int(Region::Beside)) | (1u << int(Region::Above));

/// F_0 then F_eps with early exit from {J_0u, J_0}; Options/Output are the map's batch types
/// (IterateOptions/Output or FlowIterateOptions/Output: the same fields).
template <class Options, class Output, class Map>
HoveringOutcomes run_both(const Map& m, const Map& m0, const double* phi, const double* K, std::int64_t n,
                          const HoveringAreaOptions& o) {
    if (o.n_steps < 0) bad("n_steps must be >= 0, got " + std::to_string(o.n_steps));
    if (n < 0) bad("the number of points must be >= 0, got " + std::to_string(n));
    HoveringOutcomes r;
    r.status_F0.resize(std::size_t(n));
    r.status.resize(std::size_t(n));
    r.visited.resize(std::size_t(n));
    r.steps_done.resize(std::size_t(n));
    Options io;
    io.n_steps = o.n_steps;
    io.exit_mask = kNoImpact;
    io.stop_on_exit = true;
    io.n_threads = o.n_threads;
    io.cancel = o.cancel;
    io.progress = o.progress;
    // Part 1 of the definition: the point impacts under F_0 (checked, not assumed).
    Output out0;
    out0.status = r.status_F0.data();
    m0.iterate(phi, K, n, io, out0);
    // Part 2: it never impacts under F_eps (for N/4, N/2, N steps: the steps done tell).
    Output out1;
    out1.status = r.status.data();
    out1.steps_done = r.steps_done.data();
    out1.visited = r.visited.data();
    m.iterate(phi, K, n, io, out1);
    r.interrupted = o.cancel && o.cancel->load();
    return r;
}

template <class Map>
HoveringOutcomes truncated_outcomes(const Map& m, const double* phi, const double* K, std::int64_t n,
                                    const HoveringAreaOptions& o) {
    // F_0: the same arcs and forcing at eps = 0 (hovering.TruncatedMap.with_eps(0)).
    const Map m0(0.0, m.arcs(), m.forcing(), m.band().hi);
    return run_both<IterateOptions, IterateOutput>(m, m0, phi, K, n, o);
}

void check(const HoveringAreaOptions& o, double band_lo) {
    if (o.n_steps < 4) bad("n_steps must be an integer in [4, 2^53], got " + std::to_string(o.n_steps));
    if (o.samples < 1) bad("samples must be an integer in [1, 2^53], got " + std::to_string(o.samples));
    if (!(band_lo < 0))
        bad("this map's band has no part below K = 0 (lower end " + fmt(band_lo) +
            "): no point impacts under F_0, nothing can hover");
    if (!(band_lo < o.K_low && o.K_low < 0))
        bad("K_low must lie in the band below 0, (" + fmt(band_lo) + ", 0), got " + fmt(o.K_low));
}

}  // namespace

HoveringOutcomes hovering_outcomes(const TruncatedMap& m, const double* phi, const double* K, std::int64_t n,
                                   const HoveringAreaOptions& o) {
    return truncated_outcomes(m, phi, K, n, o);
}

HoveringOutcomes hovering_outcomes(const TruncatedFamily& m, const double* phi, const double* K, std::int64_t n,
                                   const HoveringAreaOptions& o) {
    return truncated_outcomes(m, phi, K, n, o);
}

HoveringOutcomes hovering_outcomes(const FlowMap& m, const FlowMap& m0, const double* phi, const double* K,
                                   std::int64_t n, const HoveringAreaOptions& o) {
    return run_both<FlowIterateOptions, FlowIterateOutput>(m, m0, phi, K, n, o);
}

PartArea part_area(std::int64_t count, std::int64_t n, double K_low) {
    if (n < 1) bad("part_area needs at least one sample, got n = " + std::to_string(n));
    if (count < 0 || count > n)
        bad("part_area: count must lie in [0, n = " + std::to_string(n) + "], got " + std::to_string(count));
    if (!(K_low < 0) || !std::isfinite(K_low)) bad("K_low must be a finite number < 0, got " + fmt(K_low));
    const double box_area = 2 * kPi * (-K_low), dn = double(n), p = double(count) / dn;
    PartArea a;
    a.area = box_area * double(count) / dn;
    a.sampling_error = box_area * std::sqrt(std::max(p * (1 - p), 1.0 / dn) / dn);
    return a;
}

HoveringAreaResult hovering_estimate(const HoveringOutcomes& r, const double* K, std::int64_t n, std::int64_t n_steps,
                                     double K_low, bool keep_points) {
    if (n < 1) bad("hovering_estimate needs at least one sample, got " + std::to_string(n));
    const std::size_t un = std::size_t(n);
    if (r.status_F0.size() != un || r.status.size() != un || r.steps_done.size() != un || r.visited.size() != un)
        bad("hovering_estimate: the outcomes must have one entry per sample (" + std::to_string(n) + ")");
    HoveringAreaResult h;
    h.n_samples = n;
    h.K_low = K_low;
    h.interrupted = r.interrupted;
    const auto is = [](std::int8_t s, Status t) { return s == std::int8_t(t); };
    const std::int64_t Ns[3] = {n_steps / 4, n_steps / 2, n_steps};
    std::int64_t count[3] = {0, 0, 0}, hov = 0, hov_both = 0, impacts = 0, unresolved = 0;
    bool floor = false;
    if (keep_points) {
        h.hovering.assign(un, 0);
        h.both_sides.assign(un, 0);
    }
    for (std::size_t i = 0; i < un; ++i) {
        const std::int8_t s0 = r.status_F0[i], s1 = r.status[i];
        const bool impacts0 = is(s0, Status::Exited) || is(s0, Status::Corner) || is(s0, Status::Grazing);
        const bool stayed = is(s1, Status::Ok);
        impacts += impacts0;
        // Stopped at or after N steps for any reason (exit, escape, the flow's corner hits): survived N.
        for (int k = 0; k < 3; ++k) count[k] += impacts0 && (stayed || r.steps_done[i] >= Ns[k]);
        const bool hv = impacts0 && stayed;
        const bool both = hv && (unsigned(r.visited[i]) & kNoImpact) == kNoImpact;
        hov += hv;
        hov_both += both;
        floor = floor || (hv && K[i] < 0.9 * K_low);
        unresolved += !(stayed || is(s1, Status::Exited) || is(s1, Status::Escaped));
        if (keep_points) {
            h.hovering[i] = hv;
            h.both_sides[i] = both;
        }
    }
    const double dn = double(n);
    const double areas[3] = {part_area(count[0], n, K_low).area, part_area(count[1], n, K_low).area,
                             part_area(count[2], n, K_low).area};
    h.sampling_error = part_area(hov, n, K_low).sampling_error;
    h.iteration_error = areas[1] - areas[2];
    h.area = areas[2];
    h.area_half = areas[1];
    h.area_quarter = areas[0];
    h.error = 2 * h.sampling_error + h.iteration_error;
    h.impact_fraction_F0 = double(impacts) / dn;
    h.floor_touched = floor;
    h.area_both_sides = part_area(hov_both, n, K_low).area;
    h.unresolved = unresolved;
    return h;
}

namespace {

template <class Outcomes>
HoveringAreaResult whole(const HoveringAreaOptions& o, double band_lo, Outcomes&& outcomes) {
    check(o, band_lo);
    std::vector<double> phi, K;
    stratified_samples(o.samples, o.K_low, o.seed, phi, K);
    const std::int64_t n = std::int64_t(phi.size());
    return hovering_estimate(outcomes(phi.data(), K.data(), n), K.data(), n, o.n_steps, o.K_low, o.keep_points);
}

}  // namespace

HoveringAreaResult hovering_area(const TruncatedMap& m, const HoveringAreaOptions& o) {
    return whole(o, m.band().lo,
                 [&](const double* p, const double* k, std::int64_t n) { return hovering_outcomes(m, p, k, n, o); });
}

HoveringAreaResult hovering_area(const TruncatedFamily& m, const HoveringAreaOptions& o) {
    return whole(o, m.band().lo,
                 [&](const double* p, const double* k, std::int64_t n) { return hovering_outcomes(m, p, k, n, o); });
}

HoveringAreaResult hovering_area(const FlowMap& m, const FlowMap& m0, const HoveringAreaOptions& o) {
    if (!m.curve() || !m0.curve()) bad("hovering_area needs flow maps on normal coordinates (phi, K)");
    double lo = detail::kInf;
    for (double I : m.curve()->I()) lo = std::min(lo, I);
    return whole(
        o, -lo, [&](const double* p, const double* k, std::int64_t n) { return hovering_outcomes(m, m0, p, k, n, o); });
}

double first_order_shape(const std::vector<double>& b, double Omega0, double psi) {
    double g = 0.0;
    for (std::size_t k = 0; k < b.size(); ++k) {
        if (b[k] == 0) continue;
        const double m = double(k + 1);
        g = g + b[k] * (1 - std::cos(m * psi)) / (2 * std::sin(0.5 * m * Omega0));
    }
    return g;
}

double default_depth(double eps, double Omega0, const std::vector<double>& b) {
    // numpy.linspace(-pi, pi, 4001): i * step + start, the last point exactly pi.
    const double step = (kPi - -kPi) / 4000.0;
    double g = 0;
    for (int i = 0; i < 4001; ++i) {
        const double psi = i == 4000 ? kPi : double(i) * step + -kPi;
        const double a = std::abs(first_order_shape(b, Omega0, psi));
        g = std::isnan(a) || std::isnan(g) ? a + g : std::max(g, a);  // NaN propagates, as np.max
    }
    const double d = b.empty() ? detail::kNaN : 2.0 * std::abs(eps) * g;
    return std::isfinite(d) && d > 0 ? d : detail::kInf;
}

double box_floor(double band_lo) {
    return band_lo * (1 - 1e-9);
}

double default_K_low(double eps, double Omega0, const std::vector<double>& b, double band_lo) {
    const double depth = eps != 0 ? default_depth(eps, Omega0, b) : 0.1;
    return std::max(-depth, box_floor(band_lo));
}

}  // namespace hovering
