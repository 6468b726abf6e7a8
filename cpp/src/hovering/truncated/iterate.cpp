// Batch iteration of the truncated family: the scalar reference kernel, the choice of the SIMD
// lane kernel's build (lanes.cpp) for this CPU, and MapCore::iterate on the core's thread pool.

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "hovering/detail/common.hpp"
#include "hovering/detail/parallel.hpp"
#include "hovering/detail/simd_level.hpp"
#include "hovering/truncated/classify.hpp"
#include "hovering/truncated/lanes.hpp"
#include "hovering/truncated/map.hpp"

namespace hovering {

namespace {

using detail::bad;
using detail::cancelled;
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
                if (cancelled(opt)) {
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

// The builds of the lane kernel this binary has, narrowest first, each with the test of whether
// this CPU (and its OS, which must save the wider registers) runs it.
struct LaneBuild {
    const LaneKernels* kernels;
    bool (*runs)();
    const char* needs;  // the CPU features it needs, for messages
};

const std::vector<LaneBuild>& lane_builds() {
#if defined(HOVERING_LANES_DISPATCH)
    __builtin_cpu_init();  // idempotent; needed if the first call runs before libgcc's constructor
#endif
    static const std::vector<LaneBuild> builds = {
        {&hovering_lanes_base, [] { return true; }, "the baseline of this build"},
#if defined(HOVERING_LANES_DISPATCH)
        {&hovering_lanes_avx2, [] { return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"); },
         "AVX2 and FMA"},
        {&hovering_lanes_avx512,
         [] {
             return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
                    __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("avx512bw") &&
                    __builtin_cpu_supports("avx512vl");
         },
         "AVX-512 F, CD, BW, DQ and VL"},
#endif
    };
    return builds;
}

std::string level_names(bool runnable_only) {
    std::string s;
    for (const LaneBuild& b : lane_builds())
        if (!runnable_only || b.runs()) s += std::string(s.empty() ? "" : ", ") + b.kernels->level;
    return s;
}

// The build named `level` ("" or "auto": the widest this CPU runs); `what` names the setting in
// messages (the environment variable or the function).
const LaneKernels* find_lanes(const std::string& level, const char* what) {
    const LaneKernels* widest = nullptr;
    for (const LaneBuild& b : lane_builds()) {
        if (!b.runs()) continue;
        widest = b.kernels;
        if (level == b.kernels->level) return b.kernels;
    }
    if (level.empty() || level == "auto") return widest;
    for (const LaneBuild& b : lane_builds())
        if (level == b.kernels->level)
            throw std::invalid_argument(std::string(what) + "='" + level + "' is not available: this CPU lacks " +
                                        b.needs + " (allowed here: auto, " + level_names(true) + ")");
    throw std::invalid_argument(std::string(what) + " must be one of auto, " + level_names(true) + " (the " +
                                "SIMD levels of this build that this CPU runs; this build has " + level_names(false) +
                                "), got '" + level + "'");
}

// The selected build: set_simd_level's, else HOVERING_SIMD's (read at first use; a bad value is an
// error at every use until it is fixed), else the widest this CPU runs.
std::atomic<const LaneKernels*> g_lanes{nullptr};

const LaneKernels& lanes() {
    const LaneKernels* k = g_lanes.load(std::memory_order_acquire);
    if (!k) {
        const char* env = std::getenv("HOVERING_SIMD");
        k = find_lanes(env ? env : "", "HOVERING_SIMD");
        const LaneKernels* expected = nullptr;  // a concurrent set_simd_level wins
        if (!g_lanes.compare_exchange_strong(expected, k, std::memory_order_acq_rel)) k = expected;
    }
    return *k;
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

std::string simd_level() {
    return lanes().level;
}

const char* detail::selected_simd_level() {
    return lanes().level;
}

std::vector<std::string> simd_levels() {
    std::vector<std::string> v;
    for (const LaneBuild& b : lane_builds())
        if (b.runs()) v.emplace_back(b.kernels->level);
    return v;
}

void set_simd_level(const std::string& level) {
    g_lanes.store(find_lanes(level, "SIMD level"), std::memory_order_release);
}

template <class A, class F>
void MapCore<A, F>::iterate(const double* phi0, const double* K0, std::int64_t n, const IterateOptions& opt,
                            const IterateOutput& out) const {
    if (n < 0) bad("number of orbits must be >= 0, got " + std::to_string(n));
    if (opt.n_steps < 0) bad("n_steps must be >= 0, got " + std::to_string(opt.n_steps));
    if (opt.exit_mask >= (1u << kRegionCount))
        bad("exit_mask must be a set of region codes 0.." + std::to_string(kRegionCount - 1) + " (a bit mask < " +
            std::to_string(1u << kRegionCount) + "), got " + std::to_string(opt.exit_mask));
    if (opt.stop_on_exit && opt.exit_mask == 0u) bad("stop_on_exit needs a non-empty set of regions to stay in");
    if (opt.n_threads < 0 || opt.n_threads > detail::kMaxThreads)
        bad("n_threads must be in [0, " + std::to_string(detail::kMaxThreads) + "] (0 = all cores), got " +
            std::to_string(opt.n_threads));
    if (opt.every < 1) bad("every must be >= 1 (record every k-th state), got " + std::to_string(opt.every));
    opt.stop.validate();
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