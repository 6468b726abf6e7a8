// The return loop: adaptive GSL steps, events located on exact stepper steps, reflections.
//
// Events (section crossing, wall crossings, a wall distance's minimum inside a step): first guess
// on the cubic Hermite interpolant of the accepted step (values and derivatives at both ends),
// then Newton iterations on exact single steps of the stepper itself from the step's start, so the
// event state carries the stepper's accuracy, not the interpolant's. A candidate that provably
// cannot matter is not located at all: a quintic Hermite interpolant (positions, velocities and
// accelerations at both ends, all known) bounds a coordinate over the step, with the distance to
// the cubic one as its error estimate; a minimum that stays clear of a wall, a crossing of the
// line q2 = qw2 beside the step, or a crossing of q1 = qw1 well above it costs nothing.
//
// Only the effects a computation asks for are simulated: walls only for geometries that have
// them, labels (itinerary, crossings of q1 = qw1) only when set_labels(true), dense output only
// with a DenseRecorder; FlowWork counts what was done. None of them changes the orbit.

#include "hovering/flow/tracer.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <thread>

#include "hovering/detail/common.hpp"
#include "hovering/detail/parallel.hpp"

namespace hovering::detail {

namespace {

// Root of y[idx](tau) - off on [lo, hi] (values of opposite signs at the ends, whose states are
// ylo, yhi with derivatives dlo, dhi), where y(tau) is one step of the stepper of length tau from
// the step's start y0: a continuous extension of the accepted step with the stepper's own
// accuracy. The first guess is the root of the cubic Hermite interpolant through the two ends;
// Newton's method on exact steps (d/dtau y[idx] is rhs[idx] of the stepped state, to the
// stepper's accuracy) then converges in ~2 steps. The last correction delta (|delta| <=
// sqrt(time_tol)) moves the state along its derivative, leaving an error ~ delta^2 |z''| / 2 ~
// time_tol |z''| / 2.
double locate_in(Integrator& in, const double* y0, const double* d0, double lo, const double* ylo, const double* dlo,
                 double hi, const double* yhi, const double* dhi, int idx, double off, double time_tol, double* yout) {
    const int n = in.dim();
    const double f0 = ylo[idx] - off, f1 = yhi[idx] - off;
    if (f0 == 0) {
        for (int i = 0; i < n; ++i) yout[i] = ylo[i];
        return lo;
    }
    if (f1 == 0) {
        for (int i = 0; i < n; ++i) yout[i] = yhi[i];
        return hi;
    }
    const double guess = lo + hermite_root(f0, dlo[idx], f1, dhi[idx], hi - lo);
    // Taylor: on the step's own polynomial, to the last bits, and the state there.
    if (double tau; in.solve_on_step(y0, idx, off, lo, hi, f0 > 0, guess, &tau)) {
        in.exact(y0, d0, tau, yout);
        return tau;
    }
    in.prepare_extension(y0, d0, hi);
    double dy[kMaxDim];
    auto fdf = [&](double tau, double* f, double* df) {
        in.exact(y0, d0, tau, yout);
        in.field()(yout, dy);
        *f = yout[idx] - off;
        *df = dy[idx];
    };
    double delta = 0;
    double tau = newton_bracketed(fdf, lo, f0 > 0, hi, guess, std::sqrt(time_tol), &delta);
    if (delta != 0 && tau + delta >= lo && tau + delta <= hi && std::fabs(delta) <= std::sqrt(time_tol)) {
        tau += delta;
        for (int i = 0; i < n; ++i) yout[i] += delta * dy[i];
    }
    return tau;
}

// locate_in on the whole step [0, hi] from its start y0.
double locate(Integrator& in, const double* y0, const double* d0, const double* y1, const double* d1, int idx,
              double off, double hi, double time_tol, double* yout) {
    return locate_in(in, y0, d0, 0.0, y0, d0, hi, y1, d1, idx, off, time_tol, yout);
}

}  // namespace

Tracer::Tracer(const FlowSystem& s, const FlowOptions& o, int tangents, int taylor_order)
    : s_(s), o_(o.resolved(s)), in_(s, o_, tangents, taylor_order), tangents_(in_.field().tangents) {
    cands_.reserve(8);
    // The events below read each step's two ends and at most one turn of q1 (section, right wall)
    // and of q2 (upper wall) inside it: the integrator ends steps so that no more turns occur.
    in_.set_watched(1u | (s.geometry == Geometry::Step ? 2u : 0u));
}

FlowWork Tracer::work() const {
    FlowWork w = work_;
    w.field_evaluations = in_.field().evaluations();
    w.coupling_evaluations = in_.field().coupling_evaluations;
    for (const auto& v : verifier_)
        if (v) w += v->work();
    return w;
}

void Tracer::sample(const double* y0, const double* d0, double t0, double t_end) {
    DenseRecorder& D = *dense_;
    const double a = D.offset + t0, b = D.offset + t_end, len = t_end - t0;
    bool prepared = false;
    for (;;) {
        const double tk = double(D.next) * D.dt;
        if (!(tk < b)) return;
        if (D.room <= 0) {  // full: no more dense work for this orbit
            D.truncated = true;
            return;
        }
        double ys[kMaxDim];
        const double tau = std::min(std::max(tk - a, 0.0), len);
        if (tau == 0) {
            for (int i = 0; i < 4; ++i) ys[i] = y0[i];
        } else {
            if (!prepared) {
                in_.prepare_extension(y0, d0, len);  // msadams: size the rk8pd extension once per step
                prepared = true;
            }
            in_.exact(y0, d0, tau, ys);
        }
        ++work_.dense_samples;
        D.push(tk, ys, TrajectoryPoint::Sample);
        ++D.next;
    }
}

ReturnResult Tracer::trace(const std::array<double, 4>& z0, bool first_crossing, const std::atomic<bool>* cancel,
                           const double* t0) {
    if (!steps_apply()) return trace_angles(z0, first_crossing, cancel);
    begin(z0, first_crossing, t0);
    while (!(stepping().step(cancel) && settle())) {
    }
    return end();
}

void Tracer::begin(const std::array<double, 4>& z0, bool first_crossing, const double* t0) {
    const FlowSystem& s = s_;
    Ret& R = ret_;
    R = Ret{};
    vf_.level = -1;
    R.H0 = s.energy(z0.data());
    double* y = R.y;
    for (int i = 0; i < 4; ++i) y[i] = z0[std::size_t(i)];
    for (int i = 4; i < kMaxDim; ++i) y[i] = 0;
    in_.field().sync_aux(y);
    if (tangents_ > 0) {
        // The tangents follow the state (aux variables included) in the integrated vector, one
        // block of (dq1, dp1, dq2, dp2) per vector; t0 is row-major 4 x tangents.
        const int m = in_.field().state;
        for (int j = 0; j < tangents_; ++j)
            for (int r = 0; r < 4; ++r) {
                const double v = t0 ? t0[r * tangents_ + j] : (r == j ? 1.0 : 0.0);
                y[m + 4 * j + r] = v;
                R.t0[r * tangents_ + j] = v;
            }
    }
    in_.restart();
    // Step bound: a fraction of the shorter oscillator period, so one step never holds both a
    // minimum and a maximum of q1 or q2 (two sign changes of p would cancel); 1/8 leaves a factor 4
    // for the O(eps) period shifts of the coupled flow.
    const double T1 = s.V1->period(std::max(1e-12, 0.5 * y[1] * y[1] + s.V1->V(y[0])));
    const double T2 = s.V2->period(std::max(1e-12, 0.5 * y[3] * y[3] + s.V2->V(y[2])));
    R.hmax = std::min(0.125 * std::min(T1, T2), in_.max_step());
    // First trial step hmax rtol^(1/order): about the step the tolerance allows on these
    // oscillations (0.06 hmax for rk8pd at 1e-10), so a return does not spend 4-5 steps ramping up
    // from a tiny one; it depends on the options only, so every return is reproducible alone.
    R.dt = R.hmax * std::pow(std::max(o_.rtol, 1e-16), 1.0 / in_.order());
    in_.field()(y, R.dy);
    R.armed = first_crossing;
    R.z0 = z0;
    R.first_crossing = first_crossing;
    if (dense_) {
        R.dense_points = dense_->points->size();
        R.dense_kinds = dense_->kinds->size();
        R.dense_next = dense_->next;
        R.dense_room = dense_->room;
        R.dense_truncated = dense_->truncated;
    }
}

bool Tracer::step(const std::atomic<bool>* cancel) {
    const FlowSystem& s = s_;
    const FlowOptions& opt = o_;
    const int n = in_.dim();
    const Field& field = in_.field();
    const bool labels = labels_;
    DenseRecorder* const dense = dense_;
    Ret& R = ret_;
    R.cancel = cancel;
    ReturnResult& r = R.r;
    double* const y = R.y;
    double* const dy = R.dy;
    double& t = R.t;
    bool& done = R.done;
    bool& crossed = R.crossed;
    const bool right = s.geometry != Geometry::None, upper = s.geometry == Geometry::Step;
    const bool is_step = s.geometry == Geometry::Step;
    {
        if (halted(r, cancel)) return R.over = true;
        double y0[kMaxDim], d0[kMaxDim];
        for (int i = 0; i < n; ++i) {
            y0[i] = y[i];
            d0[i] = dy[i];
        }
        const double t0 = t;
        const double hmax = R.hmax;
        double h = 0;
        const Integrator::Advance adv = in_.advance(y, dy, &R.dt, hmax, &h);
        ++r.steps;
        if (adv != Integrator::Advance::Ok) {  // y is the last good state, at time t
            r.status = adv == Integrator::Advance::OutsideWell ? FlowStatus::OutsideWell : FlowStatus::NonFinite;
            return R.over = true;
        }
        t = t0 + h;
        // A runaway (a coupling unbounded below): the kinetic energy grows without bound while H
        // is kept, and with q2 pressed toward a Tan well's edge each step is shorter than the
        // last (1e6 steps per orbit, q1 ~ 1e3, before). Bounded motion keeps it below h - min V.
        if (0.5 * (y[1] * y[1] + y[3] * y[3]) > kRunawayKinetic * (1 + std::fabs(R.H0))) {
            r.status = FlowStatus::NonFinite;
            return R.over = true;
        }
        const double* d1 = dy;
        // Whether q_i stays above level over the whole step, said only where it is certain: q is
        // monotone on the step (p has the same sign at both ends, and the integrator ends steps
        // before a second turn of q1, or of q2 with the step: set_watched), so its minimum is an
        // end. A turning q's extremum is located on the step's own solution instead: a parabola
        // through the ends' q'' once stood in for it, and near a steep Tan wall, where q'' at the
        // minimum is many times its value at the ends of a long step, the exact flow's fixed T/8
        // steps with tangents skipped an impact that way, status OK.
        auto surely_above = [&](int qi, double level) {
            const double v0 = y0[qi + 1], v1 = y[qi + 1];
            return ((v0 > 0 && v1 > 0) || (v0 < 0 && v1 < 0)) && std::min(y0[qi], y[qi]) > level;
        };
        // Whether the wall of coordinate gi is surely absent on this whole step: the upper wall
        // needs q1 < qw1, the step's right wall q2 < qw2.
        auto wall_absent = [&](int gi) {
            if (!is_step) return false;
            return gi == 2 ? surely_above(0, s.qw1 + opt.corner_tol) : surely_above(2, s.qw2 + opt.corner_tol);
        };
        // A crossing of q1 = qw1 above the step (a label: the return is J_0, not J_0u).
        auto note_crossing = [&] {
            if (!labels) return;
            crossed = true;
            ++work_.label_operations;
        };

        // Candidate events of this step, each located on exact steps from y0.
        cands_.clear();
        auto wall = [&](int gi, double off, Ev cross, Ev graze) {
            const int pi = gi + 1;
            const double g0 = y0[gi] - off, g1 = y[gi] - off;
            // q turns inside the step (a minimum): g may have two roots on it, in and out again.
            // That case is settled by the minimum below, whatever the sign of g at the end: a
            // step that ends on the wall's line on the way out (g1 = 0 to rounding, which fixed
            // steps of a linear flow meet every period T = 8 hmax after an impact) would
            // otherwise bracket both roots and locate the outgoing one as an impact.
            const bool turns = y0[pi] < 0 && y[pi] > 0;
            if (g0 > 0 && g1 <= 0 && !turns) {  // crossing toward the wall
                if (wall_absent(gi)) {
                    if (gi == 0) note_crossing();  // q1 = qw1 crossed above the step
                    return;
                }
                Candidate c;
                c.kind = cross;
                ++work_.wall_searches;
                c.tau = locate(in_, y0, d0, y, d1, gi, off, h, opt.event_tol, c.y);
                cands_.push_back(c);
            } else if (g0 > 0 && turns) {
                // Turning inside the step: the minimum of g (p = 0) may dip through the wall even
                // though g > 0 at both ends (a near-grazing impact a sign test would miss); with
                // g <= 0 at the end the first root, before the minimum, is the impact.
                if (gi == 2 && wall_absent(2)) return;
                double ym[kMaxDim], dm[kMaxDim];
                ++work_.wall_searches;
                const double tm = locate(in_, y0, d0, y, d1, pi, 0.0, h, opt.event_tol, ym);
                const double gm = ym[gi] - off;
                Candidate c;
                if (gm < -opt.grazing_tol) {
                    c.kind = cross;
                    field(ym, dm);
                    ++work_.wall_searches;
                    c.tau = locate(in_, y0, d0, ym, dm, gi, off, tm, opt.event_tol, c.y);
                    cands_.push_back(c);
                } else if (gm <= opt.grazing_tol) {
                    c.kind = graze;
                    c.tau = tm;
                    for (int i = 0; i < n; ++i) c.y[i] = ym[i];
                    cands_.push_back(c);
                }
            } else if (g0 <= 0 && g1 <= 0 && y0[pi] > 0 && y[pi] < 0) {
                // Turning back inside the step: g may rise above 0 and fall through it again (a
                // crossing toward the wall after q's maximum; g0 = 0 right after a reflection
                // off this wall: a second impact within the step).
                double ym[kMaxDim], dm[kMaxDim];
                ++work_.wall_searches;
                const double tm = locate(in_, y0, d0, y, d1, pi, 0.0, h, opt.event_tol, ym);
                if (!(ym[gi] - off > 0)) return;
                if (wall_absent(gi)) {
                    if (gi == 0) note_crossing();
                    return;
                }
                field(ym, dm);
                Candidate c;
                c.kind = cross;
                ++work_.wall_searches;
                c.tau = locate_in(in_, y0, d0, tm, ym, dm, h, y, d1, gi, off, opt.event_tol, c.y);
                cands_.push_back(c);
            }
        };
        if (right) wall(0, s.qw1, Ev::Right, Ev::GrazeRight);
        if (upper) wall(2, s.qw2, Ev::Upper, Ev::GrazeUpper);
        if (R.armed && y0[1] > 0 && y[1] <= 0) {
            Candidate c{};
            c.kind = Ev::Section;
            ++work_.section_searches;
            c.tau = locate(in_, y0, d0, y, d1, 1, 0.0, h, opt.event_tol, c.y);
            cands_.push_back(c);
        }
        std::sort(cands_.begin(), cands_.end(), [](const Candidate& a, const Candidate& b) { return a.tau < b.tau; });

        bool reflected = false;
        for (const Candidate& c : cands_) {
            auto stop = [&](FlowStatus status) {
                for (int i = 0; i < 4; ++i) r.z[std::size_t(i)] = c.y[i];
                if (tangents_ > 0) take_tangents(c.y, r);
                r.time = t0 + c.tau;
                r.status = status;
                done = true;
                if (dense) {
                    sample(y0, d0, t0, r.time);
                    dense->push(dense->offset + r.time, c.y,
                                status == FlowStatus::Ok ? TrajectoryPoint::Return : TrajectoryPoint::End);
                }
            };
            if (c.kind == Ev::Section) {
                // A shallow crossing amplifies the return's error too: its time moves by
                // dp1 / |dp1/dt|, and dp1/dt = -(V1' + eps dVc/dq1) is small where the coupling
                // nearly cancels V1's restoring force at q1's maximum. Against an uncoupled
                // crossing, |V1'(q1)|: at eps = 2.76 a return of 31 rk8pd steps at rtol 1e-8 ended
                // where dp1/dt was 1/217 of it, 1.3e-6 off in time, and went unverified.
                if (s.eps != 0.0) {
                    double dc[kMaxDim];
                    field(c.y, dc);
                    const double g = s.eps * s.coupling.gradient(c.y[0], c.y[2])[0];
                    R.amplification *= std::max(1.0, std::fabs(dc[1] + g) / std::fabs(dc[1]));
                }
                stop(FlowStatus::Ok);
                break;
            }
            const bool is_right = c.kind == Ev::Right || c.kind == Ev::GrazeRight;
            // The other coordinate decides whether the wall is there: the right wall spans
            // q2 < qw2 (all q2 for the infinite wall), the upper wall q1 < qw1.
            const double other = is_right ? c.y[2] - s.qw2 : c.y[0] - s.qw1;
            const bool has_wall = is_right ? (!is_step || other < 0) : other < 0;
            if (is_step && std::fabs(other) <= opt.corner_tol && (c.kind == Ev::Right || c.kind == Ev::Upper)) {
                stop(FlowStatus::Corner);
                break;
            }
            if (!has_wall) {  // crossed the wall's line beside / above the step
                if (is_right && c.kind == Ev::Right) note_crossing();
                continue;
            }
            if (c.kind == Ev::GrazeRight || c.kind == Ev::GrazeUpper) {
                stop(FlowStatus::Grazing);
                break;
            }
            if (R.impacts >= opt.max_impacts) {
                stop(FlowStatus::ImpactLimit);
                break;
            }
            // Elastic reflection (eq:R1, eq:R2), placed exactly on the wall so that the restart
            // (g = 0, moving away) cannot find the same impact again.
            for (int i = 0; i < n; ++i) y[i] = c.y[i];
            ++R.impacts;
            if (is_right) {
                y[0] = s.qw1;
                y[1] = -y[1];
            } else {
                y[2] = s.qw2;
                y[3] = -y[3];
            }
            if (labels) {
                r.itinerary += is_right ? 'R' : '1';
                ++work_.label_operations;
            }
            field.sync_aux(y);
            t = t0 + c.tau;
            if (dense) {
                sample(y0, d0, t0, t);
                dense->push(dense->offset + t, c.y, TrajectoryPoint::ImpactIn);
                dense->push(dense->offset + t, y, TrajectoryPoint::ImpactOut);
            }
            field(y, dy);
            {
                // A shallow impact amplifies the state's error: its time moves by dq / v and the
                // reflected velocity by 2 a dq / v (the saltation term), a factor 2 |a| / (|v| w)
                // against the oscillation's own scale w (8 hmax is the shorter period). Impacts
                // compound: rk8pd's error reached 12-80 bands in 21-59 steps over 3-7 upper-wall
                // impacts, each amplifying less than 20x.
                const int pi = is_right ? 1 : 3;
                const double w = kTwoPi / (8 * R.hmax);
                R.amplification *= std::max(1.0, 2 * std::fabs(dy[pi]) / (std::fabs(y[pi]) * w));
                if (tangents_ > 0) {
                    // dy[pi] is the force on the wall: a function of the positions, which the
                    // reflection keeps; c.y[pi] the velocity before the impact.
                    saltation(y, pi - 1, c.y[pi], dy[pi]);
                    field(y, dy);  // the tangents' derivatives after the jump
                }
            }
            in_.restart();
            reflected = true;
            break;
        }
        if (done) return R.over = true;
        if (dense && !reflected) sample(y0, d0, t0, t);
        // A return passes q1's minimum (p1 from - to +, or a right-wall reflection) and then its
        // maximum (p1 from + to -). Arming the section only after the minimum makes a start with
        // p1 = +-1e-14 (a point computed on Sigma_h) safe from being taken for its own return.
        // A step from p1 = 0 exactly (a start on Sigma_h) with p1' < 0 dips below 0 before any
        // later sign change, even when it ends with p1 > 0 (a shallow minimum inside the step).
        R.seen_negative = R.seen_negative || y0[1] < 0 || y[1] < 0 || (y0[1] == 0 && d0[1] < 0);
        R.armed = R.armed || (R.seen_negative && y[1] > 0);
        }
    return false;
}

void Tracer::saltation(double* y, int gi, double v, double a) const {
    // S = R + (f+ - R f-) n^T / (n . f-) for the wall g = q_i - qw (n = e_qi) and the reflection
    // R: p_i -> -p_i. f+ - R f- = -2 v e_qi - 2 V_,i e_pi (the force is the same on both sides),
    // n . f- = v: S sends dq_i -> -dq_i and dp_i -> (2 a / v) dq_i - dp_i (a = -V_,i), all else
    // unchanged. A shallow impact (v -> 0) amplifies the tangent by 2 |a| / |v|: the grazing
    // square-root singularity, finite while v != 0.
    const int m = in_.field().state;
    for (int j = 0; j < tangents_; ++j) {
        double* t = y + m + 4 * j;
        const double dq = t[gi], dp = t[gi + 1];
        t[gi] = -dq;
        t[gi + 1] = (2 * a / v) * dq - dp;
    }
}

void Tracer::take_tangents(const double* y, ReturnResult& r) const {
    const int m = in_.field().state;
    for (int j = 0; j < tangents_; ++j)
        for (int row = 0; row < 4; ++row) r.tangents[std::size_t(row * tangents_ + j)] = y[m + 4 * j + row];
}

bool Tracer::settle() {
    if (vf_.level < 0) {
        Ret& R = ret_;
        finish(R.r, R.y, R.t, R.done, R.crossed, R.H0);
        const std::int64_t from = verify_from();
        // Step errors add up over a return and impacts multiply them: steps x amplification.
        if (from > 0 && R.r.status == FlowStatus::Ok && double(R.r.steps) * R.amplification >= double(from)) {
            vf_.prev_tol = o_.rtol;
            vf_.steps0 = vf_.steps = R.r.steps;
            vf_.prev = std::move(R.r);
            return verify_at(0);
        }
        result_ = std::move(R.r);
        return true;
    }
    // The verifying trace at level vf_.level is over: judge the first trace by it.
    Tracer& V = *verifier_[vf_.level];
    V.settle();  // never verified itself (verify_steps = 0): its result is final
    ReturnResult r = V.end();
    V.set_dense(nullptr);
    ReturnResult& prev = vf_.prev;
    vf_.steps += r.steps;
    if (r.status == FlowStatus::StepLimit || r.status == FlowStatus::NonFinite || r.status == FlowStatus::OutsideWell) {
        prev.steps = vf_.steps;  // the tighter trace could not be completed: not verified
        prev.status = FlowStatus::Imprecise;
        return conclude(std::move(prev));
    }
    if (r.status != FlowStatus::Ok) {  // the tighter trace decides (a graze, a corner, ...)
        r.steps = vf_.steps;
        return conclude(std::move(r));
    }
    // The difference in units of the band (time: rtol max(1, t); state: rtol |z| + atol), and
    // the tighter trace's error estimated from it.
    double d = std::fabs(prev.time - r.time) / (o_.rtol * std::max(1.0, std::fabs(r.time)));
    for (int i = 0; i < 4; ++i) {
        const double zi = r.z[std::size_t(i)];
        d = std::max(d, std::fabs(prev.z[std::size_t(i)] - zi) / (o_.rtol * std::fabs(zi) + o_.atol));
    }
    if (prev.itinerary != r.itinerary) d = kInf;
    const double estimate = 0.1 * d;
    r.steps = vf_.steps;
    prev = std::move(r);
    vf_.prev_tol = verifier_[vf_.level]->o_.rtol;
    if (estimate <= 1) return conclude(std::move(prev));
    return verify_at(vf_.level + 1);
}

ReturnResult Tracer::end() {
    return std::move(result_);
}

bool Tracer::conclude(ReturnResult r) {
    vf_.level = -1;
    if (r.status != FlowStatus::Ok) {  // Imprecise: no coordinates promised
        r.chart = {kNaN, kNaN};
        r.chart_point = {kNaN, kNaN, kNaN, kNaN};
    }
    result_ = std::move(r);
    return true;
}

std::int64_t Tracer::verify_from() const {
    if (o_.verify_steps >= 0) return o_.verify_steps;
    // Measured on random systems (tests/flow/test_differential.py): below these step counts, and
    // without a shallow impact, a return's error stayed within its band. A taylor step errs far
    // below rtol, whatever the tolerance; a GSL step errs by about rtol, so its errors add up
    // sooner, and an ordinary return takes rtol^(-1/order) more steps at tighter tolerances
    // (rk8pd on slow oscillators: 85-107 steps, 3-10x the band at rtol 1e-8). The closed form
    // has no step error to verify.
    if (in_.exact_kind() != ExactKind::None) return 0;
    if (o_.stepper == Stepper::Taylor) return kVerifySteps;
    const double n = double(kVerifyStepsGsl) * std::pow(1e-8 / o_.rtol, 1.0 / in_.order());
    return std::int64_t(std::clamp(n, 16.0, 1e15));
}

bool Tracer::verify_at(int level) {
    // A long return's error is not bounded by its steps' tolerance: local errors add up over
    // hundreds of steps, and a chaotic return (strong coupling, near a tangency) or a shallow
    // impact amplifies them (~3e-5 in time at rtol 1e-8 measured). Tracing it again at rtol / 100
    // measures the error of the first trace. The tighter trace's own error is taken as a tenth
    // of that difference: measured 30-300x smaller, but only ~3x where rk8pd's steps sit at the
    // step bound and its error hardly follows the tolerance (slow oscillators at rtol 1e-6), so
    // a tenth is kept only if the difference is within 10 bands; else one level tighter (level
    // 1, rtol / 10^4). The floor: below it a tighter tolerance stops reducing the error
    // (rounding): ~1e-15 for taylor; GSL's steppers, whose error estimates are differences of
    // stages, stall sooner. The tighter trace is stepped like any return (stepping()), so that a
    // lane group expands the verifying traces of its lanes together.
    const bool taylor = o_.stepper == Stepper::Taylor;
    const double floor = taylor ? 1e-15 : 1e-14;
    ReturnResult& prev = vf_.prev;
    const double factor = level == 0 ? 1e-2 : 1e-4;
    const double tol = std::max(o_.rtol * factor, floor);
    if (level > 1 || !(tol < 0.5 * vf_.prev_tol)) {  // nothing tighter to compare with
        if (prev.steps != vf_.steps0) prev.status = FlowStatus::Imprecise;  // else rtol is at the floor
        return conclude(std::move(prev));
    }
    if (!verifier_[level]) {
        FlowOptions v = o_;
        v.rtol = tol;
        v.atol = std::max(o_.atol * factor, 1e-300);
        v.verify_steps = 0;
        v.max_steps = std::max<std::int64_t>(o_.max_steps, 1);
        // Taylor's verifier keeps this trace's order, its tighter tolerance in shorter steps: a
        // lane group then expands verifying traces in the same kernel call as the returns (one
        // order per call). Alone at its own order (25 at rtol 1e-12, against 21) the verifying
        // trace of 9% of the returns took 20% of the time (Tan x Tan, walls).
        const int order = taylor ? in_.order() : 0;
        verifier_[level] = std::make_unique<Tracer>(s_, v, tangents_, order);
        verifier_[level]->set_event_driven(event_driven_);
    }
    Tracer& V = *verifier_[level];
    V.set_labels(labels_);
    V.set_section_energy(section_h_);
    // A budget of steps: the tighter trace needs about (prev_tol / tol)^(1/order) times the
    // steps; ten times that means it cannot meet its tolerance (rounding), so no verdict.
    const double growth = std::pow(vf_.prev_tol / tol, 1.0 / std::max(1, in_.order()));
    V.o_.max_steps = std::min<std::int64_t>(o_.max_steps, std::int64_t(10 * growth * double(prev.steps)) + 1000);
    if (dense_) {  // the trajectory shows the return that is kept: the tighter one's points
        dense_->points->resize(ret_.dense_points);
        dense_->kinds->resize(ret_.dense_kinds);
        dense_->next = ret_.dense_next;
        dense_->room = ret_.dense_room;
        dense_->truncated = ret_.dense_truncated;
    }
    V.set_dense(dense_);
    vf_.level = level;
    V.begin(ret_.z0, ret_.first_crossing, tangents_ > 0 ? ret_.t0 : nullptr);
    return false;
}

bool Tracer::halted(ReturnResult& r, const std::atomic<bool>* cancel) const {
    if (r.steps >= o_.max_steps) {
        r.status = FlowStatus::StepLimit;
        return true;
    }
    // The flag is read every 256 steps: an atomic load per step would show in the inner loop.
    if (cancel && (r.steps & 255) == 255 && cancel->load(std::memory_order_relaxed)) {
        r.status = FlowStatus::Interrupted;
        return true;
    }
    return false;
}

void Tracer::finish(ReturnResult& r, const double* y, double t, bool done, bool crossed, double H0) {
    if (!done) {  // stopped between events (step limit, non-finite, outside a well, interrupted)
        for (int i = 0; i < 4; ++i) r.z[std::size_t(i)] = y[i];
        r.time = t;
        if (dense_) dense_->push(dense_->offset + t, y, TrajectoryPoint::End);
    }
    if (labels_ && r.status == FlowStatus::Ok && r.itinerary.empty() && s_.geometry != Geometry::None) {
        r.itinerary = crossed ? "0" : "u";
        ++work_.label_operations;
    }
    r.energy_error = std::fabs(s_.energy(r.z.data()) - H0);
    if (r.status == FlowStatus::Ok && !on_chart(r, H0)) r.status = FlowStatus::OffSection;
    if (r.status != FlowStatus::Ok) {
        r.chart = {kNaN, kNaN};
        r.chart_point = {kNaN, kNaN, kNaN, kNaN};
    }
    if (tangents_ > 0 && r.status != FlowStatus::Ok) r.tangents.fill(kNaN);
    work_.steps += r.steps;
}

bool Tracer::on_chart(ReturnResult& r, double H0) const {
    const std::array<double, 4>& z = r.z;
    // The section's energy: the caller's (set_section_energy: the next return starts from the
    // very point computed here), else the start's.
    const double h = std::isnan(section_h_) ? H0 : section_h_;
    // A return is a maximum of q1 at energy h; Sigma_h's chart (try_section_point) holds one such
    // maximum per (theta, I): the root of V1 + eps Vc = h - H2 with q1 > 0 and dp1/dt < 0. At
    // strong coupling a maximum of q1 can lie elsewhere (q1 < 0, another root): its (theta, I)
    // would name a different point, so such a return is not reported Ok.
    if (!(z[0] > 0)) return false;
    const std::array<double, 2> c = section_coordinates(s_, z.data());
    r.chart = c;  // the callers' coordinates of the image: computed once
    if (!(c[1] > 0)) return std::isfinite(c[1]);  // I = 0: oscillator 2 at rest, the chart's centre
    std::array<double, 4>& p = r.chart_point;
    if (!try_section_point(s_, h, c[0], c[1], p, nullptr)) return false;
    // The same root moves by the return's energy error e over dF/dq1 = -dp1/dt (F(q1) = e at
    // the return); a distinct root lies O(1) away, or the two merge where dp1/dt = 0 (Sigma_h's
    // edge) and the return is not on its chart anyway. (-dp1/dt as FlowSystem::rhs has it.)
    double dp1 = -s_.V1->dV(z[0]);
    if (s_.eps != 0.0) dp1 -= s_.eps * s_.coupling.gradient(z[0], z[2])[0];
    const double e = h == H0 ? r.energy_error : std::fabs(s_.energy(z.data()) - h);
    return std::fabs(p[0] - z[0]) <= 1e-9 * (1 + std::fabs(z[0])) + 4 * e / std::fabs(dp1);
}

TracerGroup::TracerGroup(const FlowSystem& s, const FlowOptions& o, int tangents)
    : taylor_(resolve_stepper(o.stepper, s) == Stepper::Taylor) {
    // Eight lanes (two 4-double vectors, or one 8-double vector on AVX-512) rather than four:
    // measured up to 10% more returns per second on AVX2, the two chains overlapping.
    const int n = taylor_ ? kMaxTaylorGroup : 1;
    for (int l = 0; l < n; ++l) t_.push_back(std::make_unique<Tracer>(s, o, tangents));
    if (taylor_) coef_.reset(new TaylorLanes);  // uninitialised: each round writes what it reads
}

void TracerGroup::start(int l, const std::array<double, 4>& z0, bool first_crossing, const std::atomic<bool>* cancel,
                        const double* t0) {
    Tracer& t = lane(l);
    busy_ |= 1u << l;
    if (!t.steps_apply()) {  // the event-driven closed form: a whole return at once
        done_[l] = t.trace(z0, first_crossing, cancel);
        ready_ |= 1u << l;
        return;
    }
    t.begin(z0, first_crossing, t0);
}

unsigned TracerGroup::step(const std::atomic<bool>* cancel) {
    unsigned over = ready_;
    const unsigned stepping = busy_ & ~ready_;
    if (taylor_ && (stepping & (stepping - 1))) {
        // Two or more lanes: expand them together, the returns and the verifying traces (a
        // verifier keeps the order of the trace it verifies: Tracer::verify_at).
        Taylor* tt[kMaxTaylorGroup];
        const double* y[kMaxTaylorGroup];
        double hmax[kMaxTaylorGroup];
        int m = 0;
        for (int l = 0; l < lanes(); ++l)
            if ((stepping >> l) & 1u) {
                Tracer& a = lane(l).stepping();
                tt[m] = a.integrator().taylor();
                y[m] = a.next_start();
                hmax[m] = a.next_hmax();
                ++m;
            }
        Taylor::expand_group(tt, y, hmax, *coef_, m);
    }
    for (int l = 0; l < lanes(); ++l)
        if (((stepping >> l) & 1u) && lane(l).stepping().step(cancel) && lane(l).settle()) over |= 1u << l;
    ready_ |= over;
    return over;
}

ReturnResult TracerGroup::collect(int l) {
    const unsigned bit = 1u << l;
    ReturnResult r = (ready_ & bit) && !lane(l).steps_apply() ? std::move(done_[l]) : lane(l).end();
    busy_ &= ~bit;
    ready_ &= ~bit;
    return r;
}

FlowWork TracerGroup::work() const {
    FlowWork w;
    for (const auto& t : t_) w += t->work();
    return w;
}

std::unique_ptr<TracerGroup> TracerPool::take(int tangents) {
    {
        std::lock_guard<std::mutex> lock(mu_);
        auto& v = kept_[tangents];
        if (!v.empty()) {
            std::unique_ptr<TracerGroup> g = std::move(v.back());
            v.pop_back();
            return g;
        }
    }
    return std::make_unique<TracerGroup>(s_, o_, tangents);
}

void TracerPool::give(std::unique_ptr<TracerGroup> g, int tangents) {
    if (!g || g->any_busy()) return;
    // What a call may have set: the next call starts as with a new group.
    for (int l = 0; l < g->lanes(); ++l) {
        g->lane(l).set_labels(true);
        g->lane(l).set_dense(nullptr);
        g->lane(l).set_section_energy(kNaN);
    }
    const std::size_t most = std::max(1u, hardware_threads());
    std::lock_guard<std::mutex> lock(mu_);
    auto& v = kept_[tangents];
    if (v.size() < most) v.push_back(std::move(g));
}

PooledGroup::PooledGroup(TracerPool* pool, const FlowSystem& s, const FlowOptions& o, int tangents)
    : pool_(pool), tangents_(tangents), unwinding_(std::uncaught_exceptions()) {
    g_ = pool_ ? pool_->take(tangents) : std::make_unique<TracerGroup>(s, o, tangents);
    before_ = g_->work();
}

PooledGroup::~PooledGroup() {
    if (pool_ && std::uncaught_exceptions() == unwinding_) pool_->give(std::move(g_), tangents_);
}

FlowWork PooledGroup::work() const {
    FlowWork w = g_->work();
    w -= before_;
    return w;
}

}  // namespace hovering::detail
