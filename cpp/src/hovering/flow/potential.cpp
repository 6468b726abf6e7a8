// Potentials and their action-angle variables. Generic quantities use GSL: QAWS
// quadrature (its Chebyshev moments absorb the (q - a)^(-1/2) (b - q)^(-1/2) endpoint behaviour,
// so the smooth remainder is integrated to ~1e-13; near the turning points h - V comes from V',
// Level::slope) and Brent root finding.

#include "hovering/flow/potential.hpp"

#include "hovering/detail/common.hpp"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace hovering {

namespace {

using detail::bad;
using detail::fmt;
using detail::gsl_quiet;
using detail::kInf;
using detail::kPi;

double call(double x, void* p) {
    return (*static_cast<const std::function<double(double)>*>(p))(x);
}

// pi - kPi: the angle theta (a double) lies (kPi - theta) + kPiLow before pi, which matters
// relatively for p near theta = +-pi (the closed forms' sin(theta) sees it too).
constexpr double kPiLow = 1.2246467991473532e-16;

// A level h of a potential: its turning points a < 0 < b and the energy deficit h - V near them.
struct Level {
    const Potential& pot;
    double h, a, b;

    Level(const Potential& p, double level, const char* who) : pot(p), h(level) {
        const auto tp = p.turning_points(level);
        a = tp.first;
        b = tp.second;
        // Everything below takes h - V = 0 at the turning points. Above the largest value V takes
        // inside a bounded well (Tan(1.4, 0.7): ~8e30 at the last double before its wall) the
        // turning point is that last double, where h - V ~ h: the level has hard walls, which no
        // quadrature here resolves. Near a wall V may also jump 3x from one double to the next
        // (the root lies between them): that level is resolved to rounding and passes.
        for (const double e : {a, b}) {
            const double v = p.V(e);
            if (!(v >= 0.5 * h) && !std::isfinite(p.V(std::nextafter(e, e > 0 ? kInf : -kInf))))
                bad(p.name() + "." + who + ": the level h = " + fmt(h) +
                    " lies above the largest value V reaches inside the wall q_limit = " + fmt(p.q_limit()) + " (V(" +
                    fmt(e) + ") = " + fmt(v) +
                    " at the turning point): it has no turning point the "
                    "quadrature can resolve; allowed: h <= " +
                    fmt(2 * v) + ", or a closed-form potential");
        }
    }

    double end(int side) const { return side > 0 ? b : a; }

    // (h - V(q)) / |q - end| at the point q = end - side d, d >= 0, inside the turning point `end`
    // (side +1: b, -1: a), i.e. the mean of |V'| over [q, end]. h - V(q) loses the digits V shares
    // with h as q nears the turning point (relative error ~eps h / (h - V), 1e-7 at 1e-9 of the
    // width, enough to stop QAWS converging): below 1e-2 h the mean is instead 5-point
    // Gauss-Legendre on V', exact for V' of degree 9; there d <~ 1e-2 h / |V'(end)|, a length on
    // which V' changes little, so its error is ~(d / l)^10 for V' varying on the scale l.
    // At d = 0 it is |V'(end)|, the limit the quadratures need at the turning points.
    double slope(double d, int side) const {
        const double e = end(side), q = e - side * d;
        const double dq = side * (e - q);  // the distance q really has (q is rounded)
        if (dq > 0) {
            const double D = h - pot.V(q);
            if (D >= 1e-2 * h) return D / dq;
        }
        static constexpr double x[5] = {0.0, 0.5384693101056831, -0.5384693101056831, 0.9061798459386640,
                                        -0.9061798459386640};
        static constexpr double w[5] = {0.5688888888888889, 0.4786286704993665, 0.4786286704993665, 0.2369268850561891,
                                        0.2369268850561891};
        double s = 0;
        for (int i = 0; i < 5; ++i) s += w[i] * pot.dV(e - side * (0.5 * d * (1 + x[i])));
        return 0.5 * side * s;
    }

    // Smooth factor of the time to the turning point: dt/du = u^(-1/2) g(u) at distance u from it.
    double g(double u, int side) const { return 1 / std::sqrt(2 * slope(u, side)); }

    // Below this distance from a turning point the time to it is the local expansion of time():
    // 1e-6 of the length on which V' changes (at most the width, h / |V'| at the end; both are
    // that scale for power-law and Tan-like walls), where the expansion's relative error
    // (4/45) (d / l)^2 ~ 1e-13 times an angle of ~1e-3 is ~1e-16 rad.
    double window(int side) const {
        const double e = end(side);
        return 1e-6 * std::min(b - a, h / std::fabs(pot.dV(e)));
    }

    // int_lo^hi (u - lo)^al (hi - u)^be f(u) du by GSL QAWS (epsrel 1e-12). A failure is bad
    // input, not a bug: V has a plateau (V = h on an interval), or the level is too small for the
    // well's width to be resolved.
    double qaws(const std::function<double(double)>& f, double lo, double hi, double al, double be,
                const char* who) const;

