// The oscillators-step system: coupling polynomials, validation, energy and the plain vector field.

#include "hovering/flow/system.hpp"

#include <cmath>

#include "hovering/detail/common.hpp"
#include "hovering/flow/field.hpp"

namespace hovering {

using detail::bad;
using detail::fmt;
using detail::ipow;

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

}  // namespace hovering
