// Taylor's method for the flow's field: see taylor.hpp.

#include "hovering/flow/taylor.hpp"

#include <algorithm>
#include <cmath>
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
    // Jorba & Zou's order for the tolerance: the truncation error of the p-th order polynomial at
    // their step is ~ tol.
    m_.p = std::clamp(int(std::ceil(1.0 - 0.5 * std::log(rtol))), 2, kMaxTaylorOrder);
    factor_ = std::exp(-2.0 - 0.7 / (m_.p - 1));
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
    // rho = min_j (scale / ||x_j||)^(1/j), j = p - 1, p, in logarithms: two logs and one exp
    // instead of two pows.
    const double ls = std::log(std::max(norm0, scale_floor_));
    double lrho = std::numeric_limits<double>::infinity();
    if (normp1 > 0) lrho = std::min(lrho, (ls - std::log(normp1)) / (p - 1));
    if (normp > 0) lrho = std::min(lrho, (ls - std::log(normp)) / p);
    // Jorba & Zou's safety factors: e^-2 from the Cauchy estimate of the remainder, and
    // exp(-0.7 / (p - 1)) for the coefficients beyond p that the estimate does not see.
    *h = h_ = std::exp(lrho) * factor_;
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
