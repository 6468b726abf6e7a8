#pragma once
// The vector field of a FlowSystem as the integrator sees it (internal).
//
// The state is (q1, p1, q2, p2) plus, for each Tan potential, the auxiliary variable
// u = tan(alpha q) with du/dt = alpha (1 + u^2) p. The Tan force (omega^2 / alpha) u (1 + u^2) is
// then a polynomial, so the field costs no transcendental call: with libm's tan the integrator's
// inner loop spent ~40% of its time in tan. The extended system has u = tan(alpha q) as an exact
// invariant; the integrator carries both to its tolerance, and u is reset from q after every
// reflection and at every start. Events and energies read (q1, p1, q2, p2) only.
//
// With tangents (the variational equations, for the Jacobian of a return), the integrated state
// also holds that many tangent vectors (dq1, dp1, dq2, dp2) after it, each obeying
// d(dq)/dt = dp, d(dp)/dt = -Hess(V)(q) dq: V'' from the same state (Tan: a b w (3 w - 2) with
// w = 1 + u^2, a polynomial in u again), the coupling's Hessian from its terms. The tangents never
// feed back into the state, so a step's state is what it is without them.
//
// The common potentials and the bilinear coupling are inlined, one instantiation per (V1 kind,
// V2 kind, coupling kind), chosen once per system: through virtual calls the inner loop spent ~8
// of its ~21 ns per evaluation outside the force itself.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "hovering/flow/system.hpp"

namespace hovering::detail {

/// x^n for a small integer n >= 0 by repeated squaring: exact for n <= 2 and, unlike std::pow,
/// cheap enough for the integrator's inner loop.
inline double ipow(double x, int n) {
    double r = 1.0;
    while (n > 0) {
        if (n & 1) r *= x;
        x *= x;
        n >>= 1;
    }
    return r;
}

/// Largest state: (q1, p1, q2, p2) and two auxiliary tan variables.
inline constexpr int kMaxState = 6;
/// Most tangent vectors integrated with the state (the two directions of Sigma_h).
inline constexpr int kMaxTangents = 2;
/// Largest integrated vector: the state and its tangents.
inline constexpr int kMaxDim = kMaxState + 4 * kMaxTangents;

enum class Kind { Harmonic, Tan, Other };
enum class CKind { None, Bilinear, General };

/// The force V'(q) of one oscillator.
struct Force {
    Kind kind = Kind::Other;
    double a = 0, b = 0;  // Harmonic: a = omega^2; Tan: a = omega^2 / alpha, b = alpha
    const Potential* p = nullptr;
    int aux = -1;  // Tan: index of u = tan(alpha q) in the state
    explicit Force(const Potential* pot);
    /// V'(q) (q is state[QI]); the Tan force reads u from state[AUX].
    template <Kind K, int QI, int AUX>
    double eval(const double* z) const {
        if constexpr (K == Kind::Harmonic) {
            return a * z[QI];
        } else if constexpr (K == Kind::Tan) {
            const double u = z[AUX];
            return a * u * (1 + u * u);
        } else {
            return p->dV(z[QI]);
        }
    }
    /// V''(q) from the same state: closed form for Harmonic and Tan (in u: d/dq of a u (1 + u^2)
    /// is a b (1 + u^2) (1 + 3 u^2)), a central difference of V' otherwise.
    double curvature(const double* z, int qi) const {
        if (kind == Kind::Harmonic) return a;
        if (kind == Kind::Tan) {
            const double w = 1 + z[aux] * z[aux];
            return a * b * w * (3 * w - 2);
        }
        const double q = z[qi], d = 1e-6 * (1 + std::fabs(q));
        return (p->dV(q + d) - p->dV(q - d)) / (2 * d);
    }
};

/// dz/dt of the (extended) state; see the file comment.
struct Field {
    Force f1, f2;
    double eps;
    const Coupling* coupling;
    double bilinear_c = 0;
    CKind ckind = CKind::None;
    int state = 4;     ///< the state's size: (q1, p1, q2, p2) and the auxiliary tan variables
    int tangents = 0;  ///< tangent vectors integrated after it (0 .. kMaxTangents)
    int dim = 4;       ///< the integrated vector's size: state + 4 tangents
    /// dz/dt in GSL's calling convention (params = this Field), handed to GSL directly.
    int (*fn)(double, const double*, double*, void*) = nullptr;
    /// Evaluations of the field without and with its coupling term so far (FlowWork): plain
    /// counters, one Field per integrator and worker, so no atomics; each evaluation increments
    /// exactly one of them (the second inside the coupling branch), so counting costs one
    /// increment per evaluation. All evaluations: evaluations() below.
    mutable std::int64_t uncoupled_evaluations = 0, coupling_evaluations = 0;
    /// Every evaluation so far.
    std::int64_t evaluations() const { return uncoupled_evaluations + coupling_evaluations; }

