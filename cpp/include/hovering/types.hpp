#pragma once
// Vocabulary shared by both models of the return map (the truncated map and the flow): region
// labels and per-orbit outcomes.

#include <cstdint>

namespace hovering {

/// Region of Sigma_h a point lies in: which way its segment passes the step before it returns.
enum class Region : std::int8_t {
    None = -1,   ///< no return was taken from this point (the orbit had stopped)
    Beside = 0,  ///< J_0u: passes beside the step without crossing q1 = qw1
    Above = 1,   ///< J_0: crosses q1 = qw1 above the step, no impact ("hovers")
    Upper = 2,   ///< J_1: one impact on the upper wall of the step
    Right = 3,   ///< J_R: one impact on the right wall of the step
    Multi = 4,   ///< more than one impact (the flow only: outside the tangential band)
};

/// Number of region codes >= 0 (bits of a region mask).
inline constexpr int kRegionCount = 5;

/// Per-orbit outcome of a batch iteration (either model); numerical outcomes, never exceptions.
enum class Status : std::int8_t {
    Ok = 0,            ///< all requested steps were taken
    Escaped = 1,       ///< the orbit left the band where the map is defined
    Exited = 2,        ///< the orbit left the requested set of regions and stop_on_exit was set
    Interrupted = 3,   ///< the caller cancelled the run; the state reached so far is kept
    Corner = 4,        ///< flow: the orbit hit the corner of the step (the flow stops there)
    Grazing = 5,       ///< flow: the orbit touched a wall tangentially (a singular return)
    StepLimit = 6,     ///< flow: one return needed more integrator steps than allowed
    NonFinite = 7,     ///< flow: the state became non-finite (a runaway orbit)
    ImpactLimit = 8,   ///< flow: more impacts in one return than allowed (chattering)
    OffSection = 9,    ///< flow: the point is not on Sigma_h at this energy
    OutsideWell = 10,  ///< flow: no accepted step keeps the state inside a bounded well (e.g. Tan)
    Stopped = 11,      ///< the orbit reached the set of the stop condition (above / below a curve)
    Imprecise = 12,    ///< flow: a return's verified error stayed above its band (chaotic amplification)
};

/// States recorded per orbit with every = e: x_0, x_e, ..., x_{e floor(n_steps / e)}.
inline std::int64_t recorded_states(std::int64_t n_steps, std::int64_t every) {
    return n_steps / every + 1;
}
/// Returns recorded per orbit with every = e: those from the recorded states x_n with n < n_steps.
inline std::int64_t recorded_returns(std::int64_t n_steps, std::int64_t every) {
    return (n_steps + every - 1) / every;
}

/// Which implementation of one map step a batch iteration uses.
enum class Kernel : std::int8_t {
    Simd = 0,    ///< Eigen array expressions over a chunk of orbits + SLEEF vector sin
    Scalar = 1,  ///< one orbit at a time with libm sin; the reference the SIMD path is checked against
};

}  // namespace hovering