    // Time from the point at distance d inside the turning point `end` to it:
    // int_0^d u^(-1/2) g(u) du. Within window(side) this is 2 sqrt(d) g(d / 3): with
    // g = g0 + g1 u + g2 u^2 the integral is 2 sqrt(d) (g0 + g1 d / 3 + g2 d^2 / 5), the expansion
    // 2 sqrt(d) (g0 + g1 d / 3 + g2 d^2 / 9). Beyond it QAWS in the local variable u, which keeps
    // the interval's rounding off a short interval next to a turning point.
    double time(double d, int side, double win, const char* who) const {
        if (!(d > 0)) return 0;
        if (d <= win) return 2 * std::sqrt(d) * g(d / 3, side);
        return qaws([&](double u) { return g(u, side); }, 0.0, d, -0.5, 0.0, who);
    }
};

double Level::qaws(const std::function<double(double)>& f, double lo, double hi, double al, double be,
                   const char* who) const {
    gsl_quiet();
    gsl_integration_qaws_table* t = gsl_integration_qaws_table_alloc(al, be, 0, 0);
    gsl_integration_workspace* w = gsl_integration_workspace_alloc(200);
    gsl_function F{&call, const_cast<std::function<double(double)>*>(&f)};
    double r = 0, err = 0;
    // Relative accuracy only: times and actions scale with 1 / omega and h / omega, and an
    // absolute floor would stop at the first estimate for a stiff well (omega = 1e50).
    const int st = gsl_integration_qaws(&F, lo, hi, t, 0.0, 1e-12, 200, w, &r, &err);
    gsl_integration_workspace_free(w);
    gsl_integration_qaws_table_free(t);
    if (st != GSL_SUCCESS && st != GSL_EROUND && !(err <= 1e-10 * std::fabs(r)))
        bad(pot.name() + "." + who + ": the quadrature over the level h = " + fmt(h) + " did not converge (" +
            gsl_strerror(st) + "); the turning points [" + fmt(a) + ", " + fmt(b) +
            "] are too close to resolve, or V is flat there; allowed: a level the quadrature resolves (a larger h) or "
            "a "
            "closed-form potential");
    return r;
}

// Root of f on [lo, hi] (f(lo), f(hi) of opposite signs) to ~1 ulp.
double brent(const std::function<double(double)>& f, double lo, double hi) {
    return detail::brent(f, lo, hi, 4 * std::numeric_limits<double>::epsilon());
}


constexpr double kEps = std::numeric_limits<double>::epsilon();

// Ridders' extrapolation (Numerical Recipes' dfridr) of central differences of f at x, from the
// step d0 down by 1.4 per level. An entry's error is the table's own estimate (its change from
// its neighbours) plus the evaluation noise of f (`noise`, absolute) carried through the
// differences and the extrapolation weights: with quadratures good to ~1e-13 the noise, not the
// truncation, limits the smallest steps, and the table alone can miss it. The entry with the
// smallest total is returned; the table stops once the diagonal grows (noise took over).
Estimate ridders(const std::function<double(double)>& f, double x, double d0, double noise) {
    constexpr int kN = 12;
    constexpr double kCon = 1.4, kCon2 = kCon * kCon;
    double a[kN][kN], n[kN][kN];
    auto diff = [&](double d, int i) {
        const double xp = x + d, xm = x - d;  // the steps the doubles really have
        a[0][i] = (f(xp) - f(xm)) / (xp - xm);
        n[0][i] = 2 * noise / (xp - xm);
    };
    double d = d0;
    diff(d, 0);
    Estimate best{a[0][0], kInf};
    for (int i = 1; i < kN; ++i) {
        d /= kCon;
        diff(d, i);
        double fac = kCon2;
        for (int j = 1; j <= i; ++j) {
            a[j][i] = (a[j - 1][i] * fac - a[j - 1][i - 1]) / (fac - 1);
            n[j][i] = (n[j - 1][i] * fac + n[j - 1][i - 1]) / (fac - 1);
            fac *= kCon2;
            const double e = std::max(std::fabs(a[j][i] - a[j - 1][i]), std::fabs(a[j][i] - a[j - 1][i - 1])) + n[j][i];
            if (e <= best.error) best = {a[j][i], e};
        }
        if (std::fabs(a[i][i] - a[i - 1][i - 1]) >= 2 * best.error) break;
    }
    return best;
}

}  // namespace

// ------------------------------------------------------------------------------- generic paths

double Potential::q_limit() const {
    return kInf;
}

void Potential::check_energy(double h, const char* who) const {
    if (!std::isfinite(h) || !(h > 0))
        bad(name() + "." + who + ": energy must be finite and > 0 (the minimum is V(0) = 0), got " + fmt(h));
}

