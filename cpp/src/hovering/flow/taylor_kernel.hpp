#pragma once
// The Taylor recurrences of the flow's field and the evaluation of its polynomial (internal),
// written once for a value type V: a vector of 4 or 8 doubles for orbits in lock-step
// (taylor_lanes.cpp, compiled again per instruction set), double for evaluating one orbit's
// polynomial at an event (taylor.cpp). The same operations in the same order on every lane, and no
// contraction into FMAs (-ffp-contract=off), so an orbit's numbers are the same bit for bit alone
// or in a lane group, on any instruction set.

#include <array>
#include <vector>

#include "hovering/flow/field.hpp"

namespace hovering::detail {

/// Highest order the tolerances can ask for (rtol >= 1e-30 gives p <= 36).
inline constexpr int kMaxTaylorOrder = 40;
/// Coefficients stored per variable (orders 0 .. kMaxTaylorOrder).
inline constexpr int kTaylorStride = kMaxTaylorOrder + 1;
/// Highest power of q1 or q2 in a coupling (FlowSystem::validate).
inline constexpr int kMaxCouplingDegree = 20;
/// Most rows a gradient program uses (CouplingProgram; powers and Horner rows of two components
/// of degree <= 2 kMaxCouplingDegree, and the three fixed rows).
inline constexpr int kMaxProgramRows = 8 * kMaxCouplingDegree + 8;

/// One operation of a General coupling's gradient program (CouplingProgram), at one order k on
/// rows of series: a Cauchy product dst = a b (a square when a == b), or a sum dst = sum c_i src_i.
struct CouplingOp {
    bool product = true;  ///< product (a, b) or sum (terms first .. first + count)
    int dst = 0;          ///< the row written
    int a = 0, b = 0;     ///< product: the factors' rows
    int first = 0, count = 0;  ///< sum: its terms in CouplingProgram::terms
};

/// The gradient of a General coupling as a straight-line program over series rows, run once per
/// order: row 0 is the constant series 1, row 1 q1, row 2 q2 (the state's rows), rows 3 .. rows - 1
/// the program's own. Each component dVc/dq_i is written q1^a q2^b S_0 (the common factor) with
/// S_0 in Horner form in q1 or q2 (S_l = P_l + x S_{l+1}, each P_l a sum over powers of the other
/// variable), whichever takes fewer Cauchy products, the powers shared: q1^2 q2 + q1 q2^3 takes
/// 3 products (one a square) where term by term took 5, and its expansion 1.8 -> 1.3 us for eight
/// orbits at order 21 (AVX-512).
struct CouplingProgram {
    std::vector<CouplingOp> ops;                  ///< in order
    std::vector<std::pair<double, int>> terms;    ///< the sums' (coefficient, row)
    int grad[2] = {0, 0};                         ///< rows of dVc/dq1 and dVc/dq2
    int rows = 3;                                 ///< rows used (the three fixed ones included)
};

/// Everything the recurrences read besides the coefficients: fixed per system and tolerance.
struct TaylorModel {
    int n = 4;                                          ///< state dimension (what the step rule reads)
    int nt = 0;                                         ///< tangent vectors after the state (Field)
    int nv = 4;                                         ///< rows expanded: n + 4 nt
    int p = 8;                                          ///< order
    Kind kind[2] = {Kind::Harmonic, Kind::Harmonic};    ///< force kinds (Harmonic or Tan)
    double a[2] = {0, 0};                               ///< Harmonic: omega^2; Tan: omega^2 / alpha
    double b[2] = {0, 0};                               ///< Tan: alpha
    int aux[2] = {-1, -1};                              ///< Tan: index of u = tan(alpha q)
    double eps = 0;                                     ///< coupling strength
    CKind ckind = CKind::None;                          ///< coupling kind
    double bilinear_c = 0;                              ///< Bilinear: the coefficient
    std::vector<std::array<double, 3>> terms;           ///< General: (c, i, j)
    int deg1 = 0, deg2 = 0;                             ///< General with tangents: powers the Hessian needs
    CouplingProgram grad;                               ///< General: the gradient's program
    double inv[kMaxTaylorOrder] = {};                   ///< 1 / (k + 1)
    double binv[2][kMaxTaylorOrder] = {};               ///< Tan: alpha / (k + 1)
    double scale_floor = 1;                             ///< step rule: atol / rtol
    double factor = 0;                                  ///< step rule: exp(ln f - 0.7 / (p - 1))
};

/// The step rule's per-orbit numbers (TaylorModel's), which may differ between the lanes of one
/// kernel call: a verifying trace (a tighter tolerance at the same order) beside the returns.
struct TaylorLaneRule {
    double scale_floor;  ///< atol / rtol
    double factor;       ///< exp(ln f - 0.7 / (p - 1))
};

/// Work arrays of one expansion (V per entry): c points to the state coefficients (the caller's,
/// kMaxDim rows), Tan's w = 1 + u^2, the coupling gradient g, and with tangents V'' of each
/// oscillator (hs) and the coupling's Hessian (hh: h11, h12, h22); for a General coupling pow1, pow2
/// point to (deg + 1) x kTaylorStride entries each for the powers of q1 and q2 (the caller's, sized
/// by TaylorModel::deg1, deg2: the Hessian's, with tangents) and prog to (grad.rows - 3) x
/// kTaylorStride entries for the gradient program's rows.
template <class V>
struct TaylorSeries {
    V (*c)[kTaylorStride] = nullptr;
    V w[2][kTaylorStride];
    V g[2][kTaylorStride];
    V hs[2][kTaylorStride];
    V hh[3][kTaylorStride];
    V* pow1 = nullptr;
    V* pow2 = nullptr;
    V* prog = nullptr;
};

namespace taylor_detail {

// sum_{j=0}^{k} a_j b_{k-j} with four partial sums (shorter dependency chains).
template <class V>
inline V cauchy(const V* a, const V* b, int k, V zero) {
    V r0 = zero, r1 = zero, r2 = zero, r3 = zero;
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

// sum_{j=0}^{k} a_j a_{k-j}: each pair once, doubled (half the products of cauchy(a, a)). The
// newest coefficient a_k (usually this order's) enters last, in 2 a_0 a_k: the old terms' sum
// overlaps the previous order's tail.
template <class V>
inline V square(const V* a, int k, V zero) {
    if (k == 0) return a[0] * a[0];
    V r0 = zero, r1 = zero;
    int j = 1;
    for (; j + 1 < k - j - 1; j += 2) {
        r0 += a[j] * a[k - j];
        r1 += a[j + 1] * a[k - j - 1];
    }
    for (; j < k - j; ++j) r0 += a[j] * a[k - j];
    V r = 2.0 * (r0 + r1);
    if (k % 2 == 0) r += a[k / 2] * a[k / 2];
    return r + 2.0 * (a[0] * a[k]);
}

// Order k of the gradient program (CouplingProgram) on the rows it names. Inlined into the order
// loop, with the two-term sum unrolled (most of a program's sums): the program as a loop of calls
// cost 0.3 us of a 1.6 us expansion (eight orbits, order 21).
template <class V>
__attribute__((always_inline)) inline void run_program(const CouplingProgram& g, V* const* row, int k, V zero) {
    const std::pair<double, int>* terms = g.terms.data();
    for (const CouplingOp& op : g.ops) {
        V v;
        if (op.product) {
            v = op.a == op.b ? square(row[op.a], k, zero) : cauchy(row[op.a], row[op.b], k, zero);
        } else {
            const std::pair<double, int>* t = terms + op.first;
            v = zero;
            if (op.count == 2) {
                v += t[0].first * row[t[0].second][k];
                v += t[1].first * row[t[1].second][k];
            } else {
                for (int i = 0; i < op.count; ++i) v += t[i].first * row[t[i].second][k];
            }
        }
        row[op.dst][k] = v;
    }
}

// Order k of the product q1^i q2^j from the powers' series (pow1, pow2: rows of kTaylorStride).
// q^0 is the constant series 1, whose product with the other power is that power's own
// coefficient: no convolution (a Cauchy product with 1 adds only zeros to it: the same number).
template <class V>
inline V monomial(const V* pow1, const V* pow2, int i, int j, int k, V zero) {
    constexpr int P = kTaylorStride;
    if (j == 0) return pow1[i * P + k];
    if (i == 0) return pow2[j * P + k];
    return cauchy(&pow1[i * P], &pow2[j * P], k, zero);
}

// Order k + 1 of the tangents (rows n .. n + 4 nt) from orders <= k of the state and the tangents:
// d(dq)/dt = dp, d(dp)/dt = -Hess(V) dq, with Hess(V)'s series from the state's (V'' of Tan is
// a b (3 w^2 - 2 w), a product of series again; the coupling's Hessian from the powers of q1, q2).
template <class V, Kind K1, Kind K2, CKind C>
inline void tangent_order(const TaylorModel& m, TaylorSeries<V>& S, int k, V zero) {
    constexpr int P = kTaylorStride;
    constexpr Kind kinds[2] = {K1, K2};
    V (*c)[P] = S.c;
    for (int i = 0; i < 2; ++i)
        if (kinds[i] == Kind::Tan) {
            const V* w = S.w[i];
            S.hs[i][k] = (m.a[i] * m.b[i]) * (3.0 * cauchy(w, w, k, zero) - 2.0 * w[k]);
        }
    if constexpr (C == CKind::General) {
        V h11 = zero, h12 = zero, h22 = zero;
        for (const auto& t : m.terms) {
            const int i = int(t[1]), j = int(t[2]);
            if (i >= 2) h11 += t[0] * (i * (i - 1)) * monomial(S.pow1, S.pow2, i - 2, j, k, zero);
            if (i >= 1 && j >= 1) h12 += t[0] * (i * j) * monomial(S.pow1, S.pow2, i - 1, j - 1, k, zero);
            if (j >= 2) h22 += t[0] * (j * (j - 1)) * monomial(S.pow1, S.pow2, i, j - 2, k, zero);
        }
        S.hh[0][k] = m.eps * h11;
        S.hh[1][k] = m.eps * h12;
        S.hh[2][k] = m.eps * h22;
    }
    const double inv = m.inv[k];
    for (int j = 0; j < m.nt; ++j) {
        const int b = m.n + 4 * j;
        const V* dq1 = c[b];
        const V* dq2 = c[b + 2];
        V f1 = kinds[0] == Kind::Tan ? cauchy(S.hs[0], dq1, k, zero) : m.a[0] * dq1[k];
        V f2 = kinds[1] == Kind::Tan ? cauchy(S.hs[1], dq2, k, zero) : m.a[1] * dq2[k];
        if constexpr (C == CKind::Bilinear) {
            f1 += (m.eps * m.bilinear_c) * dq2[k];
            f2 += (m.eps * m.bilinear_c) * dq1[k];
        } else if constexpr (C == CKind::General) {
            f1 += cauchy(S.hh[0], dq1, k, zero) + cauchy(S.hh[1], dq2, k, zero);
            f2 += cauchy(S.hh[1], dq1, k, zero) + cauchy(S.hh[2], dq2, k, zero);
        }
        c[b][k + 1] = c[b + 1][k] * inv;
        c[b + 1][k + 1] = -f1 * inv;
        c[b + 2][k + 1] = c[b + 3][k] * inv;
        c[b + 3][k + 1] = -f2 * inv;
    }
}

template <class V, Kind K1, Kind K2, CKind C>
void series(const TaylorModel& m, TaylorSeries<V>& S) {
    constexpr int P = kTaylorStride;
    constexpr Kind kinds[2] = {K1, K2};
    const V zero = V{} + 0.0;  // +0 in every lane, for any V
    const int p = m.p;
    V (*c)[P] = S.c;
    V* row[kMaxProgramRows];  // the gradient program's rows (CouplingProgram)
    if constexpr (C == CKind::General) {
        // q^0 = 1 is the constant series; its higher coefficients stay 0.
        for (int k = 0; k < P; ++k) {
            S.pow1[k] = k == 0 ? zero + 1.0 : zero;
            S.pow2[k] = k == 0 ? zero + 1.0 : zero;
        }
        row[0] = S.pow1;
        row[1] = c[0];
        row[2] = c[2];
        for (int r = 3; r < m.grad.rows; ++r) row[r] = &S.prog[std::size_t(r - 3) * P];
    }
    V two_u0[2] = {zero, zero};
    for (int i = 0; i < 2; ++i)
        if (m.aux[i] >= 0) two_u0[i] = 2.0 * c[m.aux[i]][0];
    for (int k = 0; k < p; ++k) {
        if constexpr (C == CKind::General) {
            // Powers of q1, q2 up to the degrees the tangents' Hessian needs (none without tangents;
            // q^1 is the state's own series).
            for (int e = 1; e <= m.deg1; ++e)
                S.pow1[e * P + k] = e == 1 ? c[0][k] : cauchy(&S.pow1[(e - 1) * P], c[0], k, zero);
            for (int e = 1; e <= m.deg2; ++e)
                S.pow2[e * P + k] = e == 1 ? c[2][k] : cauchy(&S.pow2[(e - 1) * P], c[2], k, zero);
            run_program(m.grad, row, k, zero);
            S.g[0][k] = m.eps * row[m.grad.grad[0]][k];
            S.g[1][k] = m.eps * row[m.grad.grad[1]][k];
        } else if constexpr (C == CKind::Bilinear) {
            S.g[0][k] = m.eps * m.bilinear_c * c[2][k];
            S.g[1][k] = m.eps * m.bilinear_c * c[0][k];
        }
        const double inv = m.inv[k];
        for (int i = 0; i < 2; ++i) {
            const int qi = 2 * i, pi = 2 * i + 1;
            V force;
            if (kinds[i] == Kind::Tan) {
                // w = 1 + u^2, du/dt = b w p, force a u w. The order loop is bound by latency:
                // each order waits for the last one's coefficients. So every sum adds its old
                // terms first (they are ready early and overlap the previous order's tail) and
                // the newest last: u_k in w_k's sum; w_k, p_k, u_k and w_{k-1} in the products.
                const V* u = c[m.aux[i]];
                const V* q = c[pi];
                V* w = S.w[i];
                V a0 = zero, a1 = zero, b0 = zero, b1 = zero, s0 = zero, s1 = zero;
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
                V sq = 2.0 * (s0 + s1);
                if (k % 2 == 0 && k > 0) sq += u[k / 2] * u[k / 2];
                V A = a0 + a1, B = b0 + b1;
                if (k >= 2) {
                    A += w[k - 1] * q[1];
                    B += w[k - 1] * u[1];
                }
                if (k >= 1) {
                    A += w[0] * q[k];
                    B += w[0] * u[k];
                }
                const V wk = k == 0 ? 1.0 + u[0] * u[0] : sq + two_u0[i] * u[k];
                w[k] = wk;
                force = m.a[i] * (B + u[0] * wk);
                c[m.aux[i]][k + 1] = (A + wk * q[0]) * m.binv[i][k];
            } else {
                force = m.a[i] * c[qi][k];
            }
            if constexpr (C != CKind::None) force += S.g[i][k];
            c[qi][k + 1] = c[pi][k] * inv;
            c[pi][k + 1] = -force * inv;
        }
        if (m.nt > 0) tangent_order<V, K1, K2, C>(m, S, k, zero);
    }
}

template <class V, Kind K1, Kind K2>
void series_c(const TaylorModel& m, TaylorSeries<V>& S) {
    if (m.ckind == CKind::None)
        series<V, K1, K2, CKind::None>(m, S);
    else if (m.ckind == CKind::Bilinear)
        series<V, K1, K2, CKind::Bilinear>(m, S);
    else
        series<V, K1, K2, CKind::General>(m, S);
}

}  // namespace taylor_detail

/// Coefficients 1 .. p of S.c from its coefficients 0 (the starting states).
template <class V>
void taylor_series(const TaylorModel& m, TaylorSeries<V>& S) {
    using namespace taylor_detail;
    const bool t1 = m.kind[0] == Kind::Tan, t2 = m.kind[1] == Kind::Tan;
    if (t1 && t2)
        series_c<V, Kind::Tan, Kind::Tan>(m, S);
    else if (t1)
        series_c<V, Kind::Tan, Kind::Harmonic>(m, S);
    else if (t2)
        series_c<V, Kind::Harmonic, Kind::Tan>(m, S);
    else
        series_c<V, Kind::Harmonic, Kind::Harmonic>(m, S);
}

/// The polynomial of order p at tau for n <= kMaxDim variables: y[i] = sum_k c(i, k) tau^k.
template <class V, class Coef>
void estrin(Coef c, int n, int p, V tau, V* y) {
    // Estrin's scheme: pairs c_k + c_{k+1} tau, then pairs of pairs with tau^2, tau^4, ...: a
    // dependency chain of depth log2(p) instead of Horner's p (at orders 20-30 Horner's chain,
    // not the arithmetic, set the cost), the variables innermost so that their work overlaps.
    V a[kMaxDim][kTaylorStride / 2 + 1];
    int m = p + 1;
    for (int k = 0; k < m / 2; ++k)
        for (int i = 0; i < n; ++i) a[i][k] = c(i, 2 * k) + c(i, 2 * k + 1) * tau;
    if (m % 2)
        for (int i = 0; i < n; ++i) a[i][m / 2] = c(i, m - 1);
    m = (m + 1) / 2;
    V t = tau * tau;
    while (m > 1) {
        for (int k = 0; k < m / 2; ++k)
            for (int i = 0; i < n; ++i) a[i][k] = a[i][2 * k] + a[i][2 * k + 1] * t;
        if (m % 2)
            for (int i = 0; i < n; ++i) a[i][m / 2] = a[i][m - 1];
        m = (m + 1) / 2;
        t = t * t;
    }
    for (int i = 0; i < n; ++i) y[i] = a[i][0];
}

/// What the lane kernel gives each orbit besides its coefficients.
struct TaylorStep {
    double h;               ///< the step the tolerances allow (infinite for a polynomial of degree < p)
    double tau;             ///< min(h, hmax): the step taken unless it leaves a bounded well
    double y[kMaxDim];      ///< the polynomial at tau
    bool ok;                ///< orders p - 1 and p finite, hence all (else h, tau and y mean nothing)
    /// Whether the polynomial of p1 (w = 0) and of p2 (w = 1) over [0, tau], scaled as
    /// Integrator::taylor_cut scales it, passes keeps_sign (poly_roots.hpp): no sign change, no
    /// root search; the same bits and the same verdict as the scalar test.
    bool keeps_sign[2];
};

/// One build of the lane kernel (taylor_lanes.cpp): its instruction set and entry points.
struct TaylorLaneKernels {
    const char* level;  ///< "sse2", "avx2", "avx512", ...
    /// Expand count <= 4 starting states y[l] (m.n entries each) into c, lane-interleaved
    /// (c[(i kTaylorStride + k) 4 + l]: variable i, order k, lane l; 32-byte aligned), apply the
    /// step rule with rule[l] (in place of m's) and step bound hmax[l], and evaluate each
    /// polynomial at its step: out[l].
    void (*expand4)(const TaylorModel& m, const double* const* y, const double* hmax, const TaylorLaneRule* rule,
                    int count, double* c, TaylorStep* out);
    /// The same for count <= 8 (two 4-double vectors or one 8-double vector; c[(i kTaylorStride + k) 8 + l]).
    void (*expand8)(const TaylorModel& m, const double* const* y, const double* hmax, const TaylorLaneRule* rule,
                    int count, double* c, TaylorStep* out);
};

}  // namespace hovering::detail
