// The smooth oscillators flow on GSL odeiv2 and its return map to Sigma_h.
//
// Events (section crossing, wall crossings, a wall distance's minimum inside a step): first guess
// on the cubic Hermite interpolant of the accepted step (values and derivatives at both ends),
// then Newton iterations on exact single steps of the stepper itself from the step's start, so the
// event state carries the stepper's accuracy, not the interpolant's.

#include "hovering/flow.hpp"

#include "detail.hpp"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace hovering {

namespace {

using detail::bad;
using detail::fmt;
using detail::kPi;

const gsl_odeiv2_step_type* stepper_type(const std::string& name) {
    if (name == "rk2") return gsl_odeiv2_step_rk2;
    if (name == "rk4") return gsl_odeiv2_step_rk4;
    if (name == "rkf45") return gsl_odeiv2_step_rkf45;
    if (name == "rkck") return gsl_odeiv2_step_rkck;
    if (name == "rk8pd") return gsl_odeiv2_step_rk8pd;
    if (name == "msadams") return gsl_odeiv2_step_msadams;
    bad("stepper must be one of rk2, rk4, rkf45, rkck, rk8pd (explicit one-step methods) or msadams "
        "(variable-order Adams multistep); the implicit steppers need a Jacobian the flow does not "
        "provide; got '" + name + "'");
}

// x^n for a small integer n >= 0 by repeated squaring: exact for n <= 2 and, unlike std::pow,
// cheap enough for the integrator's inner loop.
double ipow(double x, int n) {
    double r = 1.0;
    while (n > 0) {
        if (n & 1) r *= x;
        x *= x;
        n >>= 1;
    }
    return r;
}

// The vector field with the common potentials and the bilinear coupling inlined, one
// instantiation per (V1 kind, V2 kind, coupling kind), chosen once per integration. The flow's
// inner loop evaluates it 13 times per rk8pd step; through virtual calls it spent ~8 of its ~21 ns
// outside the one tan() it needs. Same arithmetic, in the same order, as Potential::dV and
// FlowSystem::rhs, so both give bit-identical results.
enum class Kind { Harmonic, Tan, Other };
enum class CKind { None, Bilinear, General };

struct Force {
    Kind kind = Kind::Other;
    double a = 0, b = 0;  // Harmonic: a = omega^2; Tan: a = omega^2 / alpha, b = alpha
    const Potential* p = nullptr;
    explicit Force(const Potential* pot) : p(pot) {
        if (const auto* h = dynamic_cast<const Harmonic*>(pot)) {
            kind = Kind::Harmonic;
            a = h->omega() * h->omega();
        } else if (const auto* t = dynamic_cast<const Tan*>(pot)) {
            kind = Kind::Tan;
            a = t->omega() * t->omega() / t->alpha();
            b = t->alpha();
        }
    }
    template <Kind K>
    double eval(double q) const {
        if constexpr (K == Kind::Harmonic) {
            return a * q;
        } else if constexpr (K == Kind::Tan) {
            const double t = std::tan(b * q);
            return a * t * (1 + t * t);
        } else {
            return p->dV(q);
        }
    }
};

struct Field {
    Force f1, f2;
    double eps;
    const Coupling* coupling;
    double bilinear_c = 0;
    CKind ckind = CKind::None;
    void (*fn)(const Field&, const double*, double*) = nullptr;