double Potential::q_max_estimate(double) const {
    return detail::kNaN;
}

std::pair<double, double> Potential::turning_points(double h) const {
    check_energy(h, "turning_points");
    // Subnormal levels: h - V(q) has too few significant bits for any quadrature.
    if (h < 1e-300) bad(name() + ": energy must be >= 1e-300 on the quadrature path (no closed form), got " + fmt(h));
    const double lim = q_limit();
    auto side = [&](double sgn) {
        // Bracket V = h on one side: V(inner) < h <= V(outer) (or V(outer) not finite), expanding
        // outward by doubling up to the largest double, or halving the distance to the wall of a
        // bounded well until it reaches q_limit itself (~53 steps).
        double inner = 0, outer = std::isfinite(lim) ? 0.5 * lim : 1.0;
        double vo = V(sgn * outer);  // V(outer), kept: each V may be a call into Python
        for (int k = 0; vo < h; ++k) {
            double next = std::isfinite(lim) ? lim - 0.5 * (lim - outer) : 2 * outer;
            if (next == outer) next = lim;  // lim - ulp / 2 rounded (to even) back to outer
            if (k > 2100 || outer == lim || !std::isfinite(next))
                bad(name() + ": V never reaches the energy " + fmt(h) + " (V(" + fmt(sgn * outer) + ") = " + fmt(vo) +
                    (std::isfinite(lim) ? " at the wall q_limit" : "") +
                    "; allowed: a single well whose V rises above every level, to +inf at the wall of a bounded well)");
            inner = outer;
            outer = next;
            vo = V(sgn * outer);
        }
        // For small h, halve toward 0 first: a bracket [x/2, x] lets Brent reach full relative
        // accuracy; [0, 1] around a root 1e-35 exhausted its iterations at a point 1e-31.
        while (inner == 0 && outer > 1e-300) {
            const double v = V(sgn * 0.5 * outer);
            if (!(v >= h)) break;
            outer *= 0.5;
            vo = v;
        }
        if (inner == 0) inner = 0.5 * outer;
        // V(outer) = inf (Tan at its wall, an overflow) would make Brent return garbage: bisect
        // until V(outer) is finite. If the bracket closes to adjacent doubles first, no double has
        // h <= V(q) < inf, and inner is the largest q with V(q) <= h: Tan(1.4, 0.7)'s V reaches
        // only ~8e30 at the last double before its wall, so every h above that has q_max = q_limit
        // to 1 ulp.
        while (!std::isfinite(vo)) {
            const double mid = inner + 0.5 * (outer - inner);
            if (!(mid > inner && mid < outer)) return sgn * inner;
            const double vm = V(sgn * mid);
            if (vm < h) {
                inner = mid;
            } else {
                outer = mid;
                vo = vm;
            }
        }
        // Brent ends within ~4 eps of the root, on either side: step to the largest q with
        // V(q) <= h (a few ulps, 2-3 evaluations), so that h - V >= 0 on the whole level and the
        // answer does not depend on where Brent stopped.
        double x = brent([&](double y) { return V(sgn * y) - h; }, inner, outer);
        for (int k = 0; k < 16 && x > inner && V(sgn * x) > h; ++k) x = std::nextafter(x, 0.0);
        for (int k = 0; k < 16 && x < outer; ++k) {
            const double up = std::nextafter(x, kInf);
            if (!(V(sgn * up) <= h)) break;
            x = up;
        }
        return sgn * x;
    };
    return {side(-1.0), side(1.0)};
}

double Potential::period(double h) const {
    const Level L(*this, h, "period");
    const double a = L.a, b = L.b, mid = 0.5 * (a + b);
    // 2 int dq / sqrt(2(h - V)) = 2 int w(q) r(q) dq, w = ((q-a)(b-q))^-1/2, r = sqrt((q-a)(b-q) / (2(h-V))),
    // h - V written as slope x distance to the nearer turning point (no cancellation there).
    return 2 * L.qaws(
                   [&](double q) {
                       return q >= mid ? std::sqrt((q - a) / (2 * L.slope(b - q, 1)))
                                       : std::sqrt((b - q) / (2 * L.slope(q - a, -1)));
                   },
                   a, b, -0.5, -0.5, "period");
}

