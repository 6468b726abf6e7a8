#pragma once
// The truncated near-tangency map F_eps of the paper (eq:truncatedmap) and the general family
// F_{eps1,eps2} (eq:trunceps1eps2): a perturbed interval-exchange map on the cylinder (phi, K).
//
// Both share one implementation, MapCore<Arcs, Forcing>: the Arcs policy gives Omega(K), |J_R|(K)
// and |J_1|(K); the Forcing policy gives the odd function f. The arcs are always placed by
// eq:phi1rsymmetric, which is what makes every member of the family reversible
// (lem:truncreturnmap): R_eps F R_eps = F^{-1} with R_eps(phi, K) = (-phi, K - eps f(phi)).

#include <atomic>
#include <cstdint>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include "hovering/types.hpp"

namespace hovering {

/// Omega(K), |J_R|(K), |J_1|(K) at one K (the arcs vanish for K >= 0).
struct ArcLengths {
    double Omega;  ///< rotation of J_0 / J_0u
    double JR;     ///< length of J_R (0 for K >= 0)
    double J1;     ///< length of J_1 (0 for K >= 0)
};

/// Open interval of K on which a map is defined.
struct Band {
    double lo;  ///< lower end (< 0)
    double hi;  ///< upper end (> 0, may be +inf)
};

/// Arcs of the paper's F_eps: Omega = Omega0 + tau0 K, |J_R| = 2(pi - theta_w) + tau1 K, |J_1| = 2 lam sqrt(-K).
struct AnalyticArcs {
    double Omega0, theta_w, tau0, tau1, lam;

    /// Validate the parameters; throws std::invalid_argument naming the bad one and its range.
    void validate() const;
    /// Arc lengths at one K.
    ArcLengths at(double K) const;
    /// Lowest K of the band: all three arc lengths stay in (0, 2 pi) on (lo, 0).
    double band_lo() const;
};

/// A smooth function sampled on an increasing grid, interpolated by a GSL natural cubic spline.
class Spline {
public:
    /// Build from x (strictly increasing, >= 3 points) and y (same size, finite).
    Spline(std::vector<double> x, std::vector<double> y, const char* name);
    ~Spline();
    Spline(const Spline&);
    Spline& operator=(const Spline&) = delete;
    /// Value at x (x inside [x.front(), x.back()]); thread-safe (no shared accelerator).
    double operator()(double x) const;
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
    TabulatedArcs(const std::vector<double>& K, const std::vector<double>& Omega,
                  const std::vector<double>& JR, const std::vector<double>& J1);
    /// Arc lengths at one K (K inside the grid).
    ArcLengths at(double K) const;
    /// Lowest K of the grid range on which all arc lengths stay in (0, 2 pi) up to K = 0.
    double band_lo() const;
    /// Largest K of the grid.
    double kmax() const { return Omega.xmax(); }

