// Four orbits' Taylor expansions at once, one orbit per lane of a 4-double vector (GCC/Clang
// vector extension: AVX registers in the AVX2 and AVX-512 builds, two SSE2 registers in the
// baseline), or eight (one AVX-512 register, or two 4-double vectors). One source, compiled with the core's flags and, in the portable x86-64 build, once more
// per wider instruction set beside lanes.cpp (CMakeLists.txt), with HOVERING_TAYLOR_NS naming the
// build's namespace and HOVERING_TAYLOR_TABLE its table; Taylor::expand_group picks the table of
// the SIMD level the core runs (detail/simd_dispatch.hpp: one choice for both kernels).
//
// The recurrences are latency-bound chains of dependent additions (taylor_kernel.hpp), so four
// orbits in the lanes of one register cost little more than one: measured 3.3-4.0x per orbit-step
// on AVX2 at orders 8-18, 1.2-1.4x on SSE2.

#include <cstddef>
#include <vector>

#include "hovering/detail/simd_level.hpp"
#include "hovering/flow/taylor_kernel.hpp"

#ifndef HOVERING_TAYLOR_NS
#define HOVERING_TAYLOR_NS taylor_base
#define HOVERING_TAYLOR_TABLE hovering_taylor_base
#endif

namespace hovering::HOVERING_TAYLOR_NS {

namespace {

typedef double V4 __attribute__((vector_size(32)));

#if defined(__AVX512F__)
// Eight orbits in one 8-double register: the same IEEE operations in the same order as two 4-double
// vectors (the same bits), in half the instructions: 3-12% more returns per second on the
// polynomial-coupling systems of benchmarks/bench_systems.py, where the expansion is a third of
// the time.
typedef double V8 __attribute__((vector_size(64)));
#else
// Eight orbits as two 4-double vectors: two independent dependency chains per instruction stream,
// which the CPU overlaps (the recurrences wait on latency, not on arithmetic). A 64-byte GCC
// vector would be split by the compiler without AVX-512 into much slower code.
struct V8 {
    V4 a, b;
    double& operator[](int l) { return l < 4 ? a[l] : b[l - 4]; }
    double operator[](int l) const { return l < 4 ? a[l] : b[l - 4]; }
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

#endif
typedef long long I4 __attribute__((vector_size(32)));

// log2 to ~3e-3 and exp2 to ~2e-5, for the step rule only: libm's log and exp took 15% of a
// return's time (three logs and an exp per step), and a step length needs less. An error d in a
// log2 changes the step's truncation error by a factor 2^(2 d) (< 1.01); an error e in exp2 by
// (1 + e)^p (< 1.001 at p <= 40). Both are fixed functions of their argument's bits, so every
// lane and instruction set agrees. x >= 0 here.
inline V4 log2_fast(V4 x) {
    I4 b = (I4)x;
    I4 e = ((b >> 52) & 0x7ff) - 1023;
    b = (b & 0x000fffffffffffffLL) | 0x3ff0000000000000LL;  // mantissa in [1, 2)
    V4 m = (V4)b;
    const I4 high = m > 1.4142135623730951;  // to [sqrt(1/2), sqrt(2)): |m - 1| <= 0.42
    m = high ? m * 0.5 : m;
    e -= high;  // true is -1
    // ln(1 + z), |z| <= 0.42: the series to z^5 is within 2e-3 (ln 2 times that in log2).
    const V4 z = m - 1.0;
    const V4 ln = z * (1.0 + z * (-0.5 + z * (1.0 / 3 + z * (-0.25 + z * 0.2))));
    return __builtin_convertvector(e, V4) + ln * 1.4426950408889634;
}

inline V4 exp2_fast(V4 x) {
    const V4 inf = V4{} + __builtin_inf();
    const I4 in_range = (x >= -1022.0) & (x < 1023.0);
    const V4 xc = in_range ? x : V4{};  // no conversion of what is out of range
    I4 n = __builtin_convertvector(xc, I4);  // toward zero: floor is one lower below a non-integer < 0
    n += __builtin_convertvector(n, V4) > xc;
    const V4 y = (xc - __builtin_convertvector(n, V4)) * 0.6931471805599453;  // 2^(x - n) = e^y, y in [0, ln 2): to y^6, 2e-5
    const V4 ey = 1.0 + y * (1.0 + y * (0.5 + y * (1.0 / 6 + y * (1.0 / 24 + y * (1.0 / 120 + y / 720)))));
    const V4 r = ey * (V4)((n + 1023) << 52);
    return in_range ? r : x < -1022.0 ? V4{} : x != x ? x : inf;
}

// The step rule (taylor.hpp) on four lanes of coefficients c(i, k); *ok: all coefficients finite.
template <class Coef>
V4 step_rule(const detail::TaylorModel& m, V4 floor, V4 factor, Coef c, I4* ok) {
    const int p = m.p;
    const V4 zero = V4{};
    const I4 sign = I4{} + 0x7fffffffffffffffLL;
    // Each variable against its own scale max(|x_i0|, atol / rtol): relative control per
    // component, as GSL's. One norm for the whole state (Jorba & Zou's) let a small position err
    // relative to a large momentum or tan(alpha q) near a Tan well's edge: ~1e3-1e4 x rtol at
    // h = 1e4 - 1e6, where this rule stays within the GSL steppers' band.
    V4 q1 = zero, q2 = zero;  // max_i |x_i,p-1| / s_i and max_i |x_i,p| / s_i
    I4 finite = I4{} - 1;
    for (int i = 0; i < m.n; ++i) {
        const V4 a0 = (V4)((I4)c(i, 0) & sign), a1 = (V4)((I4)c(i, p - 1) & sign), a2 = (V4)((I4)c(i, p) & sign);
        const V4 inv = 1.0 / (a0 < floor ? floor : a0);
        const V4 t1 = a1 * inv, t2 = a2 * inv;
        q1 = q1 < t1 ? t1 : q1;
        q2 = q2 < t2 ? t2 : q2;
        // A non-finite coefficient reaches every later one (each is a sum over all below it).
        finite &= (a1 <= __DBL_MAX__) & (a2 <= __DBL_MAX__);
    }
    *ok = finite;
    // rho = min_j (1 / max_i (|x_ij| / s_i))^(1/j), j = p - 1, p, in base-2 logarithms.
    V4 lrho = zero + __builtin_inf();
    const V4 r1 = -log2_fast(q1) * m.inv[p - 2], r2 = -log2_fast(q2) * m.inv[p - 1];
    lrho = q1 > 0.0 && r1 < lrho ? r1 : lrho;
    lrho = q2 > 0.0 && r2 < lrho ? r2 : lrho;
    // The step fraction f and Jorba & Zou's exp(-0.7 / (p - 1)) for the coefficients beyond p that
    // the estimate does not see (the lane's factor).
    return exp2_fast(lrho) * factor;
}

// keeps_sign (poly_roots.hpp) of the polynomial c(k) s^k, s in [0, 1] after scaling by tau (b_k =
// c_k tau^k, the powers by repeated products as Taylor::scaled_coefficients forms them), on four
// lanes: the same operations in the same order, so the same verdict bit for bit.
template <class Coef>
I4 keeps_sign(Coef c, int n, V4 tau) {
    const I4 sign = I4{} + 0x7fffffffffffffffLL;
    V4 b[detail::kTaylorStride];
    V4 hk = V4{} + 1.0;
    for (int k = 0; k <= n; ++k) {
        b[k] = c(k) * hk;
        hk = hk * tau;
    }
    V4 tail = V4{};
    for (int k = 3; k <= n; ++k) tail += (V4)((I4)b[k] & sign);
    const V4 b0 = b[0], b1 = b[1], b2 = b[2];
    const V4 end = b0 + b1 + b2;
    V4 lo = end < b0 ? end : b0, hi = b0 < end ? end : b0;  // std::min, std::max
    const V4 v = -b1 / (2.0 * b2);
    const I4 inside = (b2 != 0.0) & (v > 0.0) & (v < 1.0);
    const V4 q = b0 + v * (b1 + v * b2);
    lo = inside ? (q < lo ? q : lo) : lo;
    hi = inside ? (hi < q ? q : hi) : hi;
    return (lo > tail) | (hi < -tail);
}

inline V4 half(const V4& v, int) { return v; }
inline V4 min_lanes(V4 a, V4 b) { return b < a ? b : a; }  // std::min(a, b)
#if defined(__AVX512F__)
inline V8 min_lanes(V8 a, V8 b) { return b < a ? b : a; }
inline V4 half(const V8& v, int j) {
    return j ? __builtin_shufflevector(v, v, 4, 5, 6, 7) : __builtin_shufflevector(v, v, 0, 1, 2, 3);
}
#else
inline V4 half(const V8& v, int j) { return j ? v.b : v.a; }
inline V8 min_lanes(V8 a, V8 b) { return {min_lanes(a.a, b.a), min_lanes(a.b, b.b)}; }
#endif

template <class V, int L>
void expand(const detail::TaylorModel& m, const double* const* y, const double* hmax, const detail::TaylorLaneRule* rule,
            int count, double* cbuf, detail::TaylorStep* out) {
    // The coefficients go straight to the caller's lane-interleaved rows (where events read them);
    // the work rows and the evaluation's are on the stack (about 19 kB for eight lanes), nothing
    // read before it is written (taylor_series
    // fills orders 1 .. p from 0 and its own work rows). A General coupling's powers (up to 110 kB)
    // live in a buffer of the thread's, grown once.
    detail::TaylorSeries<V> S;
    S.c = reinterpret_cast<V(*)[detail::kTaylorStride]>(cbuf);
    if (m.ckind == detail::CKind::General) {
        thread_local std::vector<V> pow;
        const std::size_t rows = std::size_t(m.deg1 + 1 + m.deg2 + 1 + m.grad.rows - 3) * detail::kTaylorStride;
        if (pow.size() < rows) pow.resize(rows);
        S.pow1 = pow.data();
        S.pow2 = pow.data() + std::size_t(m.deg1 + 1) * detail::kTaylorStride;
        S.prog = pow.data() + std::size_t(m.deg1 + 1 + m.deg2 + 1) * detail::kTaylorStride;
    }
    V hm, floor, factor;
    for (int l = 0; l < L; ++l) {
        const int src = l < count ? l : 0;  // idle lanes repeat lane 0
        for (int i = 0; i < m.nv; ++i) S.c[i][0][l] = y[src][i];
        hm[l] = hmax[src];
        floor[l] = rule[src].scale_floor;
        factor[l] = rule[src].factor;
    }
    detail::taylor_series(m, S);
    V h;
    I4 ok[L / 4];
    for (int j = 0; j < L / 4; ++j) {
        const V4 hj = step_rule(m, half(floor, j), half(factor, j), [&](int i, int k) { return half(S.c[i][k], j); },
                                &ok[j]);
        for (int l = 0; l < 4; ++l) h[4 * j + l] = hj[l];
    }
    const V tau = min_lanes(h, hm);
    I4 keeps[2][L / 4];
    for (int w = 0; w < 2; ++w)
        for (int j = 0; j < L / 4; ++j)
            keeps[w][j] = 2 * w + 1 < m.n ? keeps_sign([&](int k) { return half(S.c[2 * w + 1][k], j); }, m.p, half(tau, j))
                                          : I4{};
    V ye[detail::kMaxDim];
    detail::estrin<V>([&](int i, int k) { return S.c[i][k]; }, m.nv, m.p, tau, ye);
    for (int l = 0; l < count; ++l) {
        detail::TaylorStep& o = out[l];
        o.h = h[l];
        o.tau = tau[l];
        for (int i = 0; i < m.nv; ++i) o.y[i] = ye[i][l];
        o.ok = ok[l / 4][l % 4] != 0;
        for (int w = 0; w < 2; ++w) o.keeps_sign[w] = keeps[w][l / 4][l % 4] != 0;
    }
}

}  // namespace

}  // namespace hovering::HOVERING_TAYLOR_NS

extern "C" const hovering::detail::TaylorLaneKernels HOVERING_TAYLOR_TABLE = {
    hovering::detail::kSimdLevel,
    &hovering::HOVERING_TAYLOR_NS::expand<hovering::HOVERING_TAYLOR_NS::V4, 4>,
    &hovering::HOVERING_TAYLOR_NS::expand<hovering::HOVERING_TAYLOR_NS::V8, 8>};
