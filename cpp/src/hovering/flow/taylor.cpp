// Taylor's method for the flow's field: see taylor.hpp.

#include "hovering/flow/taylor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <map>
#include <string>
#include <vector>

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

// A gradient program under construction (CouplingProgram): rows for the powers of q1, q2 made on
// demand and shared.
struct ProgramBuilder {
    CouplingProgram g;
    std::map<std::pair<int, int>, int> power;  // (variable 0 or 1, exponent >= 2) -> row
    int products = 0;

    int new_row() {
        if (g.rows >= kMaxProgramRows) bad("coupling: its gradient needs more than " + std::to_string(kMaxProgramRows) +
                                           " series rows (internal limit)");
        return g.rows++;
    }
    // The row of q_(var+1)^e (e >= 0: row 0 is the constant 1).
    int pow_row(int var, int e) {
        if (e == 0) return 0;
        if (e == 1) return 1 + var;
        auto it = power.find({var, e});
        if (it != power.end()) return it->second;
        // q^e = q^(e/2)^2 (a square) for even e, q^(e-1) q for odd: ~log2(e) squares.
        const int a = e % 2 == 0 ? pow_row(var, e / 2) : pow_row(var, e - 1);
        const int b = e % 2 == 0 ? a : 1 + var;
        const int r = new_row();
        g.ops.push_back({true, r, a, b, 0, 0});
        ++products;
        power[{var, e}] = r;
        return r;
    }
    int product(int a, int b) {
        const int r = new_row();
        g.ops.push_back({true, r, a, b, 0, 0});
        ++products;
        return r;
    }
    int sum(const std::vector<std::pair<double, int>>& t) {
        const int r = new_row();
        g.ops.push_back({false, r, 0, 0, int(g.terms.size()), int(t.size())});
        g.terms.insert(g.terms.end(), t.begin(), t.end());
        return r;
    }
    // The row of sum c q1^a q2^b over terms ((a, b) -> c): the common factor q1^a0 q2^b0 times
    // the rest in Horner form in q_(var+1).
    int component(const std::map<std::pair<int, int>, double>& terms, int var) {
        if (terms.empty()) return sum({});
        int lo[2] = {1 << 30, 1 << 30};
        for (const auto& [e, c] : terms) {
            lo[0] = std::min(lo[0], e.first);
            lo[1] = std::min(lo[1], e.second);
        }
        // P_l: (coefficient, power of the other variable) of x^l.
        std::vector<std::vector<std::pair<double, int>>> P;
        for (const auto& [e, c] : terms) {
            const int ex[2] = {e.first - lo[0], e.second - lo[1]};
            if (int(P.size()) <= ex[var]) P.resize(std::size_t(ex[var]) + 1);
            P[std::size_t(ex[var])].push_back({c, ex[1 - var]});
        }
        auto level = [&](int l) {  // P_l's (coefficient, row) terms
            std::vector<std::pair<double, int>> t;
            for (const auto& [c, e] : P[std::size_t(l)]) t.push_back({c, pow_row(1 - var, e)});
            return t;
        };
        const int L = int(P.size()) - 1;
        // S_L, and the constant it may be (then x S_L is a sum term, not a product).
        bool constant = std::all_of(P.back().begin(), P.back().end(), [](const auto& t) { return t.second == 0; });
        double c_last = 0;
        for (const auto& t : P.back()) c_last += t.first;
        int S = constant && L > 0 ? -1 : sum(level(L));
        for (int l = L - 1; l >= 0; --l) {
            std::vector<std::pair<double, int>> t = level(l);
            if (S < 0)
                t.push_back({c_last, 1 + var});
            else
                t.push_back({1.0, product(1 + var, S)});
            S = sum(t);
        }
        if (lo[0] > 0) S = product(pow_row(0, lo[0]), S);
        if (lo[1] > 0) S = product(pow_row(1, lo[1]), S);
        return S;
    }
};

