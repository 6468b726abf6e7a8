#pragma once
// The flow's return map as a map you iterate: the same map interface as the truncated family
// (step, step_inverse, region, batch iteration with the same options, statuses and regions), on
// normal coordinates (phi, K) (eq:kphidef, from a TangentialCurve) or on section coordinates
// (theta, I). Each return starts on Sigma_h at energy h exactly: the image's coordinates are
// computed and the next point of Sigma_h is solved from them, so iterating n steps is the same,
// bit for bit, as n calls of step().

#include <array>
#include <atomic>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>

#include "hovering/batch.hpp"
#include "hovering/curve.hpp"
#include "hovering/flow/return_map.hpp"
#include "hovering/normal/tangential_curve.hpp"
#include "hovering/tangent.hpp"
#include "hovering/truncated/arcs.hpp"
#include "hovering/types.hpp"

namespace hovering {

namespace detail {
class Tracer;
class TracerPool;
}

/// What a flow-map iteration does besides stepping: the shared BatchOptions (counts in returns;
/// cancel is polled between and inside returns) and whether returns are labelled.
struct FlowIterateOptions : BatchOptions {
    /// Label returns (itinerary, region; needs the crossings of q1 = qw1 tracked). false: no
    /// label work at all, every region None (then regions, visited, itinerary, rotation and an
    /// exit_mask are refused); the orbit is the same bit for bit.
    bool labels = true;
};

/// Marks the itinerary of a return an orbit did not take (it had stopped); no return's own
/// itinerary is "-" (impacts 'R', '1', ..., or '0' / 'u', or '' for the smooth flow).
inline constexpr const char* kNoItinerary = "-";

/// Where a flow-map iteration writes; a null pointer means "not recorded". With e = every,
/// per-point arrays hold the points x_0, x_e, x_2e, ...: (n_orbits, n_steps / e + 1) (states: 4
/// per point), per-return arrays the returns from them: (n_orbits, ceil(n_steps / e)). Entries an
/// orbit did not reach are NaN (Region::None, -1 integrator steps, kNoItinerary). With stop_on_exit
/// the return that leaves the watched set is recorded (region, itinerary, time, ...), not taken.
struct FlowIterateOutput {
    double* x_final = nullptr;                 ///< (n) last point reached: phi or theta
    double* y_final = nullptr;                 ///< (n) K or I
    double* orbit_x = nullptr;                 ///< points: phi (normal) or theta (section)
    double* orbit_y = nullptr;                 ///< K or I
    double* orbit_theta = nullptr;             ///< section coordinates of the points
    double* orbit_I = nullptr;                 ///< I of the points (section coordinates)
    double* states = nullptr;                  ///< (n, n_steps + 1, 4) points of Sigma_h (q1, p1, q2, p2)
    std::int8_t* regions = nullptr;            ///< Region of each return
    double* times = nullptr;                   ///< return times
    double* energy_error = nullptr;            ///< |H(image) - h| before the image is put back on Sigma_h
    std::int64_t* integrator_steps = nullptr;  ///< accepted integrator steps per return
    std::string* itinerary = nullptr;          ///< itinerary of each return
    double* rotation = nullptr;                ///< (n) mean lifted rotation per return (see FlowMap::rotation_of)
    std::int8_t* status = nullptr;             ///< (n) Status, always written when non-null
    std::int64_t* steps_done = nullptr;        ///< (n) returns taken
    std::int64_t* exit_step = nullptr;         ///< (n) first return outside the watched set, else -1
    std::int8_t* visited = nullptr;            ///< (n) bit r: a return of Region r was taken (as IterateOutput)
    double* y_min = nullptr;                   ///< (n) min of y (K or I) over the points x_0 .. x_steps_done
    double* y_max = nullptr;                   ///< (n) max of y over the same points
    std::int64_t* residence = nullptr;         ///< (n, kRegionCount) returns per region (as IterateOutput)
    std::int64_t* stop_step = nullptr;         ///< (n) first n with x_n in the stop set, else -1
    FlowWork* work = nullptr;                  ///< the iteration's work counters (summed over workers)
    /// Dense output of each orbit across its returns (the clock runs on from return to return;
    /// each return's point is the image before the next start is put back on Sigma_h).
    TrajectoryOutput trajectory;
    /// Record "jacobian": each orbit's product of the Jacobians of the returns it took (QR form;
    /// status NonFinite if a return's Jacobian was not finite, which is then left out).
    TangentOutput tangent;
};

/// One return of the map: the image, its region and what the flow reported.
struct FlowStep {
    double x = 0, y = 0;           ///< image in map coordinates (NaN unless status is Ok)
    Region region = Region::None;  ///< region of the return (None unless Ok with labels)
    ReturnResult ret;              ///< the flow's return (state, time, itinerary, energy error, steps)
};

/// One return with its Jacobian (FlowMap::jacobian).
struct FlowJacobian {
    FlowStep step;  ///< the return, as FlowMap::step gives it
    /// d(x1, y1)/d(x, y) in map coordinates, row-major; NaN unless the return is Ok. The variational
    /// equations carried with the state, a saltation matrix at each impact, the projection onto
    /// Sigma_h along the flow at the return, and the charts' derivatives: (theta, I) of H2's
    /// action-angle variables (Potential::point_slope), (phi, K) of the tangential curve.
    double J[4] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
                   std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
};

/// The flow's return map on one section; see the file comment.
class FlowMap {
public:
    /// Map on normal coordinates (phi, K) when curve is set (it must be a graph), else on
    /// section coordinates (theta, I). lift (optional, e.g. the onset parameters' arcs) is the
    /// model whose rotation omega_a(K) picks the branch of each measured angle advance.
    FlowMap(FlowSystem s, double h, FlowOptions opt, std::shared_ptr<const TangentialCurve> curve = nullptr,
            std::shared_ptr<const AnalyticArcs> lift = nullptr);