double Potential::action(double h) const {
    const Level L(*this, h, "action");
    const double a = L.a, b = L.b, mid = 0.5 * (a + b);
    const auto whole = [&] {
        return L.qaws(
                   [&](double q) {
                       return q >= mid ? std::sqrt(2 * L.slope(b - q, 1) / (q - a))
                                       : std::sqrt(2 * L.slope(q - a, -1) / (b - q));
                   },
                   a, b, 0.5, 0.5, "action") /
               kPi;
    };
    // Near a steep wall p = sqrt(2 (h - V)) climbs from 0 to ~sqrt(2 h) within l = h / |V'| of the
    // turning point; on a high level of a Tan well l is 1e-10 of the width, and one QAWS over the
    // level returned "converged" 8.4e-9 off (Tan(2.6, 0.13) at h = 1.3e20). So each end's layer,
    // 1e3 l wide (p is smooth on the scale l there), is its own QAWS with the end's square root
    // as the weight, and the rest between them, where p is smooth on the scale of the width, a
    // third (without weights). A layer within ~1e6 doubles of its end is not resolved by V's
    // doubles (V jumps from one to the next) and its share of the action is below ~1e-10: there,
    // and where the layers do not converge, the single quadrature is the answer (as before).
    const double la = 1e3 * h / std::fabs(dV(a)), lb = 1e3 * h / std::fabs(dV(b));
    const double ulp = std::nextafter(std::max(-a, b), kInf) - std::max(-a, b);
    if (!(la < 0.25 * (b - a) && lb < 0.25 * (b - a)) || !std::isfinite(la + lb) || !(std::min(la, lb) >= 1e6 * ulp))
        return whole();
    try {
        // In the layers' local distance d from their turning point (exact near it): p = sqrt(2 d slope(d)).
        const double left =
            L.qaws([&](double d) { return std::sqrt(2 * L.slope(d, -1)); }, 0.0, la, 0.5, 0.0, "action");
        const double right =
            L.qaws([&](double d) { return std::sqrt(2 * L.slope(d, 1)); }, 0.0, lb, 0.5, 0.0, "action");
        const double inner = L.qaws(
            [&](double q) {
                return q >= mid ? std::sqrt(2 * L.slope(b - q, 1) * (b - q))
                                : std::sqrt(2 * L.slope(q - a, -1) * (q - a));
            },
            a + la, b - lb, 0.0, 0.0, "action");
        return (left + inner + right) / kPi;
    } catch (const std::invalid_argument&) {
        return whole();
    }
}

double Potential::energy(double I) const {
    if (!std::isfinite(I) || !(I > 0)) bad(name() + ".energy: action must be finite and > 0, got " + fmt(I));
    // Bracket by doubling / halving from h = 1 (action is increasing in h).
    double lo = 1, hi = 1;
    for (int k = 0; action(hi) < I; ++k) {
        if (k > 1000) bad(name() + ".energy: no energy has action " + fmt(I));
        lo = hi;
        hi *= 2;
    }
    for (int k = 0; lo == hi || action(lo) >= I; ++k) {
        if (k > 1000) bad(name() + ".energy: no energy has action " + fmt(I));
        hi = lo;
        lo *= 0.5;
    }
    return brent([&](double h) { return action(h) - I; }, lo, hi);
}

double Potential::frequency(double h) const {
    return 2 * kPi / period(h);
}

double Potential::angle_of(double q, double h) const {
    const Level L(*this, h, "angle_of");
    const double a = L.a, b = L.b;
    // The turning points are roots known to a few ulps: a q that far beyond one (a closed form's
    // turning point, rounding elsewhere) is on the level, at its end.
    const double tol = 8 * std::numeric_limits<double>::epsilon() * std::max(-a, b);
    if (!(q >= a - tol && q <= b + tol))
        bad(name() + ".angle_of: q = " + fmt(q) + " is outside the level h = " + fmt(h) + ", [" + fmt(a) + ", " +
            fmt(b) + "]");
    q = std::min(std::max(q, a), b);
    const double w = frequency(h);
    // From the nearer turning point (exact distance: Sterbenz), where the time has its 1/sqrt.
    if (q >= 0.5 * (a + b)) return w * L.time(b - q, 1, L.window(1), "angle_of");
    return (kPi - w * L.time(q - a, -1, L.window(-1), "angle_of")) + kPiLow;
}