    template <Kind K1, Kind K2, CKind C>
    static void eval(const Field& F, const double* z, double* dz) {
        dz[0] = z[1];
        dz[1] = -F.f1.eval<K1>(z[0]);
        dz[2] = z[3];
        dz[3] = -F.f2.eval<K2>(z[2]);
        if constexpr (C == CKind::Bilinear) {
            dz[1] -= F.eps * (F.bilinear_c * z[2]);
            dz[3] -= F.eps * (F.bilinear_c * z[0]);
        } else if constexpr (C == CKind::General) {
            const auto g = F.coupling->gradient(z[0], z[2]);
            dz[1] -= F.eps * g[0];
            dz[3] -= F.eps * g[1];
        }
    }
    template <Kind K1, Kind K2>
    void pick_c() {
        fn = ckind == CKind::None ? &eval<K1, K2, CKind::None>
           : ckind == CKind::Bilinear ? &eval<K1, K2, CKind::Bilinear> : &eval<K1, K2, CKind::General>;
    }
    template <Kind K1>
    void pick_2() {
        if (f2.kind == Kind::Harmonic) pick_c<K1, Kind::Harmonic>();
        else if (f2.kind == Kind::Tan) pick_c<K1, Kind::Tan>();
        else pick_c<K1, Kind::Other>();
    }
    explicit Field(const FlowSystem& s) : f1(s.V1.get()), f2(s.V2.get()), eps(s.eps), coupling(&s.coupling) {
        const auto& t = s.coupling.terms;
        if (eps == 0.0) {
            ckind = CKind::None;  // a scene with eps = 0 evaluates no coupling at all
        } else if (t.size() == 1 && t[0][1] == 1 && t[0][2] == 1) {
            ckind = CKind::Bilinear;
            bilinear_c = t[0][0];
        } else {
            ckind = CKind::General;
        }
        if (f1.kind == Kind::Harmonic) pick_2<Kind::Harmonic>();
        else if (f1.kind == Kind::Tan) pick_2<Kind::Tan>();
        else pick_2<Kind::Other>();
    }
    void operator()(const double* z, double* dz) const { fn(*this, z, dz); }
};

int gsl_rhs(double, const double y[], double dydt[], void* params) {
    const auto* F = static_cast<const Field*>(params);
    F->fn(*F, y, dydt);
    return GSL_SUCCESS;
}

// Owns the GSL objects of one integration. For one-step methods the adaptive loop drives GSL's
// stepper and step-size control directly instead of gsl_odeiv2_evolve_apply: the evolve object
// evaluates the field at both ends of every step, while the end derivative of one step is the
// start derivative of the next (13 instead of 14 evaluations per rk8pd step), and the event search
// needs exactly those two. The multistep msadams needs GSL's driver (it reads the control through
// it) and its history cannot restart inside a step, so its events are located on an rk8pd
// extension of the step, subdivided until rk8pd's own error estimate meets the tolerances.
struct Integrator {
    Field field;
    gsl_odeiv2_system sys;
    gsl_odeiv2_step* step = nullptr;
    gsl_odeiv2_control* control = nullptr;
    gsl_odeiv2_driver* driver = nullptr;  // msadams only: owns step, control and evolve
    gsl_odeiv2_step* ext = nullptr;       // msadams only: rk8pd for event extensions
    int ext_sub = 1;                      // substeps of the extension
    double t_ms = 0;                      // msadams: running time (its history is in time)
    double atol, rtol;
    Integrator(const FlowSystem& s, const FlowOptions& o) : field(s), atol(o.atol), rtol(o.rtol) {
        sys = gsl_odeiv2_system{&gsl_rhs, nullptr, 4, &field};
        const gsl_odeiv2_step_type* T = stepper_type(o.stepper);
        if (T == gsl_odeiv2_step_msadams) {
            driver = gsl_odeiv2_driver_alloc_standard_new(&sys, T, 1e-3, o.atol, o.rtol, 1.0, 0.0);
            step = driver->s;
            control = driver->c;
            ext = gsl_odeiv2_step_alloc(gsl_odeiv2_step_rk8pd, 4);
        } else {
            step = gsl_odeiv2_step_alloc(T, 4);
            control = gsl_odeiv2_control_standard_new(o.atol, o.rtol, 1.0, 0.0);
        }
    }
    ~Integrator() {
        if (driver) {
            gsl_odeiv2_driver_free(driver);
            gsl_odeiv2_step_free(ext);
        } else {
            gsl_odeiv2_control_free(control);
            gsl_odeiv2_step_free(step);
        }
    }
    Integrator(const Integrator&) = delete;
    Integrator& operator=(const Integrator&) = delete;
    // Forget the step history (after an impact the flow restarts from a new state).
    void restart() {
        if (driver) gsl_odeiv2_driver_reset(driver);
        else gsl_odeiv2_step_reset(step);
    }
    // One error-controlled step from (y, d = field(y)) with trial length *h (<= hmax): on return y,
    // d hold the new state and its derivative, *h_done the length taken, *h the proposal for the
    // next step. Rejected trials shrink *h and retry from the same state. false: the step size
    // underflowed or the stepper failed (non-finite state).
    bool advance(double* y, double* d, double* h, double hmax, double* h_done, std::int64_t* trials) {
        if (driver) {
            ++*trials;
            const double t0 = t_ms;
            *h = std::min(*h, hmax);
            const int st = gsl_odeiv2_evolve_apply(driver->e, driver->c, driver->s, &sys, &t_ms, t0 + hmax, h, y);
            bool finite = st == GSL_SUCCESS;
            for (int i = 0; i < 4; ++i) finite = finite && std::isfinite(y[i]);
            *h_done = t_ms - t0;
            if (!finite || !(*h_done > 0)) return false;
            field(y, d);
            return true;
        }
        double y0[4] = {y[0], y[1], y[2], y[3]}, err[4], dout[4];
        for (;;) {
            ++*trials;
            const double h0 = std::min(*h, hmax);
            const int st = gsl_odeiv2_step_apply(step, 0.0, h0, y, err, d, dout, &sys);
            bool finite = st == GSL_SUCCESS;
            for (int i = 0; i < 4; ++i) finite = finite && std::isfinite(y[i]) && std::isfinite(err[i]);
            double hn = h0;
            const int adj = finite ? gsl_odeiv2_control_hadjust(control, step, y, err, dout, &hn) : GSL_ODEIV_HADJ_DEC;
            if (adj != GSL_ODEIV_HADJ_DEC) {
                for (int i = 0; i < 4; ++i) d[i] = dout[i];
                *h_done = h0;
                *h = hn;
                return true;
            }
            for (int i = 0; i < 4; ++i) y[i] = y0[i];
            *h = finite ? hn : 0.5 * h0;
            if (!(*h >= 1e-14 * hmax) || !std::isfinite(*h)) return false;  // the tolerance cannot be met
        }
    }
    // Before an event search on [0, h] from y0: for msadams, pick the number of rk8pd substeps
    // whose error estimate meets the tolerances (rk8pd's error ~ h^8: m = ratio^(1/8), rounded up).
    void prepare_extension(const double* y0, const double* d0, double h) {
        if (!driver) return;
        double y[4] = {y0[0], y0[1], y0[2], y0[3]}, err[4], din[4] = {d0[0], d0[1], d0[2], d0[3]};
        gsl_odeiv2_step_reset(ext);
        gsl_odeiv2_step_apply(ext, 0.0, h, y, err, din, nullptr, &sys);
        double ratio = 0;
        for (int i = 0; i < 4; ++i) ratio = std::max(ratio, std::fabs(err[i]) / (atol + rtol * std::fabs(y[i])));
        ext_sub = std::isfinite(ratio) ? std::min(64, std::max(1, int(std::ceil(1.2 * std::pow(ratio, 0.125))))) : 64;
    }
    // The continuous extension of the current step at length dt from y0 (derivative d0): one step
    // of the stepper itself (its own accuracy, no error control), or for msadams ext_sub rk8pd steps.
    void exact(const double* y0, const double* d0, double dt, double* y1) {
        double err[4], dydt_in[4] = {d0[0], d0[1], d0[2], d0[3]};
        double y[4] = {y0[0], y0[1], y0[2], y0[3]};
        if (driver) {
            gsl_odeiv2_step_reset(ext);
            for (int k = 0; k < ext_sub; ++k) {
                if (k > 0) field(y, dydt_in);
                gsl_odeiv2_step_apply(ext, 0.0, dt / ext_sub, y, err, dydt_in, nullptr, &sys);
            }
        } else {
            gsl_odeiv2_step_reset(step);
            gsl_odeiv2_step_apply(step, 0.0, dt, y, err, dydt_in, nullptr, &sys);
        }
        for (int i = 0; i < 4; ++i) y1[i] = y[i];
    }
};

}  // namespace

