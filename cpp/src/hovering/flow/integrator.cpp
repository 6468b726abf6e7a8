// GSL odeiv2 stepping of one orbit: see integrator.hpp.

#include "hovering/flow/integrator.hpp"

#include <gsl/gsl_errno.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "hovering/detail/common.hpp"
#include "hovering/detail/poly_roots.hpp"

namespace hovering::detail {

const gsl_odeiv2_step_type* stepper_type(Stepper s) {
    switch (s) {
        case Stepper::Rk8pd: return gsl_odeiv2_step_rk8pd;
        case Stepper::Rkck: return gsl_odeiv2_step_rkck;
        case Stepper::Rkf45: return gsl_odeiv2_step_rkf45;
        case Stepper::Rk4: return gsl_odeiv2_step_rk4;
        case Stepper::Rk2: return gsl_odeiv2_step_rk2;
        case Stepper::Msadams: return gsl_odeiv2_step_msadams;
        case Stepper::Rk4imp: return gsl_odeiv2_step_rk4imp;
        case Stepper::Rk2imp: return gsl_odeiv2_step_rk2imp;
        case Stepper::Taylor:
        case Stepper::Exact: return nullptr;
        case Stepper::Auto: break;  // resolved on the system before (FlowOptions::resolved): never here
    }
    bad("stepper: not a Stepper value (" + std::to_string(int(s)) + ")");
}

Integrator::Integrator(const FlowSystem& s, const FlowOptions& options, int n_tangents, int taylor_order)
    : field_(s, n_tangents),
      atol_(options.atol),
      rtol_(options.rtol),
      qlim1_(s.V1->q_limit()),
      qlim2_(s.V2->q_limit()) {
    const FlowOptions o = options.resolved(s);  // "auto": the stepper it means on s
    gsl_quiet();
    sys_ = gsl_odeiv2_system{field_.fn, &Field::jacobian, std::size_t(field_.dim), &field_};
    const gsl_odeiv2_step_type* T = stepper_type(o.stepper);
    kind_ = detail::exact_kind(s, o);
    if (o.stepper == Stepper::Taylor) {
        taylor_ = std::make_unique<Taylor>(field_, s, o.rtol, o.atol, taylor_order);
    } else if (kind_ != ExactKind::None) {
        if (kind_ == ExactKind::Linear) linear_ = std::make_unique<LinearFlow>(s);
        osc_[0].V = s.V1.get();
        osc_[1].V = s.V2.get();
    } else if (T == gsl_odeiv2_step_msadams) {
        driver_ = gsl_odeiv2_driver_alloc_standard_new(&sys_, T, 1e-3, o.atol, o.rtol, 1.0, 0.0);
        if (!driver_) throw std::bad_alloc();
        step_ = driver_->s;
        control_ = driver_->c;
        ext_ = gsl_odeiv2_step_alloc(gsl_odeiv2_step_rk8pd, std::size_t(field_.dim));
        if (!ext_) {
            gsl_odeiv2_driver_free(driver_);
            throw std::bad_alloc();
        }
    } else if (T == gsl_odeiv2_step_rk2imp || T == gsl_odeiv2_step_rk4imp) {
        // GSL's implicit steppers read the tolerances of their Newton iteration from a driver's
        // control: the driver owns the stepper, which the adaptive loop below drives as any other.
        imp_driver_ = gsl_odeiv2_driver_alloc_standard_new(&sys_, T, 1e-3, o.atol, o.rtol, 1.0, 0.0);
        if (!imp_driver_) throw std::bad_alloc();
        step_ = imp_driver_->s;
        order_ = int(gsl_odeiv2_step_order(step_));
        grow_below_ = std::pow(0.9, order_);
    } else {
        step_ = gsl_odeiv2_step_alloc(T, std::size_t(field_.dim));
        if (!step_) throw std::bad_alloc();
        order_ = int(gsl_odeiv2_step_order(step_));
        grow_below_ = std::pow(0.9, order_);
    }
}

Integrator::~Integrator() {
    if (driver_) {
        gsl_odeiv2_driver_free(driver_);
        gsl_odeiv2_step_free(ext_);
    } else if (imp_driver_) {
        gsl_odeiv2_driver_free(imp_driver_);
    } else if (step_) {
        gsl_odeiv2_step_free(step_);
    }
}

double Integrator::max_step() const {
    if (!linear_ || !(linear_->fastest_rate() > 0)) return kInf;
    // As the oscillators' T/8: one step never holds both extrema of a mode (a cosh mode has none,
    // and 1/8 of 2 pi over its rate keeps the growth per step below e^0.8).
    return 0.125 * kTwoPi / linear_->fastest_rate();
}

void Integrator::restart() {
    if (driver_) {
        gsl_odeiv2_driver_reset(driver_);
        // msadams' clock restarts too: step lengths are differences t_ms_ - t0, whose rounding
        // depends on |t_ms_|, so a clock running on from earlier returns made a return depend on
        // what the worker had traced before (orbits differed with the thread count).
        t_ms_ = 0;
    } else if (step_) {
        gsl_odeiv2_step_reset(step_);
    }
}

Integrator::Advance Integrator::advance(double* y, double* d, double* h, double hmax, double* h_done) {
    const int n = field_.dim;
    if (kind_ != ExactKind::None) {  // no error to control: every step is hmax long, or shorter for events
        double y1[kMaxDim], d1[kMaxDim];
        double step = hmax;
        for (;;) {
            exact(y, d, step, y1);
            bool finite = true;
            for (int i = 0; i < n; ++i) finite = finite && std::isfinite(y1[i]);
            if (!finite) return Advance::Failed;
            field_(y1, d1);
            if (!(step > kMinEventStep * hmax) ||
                !(ambiguous(y, d, y1, d1, step) || (linear_ && linear_ambiguous(y, d, y1, d1, step))))
                break;
            step *= 0.5;
            ++event_cuts_;
        }
        for (int i = 0; i < n; ++i) {
            y[i] = y1[i];
            d[i] = d1[i];
        }
        *h = hmax;
        *h_done = step;
        return Advance::Ok;
    }
    if (taylor_) {
        // The step is chosen a priori (no error to reject); only a step that leaves a bounded well
        // is shortened (halved on the same polynomial, as the GSL steppers' rejected trials).
        // A lane group may have expanded this state already (Taylor::expand_group).
        double hn = 0;
        if (!taylor_->expanded_at(y, &hn) && !taylor_->expand(y, hmax, &hn)) return Advance::Failed;
        double step = taylor_cut(std::min(hn, hmax));
        double y1[kMaxDim];
        for (;;) {
            taylor_->eval(step, y1);
            bool finite = true;
            for (int i = 0; i < n; ++i) finite = finite && std::isfinite(y1[i]);
            if (finite && inside(y1)) break;
            step *= 0.5;
            if (!(step >= 1e-14 * hmax)) return finite ? Advance::OutsideWell : Advance::Failed;
        }
        for (int i = 0; i < n; ++i) y[i] = y1[i];
        field_(y, d);
        *h = hn;
        *h_done = step;
        return Advance::Ok;
    }
    double y0[kMaxDim], d0[kMaxDim], err[kMaxDim], dout[kMaxDim];
    for (int i = 0; i < n; ++i) {
        y0[i] = y[i];
        d0[i] = d[i];
    }
    auto restore = [&] {
        for (int i = 0; i < n; ++i) {
            y[i] = y0[i];
            d[i] = d0[i];
        }
    };
    // A loose tolerance lets a large step jump across the edge of a bounded well (Tan: the force is
    // a polynomial in u = tan(alpha q), so nothing stops the stepper at |alpha q| = pi / 2 and it
    // carries on in the next branch of tan). The exact flow never gets there at finite energy, so
    // such a step is rejected like one with too large an error, and halved.
    bool left_well = false;
    if (driver_) {
        for (;;) {
            const double t0 = t_ms_;
            *h = std::min(*h, hmax);
            const int st = gsl_odeiv2_evolve_apply(driver_->e, driver_->c, driver_->s, &sys_, &t_ms_, t0 + hmax, h, y);
            bool finite = st == GSL_SUCCESS;
            for (int i = 0; i < n; ++i) finite = finite && std::isfinite(y[i]);
            *h_done = t_ms_ - t0;
            bool cut = false;
            if (finite && *h_done > 0 && inside(y)) {
                field_(y, d);
                if (!(*h_done > kMinEventStep * hmax) || !ambiguous(y0, d0, y, d, *h_done)) return Advance::Ok;
                cut = true;
                ++event_cuts_;
            }
            const double tried = *h_done;
            restore();
            if (!cut && (!finite || !(tried > 0))) return left_well ? Advance::OutsideWell : Advance::Failed;
            // Outside a well, or two sign changes of an event velocity: forget the multistep history
            // (it holds the step) and retry shorter.
            left_well = left_well || !cut;
            gsl_odeiv2_driver_reset(driver_);
            t_ms_ = t0;
            *h = 0.5 * tried;
            if (!(*h >= 1e-14 * hmax)) return Advance::OutsideWell;
        }
    }
    for (;;) {
        const double h0 = std::min(*h, hmax);
        const int st = gsl_odeiv2_step_apply(step_, 0.0, h0, y, err, d, dout, &sys_);
        bool finite = st == GSL_SUCCESS;
        for (int i = 0; i < n; ++i) finite = finite && std::isfinite(y[i]) && std::isfinite(err[i]);
        const bool in = finite && inside(y);
        left_well = left_well || (finite && !in);
        double hn = h0;
        const int adj = in ? hadjust(y, err, &hn) : GSL_ODEIV_HADJ_DEC;
        const bool events_ok = adj == GSL_ODEIV_HADJ_DEC || !(h0 > kMinEventStep * hmax) || !ambiguous(y0, d0, y, dout, h0);
        if (adj != GSL_ODEIV_HADJ_DEC && events_ok) {
            for (int i = 0; i < n; ++i) d[i] = dout[i];
            *h_done = h0;
            *h = hn;
            return Advance::Ok;
        }
        if (!events_ok) ++event_cuts_;
        restore();
        *h = in && events_ok ? hn : 0.5 * h0;
        if (!(*h >= 1e-14 * hmax) || !std::isfinite(*h)) {  // the tolerance cannot be met
            return left_well ? Advance::OutsideWell : Advance::Failed;
        }
    }
}

int Integrator::hadjust(const double* y, const double* err, double* h) const {
    // GSL's standard rule (gsl_odeiv2_control_standard_new(atol, rtol, 1, 0), control.c): scaled
    // error rmax = max_i |err_i| / (atol + rtol |y_i|); above 1.1 the step shrinks by
    // 0.9 rmax^(-1/order) (at most 5x), below 0.5 it grows (at most 5x, never shrinks). GSL grows
    // by rmax^(-1/(order+1)); here the same root rmax^(-1/order) serves both, which for rk8pd is
    // three square roots: GSL's pow took 5% of a return's time, and cbrt for the 9th root more.
    double rmax = std::numeric_limits<double>::min();
    // The state's components only: the tangents (when integrated) do not change the steps, so a
    // return's state is the same with them as without.
    for (int i = 0; i < field_.state; ++i)
        rmax = std::max(rmax, std::fabs(err[i]) / (atol_ + rtol_ * std::fabs(y[i])));
    // The root rmax^(1/order) (three square roots for rk8pd) only where the step changes: above
    // 1.1, and below 0.9^order where the growth factor exceeds 1 (in between GSL's rule keeps h).
    auto root = [&] { return order_ == 8 ? std::sqrt(std::sqrt(std::sqrt(rmax))) : std::pow(rmax, 1.0 / order_); };
    if (rmax > 1.1) {
        *h *= std::max(0.2, 0.9 / root());
        return GSL_ODEIV_HADJ_DEC;
    }
    if (rmax < 0.5) {
        if (rmax < grow_below_) *h *= std::min(5.0, 0.9 / root());
        return GSL_ODEIV_HADJ_INC;
    }
    return GSL_ODEIV_HADJ_NIL;
}

void Integrator::prepare_extension(const double* y0, const double* d0, double h) {
    if (!driver_) return;
    // rk8pd's error ~ h^8: m = ratio^(1/8) substeps (rounded up) meet the tolerances.
    const int n = field_.dim;
    double y[kMaxDim], err[kMaxDim], din[kMaxDim];
    for (int i = 0; i < n; ++i) {
        y[i] = y0[i];
        din[i] = d0[i];
    }
    gsl_odeiv2_step_reset(ext_);
    gsl_odeiv2_step_apply(ext_, 0.0, h, y, err, din, nullptr, &sys_);
    double ratio = 0;
    for (int i = 0; i < field_.state; ++i)
        ratio = std::max(ratio, std::fabs(err[i]) / (atol_ + rtol_ * std::fabs(y[i])));
    ext_sub_ = std::isfinite(ratio) ? std::min(64, std::max(1, int(std::ceil(1.2 * std::pow(ratio, 0.125))))) : 64;
}

bool Integrator::solve_on_step(const double* y0, int i, double off, double lo, double hi, bool lo_above, double guess,
                               double* tau) const {
    return taylor_ && taylor_->expanded_at(y0) && taylor_->solve(i, off, lo, hi, lo_above, guess, tau);
}

void Integrator::exact(const double* y0, const double* d0, double dt, double* y1) {
    const int n = field_.dim;
    if (kind_ == ExactKind::Linear) {
        // The flow is linear: its tangents move by the same propagator (both potentials Harmonic: no aux).
        for (int j = 0; j <= field_.tangents; ++j) linear_->propagate(y0 + 4 * j, dt, y1 + 4 * j);
        return;
    }
    if (taylor_) {
        // Events and samples lie on the step's own polynomial; a caller asking from another
        // start (none does today) gets that start's expansion.
        if (!taylor_->expanded_at(y0)) {
            double unused;
            taylor_->expand(y0, dt, &unused);
        }
        taylor_->eval(dt, y1);
        return;
    }
    if (kind_ == ExactKind::Angles) {
        for (int i = 0; i < 2; ++i) {
            AngleOscillator& a = osc_[i];
            if (!a.set(y0[2 * i], y0[2 * i + 1])) {
                y1[2 * i] = y1[2 * i + 1] = kNaN;
                for (int j = 0; j < field_.tangents; ++j)
                    y1[field_.state + 4 * j + 2 * i] = y1[field_.state + 4 * j + 2 * i + 1] = kNaN;
                continue;
            }
            const auto [q, p] = a.at(a.theta + a.omega * dt);
            y1[2 * i] = q;
            y1[2 * i + 1] = p;
            if (field_.tangents > 0) {
                // Uncoupled: each oscillator's tangent block moves by its own angle flow's derivative.
                double J[4];
                a.tangent(dt, J);
                for (int j = 0; j < field_.tangents; ++j) {
                    const double* v = y0 + field_.state + 4 * j + 2 * i;
                    double* w = y1 + field_.state + 4 * j + 2 * i;
                    const double dq = v[0], dp = v[1];
                    w[0] = J[0] * dq + J[1] * dp;
                    w[1] = J[2] * dq + J[3] * dp;
                }
            }
        }
        field_.sync_aux(y1);
        return;
    }
    double err[kMaxDim], din[kMaxDim];
    for (int i = 0; i < n; ++i) {
        y1[i] = y0[i];
        din[i] = d0[i];
    }
    if (driver_) {
        gsl_odeiv2_step_reset(ext_);
        for (int k = 0; k < ext_sub_; ++k) {
            if (k > 0) field_(y1, din);
            gsl_odeiv2_step_apply(ext_, 0.0, dt / ext_sub_, y1, err, din, nullptr, &sys_);
        }
    } else {
        gsl_odeiv2_step_reset(step_);
        gsl_odeiv2_step_apply(step_, 0.0, dt, y1, err, din, nullptr, &sys_);
    }
}

double Integrator::taylor_cut(double step) {
    if (!watched_ || !std::isfinite(step)) return step;
    const int p = taylor_->order();
    double b[kMaxTaylorOrder + 1];
    RootBracket br[2];
    double cut = step;
    for (int w = 0; w < 2; ++w) {
        if (!((watched_ >> w) & 1u) || taylor_->keeps_sign(w, step)) continue;  // most steps: settled in the lanes
        if (!taylor_->scaled_coefficients(2 * w + 1, step, b)) continue;
        // The step's own polynomial is the solution it takes: its sign changes are exact, so the
        // step ends between the first two (on the same polynomial: no new expansion).
        if (!at_most_one_root(b, p) && isolate_roots(b, p, br, 2) == 2)
            cut = std::min(cut, 0.5 * (br[0].hi + br[1].lo) * step);
    }
    if (cut < step) ++event_cuts_;
    return cut;
}

bool Integrator::linear_ambiguous(const double* y0, const double* d0, const double* y1, const double* d1,
                                  double h) const {
    // The Hermite test below bounds the velocity's interpolation error from the step's ends, and a
    // two-mode flow can dip through zero and back between them unseen: crosscheck seed 4040 found
    // a q1 minimum and maximum 0.026 apart (|p1| < 2e-9 between) inside one exact step, and the
    // return skipped that maximum (t = 22.90 instead of 12.50; scipy's DOP853 events miss it too,
    // a fine grid shows both roots). Here the closed form decides: [0, h] is cut into pieces on
    // which p is provably monotone (|p'(mid)| > max|p''| len / 2) or provably root-free (|p(mid)| >
    // max|p'| len / 2); the sign changes at the cuts then count every crossing.
    for (int w = 0; w < 2; ++w) {
        if (!((watched_ >> w) & 1u)) continue;
        const int pi = 2 * w + 1;
        double m[2];
        linear_->velocity_derivative_bounds(y0, h, w, m);
        if (!std::isfinite(m[0]) || !std::isfinite(m[1])) continue;  // a runaway: the finite checks stop it
        // Most steps are settled by their ends (no evaluation inside): p' keeps its sign when it
        // cannot change by |p'| over the step, and p keeps its sign when neither end's cone
        // |p(end)| - max|p'| tau reaches zero before meeting the other's.
        const double p0 = y0[pi], p1 = y1[pi], a0 = d0[pi], a1 = d1[pi];
        if ((a0 > 0) == (a1 > 0) && std::min(std::fabs(a0), std::fabs(a1)) > m[1] * h) continue;
        if ((p0 > 0) == (p1 > 0) && p0 != 0 && p1 != 0 && std::fabs(p0) + std::fabs(p1) > m[0] * h) continue;
        struct Piece {
            double a, b, pa, pb;
        };
        Piece stack[64];
        int top = 0, crossings = 0, pieces = 0;
        double y[4];
        stack[top++] = {0.0, h, p0, p1};
        // Crossings are counted per settled piece from its end values (an exact zero at an end is
        // no sign change there: the start's p1 = 0 on the section is not an event).
        while (top > 0) {
            const Piece c = stack[--top];
            const double mid = 0.5 * (c.a + c.b), half = 0.5 * (c.b - c.a);
            linear_->state_at(y0, mid, y);
            const double pm = y[pi], dm = linear_->acceleration(y, w);
            const bool monotone = std::fabs(dm) > m[1] * half, free = std::fabs(pm) > m[0] * half;
            if (monotone || free) {
                if ((c.pa < 0 && c.pb > 0) || (c.pa > 0 && c.pb < 0)) ++crossings;
                if (crossings >= 2) return true;
                continue;
            }
            // Undecided within the budget (a tangency, or a dip below rounding): count it as two, so
            // the step is halved as for any ambiguous step.
            if (++pieces > 200 || top + 2 > 64 || !(half > 1e-12 * h)) return true;
            stack[top++] = {mid, c.b, pm, c.pb};
            stack[top++] = {c.a, mid, c.pa, pm};
        }
    }
    return false;
}

bool Integrator::ambiguous(const double* y0, const double* d0, const double* y1, const double* d1, double h) const {
    for (int w = 0; w < 2; ++w) {
        if (!((watched_ >> w) & 1u)) continue;
        const int qi = 2 * w, pi = qi + 1;
        // The velocity as the derivative of q's quintic Hermite interpolant (q, p, p' at both
        // ends), in s = tau / h. Its distance to the cubic Hermite of p (p, p' at both ends), one
        // order less accurate, is exactly P4 s^2 (1 - s)^2 (both match p and p' at both ends), and
        // 64 times that distance, pointwise, bounds P's error: sign changes are counted for P and
        // P -+ that band. The band vanishes at the ends, whose values are the step's own: a
        // constant band (the earlier test) lifted an end across zero wherever the band was wider
        // than the end's velocity, and then saw one root instead of two. rk8pd at rtol 1e-6 thus
        // stepped over a q1 minimum and maximum 0.011 apart (peak p1 ~1e-7) and returned 10.4
        // time units late, status OK (tests/flow/test_exact_flow.py, NEAR_TANGENT).
        const double q0 = y0[qi], v0 = h * y0[pi], a0 = h * h * d0[pi];
        const double q1 = y1[qi], v1 = h * y1[pi], a1 = h * h * d1[pi];
        const double c3 = -10 * q0 - 6 * v0 - 1.5 * a0 + 0.5 * a1 - 4 * v1 + 10 * q1;
        const double c4 = 15 * q0 + 8 * v0 + 1.5 * a0 - a1 + 7 * v1 - 15 * q1;
        const double c5 = -6 * q0 - 3 * v0 - 0.5 * a0 + 0.5 * a1 - 3 * v1 + 6 * q1;
        const double P[5] = {v0, a0, 3 * c3, 4 * c4, 5 * c5};  // h times the velocity
        // 64 |P4| s^2 (1 - s)^2 (peak 4 |P4|, the earlier constant band's width), and rounding.
        const double band = 64 * std::fabs(P[4]) + 16e-13 * (std::fabs(v0) + std::fabs(v1));
        RootBracket br[2];
        for (const double b : {0.0, band, -band}) {
            const double Q[5] = {P[0], P[1], P[2] + b, P[3] - 2 * b, P[4] + b};  // P + b s^2 (1 - s)^2
            if (isolate_roots(Q, 4, br, 2) == 2) return true;
        }
    }
    return false;
}

}  // namespace hovering::detail
