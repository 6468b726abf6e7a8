#pragma once
// GSL odeiv2 stepping of one orbit (internal): an error-controlled step, and the continuous
// extension "one stepper step of length tau from the step's start" on which events are located.

#include <gsl/gsl_odeiv2.h>

#include <cmath>
#include <memory>
#include <string>

#include "hovering/flow/exact.hpp"
#include "hovering/flow/field.hpp"
#include "hovering/flow/return_map.hpp"
#include "hovering/flow/taylor.hpp"

namespace hovering::detail {

/// The GSL stepper type of a stepper (null for Exact and Taylor: no GSL stepper).
const gsl_odeiv2_step_type* stepper_type(Stepper s);

/// Shortest step, relative to the step bound, that advance() shortens further for events: two
/// sign changes of a velocity closer than this are a tangency, below any sign test.
inline constexpr double kMinEventStep = 1e-7;

/// Owns the GSL objects of one integration, reused from return to return by one worker.
///
/// For one-step methods the adaptive loop drives GSL's stepper and step-size control directly
/// instead of gsl_odeiv2_evolve_apply: the evolve object evaluates the field at both ends of every
/// step, while the end derivative of one step is the start derivative of the next (13 instead of
/// 14 evaluations per rk8pd step), and the event search needs exactly those two. The multistep
/// msadams needs GSL's driver (it reads the control through it) and its history cannot restart
/// inside a step, so its events are located on an rk8pd extension of the step, subdivided until
/// rk8pd's own error estimate meets the tolerances. Stepper "exact" holds no GSL object: a step is
/// the closed-form flow over hmax, the extension the closed form itself (exact.hpp). Stepper
/// "taylor" holds no GSL object either: a step is the Taylor polynomial through its start, of the
/// order and length the tolerances set, and the extension that polynomial (taylor.hpp).
class Integrator {
public:
    /// An integrator of s with options o, carrying n_tangents tangent vectors with the state
    /// (the variational equations; Field).
    /// taylor_order > 0: stepper "taylor" at that order (Taylor), for a verifying trace expanded
    /// in the lanes of the returns it verifies.
    Integrator(const FlowSystem& s, const FlowOptions& o, int n_tangents = 0, int taylor_order = 0);
    ~Integrator();
    Integrator(const Integrator&) = delete;
    Integrator& operator=(const Integrator&) = delete;

