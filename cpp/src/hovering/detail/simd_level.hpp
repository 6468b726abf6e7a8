#pragma once
// The instruction set a translation unit is compiled for, as the SIMD kernels and their dispatch
// name their builds (internal). Included by each kernel's source (compiled once per build) and by
// the dispatch (compiled with the core's own flags, as the baseline build): one spelling of a
// level's name for all of them.

namespace hovering::detail {

/// "avx512", "avx2", "avx", "sse4.1", "sse2", "neon" or "none": the compiler's macros, the ones Eigen
/// vectorises for (EIGEN_VECTORIZE_*). constexpr at namespace scope: each build's object keeps its own.
constexpr const char* kSimdLevel =
#if defined(__AVX512F__)
    "avx512";
#elif defined(__AVX2__) && defined(__FMA__)
    "avx2";
#elif defined(__AVX__)
    "avx";
#elif defined(__SSE4_1__)
    "sse4.1";
#elif defined(__SSE2__)
    "sse2";
#elif defined(__ARM_NEON)
    "neon";
#else
    "none";
#endif

}  // namespace hovering::detail