std::pair<double, double> Potential::point_at(double theta, double h) const {
    if (!std::isfinite(theta) || std::fabs(theta) > kPi)
        bad(name() + ".point_at: theta must lie in [-pi, pi], got " + fmt(theta));
    const Level L(*this, h, "point_at");
    const double th = std::fabs(theta), w = frequency(h), sg = theta > 0 ? -1.0 : 1.0;
    // The right half of the level (q >= its midpoint, distance dm from b) has the angles up to
    // th_mid; beyond, the time from a is (pi - th) / omega. Either way: the distance d from the
    // turning point at which time() equals the target t.
    const double dm = 0.5 * (L.b - L.a);
    const double th_mid = w * L.time(dm, 1, L.window(1), "point_at");
    const int side = th <= th_mid ? 1 : -1;
    const double t = (side > 0 ? th : (kPi - th) + kPiLow) / w, win = L.window(side);
    // The halves' times add up to T / 2 = pi / omega (to the quadratures' ~1e-14).
    const double t_win = L.time(win, side, win, "point_at"), t_mid = (side > 0 ? th_mid : (kPi - th_mid) + kPiLow) / w;
    double d;
    if (!(t > 0)) {
        d = 0;
    } else if (t <= t_win) {
        // Invert the local expansion t = 2 sqrt(d) g(d / 3), i.e. d = t^2 slope(d / 3) / 2, by
        // fixed-point iteration: slope changes by ~d / l relative across the window (<= 1e-6), so
        // each step gains 6 digits.
        d = 0.5 * t * t * L.slope(0.0, side);
        for (int k = 0; k < 3; ++k) d = 0.5 * t * t * L.slope(d / 3, side);
    } else if (t >= t_mid) {
        d = dm;  // the two sides' times meet at the midpoint to ~1e-13
    } else {
        // Newton in r = sqrt(d), where the time is nearly linear (dt/dr = 2 g(r^2)), bracketed by
        // bisection, from linear interpolation. It stops at 1e-14 relative in r: the times are
        // quadratures good to ~1e-14, below which the corrections are their noise.
        double lo = std::sqrt(win), hi = std::sqrt(dm);
        double r = lo + (hi - lo) * (t - t_win) / (t_mid - t_win);
        for (int it = 0; it < 60; ++it) {
            const double f = L.time(r * r, side, win, "point_at") - t;
            if (f == 0) break;
            (f < 0 ? lo : hi) = r;
            double rn = r - f / (2 * L.g(r * r, side));
            if (!(rn > lo && rn < hi)) rn = 0.5 * (lo + hi);
            const bool done = std::fabs(rn - r) <= 1e-14 * r || hi - lo <= 1e-14 * hi;
            r = rn;
            if (done) break;
        }
        d = r * r;
    }
    // p from the deficit h - V = slope x d, exact near the turning point where sqrt(2 (h - V(q)))
    // would be rounding noise; d, not the distance of the rounded q: p ~ sqrt(d) would inherit
    // the rounding of q relative to d (1 at theta = 1e-8).
    return {L.end(side) - side * d, sg * std::sqrt(2 * d * L.slope(d, side))};
}

double Potential::angle_of_point(double q, double p, double h) const {
    check_energy(h, "angle_of_point");
    if (!std::isfinite(q) || !std::isfinite(p))
        bad(name() + ".angle_of_point: q and p must be finite, got q = " + fmt(q) + ", p = " + fmt(p));
    // 1e-8 relative: the energy drift of an accurate orbit passes, a point of another level does not.
    const double e = 0.5 * p * p + V(q);
    if (!(std::fabs(e - h) <= 1e-8 * h))
        bad(name() + ".angle_of_point: (q, p) = (" + fmt(q) + ", " + fmt(p) + ") has energy p^2/2 + V(q) = " + fmt(e) +
            ", not on the level h = " + fmt(h) + " (allowed: within 1e-8 h)");
    return angle_on_level(q, p, h);
}

double Potential::angle_on_level(double q, double p, double h) const {
    const auto [a, b] = turning_points(h);
    const double th = angle_of(std::min(std::max(q, a), b), h);
    return p > 0 ? -th : th;
}

// 1e-12: the tolerance every generic quadrature asks of QAWS (measured: ~3e-15 on Harmonic and
// Tan levels 1e-10 .. 1e20; the tolerance is what is promised for any V).
double Potential::relative_accuracy() const {
    return 1e-12;
}

Estimate Potential::period_slope(double h) const {
    check_energy(h, "period_slope");
    // T(h) of a single well is smooth on the scale h (power-law wells: T ~ h^k): steps from h / 4
    // keep h - d > 0 and cover the scale.
    const double T = period(h);
    return ridders([&](double e) { return period(e); }, h, 0.25 * h, relative_accuracy() * T);
}

std::array<double, 2> Potential::point_slope(double theta, double h) const {
    check_energy(h, "point_slope");
    // point_at is smooth in h on the scale h (the level's size), its noise the quadratures'
    // relative accuracy times the level's extent.
    const auto tp = turning_points(h);
    const double extent = std::max(-tp.first, tp.second), w = frequency(h);
    const double nq = relative_accuracy() * extent, np = relative_accuracy() * extent * w;
    return {ridders([&](double e) { return point_at(theta, e).first; }, h, 0.25 * h, nq).value,
            ridders([&](double e) { return point_at(theta, e).second; }, h, 0.25 * h, np).value};
}

