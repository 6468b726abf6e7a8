#pragma once
// The SIMD vocabulary of the truncated map's lane kernel: Eigen's packet type for this build and
// SLEEF's vector sin on it.

#include <sleef.h>

#include <cstdint>

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

// cos on one packet, the same SLEEF builds as psin (the tangent of the truncated map's kick).
template <bool Fast>
inline Packet pcos(const Packet& x) {
#if defined(EIGEN_VECTORIZE_AVX512)
    return Fast ? Sleef_cosd8_u35avx512f(x) : Sleef_cosd8_u10avx512f(x);
#elif defined(EIGEN_VECTORIZE_AVX) && defined(__AVX2__) && defined(__FMA__)
    return Fast ? Sleef_cosd4_u35avx2(x) : Sleef_cosd4_u10avx2(x);
#elif defined(EIGEN_VECTORIZE_AVX)
    return Fast ? Sleef_cosd4_u35avx(x) : Sleef_cosd4_u10avx(x);
#elif defined(EIGEN_VECTORIZE_SSE4_1)
    return Fast ? Sleef_cosd2_u35sse4(x) : Sleef_cosd2_u10sse4(x);
#elif defined(EIGEN_VECTORIZE_SSE2)
    return Fast ? Sleef_cosd2_u35sse2(x) : Sleef_cosd2_u10sse2(x);
#else
    return Fast ? Sleef_cos_u35(x) : Sleef_cos_u10(x);
#endif
}

// log and exp on one packet (SLEEF, 1.0 ulp): the tangent products of record "jacobian".
inline Packet plog_u10(const Packet& x) {
#if defined(EIGEN_VECTORIZE_AVX512)
    return Sleef_logd8_u10avx512f(x);
#elif defined(EIGEN_VECTORIZE_AVX) && defined(__AVX2__) && defined(__FMA__)
    return Sleef_logd4_u10avx2(x);
#elif defined(EIGEN_VECTORIZE_AVX)
    return Sleef_logd4_u10avx(x);
#elif defined(EIGEN_VECTORIZE_SSE4_1)
    return Sleef_logd2_u10sse4(x);
#elif defined(EIGEN_VECTORIZE_SSE2)
    return Sleef_logd2_u10sse2(x);
#else
    return Sleef_log_u10(x);
#endif
}

inline Packet pexp_u10(const Packet& x) {
#if defined(EIGEN_VECTORIZE_AVX512)
    return Sleef_expd8_u10avx512f(x);
#elif defined(EIGEN_VECTORIZE_AVX) && defined(__AVX2__) && defined(__FMA__)
    return Sleef_expd4_u10avx2(x);
#elif defined(EIGEN_VECTORIZE_AVX)
    return Sleef_expd4_u10avx(x);
#elif defined(EIGEN_VECTORIZE_SSE4_1)
    return Sleef_expd2_u10sse4(x);
#elif defined(EIGEN_VECTORIZE_SSE2)
    return Sleef_expd2_u10sse2(x);
#else
    return Sleef_exp_u10(x);
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

// The four coefficients base[4 i + k], k = 0..3, of the cells i given as a packet of exact integers
// in [0, 2^29) (a Curve has at most 2^24 cells): one gather per coefficient where the instruction
// set has one (AVX2, AVX-512), lane by lane otherwise. Loads only: the values are the table's bits.
inline void pgather_cells(const double* base, const Packet& cell, Packet c[4]) {
#if defined(EIGEN_VECTORIZE_AVX512)
    const __m256i i4 = _mm256_slli_epi32(_mm512_cvtpd_epi32(cell), 2);
    for (int k = 0; k < 4; ++k) c[k] = _mm512_i32gather_pd(i4, base + k, 8);
#elif defined(EIGEN_VECTORIZE_AVX) && defined(__AVX2__)
    const __m128i i4 = _mm_slli_epi32(_mm256_cvtpd_epi32(cell), 2);
    for (int k = 0; k < 4; ++k) c[k] = _mm256_i32gather_pd(base + k, i4, 8);
#else
    alignas(64) double f[kW], v[4][kW];
    ei::pstore(f, cell);
    for (int w = 0; w < kW; ++w) {
        const double* cw = base + 4 * static_cast<std::int64_t>(f[w]);
        for (int k = 0; k < 4; ++k) v[k][w] = cw[k];
    }
    for (int k = 0; k < 4; ++k) c[k] = ei::pload<Packet>(v[k]);
#endif
}

}  // namespace hovering::detail
