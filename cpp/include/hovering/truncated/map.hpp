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
#include <string>
#include <utility>
#include <vector>

#include "hovering/batch.hpp"
#include "hovering/curve.hpp"
#include "hovering/simd.hpp"  // simd_width, simd_level, ...: declared here before they served every kernel
#include "hovering/tangent.hpp"
#include "hovering/truncated/arcs.hpp"
#include "hovering/truncated/forcing.hpp"
#include "hovering/types.hpp"

namespace hovering {

/// Where a batch iteration writes; a null pointer means "not recorded".
///
/// Arrays are row-major. With e = IterateOptions::every, the orbit arrays hold the states
/// x_0, x_e, x_2e, ... (n_orbits, n_steps / e + 1) and the regions the returns taken from them,
/// (n_orbits, ceil(n_steps / e)); entries an orbit did not reach are NaN (Region::None).
struct IterateOutput {
    double* phi_final = nullptr;  ///< (n_orbits,) last state reached
    double* K_final = nullptr;    ///< (n_orbits,)
    double* orbit_phi = nullptr;  ///< (n_orbits, n_steps/every + 1), NaN after the orbit stopped
    double* orbit_K = nullptr;    ///< (n_orbits, n_steps/every + 1), NaN after the orbit stopped
    /// (n_orbits, ceil(n_steps/every)), Region::None after the orbit stopped; with stop_on_exit the
    /// return that leaves the watched set is recorded (its region), though not taken.
    std::int8_t* regions = nullptr;
    double* rotation = nullptr;          ///< (n_orbits,) mean of omega_a over the steps taken (NaN if none)
    std::int8_t* status = nullptr;       ///< (n_orbits,) Status, always written when non-null
    std::int64_t* steps_done = nullptr;  ///< (n_orbits,) steps actually taken
    std::int64_t* exit_step = nullptr;   ///< (n_orbits,) first n with region(x_n) outside the set, else -1
    /// (n_orbits,) bit r set: the orbit reached a point of Region r (the points steps were taken
    /// from, and the one where it left the watched set)
    std::int8_t* visited = nullptr;
    double* K_min = nullptr;  ///< (n_orbits,) min of K over the states x_0 .. x_steps_done
    double* K_max = nullptr;  ///< (n_orbits,) max of K over the same states
    /// (n_orbits, kRegionCount) returns per region code 0..4 (those taken, and with stop_on_exit
    /// the one that leaves the watched set: the returns whose region `visited` sets)
    std::int64_t* residence = nullptr;
    std::int64_t* stop_step = nullptr;  ///< (n_orbits,) first n with x_n in the stop set, else -1
    /// Record "jacobian": each orbit's product of the step Jacobians it took (QR form); status
    /// Corner when a step was taken from an arc start (the derivative there is one-sided).
    TangentOutput tangent;
};

/// One step with the derivative of the branch it takes (the truncated map is smooth on each arc).
struct StepJacobian {
    double phi = 0, K = 0;         ///< the image (as step())
    double J[4] = {1, 0, 0, 1};    ///< d(phibar, Kbar) / d(phi, K), row-major
    Region region = Region::None;  ///< the arc the point lies in
    /// Ok, or Corner for a point exactly on an arc start (a corner-singularity curve): the map is
    /// discontinuous there and J is the one-sided derivative of the arc that owns the start.
    Status status = Status::Ok;
};

/// What a batch iteration of a truncated map does besides stepping: the shared BatchOptions and
/// the choice of kernel.
struct IterateOptions : BatchOptions {
    Kernel kernel = Kernel::Simd;  ///< which step implementation to use
    /// SIMD kernel only: SLEEF's 3.5-ulp sin instead of the 1-ulp one (about 20% faster per step).
    bool fast_sin = false;
};

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
    /// One forward step (scalar libm path); arcs are half-open [start, next start), see arc_starts().
    std::pair<double, double> step(double phi, double K) const;
    /// One step and its Jacobian [[1, w'], [eps f'(phibar), 1 + eps f'(phibar) w']], w' = d omega_a / dK
    /// of the point's arc (determinant 1: the map preserves area); throws as step().
    StepJacobian step_jacobian(double phi, double K) const;
    /// One backward step: inverse of step() on the band, with the same boundary convention.
    std::pair<double, double> step_inverse(double phi, double K) const;
    /// Left ends of J_1, J_R, J_0 on the circle K (K < 0), each in [-pi, pi): each arc owns its start.
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
    /// Height K1 - kick of a preimage, clamped into the band when K1 is an image of a band height.
    double preimage_height(double K1, double kick) const;
    /// Whether p is the image of an arc start at a height merged with K0 by the rounding of K + kick.
    bool merged_start(double p, double K0, double K1, double kick, double& phi0, double& Ks) const;

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
TruncatedMap make_truncated_map(double eps, double Omega0, double theta_w, double tau0, double tau1, double lam,
                                double K_max = std::numeric_limits<double>::infinity());

/// Wrap an angle to [-pi, pi).
double wrap_angle(double x);

}  // namespace hovering
