#pragma once
// The one place where a point of the truncated map is assigned to an arc (internal): the scalar
// step, the inverse and the scalar kernel call it; the SIMD kernel repeats exactly its arithmetic.

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

/// Region and rotation of (phi, K) given the arcs at K (arcs placed by eq:phi1rsymmetric).
inline Classified classify(double phi, double K, const ArcLengths& a) {
    if (!(K < 0.0)) return {Region::Beside, a.Omega};
    double d = phi - (kPi - 0.5 * (a.Omega + a.JR + a.J1));  // offset from the left end of J_1
    d -= kTwoPi * std::floor(d * kInvTwoPi);
    if (d < a.J1) return {Region::Upper, a.Omega + a.JR};
    if (d < a.J1 + a.JR) return {Region::Right, a.Omega - a.J1};
    return {Region::Above, a.Omega};
}

}  // namespace hovering::detail