Estimate Potential::angle_slope(double q, double h) const {
    check_energy(h, "angle_slope");
    const double D = h - V(q);
    if (!std::isfinite(q) || !(D > 0))
        bad(name() + ".angle_slope: q = " + fmt(q) + " must lie strictly inside the level h = " + fmt(h) +
            " (V(q) < h), got V(q) = " + fmt(V(q)));
    // The angle at fixed q is sqrt(h - V(q)) near the turning point: smooth on the scale min(h, D).
    // Its noise: the quadratures' plus the turning point's rounding (~4 ulps) times
    // d theta / dq = omega / |p|, |p| at least sqrt(2 * 3D / 4) over the steps.
    const auto tp = turning_points(h);
    const double w = frequency(h);
    const double noise = relative_accuracy() * kPi + 4 * kEps * std::max(-tp.first, tp.second) * w / std::sqrt(1.5 * D);
    return ridders([&](double e) { return angle_of(q, e); }, h, 0.25 * std::min(h, D), noise);
}

// ------------------------------------------------------------------------------- closed forms

Harmonic::Harmonic(double omega) : omega_(omega) {
    check_parameter(kInfo.cls, kInfo.params[0], omega);
}
double Harmonic::V(double q) const {
    return 0.5 * omega_ * omega_ * q * q;
}
double Harmonic::dV(double q) const {
    return omega_ * omega_ * q;
}
std::string Harmonic::name() const {
    return "Harmonic(omega=" + fmt(omega_) + ")";
}
std::pair<double, double> Harmonic::turning_points(double h) const {
    check_energy(h, "turning_points");
    const double A = std::sqrt(2 * h) / omega_;
    return {-A, A};
}
double Harmonic::q_max_estimate(double h) const {
    return std::sqrt(2 * h) / omega_;
}
double Harmonic::period(double h) const {
    check_energy(h, "period");
    return 2 * kPi / omega_;
}
double Harmonic::action(double h) const {
    check_energy(h, "action");
    return h / omega_;
}
double Harmonic::energy(double I) const {
    if (!std::isfinite(I) || !(I > 0)) bad(name() + ".energy: action must be finite and > 0, got " + fmt(I));
    return omega_ * I;
}
double Harmonic::angle_of(double q, double h) const {
    const double A = turning_points(h).second;
    if (!(std::fabs(q) <= A)) bad(name() + ".angle_of: q = " + fmt(q) + " is outside the level h = " + fmt(h));
    return std::acos(q / A);
}

std::pair<double, double> Harmonic::point_at(double theta, double h) const {
    if (!std::isfinite(theta) || std::fabs(theta) > kPi)
        bad(name() + ".point_at: theta must lie in [-pi, pi], got " + fmt(theta));
    const double A = turning_points(h).second;
    return {A * std::cos(theta), -A * omega_ * std::sin(theta)};
}

std::array<double, 2> Harmonic::point_slope(double theta, double h) const {
    const auto [q, p] = point_at(theta, h);  // A (cos theta, -omega sin theta), A = sqrt(2 h) / omega
    return {q / (2 * h), p / (2 * h)};
}

double Harmonic::angle_on_level(double q, double p, double) const {
    return std::atan2(-p / omega_, q);  // (q, p) = A (cos theta, -omega sin theta): no arccos near +-1
}

double Harmonic::relative_accuracy() const {
    return 4 * kEps;
}

Estimate Harmonic::period_slope(double h) const {
    check_energy(h, "period_slope");
    return {0.0, 0.0};
}

Estimate Harmonic::angle_slope(double q, double h) const {
    check_energy(h, "angle_slope");
    const double v = V(q), D = h - v;
    if (!std::isfinite(q) || !(D > 0))
        bad(name() + ".angle_slope: q = " + fmt(q) + " must lie strictly inside the level h = " + fmt(h) +
            " (V(q) < h)");
    // theta = acos(q / A), A = sqrt(2 h) / omega, sin(theta) = sqrt(D / h). The deficit D = h - V
    // carries the rounding of V (4 ulps) relative to D: the slope's sqrt halves it.
    const double s = q * omega_ / (2 * std::sqrt(2.0) * h * std::sqrt(D));
    return {s, std::fabs(s) * (8 * kEps + kEps * (D + 4 * v) / (2 * D))};
}

