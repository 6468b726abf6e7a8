#pragma once
// What the two batch kernels of the truncated family share (an orbit's tally, the writer of its
// outputs, the cancellation poll), and the table through which MapCore::iterate reaches the SIMD
// lane kernel. lanes.cpp is compiled once per instruction set (see CMakeLists.txt): each build
// defines one table, and iterate.cpp picks one at run time from what this CPU runs.

#include <algorithm>
#include <atomic>
#include <cstdint>

#include "hovering/detail/common.hpp"
#include "hovering/detail/parallel.hpp"
#include "hovering/truncated/classify.hpp"
#include "hovering/truncated/map.hpp"

namespace hovering::detail {

// What an orbit gathers besides its state, for the records that stream (nothing per step is stored).
struct Tally {
    double rot = 0.0;                   // sum of omega_a over the steps taken
    int visited = 0;                    // bit r: a return from Region r was taken (or was the exiting one)
    double K_min = kNaN, K_max = kNaN;  // over the states x_0 .. x_steps
    // Returns counted for the residence: from J_1, from J_R, from any point with K < 0 (all three
    // arcs), and in all (those taken, plus the exiting one with stop_on_exit); J_0 and J_0u follow.
    double upper = 0, right = 0, below = 0;
    std::int64_t counted = 0;
    TangentProduct tangent;         // record "jacobian": the product of the steps' Jacobians
    Status tangent_status = Status::Ok;  // Corner once a step was taken from an arc start
};

// The Jacobian of the step from (phi, K) in arc r to the image angle p (MapCore::step_jacobian's
// formula), multiplied into t; a start exactly on an arc start marks the product one-sided.
template <class A, class F>
inline void tangent_step(const MapCore<A, F>& m, double phi, double K, Region r, double p, Tally& t) {
    const ArcSlopes d = m.arcs().slopes(K);
    double w = d.Omega;
    if (r == Region::Upper) w += d.JR;
    if (r == Region::Right) w -= d.J1;
    const double g = m.eps() * m.forcing().slope(p);
    const double J[4] = {1.0, w, g, 1.0 + g * w};
    t.tangent.multiply(J);
    if (K < 0.0 && t.tangent_status == Status::Ok) {
        const ArcStarts s = arc_starts(m.arcs().at(K));
        if (phi == s.s1 || phi == s.sR || phi == s.s0) t.tangent_status = Status::Corner;
    }
}

// Writes an orbit's outputs once it stops, and the NaN / None tail of its recorded arrays.
struct Finisher {
    const IterateOptions& opt;
    const IterateOutput& out;
    detail::ProgressShare& progress;          // credits the steps an orbit that stops early will not take
    std::int64_t every, n_states, n_returns;  // recorded per orbit: every e-th state and return
    Finisher(const IterateOptions& o, const IterateOutput& w, detail::ProgressShare& p)
        : opt(o),
          out(w),
          progress(p),
          every(o.every),
          n_states(recorded_states(o.n_steps, o.every)),
          n_returns(recorded_returns(o.n_steps, o.every)) {}
    void start(std::int64_t i, double phi, double K) const {
        if (out.orbit_phi) out.orbit_phi[i * n_states] = phi;
        if (out.orbit_K) out.orbit_K[i * n_states] = K;
        if (out.exit_step) out.exit_step[i] = -1;
        if (out.stop_step) out.stop_step[i] = -1;
    }
    // State x_n of orbit i (n a multiple of every).
    void state(std::int64_t i, std::int64_t n, double phi, double K) const {
        if (out.orbit_phi) out.orbit_phi[i * n_states + n / every] = phi;
        if (out.orbit_K) out.orbit_K[i * n_states + n / every] = K;
    }
    // Region of the return from x_n of orbit i (n a multiple of every, n < n_steps).
    void region(std::int64_t i, std::int64_t n, int r) const {
        if (out.regions) out.regions[i * n_returns + n / every] = static_cast<std::int8_t>(r);
    }
    void operator()(std::int64_t i, double phi, double K, std::int64_t steps, Status st, const Tally& t) const {
        if (out.visited) out.visited[i] = static_cast<std::int8_t>(t.visited);
        if (out.phi_final) out.phi_final[i] = phi;
        if (out.K_final) out.K_final[i] = K;
        if (out.rotation) out.rotation[i] = steps > 0 ? t.rot / double(steps) : kNaN;
        if (out.status) out.status[i] = static_cast<std::int8_t>(st);
        if (out.steps_done) out.steps_done[i] = steps;
        if (out.stop_step && st == Status::Stopped) out.stop_step[i] = steps;
        out.tangent.write(i, t.tangent, t.tangent_status);
        if (out.K_min) out.K_min[i] = t.K_min;
        if (out.K_max) out.K_max[i] = t.K_max;
        if (out.residence) {
            std::int64_t* r = out.residence + i * kRegionCount;
            r[int(Region::Beside)] = t.counted - std::int64_t(t.below);
            r[int(Region::Above)] = std::int64_t(t.below - t.upper - t.right);
            r[int(Region::Upper)] = std::int64_t(t.upper);
            r[int(Region::Right)] = std::int64_t(t.right);
            r[int(Region::Multi)] = 0;
        }
        if (st != Status::Interrupted) progress.add(opt.n_steps - steps);
        if (steps % every == 0) state(i, steps, phi, K);
        const std::int64_t s_end = steps / every + 1;  // first state index not reached
        if (out.orbit_phi) std::fill(out.orbit_phi + i * n_states + s_end, out.orbit_phi + (i + 1) * n_states, kNaN);
        if (out.orbit_K) std::fill(out.orbit_K + i * n_states + s_end, out.orbit_K + (i + 1) * n_states, kNaN);
        // Returns recorded: those from x_n, n < steps, and the exiting one (n = steps) if it was.
        const std::int64_t exiting = st == Status::Exited ? 1 : 0;
        const std::int64_t r_end = (steps + exiting + every - 1) / every;
        if (out.regions)
            std::fill(out.regions + i * n_returns + r_end, out.regions + (i + 1) * n_returns,
                      static_cast<std::int8_t>(Region::None));
    }
};

/// The lane kernel of one map type: iterates the orbits src hands out.
template <class A, class F>
using LaneKernel = void (*)(const MapCore<A, F>&, const double* phi0, const double* K0, WorkCursor& src,
                            const IterateOptions& opt, const IterateOutput& out, ProgressShare& progress);

/// One build of the lane kernel: its instruction set, its packet width and its entry points.
struct LaneKernels {
    const char* level;                                       ///< "sse2", "avx2", "avx512", ... as compiled
    int width;                                               ///< doubles per packet
    int lanes;                                               ///< orbits stepped together by one worker
    LaneKernel<AnalyticArcs, SineForcing> analytic[2];       ///< [fast_sin]
    LaneKernel<TabulatedArcs, FourierForcing> tabulated[2];  ///< [fast_sin]
};

}  // namespace hovering::detail

// The builds of lanes.cpp: the one compiled with the core's own flags, always; with
// HOVERING_LANES_DISPATCH (x86-64, portable build) also an AVX2 and an AVX-512 one, whose objects
// keep only this symbol global so that none of their code can stand in for the core's own.
extern "C" {
extern const hovering::detail::LaneKernels hovering_lanes_base;
#if defined(HOVERING_LANES_DISPATCH)
extern const hovering::detail::LaneKernels hovering_lanes_avx2;
extern const hovering::detail::LaneKernels hovering_lanes_avx512;
#endif
}