    explicit Field(const FlowSystem& s, int n_tangents = 0);
    void operator()(const double* z, double* dz) const { fn(0.0, z, dz, const_cast<Field*>(this)); }
    /// Set the auxiliary variables from the positions (at a start, or after a reflection).
    void sync_aux(double* z) const {
        if (f1.aux >= 0) z[f1.aux] = std::tan(f1.b * z[0]);
        if (f2.aux >= 0) z[f2.aux] = std::tan(f2.b * z[2]);
    }
    /// eps times the coupling's Hessian at the state z: (h11, h12, h22).
    std::array<double, 3> coupling_hessian(const double* z) const {
        std::array<double, 3> h{0, 0, 0};
        if (ckind == CKind::Bilinear) {
            h[1] = eps * bilinear_c;
        } else if (ckind == CKind::General) {
            for (const auto& t : coupling->terms) {  // Vc = sum c q1^i q2^j
                const double c = t[0];
                const int i = int(t[1]), j = int(t[2]);
                const double q1 = z[0], q2 = z[2];
                if (i >= 2) h[0] += c * i * (i - 1) * ipow(q1, i - 2) * ipow(q2, j);
                if (i >= 1 && j >= 1) h[1] += c * i * j * ipow(q1, i - 1) * ipow(q2, j - 1);
                if (j >= 2) h[2] += c * j * (j - 1) * ipow(q1, i) * ipow(q2, j - 2);
            }
            for (double& x : h) x *= eps;
        }
        return h;
    }
    /// d(tangents)/dt at z (the variational equations), into dz after the state.
    void tangent_rhs(const double* z, double* dz) const {
        const double c1 = f1.curvature(z, 0), c2 = f2.curvature(z, 2);
        const auto h = coupling_hessian(z);
        for (int j = 0; j < tangents; ++j) {
            const double* v = z + state + 4 * j;
            double* dv = dz + state + 4 * j;
            dv[0] = v[1];
            dv[1] = -((c1 + h[0]) * v[0] + h[1] * v[2]);
            dv[2] = v[3];
            dv[3] = -(h[1] * v[0] + (c2 + h[2]) * v[2]);
        }
    }

    template <Kind K1, Kind K2, CKind C>
    static int eval(double, const double* z, double* dz, void* params) {
        // The auxiliary variables follow (q1, p1, q2, p2) in the order V1, V2: compile-time indices.
        constexpr int A1 = 4, A2 = K1 == Kind::Tan ? 5 : 4;
        const Field& F = *static_cast<const Field*>(params);
        if constexpr (C == CKind::None) ++F.uncoupled_evaluations;
        dz[0] = z[1];
        dz[1] = -F.f1.eval<K1, 0, A1>(z);
        dz[2] = z[3];
        dz[3] = -F.f2.eval<K2, 2, A2>(z);
        if constexpr (C == CKind::Bilinear) {
            ++F.coupling_evaluations;
            dz[1] -= F.eps * (F.bilinear_c * z[2]);
            dz[3] -= F.eps * (F.bilinear_c * z[0]);
        } else if constexpr (C == CKind::General) {
            ++F.coupling_evaluations;
            const auto g = F.coupling->gradient(z[0], z[2]);
            dz[1] -= F.eps * g[0];
            dz[3] -= F.eps * g[1];
        }
        if constexpr (K1 == Kind::Tan) {
            const double u = z[A1];
            dz[A1] = F.f1.b * (1 + u * u) * z[1];
        }
        if constexpr (K2 == Kind::Tan) {
            const double u = z[A2];
            dz[A2] = F.f2.b * (1 + u * u) * z[3];
        }
        return 0;  // GSL_SUCCESS
    }

    /// eval with the tangents' variational equations after the state.
    template <Kind K1, Kind K2, CKind C>
    static int eval_tangents(double t, const double* z, double* dz, void* params) {
        eval<K1, K2, C>(t, z, dz, params);
        static_cast<const Field*>(params)->tangent_rhs(z, dz);
        return 0;  // GSL_SUCCESS
    }

