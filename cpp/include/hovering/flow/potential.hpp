#pragma once
// One-degree-of-freedom potentials V(q) with a single minimum V(0) = 0 (convex: q V'(q) > 0), and
// their action-angle variables. Closed forms where they exist (harmonic, Tan); otherwise GSL
// quadrature (QAWS, which integrates the 1/sqrt endpoint singularities exactly) and Brent root
// finding, so that any smooth single-well potential given V and V' works.
//
// Angle convention of the paper (sec:setup): theta = 0 at the right turning point (q = q_max,
// p = 0, dp/dt < 0), increasing with time, so on [-pi, pi) sign(theta) = -sign(p).

#include <array>
#include <memory>
#include <string>
#include <utility>

namespace hovering {

/// A computed value and an estimate of its absolute error.
struct Estimate {
    double value;  ///< the value
    double error;  ///< estimated absolute error (0: exact)
};

/// A single-well potential and its energy-dependent quantities.
class Potential {
public:
    /// Potentials are used through shared pointers to the base.
    virtual ~Potential() = default;
    /// V(q).
    virtual double V(double q) const = 0;
    /// V'(q).
    virtual double dV(double q) const = 0;
    /// Short description, e.g. "Harmonic(omega=1)".
    virtual std::string name() const = 0;
    /// Largest |q| for which V is defined (infinity if unbounded).
    virtual double q_limit() const;

