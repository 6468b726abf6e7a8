#pragma once
// A resolved sweep plan (docs/sweep-plan.md): a small versioned TOML file in which every number of
// every point is explicit (no expressions, no defaults to resolve), written by Python's
// `python -m hovering plan SCENE.toml` or by hand, and run by hovering_sweep. Reading it checks
// types and ranges only: an unknown key, a missing one, a value of the wrong type or out of range,
// or another format version is a std::invalid_argument naming the file, the key, the value and
// what is allowed. The parameters of each point are also handed to the core's constructors
// (maps, systems, integrator options), so a point the core would refuse is refused here, before
// anything is computed.

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "hovering/flow/return_map.hpp"

namespace hovering::sweep {

/// The plan format this reader takes (the file's `version`).
constexpr int kPlanVersion = 1;

/// The six parameters of a truncated map F_eps (eq:truncatedmap).
struct MapParams {
    double eps = 0, Omega0 = 0, theta_w = 0, tau0 = 0, tau1 = 0, lam = 0;
};

/// A potential of a flow system: a compiled kind (hovering::potential_kinds(): "harmonic" with
/// omega, "tan" with omega and alpha) and its parameters, keys of the plan's table.
struct PotentialSpec {
    std::string kind;            ///< a PotentialKind::kind
    std::vector<double> params;  ///< the kind's parameters, in its order
};

/// One term c q1^i q2^j of the coupling.
struct CouplingTerm {
    double c = 0;
    int i = 0, j = 0;
};

/// The oscillators-step system of a flow point (hovering.StepSystem).
struct SystemSpec {
    PotentialSpec V1, V2;
    std::vector<CouplingTerm> coupling;  ///< distinct (i, j); empty: no coupling
    double eps = 0, qw1 = 0, qw2 = 0;
    std::string geometry;  ///< "none", "wall" or "step"
};

/// The integrator of a flow point: every FlowOptions field, each explicit in a plan.
struct IntegratorSpec {
    Stepper stepper = Stepper::Auto;  ///< parsed from the plan's name (kSteppers)
    double rtol = 0, atol = 0;         ///< tolerances of the step control
    double event_tol = 0;              ///< FlowOptions::event_tol
    std::int64_t max_steps = 0;        ///< FlowOptions::max_steps
    int max_impacts = 0;               ///< FlowOptions::max_impacts
    double grazing_tol = 0;            ///< FlowOptions::grazing_tol
    double corner_tol = 0;             ///< FlowOptions::corner_tol
    std::int64_t verify_steps = 0;     ///< FlowOptions::verify_steps
};

/// A truncated model of a flow point: a TruncatedFamily by its tables, and the box it samples.
struct ModelSpec {
    std::string name;
    double K_low = 0;  ///< bottom of the model's box (the point's K_low: verdicts are compared)
    double eps = 0;    ///< forcing amplitude eps_1
    std::vector<double> K, Omega, JR, J1, forcing;
    double K_max = std::numeric_limits<double>::infinity();
};

/// One point of a plan.
struct PlanPoint {
    std::string label;                                         ///< what it is, for messages (optional)
    std::int64_t n_steps = 0;                                  ///< N, in [4, 2^53]
    std::int64_t samples = 0;                                  ///< sample points asked for, in [1, 2^53]
    std::uint64_t seed = 0;                                    ///< in [0, 2^63 - 1]
    double K_low = 0;                                          ///< bottom of the box, < 0
    double theory = std::numeric_limits<double>::quiet_NaN();  ///< carried into the row
    double b1 = std::numeric_limits<double>::quiet_NaN();      ///< carried into the row (flow points)
    MapParams map;                                             ///< hovering_area points
    SystemSpec system;                                         ///< flow_hovering_area points
    double h = 0;                                              ///< flow_hovering_area points
    IntegratorSpec integrator;                                 ///< flow_hovering_area points
    std::vector<ModelSpec> models;                             ///< flow_hovering_area points (may be empty)
    /// The point's key in a checkpoint: the canonical JSON (sorted keys, shortest round-trip
    /// numbers, non-finite numbers as the strings "NaN", "Infinity", "-Infinity") of its parameters,
    /// i.e. every field above except label, theory and b1, with the kind.
    std::string key;
};

/// A validated plan.
struct Plan {
    std::string path;        ///< the file ("" for text)
    std::string kind;        ///< "hovering_area" or "flow_hovering_area"
    std::string name;        ///< what the sweep is (messages)
    std::string checkpoint;  ///< default output, relative to the plan's folder ("" if none)
    std::vector<PlanPoint> points;
};

/// A double as every message of the core, the plan reader and hovering_sweep shows it: the
/// shortest text that reads back as it ("nan", "inf", "-inf" for the others).
std::string format_number(double x);

/// Validate a plan given as TOML text; `where` names it in messages.
Plan parse_plan(const std::string& text, const std::string& where = "plan");
/// Read (a regular file of at most 256 MiB) and validate a plan file.
Plan load_plan(const std::string& path);

}  // namespace hovering::sweep
