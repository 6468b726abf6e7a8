#pragma once
// The core objects of a plan's point, built from its explicit numbers exactly as the Python package
// builds them from the same numbers (hovering.TruncatedMap(**map), hovering.StepSystem,
// hovering.FlowMap(sys, h, stepper=, rtol=, atol=), hovering.TruncatedFamily._from_record), so that
// both programs compute the same doubles. Private to the sweep library (plan.cpp checks a point
// by building it, run.cpp runs it).

#include <memory>
#include <string>

#include "hovering/flow/return_map.hpp"
#include "hovering/normal/flow_map.hpp"
#include "hovering/sweep/plan.hpp"
#include "hovering/truncated/map.hpp"

namespace hovering::sweep {

/// F_eps of a hovering_area point.
TruncatedMap build_map(const MapParams& m);
/// The system of a flow point at coupling strength eps (validated).
FlowSystem build_system(const SystemSpec& s, double eps);
/// The integrator options of a flow point (validated for the system).
FlowOptions build_options(const IntegratorSpec& it, const FlowSystem& s);
/// A truncated model by its tables.
TruncatedFamily build_model(const ModelSpec& m);
/// The flow map on normal coordinates of hovering.FlowMap(sys, h, **integrator): its default
/// tangential curve, and the onset parameters' arcs as lift (none where they are not accurate).
FlowMap build_flow_map(const FlowSystem& s, double h, const FlowOptions& opt);
/// Build what can be built of a point without computing (maps, system, options, models):
/// std::invalid_argument with the core's message for a point the core would refuse.
void check_point(const std::string& kind, const PlanPoint& p);

}  // namespace hovering::sweep