    /// Turning points (q_min < 0 < q_max) with V = h > 0. Generic path: on each side the largest
    /// |q| with V(q) <= h (the root to 1 ulp; for a bounded well whose V stays below h up to its
    /// wall in double precision, e.g. Tan above ~1e31, the last double before q_limit).
    virtual std::pair<double, double> turning_points(double h) const;
    /// Period T(h) = 2 int dq / sqrt(2 (h - V)). The generic energy-dependent quantities (period,
    /// action, angle_of, point_at) throw std::invalid_argument for a level above the largest value
    /// V reaches before the wall of a bounded well: its turning points are the wall to rounding.
    virtual double period(double h) const;
    /// Action I(h) = (1/pi) int sqrt(2 (h - V)) dq over [q_min, q_max].
    virtual double action(double h) const;
    /// Energy of an action: the inverse of action().
    virtual double energy(double I) const;
    /// omega(h) = 2 pi / T(h) = dH/dI.
    double frequency(double h) const;
    /// Angle of the point (q, p < 0) on the level h: omega(h) times the time from q to q_max,
    /// in [0, pi] (theta_w of eq:thw for q = q_w). q in [q_min, q_max]; the generic path also takes
    /// a q up to 8 ulps beyond a turning point (roots known to rounding) as that turning point.
    virtual double angle_of(double q, double h) const;
    /// Inverse of the angle: (q, p) on the level h at angle theta in [-pi, pi] (sign(p) = -sign(theta)).
    virtual std::pair<double, double> point_at(double theta, double h) const;
    /// d(q, p)/dh of point_at(theta, h) at fixed theta (the tangent of the action-angle chart:
    /// with d(q, p)/dtheta = (p, -V') / omega it inverts d(theta, I)/d(q, p)). Generic path:
    /// Ridders-extrapolated central differences of point_at in h.
    virtual std::array<double, 2> point_slope(double theta, double h) const;
    /// Signed angle in [-pi, pi] of the phase point (q, p) on its level h = p^2/2 + V(q); throws
    /// std::invalid_argument unless (q, p) lies on that level to 1e-8 relative.
    double angle_of_point(double q, double p, double h) const;
    /// angle_of_point without the level check, for callers that computed h from (q, p) themselves.
    virtual double angle_on_level(double q, double p, double h) const;
    /// Relative accuracy of period, action, frequency (and, times pi, the absolute accuracy of
    /// angle_of) at exact arguments: the quadrature tolerance on the generic path, a few ulps for
    /// closed forms.
    virtual double relative_accuracy() const;
    /// dT/dh with its error estimate. Generic path: Ridders-extrapolated central differences of
    /// period() (steps from h / 4 down), error from the extrapolation table plus the quadratures'
    /// noise divided by the step.
    virtual Estimate period_slope(double h) const;
    /// d angle_of(q, h) / dh at fixed q, for q strictly inside the level (V(q) < h), with its error
    /// estimate. Generic path: as period_slope, steps from min(h, h - V(q)) / 4 down (the angle has
    /// a square-root branch point at h = V(q)).
    virtual Estimate angle_slope(double q, double h) const;

protected:
    /// Throw std::invalid_argument (naming the potential and who) unless h is finite and > 0.
    void check_energy(double h, const char* who) const;
};

/// V = omega^2 q^2 / 2.
class Harmonic final : public Potential {
public:
    /// Throws std::invalid_argument unless omega lies in [1e-100, 1e100] (omega^2 stays a normal double).
    explicit Harmonic(double omega);
    /// V(q) in closed form.
    double V(double q) const override;
    /// V'(q) in closed form.
    double dV(double q) const override;
    /// Short description with the parameters.
    std::string name() const override;
    /// Turning points in closed form.
    std::pair<double, double> turning_points(double h) const override;
    /// T(h) in closed form.
    double period(double h) const override;
    /// I(h) in closed form.
    double action(double h) const override;
    /// H(I) in closed form.
    double energy(double I) const override;
    /// Angle of (q, p < 0) in closed form.
    double angle_of(double q, double h) const override;
    /// (q, p) at angle theta in closed form.
    std::pair<double, double> point_at(double theta, double h) const override;
    /// d(q, p)/dh at fixed theta = (q, p) / (2 h) in closed form.
    std::array<double, 2> point_slope(double theta, double h) const override;
    /// Signed angle of (q, p) in closed form.
    double angle_on_level(double q, double p, double h) const override;
    /// Closed forms: a few ulps.
    double relative_accuracy() const override;
    /// dT/dh = 0 (isochronous).
    Estimate period_slope(double h) const override;
    /// d angle / dh = q omega / (2 sqrt(2) h sqrt(h - V(q))) in closed form.
    Estimate angle_slope(double q, double h) const override;
    /// The frequency parameter omega.
    double omega() const { return omega_; }

private:
    double omega_;
};

/// V = omega^2 / (2 alpha^2) tan^2(alpha q), |q| < pi / (2 alpha): H(I) = omega I + alpha^2 I^2 / 2.
/// Beyond the wall of the well (|q| >= pi / (2 alpha)) V = +inf and V' = sign(q) inf.
class Tan final : public Potential {
public:
    /// Throws std::invalid_argument unless omega and alpha lie in [1e-100, 1e100].
    Tan(double omega, double alpha);
    /// V(q) in closed form.
    double V(double q) const override;
    /// V'(q) in closed form.
    double dV(double q) const override;
    /// Short description with the parameters.
    std::string name() const override;
    /// pi / (2 alpha): the wall of the well.
    double q_limit() const override;
    /// Turning points in closed form.
    std::pair<double, double> turning_points(double h) const override;
    /// T(h) in closed form.
    double period(double h) const override;
    /// I(h) in closed form.
    double action(double h) const override;
    /// H(I) in closed form.
    double energy(double I) const override;
    /// Angle of (q, p < 0) in closed form.
    double angle_of(double q, double h) const override;
    /// (q, p) at angle theta in closed form.
    std::pair<double, double> point_at(double theta, double h) const override;
    /// d(q, p)/dh at fixed theta in closed form (the derivative of point_at's expressions).
    std::array<double, 2> point_slope(double theta, double h) const override;
    /// Signed angle of (q, p) in closed form.
    double angle_on_level(double q, double p, double h) const override;
    /// Closed forms: a few ulps.
    double relative_accuracy() const override;
    /// dT/dh = -2 pi alpha^2 / W^3, W = sqrt(omega^2 + 2 alpha^2 h), in closed form.
    Estimate period_slope(double h) const override;
    /// d angle / dh = sin(alpha q) omega^2 / (2 sqrt(2) alpha h W cos(alpha q) sqrt(h - V(q))) in closed form.
    Estimate angle_slope(double q, double h) const override;
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
    /// The base's V.
    double V(double q) const override { return base_->V(q); }
    /// The base's V'.
    double dV(double q) const override { return base_->dV(q); }
    /// "Numerical(<base>)".
    std::string name() const override { return "Numerical(" + base_->name() + ")"; }
    /// The base's q_limit.
    double q_limit() const override { return base_->q_limit(); }
    /// The wrapped potential.
    const std::shared_ptr<const Potential>& base() const { return base_; }

private:
    std::shared_ptr<const Potential> base_;
};

}  // namespace hovering