double Coupling::value(double q1, double q2) const {
    double v = 0;
    for (const auto& t : terms) v += t[0] * ipow(q1, int(t[1])) * ipow(q2, int(t[2]));
    return v;
}

std::array<double, 2> Coupling::gradient(double q1, double q2) const {
    double g1 = 0, g2 = 0;
    for (const auto& t : terms) {
        if (t[1] > 0) g1 += t[0] * t[1] * ipow(q1, int(t[1]) - 1) * ipow(q2, int(t[2]));
        if (t[2] > 0) g2 += t[0] * t[2] * ipow(q1, int(t[1])) * ipow(q2, int(t[2]) - 1);
    }
    return {g1, g2};
}

void FlowSystem::validate() const {
    if (!V1 || !V2) bad("the system needs two potentials V1 and V2");
    if (!std::isfinite(eps)) bad("eps must be finite, got " + fmt(eps));
    for (const auto& t : coupling.terms) {
        if (!std::isfinite(t[0])) bad("coupling coefficients must be finite, got " + fmt(t[0]));
        for (int k = 1; k < 3; ++k)
            if (!(t[k] >= 0 && t[k] == std::floor(t[k]) && t[k] <= 20))
                bad("coupling exponents must be integers in [0, 20], got " + fmt(t[k]));
    }
    if (!(qw1 < 0 && std::fabs(qw1) < V1->q_limit())) bad("qw1 must be < 0 and inside the well of V1, got " + fmt(qw1));
    if (!(qw2 < 0 && std::fabs(qw2) < V2->q_limit())) bad("qw2 must be < 0 and inside the well of V2, got " + fmt(qw2));
}