    /// The field (with its auxiliary variables) this integrator steps.
    const Field& field() const { return field_; }
    /// Integrated dimension: the state (4 plus one per Tan potential) and 4 per tangent vector.
    int dim() const { return field_.dim; }
    /// The state's dimension (4 plus one per Tan potential): what the step control reads.
    int state_dim() const { return field_.state; }
    /// Order of the stepper (8 for rk8pd; "exact": 8, only the first trial step reads it, and exact steps ignore it).
    int order() const { return taylor_ ? taylor_->order() : step_ ? int(gsl_odeiv2_step_order(step_)) : 8; }
    /// The Taylor expansion of stepper "taylor" (null for the others).
    Taylor* taylor() { return taylor_.get(); }
    /// The closed form of stepper "exact" (None for the GSL steppers).
    ExactKind exact_kind() const { return kind_; }
    /// Longest step the stepper allows (infinite but for the linear flow: 1/8 of its fastest mode's period).
    double max_step() const;
    /// The step-size rule of GSL's standard control for the step just taken (y its end, err its
    /// error estimate): scales *h and returns GSL_ODEIV_HADJ_DEC (reject), _INC or _NIL.
    int hadjust(const double* y, const double* err, double* h) const;
    /// Forget the step history (a new orbit, or a restart after an impact).
    void restart();
    /// Outcome of advance().
    enum class Advance { Ok, Failed, OutsideWell };
    /// One error-controlled step (GSL step, GSL's standard step-size rule) from (y, d = field(y)) with
    /// trial length *h (<= hmax): on Ok y, d hold the new state and its derivative, *h_done the
    /// length taken, *h the proposal for the next step. Rejected trials (error too large, or an end
    /// state outside a bounded well) shrink *h and retry from the same state. Failed: the step size
    /// underflowed or the stepper failed (non-finite state); OutsideWell: every step down to 1e-14
    /// hmax left a well. In both y, d are the unchanged start state.
    Advance advance(double* y, double* d, double* h, double hmax, double* h_done);
    /// Whether (q1, q2) of y lie strictly inside both wells (|q| < q_limit).
    bool inside(const double* y) const { return std::fabs(y[0]) < qlim1_ && std::fabs(y[2]) < qlim2_; }
    /// Before an event search on [0, h] from y0 (msadams only: sizes the rk8pd extension).
    void prepare_extension(const double* y0, const double* d0, double h);
    /// The continuous extension of the current step at length dt from y0 (derivative d0).
    void exact(const double* y0, const double* d0, double dt, double* y1);
    /// With taylor, the current step's polynomial through y0: the time in [lo, hi] where variable
    /// i crosses off (Taylor::solve) into *tau; false for the other steppers (or no expansion
    /// through y0), whose events are located on exact() by Newton's method.
    bool solve_on_step(const double* y0, int i, double off, double lo, double hi, bool lo_above, double guess,
                       double* tau) const;
    /// Coordinates whose velocity may change sign at most once in a step (bit 0: p1, bit 1: p2),
    /// which the event search relies on (tracer.cpp): advance() shortens a step until it holds.
    void set_watched(unsigned mask) { watched_ = mask; }
    /// Steps shortened so far because a watched velocity changed sign twice in them.
    long long event_cuts() const { return event_cuts_; }

private:
    Field field_;
    gsl_odeiv2_system sys_;
    gsl_odeiv2_step* step_ = nullptr;
    gsl_odeiv2_control* control_ = nullptr;    // msadams only (the driver's)
    gsl_odeiv2_driver* driver_ = nullptr;      // msadams only: owns step, control and evolve
    gsl_odeiv2_step* ext_ = nullptr;           // msadams only: rk8pd for event extensions
    gsl_odeiv2_driver* imp_driver_ = nullptr;  // rk2imp / rk4imp: owns step_ (their Newton reads its control)
    int ext_sub_ = 1;                          // substeps of the extension
    double t_ms_ = 0;                          // msadams: running time (its history is in time)
    double atol_, rtol_;
    double qlim1_, qlim2_;  // the wells' edges (infinite for unbounded potentials)
    ExactKind kind_ = ExactKind::None;
    std::unique_ptr<LinearFlow> linear_;  // stepper "exact", linear flow
    std::unique_ptr<Taylor> taylor_;      // stepper "taylor"
    AngleOscillator osc_[2];              // stepper "exact", uncoupled flow (step loop only)
    unsigned watched_ = 0;                // set_watched
    long long event_cuts_ = 0;            // event_cuts
    // Taylor: the end (<= step) of a step on the current polynomial that holds at most one sign
    // change of each watched velocity.
    double taylor_cut(double step);
    // The other steppers: whether the step (y0, d0) -> (y1, d1) of length h may hold two sign
    // changes of a watched velocity, judged on its Hermite interpolant with a margin.
    bool ambiguous(const double* y0, const double* d0, const double* y1, const double* d1, double h) const;
    // The linear closed form's own test: whether a watched velocity may change sign twice or more
    // on [0, h] from y0 (exact pieces where it is monotone or has no root; undecided counts as twice).
    bool linear_ambiguous(const double* y0, const double* d0, const double* y1, const double* d1, double h) const;
    int order_ = 8;                       // one-step methods: the stepper's order, for the step-size rule
    double grow_below_ = 0.43;            // 0.9^order: below this scaled error the step grows
};

}  // namespace hovering::detail
