#pragma once
// The flow of a FlowSystem on GSL odeiv2 and its Poincare return map to
// Sigma_h = {p1 = 0, dp1/dt < 0}: section coordinates, impacts with the right wall (geometry
// Wall: the infinite wall q1 = qw1; Step: q2 < qw2 only) and the upper wall (Step, q1 < qw1),
// corner hits, grazing, and per-orbit status. Events are searched on every accepted step,
// including minima of a wall distance inside a step (near-grazing dips).

#include <array>
#include <atomic>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "hovering/flow/system.hpp"
#include "hovering/types.hpp"

namespace hovering {

namespace detail {
class TracerPool;
}

/// Per-orbit outcome of a return-map computation.
enum class FlowStatus : std::int8_t {
    Ok = 0,           ///< returned to Sigma_h
    Corner = 1,       ///< hit the corner (orbit stops)
    Grazing = 2,      ///< touched a wall tangentially
    StepLimit = 3,    ///< max_steps reached before returning
    NonFinite = 4,    ///< the state became non-finite, or ran away (kinetic energy > kRunawayKinetic (1 + |h|))
    ImpactLimit = 5,  ///< more impacts than max_impacts in one return (chattering)
    OffSection = 6,   ///< the starting point is not on Sigma_h at this energy (nothing integrated)
    Interrupted = 7,  ///< the caller cancelled the batch before or during this return
    OutsideWell = 8,  ///< no step that the tolerances accept keeps the state inside a bounded well
    Imprecise = 9,    ///< a verified return whose error stayed above its band at rtol / 10^4 (FlowOptions::verify_steps)
};

/// The orbit outcome (Status) of a return that ended with this FlowStatus.
Status orbit_status(FlowStatus s);

/// A FlowStatus's name (as hovering.FlowStatus spells it) and meaning.
struct FlowStatusInfo {
    FlowStatus status;  ///< the code
    const char* name;   ///< e.g. "IMPRECISE"
    const char* doc;    ///< what it means, one line
};

/// Every FlowStatus in code order: the one list the bindings and the core's messages read.
extern const std::array<FlowStatusInfo, 10> kFlowStatuses;

/// "NAME (meaning)" of a FlowStatus, for messages.
std::string describe(FlowStatus s);

/// The integrator of a return, parsed once from its name (parse_stepper) where a name enters the
/// core (the bindings, the plan reader) and compared as this enum everywhere else.
enum class Stepper : std::int8_t {
    Auto = 0,     ///< the default: Taylor where it applies, else Rk8pd (resolve_stepper, per system)
    Rk8pd = 1,    ///< GSL's explicit Runge-Kutta Prince-Dormand 8(9)
    Rkck = 2,     ///< GSL's explicit Runge-Kutta Cash-Karp 4(5)
    Rkf45 = 3,    ///< GSL's explicit Runge-Kutta-Fehlberg 4(5)
    Rk4 = 4,      ///< GSL's classical explicit Runge-Kutta 4
    Rk2 = 5,      ///< GSL's explicit Runge-Kutta 2(3)
    Msadams = 6,  ///< GSL's variable-order Adams multistep method
    Rk4imp = 7,   ///< GSL's implicit Gauss-Legendre 4 (with the Jacobian)
    Rk2imp = 8,   ///< GSL's implicit Gauss-Legendre 2 (with the Jacobian)
    Taylor = 9,   ///< Taylor's method (order and step from the tolerances; Harmonic and Tan potentials)
    Exact = 10,   ///< the flow in closed form, where the system has one
};

/// The names of the steppers in Stepper's order, its default first (bound as
/// hovering.flow.STEPPERS; the choices of scene files and plans). Names are what is stored
/// (pickles, scene files, plans, results), never the enum's values.
inline constexpr std::array<const char*, 11> kSteppers = {"auto",   "rk8pd",  "rkck",   "rkf45",
                                                          "rk4",    "rk2",    "msadams", "rk4imp",
                                                          "rk2imp", "taylor", "exact"};

/// The stepper a name means; throws std::invalid_argument naming the value and every allowed name.
Stepper parse_stepper(const std::string& name);
/// The name of a stepper (an entry of kSteppers).
const char* stepper_name(Stepper s);
/// The stepper that runs for st on s: "auto" is "taylor" where Taylor's method applies (V1 and V2
/// each Harmonic or Tan: a polynomial field; the fastest stepper at every tolerance measured, and
/// the only one reaching the rounding floor) and "rk8pd" elsewhere; any other stepper is itself.
Stepper resolve_stepper(Stepper st, const FlowSystem& s);

/// Kinetic energy, relative to 1 + |h|, beyond which an orbit is a runaway (status NonFinite): a
/// coupling unbounded below lets it grow without bound; bounded motion keeps it below h - min V,
/// so only a potential whose minimum lies below -1e4 (1 + |h|) could be stopped wrongly.
inline constexpr double kRunawayKinetic = 1e4;

/// Steps (times the impacts' amplification) from which a "taylor" return is verified by default
/// (FlowOptions::verify_steps = -1).
inline constexpr std::int64_t kVerifySteps = 128;
/// The same for a GSL stepper of order p at rtol 1e-8; kVerifyStepsGsl (1e-8 / rtol)^(1/p) at
/// another rtol (at least 16): its steps grow so as the tolerance tightens.
inline constexpr std::int64_t kVerifyStepsGsl = 40;

/// Integrator settings.
/// Stepper "exact" is the flow in closed form where the system has one (eps = 0 with Harmonic or
/// Tan potentials: event to event on the action-angle variables; Harmonic + Harmonic with a
/// quadratic coupling: the normal modes of the linear flow); it ignores rtol and atol, and its
/// "steps" are events passed (uncoupled) or closed-form steps of 1/8 period (linear).
struct FlowOptions {
    Stepper stepper = Stepper::Auto;  ///< the integrator (see Stepper; by name: parse_stepper; resolved per system)
    double rtol = 1e-10;               ///< relative tolerance of the step control (not read by "exact")
    double atol = default_atol(rtol);  ///< absolute tolerance of the step control (not read by "exact")
    double event_tol = 1e-15;          ///< time accuracy of located events (Newton on exact steps)
    std::int64_t max_steps = 1000000;  ///< per return
    int max_impacts = 100;             ///< per return; more ends the orbit with ImpactLimit
    double grazing_tol = 1e-12;        ///< |min distance to a wall| below which an orbit touches it tangentially
    double corner_tol = 1e-10;         ///< distance to the corner below which an impact is a corner hit
    /// A return whose steps times its error amplification (the product of each impact's
    /// 2 |a| / (|v| w), at least 1: a shallow impact's saltation term; and of the section
    /// crossing's |V1'(q1)| / |dp1/dt|, at least 1: a shallow crossing) reach this is verified:
    /// traced again at rtol / 100 (and / 10^4 if needed) and the tighter result kept once its
    /// estimated error is within the band (time within rtol max(1, t), each state component within
    /// rtol |z| + atol), else Imprecise. -1 (default): kVerifySteps for "taylor", kVerifyStepsGsl
    /// scaled by the tolerance for the GSL steppers, never for "exact"; 0: never.
    std::int64_t verify_steps = -1;
    /// The absolute tolerance wherever none is given: rtol's, the one policy of the core, the
    /// bindings, FlowMap and the scenes. The flow's variables are O(1) on the sections studied,
    /// and an atol below rtol only tightens the steps where a momentum crosses zero (at rtol
    /// 1e-10, atol 1e-12 cost 17% more steps for a 2.5x smaller error per return).
    static constexpr double default_atol(double rtol) { return rtol; }
    /// Validate (throws std::invalid_argument naming the bad value and the allowed range).
    void validate() const;
    /// validate(), and that the stepper applies to s ("exact" needs a closed-form flow; the message
    /// names what s has and what "exact" needs).
    void validate(const FlowSystem& s) const;
    /// A copy whose stepper is resolved on s (resolve_stepper): what a tracer runs and a map reports.
    FlowOptions resolved(const FlowSystem& s) const;
};

/// Point of Sigma_h from section coordinates (theta, I) of the unperturbed H2 at energy h:
/// (q2, p2) = S2^{-1}(theta, I), p1 = 0, q1 > 0 solves H = h (the root near q1's maximum).
/// Throws std::invalid_argument when no such point exists (e.g. h below H2(I)).
std::array<double, 4> section_point(const FlowSystem& s, double h, double theta, double I);

/// section_point without exceptions for numerical outcomes: false (z untouched, *why set when
/// non-null) where (theta, I) has no point of Sigma_h; bad parameters (h, theta) still throw.
bool try_section_point(const FlowSystem& s, double h, double theta, double I, std::array<double, 4>& z,
                       std::string* why = nullptr);

/// (theta, I) = S2(q2, p2) of a state (unperturbed H2; theta in [-pi, pi), sign(theta) = -sign(p2));
/// NaN where H2 overflows (a runaway orbit's last state has no coordinates).
std::array<double, 2> section_coordinates(const FlowSystem& s, const double* z);

/// Result of one return.
struct ReturnResult {
    std::array<double, 4> z{};           ///< state at the return (or where the orbit stopped)
    double time = 0;                     ///< return time, or the time of z where the orbit stopped (every status)
    FlowStatus status = FlowStatus::Ok;  ///< how the return ended
    /// Impacts in order ('R' right wall, '1' upper wall: "R", "1", "11", "R1", ...); without
    /// impact "0" if the segment crossed q1 = qw1 above the step, "u" if it never crossed it;
    /// "" for the smooth flow (geometry None), for a return that did not end Ok without impact,
    /// and when labels are off (FlowIterateOptions::labels = false).
    std::string itinerary;
    double energy_error = 0;  ///< |H(z) - H(z0)|
    std::int64_t steps = 0;   ///< accepted integrator steps
    /// Tracers with tangents only: the tangent vectors at z, before the section's projection
    /// (row-major 4 x 2: row r is component r of each); NaN unless the return ended Ok.
    std::array<double, 8> tangents{};
    /// An Ok return's section coordinates (theta, I) = section_coordinates(z), computed once where
    /// the tracer checks that z lies on Sigma_h's chart; NaN for every other status.
    std::array<double, 2> chart{std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
    /// An Ok return's point of Sigma_h at chart (the check's own, at the tracer's section energy):
    /// what a next return from the image starts from; NaN for every other status.
    std::array<double, 4> chart_point{std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
                                      std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
};

/// What the tracer did, counted per worker and summed at the end of a batch (no atomics in the
/// loop): shows that a computation simulates only the effects it needs (no walls: no wall-event
/// search; eps = 0: no coupling term; no labels: no crossing bookkeeping; no trajectory: no dense
/// sample).
struct FlowWork {
    std::int64_t field_evaluations = 0;     ///< evaluations of the vector field (steps, events, samples)
    std::int64_t coupling_evaluations = 0;  ///< of those, evaluations of the coupling term eps grad Vc
    std::int64_t wall_searches = 0;         ///< event searches (locate) for wall crossings and grazing minima
    std::int64_t section_searches = 0;      ///< event searches for the crossing of Sigma_h
    std::int64_t label_operations = 0;      ///< crossing-of-q1 = qw1 and itinerary bookkeeping operations
    std::int64_t dense_samples = 0;         ///< uniform trajectory samples computed (one stepper step each)
    std::int64_t steps = 0;                 ///< accepted integrator steps
    /// Add another worker's counts.
    FlowWork& operator+=(const FlowWork& o);
    /// Take away counts made before (what a kept tracer counted in earlier calls).
    FlowWork& operator-=(const FlowWork& o);
};

/// What a recorded trajectory point is.
enum class TrajectoryPoint : std::int8_t {
    Sample = 0,     ///< uniform sample at t = k dt of the orbit's clock
    ImpactIn = 1,   ///< state at an impact, before the reflection (on the wall)
    ImpactOut = 2,  ///< state at an impact, after the reflection
    Return = 3,     ///< the return to Sigma_h that ends a return
    End = 4,        ///< where a return stopped otherwise (corner, grazing, step or impact limit, ...)
};

/// Dense output of a batch ("trajectory"): per orbit, the states (t, q1, p1, q2, p2) at the
/// uniform times t = k dt of the orbit's clock (it runs on across returns; samples come from one
/// exact stepper step from the start of the accepted step, so they carry the stepper's accuracy),
/// plus the exact pre- and post-impact states of every reflection, each return point and where an
/// orbit stopped. Nothing is computed when points is null.
struct TrajectoryOutput {
    double dt = 0;                              ///< sample spacing (> 0 when points is set)
    std::int64_t max_points_per_orbit = 0;      ///< points kept per orbit (>= 1); beyond, recording stops
    std::vector<double>* points = nullptr;      ///< (n) per orbit, 5 doubles per point: t, q1, p1, q2, p2
    std::vector<std::int8_t>* kinds = nullptr;  ///< (n) per orbit, the TrajectoryPoint of each point
    std::int8_t* truncated = nullptr;           ///< (n) 1 where the orbit reached max_points_per_orbit
    /// Whether a trajectory is recorded.
    bool active() const { return points != nullptr; }
    /// Throw std::invalid_argument for a bad dt or limit (when active).
    void validate() const;
};

/// Region of Sigma_h a return's itinerary labels: "u" Beside (J_0u), "0" Above (J_0), "1" Upper
/// (J_1), "R" Right (J_R), two or more impacts Multi, anything else (no walls, no return) None.
Region region_of(const std::string& itinerary);

/// Follow the flow from a point of Sigma_h until it returns to Sigma_h.
ReturnResult return_map(const FlowSystem& s, const std::array<double, 4>& z0, const FlowOptions& opt);

/// Where a batch of returns writes; null pointers are not written. Arrays have one entry per
/// orbit (z: 4 per orbit, row-major).
struct ReturnMapsOutput {
    double* z = nullptr;               ///< image states (NaN for OffSection)
    double* time = nullptr;            ///< return times
    std::int8_t* status = nullptr;     ///< FlowStatus
    std::int8_t* region = nullptr;     ///< Region of the return (region_of(itinerary))
    double* energy_error = nullptr;    ///< |H(image) - H(start)|
    std::int64_t* steps = nullptr;     ///< accepted integrator steps
    std::string* itinerary = nullptr;  ///< itinerary of each return
    double* chart = nullptr;           ///< (theta, I) of each Ok image (ReturnResult::chart), NaN otherwise
    FlowWork* work = nullptr;          ///< the batch's work counters (summed over workers)
    TrajectoryOutput trajectory;       ///< dense output of each return (its clock starts at 0)
};

/// Returns of n states z0 (row-major (n, 4)) on the core's thread pool (n_threads, 0 = all
/// cores). A state with a non-finite entry is OffSection (a failed section point); every orbit
/// gets its own status, none stops the batch. Setting *cancel ends the batch promptly: returns not
/// finished are Interrupted. Bad options throw std::invalid_argument before anything runs.
/// progress (optional) is increased by one per finished return (relaxed), for a progress bar.
void return_maps(const FlowSystem& s, const double* z0, std::int64_t n, const FlowOptions& opt, int n_threads,
                 const std::atomic<bool>* cancel, const ReturnMapsOutput& out,
                 std::atomic<std::int64_t>* progress = nullptr);

/// return_maps of one system with one set of options, validated once, whose tracers are kept from
/// call to call (detail::TracerPool): for callers that map a few points at a time, many times (a
/// section's repeated return_map calls). Results are return_maps' bit for bit.
class ReturnMapper {
public:
    /// The system and options (both validated here; std::invalid_argument names what is wrong).
    ReturnMapper(const FlowSystem& s, const FlowOptions& opt);
    /// return_maps(system(), z0, n, options(), ...) on the kept tracers.
    void run(const double* z0, std::int64_t n, int n_threads, const std::atomic<bool>* cancel,
             const ReturnMapsOutput& out, std::atomic<std::int64_t>* progress = nullptr) const;
    /// One return from z0 on the calling thread (a non-finite z0: OffSection, nothing traced);
    /// its work counters go to *work when given (as run()'s out.work).
    ReturnResult one(const std::array<double, 4>& z0, FlowWork* work = nullptr) const;
    /// The system.
    const FlowSystem& system() const;
    /// The options.
    const FlowOptions& options() const;

private:
    std::shared_ptr<detail::TracerPool> pool_;
};

}  // namespace hovering
