#pragma once
// The oscillators-step flow (sec:setup) on GSL odeiv2 and its Poincare return map to
// Sigma_h = {p1 = 0, dp1/dt < 0}: section coordinates, impacts with the right wall (geometry
// Wall: the infinite wall q1 = qw1; Step: q2 < qw2 only) and the upper wall (Step, q1 < qw1),
// corner hits, grazing, and per-orbit status. Events are searched on every accepted step,
// including minima of a wall distance inside a step (near-grazing dips).

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hovering/potential.hpp"

namespace hovering {

/// Which walls the flow sees.
enum class Geometry : std::int8_t {
    None = 0,  ///< the smooth flow, no impact events
    Wall = 1,  ///< the infinite wall q1 = qw1
    Step = 2,  ///< the step {q1 < qw1, q2 < qw2}: right wall, upper wall, corner
};

/// Per-orbit outcome of a return-map computation.
enum class FlowStatus : std::int8_t {
    Ok = 0,         ///< returned to Sigma_h
    Corner = 1,     ///< hit the corner (orbit stops)
    Grazing = 2,    ///< touched a wall tangentially
    StepLimit = 3,  ///< max_steps reached before returning
    NonFinite = 4,  ///< the state became non-finite
    ImpactLimit = 5,  ///< more impacts than max_impacts in one return (chattering)
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
    std::shared_ptr<const Potential> V1, V2;
    Coupling coupling;
    double eps = 0.0;
    double qw1 = -1.0, qw2 = -0.5;
    Geometry geometry = Geometry::None;
    /// Validate (throws std::invalid_argument naming the bad value).
    void validate() const;
    /// H(z), z = (q1, p1, q2, p2); eps = 0 evaluates no coupling.
    double energy(const double* z) const;
    /// dz/dt.
    void rhs(const double* z, double* dz) const;
};

/// Integrator settings.
struct FlowOptions {
    std::string stepper = "rk8pd";  ///< GSL explicit RK: rk2, rk4, rkf45, rkck, rk8pd
    double rtol = 1e-10;            ///< relative tolerance of the step control
    double atol = 1e-12;            ///< absolute tolerance of the step control
    double event_tol = 1e-15;       ///< time accuracy of located events (Newton on exact steps)
    std::int64_t max_steps = 1000000;  ///< per return
    int max_impacts = 100;          ///< per return; more ends the orbit with ImpactLimit
    double grazing_tol = 1e-12;     ///< |min distance to a wall| below which an orbit touches it tangentially
    double corner_tol = 1e-10;      ///< distance to the corner below which an impact is a corner hit
    /// Validate (throws std::invalid_argument naming the bad value and the allowed range).
    void validate() const;
};

/// Point of Sigma_h from section coordinates (theta, I) of the unperturbed H2 at energy h:
/// (q2, p2) = S2^{-1}(theta, I), p1 = 0, q1 > 0 solves H = h (the root near q1's maximum).
/// Throws std::invalid_argument when no such point exists (e.g. h below H2(I)).
std::array<double, 4> section_point(const FlowSystem& s, double h, double theta, double I);

/// (theta, I) = S2(q2, p2) of a state (unperturbed H2; theta in [-pi, pi), sign(theta) = -sign(p2)).
std::array<double, 2> section_coordinates(const FlowSystem& s, const double* z);

/// Result of one return.
struct ReturnResult {
    std::array<double, 4> z{};  ///< state at the return (or where the orbit stopped)
    double time = 0;            ///< return time
    FlowStatus status = FlowStatus::Ok;
    std::string itinerary;      ///< wall impacts in order ('R', '1'); empty for no impact
    double energy_error = 0;    ///< |H(z) - H(z0)|
    std::int64_t steps = 0;     ///< accepted integrator steps
};

/// Follow the flow from a point of Sigma_h until it returns to Sigma_h.
ReturnResult return_map(const FlowSystem& s, const std::array<double, 4>& z0, const FlowOptions& opt);

}  // namespace hovering
