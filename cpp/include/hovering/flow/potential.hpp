#pragma once
// One-degree-of-freedom potentials V(q) with a single minimum V(0) = 0 (convex: q V'(q) > 0), and
// their action-angle variables. Closed forms where they exist (harmonic, Tan); otherwise GSL
// quadrature (QAWS, which integrates the 1/sqrt endpoint singularities exactly) and Brent root
// finding, so that any smooth single-well potential given V and V' works.
//
// Angle convention of the paper (sec:setup): theta = 0 at the right turning point (q = q_max,
// p = 0, dp/dt < 0), increasing with time, so on [-pi, pi) sign(theta) = -sign(p).

#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace hovering {

/// A computed value and an estimate of its absolute error.
struct Estimate {
    double value;  ///< the value
    double error;  ///< estimated absolute error (0: exact)
};

/// One parameter of a compiled potential: its name and the closed range its constructor accepts.
struct PotentialParam {
    const char* name;  ///< "omega", "alpha": the key in scene files and plans, the bound property
    double lo;         ///< smallest value allowed
    double hi;         ///< largest value allowed
};

/// How everything outside the core knows a compiled potential (its class's kInfo): its kind, its
/// class, its formula and its parameters in the constructor's order.
template <std::size_t N>
struct PotentialInfo {
    const char* kind;                      ///< "harmonic": the `kind` of scene files and plans
    const char* cls;                       ///< "Harmonic": the class, as bound into Python
    const char* formula;                   ///< "V = omega^2 q^2 / 2": one line for docs and messages
    std::array<PotentialParam, N> params;  ///< the constructor's parameters, in order
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
    /// (V(q), V'(q)), the same numbers as V and dV (a potential may share their work).
    virtual std::array<double, 2> V_dV(double q) const { return {V(q), dV(q)}; }
    /// Short description, e.g. "Harmonic(omega=1)".
    virtual std::string name() const = 0;
    /// Largest |q| for which V is defined (infinity if unbounded).
    virtual double q_limit() const;

    /// Turning points (q_min < 0 < q_max) with V = h > 0. Generic path: on each side the largest
    /// |q| with V(q) <= h (the root to 1 ulp; for a bounded well whose V stays below h up to its
    /// wall in double precision, e.g. Tan above ~1e31, the last double before q_limit).
    virtual std::pair<double, double> turning_points(double h) const;
    /// A cheap estimate of q_max = turning_points(h).second where one exists in closed form (a
    /// starting point for Newton's method, not an answer), else NaN.
    virtual double q_max_estimate(double h) const;
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
    /// Its kind, class and parameter (omega in [1e-100, 1e100]: omega^2 stays a normal double).
    static constexpr PotentialInfo<1> kInfo{
        "harmonic", "Harmonic", "V = omega^2 q^2 / 2", {{{"omega", 1e-100, 1e100}}}};
    /// Throws std::invalid_argument unless omega lies in kInfo's range.
    explicit Harmonic(double omega);
    /// The constructor's parameters, in kInfo's order.
    std::array<double, 1> parameters() const { return {omega_}; }
    /// V(q) in closed form.
    double V(double q) const override;
    /// V'(q) in closed form.
    double dV(double q) const override;
    /// Short description with the parameters.
    std::string name() const override;
    /// Turning points in closed form.
    std::pair<double, double> turning_points(double h) const override;
    /// q_max in closed form (no check of h: NaN for h <= 0).
    double q_max_estimate(double h) const override;
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
    /// Its kind, class and parameters (each in [1e-100, 1e100]: the ratios of V stay normal doubles).
    static constexpr PotentialInfo<2> kInfo{"tan",
                                            "Tan",
                                            "V = omega^2 / (2 alpha^2) tan^2(alpha q)",
                                            {{{"omega", 1e-100, 1e100}, {"alpha", 1e-100, 1e100}}}};
    /// Throws std::invalid_argument unless omega and alpha lie in kInfo's ranges.
    Tan(double omega, double alpha);
    /// The constructor's parameters, in kInfo's order.
    std::array<double, 2> parameters() const { return {omega_, alpha_}; }
    /// V(q) in closed form.
    double V(double q) const override;
    /// V'(q) in closed form.
    double dV(double q) const override;
    /// V and V' from one tan.
    std::array<double, 2> V_dV(double q) const override;
    /// Short description with the parameters.
    std::string name() const override;
    /// pi / (2 alpha): the wall of the well.
    double q_limit() const override;
    /// Turning points in closed form.
    std::pair<double, double> turning_points(double h) const override;
    /// q_max in closed form (no check of h: NaN for h <= 0).
    double q_max_estimate(double h) const override;
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
    /// The base's V_dV.
    std::array<double, 2> V_dV(double q) const override { return base_->V_dV(q); }
    /// "Numerical(<base>)".
    std::string name() const override { return "Numerical(" + base_->name() + ")"; }
    /// The base's q_limit.
    double q_limit() const override { return base_->q_limit(); }
    /// The wrapped potential.
    const std::shared_ptr<const Potential>& base() const { return base_; }

private:
    std::shared_ptr<const Potential> base_;
};

// ------------------------------------------------------------------ the registry of compiled kinds

/// A list of potential classes (each with a static kInfo and parameters()).
template <class... P>
struct PotentialList {};

/// The compiled potentials: the one list of the classes that scene files and plans name by kind,
/// that the bindings bind and pickle by their parameters, and that the system checks know. Adding
/// a class here (with its kInfo, parameters() and a constructor taking them in order) makes it a kind.
using CompiledPotentials = PotentialList<Harmonic, Tan>;

/// A compiled kind as the run time sees it (potential_kinds()).
struct PotentialKind {
    std::string kind;                     ///< PotentialInfo::kind
    std::string cls;                      ///< PotentialInfo::cls
    std::string formula;                  ///< PotentialInfo::formula
    std::vector<PotentialParam> params;   ///< PotentialInfo::params
};

/// Every compiled kind, in CompiledPotentials' order.
const std::vector<PotentialKind>& potential_kinds();
/// The compiled kind named `kind`; throws std::invalid_argument naming the value and the kinds.
const PotentialKind& potential_kind(const std::string& kind);
/// A potential of a compiled kind from its parameters, in the kind's order: the one factory of the
/// plan reader and the sweep. Throws std::invalid_argument for an unknown kind, a wrong number of
/// parameters (naming them) or a value the class refuses.
std::shared_ptr<const Potential> make_potential(const std::string& kind, const std::vector<double>& params);
/// Throw std::invalid_argument ("<cls>: <name> must lie in [lo, hi], got v") unless v is in p's range.
void check_parameter(const char* cls, const PotentialParam& p, double v);

}  // namespace hovering
