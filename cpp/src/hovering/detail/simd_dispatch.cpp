// The run-time choice of the SIMD kernels' build: see simd_dispatch.hpp and hovering/simd.hpp.

#include "hovering/detail/simd_dispatch.hpp"

#include <array>
#include <atomic>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "hovering/detail/simd_level.hpp"
#include "hovering/simd.hpp"

namespace hovering {

namespace detail {

namespace {

// A build: its level's name, whether this CPU (and its OS, which must save the wider registers)
// runs it, and what it needs (for messages).
struct Build {
    const char* level;
    bool (*runs)();
    const char* needs;
};

const std::array<Build, kSimdBuilds>& builds() {
#if defined(HOVERING_LANES_DISPATCH)
    __builtin_cpu_init();  // idempotent; needed if the first call runs before libgcc's constructor
#endif
    // This file is compiled with the core's own flags: the baseline build's, so its name is the
    // baseline kernels' own (kSimdLevel there and here).
    static const std::array<Build, kSimdBuilds> b = {{
        {kSimdLevel, [] { return true; }, "the baseline of this build"},
#if defined(HOVERING_LANES_DISPATCH)
        {"avx2", [] { return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"); }, "AVX2 and FMA"},
        {"avx512",
         [] {
             return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
                    __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("avx512bw") &&
                    __builtin_cpu_supports("avx512vl");
         },
         "AVX-512 F, CD, BW, DQ and VL"},
#endif
    }};
    return b;
}

std::string level_names(bool runnable_only) {
    std::string s;
    for (const Build& b : builds())
        if (!runnable_only || b.runs()) s += std::string(s.empty() ? "" : ", ") + b.level;
    return s;
}

// The build named `level` ("" or "auto": the widest this CPU runs); `what` names the setting in
// messages (the environment variable or the function).
int find_build(const std::string& level, const char* what) {
    int widest = 0;
    for (int i = 0; i < kSimdBuilds; ++i) {
        if (!builds()[i].runs()) continue;
        widest = i;
        if (level == builds()[i].level) return i;
    }
    if (level.empty() || level == "auto") return widest;
    for (const Build& b : builds())
        if (level == b.level)
            throw std::invalid_argument(std::string(what) + "='" + level + "' is not available: this CPU lacks " +
                                        b.needs + " (allowed here: auto, " + level_names(true) + ")");
    throw std::invalid_argument(std::string(what) + " must be one of auto, " + level_names(true) + " (the " +
                                "SIMD levels of this build that this CPU runs; this build has " + level_names(false) +
                                "), got '" + level + "'");
}

std::atomic<int> g_build{-1};  // -1: not chosen yet

}  // namespace

int simd_build() {
    int k = g_build.load(std::memory_order_acquire);
    if (k < 0) {
        const char* env = std::getenv("HOVERING_SIMD");
        k = find_build(env ? env : "", "HOVERING_SIMD");
        int expected = -1;  // a concurrent set_simd_level wins
        if (!g_build.compare_exchange_strong(expected, k, std::memory_order_acq_rel)) k = expected;
    }
    return k;
}

}  // namespace detail

std::string simd_level() {
    return detail::builds()[detail::simd_build()].level;
}

std::vector<std::string> simd_levels() {
    std::vector<std::string> v;
    for (const detail::Build& b : detail::builds())
        if (b.runs()) v.emplace_back(b.level);
    return v;
}

void set_simd_level(const std::string& level) {
    detail::g_build.store(detail::find_build(level, "SIMD level"), std::memory_order_release);
}

}  // namespace hovering
