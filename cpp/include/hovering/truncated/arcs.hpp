#pragma once
// Arc models of the truncated family: Omega(K), |J_R|(K), |J_1|(K) either in the closed form of
// the paper's F_eps (eq:omegaofalead) or as tables splined in K (|J_1| in sqrt(-K)).

#include <vector>

namespace hovering {

/// Omega(K), |J_R|(K), |J_1|(K) at one K (the arcs vanish for K >= 0).
struct ArcLengths {
    double Omega;  ///< rotation of J_0 / J_0u
    double JR;     ///< length of J_R (0 for K >= 0)
    double J1;     ///< length of J_1 (0 for K >= 0)
};

/// d/dK of Omega(K), |J_R|(K), |J_1|(K) at one K (0 for the arcs at K >= 0, where they do not exist).
struct ArcSlopes {
    double Omega;  ///< dOmega / dK
    double JR;     ///< d|J_R| / dK (0 for K >= 0)
    double J1;     ///< d|J_1| / dK (0 for K >= 0; unbounded as K -> 0-: a square-root singularity)
};

/// Open interval of K on which a map is defined.
struct Band {
    double lo;  ///< lower end (< 0)
    double hi;  ///< upper end (> 0, may be +inf)
};

/// Arcs of the paper's F_eps: Omega = Omega0 + tau0 K, |J_R| = 2(pi - theta_w) + tau1 K, |J_1| = 2 lam sqrt(-K).
struct AnalyticArcs {
    double Omega0, theta_w, tau0, tau1, lam;  ///< the paper's parameters (eq:truncatedmap)

    /// Validate the parameters; throws std::invalid_argument naming the bad one and its range.
    void validate() const;
    /// Arc lengths at one K.
    ArcLengths at(double K) const;
    /// Their slopes at one K: (tau0, tau1, -lam / sqrt(-K)) below K = 0, (tau0, 0, 0) above.
    ArcSlopes slopes(double K) const;
    /// Lowest K of the band: all three arc lengths stay in (0, 2 pi) on (lo, 0).
    double band_lo() const;
};

/// A smooth function sampled on an increasing grid, interpolated by a GSL natural cubic spline.
class Spline {
public:
    /// Build from x (strictly increasing, >= 3 points) and y (same size, finite).
    Spline(std::vector<double> x, std::vector<double> y, const char* name);
    /// Frees the GSL spline.
    ~Spline();
    /// A copy with its own GSL spline.
    Spline(const Spline&);
    /// Not assignable (const tables).
    Spline& operator=(const Spline&) = delete;
    /// Value at x (x inside [x.front(), x.back()]); thread-safe (no shared accelerator).
    double operator()(double x) const;
    /// First derivative at x (the spline's own, x clamped as by operator()).
    double derivative(double x) const;
    /// Smallest grid abscissa.
    double xmin() const { return x_.front(); }
    /// Largest grid abscissa.
    double xmax() const { return x_.back(); }
    /// The grid abscissae.
    const std::vector<double>& x() const { return x_; }
    /// The grid values.
    const std::vector<double>& y() const { return y_; }

private:
    std::vector<double> x_, y_;
    const char* name_;
    void* spline_;  // gsl_spline*, opaque so that GSL headers stay out of the public interface
};

/// Arcs given as tables: Omega on a K grid, |J_R| on its K <= 0 part, |J_1| interpolated in sqrt(-K).
///
/// |J_1| is smooth in sqrt(-K), not in K (thm:cornersing), so it is splined in s = sqrt(-K);
/// |J_R| and Omega are smooth in K.
struct TabulatedArcs {
    /// Build from a K grid (strictly increasing, containing 0 and >= 3 points with K <= 0).
    TabulatedArcs(const std::vector<double>& K, const std::vector<double>& Omega, const std::vector<double>& JR,
                  const std::vector<double>& J1);
    /// Arc lengths at one K (K inside the grid).
    ArcLengths at(double K) const;
    /// Their slopes at one K: the splines' derivatives, |J_1|'s through s = sqrt(-K) (d/dK = -1 / (2 s) d/ds).
    ArcSlopes slopes(double K) const;
    /// Lowest K of the grid range on which all arc lengths stay in (0, 2 pi) up to K = 0.
    double band_lo() const;
    /// Largest K of the grid.
    double kmax() const { return Omega.xmax(); }
    /// First K from 0 towards +inf (direction > 0) or -inf where the spline's |Omega| exceeds 1e6
    /// (sampled 64 times per grid interval, then bisected); +-inf if it never does on the grid.
    double omega_limit(double direction) const;

    Spline Omega;  ///< Omega(K) on the whole grid
    Spline JR;     ///< |J_R|(K) for K <= 0
    Spline J1s;    ///< |J_1| as a function of s = sqrt(-K)
};

}  // namespace hovering
