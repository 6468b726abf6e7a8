// Taylor's method for the flow's field: see taylor.hpp.

#include "hovering/flow/taylor.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

#include "hovering/detail/common.hpp"
#include "hovering/flow/exact.hpp"

namespace hovering::detail {

namespace {

// sum_{j=0}^{k} a_j b_{k-j}: the k-th coefficient of a product of series. Four partial sums:
// one running sum is a chain of dependent additions (4 cycles each), and these short sums are
// the whole cost of a step.
inline double cauchy(const double* a, const double* b, int k) {
    double r0 = 0, r1 = 0, r2 = 0, r3 = 0;
    int j = 0;
    for (; j + 3 <= k; j += 4) {
        r0 += a[j] * b[k - j];
        r1 += a[j + 1] * b[k - j - 1];
        r2 += a[j + 2] * b[k - j - 2];
        r3 += a[j + 3] * b[k - j - 3];
    }
    for (; j <= k; ++j) r0 += a[j] * b[k - j];
    return (r0 + r1) + (r2 + r3);
}

// The k-th coefficient of a^2: the symmetric half of the sum, doubled.
inline double cauchy_square(const double* a, int k) {
    const int half = (k + 1) / 2;
    double r0 = 0, r1 = 0;
    int j = 0;
    for (; j + 1 < half; j += 2) {
        r0 += a[j] * a[k - j];
        r1 += a[j + 1] * a[k - j - 1];
    }
    for (; j < half; ++j) r0 += a[j] * a[k - j];
    double r = 2 * (r0 + r1);
    if (k % 2 == 0) r += a[k / 2] * a[k / 2];
    return r;
}

const Potential* unwrap(const Potential* v) {
    while (const auto* w = dynamic_cast<const Numerical*>(v)) v = w->base().get();
    return v;
}

}  // namespace

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

Taylor::Taylor(const Field& f, const FlowSystem& s, double rtol, double atol)
    : n_(f.dim), scale_floor_(atol / rtol), eps_(s.eps), ckind_(f.ckind), bilinear_c_(f.bilinear_c) {
    const std::string why = taylor_unsupported(s);
    if (!why.empty()) bad(why);
    // Jorba & Zou's order for the tolerance: the truncation error of the p-th order polynomial at
    // their step is ~ tol.
    p_ = std::clamp(int(std::ceil(1.0 - 0.5 * std::log(rtol))), 2, kMaxTaylorOrder);
    const Force* forces[2] = {&f.f1, &f.f2};
    for (int i = 0; i < 2; ++i) {
        Osc& o = osc_[i];
        o.kind = forces[i]->kind;
        o.a = forces[i]->a;
        o.b = forces[i]->b;
        o.q = 2 * i;
        o.p = 2 * i + 1;
        o.aux = forces[i]->aux;
    }
    if (ckind_ == CKind::General) {
        terms_ = s.coupling.terms;
        for (const auto& t : terms_) {
            deg1_ = std::max(deg1_, int(t[1]));
            deg2_ = std::max(deg2_, int(t[2]));
        }
        pow1_.assign(std::size_t(deg1_ + 1) * (kMaxTaylorOrder + 1), 0.0);
        pow2_.assign(std::size_t(deg2_ + 1) * (kMaxTaylorOrder + 1), 0.0);
        pow1_[0] = pow2_[0] = 1.0;  // q^0 = 1: the constant series
    }
    std::memset(c_, 0, sizeof c_);
    for (int k = 0; k < kMaxTaylorOrder; ++k) {
        inv_[k] = 1.0 / (k + 1);
        for (int i = 0; i < 2; ++i) binv_[i][k] = osc_[i].b / (k + 1);
    }
    coefficients_ = osc_[0].kind == Kind::Tan ? pick<Kind::Tan>(osc_[1].kind, ckind_)
                                              : pick<Kind::Harmonic>(osc_[1].kind, ckind_);
}

template <Kind K1, Kind K2, CKind C>
void Taylor::coefficients() {
    // Compile-time kinds: the order loop is a straight sequence of short Cauchy sums.
    constexpr int P = kMaxTaylorOrder + 1;
    constexpr Kind kinds[2] = {K1, K2};
    for (int k = 0; k < p_; ++k) {
        if constexpr (C == CKind::General) {
            // Powers of q1, q2 up to the degrees the gradient needs (q^1 is the state's own series).
            for (int m = 1; m <= deg1_; ++m)
                pow1_[std::size_t(m * P + k)] = m == 1 ? c_[0][k] : cauchy(&pow1_[std::size_t((m - 1) * P)], c_[0], k);
            for (int m = 1; m <= deg2_; ++m)
                pow2_[std::size_t(m * P + k)] = m == 1 ? c_[2][k] : cauchy(&pow2_[std::size_t((m - 1) * P)], c_[2], k);
            double g1 = 0, g2 = 0;
            for (const auto& t : terms_) {
                const int i = int(t[1]), j = int(t[2]);
                // d/dq1 c q1^i q2^j = c i q1^(i-1) q2^j; a zero exponent's power is the constant series.
                if (i > 0) g1 += t[0] * i * cauchy(&pow1_[std::size_t((i - 1) * P)], &pow2_[std::size_t(j * P)], k);
                if (j > 0) g2 += t[0] * j * cauchy(&pow1_[std::size_t(i * P)], &pow2_[std::size_t((j - 1) * P)], k);
            }
            g_[0][k] = eps_ * g1;
            g_[1][k] = eps_ * g2;
        } else if constexpr (C == CKind::Bilinear) {
            g_[0][k] = eps_ * bilinear_c_ * c_[2][k];
            g_[1][k] = eps_ * bilinear_c_ * c_[0][k];
        }
        const double inv = inv_[k];
        for (int i = 0; i < 2; ++i) {
            const Osc& o = osc_[i];
            double force;
            if (kinds[i] == Kind::Tan) {
                // w = 1 + u^2, du/dt = b w p, force a u w. The order loop is bound by latency:
                // each order waits for the last one's coefficients. So every sum adds its old
                // terms first (they are ready early and overlap the previous order's tail) and
                // the newest last: u_k in w_k's sum; w_k, p_k, u_k and w_{k-1} in the products.
                const double* u = c_[o.aux];
                const double* q = c_[o.p];
                double* w = w_[i];
                double a0 = 0, a1 = 0, b0 = 0, b1 = 0, s0 = 0, s1 = 0;
                int j = 1;
                for (; j + 1 <= k - 2; j += 2) {
                    a0 += w[j] * q[k - j];
                    b0 += w[j] * u[k - j];
                    a1 += w[j + 1] * q[k - j - 1];
                    b1 += w[j + 1] * u[k - j - 1];
                }
                for (; j <= k - 2; ++j) {
                    a0 += w[j] * q[k - j];
                    b0 += w[j] * u[k - j];
                }
                const int half = (k + 1) / 2;
                for (j = 1; j + 1 < half; j += 2) {
                    s0 += u[j] * u[k - j];
                    s1 += u[j + 1] * u[k - j - 1];
                }
                for (; j < half; ++j) s0 += u[j] * u[k - j];
                double sq = 2 * (s0 + s1);
                if (k % 2 == 0 && k > 0) sq += u[k / 2] * u[k / 2];
                double A = a0 + a1, B = b0 + b1;
                if (k >= 2) {
                    A += w[k - 1] * q[1];
                    B += w[k - 1] * u[1];
                }
                if (k >= 1) {
                    A += w[0] * q[k];
                    B += w[0] * u[k];
                }
                const double wk = k == 0 ? 1 + u[0] * u[0] : sq + two_u0_[i] * u[k];
                w[k] = wk;
                force = o.a * (B + u[0] * wk);
                c_[o.aux][k + 1] = (A + wk * q[0]) * binv_[i][k];
            } else {
                force = o.a * c_[o.q][k];
            }
            if constexpr (C != CKind::None) force += g_[i][k];
            c_[o.q][k + 1] = c_[o.p][k] * inv;
            c_[o.p][k + 1] = -force * inv;
        }
    }
}

template <Kind K1>
Taylor::Coefficients Taylor::pick(Kind k2, CKind c) {
    auto with = [&](auto k2c) -> Coefficients {
        constexpr Kind K2 = decltype(k2c)::value;
        return c == CKind::None       ? &Taylor::coefficients<K1, K2, CKind::None>
               : c == CKind::Bilinear ? &Taylor::coefficients<K1, K2, CKind::Bilinear>
                                      : &Taylor::coefficients<K1, K2, CKind::General>;
    };
    return k2 == Kind::Tan ? with(std::integral_constant<Kind, Kind::Tan>{})
                           : with(std::integral_constant<Kind, Kind::Harmonic>{});
}

bool Taylor::expand(const double* y0, double* h) {
    for (int i = 0; i < n_; ++i) c_[i][0] = y0[i];
    for (int i = 0; i < 2; ++i)
        if (osc_[i].aux >= 0) two_u0_[i] = 2 * y0[osc_[i].aux];
    (this->*coefficients_)();
    double norm0 = 0, normp1 = 0, normp = 0;
    bool finite = true;
    for (int i = 0; i < n_; ++i) {
        norm0 = std::max(norm0, std::fabs(c_[i][0]));
        normp1 = std::max(normp1, std::fabs(c_[i][p_ - 1]));
        normp = std::max(normp, std::fabs(c_[i][p_]));
        // A non-finite coefficient reaches every later one (each is a sum over all below it).
        finite = finite && std::isfinite(c_[i][p_ - 1]) && std::isfinite(c_[i][p_]);
    }
    if (!finite) return false;
    // rho = min_j (scale / ||x_j||)^(1/j), j = p - 1, p, in logarithms: two logs and one exp
    // instead of two pows (a fifth of a step's time at low orders).
    const double ls = std::log(std::max(norm0, scale_floor_));
    double lrho = std::numeric_limits<double>::infinity();
    if (normp1 > 0) lrho = std::min(lrho, (ls - std::log(normp1)) / (p_ - 1));
    if (normp > 0) lrho = std::min(lrho, (ls - std::log(normp)) / p_);
    // Jorba & Zou's safety factors: e^-2 from the Cauchy estimate of the remainder, and
    // exp(-0.7 / (p - 1)) for the coefficients beyond p that the estimate does not see.
    *h = std::exp(lrho - 2.0 - 0.7 / (p_ - 1));
    return true;
}

bool Taylor::expanded_at(const double* y0) const {
    for (int i = 0; i < n_; ++i)
        if (c_[i][0] != y0[i]) return false;
    return true;
}

void Taylor::eval(double tau, double* y) const {
    // Horner with the variables innermost: their chains are independent and overlap.
    double r[kMaxDim];
    for (int i = 0; i < n_; ++i) r[i] = c_[i][p_];
    for (int k = p_ - 1; k >= 0; --k)
        for (int i = 0; i < n_; ++i) r[i] = r[i] * tau + c_[i][k];
    for (int i = 0; i < n_; ++i) y[i] = r[i];
}

void Taylor::eval_derivative(double tau, double* dy) const {
    for (int i = 0; i < n_; ++i) {
        double r = p_ * c_[i][p_];
        for (int k = p_ - 1; k >= 1; --k) r = r * tau + k * c_[i][k];
        dy[i] = r;
    }
}

}  // namespace hovering::detail