    /// d(dz/dt)/dz (row-major dim x dim) and df/dt = 0, in GSL's calling convention (params = this
    /// Field): for GSL's implicit steppers. V'' in closed form for Harmonic and Tan (in u), by a
    /// central difference of V' otherwise; the coupling's Hessian from its polynomial terms.
    static int jacobian(double, const double* z, double* J, double* dfdt, void* params) {
        const Field& F = *static_cast<const Field*>(params);
        const int n = F.dim;
        for (int i = 0; i < n * n; ++i) J[i] = 0;
        for (int i = 0; i < n; ++i) dfdt[i] = 0;
        J[0 * n + 1] = 1;
        J[2 * n + 3] = 1;
        auto osc = [&](const Force& f, int qi) {
            const int pi = qi + 1;
            if (f.kind == Kind::Harmonic) {
                J[pi * n + qi] = -f.a;
            } else if (f.kind == Kind::Tan) {
                const double u = z[f.aux];
                J[pi * n + f.aux] = -f.a * (1 + 3 * u * u);  // d/du of -a u (1 + u^2)
                J[f.aux * n + f.aux] = 2 * f.b * u * z[pi];  // d/du of b (1 + u^2) p
                J[f.aux * n + pi] = f.b * (1 + u * u);       // d/dp
            } else {
                const double q = z[qi], d = 1e-6 * (1 + std::fabs(q));
                J[pi * n + qi] = -(f.p->dV(q + d) - f.p->dV(q - d)) / (2 * d);
            }
        };
        osc(F.f1, 0);
        osc(F.f2, 2);
        if (F.ckind != CKind::None) {
            for (const auto& t : F.coupling->terms) {  // Vc = sum c q1^i q2^j
                const double c = t[0];
                const int i = int(t[1]), j = int(t[2]);
                const double q1 = z[0], q2 = z[2];
                const double h11 = i >= 2 ? c * i * (i - 1) * ipow(q1, i - 2) * ipow(q2, j) : 0.0;
                const double h22 = j >= 2 ? c * j * (j - 1) * ipow(q1, i) * ipow(q2, j - 2) : 0.0;
                const double h12 = i >= 1 && j >= 1 ? c * i * j * ipow(q1, i - 1) * ipow(q2, j - 1) : 0.0;
                J[1 * n + 0] -= F.eps * h11;
                J[1 * n + 2] -= F.eps * h12;
                J[3 * n + 0] -= F.eps * h12;
                J[3 * n + 2] -= F.eps * h22;
            }
        }
        if (F.tangents > 0) {
            // The tangents' own block (each tangent's equations in itself); their dependence on the
            // state (third derivatives of V) is left out: an implicit stepper's Newton iteration
            // then still converges, and the state block is solved as without tangents.
            const double c1 = F.f1.curvature(z, 0), c2 = F.f2.curvature(z, 2);
            const auto h = F.coupling_hessian(z);
            for (int j = 0; j < F.tangents; ++j) {
                const int b = F.state + 4 * j;
                J[b * n + b + 1] = 1;
                J[(b + 1) * n + b] = -(c1 + h[0]);
                J[(b + 1) * n + b + 2] = -h[1];
                J[(b + 2) * n + b + 3] = 1;
                J[(b + 3) * n + b] = -h[1];
                J[(b + 3) * n + b + 2] = -(c2 + h[2]);
            }
        }
        return 0;  // GSL_SUCCESS
    }

private:
    template <Kind K1, Kind K2>
    void pick_c();
    template <Kind K1>
    void pick_2();
};

inline Force::Force(const Potential* pot) : p(pot) {
    // Numerical answers energy questions by quadrature but its force is its base's: the same
    // inlined (and, for Tan, polynomial) force serves both.
    while (const auto* w = dynamic_cast<const Numerical*>(pot)) pot = w->base().get();
    if (const auto* h = dynamic_cast<const Harmonic*>(pot)) {
        kind = Kind::Harmonic;
        a = h->omega() * h->omega();
    } else if (const auto* t = dynamic_cast<const Tan*>(pot)) {
        kind = Kind::Tan;
        a = t->omega() * t->omega() / t->alpha();
        b = t->alpha();
    }
}

template <Kind K1, Kind K2>
void Field::pick_c() {
    if (tangents > 0)
        fn = ckind == CKind::None       ? &eval_tangents<K1, K2, CKind::None>
             : ckind == CKind::Bilinear ? &eval_tangents<K1, K2, CKind::Bilinear>
                                        : &eval_tangents<K1, K2, CKind::General>;
    else
        fn = ckind == CKind::None       ? &eval<K1, K2, CKind::None>
             : ckind == CKind::Bilinear ? &eval<K1, K2, CKind::Bilinear>
                                        : &eval<K1, K2, CKind::General>;
}

template <Kind K1>
void Field::pick_2() {
    if (f2.kind == Kind::Harmonic)
        pick_c<K1, Kind::Harmonic>();
    else if (f2.kind == Kind::Tan)
        pick_c<K1, Kind::Tan>();
    else
        pick_c<K1, Kind::Other>();
}

inline Field::Field(const FlowSystem& s, int n_tangents)
    : f1(s.V1.get()), f2(s.V2.get()), eps(s.eps), coupling(&s.coupling) {
    const auto& t = s.coupling.terms;
    if (eps == 0.0) {
        ckind = CKind::None;  // a scene with eps = 0 evaluates no coupling at all
    } else if (t.size() == 1 && t[0][1] == 1 && t[0][2] == 1) {
        ckind = CKind::Bilinear;
        bilinear_c = t[0][0];
    } else {
        ckind = CKind::General;
    }
    if (f1.kind == Kind::Tan) f1.aux = state++;
    if (f2.kind == Kind::Tan) f2.aux = state++;
    tangents = std::clamp(n_tangents, 0, kMaxTangents);
    dim = state + 4 * tangents;
    if (f1.kind == Kind::Harmonic)
        pick_2<Kind::Harmonic>();
    else if (f1.kind == Kind::Tan)
        pick_2<Kind::Tan>();
    else
        pick_2<Kind::Other>();
}

}  // namespace hovering::detail
