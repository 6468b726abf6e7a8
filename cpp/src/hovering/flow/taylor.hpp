#pragma once
// Taylor's method for the flow's field (internal): stepper "taylor".
//
// With the Tan potentials carrying u = tan(alpha q) (field.hpp), the field is a polynomial in the
// state: Harmonic forces are linear, the Tan force is a u (1 + u^2), du/dt = b (1 + u^2) p, and
// the coupling is a polynomial sum c q1^i q2^j. The Taylor coefficients of the solution through
// a point therefore follow from the recurrences of automatic differentiation (x_{k+1} = f_k /
// (k + 1), f_k from Cauchy products of lower coefficients; taylor_kernel.hpp), and no field is
// evaluated.
//
// Order and step follow Jorba & Zou (2005), as heyoka does, with two changes. Each variable is
// measured against its own scale: rho = min_{j = p-1, p} min_i (s_i / |x_ij|)^(1/j), s_i = max(|x_i0|,
// atol / rtol) (relative control per component, as GSL's; one norm for the whole state let a
// small position err relative to a large momentum or tan(alpha q) near a Tan well's edge). And a
// step is the fraction f = exp(-1.2) of that radius of convergence, times exp(-0.7 / (p - 1)),
// at the order p = ceil(1 - ln(tol) / 1.2) that makes f^p = tol (at least the coupling's degree + 4,
// below which the coefficients have not begun the decay the rule extrapolates). Jorba & Zou take f = exp(-2), the
// optimum when a step costs p^2; with four orbits expanded per SIMD register the expansion is
// cheap and a step's fixed costs (events, evaluation, bookkeeping) dominate, so fewer, longer
// steps of higher order win: measured 25-30% less time per return on the Tan systems than with
// exp(-2) (half the steps: 17 instead of 36 per return), 5-15% more on Harmonic x Harmonic, whose
// steps are bounded by the event search's 1/8 period either way. No step is rejected for its
// error; the polynomial of the step is its continuous extension, so every event is located on
// the very polynomial the step took (same accuracy at no further expansion).
//
// Several orbits can be expanded at once (expand_group): 4 in the lanes of one SIMD register (8 in
// two, or in one AVX-512 register), on the instruction set the core's SIMD level selects (taylor_lanes.cpp), bit for bit what
// each would get alone; the lanes also apply the step rule and evaluate each polynomial at its
// step's end.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "hovering/flow/field.hpp"
#include "hovering/flow/system.hpp"
#include "hovering/flow/taylor_kernel.hpp"

namespace hovering::detail {

/// Why stepper "taylor" does not apply to s ("" when it does): it needs Harmonic or Tan
/// potentials (also wrapped in Numerical); a Python-defined potential has no recurrences.
std::string taylor_unsupported(const FlowSystem& s);

/// Most orbits expand_group expands at once.
inline constexpr int kMaxTaylorGroup = 8;

/// ln f: a step is the fraction f of the estimated radius of convergence (see the file comment).
inline constexpr double kLogStepFraction = -1.2;

/// Coefficients of up to kMaxTaylorGroup expansions, lane-interleaved as the lane kernel writes
/// them (TaylorLaneKernels), and a count of the kernel calls that wrote them.
struct alignas(64) TaylorLanes {
    double c[std::size_t(kMaxDim) * kTaylorStride * kMaxTaylorGroup];  ///< the coefficients
    std::uint64_t round = 0;                                            ///< kernel calls that wrote c so far
};

/// The Taylor expansion of the flow through one point, and its step rule (see the file comment).
class Taylor {
public:
    /// For the field f of system s (throws std::invalid_argument where taylor_unsupported says why);
    /// order > 0: at that order instead of the tolerance's, with the step fraction f at most
    /// rtol^(1 / (p - 1)) (shorter steps where the tolerance would take a higher order).
    Taylor(const Field& f, const FlowSystem& s, double rtol, double atol, int order = 0);
    Taylor(const Taylor&) = delete;  // c_ points into own_ or a group's lanes
    Taylor& operator=(const Taylor&) = delete;
    /// The order p.
    int order() const { return m_.p; }
    /// Expand the solution through y0 (dim entries): false if a coefficient is not finite. The
    /// step the tolerances allow goes to *h (infinite for a polynomial solution of degree < p); the
    /// polynomial at min(*h, hmax) is ready for eval().
    bool expand(const double* y0, double hmax, double* h);
    /// expand() for count <= kMaxTaylorGroup orbits of the same system and order at once (SIMD
    /// lanes; the tolerances may differ: a verifying trace's beside the returns'), their
    /// coefficients in lanes (which stay t[l]'s until lanes is written again): t[l] expanded
    /// through y[l] with step bound hmax[l]. Bit for bit t[l]->expand(y[l], hmax[l], .).
    static void expand_group(Taylor* const* t, const double* const* y, const double* hmax, TaylorLanes& lanes,
                             int count);
    /// Whether the current expansion is the one through y0 (bit for bit) and finite, and its step.
    bool expanded_at(const double* y0, double* h = nullptr) const;
    /// The current expansion at time tau from its point: dim entries (NaN unless expanded_at
    /// would find the expansion current: a later round overwrote a group's coefficients).
    void eval(double tau, double* y) const;
    /// Whether the lanes found that the velocity of oscillator w + 1 keeps its sign over the step
    /// `step` (TaylorStep::keeps_sign; false unless step is the step they took).
    bool keeps_sign(int w, double step) const { return valid_ && step == step_.tau && step_.keeps_sign[w]; }
    /// The time in [lo, hi] where variable i of the current expansion equals off, for a crossing
    /// on that interval (lo_above: the variable is above off at lo): Newton's method on the
    /// variable's own polynomial from guess, bisection where it would leave the bracket, until the
    /// correction is below rounding. False unless an expansion is current (or it fails to settle).
    bool solve(int i, double off, double lo, double hi, bool lo_above, double guess, double* tau) const;
    /// The p + 1 coefficients of variable i of the current expansion, scaled to the step length h
    /// (c_k h^k: the polynomial in s = tau / h); false unless an expansion is current.
    bool scaled_coefficients(int i, double h, double* out) const;

private:
    // Adopt lane `lane` of buf (width lanes per row) and what the kernel gave it.
    void take(const TaylorLanes* buf, int lane, int width, const TaylorStep& st);
    TaylorModel m_;
    std::unique_ptr<TaylorLanes> own_;   // expand()'s coefficients
    const TaylorLanes* buf_ = nullptr;   // where the current coefficients are
    std::uint64_t round_ = 0;            // buf_->round when they were written
    const double* c_ = nullptr;          // variable 0, order 0 of this expansion in buf_
    int width_ = 4;                      // lanes per row of buf_
    TaylorStep step_{};                  // step, step taken and end state of the current expansion
    bool valid_ = false;                 // an expansion with finite coefficients is current
};

}  // namespace hovering::detail
