#pragma once
// The hovering set HOV(eps) by its definition (sec:truncinvcurves), measured on any map of the
// core: points that impact under F_0 and never impact under F_eps within N iterates. The one
// implementation of its numerics: the stratified samples (numpy's default_rng(seed) stream, so the
// points are the doubles numpy draws), the per-sample outcomes (F_0, then F_eps, each with early
// exit from {J_0u, J_0}), the estimates at N/4, N/2, N with their error bar, and the default box.
// Python's hovering.hovering_area and the sweep executable both call these.
//
// Pieces: the samples of an index range [lo, hi) are drawn on their own (the stream is jumped
// ahead, not replayed), their outcomes computed anywhere, and the outcomes of all pieces,
// concatenated in index order, give hovering_estimate the single-process answer bit for bit (the
// estimate only counts).

#include <atomic>
#include <cstdint>
#include <vector>

#include "hovering/normal/flow_map.hpp"
#include "hovering/truncated/map.hpp"

namespace hovering {

/// The near-square grid of the box [-pi, pi) x [K_low, 0): n_phi columns, n_K rows, one sample per cell.
struct SampleGrid {
    std::int64_t n_phi = 0;  ///< round(sqrt(samples 2 pi / -K_low)) clipped to [1, samples]
    std::int64_t n_K = 0;    ///< ceil(samples / n_phi)
    /// Number of samples (cells), at most samples + n_phi.
    std::int64_t size() const { return n_phi * n_K; }
};

/// The grid for `samples` points asked for (>= 1) over the box of bottom K_low (finite, < 0).
SampleGrid sample_grid(std::int64_t samples, double K_low);

/// Samples lo..hi-1 (0 <= lo <= hi <= grid size) of the box: sample i lies in column i / n_K, row
/// i % n_K, jittered by numpy's default_rng(seed).random(): the phi jitters are its outputs 0..n-1,
/// the K jitters n..2n-1 (n the grid size). K is capped at -1e-300 (the box is K < 0).
void stratified_samples(std::int64_t samples, double K_low, std::uint64_t seed, std::int64_t lo, std::int64_t hi,
                        double* phi, double* K);

/// All samples of the box (lo = 0, hi = grid size).
void stratified_samples(std::int64_t samples, double K_low, std::uint64_t seed, std::vector<double>& phi,
                        std::vector<double>& K);

/// Counts and cancellation of a hovering_area measurement.
struct HoveringAreaOptions {
    std::int64_t n_steps = 10000;                   ///< N: iterates that count as "never" (>= 4)
    std::int64_t samples = 100000;                  ///< sample points asked for (the grid rounds up)
    double K_low = -0.1;                            ///< bottom of the box (inside the band, < 0)
    std::uint64_t seed = 0;                         ///< seed of the jitter (numpy's default_rng(seed))
    int n_threads = 0;                              ///< worker threads, 0 = all cores
    const std::atomic<bool>* cancel = nullptr;      ///< set to stop early (then interrupted)
    std::atomic<std::int64_t>* progress = nullptr;  ///< steps / returns done, 2 N n in all
    bool keep_points = false;                       ///< keep each sample's membership (HoveringAreaResult::hovering)
};

/// Per-sample outcomes of the two iterations: the Status under F_0 and under F_eps, the steps
/// F_eps took before it stopped, and the regions its orbit visited (bit r: Region r).
struct HoveringOutcomes {
    std::vector<std::int8_t> status_F0, status;  ///< per sample: its Status under F_0, under F_eps
    std::vector<std::int64_t> steps_done;        ///< per sample: steps F_eps took before it stopped
    std::vector<std::int8_t> visited;            ///< per sample: bit r set when its orbit reached Region r
    bool interrupted = false;                    ///< cancelled: the outcomes are not a result
};

/// The measured area; the fields of Python's HoveringArea that do not need the theory.
struct HoveringAreaResult {
    double area = 0;                         ///< estimate at N
    double error = 0;                        ///< 2 sampling_error + iteration_error
    double sampling_error = 0;               ///< one binomial sigma
    double iteration_error = 0;              ///< estimate at N/2 minus estimate at N
    double area_quarter = 0, area_half = 0;  ///< estimates at N/4 and N/2
    std::int64_t n_samples = 0;              ///< points sampled
    double K_low = 0;                        ///< bottom of the box
    double impact_fraction_F0 = 0;           ///< fraction of the box impacting under F_0 within N
    bool floor_touched = false;              ///< a hovering point in the lowest tenth of the box
    double area_both_sides = 0;              ///< part whose orbits visit both J_0 and J_0u
    std::int64_t unresolved = 0;             ///< orbits of F_eps ending otherwise (corner, grazing, limits)
    bool interrupted = false;                ///< cancelled: the numbers are not a result
    std::vector<std::int8_t> hovering;       ///< per sample (keep_points): 1 if it hovers
    std::vector<std::int8_t> both_sides;     ///< per sample (keep_points): 1 if it hovers visiting J_0 and J_0u
};

/// Outcomes of the n points (phi, K) under F_0 (the same arcs at eps = 0) and the truncated map m.
/// Uses opt.n_steps, n_threads, cancel, progress (2 n N in all).
HoveringOutcomes hovering_outcomes(const TruncatedMap& m, const double* phi, const double* K, std::int64_t n,
                                   const HoveringAreaOptions& opt);
/// The same for the truncated family m.
HoveringOutcomes hovering_outcomes(const TruncatedFamily& m, const double* phi, const double* K, std::int64_t n,
                                   const HoveringAreaOptions& opt);
/// The same for the flow map m, with F_0 = m0 (the eps = 0 flow on its own normal coordinates).
HoveringOutcomes hovering_outcomes(const FlowMap& m, const FlowMap& m0, const double* phi, const double* K,
                                   std::int64_t n, const HoveringAreaOptions& opt);

/// The estimates from the outcomes of the samples (their heights K, n of them) of a box of bottom
/// K_low after N = n_steps iterates: counts only, so pieces concatenated give the whole answer.
HoveringAreaResult hovering_estimate(const HoveringOutcomes& r, const double* K, std::int64_t n, std::int64_t n_steps,
                                     double K_low, bool keep_points);

/// Area of a part of the box holding `count` of its n samples, and the part's one binomial sigma.
struct PartArea {
    double area = 0;            ///< box area * count / n
    double sampling_error = 0;  ///< box area * sqrt(max(p (1 - p), 1 / n) / n), p = count / n
};

/// The area and sampling error of a part (0 <= count <= n, n >= 1) of the box of bottom K_low
/// (finite, < 0): the one formula of the estimate, the whole set's and each of its components'.
PartArea part_area(std::int64_t count, std::int64_t n, double K_low);

/// HOV of the truncated map m: checks, samples, outcomes and estimate in one call.
HoveringAreaResult hovering_area(const TruncatedMap& m, const HoveringAreaOptions& opt);
/// HOV of the truncated family m.
HoveringAreaResult hovering_area(const TruncatedFamily& m, const HoveringAreaOptions& opt);
/// HOV of the flow map m with F_0 = m0.
HoveringAreaResult hovering_area(const FlowMap& m, const FlowMap& m0, const HoveringAreaOptions& opt);

/// First-order shape G(psi) = sum_k b_k (1 - cos(k psi)) / (2 sin(k Omega0 / 2)) of the invariant
/// curves through L1 (psi = phi + Omega0 / 2); b[0] multiplies sin(phi). hovering.Theory.G.
double first_order_shape(const std::vector<double>& b, double Omega0, double psi);

/// Depth of the default box below K = 0: 2 |eps| max |G| over 4001 angles in [-pi, pi]
/// (2 |eps| / |sin(Omega0 / 2)| for f = sin); +inf when that is not finite and positive (or b is empty).
double default_depth(double eps, double Omega0, const std::vector<double>& b);

/// The deepest box bottom inside a band whose lower end is band_lo: band_lo (1 - 1e-9), so that
/// every sample lies strictly inside the band.
double box_floor(double band_lo);

/// Bottom K_low of hovering_area's default box, the one rule of Python's hovering_area and of the
/// plan writers: -default_depth(eps, Omega0, b) (-0.1 at eps = 0, which has no critical band),
/// raised to box_floor(band_lo) (band_lo = -inf: not cut).
double default_K_low(double eps, double Omega0, const std::vector<double>& b, double band_lo);

}  // namespace hovering