    Spline Omega;  ///< Omega(K) on the whole grid
    Spline JR;     ///< |J_R|(K) for K <= 0
    Spline J1s;    ///< |J_1| as a function of s = sqrt(-K)
};

/// f(phi) = sin(phi): the first Fourier mode, the paper's choice for F_eps.
struct SineForcing {
    /// f at one angle.
    double at(double phi) const;
};

/// f(phi) = sum_k b_k sin(k phi), k = 1..n: any odd forcing, which keeps the map reversible.
struct FourierForcing {
    std::vector<double> b;  ///< b[0] multiplies sin(phi), b[1] sin(2 phi), ...
    /// f at one angle.
    double at(double phi) const;
};

/// Where a batch iteration writes; a null pointer means "not recorded".
///
/// Orbit arrays are row-major (n_orbits, n_steps + 1), regions (n_orbits, n_steps).
struct IterateOutput {
    double* phi_final = nullptr;       ///< (n_orbits,) last state reached
    double* K_final = nullptr;         ///< (n_orbits,)
    double* orbit_phi = nullptr;       ///< (n_orbits, n_steps+1), NaN after the orbit stopped
    double* orbit_K = nullptr;         ///< (n_orbits, n_steps+1), NaN after the orbit stopped
    std::int8_t* regions = nullptr;    ///< (n_orbits, n_steps), Region::None after the orbit stopped
    double* rotation = nullptr;        ///< (n_orbits,) mean of omega_a over the steps taken (NaN if none)
    std::int8_t* status = nullptr;     ///< (n_orbits,) Status, always written when non-null
    std::int64_t* steps_done = nullptr;  ///< (n_orbits,) steps actually taken
    std::int64_t* exit_step = nullptr;   ///< (n_orbits,) first n with region(x_n) outside the set, else -1
};

/// What a batch iteration does besides stepping.
struct IterateOptions {
    std::int64_t n_steps = 0;  ///< steps per orbit (>= 0)
    /// Bit r set: Region r is in the watched set (for exit_step / stop_on_exit); 0 disables the watch.
    unsigned exit_mask = 0;
    bool stop_on_exit = false;        ///< stop an orbit (Status::Exited) when it first leaves the set
    int n_threads = 0;                ///< worker threads; 0 = all hardware threads
    Kernel kernel = Kernel::Simd;     ///< which step implementation to use
    /// SIMD kernel only: SLEEF's 3.5-ulp sin instead of the 1-ulp one (about 20% faster per step).
    bool fast_sin = false;
    const std::atomic<bool>* cancel = nullptr;  ///< polled every few steps; set it to stop early
};

struct OrbitSource;  // work queue of a batch iteration (internal)

/// One member of the truncated family; see the file comment.
template <class Arcs, class Forcing>
class MapCore {
public:
    /// Construct and validate; K_max caps the band from above (the map itself is defined for all K >= 0).
    MapCore(double eps, Arcs arcs, Forcing forcing, double K_max);

    /// Region of one point; throws if K is outside the band or a value is not finite.
    Region region(double phi, double K) const;
    /// Rotation omega_a(K) of the region the point lies in.
    double rotation(double phi, double K) const;
    /// Region and rotation together; `who` prefixes error messages.
    std::pair<Region, double> classify_point(double phi, double K, const char* who) const;
    /// One forward step (scalar libm path).
    std::pair<double, double> step(double phi, double K) const;
    /// One backward step: the exact inverse of step().
    std::pair<double, double> step_inverse(double phi, double K) const;
    /// Left ends of J_1, J_R, J_0 on the circle K (K < 0), each in [-pi, pi).
    std::vector<double> arc_starts(double K) const;

    /// Iterate n orbits; phi0/K0 have n entries; see IterateOutput for what is written.
    void iterate(const double* phi0, const double* K0, std::int64_t n, const IterateOptions& opt,
                 const IterateOutput& out) const;

    /// Band of K on which the map is defined.
    Band band() const { return band_; }
    /// Perturbation amplitude eps.
    double eps() const { return eps_; }
    /// The arc model.
    const Arcs& arcs() const { return arcs_; }
    /// The forcing.
    const Forcing& forcing() const { return forcing_; }
    /// Arc lengths at K (zero arcs for K >= 0); throws outside the band.
    ArcLengths arc_lengths(double K) const;

private:
    void check_point(double phi, double K, const char* who) const;
    template <bool Fast>
    void run_simd(const double* phi0, const double* K0, OrbitSource& src,
                  const IterateOptions& opt, const IterateOutput& out) const;
    void run_scalar(const double* phi0, const double* K0, OrbitSource& src,
                    const IterateOptions& opt, const IterateOutput& out) const;

    double eps_;
    Arcs arcs_;
    Forcing forcing_;
    Band band_;
};

/// The paper's F_eps (eq:truncatedmap).
using TruncatedMap = MapCore<AnalyticArcs, SineForcing>;
/// The general family F_{eps1,eps2} (eq:trunceps1eps2) with tabulated arcs and Fourier forcing.
using TruncatedFamily = MapCore<TabulatedArcs, FourierForcing>;

/// Build F_eps from the paper's six parameters (validated).
TruncatedMap make_truncated_map(double eps, double Omega0, double theta_w, double tau0, double tau1,
                                double lam, double K_max = std::numeric_limits<double>::infinity());

/// Wrap an angle to [-pi, pi).
double wrap_angle(double x);

/// Whether this build's SIMD kernel uses 4-wide AVX2 (true) or 2-wide SSE2 (false) vectors.
bool simd_is_avx2();

}  // namespace hovering