// The terms ((a, b) -> c) of dVc/dq_i = sum c q1^a q2^b (like powers merged, zeros dropped).
std::map<std::pair<int, int>, double> gradient_terms(const std::vector<std::array<double, 3>>& vc, int i) {
    std::map<std::pair<int, int>, double> g;
    for (const auto& t : vc) {
        const int a = int(t[1]), b = int(t[2]);
        if (i == 0 && a > 0) g[{a - 1, b}] += t[0] * a;
        if (i == 1 && b > 0) g[{a, b - 1}] += t[0] * b;
    }
    for (auto it = g.begin(); it != g.end();) it = it->second == 0 ? g.erase(it) : std::next(it);
    return g;
}

// The gradient program of Vc = sum c q1^i q2^j with the fewest Cauchy products over the four
// choices of Horner variable (one per component).
CouplingProgram gradient_program(const std::vector<std::array<double, 3>>& vc) {
    const std::map<std::pair<int, int>, double> g[2] = {gradient_terms(vc, 0), gradient_terms(vc, 1)};
    CouplingProgram best;
    int fewest = 1 << 30;
    for (int v0 = 0; v0 < 2; ++v0)
        for (int v1 = 0; v1 < 2; ++v1) {
            ProgramBuilder b;
            b.g.grad[0] = b.component(g[0], v0);
            b.g.grad[1] = b.component(g[1], v1);
            if (b.products < fewest) {
                fewest = b.products;
                best = std::move(b.g);
            }
        }
    return best;
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
        if (m_.nt > 0)  // the Hessian's powers (tangent_order)
            for (const auto& t : m_.terms) {
                m_.deg1 = std::max(m_.deg1, int(t[1]));
                m_.deg2 = std::max(m_.deg2, int(t[2]));
            }
        m_.grad = gradient_program(m_.terms);
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

bool Taylor::solve(int i, double off, double lo, double hi, bool lo_above, double guess, double* tau) const {
    if (!valid_ || buf_->round != round_) return false;
    const std::size_t w = std::size_t(width_);
    const double* c = c_ + std::size_t(i) * kTaylorStride * w;
    const int p = m_.p;
    // A polynomial's value and slope by Horner: ~2p flops per iterate where the generic search
    // evaluated every variable and the field (and located only to sqrt(event_tol), then
    // extrapolated): a tenth of a Tan x Tan return with walls went to locating its events.
    // The level is taken off the constant term first, as heyoka does with an event's polynomial:
    // near a root the sum is small, and its rounding then is the small sum's, not |x0|'s (the
    // impact time of a return with a right-wall impact: 1-2e-15 off, 2-4e-15 in p1 after it).
    const double c0 = c[0] - off;
    auto fdf = [&](double t, double* d) {
        double v = c[std::size_t(p) * w], dv = 0;
        for (int k = p - 1; k >= 1; --k) {
            dv = dv * t + v;
            v = v * t + c[std::size_t(k) * w];
        }
        dv = dv * t + v;
        v = v * t + c0;
        *d = dv;
        return v;
    };
    const double scale = std::max(std::fabs(lo), std::fabs(hi));
    double t = guess >= lo && guess <= hi ? guess : 0.5 * (lo + hi);
    for (int it = 0; it < 100; ++it) {
        double d = 0;
        const double f = fdf(t, &d);
        if (f == 0) break;
        ((f > 0) == lo_above ? lo : hi) = t;
        const double tn = d != 0 ? t - f / d : kNaN;
        // Converged: the correction is below rounding of the time (the step's scale).
        if (std::fabs(tn - t) <= 4.5e-16 * scale) {
            t = tn >= lo && tn <= hi ? tn : t;
            break;
        }
        const double next = tn > lo && tn < hi ? tn : 0.5 * (lo + hi);
        if (next == t) break;  // the bracket's ends are neighbours
        t = next;
    }
    *tau = t;
    return std::isfinite(t);
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
