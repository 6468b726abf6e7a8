// Four orbits' Taylor expansions at once, one orbit per lane of a 4-double vector (GCC/Clang
// vector extension: AVX registers in the AVX2 and AVX-512 builds, two SSE2 registers in the
// baseline). One source, compiled with the core's flags and, in the portable x86-64 build, once more
// per wider instruction set beside lanes.cpp (CMakeLists.txt), with HOVERING_TAYLOR_NS naming the
// build's namespace and HOVERING_TAYLOR_TABLE its table; Taylor::expand_group picks the table of
// the SIMD level the core runs (simd_level(): HOVERING_SIMD, set_simd_level, else the widest).
//
// The recurrences are latency-bound chains of dependent additions (taylor_kernel.hpp), so four
// orbits in the lanes of one register cost little more than one: measured 3.3-4.0x per orbit-step
// on AVX2 at orders 8-18, 1.2-1.4x on SSE2.

#include <cstddef>

#include "hovering/flow/taylor_kernel.hpp"

#ifndef HOVERING_TAYLOR_NS
#define HOVERING_TAYLOR_NS taylor_base
#define HOVERING_TAYLOR_TABLE hovering_taylor_base
#endif

namespace hovering::HOVERING_TAYLOR_NS {

namespace {

typedef double V4 __attribute__((vector_size(32)));

void expand4(const detail::TaylorModel& m, const double* const* y, int count, double* const* out) {
    // On the stack (68 kB at most): every worker has its own, and nothing is read before it is
    // written (taylor_series fills orders 1 .. p from 0 and its own work rows).
    detail::TaylorSeries<V4> S;
    for (int i = 0; i < m.n; ++i)
        for (int l = 0; l < 4; ++l) S.c[i][0][l] = y[l < count ? l : 0][i];  // idle lanes repeat lane 0
    detail::taylor_series(m, S);
    for (int l = 0; l < count; ++l)
        for (int i = 0; i < m.n; ++i)
            for (int k = 0; k <= m.p; ++k) out[l][std::size_t(i) * detail::kTaylorStride + std::size_t(k)] = S.c[i][k][l];
}

constexpr const char* kLevel =
#if defined(__AVX512F__)
    "avx512";
#elif defined(__AVX2__)
    "avx2";
#elif defined(__AVX__)
    "avx";
#elif defined(__SSE2__)
    "sse2";
#else
    "none";
#endif

}  // namespace

}  // namespace hovering::HOVERING_TAYLOR_NS

extern "C" const hovering::detail::TaylorLaneKernels HOVERING_TAYLOR_TABLE = {hovering::HOVERING_TAYLOR_NS::kLevel,
                                                                              &hovering::HOVERING_TAYLOR_NS::expand4};
