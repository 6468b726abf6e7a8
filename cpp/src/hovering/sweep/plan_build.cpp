// The core objects of a plan's point; see plan_build.hpp.
#include "hovering/sweep/plan_build.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "hovering/detail/common.hpp"
#include "hovering/flow/potential.hpp"

namespace hovering::sweep {

TruncatedMap build_map(const MapParams& m) {
    return make_truncated_map(m.eps, m.Omega0, m.theta_w, m.tau0, m.tau1, m.lam);
}

FlowSystem build_system(const SystemSpec& sp, double eps) {
    FlowSystem s;
    s.V1 = make_potential(sp.V1.kind, sp.V1.params);  // the core's one factory of compiled kinds
    s.V2 = make_potential(sp.V2.kind, sp.V2.params);
    // hovering.StepSystem's core copy: the terms (c, i, j) in order (hovering.Polynomial).
    for (const auto& t : sp.coupling) s.coupling.terms.push_back({t.c, double(t.i), double(t.j)});
    s.eps = eps;
    s.qw1 = sp.qw1;
    s.qw2 = sp.qw2;
    s.geometry = sp.geometry == "step" ? Geometry::Step : sp.geometry == "wall" ? Geometry::Wall : Geometry::None;
    if (eps != 0 && s.coupling.terms.empty())
        throw std::invalid_argument("system.eps = " + detail::fmt(eps) +
                                    " needs a coupling (system.coupling is empty)");
    s.validate();
    return s;
}

FlowOptions build_options(const IntegratorSpec& it, const FlowSystem& s) {
    FlowOptions o;
    o.stepper = it.stepper;
    o.rtol = it.rtol;
    o.atol = it.atol;
    o.event_tol = it.event_tol;
    o.max_steps = it.max_steps;
    o.max_impacts = it.max_impacts;
    o.grazing_tol = it.grazing_tol;
    o.corner_tol = it.corner_tol;
    o.verify_steps = it.verify_steps;
    o.validate(s);
    return o.resolved(s);
}

TruncatedFamily build_model(const ModelSpec& m) {
    return TruncatedFamily(m.eps, TabulatedArcs(m.K, m.Omega, m.JR, m.J1), FourierForcing{m.forcing}, m.K_max);
}

FlowMap build_flow_map(const FlowSystem& s, double h, const FlowOptions& opt) {
    std::shared_ptr<const AnalyticArcs> lift;
    try {
        const OnsetParameters p = onset_parameters(*s.V1, *s.V2, s.qw1, s.qw2, h);
        lift = std::make_shared<const AnalyticArcs>(AnalyticArcs{p.Omega0, p.theta_w, p.tau0, p.tau1, p.lam});
    } catch (const std::invalid_argument&) {
        // no onset parameters (or no accurate ones) at this h: no lift model, as hovering.FlowMap
    }
    auto curve = std::make_shared<const TangentialCurve>(TangentialCurve::measure_default(s, h));
    if (!curve->is_graph()) throw std::invalid_argument(curve->not_graph_reason());
    return FlowMap(s, h, opt, curve, lift);
}

void check_point(const std::string& kind, const PlanPoint& p) {
    if (kind == "hovering_area") {
        const TruncatedMap m = build_map(p.map);
        if (!(m.band().lo < p.K_low))
            throw std::invalid_argument("K_low = " + detail::fmt(p.K_low) + " lies below the map's band (lower end " +
                                        detail::fmt(m.band().lo) + ")");
        return;
    }
    const FlowSystem s = build_system(p.system, p.system.eps);
    build_options(p.integrator, s);
    if (!std::isfinite(p.h)) throw std::invalid_argument("h must be finite");
    for (const auto& m : p.models) {
        try {
            build_model(m);
        } catch (const std::invalid_argument& e) {
            throw std::invalid_argument("model '" + m.name + "': " + e.what());
        }
    }
}

}  // namespace hovering::sweep