double FlowSystem::energy(const double* z) const {
    double H = 0.5 * z[1] * z[1] + V1->V(z[0]) + 0.5 * z[3] * z[3] + V2->V(z[2]);
    if (eps != 0.0) H += eps * coupling.value(z[0], z[2]);
    return H;
}

void FlowSystem::rhs(const double* z, double* dz) const {
    dz[0] = z[1];
    dz[1] = -V1->dV(z[0]);
    dz[2] = z[3];
    dz[3] = -V2->dV(z[2]);
    if (eps != 0.0) {  // a scene with eps = 0 evaluates no coupling at all
        const auto g = coupling.gradient(z[0], z[2]);
        dz[1] -= eps * g[0];
        dz[3] -= eps * g[1];
    }
}

void FlowOptions::validate() const {
    stepper_type(stepper);
    if (!(rtol > 0 && rtol < 1)) bad("rtol must lie in (0, 1), got " + fmt(rtol));
    if (!(atol > 0 && std::isfinite(atol))) bad("atol must be finite and > 0, got " + fmt(atol));
    if (!(event_tol > 0 && std::isfinite(event_tol))) bad("event_tol must be finite and > 0, got " + fmt(event_tol));
    if (max_steps < 1) bad("max_steps must be >= 1, got " + std::to_string(max_steps));
    if (max_impacts < 1 || max_impacts > 1000000) bad("max_impacts must be in [1, 1000000], got " + std::to_string(max_impacts));
    if (!(grazing_tol >= 0 && std::isfinite(grazing_tol))) bad("grazing_tol must be finite and >= 0, got " + fmt(grazing_tol));
    if (!(corner_tol >= 0 && std::isfinite(corner_tol))) bad("corner_tol must be finite and >= 0, got " + fmt(corner_tol));
}

