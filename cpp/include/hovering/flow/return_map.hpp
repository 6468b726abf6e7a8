#pragma once
// The flow of a FlowSystem on GSL odeiv2 and its Poincare return map to
// Sigma_h = {p1 = 0, dp1/dt < 0}: section coordinates, impacts with the right wall (geometry
// Wall: the infinite wall q1 = qw1; Step: q2 < qw2 only) and the upper wall (Step, q1 < qw1),
// corner hits, grazing, and per-orbit status. Events are searched on every accepted step,
// including minima of a wall distance inside a step (near-grazing dips).

#include <array>
#include <atomic>
#include <cstdint>
#include <string>

#include "hovering/flow/system.hpp"
#include "hovering/types.hpp"

namespace hovering {

/// Per-orbit outcome of a return-map computation.
enum class FlowStatus : std::int8_t {
    Ok = 0,           ///< returned to Sigma_h
    Corner = 1,       ///< hit the corner (orbit stops)
    Grazing = 2,      ///< touched a wall tangentially
    StepLimit = 3,    ///< max_steps reached before returning
    NonFinite = 4,    ///< the state became non-finite
    ImpactLimit = 5,  ///< more impacts than max_impacts in one return (chattering)
    OffSection = 6,   ///< the starting point is not on Sigma_h at this energy (nothing integrated)
    Interrupted = 7,  ///< the caller cancelled the batch before or during this return
};

/// The orbit outcome (Status) of a return that ended with this FlowStatus.
Status orbit_status(FlowStatus s);

/// Integrator settings.
struct FlowOptions {
    std::string stepper = "rk8pd";  ///< GSL explicit RK (rk2, rk4, rkf45, rkck, rk8pd) or msadams
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

/// section_point without exceptions for numerical outcomes: false (z untouched, *why set when
/// non-null) where (theta, I) has no point of Sigma_h; bad parameters (h, theta) still throw.
bool try_section_point(const FlowSystem& s, double h, double theta, double I, std::array<double, 4>& z,
                       std::string* why = nullptr);

/// (theta, I) = S2(q2, p2) of a state (unperturbed H2; theta in [-pi, pi), sign(theta) = -sign(p2)).
std::array<double, 2> section_coordinates(const FlowSystem& s, const double* z);

/// Result of one return.
struct ReturnResult {
    std::array<double, 4> z{};  ///< state at the return (or where the orbit stopped)
    double time = 0;            ///< return time (up to the stop for a non-Ok status)
    FlowStatus status = FlowStatus::Ok;
    /// Impacts in order ('R' right wall, '1' upper wall: "R", "1", "11", "R1", ...); without
    /// impact "0" if the segment crossed q1 = qw1 above the step, "u" if it never crossed it;
    /// "" for the smooth flow (geometry None) and for a return that did not end Ok without impact.
    std::string itinerary;
    double energy_error = 0;    ///< |H(z) - H(z0)|
    std::int64_t steps = 0;     ///< accepted integrator steps
};

/// Region of Sigma_h a return's itinerary labels: "u" Beside (J_0u), "0" Above (J_0), "1" Upper
/// (J_1), "R" Right (J_R), two or more impacts Multi, anything else (no walls, no return) None.
Region region_of(const std::string& itinerary);

/// Follow the flow from a point of Sigma_h until it returns to Sigma_h.
ReturnResult return_map(const FlowSystem& s, const std::array<double, 4>& z0, const FlowOptions& opt);

/// Where a batch of returns writes; null pointers are not written. Arrays have one entry per
/// orbit (z: 4 per orbit, row-major).
struct ReturnMapsOutput {
    double* z = nullptr;             ///< image states (NaN for OffSection)
    double* time = nullptr;          ///< return times
    std::int8_t* status = nullptr;   ///< FlowStatus
    std::int8_t* region = nullptr;   ///< Region of the return (region_of(itinerary))
    double* energy_error = nullptr;  ///< |H(image) - H(start)|
    std::int64_t* steps = nullptr;   ///< accepted integrator steps
    std::string* itinerary = nullptr;
};

/// Returns of n states z0 (row-major (n, 4)) on the core's thread pool (n_threads, 0 = all
/// cores). A state with a non-finite entry is OffSection (a failed section point); every orbit
/// gets its own status, none stops the batch. Setting *cancel ends the batch promptly: returns not
/// finished are Interrupted. Bad options throw std::invalid_argument before anything runs.
void return_maps(const FlowSystem& s, const double* z0, std::int64_t n, const FlowOptions& opt, int n_threads,
                 const std::atomic<bool>* cancel, const ReturnMapsOutput& out);

}  // namespace hovering