    /// One return from (x, y); a point with no point of Sigma_h gives status OffSection.
    FlowStep step(double x, double y) const;
    /// The preimage, by time reversal (lem:timerevgen): F^{-1} = R2 F R2 in (theta, I).
    FlowStep step_inverse(double x, double y) const;
    /// One return from (x, y) with its Jacobian; the return is step()'s (bit for bit for the
    /// explicit steppers and taylor: the step control reads the state only).
    FlowJacobian jacobian(double x, double y) const;
    /// jacobian() of n points on the core's thread pool, into out[0 .. n) (Interrupted as steps()).
    void jacobians(const double* x, const double* y, std::int64_t n, int n_threads, const std::atomic<bool>* cancel,
                   FlowJacobian* out) const;
    /// step (or step_inverse) of n points on the core's thread pool, into out[0 .. n). Points not
    /// reached before *cancel is set get FlowStatus::Interrupted.
    void steps(const double* x, const double* y, std::int64_t n, bool inverse, int n_threads,
               const std::atomic<bool>* cancel, FlowStep* out) const;
    /// Iterate n orbits from (x0[i], y0[i]); see FlowIterateOutput for what is written. One
    /// orbit's outcome (corner, grazing, runaway, off the section) never stops the others.
    void iterate(const double* x0, const double* y0, std::int64_t n, const FlowIterateOptions& opt,
                 const FlowIterateOutput& out) const;

    /// Section coordinates (theta, I) of a map point (phi wrapped to [-pi, pi)).
    std::pair<double, double> to_section(double x, double y) const;
    /// Map coordinates of section coordinates.
    std::pair<double, double> from_section(double theta, double I) const;
    /// Point of Sigma_h at map coordinates (x, y); false where there is none.
    bool state(double x, double y, std::array<double, 4>& z, std::string* why = nullptr) const;
    /// The lifted rotation of a return from (x, y) in region r to the image angle x1: the advance
    /// x1 - x on the branch nearest to the lift model's omega_r(K) ([0, 2 pi) without a model).
    double rotation_of(double x, double y, Region r, double x1) const;

    /// The system.
    const FlowSystem& system() const { return s_; }
    /// Energy of the section.
    double h() const { return h_; }
    /// Integrator options, their stepper resolved on the system (never "auto").
    const FlowOptions& options() const { return opt_; }
    /// The tangential curve (null: section coordinates).
    const std::shared_ptr<const TangentialCurve>& curve() const { return curve_; }

private:
    FlowStep advance(detail::Tracer& tr, double x, double y, bool inverse, const std::atomic<bool>* cancel) const;
    // advance() in two halves around the trace (for interleaved returns): the start state of the
    // return from (x, y) (false: none, st then holds the OffSection step; chart, chart_point: the
    // last image's ReturnResult ones, traced at section energy h_, reused where (x, y) names the
    // same coordinates), and the step a finished return makes.
    bool advance_start(double x, double y, bool inverse, std::array<double, 4>& z, FlowStep& st,
                       const std::array<double, 2>* chart = nullptr,
                       const std::array<double, 4>* chart_point = nullptr) const;
    FlowStep advance_end(ReturnResult ret, bool inverse) const;
    // The tangents d z0 / d(x, y) of the chart at the start z0 of the return from (x, y)
    // (row-major 4 x 2), and the Jacobian of a finished forward return from there.
    void start_tangents(double x, const std::array<double, 4>& z0, double I0, double* t0) const;
    void end_jacobian(const FlowStep& st, double* J) const;
    FlowSystem s_;
    double h_;
    FlowOptions opt_;
    std::shared_ptr<const TangentialCurve> curve_;
    std::shared_ptr<const AnalyticArcs> lift_;
    double lift_I0_ = 0;
    // The tracers of earlier calls, kept for the next (a loop of one-point calls paid ~10 us a call
    // to build them); shared by copies of this map (the pool owns its system and options).
    std::shared_ptr<detail::TracerPool> pool_;
};

}  // namespace hovering
