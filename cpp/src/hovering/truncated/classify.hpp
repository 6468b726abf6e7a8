#pragma once
// The one place where a point of the truncated map is assigned to an arc (internal): the scalar
// step, the inverse and the scalar kernel call it; the SIMD kernel gets the same regions (it uses
// a cheaper offset test away from the arc ends and these comparisons near them).
//
// Boundary convention. Each arc is half-open and owns its left end: J_1 = [s_1, s_R),
// J_R = [s_R, s_0), J_0 = [s_0, s_1) on the circle [-pi, pi), where s_1, s_R, s_0 are the doubles
// arc_starts() below computes - exactly the values MapCore::arc_starts(), arcs() and
// corner_curves() hand out - and a point is placed by comparing it with them, not by a
// recomputed offset (which rounds differently, and put some handed-out starts in the arc before).
// The image arcs are half-open the same way: F maps J_a onto [t_a, t_next), t_a = image of s_a
// computed by the very expression of the forward step, so the inverse gives every image start
// back to the arc that owns it: in exact arithmetic F is a bijection of the band. (In floating
// point step() can send several doubles to one; MapCore::step_inverse says which it returns.)

#include <cmath>

#include "hovering/detail/common.hpp"
#include "hovering/truncated/arcs.hpp"
#include "hovering/types.hpp"

namespace hovering::detail {

/// Region of a point and the rotation omega_a applied to it.
struct Classified {
    Region region;
    double omega;
};

/// Wrap u in [-pi, 3 pi) to [-pi, pi), exactly (u - 2 pi is exact for u in [pi, 4 pi]).
inline double wrap_once(double u) {
    return u >= kPi ? u - kTwoPi : u;
}

/// Left ends of J_1, J_R, J_0 (eq:phi1rsymmetric) in [-pi, pi), for K < 0.
struct ArcStarts {
    double s1, sR, s0;
};

/// s_1 = wrap(pi - (Omega + |J_R| + |J_1|) / 2); s_R and s_0 add |J_1| and |J_R| to s_1 unwrapped
/// and wrap once, exactly: the three stay in cyclic order (rounding is monotone) up to the
/// degenerate case of an arc shorter than the rounding, and no start is off by a turn.
inline ArcStarts arc_starts(const ArcLengths& a) {
    const double u1 = wrap(kPi - 0.5 * (a.Omega + a.JR + a.J1));
    const double uR = u1 + a.J1;
    const double u0 = uR + a.JR;
    return {u1, wrap_once(uR), wrap_once(u0)};
}

/// Whether q lies in the half-open arc [a, b) of the circle (empty if a == b); all in [-pi, pi).
inline bool in_arc(double q, double a, double b) {
    return a <= b ? (a <= q && q < b) : (a <= q || q < b);
}

/// Rotation omega_a of the arc r at these arc lengths (for r = Beside: Omega).
inline double arc_rotation(Region r, const ArcLengths& a) {
    if (r == Region::Upper) return a.Omega + a.JR;
    if (r == Region::Right) return a.Omega - a.J1;
    return a.Omega;
}

/// Region and rotation of (phi, K), phi in [-pi, pi), given the arcs at K. J_1 is tested first,
/// then J_R, J_0 is the rest: every point gets exactly one region even when an arc is shorter
/// than the rounding of its ends (within an ulp of the band floor).
inline Classified classify(double phi, double K, const ArcLengths& a) {
    if (!(K < 0.0)) return {Region::Beside, a.Omega};
    const ArcStarts s = arc_starts(a);
    const Region r = in_arc(phi, s.s1, s.sR) ? Region::Upper : in_arc(phi, s.sR, s.s0) ? Region::Right : Region::Above;
    return {r, arc_rotation(r, a)};
}

/// Image of (phi, K) under the rotation part of a step: wrap(phi + omega_a), the one expression
/// the forward step, both kernels and the inverse's image starts use.
inline double rotate(double phi, double omega) {
    return wrap(phi + omega);
}

}  // namespace hovering::detail