std::array<double, 4> section_point(const FlowSystem& s, double h, double theta, double I) {
    if (!std::isfinite(h)) bad("h must be finite, got " + fmt(h));
    if (!std::isfinite(theta) || std::fabs(theta) > kPi) bad("theta must lie in [-pi, pi], got " + fmt(theta));
    if (!std::isfinite(I) || !(I > 0)) bad("I must be finite and > 0, got " + fmt(I));
    const double e2 = s.V2->energy(I);
    const auto [q2, p2] = s.V2->point_at(theta, e2);
    // p1 = 0: V1(q1) + eps Vc(q1, q2) = h - H2; the root with q1 > 0 (near q1's maximum).
    const double rest = h - e2;
    auto F = [&](double q1) { return s.V1->V(q1) + (s.eps != 0 ? s.eps * s.coupling.value(q1, q2) : 0.0) - rest; };
    if (!(F(0.0) < 0))
        bad("no point of Sigma_h at (theta, I) = (" + fmt(theta) + ", " + fmt(I) + "): h - H2(I) = " + fmt(rest) +
            " leaves no energy for oscillator 1 (h must exceed H2(I) = " + fmt(e2) + ")");
    const double lim = s.V1->q_limit();
    double lo = 0, hi = std::isfinite(lim) ? 0.5 * lim : 1.0;
    for (int k = 0; F(hi) < 0; ++k) {
        if (k > 200) bad("no point of Sigma_h: V1 + eps Vc never reaches h - H2(I) = " + fmt(rest));
        lo = hi;
        hi = std::isfinite(lim) ? lim - 0.5 * (lim - hi) : 2 * hi;
    }
    // Newton on F (F' = V1' + eps dVc/dq1 > 0 on the bracket's right part), kept inside the
    // bracket by bisection: ~5 iterations instead of ~55 bisections (1.6 us per point before).
    auto dF = [&](double q1) { return s.V1->dV(q1) + (s.eps != 0 ? s.eps * s.coupling.gradient(q1, q2)[0] : 0.0); };
    double q = 0.5 * (lo + hi);
    for (int it = 0; it < 200 && hi - lo > 1e-16 * hi; ++it) {
        const double f = F(q);
        if (f == 0) {
            lo = hi = q;
            break;
        }
        (f < 0 ? lo : hi) = q;
        const double d = dF(q);
        double qn = d > 0 ? q - f / d : 0.5 * (lo + hi);
        if (!(qn > lo && qn < hi)) qn = 0.5 * (lo + hi);
        if (std::fabs(qn - q) <= 1e-16 * std::fabs(q)) {
            q = qn;
            break;
        }
        q = qn;
    }
    std::array<double, 4> z{q, 0.0, q2, p2};
    double dz[4];
    s.rhs(z.data(), dz);
    if (!(dz[1] < 0))
        bad("the point of Sigma_h at (theta, I) = (" + fmt(theta) + ", " + fmt(I) + ") has dp1/dt = " + fmt(dz[1]) +
            " >= 0 (Sigma_h needs dp1/dt < 0)");
    return z;
}

std::array<double, 2> section_coordinates(const FlowSystem& s, const double* z) {
    const double e2 = 0.5 * z[3] * z[3] + s.V2->V(z[2]);
    double th = s.V2->angle_of_point(z[2], z[3], e2);
    if (th >= kPi) th -= 2 * kPi;  // [-pi, pi)
    return {th, s.V2->action(e2)};
}

