#pragma once
// The oscillators-step system of sec:setup: H = p1^2/2 + V1(q1) + p2^2/2 + V2(q2) + eps Vc(q1, q2)
// with a step {q1 < qw1, q2 < qw2}, and its onset parameters (sec:parametersdef).

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "hovering/flow/potential.hpp"

namespace hovering {

/// Which walls the flow sees.
enum class Geometry : std::int8_t {
    None = 0,  ///< the smooth flow, no impact events
    Wall = 1,  ///< the infinite wall q1 = qw1
    Step = 2,  ///< the step {q1 < qw1, q2 < qw2}: right wall, upper wall, corner
};

/// Vc = sum_k c_k q1^i_k q2^j_k.
struct Coupling {
    std::vector<std::array<double, 3>> terms;  ///< (c, i, j) with integer i, j >= 0
    /// Vc(q1, q2).
    double value(double q1, double q2) const;
    /// (dVc/dq1, dVc/dq2).
    std::array<double, 2> gradient(double q1, double q2) const;
    /// q1 q2.
    static Coupling bilinear() { return Coupling{{{1.0, 1.0, 1.0}}}; }
};

/// H = p1^2/2 + V1(q1) + p2^2/2 + V2(q2) + eps Vc(q1, q2), with walls at qw1, qw2.
struct FlowSystem {
    std::shared_ptr<const Potential> V1, V2;  ///< the oscillators' potentials
    Coupling coupling;                        ///< the coupling Vc
    double eps = 0.0;                         ///< coupling strength (0: no coupling term is evaluated)
    double qw1 = -1.0, qw2 = -0.5;            ///< the walls' positions (step corner at (qw1, qw2))
    Geometry geometry = Geometry::None;       ///< which walls the flow sees
    /// Validate (throws std::invalid_argument naming the bad value).
    void validate() const;
    /// H(z), z = (q1, p1, q2, p2); eps = 0 evaluates no coupling.
    double energy(const double* z) const;
    /// dz/dt.
    void rhs(const double* z, double* dz) const;
};

/// The onset parameters of sec:parametersdef at energy h (eq:omega0ofI .. eq:deftau1).
struct OnsetParameters {
    double Omega0;   ///< rotation of non-impacting orbits at I_tan (eq:omega0ofI)
    double tau0;     ///< dOmega0/dI at I_tan (eq:deftau0)
    double tau1;     ///< -2 dtheta_w/dI at I_tan (eq:deftau1)
    double lam;      ///< sqrt(2 omega_2^3) / |V_1'(qw1)| (eq:deflambdah)
    double theta_w;  ///< angle of the corner height qw2 on the tangent circle (eq:thw)
    double I_tan;    ///< action of the tangent circle, H_2(I_tan) = h - V_1(qw1) (eq:Itan)
};

/// Onset parameters with the estimated absolute error of each one (same fields).
struct OnsetEstimate {
    OnsetParameters value;  ///< the parameters
    OnsetParameters error;  ///< estimated absolute error of each parameter
};

/// Onset parameters from the definitions with error estimates: Omega0 = omega2(h2) T1(h1w),
/// tau0 = omega2 (omega2'(h2) T1(h1w) - omega2 T1'(h1w)), tau1 = -2 omega2 d angle_of(qw2, h2) / dh
/// (h1w = V1(qw1), h2 = h - h1w), the slopes from the potentials (closed forms for Harmonic/Tan,
/// Ridders differences otherwise). Each error adds the potentials' own error to the propagated
/// rounding of h, V1(qw1) and V2(qw2) (the step energy is known only to a few ulps, so
/// h - h_w is too). Throws std::invalid_argument for walls outside the wells, h not above the step
/// energy, or a parameter whose estimated relative error exceeds rtol (naming it, the energy and
/// why); tau0 or tau1 smaller than its error, which is below rtol times its scale (Omega0 / I_tan,
/// 1 / I_tan), is reported as 0.
OnsetEstimate onset_estimate(const Potential& V1, const Potential& V2, double qw1, double qw2, double h,
                             double rtol = 1e-6);

/// The values of onset_estimate (same checks, same errors).
OnsetParameters onset_parameters(const Potential& V1, const Potential& V2, double qw1, double qw2, double h,
                                 double rtol = 1e-6);

/// The closed forms of the appendix (sec:calculationofparam) for Tan/harmonic pairs, with the two
/// corrections the definitions require (see the README): tau0's last term over W1^3 (printed W1^4),
/// and theta_w = arccos(+sqrt(alpha^2 + omega^2 / (2 h2)) sin(alpha qw2) / alpha) (printed with a minus);
/// evaluated without their cancellations (theta_w by atan2 with sin theta_w = cos(alpha2 qw2)
/// sqrt((h - h_w) / h2), tau1's root as sqrt(2 cos^2(alpha2 qw2) (h - h_w))), with error
/// estimates and the checks of onset_estimate.
OnsetEstimate onset_estimate_closed_form(double omega1, double alpha1, double omega2, double alpha2, double qw1,
                                         double qw2, double h, double rtol = 1e-6);

/// The values of onset_estimate_closed_form.
OnsetParameters onset_parameters_closed_form(double omega1, double alpha1, double omega2, double alpha2, double qw1,
                                             double qw2, double h, double rtol = 1e-6);

}  // namespace hovering
