#pragma once
// The hovering set HOV(eps) by its definition (sec:truncinvcurves), measured on any map of the
// core: points that impact under F_0 and never impact under F_eps within N iterates. The C++ twin of
// python/hovering/analysis/hovering_area: the same stratified samples to the bit (numpy's
// default_rng(seed) stream is reproduced), the same early exit from {J_0u, J_0}, the same
// estimates at N/4, N/2, N and the same error bar (2 sampling sigma + the change over the last
// doubling of N). On the truncated maps the result is Python's bit for bit.

#include <atomic>
#include <cstdint>
#include <vector>

#include "hovering/normal/flow_map.hpp"
#include "hovering/truncated/map.hpp"

namespace hovering {

/// Unsigned 128-bit integers (a GCC/Clang extension; PCG64's state).
__extension__ typedef unsigned __int128 uint128;

/// numpy.random.default_rng(seed).random(): PCG64 seeded through SeedSequence, 53-bit doubles.
class NumpyRandom {
public:
    /// The generator numpy.random.default_rng(seed) starts as (seed >= 0).
    explicit NumpyRandom(std::uint64_t seed);
    /// The next raw 64-bit output (PCG64 XSL-RR).
    std::uint64_t next_u64();
    /// The next double in [0, 1), as Generator.random().
    double random() { return double(next_u64() >> 11) * (1.0 / 9007199254740992.0); }

private:
    uint128 state_ = 0, inc_ = 0;
};

/// One uniform point per cell of a near-square grid over [-pi, pi) x [K_low, 0) (as Python's
/// _stratified: n_phi = round(sqrt(samples 2 pi / -K_low)) columns, ceil(samples / n_phi) rows).
void stratified_samples(std::int64_t samples, double K_low, std::uint64_t seed, std::vector<double>& phi,
                        std::vector<double>& K);

/// Counts and cancellation of a hovering_area measurement.
struct HoveringAreaOptions {
    std::int64_t n_steps = 10000;  ///< N: iterates that count as "never" (>= 4)
    std::int64_t samples = 100000; ///< sample points asked for (the grid rounds up)
    double K_low = -0.1;           ///< bottom of the box (inside the band, < 0)
    std::uint64_t seed = 0;        ///< seed of the jitter (numpy's default_rng(seed))
    int n_threads = 0;             ///< worker threads, 0 = all cores
    const std::atomic<bool>* cancel = nullptr;      ///< set to stop early (then interrupted)
    std::atomic<std::int64_t>* progress = nullptr;  ///< steps / returns done, 2 N n in all
    bool keep_points = false;      ///< keep each sample's membership (HoveringAreaResult::hovering)
};

/// The measured area; the fields of Python's HoveringArea that do not need the theory.
struct HoveringAreaResult {
    double area = 0;              ///< estimate at N
    double error = 0;             ///< 2 sampling_error + iteration_error
    double sampling_error = 0;    ///< one binomial sigma
    double iteration_error = 0;   ///< estimate at N/2 minus estimate at N
    double area_quarter = 0, area_half = 0;  ///< estimates at N/4 and N/2
    std::int64_t n_samples = 0;   ///< points sampled
    double K_low = 0;             ///< bottom of the box
    double impact_fraction_F0 = 0;///< fraction of the box impacting under F_0 within N
    bool floor_touched = false;   ///< a hovering point in the lowest tenth of the box
    double area_both_sides = 0;   ///< part whose orbits visit both J_0 and J_0u
    std::int64_t unresolved = 0;  ///< orbits of F_eps ending otherwise (corner, grazing, limits)
    bool interrupted = false;     ///< cancelled: the numbers are not a result
    std::vector<std::int8_t> hovering;  ///< per sample (keep_points): 1 if it hovers
};

/// HOV of the truncated map m (F_0 = m at eps = 0).
HoveringAreaResult hovering_area(const TruncatedMap& m, const HoveringAreaOptions& opt);
/// HOV of the truncated family m (F_0 = the same arcs at eps = 0).
HoveringAreaResult hovering_area(const TruncatedFamily& m, const HoveringAreaOptions& opt);
/// HOV of the flow map m with F_0 = m0, the eps = 0 flow on its own normal coordinates.
HoveringAreaResult hovering_area(const FlowMap& m, const FlowMap& m0, const HoveringAreaOptions& opt);

}  // namespace hovering
