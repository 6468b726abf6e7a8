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
#include <vector>

#include "hovering/flow/taylor_kernel.hpp"

#ifndef HOVERING_TAYLOR_NS
#define HOVERING_TAYLOR_NS taylor_base
#define HOVERING_TAYLOR_TABLE hovering_taylor_base
#endif

namespace hovering::HOVERING_TAYLOR_NS {

namespace {

typedef double V4 __attribute__((vector_size(32)));

// Eight orbits as two 4-double vectors: two independent dependency chains per instruction stream,
// which the CPU overlaps (the recurrences wait on latency, not on arithmetic). A 64-byte GCC
// vector would be split by the compiler without AVX-512 into much slower code.
struct V8 {
    V4 a, b;
    double& operator[](int l) { return l < 4 ? a[l] : b[l - 4]; }
    V8& operator+=(const V8& o) {
        a += o.a;
        b += o.b;
        return *this;
    }
};
inline V8 operator+(const V8& x, const V8& y) { return {x.a + y.a, x.b + y.b}; }
inline V8 operator-(const V8& x, const V8& y) { return {x.a - y.a, x.b - y.b}; }
inline V8 operator*(const V8& x, const V8& y) { return {x.a * y.a, x.b * y.b}; }
inline V8 operator-(const V8& x) { return {-x.a, -x.b}; }
inline V8 operator*(double s, const V8& x) { return {s * x.a, s * x.b}; }
inline V8 operator*(const V8& x, double s) { return {x.a * s, x.b * s}; }
inline V8 operator+(double s, const V8& x) { return {s + x.a, s + x.b}; }
inline V8 operator+(const V8& x, double s) { return {x.a + s, x.b + s}; }

template <class V, int L>
void expand(const detail::TaylorModel& m, const double* const* y, int count, double* const* out) {
    // On the stack (26 kB for 8 lanes): every worker has its own, and nothing is read before it is
    // written (taylor_series fills orders 1 .. p from 0 and its own work rows). A General
    // coupling's powers (up to 110 kB) live in a buffer of the thread's, grown once.
    detail::TaylorSeries<V> S;
    if (m.ckind == detail::CKind::General) {
        thread_local std::vector<V> pow;
        const std::size_t rows = std::size_t(m.deg1 + 1 + m.deg2 + 1) * detail::kTaylorStride;
        if (pow.size() < rows) pow.resize(rows);
        S.pow1 = pow.data();
        S.pow2 = pow.data() + std::size_t(m.deg1 + 1) * detail::kTaylorStride;
    }
    for (int i = 0; i < m.n; ++i)
        for (int l = 0; l < L; ++l) S.c[i][0][l] = y[l < count ? l : 0][i];  // idle lanes repeat lane 0
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

extern "C" const hovering::detail::TaylorLaneKernels HOVERING_TAYLOR_TABLE = {
    hovering::HOVERING_TAYLOR_NS::kLevel,
    &hovering::HOVERING_TAYLOR_NS::expand<hovering::HOVERING_TAYLOR_NS::V4, 4>,
    &hovering::HOVERING_TAYLOR_NS::expand<hovering::HOVERING_TAYLOR_NS::V8, 8>};
