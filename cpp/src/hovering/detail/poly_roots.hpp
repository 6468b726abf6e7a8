#pragma once
// Real-root isolation of a polynomial on (0, 1] (internal): the event search's guarantee that a
// step holds at most one sign change of each event velocity.
//
// The polynomial P(s) = sum_k b_k s^k is written in the Bernstein basis of [0, 1]; the number of
// sign changes of its Bernstein coefficients bounds the number of roots in the interval and has
// the same parity (the variation-diminishing property: Descartes' rule of signs after the Moebius
// map of [0, 1] onto [0, inf)). Intervals with two or more changes are halved by de Casteljau's
// algorithm, left half first, so roots come out in time order. This is the isolation heyoka
// applies to each event polynomial of a Taylor step; here it also serves the Hermite
// interpolants of the GSL steppers' steps.

#include <algorithm>
#include <array>
#include <cmath>

namespace hovering::detail {

/// Highest degree isolate_roots accepts.
inline constexpr int kMaxRootDegree = 44;

/// A bracket [lo, hi] of (0, 1] holding exactly one sign change of the polynomial (or, when it is
/// narrower than the isolation's resolution, an odd number of them).
struct RootBracket {
    double lo, hi;
};

namespace poly_detail {

// 1 / C(n, k) for n <= kMaxRootDegree, built once.
inline const double* inverse_binomials(int n) {
    struct Table {
        double v[kMaxRootDegree + 1][kMaxRootDegree + 1];
        Table() {
            for (int m = 0; m <= kMaxRootDegree; ++m) {
                double c = 1;
                for (int k = 0; k <= m; ++k) {
                    v[m][k] = 1.0 / c;
                    c = c * (m - k) / (k + 1);
                }
            }
        }
    };
    static const Table t;
    return t.v[n];
}

inline int sign_changes(const double* b, int n) {
    int changes = 0, last = 0;
    for (int j = 0; j <= n; ++j) {
        const int s = (b[j] > 0) - (b[j] < 0);
        if (s == 0) continue;
        if (last != 0 && s != last) ++changes;
        last = s;
    }
    return changes;
}

// Depth-first, left first: brackets of the sign changes of the Bernstein polynomial b (degree n)
// on [u, v] appended to out until it holds max_out of them. Returns false once out is full.
inline bool isolate(const double* b, int n, double u, double v, int depth, RootBracket* out, int* count,
                    int max_out) {
    const int changes = sign_changes(b, n);
    if (changes == 0) return true;
    const bool ends_differ = (b[0] > 0) != (b[n] > 0) && b[0] != 0 && b[n] != 0;
    // One change is exactly one root; below the resolution, an odd count of changes between the
    // ends is one root and an even count a tangency, which no sign test resolves (and which
    // moves the orbit by less than the resolution's cube).
    if (changes == 1 || depth >= 52) {
        if (changes == 1 || ends_differ) {
            out[(*count)++] = {u, v};
            return *count < max_out;
        }
        return true;
    }
    double l[kMaxRootDegree + 1], r[kMaxRootDegree + 1], w[kMaxRootDegree + 1];
    for (int j = 0; j <= n; ++j) w[j] = b[j];
    // de Casteljau at 1/2: l takes the left edge of each level, r the right edge.
    for (int k = 0; k <= n; ++k) {
        l[k] = w[0];
        r[n - k] = w[n - k];
        for (int j = 0; j < n - k; ++j) w[j] = 0.5 * (w[j] + w[j + 1]);
    }
    const double m = 0.5 * (u + v);
    if (!isolate(l, n, u, m, depth + 1, out, count, max_out)) return false;
    return isolate(r, n, m, v, depth + 1, out, count, max_out);
}

}  // namespace poly_detail

/// Whether P(s) = sum_{k<=n} b[k] s^k provably keeps one sign on [0, 1] (a bound, O(n): the
/// range of b0 + b1 s + b2 s^2 widened by sum_{k>=3} |b_k|); false says nothing.
inline bool keeps_sign(const double* b, int n) {
    double tail = 0;
    for (int k = 3; k <= n; ++k) tail += std::fabs(b[k]);
    const double b2 = n >= 2 ? b[2] : 0.0, b1 = n >= 1 ? b[1] : 0.0;
    double lo = std::min(b[0], b[0] + b1 + b2), hi = std::max(b[0], b[0] + b1 + b2);
    if (b2 != 0) {
        const double v = -b1 / (2 * b2);  // the quadratic's vertex
        if (v > 0 && v < 1) {
            const double q = b[0] + v * (b1 + v * b2);
            lo = std::min(lo, q);
            hi = std::max(hi, q);
        }
    }
    return lo > tail || hi < -tail;
}

/// Brackets (in time order, at most max_out) of the sign changes of P(s) = sum_{k<=n} b[k] s^k on
/// (0, 1]; returns how many were written. A root at s = 0 itself is not counted (P is divided by
/// s while b[0] == 0: the orbit leaves a wall or the section there). n <= kMaxRootDegree.
inline int isolate_roots(const double* b, int n, RootBracket* out, int max_out) {
    while (n > 0 && b[0] == 0) {
        ++b;
        --n;
    }
    if (n <= 0 || max_out <= 0) return 0;
    // Cheap exclusion first: |P(s) - b0 - b1 s| <= sum_{k>=2} |b_k| on [0, 1].
    double tail = 0;
    for (int k = 2; k <= n; ++k) tail += std::fabs(b[k]);
    if (std::min(b[0], b[0] + b[1]) > tail || std::max(b[0], b[0] + b[1]) < -tail) return 0;
    // Bernstein coefficients: beta_j = sum_{k<=j} C(j, k) / C(n, k) b_k, by n passes of
    // neighbour sums over b_k / C(n, k) (Farouki's power-to-Bernstein conversion).
    const double* ib = poly_detail::inverse_binomials(n);
    double c[kMaxRootDegree + 1];
    for (int k = 0; k <= n; ++k) c[k] = b[k] * ib[k];
    for (int r = 1; r <= n; ++r)
        for (int j = n; j >= r; --j) c[j] += c[j - 1];
    int count = 0;
    poly_detail::isolate(c, n, 0.0, 1.0, 0, out, &count, max_out);
    return count;
}

/// Whether P(s) = sum_{k<=n} b[k] s^k has at most one sign change on (0, 1]: O(n) bounds on P
/// and on P' (monotone: Rolle) settle nearly every step; the rest are isolated.
inline bool at_most_one_root(const double* b, int n) {
    if (n <= 1 || keeps_sign(b, n)) return true;
    double d[kMaxRootDegree + 1];
    for (int k = 0; k < n; ++k) d[k] = (k + 1) * b[k + 1];
    if (keeps_sign(d, n - 1)) return true;
    RootBracket br[2];
    return isolate_roots(b, n, br, 2) < 2;
}

}  // namespace hovering::detail