Tan::Tan(double omega, double alpha) : omega_(omega), alpha_(alpha) {
    check_parameter(kInfo.cls, kInfo.params[0], omega);
    check_parameter(kInfo.cls, kInfo.params[1], alpha);
}
double Tan::V(double q) const {
    // tan is periodic: without this, a q beyond the wall would land in another copy of the well.
    if (!(std::fabs(q) < q_limit())) return std::isnan(q) ? q : kInf;
    const double t = std::tan(alpha_ * q);
    return 0.5 * omega_ * omega_ / (alpha_ * alpha_) * t * t;
}
double Tan::dV(double q) const {
    // tan / cos^2 = tan (1 + tan^2): one transcendental call per force evaluation, the flow's
    // dominant cost.
    if (!(std::fabs(q) < q_limit())) return std::isnan(q) ? q : std::copysign(kInf, q);
    const double t = std::tan(alpha_ * q);
    return omega_ * omega_ / alpha_ * t * (1 + t * t);
}
std::array<double, 2> Tan::V_dV(double q) const {
    // The section point's Newton iteration needs both at each q: tan once instead of twice.
    if (!(std::fabs(q) < q_limit())) return {V(q), dV(q)};
    const double t = std::tan(alpha_ * q);
    return {0.5 * omega_ * omega_ / (alpha_ * alpha_) * t * t, omega_ * omega_ / alpha_ * t * (1 + t * t)};
}
std::string Tan::name() const {
    return "Tan(omega=" + fmt(omega_) + ", alpha=" + fmt(alpha_) + ")";
}
double Tan::q_limit() const {
    return 0.5 * kPi / alpha_;
}
std::pair<double, double> Tan::turning_points(double h) const {
    check_energy(h, "turning_points");
    const double b = std::atan(alpha_ * std::sqrt(2 * h) / omega_) / alpha_;
    return {-b, b};
}
double Tan::q_max_estimate(double h) const {
    return std::atan(alpha_ * std::sqrt(2 * h) / omega_) / alpha_;
}
double Tan::period(double h) const {
    check_energy(h, "period");
    return 2 * kPi / std::sqrt(omega_ * omega_ + 2 * alpha_ * alpha_ * h);
}
double Tan::action(double h) const {
    check_energy(h, "action");
    // Inverse of H = omega I + alpha^2 I^2 / 2, written without cancellation for small h.
    return 2 * h / (omega_ + std::sqrt(omega_ * omega_ + 2 * alpha_ * alpha_ * h));
}
double Tan::energy(double I) const {
    if (!std::isfinite(I) || !(I > 0)) bad(name() + ".energy: action must be finite and > 0, got " + fmt(I));
    return omega_ * I + 0.5 * alpha_ * alpha_ * I * I;
}
double Tan::angle_of(double q, double h) const {
    const auto [a, b] = turning_points(h);
    if (!(q >= a && q <= b)) bad(name() + ".angle_of: q = " + fmt(q) + " is outside the level h = " + fmt(h));
    const double c = std::sqrt(alpha_ * alpha_ + omega_ * omega_ / (2 * h)) * std::sin(alpha_ * q) / alpha_;
    return std::acos(std::max(-1.0, std::min(1.0, c)));
}

std::pair<double, double> Tan::point_at(double theta, double h) const {
    if (!std::isfinite(theta) || std::fabs(theta) > kPi)
        bad(name() + ".point_at: theta must lie in [-pi, pi], got " + fmt(theta));
    check_energy(h, "point_at");
    // q = asin(k cos theta) / alpha and p = omega(h) dq/dtheta: no sqrt(h - V) near the turning
    // points, where it would turn a rounding of V into an O(1e-8) momentum.
    const double k = alpha_ / std::sqrt(alpha_ * alpha_ + omega_ * omega_ / (2 * h));
    const double kc = k * std::cos(theta);
    const double q = std::asin(kc) / alpha_;
    const double w = std::sqrt(omega_ * omega_ + 2 * alpha_ * alpha_ * h);
    const double p = -w * k * std::sin(theta) / (alpha_ * std::sqrt(1 - kc * kc));
    return {q, p};
}

std::array<double, 2> Tan::point_slope(double theta, double h) const {
    check_energy(h, "point_slope");
    // point_at: q = asin(k c) / alpha, p = -W k s / (alpha r), c = cos theta, s = sin theta,
    // k = alpha sqrt(2 h) / W, W = sqrt(omega^2 + 2 alpha^2 h), r = sqrt(1 - k^2 c^2); and
    // dk/dh = alpha omega^2 / (sqrt(2 h) W^3), dW/dh = alpha^2 / W.
    const double c = std::cos(theta), sn = std::sin(theta);
    const double W = std::sqrt(omega_ * omega_ + 2 * alpha_ * alpha_ * h);
    const double k = alpha_ / std::sqrt(alpha_ * alpha_ + omega_ * omega_ / (2 * h));
    const double dk = alpha_ * omega_ * omega_ / (std::sqrt(2 * h) * W * W * W), dW = alpha_ * alpha_ / W;
    const double r = std::sqrt(1 - k * k * c * c);
    const double dq = c * dk / (alpha_ * r);
    const double dp = -sn / alpha_ * ((dW * k + W * dk) / r + W * k * k * c * c * dk / (r * r * r));
    return {dq, dp};
}

double Tan::angle_on_level(double q, double p, double h) const {
    // cos theta = sin(alpha q) / k and sin theta = -p alpha cos(alpha q) / (omega(h) k), k > 0.
    const double w = std::sqrt(omega_ * omega_ + 2 * alpha_ * alpha_ * h);
    return std::atan2(-p * alpha_ * std::cos(alpha_ * q) / w, std::sin(alpha_ * q));
}

