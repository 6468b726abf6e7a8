#pragma once
// The tangential curve I_tan^eps(theta) of Sigma_h (Def:sing_curve), measured on the flow, and the
// normal coordinates (phi, K) = (theta, I - I_tan^eps(theta)) it defines (eq:kphidef).
//
// Construction without bisection: the points where an orbit touches q1 = qw1 tangentially are
// known in closed form on the wall section (q1 = qw1, p1 = 0, H = h: the wall tangency curve of
// eq:XiwallepsI, one action I_w(s) per wall angle s); the tangential curve is their preimage
// under the smooth flow, found by following each wall point backward to its last crossing of
// Sigma_h (forward from the time-reversed point, lem:timerevgen). That gives the curve as a closed
// curve s -> (theta(s), I(s)); theta(s) - s and I(s) are smooth and 2 pi-periodic, so their
// trigonometric interpolants from n equispaced s converge spectrally. The curve is a graph
// I = I_tan(theta) exactly when theta(s) is increasing; I_tan(theta) inverts theta(s) by
// safeguarded Newton on the interpolant.

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "hovering/flow/return_map.hpp"

namespace hovering {

/// A 2 pi-periodic function from its samples at n equispaced points (n even), evaluated by its
/// trigonometric interpolant.
class TrigInterpolant {
public:
    /// An empty interpolant (assign a real one before use).
    TrigInterpolant() = default;
    /// Interpolant of values[k] at s_k = -pi + 2 pi k / n.
    explicit TrigInterpolant(const std::vector<double>& values);
    /// Value at s.
    double operator()(double s) const;
    /// Value and derivative at s.
    std::pair<double, double> with_derivative(double s) const;
    /// The constant term (mean over the period).
    double mean() const { return a_.empty() ? 0.0 : a_[0]; }

private:
    std::vector<double> a_, b_;  // cos and sin coefficients in (s + pi), a_[0] the mean
};

/// The n_phi midpoint angles phi_j = -pi + 2 pi (j + 1/2) / n_phi at which a forcing is sampled.
std::vector<double> forcing_angles(int n_phi);

/// Sine coefficients b_1..b_n_modes of f from its values at forcing_angles(f.size()): the least-squares
/// fit, which on these angles is the discrete sine transform b_k = (2 / n) sum_j f_j sin(k phi_j)
/// (the modes are orthogonal there). Throws std::invalid_argument unless 1 <= n_modes and
/// 2 n_modes < f.size().
std::vector<double> sine_coefficients(const std::vector<double>& f, int n_modes);

/// I_tan^eps of a system at energy h; see the file comment.
class TangentialCurve {
public:
    /// Measure the curve from n wall points (n even, >= 8) with the integrator options opt
    /// (tolerances of the backward traces), plus n_check off-grid points to estimate the
    /// interpolation error. Throws std::invalid_argument, saying why, when the wall tangency curve
    /// does not exist or is not a graph over the wall angle (eps too large), or a trace fails.
    static TangentialCurve measure(const FlowSystem& s, double h, int n, const FlowOptions& opt, int n_check = 4);
    /// measure() with as many wall points as the curve needs: 64, doubled (up to 1024) until the
    /// interpolation error in I measured at n_check points is below 1e-12 (64 when n_check = 0).
    static TangentialCurve measure_refined(const FlowSystem& s, double h, const FlowOptions& opt, int n_check = 4);
    /// The curve a flow map on normal coordinates uses unless given one: measure_refined with the
    /// traces at rtol 1e-13 (atol 1e-15) and the other options' defaults.
    static TangentialCurve measure_default(const FlowSystem& s, double h);
    /// The curve of measure() from its samples (theta_k, I_k at s_k = -pi + 2 pi k / n), its
    /// energy h, the system's eps, I_tan0 and the measured interpolation errors: bit for bit the
    /// curve measure() built from them (what a saved or pickled curve is rebuilt from).
    static TangentialCurve from_samples(double h, double eps, double I_tan0, const std::vector<double>& theta,
                                        const std::vector<double>& I, double err_theta, double err_I);

    /// (theta(s), I(s)) at the wall angle s (theta in [-pi, pi)).
    std::pair<double, double> at(double s) const;
    /// Whether theta(s) is increasing, i.e. the curve is a graph I = I_tan(theta).
    bool is_graph() const { return min_slope_ > 0; }
    /// min over s of dtheta/ds on a grid 8x finer than the samples (> 0 for a graph).
    double min_slope() const { return min_slope_; }
    /// Where that minimum lies (wall angle s).
    double min_slope_at() const { return min_slope_s_; }
    /// I_tan(theta); throws std::invalid_argument if the curve is not a graph. One evaluation of a
    /// trigonometric interpolant in theta (built by inverting theta(s) at n equispaced angles).
    double I_tan(double theta) const;
    /// dI_tan/dtheta (the derivative of the same interpolant); same condition.
    double I_tan_slope(double theta) const;
    /// The wall angle s with theta(s) = theta (mod 2 pi); same condition.
    double parameter_of(double theta) const;
    /// Largest deviation of the interpolant from direct traces at off-grid points: (in theta, in I).
    std::pair<double, double> interpolation_error() const { return {err_theta_, err_I_}; }
    /// The measured wall angles s_k = -pi + 2 pi k / n.
    const std::vector<double>& s() const { return s_; }
    /// The measured angles theta_k = theta(s_k) on Sigma_h.
    const std::vector<double>& theta() const { return theta_; }
    /// The measured actions I_k = I(s_k) on Sigma_h.
    const std::vector<double>& I() const { return I_; }
    /// The unperturbed tangent action I_tan(h) = H2^{-1}(h - V1(qw1)) (eq:Itan).
    double I_tan0() const { return I0_; }
    /// Energy of the section.
    double h() const { return h_; }
    /// The coupling strength eps of the system the curve was measured on.
    double eps() const { return eps_; }
    /// A one-line explanation of why the curve is not a graph (empty if it is).
    std::string not_graph_reason() const;
    /// Sine coefficients b_1..b_n_modes of the measured forcing f(phi) = (I_tan(-phi) - I_tan(phi)) / eps
    /// (eq:defoff): f sampled at forcing_angles(n_phi) and fitted by sine_coefficients. Throws
    /// std::invalid_argument at eps = 0 (f divides by eps) or if the curve is not a graph.
    std::vector<double> forcing_coefficients(int n_modes = kForcingModes, int n_phi = kForcingSamples) const;

    /// Sine modes of the measured forcing fitted by default.
    static constexpr int kForcingModes = 8;
    /// Angles the measured forcing is sampled at by default.
    static constexpr int kForcingSamples = 256;

private:
    /// Build the interpolants, min_slope and I_tan(theta) from s_, theta_, I_ (throws if theta(s) winds).
    void interpolate();
    std::vector<double> s_, theta_, I_;
    TrigInterpolant u_, Ifun_;  // theta(s) = s + u(s), I(s)
    TrigInterpolant Itheta_;    // I_tan(theta) itself, from the inverted curve at n equispaced theta
    double min_slope_ = 0, min_slope_s_ = 0;
    double err_theta_ = 0, err_I_ = 0;
    double I0_ = 0, h_ = 0, eps_ = 0;
};

}  // namespace hovering
