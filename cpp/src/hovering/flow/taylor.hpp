#pragma once
// Taylor's method for the flow's field (internal): stepper "taylor".
//
// With the Tan potentials carrying u = tan(alpha q) (field.hpp), the field is a polynomial in the
// state: Harmonic forces are linear, the Tan force is a u (1 + u^2), du/dt = b (1 + u^2) p, and
// the coupling is a polynomial sum c q1^i q2^j. The Taylor coefficients of the solution through
// a point therefore follow from the recurrences of automatic differentiation (x_{k+1} = f_k /
// (k + 1), f_k from Cauchy products of lower coefficients): order p costs O(p) operations per
// linear term and O(p^2) per product, and no field is evaluated.
//
// Order and step follow Jorba & Zou (2005), as heyoka does: for a tolerance tol, order
// p = ceil(1 - ln(tol) / 2), and the step rho / e^2 exp(-0.7 / (p - 1)) with rho estimated from
// the last two coefficients, rho = min_{j = p-1, p} (scale / ||x_j||)^(1/j) (scale = max of the
// state's infinity norm and atol / rtol: relative control above, absolute below). No step is
// rejected for its error; the polynomial of the step is its continuous extension, so every event
// is located on the very polynomial the step took (same accuracy at no further expansion).

#include <vector>

#include "hovering/flow/field.hpp"
#include "hovering/flow/system.hpp"

namespace hovering::detail {

/// Highest order the tolerances can ask for (rtol >= 1e-30 gives p <= 36).
inline constexpr int kMaxTaylorOrder = 40;

/// Why stepper "taylor" does not apply to s ("" when it does): it needs Harmonic or Tan
/// potentials (also wrapped in Numerical); a Python-defined potential has no recurrences.
std::string taylor_unsupported(const FlowSystem& s);

/// The Taylor expansion of the flow through one point, and its step rule (see the file comment).
class Taylor {
public:
    /// For the field f of system s (throws std::invalid_argument where taylor_unsupported says why).
    Taylor(const Field& f, const FlowSystem& s, double rtol, double atol);
    /// The order p.
    int order() const { return p_; }
    /// Expand the solution through y0 (dim entries): false if a coefficient is not finite. The
    /// step the tolerances allow goes to *h (infinite for a polynomial solution of degree < p).
    bool expand(const double* y0, double* h);
    /// Whether the current expansion is the one through y0 (bit for bit).
    bool expanded_at(const double* y0) const;
    /// The expansion at time tau from its point (Horner): dim entries.
    void eval(double tau, double* y) const;
    /// Its time derivative at tau: dim entries.
    void eval_derivative(double tau, double* dy) const;

private:
    // Coefficients 1 .. p of the state from coefficient 0, for compile-time force and coupling kinds.
    template <Kind K1, Kind K2, CKind C>
    void coefficients();
    using Coefficients = void (Taylor::*)();
    template <Kind K1>
    static Coefficients pick(Kind k2, CKind c);
    Coefficients coefficients_ = nullptr;
    int n_ = 4, p_ = 8;
    double scale_floor_;  // atol / rtol
    struct Osc {
        Kind kind = Kind::Harmonic;
        double a = 0, b = 0;
        int q = 0, p = 1, aux = -1;
    } osc_[2];
    double eps_ = 0;
    CKind ckind_ = CKind::None;
    double bilinear_c_ = 0;
    std::vector<std::array<double, 3>> terms_;  // general coupling
    int deg1_ = 0, deg2_ = 0;                   // highest powers of q1, q2 the gradient needs
    // Coefficients: c_[i][k] of variable i; per Tan oscillator w = 1 + u^2; powers of q1, q2.
    double c_[kMaxDim][kMaxTaylorOrder + 1];
    double w_[2][kMaxTaylorOrder + 1];
    double inv_[kMaxTaylorOrder], binv_[2][kMaxTaylorOrder];  // 1 / (k + 1), b / (k + 1)
    double two_u0_[2] = {0, 0};                                 // 2 u_0 of each Tan oscillator
    double g_[2][kMaxTaylorOrder + 1];  // coupling gradient series
    std::vector<double> pow1_, pow2_;   // (deg + 1) x (P + 1): q^m series, m = 0 .. deg
};

}  // namespace hovering::detail
