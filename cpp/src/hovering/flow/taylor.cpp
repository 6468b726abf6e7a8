// Taylor's method for the flow's field: see taylor.hpp.

#include "hovering/flow/taylor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "hovering/detail/common.hpp"
#include "hovering/detail/simd_level.hpp"
#include "hovering/flow/exact.hpp"

// The builds of taylor_lanes.cpp (see there and CMakeLists.txt).
extern "C" {
extern const hovering::detail::TaylorLaneKernels hovering_taylor_base;
#if defined(HOVERING_LANES_DISPATCH)
extern const hovering::detail::TaylorLaneKernels hovering_taylor_avx2;
extern const hovering::detail::TaylorLaneKernels hovering_taylor_avx512;
#endif
}

namespace hovering::detail {

namespace {

const Potential* unwrap(const Potential* v) {
    while (const auto* w = dynamic_cast<const Numerical*>(v)) v = w->base().get();
    return v;
}

// log2 to ~3e-3 and exp2 to ~2e-5, for the step rule only: libm's log and exp took 15% of a
// return's time (three logs and an exp per step), and a step length needs less. An error d in a
// log2 changes the step's truncation error by a factor 2^(2 d) (< 1.01); an error e in exp2 by
// (1 + e)^p (< 1.001 at p <= 40). Both are fixed functions of their argument's bits, so every
// lane and instruction set agrees.
double fast_log2(double x) {
    std::uint64_t b;
    std::memcpy(&b, &x, sizeof b);
    int e = int((b >> 52) & 0x7ff) - 1023;
    b = (b & 0x000fffffffffffffULL) | 0x3ff0000000000000ULL;  // mantissa in [1, 2)
    double m;
    std::memcpy(&m, &b, sizeof m);
    if (m > 1.4142135623730951) {  // to [sqrt(1/2), sqrt(2)): |m - 1| <= 0.42
        m *= 0.5;
        ++e;
    }
    // ln(1 + z), |z| <= 0.42: the series to z^5 is within 2e-3 (ln 2 times that in log2).
    const double z = m - 1;
    const double ln = z * (1 + z * (-0.5 + z * (1.0 / 3 + z * (-0.25 + z * 0.2))));
    return e + ln * 1.4426950408889634;
}

double fast_exp2(double x) {
    if (!(x < 1023)) return x != x ? x : std::numeric_limits<double>::infinity();
    if (x < -1022) return 0.0;
    const double n = std::floor(x);
    const double y = (x - n) * 0.6931471805599453;  // 2^(x - n) = e^y, y in [0, ln 2): to y^6, 2e-5
    const double ey = 1 + y * (1 + y * (0.5 + y * (1.0 / 6 + y * (1.0 / 24 + y * (1.0 / 120 + y / 720)))));
    const std::uint64_t b = std::uint64_t(int(n) + 1023) << 52;
    double two_n;
    std::memcpy(&two_n, &b, sizeof two_n);
    return ey * two_n;
}

template <int N>
void horner(const double (*c)[kTaylorStride], int p, double tau, double* y) {
    // Estrin's scheme: pairs c_k + c_{k+1} tau, then pairs of pairs with tau^2, tau^4, ...: a
    // dependency chain of depth log2(p) instead of Horner's p (at orders 20-30 Horner's chain,
    // not the arithmetic, set the cost), the variables innermost so that their work overlaps.
    double a[N][kTaylorStride];
    int m = p + 1;
    for (int k = 0; k < m / 2; ++k)
        for (int i = 0; i < N; ++i) a[i][k] = c[i][2 * k] + c[i][2 * k + 1] * tau;
    if (m % 2)
        for (int i = 0; i < N; ++i) a[i][m / 2] = c[i][m - 1];
    m = (m + 1) / 2;
    double t = tau * tau;
    while (m > 1) {
        for (int k = 0; k < m / 2; ++k)
            for (int i = 0; i < N; ++i) a[i][k] = a[i][2 * k] + a[i][2 * k + 1] * t;
        if (m % 2)
            for (int i = 0; i < N; ++i) a[i][m / 2] = a[i][m - 1];
        m = (m + 1) / 2;
        t *= t;
    }
    for (int i = 0; i < N; ++i) y[i] = a[i][0];
}

// The build of the 4-orbit kernel for the SIMD level the core runs (the truncated map's choice:
// one owner of HOVERING_SIMD and set_simd_level), looked up once per thread and level.
const TaylorLaneKernels& lane_kernels() {
    thread_local const char* level = nullptr;
    thread_local const TaylorLaneKernels* k = &hovering_taylor_base;
    const char* now = selected_simd_level();
    if (now != level) {  // the level names are static strings: a pointer compare per call
        level = now;
        k = &hovering_taylor_base;
#if defined(HOVERING_LANES_DISPATCH)
        if (std::strcmp(level, hovering_taylor_avx2.level) == 0) k = &hovering_taylor_avx2;
        if (std::strcmp(level, hovering_taylor_avx512.level) == 0) k = &hovering_taylor_avx512;
#endif
    }
    return *k;
}

}  // namespace

const char* taylor_lane_level() {
    return lane_kernels().level;
}

void Taylor::expand_group(Taylor* const* t, const double* const* y, double* h, bool* ok, int count) {
    if (count == 1) {
        ok[0] = t[0]->expand(y[0], &h[0]);
        return;
    }
    double* out[kMaxTaylorGroup];
    for (int l = 0; l < count; ++l) out[l] = &t[l]->work_.c[0][0];
    const TaylorLaneKernels& k = lane_kernels();
    (count <= 4 ? k.expand4 : k.expand8)(t[0]->m_, y, count, out);
    for (int l = 0; l < count; ++l) ok[l] = t[l]->finish(&h[l]);
}

std::string taylor_unsupported(const FlowSystem& s) {
    for (const Potential* v : {s.V1.get(), s.V2.get()}) {
        const Potential* b = unwrap(v);
        if (!dynamic_cast<const Harmonic*>(b) && !dynamic_cast<const Tan*>(b))
            return "stepper 'taylor' needs V1 and V2 each Harmonic or Tan (a field polynomial in the state, "
                   "whose Taylor coefficients follow from recurrences); the system has " +
                   describe(s) + " (use a GSL stepper such as 'rk8pd')";
    }
    return "";
}

Taylor::Taylor(const Field& f, const FlowSystem& s, double rtol, double atol) : scale_floor_(atol / rtol) {
    const std::string why = taylor_unsupported(s);
    if (!why.empty()) bad(why);
    m_.n = f.dim;
    // The order for the tolerance: the truncation error of the p-th order polynomial at the step
    // f rho is ~ f^p = tol.
    m_.p = std::clamp(int(std::ceil(1.0 + std::log(rtol) / kLogStepFraction)), 2, kMaxTaylorOrder);
    factor_ = std::exp(kLogStepFraction - 0.7 / (m_.p - 1));
    const Force* forces[2] = {&f.f1, &f.f2};
    for (int i = 0; i < 2; ++i) {
        m_.kind[i] = forces[i]->kind;
        m_.a[i] = forces[i]->a;
        m_.aux[i] = forces[i]->aux;
        for (int k = 0; k < kMaxTaylorOrder; ++k) m_.binv[i][k] = forces[i]->b / (k + 1);
    }
    for (int k = 0; k < kMaxTaylorOrder; ++k) m_.inv[k] = 1.0 / (k + 1);
    m_.eps = s.eps;
    m_.ckind = f.ckind;
    m_.bilinear_c = f.bilinear_c;
    if (m_.ckind == CKind::General) {
        m_.terms = s.coupling.terms;
        for (const auto& t : m_.terms) {
            m_.deg1 = std::max(m_.deg1, int(t[1]));
            m_.deg2 = std::max(m_.deg2, int(t[2]));
        }
        pow_.assign(std::size_t(m_.deg1 + 1 + m_.deg2 + 1) * kTaylorStride, 0.0);
        work_.pow1 = pow_.data();
        work_.pow2 = pow_.data() + std::size_t(m_.deg1 + 1) * kTaylorStride;
    }
    std::memset(work_.c, 0, sizeof work_.c);
}

bool Taylor::expand(const double* y0, double* h) {
    for (int i = 0; i < m_.n; ++i) work_.c[i][0] = y0[i];
    taylor_series(m_, work_);
    return finish(h);
}

bool Taylor::finish(double* h) {
    const int p = m_.p;
    double norm0 = 0, normp1 = 0, normp = 0;
    bool finite = true;
    for (int i = 0; i < m_.n; ++i) {
        norm0 = std::max(norm0, std::fabs(work_.c[i][0]));
        normp1 = std::max(normp1, std::fabs(work_.c[i][p - 1]));
        normp = std::max(normp, std::fabs(work_.c[i][p]));
        // A non-finite coefficient reaches every later one (each is a sum over all below it).
        finite = finite && std::isfinite(work_.c[i][p - 1]) && std::isfinite(work_.c[i][p]);
    }
    valid_ = finite;
    if (!finite) return false;
    // rho = min_j (scale / ||x_j||)^(1/j), j = p - 1, p, in base-2 logarithms.
    const double ls = fast_log2(std::max(norm0, scale_floor_));
    double lrho = std::numeric_limits<double>::infinity();
    if (normp1 > 0) lrho = std::min(lrho, (ls - fast_log2(normp1)) * m_.inv[p - 2]);
    if (normp > 0) lrho = std::min(lrho, (ls - fast_log2(normp)) * m_.inv[p - 1]);
    // The step fraction f and Jorba & Zou's exp(-0.7 / (p - 1)) for the coefficients beyond p that
    // the estimate does not see (factor_).
    *h = h_ = fast_exp2(lrho) * factor_;
    return true;
}

bool Taylor::expanded_at(const double* y0, double* h) const {
    if (!valid_) return false;
    for (int i = 0; i < m_.n; ++i)
        if (work_.c[i][0] != y0[i]) return false;
    if (h) *h = h_;
    return true;
}

void Taylor::eval(double tau, double* y) const {
    switch (m_.n) {
        case 4:
            return horner<4>(work_.c, m_.p, tau, y);
        case 5:
            return horner<5>(work_.c, m_.p, tau, y);
        default:
            return horner<6>(work_.c, m_.p, tau, y);
    }
}

}  // namespace hovering::detail