double Tan::relative_accuracy() const {
    return 8 * kEps;
}

Estimate Tan::period_slope(double h) const {
    check_energy(h, "period_slope");
    const double W = std::sqrt(omega_ * omega_ + 2 * alpha_ * alpha_ * h);
    const double s = -2 * kPi * alpha_ * alpha_ / (W * W * W);
    return {s, 8 * kEps * std::fabs(s)};
}

Estimate Tan::angle_slope(double q, double h) const {
    check_energy(h, "angle_slope");
    const double v = V(q), D = h - v;
    if (!std::isfinite(q) || !(D > 0))
        bad(name() + ".angle_slope: q = " + fmt(q) + " must lie strictly inside the level h = " + fmt(h) +
            " (V(q) < h)");
    // cos(theta) = k sin(alpha q) / alpha, k = W / sqrt(2 h): d theta / dh = -(d cos / dh) / sin(theta)
    // with sin(theta) = cos(alpha q) sqrt(D / h) (no cancellation: 1 - k^2 s^2 written out).
    const double x = alpha_ * q, c = std::cos(x);
    const double W = std::sqrt(omega_ * omega_ + 2 * alpha_ * alpha_ * h);
    const double s = std::sin(x) / alpha_ * omega_ * omega_ / (2 * std::sqrt(2.0) * h * W * c * std::sqrt(D));
    // Rounding: x = alpha q (1 ulp) moves cos(x) by |x tan x| ulps near the wall, V(q) by
    // |q V'/V| of its ulps; V's error is D's, halved by the sqrt.
    const double eV = kEps * (4 * v + std::fabs(q * dV(q)));
    return {s, std::fabs(s) * (16 * kEps + kEps * std::fabs(x * std::tan(x)) + (kEps * D + eV) / (2 * D))};
}

Numerical::Numerical(std::shared_ptr<const Potential> base) : base_(std::move(base)) {
    if (!base_) bad("Numerical: needs a potential");
}

// ------------------------------------------------------------------ the registry of compiled kinds

namespace {

// A bound as the messages write it: 1e100, not 1e+100.
std::string bound_text(double x) {
    std::string t = fmt(x);
    const auto e = t.find("e+");
    return e == std::string::npos ? t : t.erase(e + 1, 1);
}

template <class P, std::size_t... I>
std::shared_ptr<const Potential> construct(const double* p, std::index_sequence<I...>) {
    return std::make_shared<P>(p[I]...);
}

template <class P>
PotentialKind kind_of() {
    return {P::kInfo.kind, P::kInfo.cls, P::kInfo.formula,
            std::vector<PotentialParam>(P::kInfo.params.begin(), P::kInfo.params.end())};
}

template <class... P>
std::vector<PotentialKind> kinds_of(PotentialList<P...>) {
    return {kind_of<P>()...};
}

// The factory of each kind, in CompiledPotentials' order.
using Factory = std::shared_ptr<const Potential> (*)(const double*);
template <class P>
std::shared_ptr<const Potential> make_of(const double* p) {
    return construct<P>(p, std::make_index_sequence<P::kInfo.params.size()>{});
}
template <class... P>
std::vector<Factory> factories_of(PotentialList<P...>) {
    return {&make_of<P>...};
}

std::string kind_names() {
    std::string s;
    for (const PotentialKind& k : potential_kinds()) s += (s.empty() ? "'" : ", '") + k.kind + "'";
    return s;
}

}  // namespace

void check_parameter(const char* cls, const PotentialParam& p, double v) {
    if (!(v >= p.lo && v <= p.hi))
        bad(std::string(cls) + ": " + p.name + " must lie in [" + bound_text(p.lo) + ", " + bound_text(p.hi) +
            "], got " + fmt(v));
}

const std::vector<PotentialKind>& potential_kinds() {
    static const std::vector<PotentialKind> kinds = kinds_of(CompiledPotentials{});
    return kinds;
}

const PotentialKind& potential_kind(const std::string& kind) {
    for (const PotentialKind& k : potential_kinds())
        if (k.kind == kind) return k;
    bad("potential kind must be one of " + kind_names() + ", got '" + kind + "'");
}

std::shared_ptr<const Potential> make_potential(const std::string& kind, const std::vector<double>& params) {
    static const std::vector<Factory> make = factories_of(CompiledPotentials{});
    const PotentialKind& k = potential_kind(kind);
    if (params.size() != k.params.size()) {
        std::string names;
        for (const PotentialParam& p : k.params) names += std::string(names.empty() ? "" : ", ") + p.name;
        bad("a " + k.kind + " potential takes " + std::to_string(k.params.size()) + " parameter(s) (" + names +
            "), got " + std::to_string(params.size()));
    }
    return make[std::size_t(&k - potential_kinds().data())](params.data());
}

}  // namespace hovering
