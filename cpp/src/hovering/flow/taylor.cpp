// Taylor's method for the flow's field: see taylor.hpp.

#include "hovering/flow/taylor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>

#include "hovering/detail/common.hpp"
#include "hovering/flow/exact.hpp"
#include "hovering/truncated/map.hpp"

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

// log2 and exp2 to ~1e-7 relative, for the step rule only: a step length is a heuristic, and
// libm's log and exp took 15% of a return's time (three logs and an exp per step). Both are exact
// functions of their argument's bits, so every lane and instruction set agrees.
double fast_log2(double x) {
    std::uint64_t b;
    std::memcpy(&b, &x, sizeof b);
    const int e = int((b >> 52) & 0x7ff) - 1023;
    b = (b & 0x000fffffffffffffULL) | 0x3ff0000000000000ULL;  // mantissa in [1, 2)
    double m;
    std::memcpy(&m, &b, sizeof m);
    // ln(m) = 2 atanh(t), t = (m - 1) / (m + 1), |t| <= 1/3 on [1, 2): the odd series to t^11
    // is within 1e-7.
    const double t = (m - 1) / (m + 1), t2 = t * t;
    const double series = t * (2 + t2 * (2.0 / 3 + t2 * (2.0 / 5 + t2 * (2.0 / 7 + t2 * (2.0 / 9 + t2 * (2.0 / 11))))));
    return e + series * 1.4426950408889634;
}

double fast_exp2(double x) {
    if (!(x < 1023)) return x != x ? x : std::numeric_limits<double>::infinity();
    if (x < -1022) return 0.0;
    const double n = std::floor(x), f = x - n;  // 2^x = 2^n 2^f, f in [0, 1)
    const double y = f * 0.6931471805599453;    // e^y, y in [0, ln 2): Taylor to y^9 within 1e-8
    const double ey =
        1 + y * (1 + y * (0.5 + y * (1.0 / 6 + y * (1.0 / 24 + y * (1.0 / 120 + y * (1.0 / 720 + y * (1.0 / 5040 + y * (1.0 / 40320 + y / 362880))))))));
    std::uint64_t b = std::uint64_t(int(n) + 1023) << 52;
    double two_n;
    std::memcpy(&two_n, &b, sizeof two_n);
    return ey * two_n;
}

template <int N>
void horner(const double (*c)[kTaylorStride], int p, double tau, double* y) {
    // The variables innermost: their chains are independent and overlap.
    double r[N];
    for (int i = 0; i < N; ++i) r[i] = c[i][p];
    for (int k = p - 1; k >= 0; --k)
        for (int i = 0; i < N; ++i) r[i] = r[i] * tau + c[i][k];
    for (int i = 0; i < N; ++i) y[i] = r[i];
}

// The build of the 4-orbit kernel for the SIMD level the core runs (the truncated map's choice:
// one owner of HOVERING_SIMD and set_simd_level), looked up once per thread and level.
const TaylorLaneKernels& lane_kernels() {
    thread_local std::string level;
    thread_local const TaylorLaneKernels* k = &hovering_taylor_base;
    const std::string now = simd_level();
    if (now != level) {
        level = now;
        k = &hovering_taylor_base;
#if defined(HOVERING_LANES_DISPATCH)
        if (level == hovering_taylor_avx2.level) k = &hovering_taylor_avx2;
        if (level == hovering_taylor_avx512.level) k = &hovering_taylor_avx512;
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
    double* out[4];
    for (int l = 0; l < count; ++l) out[l] = &t[l]->work_.c[0][0];
    lane_kernels().expand4(t[0]->m_, y, count, out);
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
    if (normp1 > 0) lrho = std::min(lrho, (ls - fast_log2(normp1)) / (p - 1));
    if (normp > 0) lrho = std::min(lrho, (ls - fast_log2(normp)) / p);
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