namespace {

// Root of y[idx](tau) - off on [0, hi] (values of opposite signs), where y(tau) is one step of
// the stepper of length tau from y0: a continuous extension of the accepted step with the
// stepper's own accuracy. The first guess is the root of the cubic Hermite interpolant through
// y0, y1 = y(hi) and their derivatives d0, d1; Newton's method on exact steps (d/dtau y[idx] is
// rhs[idx] of the stepped state, to the stepper's accuracy) then converges in ~2 steps. The last
// correction delta (|delta| <= sqrt(time_tol)) moves the state along its derivative, leaving an
// error ~ delta^2 |z''| / 2 ~ time_tol |z''| / 2.
double locate(Integrator& in, const double* y0, const double* d0, const double* y1, const double* d1, int idx,
              double off, double hi, double time_tol, double* yout) {
    const double f0 = y0[idx] - off, f1 = y1[idx] - off;
    if (f0 == 0) {
        for (int i = 0; i < 4; ++i) yout[i] = y0[i];
        return 0.0;
    }
    if (f1 == 0) {
        for (int i = 0; i < 4; ++i) yout[i] = y1[i];
        return hi;
    }
    const double guess = detail::hermite_root(f0, d0[idx], f1, d1[idx], hi);
    in.prepare_extension(y0, d0, hi);
    double dy[4];
    auto fdf = [&](double tau, double* f, double* df) {
        in.exact(y0, d0, tau, yout);
        in.field(yout, dy);
        *f = yout[idx] - off;
        *df = dy[idx];
    };
    double delta = 0;
    double tau = detail::newton_bracketed(fdf, 0.0, f0 > 0, hi, guess, std::sqrt(time_tol), &delta);
    if (delta != 0 && tau + delta >= 0 && tau + delta <= hi && std::fabs(delta) <= std::sqrt(time_tol)) {
        tau += delta;
        for (int i = 0; i < 4; ++i) yout[i] += delta * dy[i];
    }
    return tau;
}

enum class Ev { Section, Right, Upper, GrazeRight, GrazeUpper };

struct Candidate {
    double tau;
    Ev kind;
    double y[4];
};

}  // namespace

