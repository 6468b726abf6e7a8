// The flow in closed form (stepper "exact"): see exact.hpp. Here: which systems have it, the linear
// flow's normal modes, one oscillator's angle flow, and the Tracer's event-driven return loop for
// the uncoupled flow (Tracer::trace_angles).

#include "hovering/flow/exact.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

#include "hovering/detail/common.hpp"
#include "hovering/flow/tracer.hpp"

namespace hovering::detail {

namespace {

bool closed_form(const Potential* V) {
    return dynamic_cast<const Harmonic*>(V) || dynamic_cast<const Tan*>(V);
}
bool harmonic(const Potential* V) {
    return dynamic_cast<const Harmonic*>(V) != nullptr;
}

// Terms that move the flow: nonzero coefficient and a non-constant monomial (eps = 0: none).
bool coupled(const FlowSystem& s) {
    if (s.eps == 0.0) return false;
    for (const auto& t : s.coupling.terms)
        if (t[0] != 0 && t[1] + t[2] > 0) return true;
    return false;
}

bool quadratic(const Coupling& c) {
    for (const auto& t : c.terms)
        if (t[0] != 0 && t[1] + t[2] != 2 && t[1] + t[2] != 0) return false;
    return true;
}

}  // namespace

std::string describe(const FlowSystem& s) {
    std::string c;
    for (const auto& t : s.coupling.terms) {
        if (!c.empty()) c += " + ";
        c += fmt(t[0]) + " q1^" + fmt(t[1]) + " q2^" + fmt(t[2]);
    }
    return "V1 = " + s.V1->name() + ", V2 = " + s.V2->name() + ", eps = " + fmt(s.eps) +
           ", Vc = " + (c.empty() ? "0" : c);
}

ExactKind exact_kind(const FlowSystem& s, const FlowOptions& o) {
    if (o.stepper != Stepper::Exact) return ExactKind::None;
    if (!s.V1 || !s.V2) bad("the system needs two potentials V1 and V2");
    const bool c = coupled(s);
    if (!c && closed_form(s.V1.get()) && closed_form(s.V2.get())) return ExactKind::Angles;
    if (c && harmonic(s.V1.get()) && harmonic(s.V2.get()) && quadratic(s.coupling)) return ExactKind::Linear;
    bad("stepper 'exact' needs a flow in closed form: eps = 0 (or no coupling) with V1 and V2 each Harmonic "
        "or Tan (closed action-angle variables), or V1 and V2 both Harmonic with a quadratic coupling "
        "(terms q1 q2, q1^2, q2^2: a linear flow); the system has " +
        describe(s) + " (use a GSL stepper such as 'rk8pd')");
}

// ------------------------------------------------------------------------------- linear flow

LinearFlow::LinearFlow(const FlowSystem& s) {
    const double w1 = static_cast<const Harmonic&>(*s.V1).omega(), w2 = static_cast<const Harmonic&>(*s.V2).omega();
    Eigen::Matrix2d K;
    K << w1 * w1, 0, 0, w2 * w2;
    for (const auto& t : s.coupling.terms) {
        const int i = int(t[1]), j = int(t[2]);
        if (i + j != 2) continue;  // constants: no force
        const double c = s.eps * t[0];
        if (i == 1) {
            K(0, 1) += c;
            K(1, 0) += c;
        } else {
            K(i == 2 ? 0 : 1, i == 2 ? 0 : 1) += 2 * c;
        }
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(K);
    for (int k = 0; k < 2; ++k) {
        lam_[std::size_t(k)] = es.eigenvalues()(k);
        rate_[std::size_t(k)] = std::sqrt(std::fabs(lam_[std::size_t(k)]));
        for (int i = 0; i < 2; ++i) Q_[i][k] = es.eigenvectors()(i, k);
    }
}

double LinearFlow::fastest_rate() const {
    return std::max(rate_[0], rate_[1]);
}

void LinearFlow::propagate(const double* y0, double t, double* y1) const {
    if (!(t == t_last_)) {
        modes_at(t, c_last_, s_last_);
        t_last_ = t;
    }
    apply(y0, t, c_last_, s_last_, y1);
}

void LinearFlow::state_at(const double* y0, double t, double* y1) const {
    double c[2], sn[2];
    modes_at(t, c, sn);
    apply(y0, t, c, sn, y1);
}

void LinearFlow::modes_at(double t, double* c, double* sn) const {
    for (int k = 0; k < 2; ++k) {
        const double lam = lam_[std::size_t(k)], a = rate_[std::size_t(k)] * t;
        c[k] = lam > 0 ? std::cos(a) : lam < 0 ? std::cosh(a) : 1.0;
        sn[k] = lam > 0 ? std::sin(a) : lam < 0 ? std::sinh(a) : 0.0;
    }
}

void LinearFlow::apply(const double* y0, double t, const double* c_, const double* s_, double* y1) const {
    const double q[2] = {y0[0], y0[2]}, p[2] = {y0[1], y0[3]};
    double x[2], v[2];
    for (int k = 0; k < 2; ++k) {
        // Mode k: x'' = -lam x, x = Q^T q.
        const double x0 = Q_[0][k] * q[0] + Q_[1][k] * q[1], v0 = Q_[0][k] * p[0] + Q_[1][k] * p[1];
        const double lam = lam_[std::size_t(k)], s = rate_[std::size_t(k)];
        const double c = c_[k], sn = s_[k];
        if (lam > 0) {
            x[k] = c * x0 + sn / s * v0;
            v[k] = -s * sn * x0 + c * v0;
        } else if (lam < 0) {
            x[k] = c * x0 + sn / s * v0;
            v[k] = s * sn * x0 + c * v0;
        } else {
            x[k] = x0 + t * v0;
            v[k] = v0;
        }
    }
    y1[0] = Q_[0][0] * x[0] + Q_[0][1] * x[1];
    y1[1] = Q_[0][0] * v[0] + Q_[0][1] * v[1];
    y1[2] = Q_[1][0] * x[0] + Q_[1][1] * x[1];
    y1[3] = Q_[1][0] * v[0] + Q_[1][1] * v[1];
}

double LinearFlow::acceleration(const double* y, int i) const {
    // -(K q)_i with K = Q diag(lam) Q^T.
    double a = 0;
    for (int k = 0; k < 2; ++k) a -= Q_[i][k] * lam_[std::size_t(k)] * (Q_[0][k] * y[0] + Q_[1][k] * y[2]);
    return a;
}

void LinearFlow::velocity_derivative_bounds(const double* y0, double h, int i, double* m) const {
    // p_i = sum_k Q_ik x_k', so p_i' = -sum_k Q_ik lam_k x_k and p_i'' = -sum_k Q_ik lam_k x_k':
    // each mode's |x_k|, |x_k'| bounded over [0, h] by its amplitude (oscillating), its cosh/sinh
    // growth (lam < 0) or its line (lam = 0, which adds nothing: lam_k = 0).
    m[0] = m[1] = 0;
    for (int k = 0; k < 2; ++k) {
        const double x0 = Q_[0][k] * y0[0] + Q_[1][k] * y0[2], v0 = Q_[0][k] * y0[1] + Q_[1][k] * y0[3];
        const double lam = lam_[std::size_t(k)], r = rate_[std::size_t(k)];
        double X = 0, V = 0;
        if (lam > 0) {
            const double A = std::hypot(x0, v0 / r);
            X = A;
            V = r * A;
        } else if (lam < 0) {
            const double c = std::cosh(r * h), sn = std::sinh(r * h);
            X = std::fabs(x0) * c + std::fabs(v0) / r * sn;
            V = r * std::fabs(x0) * sn + std::fabs(v0) * c;
        }
        m[0] += std::fabs(Q_[i][k] * lam) * X;
        m[1] += std::fabs(Q_[i][k] * lam) * V;
    }
    // Rounding of the modes and of the states the bounds are compared with.
    m[0] = m[0] * (1 + 1e-12) + 1e-300;
    m[1] = m[1] * (1 + 1e-12) + 1e-300;
}

// ------------------------------------------------------------------------------- angle flow

double wrap_angle(double th) {
    return th >= -kPi && th < kPi ? th : wrap(th);  // most calls: no floor
}

bool AngleOscillator::set(double q, double p) {
    h = 0.5 * p * p + V->V(q);
    omega = theta = 0;
    if (!(std::isfinite(h) && h >= 0)) return false;
    q_rest = q;
    p_rest = p;
    if (h == 0) return true;  // at rest at the bottom of the well: no angle, no motion
    omega = V->frequency(h);
    theta = wrap_angle(V->angle_on_level(q, p, h));
    return std::isfinite(omega) && std::isfinite(theta);
}

std::pair<double, double> AngleOscillator::at(double th) const {
    if (!(h > 0)) return {q_rest, p_rest};
    return V->point_at(wrap_angle(th), h);
}

void AngleOscillator::tangent(double t, double* J) const {
    if (!(h > 0)) {
        const double d = 1e-6, c0 = (V->dV(d) - V->dV(-d)) / (2 * d), w = std::sqrt(std::max(c0, 0.0));
        const double a = w * t, c = std::cos(a), s = w > 0 ? std::sin(a) / w : t;
        J[0] = c;
        J[1] = s;
        J[2] = -c0 * s;
        J[3] = c;
        return;
    }
    const auto [q0, p0] = at(theta);
    const double th1 = theta + omega * t;
    const auto [q1, p1] = at(th1);
    const std::array<double, 2> v0 = V->point_slope(theta, h), v1 = V->point_slope(wrap_angle(th1), h);
    // omega'(h) = -omega^2 T'(h) / (2 pi).
    const double dw = -omega * omega * V->period_slope(h).value / kTwoPi;
    const double X0[2] = {p0 / omega, -V->dV(q0) / omega}, X1[2] = {p1 / omega, -V->dV(q1) / omega};
    const double M1[4] = {X1[0], v1[0] + X1[0] * dw * t, X1[1], v1[1] + X1[1] * dw * t};
    // M0^{-1}: M0 = [[X0q, v0q], [X0p, v0p]].
    const double det = X0[0] * v0[1] - v0[0] * X0[1];
    const double I0[4] = {v0[1] / det, -v0[0] / det, -X0[1] / det, X0[0] / det};
    J[0] = M1[0] * I0[0] + M1[1] * I0[2];
    J[1] = M1[0] * I0[1] + M1[1] * I0[3];
    J[2] = M1[2] * I0[0] + M1[3] * I0[2];
    J[3] = M1[2] * I0[1] + M1[3] * I0[3];
}

// ------------------------------------------------------------------------------- event-driven returns

void Tracer::sample_angles(const AngleOscillator* o, double t0, double t_end) {
    DenseRecorder& D = *dense_;
    const double a = D.offset + t0, b = D.offset + t_end, len = t_end - t0;
    for (;;) {
        const double tk = double(D.next) * D.dt;
        if (!(tk < b)) return;
        if (D.room <= 0) {
            D.truncated = true;
            return;
        }
        const double tau = std::min(std::max(tk - a, 0.0), len);
        const auto [q1, p1] = o[0].at(o[0].theta + o[0].omega * tau);
        const auto [q2, p2] = o[1].at(o[1].theta + o[1].omega * tau);
        const double y[4] = {q1, p1, q2, p2};
        ++work_.dense_samples;
        D.push(tk, y, TrajectoryPoint::Sample);
        ++D.next;
    }
}

// The uncoupled flow event to event. Every event is an angle reaching a value known in closed
// form: q1's wall line at theta_w1 = angle_of(qw1, h1) (reflection: theta1 -> -theta_w1), q2's at
// theta_w2, a minimum of q_i at theta_i = pi (grazing when it lies within grazing_tol of the wall;
// q1's also arms the section, as in trace()), the section at theta1 = 0. The semantics are
// trace()'s: the same statuses, corner and grazing tests, arming, labels and dense output; "steps"
// counts the events passed.
ReturnResult Tracer::trace_angles(const std::array<double, 4>& z0, bool first_crossing,
                                  const std::atomic<bool>* cancel) {
    const FlowSystem& s = s_;
    const FlowOptions& opt = o_;
    const bool labels = labels_;
    DenseRecorder* const dense = dense_;
    ReturnResult r;
    const double H0 = s.energy(z0.data());
    AngleOscillator o[2];
    o[0].V = s.V1.get();
    o[1].V = s.V2.get();
    double t = 0;
    bool done = false;
    auto current = [&](double* y) {
        const auto [q1, p1] = o[0].at(o[0].theta);
        const auto [q2, p2] = o[1].at(o[1].theta);
        y[0] = q1;
        y[1] = p1;
        y[2] = q2;
        y[3] = p2;
    };
    auto stop = [&](FlowStatus status, const double* y) {
        for (int i = 0; i < 4; ++i) r.z[std::size_t(i)] = y[i];
        r.time = t;
        r.status = status;
        done = true;
        if (dense)
            dense->push(dense->offset + t, y,
                        status == FlowStatus::Ok ? TrajectoryPoint::Return : TrajectoryPoint::End);
    };
    const bool ok = o[0].set(z0[0], z0[1]) && o[1].set(z0[2], z0[3]);
    if (!ok) {
        stop(FlowStatus::NonFinite, z0.data());
        r.energy_error = std::fabs(s.energy(r.z.data()) - H0);
        return r;
    }
    const bool right = s.geometry != Geometry::None, is_step = s.geometry == Geometry::Step;
    // Where oscillator i meets its wall line: crossing at angle theta_w, a touch (grazing) at its
    // minimum theta = pi, or never.
    enum class Meets { Never, Cross, Touch };
    struct WallLine {
        Meets meets = Meets::Never;
        double angle = 0;
    };
    auto wall_line = [&](const AngleOscillator& a, double qw) {
        WallLine w;
        if (!(a.h > 0)) return w;                              // at rest at q = 0 > qw
        const double d = a.V->turning_points(a.h).first - qw;  // the minimum's distance to the wall
        if (d > opt.grazing_tol) return w;
        if (d >= -opt.grazing_tol) {
            w.meets = Meets::Touch;
            w.angle = kPi;
        } else {
            w.meets = Meets::Cross;
            w.angle = a.V->angle_of(qw, a.h);
        }
        return w;
    };
    const WallLine w1 = right ? wall_line(o[0], s.qw1) : WallLine{};
    const WallLine w2 = is_step ? wall_line(o[1], s.qw2) : WallLine{};
    bool armed = first_crossing, crossed = false;
    int impacts = 0;
    // fresh[i]: oscillator i sits exactly on the angle of its last event (or its start), so a target
    // at distance 0 is a full turn away (trace() never finds an event at a step's start). The
    // other oscillator's angle was advanced by omega tau with rounding: a target it overshot by
    // rounding (distance just below 2 pi) is reached now.
    bool fresh[2] = {true, true};
    enum class Ev { Section, Min1, Right, Upper, Min2 };
    auto time_to = [&](int i, double target) {
        double d = target - o[i].theta;
        d -= kTwoPi * std::floor(d * kInvTwoPi);
        if (d >= kTwoPi) d -= kTwoPi;
        if (d == 0 && fresh[i]) d = kTwoPi;
        if (!fresh[i] && d > kTwoPi - 1e-13) d = 0;
        return d / o[i].omega;
    };
    if (!(o[0].omega > 0)) {
        // Oscillator 1 rests at the bottom of its well: p1 stays 0, the orbit never returns.
        double y[4];
        current(y);
        stop(FlowStatus::StepLimit, y);
    }
    while (!done) {
        if (halted(r, cancel)) break;
        // The next event: the earliest angle target of either oscillator.
        double tau = kInf, target = 0;
        Ev ev = Ev::Section;
        auto consider = [&](int i, double th, Ev e) {
            const double d = time_to(i, th);
            if (d < tau) {
                tau = d;
                target = th;
                ev = e;
            }
        };
        if (armed) consider(0, 0.0, Ev::Section);
        if (!armed || w1.meets == Meets::Touch) consider(0, kPi, Ev::Min1);
        if (w1.meets == Meets::Cross) consider(0, w1.angle, Ev::Right);
        if (o[1].omega > 0) {
            if (w2.meets == Meets::Cross) consider(1, w2.angle, Ev::Upper);
            if (w2.meets == Meets::Touch) consider(1, kPi, Ev::Min2);
        }
        if (dense) sample_angles(o, t, t + tau);
        const int i = ev == Ev::Upper || ev == Ev::Min2 ? 1 : 0;
        o[i].theta = wrap_angle(target);
        o[1 - i].theta = wrap_angle(o[1 - i].theta + o[1 - i].omega * tau);
        fresh[i] = true;
        fresh[1 - i] = false;
        t += tau;
        ++r.steps;

        // The state is computed only where it is read (point_at is most of the cost of a return).
        double y[4];
        if (ev == Ev::Section) {
            ++work_.section_searches;
            current(y);
            stop(FlowStatus::Ok, y);
            break;
        }
        if (ev == Ev::Min1 && w1.meets != Meets::Touch) {  // q1's minimum: arms the section
            armed = true;
            continue;
        }
        ++work_.wall_searches;
        const bool is_right = ev == Ev::Right || ev == Ev::Min1;
        // The other coordinate decides whether the wall is there (the infinite wall: always).
        const double other =
            is_right ? (is_step ? o[1].at(o[1].theta).first - s.qw2 : -1.0) : o[0].at(o[0].theta).first - s.qw1;
        auto stop_here = [&](FlowStatus status) {
            current(y);
            stop(status, y);
        };
        const bool has_wall = is_right ? (!is_step || other < 0) : other < 0;
        if (ev == Ev::Min1 || ev == Ev::Min2) {  // touching the wall line: grazing where the wall is
            if (has_wall) {
                stop_here(FlowStatus::Grazing);
                break;
            }
            armed = armed || ev == Ev::Min1;
            continue;
        }
        if (is_step && std::fabs(other) <= opt.corner_tol) {
            stop_here(FlowStatus::Corner);
            break;
        }
        if (!has_wall) {  // crossed the wall's line beside / above the step
            if (is_right && labels) {
                crossed = true;
                ++work_.label_operations;
            }
            continue;
        }
        if (impacts >= opt.max_impacts) {
            stop_here(FlowStatus::ImpactLimit);
            break;
        }
        // Elastic reflection: the oscillator keeps its energy, its angle jumps to the wall's
        // outgoing point -theta_w (the post-impact state sits on the wall exactly, as in trace()).
        ++impacts;
        if (dense) {
            current(y);
            double yo[4] = {y[0], y[1], y[2], y[3]};
            yo[is_right ? 0 : 2] = is_right ? s.qw1 : s.qw2;
            yo[is_right ? 1 : 3] = -y[is_right ? 1 : 3];
            dense->push(dense->offset + t, y, TrajectoryPoint::ImpactIn);
            dense->push(dense->offset + t, yo, TrajectoryPoint::ImpactOut);
        }
        if (is_right) {
            o[0].theta = wrap_angle(-w1.angle);
            armed = true;
        } else {
            o[1].theta = wrap_angle(-w2.angle);
        }
        if (labels) {
            r.itinerary += is_right ? 'R' : '1';
            ++work_.label_operations;
        }
    }
    double y[4] = {0, 0, 0, 0};
    if (!done) current(y);
    finish(r, y, t, done, crossed, H0);
    return r;
}

}  // namespace hovering::detail
