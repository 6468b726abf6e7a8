#pragma once
// Vocabulary shared by every model of the return map: region labels and per-orbit outcomes.

#include <cstdint>

namespace hovering {

/// Region of the tangential band an orbit point lies in (paper labels 0u, 0, 1, R).
enum class Region : std::int8_t {
    None = -1,   ///< no step was taken from this point (orbit already stopped)
    Beside = 0,  ///< J_0u: K >= 0, passes beside the step without crossing q1 = qw1
    Above = 1,   ///< J_0: hovers above the step without impact
    Upper = 2,   ///< J_1: one impact on the upper wall of the step
    Right = 3,   ///< J_R: one impact on the right wall of the step
};

/// Per-orbit outcome of a batch iteration; numerical outcomes, never exceptions.
enum class Status : std::int8_t {
    Ok = 0,           ///< all requested steps were taken
    Escaped = 1,      ///< the orbit left the band where the map is defined
    Exited = 2,       ///< the orbit left the requested set of regions and stop_on_exit was set
    Interrupted = 3,  ///< the caller cancelled the run; the state reached so far is kept
};

/// Which implementation of one map step a batch iteration uses.
enum class Kernel : std::int8_t {
    Simd = 0,    ///< Eigen array expressions over a chunk of orbits + SLEEF vector sin
    Scalar = 1,  ///< one orbit at a time with libm sin; the reference the SIMD path is checked against
};

}  // namespace hovering
