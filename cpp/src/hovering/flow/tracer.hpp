#pragma once
// One worker's engine for returns to Sigma_h (internal): the adaptive loop, event search on every
// accepted step, reflections, and the bookkeeping of impacts and crossings of q1 = qw1.

#include <array>
#include <atomic>
#include <vector>

#include "hovering/flow/integrator.hpp"
#include "hovering/flow/return_map.hpp"

namespace hovering::detail {

/// Follows orbits of one system from a point of Sigma_h to its next crossing of Sigma_h. Holds
/// the GSL objects, so a worker builds one and traces many returns with it.
class Tracer {
public:
    Tracer(const FlowSystem& s, const FlowOptions& o);
    /// One return from z0 (on Sigma_h): the first crossing of Sigma_h after q1 has passed its
    /// minimum. With first_crossing, the first crossing of Sigma_h at all (z0 need not lie on it:
    /// the tangential curve starts at q1's minimum). cancel is polled every 256 steps.
    ReturnResult trace(const std::array<double, 4>& z0, bool first_crossing = false,
                       const std::atomic<bool>* cancel = nullptr);
    /// The system traced.
    const FlowSystem& system() const { return s_; }

private:
    enum class Ev { Section, Right, Upper, GrazeRight, GrazeUpper };
    struct Candidate {
        double tau;
        Ev kind;
        double y[kMaxDim];
    };
    const FlowSystem& s_;
    FlowOptions o_;
    Integrator in_;
    std::vector<Candidate> cands_;
};

}  // namespace hovering::detail
