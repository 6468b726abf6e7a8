// Batch iteration of the truncated family: the scalar reference kernel, the SIMD lane kernel's
// build (lanes.cpp) the dispatch selected (detail/simd_dispatch.hpp), and MapCore::iterate on the
// core's thread pool.

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "hovering/detail/common.hpp"
#include "hovering/detail/parallel.hpp"
#include "hovering/detail/simd_dispatch.hpp"
#include "hovering/truncated/classify.hpp"
#include "hovering/truncated/lanes.hpp"
#include "hovering/truncated/map.hpp"

namespace hovering {

namespace {

using detail::bad;
using detail::Classified;
using detail::classify;
using detail::Finisher;
using detail::LaneKernels;
using detail::Tally;
using detail::WorkCursor;

// Orbits per worker at least, for the scalar kernel: the lane block of the AVX2 build, which the
// scalar kernel has always been given.
constexpr std::int64_t kScalarBlock = 32;

template <class A, class F>
void run_scalar(const MapCore<A, F>& m, const double* phi0, const double* K0, WorkCursor& src,
                const IterateOptions& opt, const IterateOutput& out, detail::ProgressShare& progress) {
    const Finisher finish(opt, out, progress);
    const std::int64_t ns = opt.n_steps, every = opt.every;
    const bool rec_states = out.orbit_phi || out.orbit_K;
    const bool tangent = out.tangent.active();
    const StopCondition& stop = opt.stop;
    for (std::int64_t i; src.pop(i);) {
        double phi = detail::wrap(phi0[i]), K = K0[i];
        Tally t;
        t.K_min = t.K_max = K;
        finish.start(i, phi, K);
        bool reported = false;
        std::int64_t n = 0;
        Status st = Status::Ok;
        if (!(K > m.band().lo && K < m.band().hi)) {
            finish(i, phi, K, 0, Status::Escaped, t);
            continue;
        }
        if (stop.active() && stop.reached(phi, K)) {
            finish(i, phi, K, 0, Status::Stopped, t);
            continue;
        }
        std::int64_t counted = 0;  // steps of this orbit handed to progress so far
        std::int64_t phase = 0;    // n mod every
        for (; n < ns; ++n) {
            if ((n & 63) == 0) {
                progress.add(n - counted);  // every 64 steps, off the per-step path
                counted = n;
                if (opt.cancelled()) {
                    st = Status::Interrupted;
                    break;
                }
            }
            const Classified c = classify(phi, K, m.arcs().at(K));
            const int r = int(c.region);
            t.visited |= 1 << r;
            // The return from x_n is counted (residence) and recorded (regions) also when it is
            // the exiting one, which stop_on_exit then does not take.
            t.upper += r == int(Region::Upper);
            t.right += r == int(Region::Right);
            t.below += r != int(Region::Beside);
            ++t.counted;
            if (phase == 0) {
                if (rec_states) finish.state(i, n, phi, K);
                finish.region(i, n, r);
            }
            if (opt.exit_mask && !reported && !((opt.exit_mask >> r) & 1u)) {
                if (out.exit_step) out.exit_step[i] = n;
                reported = true;
                if (opt.stop_on_exit) {
                    st = Status::Exited;
                    break;
                }
            }
            t.rot += c.omega;
            const double phi_from = phi, K_from = K;
            phi = detail::rotate(phi, c.omega);
            K += m.eps() * m.forcing().at(phi);
            if (tangent) detail::tangent_step(m, phi_from, K_from, c.region, phi, t);
            t.K_min = std::min(t.K_min, K);
            t.K_max = std::max(t.K_max, K);
            if (++phase == every) phase = 0;
            if (!(K > m.band().lo && K < m.band().hi)) {
                st = Status::Escaped;
                ++n;
                break;
            }
            if (stop.active() && stop.reached(phi, K)) {
                st = Status::Stopped;
                ++n;
                break;
            }
        }
        progress.add(n - counted);
        finish(i, phi, K, n, st, t);
    }
}

// The builds of the lane kernel, in the dispatch's order (detail/simd_dispatch.hpp).
const LaneKernels* const kLaneBuilds[detail::kSimdBuilds] = {
    &hovering_lanes_base,
#if defined(HOVERING_LANES_DISPATCH)
    &hovering_lanes_avx2,
    &hovering_lanes_avx512,
#endif
};

const LaneKernels& lanes() {
    return detail::selected_build(kLaneBuilds);
}

template <class A, class F>
detail::LaneKernel<A, F> lane_kernel(bool fast);
template <>
detail::LaneKernel<AnalyticArcs, SineForcing> lane_kernel<AnalyticArcs, SineForcing>(bool fast) {
    return lanes().analytic[fast];
}
template <>
detail::LaneKernel<TabulatedArcs, FourierForcing> lane_kernel<TabulatedArcs, FourierForcing>(bool fast) {
    return lanes().tabulated[fast];
}

}  // namespace

bool simd_is_avx2() {
    return lanes().width >= 4;
}

int simd_width() {
    return lanes().width;
}

template <class A, class F>
void MapCore<A, F>::iterate(const double* phi0, const double* K0, std::int64_t n, const IterateOptions& opt,
                            const IterateOutput& out) const {
    if (n < 0) bad("number of orbits must be >= 0, got " + std::to_string(n));
    opt.validate();
    for (std::int64_t i = 0; i < n; ++i) {
        detail::require_angle(phi0[i], "phi0[" + std::to_string(i) + "]");
        detail::require_finite(K0[i], "K0[" + std::to_string(i) + "]");
    }
    if (n == 0) return;
    // A SIMD worker needs at least a lane-block's worth of orbits to fill its vectors; small blocks
    // keep workers balanced when orbits stop at different times. (The scalar kernel takes the
    // SIMD path's thread count too, without asking for a lane build it does not use.)
    const std::int64_t block = opt.kernel == Kernel::Simd ? lanes().lanes : kScalarBlock;
    const detail::LaneKernel<A, F> simd = opt.kernel == Kernel::Simd ? lane_kernel<A, F>(opt.fast_sin) : nullptr;
    const int threads = detail::worker_count(opt.n_threads, (n + block - 1) / block);
    detail::WorkQueue queue(n, detail::balanced_block(n, threads, 256));
    detail::run_workers(threads, queue, [&](WorkCursor& src) {
        // Steps are ~1 ns: a worker hands its count over every 2^14 of them (~20 us).
        detail::ProgressShare progress(opt.progress, std::int64_t(1) << 14);
        if (simd)
            simd(*this, phi0, K0, src, opt, out, progress);
        else
            run_scalar(*this, phi0, K0, src, opt, out, progress);
    });
}

template void MapCore<AnalyticArcs, SineForcing>::iterate(const double*, const double*, std::int64_t,
                                                          const IterateOptions&, const IterateOutput&) const;
template void MapCore<TabulatedArcs, FourierForcing>::iterate(const double*, const double*, std::int64_t,
                                                              const IterateOptions&, const IterateOutput&) const;

}  // namespace hovering