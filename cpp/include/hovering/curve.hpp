#pragma once
// A closed curve K(phi) on the circle, and the stop condition "above / below a curve" that the
// batch iterations of every map test at each state they reach.
//
// The curve is the periodic cubic spline (C^2) through n samples K_j at the uniform grid
// phi_j = -pi + 2 pi j / n. Why a cubic spline and not the trigonometric interpolant: on a smooth
// curve both converge fast (the spline as h^4, h = 2 pi / n), but the invariant curves of the
// piecewise-smooth maps have kinks at the corner curves, where the trigonometric interpolant rings
// over the whole circle (Gibbs) while the spline's error stays local (it decays by a factor
// 2 - sqrt(3) = 0.27 per cell away from a kink); and a spline value costs O(1) operations (one
// cell, four coefficients), which the kernels pay once per step, where a trigonometric sum costs
// O(n). The spline is exact at the samples: a sample's cell polynomial at s = 0 is K_j + 0.
//
// One evaluation: value() here (Python's Curve.__call__, the scalar kernel and the flow map call
// it); the SIMD kernel evaluates the same cell polynomial with the same operations in the same
// order on packets (compiled with -ffp-contract=off), so all agree bit for bit.

#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

namespace hovering {

/// A closed curve K(phi) on the circle: the periodic cubic spline through samples on a uniform grid.
class Curve {
public:
    /// Through K[j] at phi_j = -pi + 2 pi j / n: one sample is a constant, two are refused (use
    /// one or at least three), three or more give the periodic cubic spline; all finite.
    explicit Curve(std::vector<double> K);

    /// K at phi: NaN for NaN (a missing angle), else |phi| <= 1e6 (wrapped to [-pi, pi) first).
    double operator()(double phi) const;
    /// K at phi in [-pi, pi) (unchecked): the evaluation every caller shares.
    double value(double phi) const {
        if (n_ == 1) return samples_[0];
        const double t = (phi + kPi) * scale_;  // in [0, n]: n only when phi + pi rounds up to 2 pi
        const double f = std::floor(t);
        const double s = t - f;  // exact (Sterbenz), in [0, 1)
        std::int64_t i = static_cast<std::int64_t>(f);
        if (i >= n_) i -= n_;  // t == n: the start of cell 0, s = 0
        const double* c = &cells_[std::size_t(4 * i)];
        return c[0] + s * (c[1] + s * (c[2] + s * c[3]));
    }

    /// Number of samples.
    std::int64_t size() const { return n_; }
    /// The samples K_j.
    const std::vector<double>& samples() const { return samples_; }
    /// Whether the curve is one constant (a single sample).
    bool is_constant() const { return n_ == 1; }
    /// Cell polynomials, four coefficients per cell (y, b, c, d: y + s (b + s (c + s d)), s in [0, 1)).
    const double* cells() const { return cells_.data(); }
    /// Cells per radian, n / (2 pi).
    double scale() const { return scale_; }
    /// A number at or below every value value() returns (the spline's minimum less its rounding).
    double lower() const { return lower_; }
    /// A number at or above every value value() returns.
    double upper() const { return upper_; }

    /// Most samples a curve takes (2^24: the SIMD kernel gathers cells with 32-bit indices).
    static constexpr std::int64_t kMaxSamples = std::int64_t(1) << 24;
    /// pi as the evaluation uses it.
    static constexpr double kPi = 3.14159265358979323846;

private:
    std::int64_t n_;
    std::vector<double> samples_;
    std::vector<double> cells_;
    double scale_ = 0, lower_ = 0, upper_ = 0;
};

/// Which side of its curve a stop condition's set lies on.
enum class StopSide : std::int8_t {
    None = 0,   ///< no stop condition
    Above = 1,  ///< the set K >= curve(phi)
    Below = 2,  ///< the set K <= curve(phi)
};

/// Stop an orbit the first time a state (phi, K) lies in the set on one side of a curve.
struct StopCondition {
    std::shared_ptr<const Curve> curve;  ///< the curve (null with StopSide::None)
    StopSide side = StopSide::None;      ///< which side

    /// Whether a stop condition is set.
    bool active() const { return side != StopSide::None; }
    /// Whether (phi, K), phi in [-pi, pi), lies in the set.
    bool reached(double phi, double K) const {
        const double c = curve->value(phi);
        return side == StopSide::Above ? K >= c : K <= c;
    }
    /// Throws unless the condition is consistent (a side with a curve, or neither).
    void validate() const;
};

}  // namespace hovering
