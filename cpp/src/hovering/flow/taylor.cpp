// Taylor's method for the flow's field: see taylor.hpp.

#include "hovering/flow/taylor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "hovering/detail/common.hpp"
#include "hovering/detail/simd_dispatch.hpp"
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

// The builds of the lane kernel, in the dispatch's order (detail/simd_dispatch.hpp): the level the
// core runs is the truncated map's too.
const TaylorLaneKernels* const kTaylorBuilds[kSimdBuilds] = {
    &hovering_taylor_base,
#if defined(HOVERING_LANES_DISPATCH)
    &hovering_taylor_avx2,
    &hovering_taylor_avx512,
#endif
};

const TaylorLaneKernels& lane_kernels() {
    return selected_build(kTaylorBuilds);
}

}  // namespace

void Taylor::expand_group(Taylor* const* t, const double* const* y, const double* hmax, TaylorLanes& lanes,
                          int count) {
    TaylorStep out[kMaxTaylorGroup] = {};  // y beyond dim is not written, but copied
    const TaylorLaneKernels& k = lane_kernels();
    const int width = count <= 4 ? 4 : 8;
    ++lanes.round;  // first: were the kernel ever to throw midway, no lane would trust its rows
    // One model for the call (t[0]'s: every lane's but for the step rule's numbers, rule[l]).
    TaylorLaneRule rule[kMaxTaylorGroup];
    for (int l = 0; l < count; ++l) rule[l] = {t[l]->m_.scale_floor, t[l]->m_.factor};
    (width == 4 ? k.expand4 : k.expand8)(t[0]->m_, y, hmax, rule, count, lanes.c, out);
    for (int l = 0; l < count; ++l) t[l]->take(&lanes, l, width, out[l]);
}

void Taylor::take(const TaylorLanes* buf, int lane, int width, const TaylorStep& st) {
    buf_ = buf;
    round_ = buf->round;
    c_ = buf->c + lane;
    width_ = width;
    step_ = st;
    valid_ = st.ok;
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

Taylor::Taylor(const Field& f, const FlowSystem& s, double rtol, double atol, int order) {
    const std::string why = taylor_unsupported(s);
    if (!why.empty()) bad(why);
    m_.n = f.state;  // the step rule reads the state only: tangents do not change the steps
    m_.nt = f.tangents;
    m_.nv = f.dim;
    // The order for the tolerance: the truncation error of the p-th order polynomial at the step
    // f rho is ~ f^p = tol.
    m_.p = std::clamp(int(std::ceil(1.0 + std::log(rtol) / kLogStepFraction)), 2, kMaxTaylorOrder);
    // A coupling term q1^i q2^j makes the coefficients grow for orders up to ~ i + j before the
    // geometric decay that the step rule extrapolates from the last two sets in: below that order
    // the radius is overestimated (a degree-20 coupling at rtol 1e-6, order 13: 8e-3 in the return
    // time, rk8pd 3e-6). The order is at least the coupling's degree + 4.
    int degree = 0;
    if (f.ckind == CKind::General)
        for (const auto& t : s.coupling.terms) degree = std::max(degree, int(t[1] + t[2]));
    m_.p = std::clamp(std::max(order > 0 ? order : m_.p, degree + 4), 2, kMaxTaylorOrder);
    m_.scale_floor = atol / rtol;
    // A given order below the tolerance's takes shorter steps: f^(p - 1) = rtol.
    const double log_f = std::min(kLogStepFraction, std::log(rtol) / (m_.p - 1));
    m_.factor = std::exp(log_f - 0.7 / (m_.p - 1));
    const Force* forces[2] = {&f.f1, &f.f2};
    for (int i = 0; i < 2; ++i) {
        m_.kind[i] = forces[i]->kind;
        m_.a[i] = forces[i]->a;
        m_.aux[i] = forces[i]->aux;
        m_.b[i] = forces[i]->b;
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
}

bool Taylor::expand(const double* y0, double hmax, double* h) {
    // One orbit takes the 4-lane kernel: latency-bound, it costs about what a scalar build would,
    // and there is one implementation of the recurrences, the step rule and the evaluation.
    // Allocated at first use, uninitialised (the kernel writes before anything reads): a lane of a
    // group may never expand alone, and a return map of one point builds eight lanes.
    if (!own_) own_.reset(new TaylorLanes);
    TaylorStep out{};
    ++own_->round;
    const TaylorLaneRule rule{m_.scale_floor, m_.factor};
    lane_kernels().expand4(m_, &y0, &hmax, &rule, 1, own_->c, &out);
    take(own_.get(), 0, 4, out);
    *h = step_.h;
    return valid_;
}

bool Taylor::expanded_at(const double* y0, double* h) const {
    if (!valid_ || buf_->round != round_) return false;
    for (int i = 0; i < m_.nv; ++i)
        if (c_[std::size_t(i) * kTaylorStride * std::size_t(width_)] != y0[i]) return false;
    if (h) *h = step_.h;
    return true;
}

void Taylor::eval(double tau, double* y) const {
    if (!valid_ || buf_->round != round_) {  // no caller does this: every one checks expanded_at first
        for (int i = 0; i < m_.nv; ++i) y[i] = std::numeric_limits<double>::quiet_NaN();
        return;
    }
    if (tau == step_.tau) {  // the step's end, evaluated in the lanes already (the same bits)
        for (int i = 0; i < m_.nv; ++i) y[i] = step_.y[i];
        return;
    }
    const double* c = c_;
    const std::size_t w = std::size_t(width_);
    estrin<double>([c, w](int i, int k) { return c[(std::size_t(i) * kTaylorStride + std::size_t(k)) * w]; }, m_.nv,
                   m_.p, tau, y);
}

bool Taylor::scaled_coefficients(int i, double h, double* out) const {
    if (!valid_ || buf_->round != round_) return false;
    const std::size_t w = std::size_t(width_);
    double hk = 1;
    for (int k = 0; k <= m_.p; ++k) {
        out[k] = c_[(std::size_t(i) * kTaylorStride + std::size_t(k)) * w] * hk;
        hk *= h;
    }
    return true;
}

}  // namespace hovering::detail
