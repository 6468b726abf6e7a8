#pragma once
// One-degree-of-freedom potentials V(q) with a single minimum V(0) = 0 (convex: q V'(q) > 0), and
// their action-angle variables. Closed forms where they exist (harmonic, Tan); otherwise GSL
// quadrature (QAWS, which integrates the 1/sqrt endpoint singularities exactly) and Brent root
// finding, so that any smooth single-well potential given V and V' works.
//
// Angle convention of the paper (sec:setup): theta = 0 at the right turning point (q = q_max,
// p = 0, dp/dt < 0), increasing with time, so on [-pi, pi) sign(theta) = -sign(p).

#include <memory>
#include <string>
#include <utility>

namespace hovering {

/// A single-well potential and its energy-dependent quantities.
class Potential {
public:
    virtual ~Potential() = default;
    /// V(q).
    virtual double V(double q) const = 0;
    /// V'(q).
    virtual double dV(double q) const = 0;
    /// Short description, e.g. "Harmonic(omega=1)".
    virtual std::string name() const = 0;
    /// Largest |q| for which V is defined (infinity if unbounded).
    virtual double q_limit() const;

    /// Turning points (q_min < 0 < q_max) with V = h > 0.
    virtual std::pair<double, double> turning_points(double h) const;
    /// Period T(h) = 2 int dq / sqrt(2 (h - V)).
    virtual double period(double h) const;
    /// Action I(h) = (1/pi) int sqrt(2 (h - V)) dq over [q_min, q_max].
    virtual double action(double h) const;
    /// Energy of an action: the inverse of action().
    virtual double energy(double I) const;
    /// omega(h) = 2 pi / T(h) = dH/dI.
    double frequency(double h) const;
    /// Angle of the point (q, p < 0) on the level h: omega(h) times the time from q to q_max,
    /// in [0, pi] (theta_w of eq:thw for q = q_w).
    virtual double angle_of(double q, double h) const;
    /// Inverse of the angle: (q, p) on the level h at angle theta in [-pi, pi] (sign(p) = -sign(theta)).
    virtual std::pair<double, double> point_at(double theta, double h) const;
    /// Signed angle in [-pi, pi] of the phase point (q, p) on its level h = p^2/2 + V(q).
    virtual double angle_of_point(double q, double p, double h) const;

protected:
    void check_energy(double h, const char* who) const;
};

/// V = omega^2 q^2 / 2.
class Harmonic final : public Potential {
public:
    /// Throws std::invalid_argument unless omega > 0 and finite.
    explicit Harmonic(double omega);
    double V(double q) const override;
    double dV(double q) const override;
    std::string name() const override;
    std::pair<double, double> turning_points(double h) const override;
    double period(double h) const override;
    double action(double h) const override;
    double energy(double I) const override;
    double angle_of(double q, double h) const override;
    std::pair<double, double> point_at(double theta, double h) const override;
    double angle_of_point(double q, double p, double h) const override;
    /// The frequency parameter omega.
    double omega() const { return omega_; }

private:
    double omega_;
};

/// V = omega^2 / (2 alpha^2) tan^2(alpha q), |q| < pi / (2 alpha): H(I) = omega I + alpha^2 I^2 / 2.
class Tan final : public Potential {
public:
    /// Throws std::invalid_argument unless omega > 0, alpha > 0, both finite.
    Tan(double omega, double alpha);
    double V(double q) const override;
    double dV(double q) const override;
    std::string name() const override;
    double q_limit() const override;
    std::pair<double, double> turning_points(double h) const override;
    double period(double h) const override;
    double action(double h) const override;
    double energy(double I) const override;
    double angle_of(double q, double h) const override;
    std::pair<double, double> point_at(double theta, double h) const override;
    double angle_of_point(double q, double p, double h) const override;
    /// The frequency parameter omega.
    double omega() const { return omega_; }
    /// The nonlinearity alpha.
    double alpha() const { return alpha_; }

private:
    double omega_, alpha_;
};

/// Wraps another potential but answers every energy question by quadrature and root finding:
/// the generic path for any V, and the independent check of the closed forms.
class Numerical final : public Potential {
public:
    /// Use base.V and base.dV only.
    explicit Numerical(std::shared_ptr<const Potential> base);
    double V(double q) const override { return base_->V(q); }
    double dV(double q) const override { return base_->dV(q); }
    std::string name() const override { return "Numerical(" + base_->name() + ")"; }
    double q_limit() const override { return base_->q_limit(); }

private:
    std::shared_ptr<const Potential> base_;
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

/// Onset parameters from the definitions: derivatives of Omega0(I) and theta_w(I) by central
/// differences (step chosen for the ~1e-12 accuracy of the underlying quantities).
/// Throws std::invalid_argument if h is not above the step energy V1(qw1) + V2(qw2) or a wall lies
/// outside its potential's well.
OnsetParameters onset_parameters(const Potential& V1, const Potential& V2, double qw1, double qw2, double h);

/// The closed forms of the appendix (sec:calculationofparam) for Tan/harmonic pairs, with the two
/// corrections the definitions require (see the README): tau0's last term over W1^3 (printed W1^4),
/// and theta_w = arccos(+sqrt(alpha^2 + omega^2 / (2 h2)) sin(alpha qw2) / alpha) (printed with a minus).
OnsetParameters onset_parameters_closed_form(double omega1, double alpha1, double omega2, double alpha2,
                                             double qw1, double qw2, double h);

}  // namespace hovering
