#pragma once
// The flow in closed form (internal): stepper "exact".
//
// Two families of systems have an exact flow between impacts:
//  - Angles: eps = 0 (or no coupling term) with V1, V2 each Harmonic or Tan. Each oscillator keeps
//    its energy h_i (a reflection only flips its momentum) and turns on its own angle,
//    theta_i(t) = theta_i(0) + omega_i(h_i) t, through the potentials' closed action-angle forms.
//    Every event is an angle reaching a known value, so the Tracer runs event to event
//    (Tracer::trace_angles) instead of step by step.
//  - Linear: V1, V2 both Harmonic and a coupling that is a quadratic form (terms q1 q2, q1^2, q2^2;
//    constants do not move the flow), any eps: q'' = -K q, solved through the normal modes of K
//    (cos/sin, linear or cosh/sinh for eigenvalues > 0, = 0, < 0). The Tracer steps it as it steps
//    GSL's steppers, with the closed form as its continuous extension; a step is halved wherever
//    the closed form shows a watched velocity changing sign twice (Integrator::linear_ambiguous:
//    the GSL steppers' Hermite test alone missed a q1 minimum and maximum 0.026 apart).

#include <array>
#include <limits>
#include <string>

#include "hovering/flow/return_map.hpp"

namespace hovering::detail {

/// Which closed form a system's flow has under stepper "exact".
enum class ExactKind { None, Angles, Linear };

/// The closed form of stepper "exact" for this system: None for the GSL steppers; for "exact",
/// Angles or Linear, or std::invalid_argument naming what the system has and what "exact" needs.
ExactKind exact_kind(const FlowSystem& s, const FlowOptions& o);

/// "V1 = ..., V2 = ..., eps = ..., Vc = ...": the system named in error messages.
std::string describe(const FlowSystem& s);

/// q'' = -K q in closed form through the normal modes of the symmetric K.
class LinearFlow {
public:
    /// The flow of a Linear system (exact_kind == Linear).
    explicit LinearFlow(const FlowSystem& s);
    /// y1 = exp(A t) y0 for y = (q1, p1, q2, p2) (the modes at t kept for the next call's t).
    void propagate(const double* y0, double t, double* y1) const;
    /// propagate() without touching what it keeps (a time inside a step).
    void state_at(const double* y0, double t, double* y1) const;
    /// The largest |eigenvalue|^(1/2) of K: the fastest rate of the flow.
    double fastest_rate() const;
    /// The eigenvalues of K (ascending).
    const std::array<double, 2>& eigenvalues() const { return lam_; }
    /// dp_i/dt = -(K q)_i at the state y (i = 0: p1, 1: p2).
    double acceleration(const double* y, int i) const;
    /// Bounds of |dp_i/dt| (m[0]) and |d^2 p_i/dt^2| (m[1]) over [0, h] along the flow from y0,
    /// from each mode's amplitude (its cosh/sinh growth for an eigenvalue < 0), rounding included.
    void velocity_derivative_bounds(const double* y0, double h, int i, double* m) const;

private:
    void modes_at(double t, double* c, double* sn) const;  // each mode's (cos, sin) or (cosh, sinh)
    void apply(const double* y0, double t, const double* c, const double* sn, double* y1) const;
    std::array<double, 2> lam_{}, rate_{};  // eigenvalues, sqrt(|eigenvalue|)
    double Q_[2][2]{};                      // columns: unit eigenvectors
    // The modes' (cos, sin) or (cosh, sinh) at the last t: every full step has the same length
    // (one LinearFlow per integrator, i.e. per worker: no sharing).
    mutable double t_last_ = std::numeric_limits<double>::quiet_NaN(), c_last_[2]{}, s_last_[2]{};
};

/// One oscillator's closed-form angle flow: (q, p) <-> (h, theta) and theta(t) = theta + omega t.
struct AngleOscillator {
    const Potential* V = nullptr;
    double h = 0, omega = 0, theta = 0;  // energy, frequency (0 at rest, h = 0), angle in [-pi, pi)
    double q_rest = 0, p_rest = 0;       // the state when it rests (h = 0)
    /// Set (h, omega, theta) from (q, p); false if the level is not finite.
    bool set(double q, double p);
    /// (q, p) at angle th (any real: wrapped to [-pi, pi)).
    std::pair<double, double> at(double th) const;
    /// d(q, p)(t) / d(q, p)(0) of the flow over time t from the current angle, row-major 2x2: the
    /// action-angle chart's tangent M = [X / omega, d(q, p)/dh] carried by theta += omega(h) t
    /// (the h column gains X omega'(h) t / omega). At rest, the small oscillation of V''(0).
    void tangent(double t, double* J) const;
};

/// th wrapped to [-pi, pi).
double wrap_angle(double th);

}  // namespace hovering::detail
