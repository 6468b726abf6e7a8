#pragma once
// The SIMD vocabulary of the truncated map's lane kernel: Eigen's packet type for this build and
// SLEEF's vector sin on it.

#include <sleef.h>

#include <Eigen/Core>

#if defined(__AVX2__) || defined(__SSE2__)
#include <immintrin.h>
#endif

namespace hovering::detail {

namespace ei = Eigen::internal;
// The SIMD register type Eigen picked for this build (AVX-512, AVX, SSE2 or plain double).
using Packet = ei::packet_traits<double>::type;
constexpr int kW = ei::packet_traits<double>::size;  // (unpacket_traits<Packet> trips -Wignored-attributes)

// sin on one packet with SLEEF's vector sin for this instruction set: max error 1.0 ulp, or 3.5 ulp
// (about 20% faster per step) when Fast is set.
template <bool Fast>
inline Packet psin(const Packet& x) {
#if defined(EIGEN_VECTORIZE_AVX512)
    return Fast ? Sleef_sind8_u35avx512f(x) : Sleef_sind8_u10avx512f(x);
#elif defined(EIGEN_VECTORIZE_AVX) && defined(__AVX2__) && defined(__FMA__)
    return Fast ? Sleef_sind4_u35avx2(x) : Sleef_sind4_u10avx2(x);
#elif defined(EIGEN_VECTORIZE_AVX)
    return Fast ? Sleef_sind4_u35avx(x) : Sleef_sind4_u10avx(x);
#elif defined(EIGEN_VECTORIZE_SSE4_1)
    return Fast ? Sleef_sind2_u35sse4(x) : Sleef_sind2_u10sse4(x);
#elif defined(EIGEN_VECTORIZE_SSE2)
    return Fast ? Sleef_sind2_u35sse2(x) : Sleef_sind2_u10sse2(x);
#else
    return Fast ? Sleef_sin_u35(x) : Sleef_sin_u10(x);
#endif
}

// Correctly rounded sqrt on one packet, as std::sqrt. Eigen 3.4's psqrt for AVX-512 doubles is, by
// default (EIGEN_FAST_MATH), rsqrt14 and two Newton steps: off by 1-4 ulp, which made the SIMD
// kernel's |J_1| and so phi differ from step() on ~2% of the points of J_R.
inline Packet psqrt_rn(const Packet& x) {
#if defined(EIGEN_VECTORIZE_AVX512)
    return _mm512_sqrt_pd(x);
#else
    return ei::psqrt(x);  // _mm256_sqrt_pd / _mm_sqrt_pd / std::sqrt: correctly rounded
#endif
}


}  // namespace hovering::detail
