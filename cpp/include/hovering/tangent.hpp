#pragma once
// Tangent dynamics shared by both models of the return map: the product of a return's 2x2
// Jacobians along an orbit, kept in QR form so that it stays finite however long the orbit, and
// where a batch iteration writes it.
//
// The product M_n = J_{n-1} ... J_1 J_0 is held as Q R with Q a rotation and R upper triangular,
// R = diag(e^L1, e^L2) [[1, u], [0, 1]]. Each new factor J is absorbed by one Gram-Schmidt step
// (J Q = Q' R', R'_11 > 0) and R' R is folded into (L1, L2, u): L1 / n and L2 / n are the finite-time
// Lyapunov exponents of the orbit (Benettin's method), L1 + L2 = sum log det J_k (0 for an
// area-preserving map, up to rounding), and u stays bounded (it converges where L1 > L2).

#include <cmath>
#include <cstdint>

#include "hovering/types.hpp"

namespace hovering {

/// The product of 2x2 Jacobians along an orbit, QR-renormalised; see the file comment.
struct TangentProduct {
    double c = 1.0, s = 0.0;    ///< Q = [[c, -s], [s, c]]
    double L1 = 0.0, L2 = 0.0;  ///< log R_11, log |R_22| of the product's R
    double u = 0.0;             ///< R_12 / R_11 of the product's R
    std::int64_t factors = 0;   ///< Jacobians multiplied in

    /// Multiply by J (row-major: J[0] J[1]; J[2] J[3]) from the left: M <- J M.
    void multiply(const double* J) {
        // J Q: its first column gives the new rotation, the rest R' = [[r11, r12], [0, r22]].
        const double x1 = J[0] * c + J[1] * s, y1 = J[2] * c + J[3] * s;
        const double x2 = J[1] * c - J[0] * s, y2 = J[3] * c - J[2] * s;
        const double r11 = std::hypot(x1, y1);
        const double cn = x1 / r11, sn = y1 / r11;
        const double r12 = cn * x2 + sn * y2, r22 = cn * y2 - sn * x2;
        // R' R = [[r11 e^L1, r11 e^L1 u + r12 e^L2], [0, r22 e^L2]]: u' = u + (r12 / r11) e^(L2 - L1).
        u += (r12 / r11) * std::exp(L2 - L1);
        L1 += std::log(r11);
        L2 += std::log(std::fabs(r22));
        c = cn;
        s = sn;
        ++factors;
    }
    /// The product M itself, row-major (entries overflow to +-inf once e^L1 does).
    void matrix(double* M) const {
        const double a = std::exp(L1), d = std::exp(L2), b = a * u;
        M[0] = c * a;
        M[1] = c * b - s * d;
        M[2] = s * a;
        M[3] = s * b + c * d;
    }
};

/// Where a batch iteration writes each orbit's tangent product (record "jacobian"); null
/// pointers are not written, and q set means all of them are.
struct TangentOutput {
    double* q = nullptr;            ///< (n, 4) Q of the product, row-major (identity for 0 steps)
    double* log_r = nullptr;        ///< (n, 2) L1, L2 (log R_11, log |R_22|)
    double* r12 = nullptr;          ///< (n,) u = R_12 / R_11
    std::int8_t* status = nullptr;  ///< (n,) Status::Ok, or the first point the derivative is one-sided at (Corner)
    /// Whether tangent products are recorded.
    bool active() const { return q != nullptr; }
    /// Write orbit i's product and status.
    void write(std::int64_t i, const TangentProduct& t, Status st) const {
        if (!q) return;
        q[4 * i + 0] = t.c;
        q[4 * i + 1] = -t.s;
        q[4 * i + 2] = t.s;
        q[4 * i + 3] = t.c;
        if (log_r) {
            log_r[2 * i] = t.L1;
            log_r[2 * i + 1] = t.L2;
        }
        if (r12) r12[i] = t.u;
        if (status) status[i] = static_cast<std::int8_t>(st);
    }
};

}  // namespace hovering
