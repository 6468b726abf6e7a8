// Points of Sigma_h from section coordinates and back, and the options of the return map.

#include <cmath>
#include <string>

#include "hovering/detail/common.hpp"
#include "hovering/flow/exact.hpp"
#include "hovering/flow/taylor.hpp"
#include "hovering/flow/integrator.hpp"
#include "hovering/flow/return_map.hpp"

namespace hovering {

using detail::bad;
using detail::fmt;
using detail::kInf;
using detail::kNaN;
using detail::kPi;

Stepper parse_stepper(const std::string& name) {
    for (std::size_t i = 0; i < kSteppers.size(); ++i)
        if (name == kSteppers[i]) return static_cast<Stepper>(i);
    bad("stepper must be one of auto (the default: taylor where it applies, else rk8pd), rk8pd, rkck, rkf45, rk4, rk2 (explicit one-step methods), msadams "
        "(variable-order Adams multistep), rk4imp, rk2imp (implicit Gauss-Legendre, symplectic at a fixed "
        "step; with the Jacobian), taylor (Taylor's method, order and step from the tolerances; Harmonic and Tan "
        "potentials) or exact (closed-form flow, where the system has one); GSL's bsimp and msbdf are not "
        "offered (stiff solvers, and this flow is not stiff); got '" +
        name + "'");
}

const char* stepper_name(Stepper s) {
    const auto i = static_cast<std::size_t>(s);
    if (i >= kSteppers.size()) bad("stepper: not a Stepper value (" + std::to_string(int(s)) + ")");
    return kSteppers[i];
}

Stepper resolve_stepper(Stepper st, const FlowSystem& s) {
    if (st != Stepper::Auto) return st;
    return detail::taylor_unsupported(s).empty() ? Stepper::Taylor : Stepper::Rk8pd;
}

FlowOptions FlowOptions::resolved(const FlowSystem& s) const {
    FlowOptions o = *this;
    o.stepper = resolve_stepper(stepper, s);
    return o;
}

void FlowOptions::validate() const {
    stepper_name(stepper);  // an enum value out of range (a cast from elsewhere)
    if (!(rtol > 0 && rtol < 1)) bad("rtol must lie in (0, 1), got " + fmt(rtol));
    if (!(atol > 0 && std::isfinite(atol))) bad("atol must be finite and > 0, got " + fmt(atol));
    if (!(event_tol > 0 && std::isfinite(event_tol))) bad("event_tol must be finite and > 0, got " + fmt(event_tol));
    if (max_steps < 1) bad("max_steps must be >= 1, got " + std::to_string(max_steps));
    if (max_impacts < 1 || max_impacts > 1000000)
        bad("max_impacts must be in [1, 1000000], got " + std::to_string(max_impacts));
    if (!(grazing_tol >= 0 && std::isfinite(grazing_tol)))
        bad("grazing_tol must be finite and >= 0, got " + fmt(grazing_tol));
    if (!(corner_tol >= 0 && std::isfinite(corner_tol)))
        bad("corner_tol must be finite and >= 0, got " + fmt(corner_tol));
    if (verify_steps < -1)
        bad("verify_steps must be -1 (automatic), 0 (never) or >= 1, got " + std::to_string(verify_steps));
}

void FlowOptions::validate(const FlowSystem& s) const {
    validate();
    detail::exact_kind(s, *this);
    if (stepper == Stepper::Taylor) {
        const std::string why = detail::taylor_unsupported(s);
        if (!why.empty()) bad(why);
    }
}

bool try_section_point(const FlowSystem& s, double h, double theta, double I, std::array<double, 4>& z,
                       std::string* why) {
    if (!std::isfinite(h)) bad("h must be finite, got " + fmt(h));
    if (!std::isfinite(theta) || std::fabs(theta) > kPi) bad("theta must lie in [-pi, pi], got " + fmt(theta));
    if (!std::isfinite(I)) bad("I must be finite, got " + fmt(I));
    auto fail = [&](const std::string& msg) {
        if (why) *why = msg;
        return false;
    };
    if (!(I > 0)) return fail("no point of Sigma_h at I = " + fmt(I) + ": actions are > 0");
    const double e2 = s.V2->energy(I);
    // An action so large that H2(I) overflows (I = 1e154) has no point either; point_at would
    // refuse the infinite energy as bad input. (Finite H2 >= h is decided below: eps Vc can be < 0.)
    if (!std::isfinite(e2))
        return fail("no point of Sigma_h at (theta, I) = (" + fmt(theta) + ", " + fmt(I) + "): H2(I) = " + fmt(e2) +
                    " >= h = " + fmt(h) + " leaves no energy for oscillator 1");
    const auto [q2, p2] = s.V2->point_at(theta, e2);
    // p1 = 0: V1(q1) + eps Vc(q1, q2) = h - H2; the root with q1 > 0 (near q1's maximum).
    const double rest = h - e2;
    auto F = [&](double q1) { return s.V1->V(q1) + (s.eps != 0 ? s.eps * s.coupling.value(q1, q2) : 0.0) - rest; };
    const double lim = s.V1->q_limit();
    double lo = 0, hi = std::isfinite(lim) ? 0.5 * lim : 1.0;
    if (!(F(0.0) < 0)) {
        // H2 >= h can still leave a maximum of q1 > 0 where eps Vc < 0 (strong coupling): F dips
        // below 0 and rises through it again, at Sigma_h's point (F' > 0 there: dp1/dt < 0). The
        // last rise through 0 on a grid of (0, B], B where F is positive and past V1's growth.
        if (s.eps == 0 || !(rest > -1e300))
            return fail("no point of Sigma_h at (theta, I) = (" + fmt(theta) + ", " + fmt(I) + "): h - H2(I) = " +
                        fmt(rest) + " leaves no energy for oscillator 1 (h must exceed H2(I) = " + fmt(e2) + ")");
        double B = hi;
        for (int k = 0; k < 60 && !(F(B) > 0 && s.V1->V(B) > 2 * std::fabs(rest) + 1); ++k)
            B = std::isfinite(lim) ? lim - 0.5 * (lim - B) : 2 * B;
        constexpr int kGrid = 256;
        int last = -1;
        double prev = F(0.0);
        for (int k = 1; k <= kGrid; ++k) {
            const double f = F(B * k / kGrid);
            if (prev < 0 && f >= 0) last = k;
            prev = f;
        }
        if (last < 0)
            return fail("no point of Sigma_h at (theta, I) = (" + fmt(theta) + ", " + fmt(I) + "): h - H2(I) = " +
                        fmt(rest) + " leaves no energy for oscillator 1 (h must exceed H2(I) = " + fmt(e2) +
                        ", and V1 + eps Vc stays above h - H2 for q1 > 0)");
        lo = B * (last - 1) / kGrid;
        hi = B * last / kGrid;
    }
    for (int k = 0; F(hi) < 0; ++k) {
        if (k > 200) return fail("no point of Sigma_h: V1 + eps Vc never reaches h - H2(I) = " + fmt(rest));
        lo = hi;
        hi = std::isfinite(lim) ? lim - 0.5 * (lim - hi) : 2 * hi;
    }
    // Newton on F (F' = V1' + eps dVc/dq1 > 0 on the bracket's right part), kept inside the
    // bracket by bisection: ~5 iterations instead of ~55 bisections (1.6 us per point before).
    // F and F' at once: V_dV shares their transcendental (one tan per iteration for Tan, not two).
    auto FdF = [&](double q1) {
        const std::array<double, 2> v = s.V1->V_dV(q1);
        if (s.eps == 0) return std::array<double, 2>{v[0] - rest, v[1]};
        return std::array<double, 2>{v[0] + s.eps * s.coupling.value(q1, q2) - rest,
                                     v[1] + s.eps * s.coupling.gradient(q1, q2)[0]};
    };
    // Started from V1's own turning point at h - H2 where it has a closed form (the coupling moves
    // the root by O(eps)), a function of (theta, I) alone, so every caller gets the same bits.
    double q = 0.5 * (lo + hi);
    if (const double g = rest > 0 ? s.V1->q_max_estimate(rest) : kNaN; g > lo && g < hi) q = g;
    for (int it = 0; it < 200 && hi - lo > 1e-16 * hi; ++it) {
        const auto [f, d] = FdF(q);
        if (f == 0) {
            lo = hi = q;
            break;
        }
        (f < 0 ? lo : hi) = q;
        const double qn = d > 0 ? q - f / d : kNaN;
        // Converged: Newton's correction is within two ulps (F's rounding). Tested before the
        // bracket, which q itself has just become an end of: a correction that rounds to q or its
        // neighbour is "outside", and bisection then crept from the other end to q a bit per
        // iteration (20-55 iterations in an eighth of the calls, 4-6 in the rest).
        if (std::fabs(qn - q) <= 4.5e-16 * std::fabs(q)) {
            q = qn;
            break;
        }
        const double next = qn > lo && qn < hi ? qn : 0.5 * (lo + hi);
        if (next == q) break;  // the bracket's ends are neighbours: q is the root to an ulp
        q = next;
    }
    const std::array<double, 4> p{q, 0.0, q2, p2};
    double dz[4];
    s.rhs(p.data(), dz);
    if (!(dz[1] < 0))
        return fail("the point of Sigma_h at (theta, I) = (" + fmt(theta) + ", " + fmt(I) +
                    ") has dp1/dt = " + fmt(dz[1]) + " >= 0 (Sigma_h needs dp1/dt < 0)");
    z = p;
    return true;
}

std::array<double, 4> section_point(const FlowSystem& s, double h, double theta, double I) {
    std::array<double, 4> z{};
    std::string why;
    if (!try_section_point(s, h, theta, I, z, &why)) bad(why);
    return z;
}

namespace {

// section_coordinates of a state with H2 = e2 <= 0 (or NaN), out of line: the hot path stays as
// small as it was.
[[noreturn]] void negative_h2(const double* z, double e2) {
    bad("section_coordinates: H2 = p2^2/2 + V2(q2) = " + fmt(e2) + " at (q2, p2) = (" + fmt(z[2]) + ", " + fmt(z[3]) +
        ") must be >= 0 (V2 is a single well with minimum V2(0) = 0; allowed: finite states with V2(q2) >= 0)");
}

}  // namespace

std::array<double, 2> section_coordinates(const FlowSystem& s, const double* z) {
    const double e2 = 0.5 * z[3] * z[3] + s.V2->V(z[2]);
    if (!(e2 > 0)) {
        // H2 = 0: oscillator 2 rests at the bottom of its well (q2 = p2 = 0), the centre of the
        // polar-like (theta, I), where I = 0 and the angle is undefined: theta = 0 by convention.
        // Not an error, because the callers meet it legitimately: the return map's images and the
        // flow map's steps (an orbit can hand all its energy to oscillator 1, as the starts
        // I -> 0 do), and Section.coordinates of any state of the phase space.
        if (e2 == 0) return {0.0, 0.0};
        negative_h2(z, e2);
    }
    // A finite state whose H2 overflows (the last state of an orbit that ran away, NON_FINITE) has
    // no action in double precision: no coordinates, as for a non-finite state, not an error.
    if (e2 == kInf) return {kNaN, kNaN};
    double th = s.V2->angle_on_level(z[2], z[3], e2);
    if (th >= kPi) th -= 2 * kPi;  // [-pi, pi)
    return {th, s.V2->action(e2)};
}

}  // namespace hovering
