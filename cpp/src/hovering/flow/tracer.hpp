#pragma once
// One worker's engine for returns to Sigma_h (internal): the adaptive loop, event search on every
// accepted step, reflections, the bookkeeping of impacts and crossings of q1 = qw1 (labels, only
// when asked for), dense output (only when asked for) and the work counters.

#include <array>
#include <atomic>
#include <limits>
#include <memory>
#include <mutex>
#include <vector>

#include "hovering/flow/exact.hpp"
#include "hovering/flow/integrator.hpp"
#include "hovering/flow/return_map.hpp"

namespace hovering::detail {

/// One orbit's trajectory while it is recorded: where the points go, the orbit's clock and the
/// room left. The tracer samples t = k dt of the clock offset + (time within the return).
struct DenseRecorder {
    double dt = 0;                              ///< sample spacing
    double offset = 0;                          ///< the orbit's clock at the start of the current return
    std::int64_t next = 0;                      ///< index k of the next uniform sample
    std::int64_t room = 0;                      ///< points that may still be recorded
    bool truncated = false;                     ///< a point was dropped for want of room
    std::vector<double>* points = nullptr;      ///< 5 doubles per point: t, q1, p1, q2, p2
    std::vector<std::int8_t>* kinds = nullptr;  ///< TrajectoryPoint of each point