ReturnResult return_map(const FlowSystem& s, const std::array<double, 4>& z0, const FlowOptions& opt) {
    detail::gsl_quiet();
    opt.validate();
    s.validate();
    Integrator in(s, opt);
    ReturnResult r;
    const double H0 = s.energy(z0.data());
    double y[4] = {z0[0], z0[1], z0[2], z0[3]}, t = 0;
    // Step bound: a fraction of the shorter oscillator period, so one step never holds both a
    // minimum and a maximum of q1 or q2 (two sign changes of p would cancel); 1/8 leaves a factor 4
    // for the O(eps) period shifts of the coupled flow.
    const double T1 = s.V1->period(std::max(1e-12, 0.5 * y[1] * y[1] + s.V1->V(y[0])));
    const double T2 = s.V2->period(std::max(1e-12, 0.5 * y[3] * y[3] + s.V2->V(y[2])));
    const double hmax = 0.125 * std::min(T1, T2);
    double dt = 1e-3 * hmax;
    double dy[4];
    in.field(y, dy);
    bool seen_negative = false, armed = false;
    const bool right = s.geometry != Geometry::None, upper = s.geometry == Geometry::Step;
    const bool is_step = s.geometry == Geometry::Step;
    bool done = false;
    while (!done) {
        if (r.steps >= opt.max_steps) {
            r.status = FlowStatus::StepLimit;
            break;
        }
        double y0[4] = {y[0], y[1], y[2], y[3]}, d0[4] = {dy[0], dy[1], dy[2], dy[3]};
        const double t0 = t;
        double h = 0;
        std::int64_t trials = 0;
        const bool ok = in.advance(y, dy, &dt, hmax, &h, &trials);
        ++r.steps;
        if (!ok) {
            for (int i = 0; i < 4; ++i) y[i] = y0[i];
            r.status = FlowStatus::NonFinite;
            break;
        }
        t = t0 + h;
        const double* d1 = dy;
        // Both end derivatives are known (d0 from the last step, d1 from this one): the event
        // interpolants cost no extra evaluation.

        // Candidate events of this step, each located on exact steps from y0.
        std::vector<Candidate> cands;
        auto wall = [&](int gi, double off, Ev cross, Ev graze) {
            const int pi = gi + 1;
            const double g0 = y0[gi] - off, g1 = y[gi] - off;
            Candidate c{};
            if (g0 > 0 && g1 <= 0) {  // crossing toward the wall
                c.kind = cross;
                c.tau = locate(in, y0, d0, y, d1, gi, off, h, opt.event_tol, c.y);
                cands.push_back(c);
            } else if (g0 > 0 && g1 > 0 && y0[pi] < 0 && y[pi] > 0) {
                // Turning inside the step: the minimum of g (p = 0) may dip through the wall even
                // though g > 0 at both ends (a near-grazing impact a sign test would miss).
                double ym[4], dm[4];
                const double tm = locate(in, y0, d0, y, d1, pi, 0.0, h, opt.event_tol, ym);
                const double gm = ym[gi] - off;
                if (gm < -opt.grazing_tol) {
                    c.kind = cross;
                    in.field(ym, dm);
                    c.tau = locate(in, y0, d0, ym, dm, gi, off, tm, opt.event_tol, c.y);
                    cands.push_back(c);
                } else if (gm <= opt.grazing_tol) {
                    c.kind = graze;
                    c.tau = tm;
                    for (int i = 0; i < 4; ++i) c.y[i] = ym[i];
                    cands.push_back(c);
                }
            }
        };
        if (right) wall(0, s.qw1, Ev::Right, Ev::GrazeRight);
        if (upper) wall(2, s.qw2, Ev::Upper, Ev::GrazeUpper);
        if (armed && y0[1] > 0 && y[1] <= 0) {
            Candidate c{};
            c.kind = Ev::Section;
            c.tau = locate(in, y0, d0, y, d1, 1, 0.0, h, opt.event_tol, c.y);
            cands.push_back(c);
        }
        std::sort(cands.begin(), cands.end(), [](const Candidate& a, const Candidate& b) { return a.tau < b.tau; });

        bool restarted = false;
        for (const Candidate& c : cands) {
            auto stop = [&](FlowStatus status) {
                for (int i = 0; i < 4; ++i) r.z[std::size_t(i)] = c.y[i];
                r.time = t0 + c.tau;
                r.status = status;
                done = true;
            };
            if (c.kind == Ev::Section) {
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
            if (!has_wall) continue;  // crossed the wall's line beside / above the step
            if (c.kind == Ev::GrazeRight || c.kind == Ev::GrazeUpper) {
                stop(FlowStatus::Grazing);
                break;
            }
            if (r.itinerary.size() >= std::size_t(opt.max_impacts)) {
                stop(FlowStatus::ImpactLimit);
                break;
            }
            // Elastic reflection (eq:R1, eq:R2), placed exactly on the wall so that the restart
            // (g = 0, moving away) cannot find the same impact again.
            for (int i = 0; i < 4; ++i) y[i] = c.y[i];
            if (is_right) {
                y[0] = s.qw1;
                y[1] = -y[1];
                r.itinerary += 'R';
            } else {
                y[2] = s.qw2;
                y[3] = -y[3];
                r.itinerary += '1';
            }
            t = t0 + c.tau;
            in.field(y, dy);
            in.restart();
            restarted = true;
            break;
        }
        if (done) break;
        // A return passes q1's minimum (p1 from - to +, or a right-wall reflection) and then its
        // maximum (p1 from + to -). Arming the section only after the minimum makes a start with
        // p1 = +-1e-14 (a point computed on Sigma_h) safe from being taken for its own return.
        seen_negative = seen_negative || y0[1] < 0 || y[1] < 0;
        armed = armed || (seen_negative && y[1] > 0);
        (void)restarted;
    }
    if (!done)
        for (int i = 0; i < 4; ++i) r.z[std::size_t(i)] = y[i];
    r.energy_error = std::fabs(s.energy(r.z.data()) - H0);
    return r;
}

}  // namespace hovering
