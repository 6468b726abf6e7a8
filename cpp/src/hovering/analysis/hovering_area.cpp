// HOV(eps) by its definition; see hovering_area.hpp. Every floating-point expression below is
// Python's (python/hovering/analysis/hovering.py) in the same order, so that with the same numpy
// random stream the samples, and on the truncated maps the whole result, are the same doubles.
#include "hovering/analysis/hovering_area.hpp"

#include <algorithm>
#include <cmath>

#include "hovering/detail/common.hpp"

namespace hovering {

using detail::bad;
using detail::fmt;
using detail::kPi;

namespace {

// numpy's SeedSequence (bit_generator.pyx): entropy words hashed into a pool of 4, then drawn out.
constexpr std::uint32_t kInitA = 0x43b0d7e5, kMultA = 0x931e8875, kInitB = 0x8b51f9dd, kMultB = 0x58f38ded;
constexpr std::uint32_t kMixL = 0xca01f9dd, kMixR = 0x4973f715;

std::uint32_t hashmix(std::uint32_t v, std::uint32_t& hc) {
    v ^= hc;
    hc *= kMultA;
    v *= hc;
    return v ^ (v >> 16);
}

std::uint32_t mix(std::uint32_t x, std::uint32_t y) {
    std::uint32_t r = kMixL * x - kMixR * y;
    return r ^ (r >> 16);
}

/// SeedSequence(seed).generate_state(4, uint64).
void seed_state(std::uint64_t seed, std::uint64_t out[4]) {
    std::vector<std::uint32_t> entropy;
    do {
        entropy.push_back(std::uint32_t(seed & 0xffffffffu));
        seed >>= 32;
    } while (seed != 0);
    std::uint32_t pool[4], hc = kInitA;
    for (std::size_t i = 0; i < 4; ++i) pool[i] = hashmix(i < entropy.size() ? entropy[i] : 0u, hc);
    for (int s = 0; s < 4; ++s)
        for (int d = 0; d < 4; ++d)
            if (s != d) pool[d] = mix(pool[d], hashmix(pool[s], hc));
    for (std::size_t s = 4; s < entropy.size(); ++s)
        for (int d = 0; d < 4; ++d) pool[d] = mix(pool[d], hashmix(entropy[s], hc));
    std::uint32_t words[8], hb = kInitB;
    for (int i = 0; i < 8; ++i) {
        std::uint32_t v = pool[i % 4] ^ hb;
        hb *= kMultB;
        v *= hb;
        words[i] = v ^ (v >> 16);
    }
    for (int k = 0; k < 4; ++k) out[k] = std::uint64_t(words[2 * k]) | (std::uint64_t(words[2 * k + 1]) << 32);
}

constexpr uint128 kPcgMult =
    (static_cast<uint128>(2549297995355413924ULL) << 64) + 4865540595714422341ULL;

}  // namespace

NumpyRandom::NumpyRandom(std::uint64_t seed) {
    std::uint64_t s[4];
    seed_state(seed, s);
    const uint128 initstate = (static_cast<uint128>(s[0]) << 64) | s[1];
    const uint128 initseq = (static_cast<uint128>(s[2]) << 64) | s[3];
    inc_ = (initseq << 1) | 1u;
    state_ = inc_;  // 0 * mult + inc: the first step of pcg_setseq_128_srandom_r
    state_ += initstate;
    state_ = state_ * kPcgMult + inc_;
}

std::uint64_t NumpyRandom::next_u64() {
    state_ = state_ * kPcgMult + inc_;
    const std::uint64_t x = std::uint64_t(state_ >> 64) ^ std::uint64_t(state_);
    const unsigned r = unsigned(state_ >> 122);
    return (x >> r) | (x << ((64 - r) & 63));
}

void stratified_samples(std::int64_t samples, double K_low, std::uint64_t seed, std::vector<double>& phi,
                        std::vector<double>& K) {
    if (samples < 1) bad("samples must be >= 1, got " + std::to_string(samples));
    if (!(K_low < 0) || !std::isfinite(K_low)) bad("K_low must be a finite number < 0, got " + fmt(K_low));
    const double H = -K_low;
    // Python's round() is round-half-even, as nearbyint in the default rounding mode.
    const double cols = std::nearbyint(std::sqrt(double(samples * 2) * kPi / H));
    const std::int64_t n_phi = std::int64_t(std::min(std::max(1.0, cols), double(samples)));
    const std::int64_t n_K = std::max<std::int64_t>(1, std::int64_t(std::ceil(double(samples) / double(n_phi))));
    const std::int64_t n = n_phi * n_K;
    phi.resize(std::size_t(n));
    K.resize(std::size_t(n));
    NumpyRandom rng(seed);
    const double dphi = 2 * kPi / double(n_phi), dK = H / double(n_K);
    // Row-major (i over phi, j over K) as numpy's meshgrid(..., indexing="ij").ravel(); all phi
    // jitters are drawn before all K jitters.
    for (std::int64_t i = 0; i < n_phi; ++i)
        for (std::int64_t j = 0; j < n_K; ++j) phi[std::size_t(i * n_K + j)] = -kPi + (double(i) + rng.random()) * dphi;
    for (std::int64_t i = 0; i < n_phi; ++i)
        for (std::int64_t j = 0; j < n_K; ++j) {
            const double k = K_low + (double(j) + rng.random()) * dK;
            K[std::size_t(i * n_K + j)] = std::min(k, -1e-300);  // the box is K < 0 (HOV lies in J_0)
        }
}

namespace {

constexpr unsigned kNoImpact = (1u << int(Region::Beside)) | (1u << int(Region::Above));

/// Per-sample outcomes of the two iterations (F_0, then F_eps).
struct Outcomes {
    std::vector<std::int8_t> s0, s1, visited;
    std::vector<std::int64_t> steps_done;
    bool interrupted = false;
};

/// F_0 then F_eps with early exit from {J_0u, J_0}; Options/Output are the map's batch types
/// (IterateOptions/Output or FlowIterateOptions/Output: the same fields).
template <class Options, class Output, class Map>
Outcomes run_both(const Map& m, const Map& m0, const std::vector<double>& phi, const std::vector<double>& K,
                  const HoveringAreaOptions& o) {
    const std::int64_t n = std::int64_t(phi.size());
    Outcomes r;
    r.s0.resize(phi.size());
    r.s1.resize(phi.size());
    r.visited.resize(phi.size());
    r.steps_done.resize(phi.size());
    Options io;
    io.n_steps = o.n_steps;
    io.exit_mask = kNoImpact;
    io.stop_on_exit = true;
    io.n_threads = o.n_threads;
    io.cancel = o.cancel;
    io.progress = o.progress;
    Output out0;
    out0.status = r.s0.data();
    m0.iterate(phi.data(), K.data(), n, io, out0);
    Output out1;
    out1.status = r.s1.data();
    out1.steps_done = r.steps_done.data();
    out1.visited = r.visited.data();
    m.iterate(phi.data(), K.data(), n, io, out1);
    r.interrupted = o.cancel && o.cancel->load();
    return r;
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

/// The estimates of Python's hovering_area from the per-sample outcomes.
HoveringAreaResult summarise(const Outcomes& r, const std::vector<double>& K, const HoveringAreaOptions& o) {
    HoveringAreaResult h;
    const std::int64_t n = std::int64_t(K.size());
    h.n_samples = n;
    h.K_low = o.K_low;
    h.interrupted = r.interrupted;
    const auto is = [](std::int8_t s, Status t) { return s == std::int8_t(t); };
    const double box_area = 2 * kPi * (-o.K_low);
    const std::int64_t Ns[3] = {o.n_steps / 4, o.n_steps / 2, o.n_steps};
    std::int64_t count[3] = {0, 0, 0}, hov = 0, hov_both = 0, impacts = 0, unresolved = 0;
    bool floor = false;
    if (o.keep_points) h.hovering.assign(K.size(), 0);
    for (std::size_t i = 0; i < K.size(); ++i) {
        const std::int8_t s0 = r.s0[i], s1 = r.s1[i];
        const bool impacts0 = is(s0, Status::Exited) || is(s0, Status::Corner) || is(s0, Status::Grazing);
        const bool stayed = is(s1, Status::Ok);
        impacts += impacts0;
        for (int k = 0; k < 3; ++k) count[k] += impacts0 && (stayed || r.steps_done[i] >= Ns[k]);
        const bool hv = impacts0 && stayed;
        hov += hv;
        hov_both += hv && (unsigned(r.visited[i]) & kNoImpact) == kNoImpact;
        floor = floor || (hv && K[i] < 0.9 * o.K_low);
        unresolved += !(stayed || is(s1, Status::Exited) || is(s1, Status::Escaped));
        if (o.keep_points) h.hovering[i] = hv;
    }
    const double areas[3] = {box_area * double(count[0]) / double(n), box_area * double(count[1]) / double(n),
                             box_area * double(count[2]) / double(n)};
    const double p = double(hov) / double(n);
    h.sampling_error = box_area * std::sqrt(std::max(p * (1 - p), 1.0 / double(n)) / double(n));
    h.iteration_error = areas[1] - areas[2];
    h.area = areas[2];
    h.area_half = areas[1];
    h.area_quarter = areas[0];
    h.error = 2 * h.sampling_error + h.iteration_error;
    h.impact_fraction_F0 = double(impacts) / double(n);
    h.floor_touched = floor;
    h.area_both_sides = box_area * double(hov_both) / double(n);
    h.unresolved = unresolved;
    return h;
}

template <class Map>
HoveringAreaResult truncated_area(const Map& m, const HoveringAreaOptions& o) {
    check(o, m.band().lo);
    const Map m0(0.0, m.arcs(), m.forcing(), m.band().hi);  // Python's with_eps(0): K_max = the band's top
    std::vector<double> phi, K;
    stratified_samples(o.samples, o.K_low, o.seed, phi, K);
    return summarise(run_both<IterateOptions, IterateOutput>(m, m0, phi, K, o), K, o);
}

}  // namespace

HoveringAreaResult hovering_area(const TruncatedMap& m, const HoveringAreaOptions& o) { return truncated_area(m, o); }

HoveringAreaResult hovering_area(const TruncatedFamily& m, const HoveringAreaOptions& o) { return truncated_area(m, o); }

HoveringAreaResult hovering_area(const FlowMap& m, const FlowMap& m0, const HoveringAreaOptions& o) {
    if (!m.curve() || !m0.curve()) bad("hovering_area needs flow maps on normal coordinates (phi, K)");
    double lo = detail::kInf;
    for (double I : m.curve()->I()) lo = std::min(lo, I);
    check(o, -lo);
    std::vector<double> phi, K;
    stratified_samples(o.samples, o.K_low, o.seed, phi, K);
    return summarise(run_both<FlowIterateOptions, FlowIterateOutput>(m, m0, phi, K, o), K, o);
}

}  // namespace hovering