    /// Start an orbit at clock 0 (clears the vectors).
    void start(std::vector<double>* pts, std::vector<std::int8_t>* kds, double spacing, std::int64_t limit) {
        points = pts;
        kinds = kds;
        dt = spacing;
        offset = 0;
        next = 0;
        room = limit;
        truncated = false;
        points->clear();
        kinds->clear();
    }
    /// Append (t, y[0..4)) of this kind; false (and truncated set) when there is no room left.
    bool push(double t, const double* y, TrajectoryPoint kind) {
        if (room <= 0) {
            truncated = true;
            return false;
        }
        --room;
        points->insert(points->end(), {t, y[0], y[1], y[2], y[3]});
        kinds->push_back(static_cast<std::int8_t>(kind));
        return true;
    }
};

/// Follows orbits of one system from a point of Sigma_h to its next crossing of Sigma_h. Holds
/// the GSL objects, so a worker builds one and traces many returns with it.
class Tracer {
public:
    /// A tracer of system s with integrator options o (s must outlive it). With tangents (0 or
    /// kMaxTangents), every return also carries that many tangent vectors (the variational
    /// equations, a saltation matrix at every impact: ReturnResult::tangents); the state is the
    /// same as without them (the step control reads the state only) for every stepper but
    /// msadams, rk2imp and rk4imp, whose control or Newton iteration sees all components.
    /// taylor_order > 0: stepper "taylor" at that order (Integrator), for a verifier.
    Tracer(const FlowSystem& s, const FlowOptions& o, int tangents = 0, int taylor_order = 0);
    /// One return from z0 (on Sigma_h): the first crossing of Sigma_h after q1 has passed its
    /// minimum. With first_crossing, the first crossing of Sigma_h at all (z0 need not lie on it:
    /// the tangential curve starts at q1's minimum). cancel is polled every 256 steps. t0: the
    /// starting tangents (4 x tangents, row-major: row r is component r of each vector), tracers
    /// with tangents only.
    ReturnResult trace(const std::array<double, 4>& z0, bool first_crossing = false,
                       const std::atomic<bool>* cancel = nullptr, const double* t0 = nullptr);
    /// trace() in pieces, for drivers that interleave several returns (a lane group): begin a
    /// return from z0 (not for the event-driven closed form, stepper "exact" at eps = 0) ...
    void begin(const std::array<double, 4>& z0, bool first_crossing = false, const double* t0 = nullptr);
    /// ... take one accepted step with its events of the trace stepping() names (true: that
    /// trace is over) ...
    bool step(const std::atomic<bool>* cancel = nullptr);
    /// ... settle it when it is over (true: the return's result is final; false: a verifying trace
    /// has begun, stepped through stepping()) ...
    bool settle();
    /// ... and collect the settled result. trace() is begin, stepping().step() until a trace is
    /// over and settle() says final, end.
    ReturnResult end();
    /// The tracer whose step() advances the return: this one, or while the return is verified
    /// (FlowOptions::verify_steps) the verifier tracing it again at a tighter tolerance.
    Tracer& stepping() { return vf_.level < 0 ? *this : *verifier_[vf_.level]; }
    /// The verification level in progress (-1: none; 0: rtol / 100; 1: rtol / 10^4).
    int verifying() const { return vf_.level; }
    /// The state (with its auxiliary variables) the next step() starts from.
    const double* next_start() const { return ret_.y; }
    /// The longest step the next step() may take (the return's step bound).
    double next_hmax() const { return ret_.hmax; }
    /// Whether begin() and step() apply (every stepper but the event-driven closed form, which
    /// tangents turn off: they are carried on the closed form's steps).
    bool steps_apply() const { return !(in_.exact_kind() == ExactKind::Angles && event_driven_ && tangents_ == 0); }
    /// Tangent vectors carried with each return.
    int tangents() const { return tangents_; }
    /// The integrator (a lane group expands its Taylor series for it).
    Integrator& integrator() { return in_; }
    /// Whether returns are labelled (itinerary, crossings of q1 = qw1 above the step; default on).
    /// Off, the itinerary stays "" and no crossing is tracked; the orbit is the same bit for bit.
    void set_labels(bool on) { labels_ = on; }
    /// Stepper "exact" on an uncoupled system: event to event in closed form (default), or off:
    /// trace()'s step loop on closed-form steps (the same flow by another route, for tests).
    void set_event_driven(bool on) { event_driven_ = on; }
    /// Record the following returns into this trajectory (null: no dense output, no dense work).
    void set_dense(DenseRecorder* d) { dense_ = d; }
    /// The energy h of the section Sigma_h the caller's returns end on (NaN: each start's own
    /// energy): the image's ReturnResult::chart_point is then the point of Sigma_h at its section
    /// coordinates, bit for bit what try_section_point gives the next start from there.
    void set_section_energy(double h) { section_h_ = h; }
    /// Everything counted since construction (FlowWork), field evaluations included.
    FlowWork work() const;
    /// The system traced.
    const FlowSystem& system() const { return s_; }
    /// The options it traces with (resolved: the stepper named, the default atol applied).
    const FlowOptions& options() const { return o_; }

private:
    enum class Ev { Section, Right, Upper, GrazeRight, GrazeUpper };
    // The state of the return in progress (begin / step / end).
    struct Ret {
        ReturnResult r;
        double y[kMaxDim] = {}, dy[kMaxDim] = {};
        double t = 0, dt = 0, hmax = 0, H0 = 0;
        int impacts = 0;
        bool seen_negative = false, armed = false, crossed = false;
        bool done = false;  // the return found its end event (section, corner, graze, limit)
        bool over = false;  // step() will take no more steps
        double amplification = 1;    // product of the impacts' and the section crossing's error amplifications
        std::array<double, 4> z0{};  // where the return started (verification traces it again)
        double t0[4 * kMaxTangents] = {};  // and its starting tangents
        bool first_crossing = false;
        const std::atomic<bool>* cancel = nullptr;  // the last step()'s, polled by verification too
        // The dense output's state when the return began: a verified return replaces its points.
        std::size_t dense_points = 0, dense_kinds = 0;
        std::int64_t dense_next = 0, dense_room = 0;
        bool dense_truncated = false;
    };
    Ret ret_;
    struct Candidate {
        double tau;
        Ev kind;
        double y[kMaxDim];
    };
    // Uniform samples of the clock in [t0, t_end) (times within the return) of the step from
    // (y0, d0) at t0, each one exact stepper step from y0.
    void sample(const double* y0, const double* d0, double t0, double t_end);
    // Stepper "exact", uncoupled system: the return event to event (exact.cpp).
    ReturnResult trace_angles(const std::array<double, 4>& z0, bool first_crossing, const std::atomic<bool>* cancel);
    /// Whether the loop must stop before its next step (step limit, or a cancel seen every 256
    /// steps); sets r.status.
    bool halted(ReturnResult& r, const std::atomic<bool>* cancel) const;
    /// The end of every return (both loops): where a return that stopped between events (!done)
    /// stopped (state y at time t), the "0" / "u" label of an Ok return without impact, the energy
    /// error against H0, and the step count.
    void finish(ReturnResult& r, const double* y, double t, bool done, bool crossed, double H0);
    // The steps from which a return is verified (0: never), from FlowOptions::verify_steps.
    std::int64_t verify_from() const;
    // Begin verifying vf_.prev (a finished Ok return of verify_from() steps or more) at level
    // (rtol / 100, then / 10^4): the first tighter result whose estimated error is within the
    // band is kept, else Imprecise (settle()). False: a verifying trace has begun; true: nothing
    // tighter to trace, the result is final.
    bool verify_at(int level);
    // The return's final result is r (settle()'s true).
    bool conclude(ReturnResult r);
    // A return under verification: the result to judge and the steps so far.
    struct Verification {
        int level = -1;        // verifier_[level] is tracing (-1: none)
        ReturnResult prev;     // the last result kept
        double prev_tol = 0;   // its rtol
        std::int64_t steps0 = 0, steps = 0;  // the first trace's steps; all traces' so far
    };
    Verification vf_;
    ReturnResult result_;  // the settled result (end())
    // Whether the return's end r.z is the point of Sigma_h that its section coordinates name
    // (see finish(); the section's energy, or the start's H0); the coordinates go to r.chart, the
    // point to r.chart_point.
    bool on_chart(ReturnResult& r, double H0) const;
    // Uniform samples in [t0, t_end) of the angle flow from the angles of o at t0.
    void sample_angles(const AngleOscillator* o, double t0, double t_end);
    const FlowSystem& s_;
    FlowOptions o_;
    Integrator in_;
    std::vector<Candidate> cands_;
    FlowWork work_;
    bool labels_ = true;
    bool event_driven_ = true;
    DenseRecorder* dense_ = nullptr;
    double section_h_ = std::numeric_limits<double>::quiet_NaN();  // set_section_energy
    std::unique_ptr<Tracer> verifier_[2];  // at rtol / 100 and / 10^4, built on first use
    int tangents_ = 0;
    // The state y's tangents at an impact on coordinate gi, through the saltation matrix: y holds
    // the reflected state (positions on the wall), v the velocity before the impact, a = dp/dt.
    void saltation(double* y, int gi, double v, double a) const;
    // Copy the tangents of the integrated vector y into r (row-major 4 x tangents).
    void take_tangents(const double* y, ReturnResult& r) const;
};

/// Several returns traced side by side by one worker. With stepper "taylor" eight lanes: every
/// round expands the Taylor series of all busy lanes at once (Taylor::expand_group, SIMD lanes),
/// then each lane takes its step, events and reflections on its own; other steppers, one lane.
/// Either way a lane's return is bit for bit what Tracer::trace() gives it alone.
class TracerGroup {
public:
    /// Lanes of one system with integrator options o (s must outlive the group), carrying
    /// `tangents` tangent vectors (Tracer).
    TracerGroup(const FlowSystem& s, const FlowOptions& o, int tangents = 0);
    /// How many returns run side by side (kMaxTaylorGroup for stepper "taylor", else 1).
    int lanes() const { return int(t_.size()); }
    /// Lane l's tracer (labels, dense output, work).
    Tracer& lane(int l) { return *t_[std::size_t(l)]; }
    /// Whether lane l holds a return that has not been collected.
    bool busy(int l) const { return (busy_ >> l) & 1u; }
    /// Whether any lane does.
    bool any_busy() const { return busy_ != 0; }
    /// Start a return in the idle lane l (as Tracer::trace).
    void start(int l, const std::array<double, 4>& z0, bool first_crossing, const std::atomic<bool>* cancel,
               const double* t0 = nullptr);
    /// One step of every busy lane; the set of lanes whose return is over (bit l: lane l).
    unsigned step(const std::atomic<bool>* cancel);
    /// Collect lane l's finished return; the lane is idle again.
    ReturnResult collect(int l);
    /// Everything the lanes counted (FlowWork).
    FlowWork work() const;

private:
    std::vector<std::unique_ptr<Tracer>> t_;
    ReturnResult done_[kMaxTaylorGroup];  // returns traced whole at start (the event-driven closed form)
    std::unique_ptr<TaylorLanes> coef_;   // stepper "taylor": the lanes' coefficients of the last round
    unsigned busy_ = 0, ready_ = 0;
    bool taylor_ = false;
};

/// The TracerGroups of one map (FlowMap, ReturnMapper), kept from call to call: building a group
/// (eight tracers with their integrators for taylor) cost ~10 us, as much as a return, and a user's
/// loop of one-point calls paid it every call. The pool owns its copy of the system and options,
/// which every group it builds refers to, so the maps that share it may be copied freely.
/// Thread-safe: each worker takes its own group and gives it back when its call ends. A kept group
/// traces exactly as a new one (a lane's returns never depend on the lane's earlier returns).
class TracerPool {
public:
    /// A pool for system s with integrator options o (copied).
    TracerPool(const FlowSystem& s, const FlowOptions& o) : s_(s), o_(o) {}
    TracerPool(const TracerPool&) = delete;
    TracerPool& operator=(const TracerPool&) = delete;
    /// A group carrying `tangents` tangent vectors: a kept one (labels on, no dense output, as a new
    /// one) or a new one.
    std::unique_ptr<TracerGroup> take(int tangents);
    /// Keep an idle group (all its returns collected) for the next take; beyond a few per tangent
    /// count (one per hardware thread) it is dropped.
    void give(std::unique_ptr<TracerGroup> g, int tangents);
    /// The pool's system (the one its groups trace).
    const FlowSystem& system() const { return s_; }
    /// The pool's integrator options.
    const FlowOptions& options() const { return o_; }

private:
    const FlowSystem s_;
    const FlowOptions o_;
    std::mutex mu_;
    std::vector<std::unique_ptr<TracerGroup>> kept_[kMaxTangents + 1];
};

/// One worker's group for one call: taken from a pool (or new without one) and given back when the
/// call ends, unless an exception is unwinding through it (its lanes may be mid-return).
class PooledGroup {
public:
    /// A group of `tangents` tangent vectors from pool (null: a new group of s and o, not kept).
    PooledGroup(TracerPool* pool, const FlowSystem& s, const FlowOptions& o, int tangents = 0);
    ~PooledGroup();
    PooledGroup(const PooledGroup&) = delete;
    PooledGroup& operator=(const PooledGroup&) = delete;
    /// The group.
    TracerGroup& operator*() { return *g_; }
    /// The group's members.
    TracerGroup* operator->() { return g_.get(); }
    /// What the group counted during this call (FlowWork; a kept group counted earlier calls too).
    FlowWork work() const;

private:
    TracerPool* pool_;
    std::unique_ptr<TracerGroup> g_;
    FlowWork before_;
    int tangents_;
    int unwinding_;
};

}  // namespace hovering::detail
