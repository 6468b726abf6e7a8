#pragma once
// Running a sweep scene point by point, as python -m hovering scene does: one point per (series,
// eps) of a hovering_area scene and per eps of a flow_hovering_area scene, each measured by
// hovering_area (stratified samples, F_0 then F_eps with early exit from {J_0u, J_0}). A point's
// key holds every parameter that changes its numbers, so a CSV of finished points can be resumed
// by key. What the flow scene's figure adds in Python (its truncated models) is not computed here.

#include <atomic>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "hovering/scene/sweep_scene.hpp"

namespace hovering::scene {

/// Quick runs: iterate counts and samples divided by this (as Python's QUICK_FACTOR).
constexpr int kQuickFactor = 50;

/// The counts a run uses: the scene's, or its --quick reduction (Python's rules).
struct SweepCounts {
    std::int64_t n_steps = 0;  ///< iterates (returns) that count as "never"
    std::int64_t samples = 0;  ///< sample points asked for (the grid rounds up)
};

/// One point: the series index (0 for a flow scene) and eps.
struct SweepPoint {
    std::size_t series = 0;
    double eps = 0;
};

/// A computed point: named values in column order (counts are exact in a double).
struct SweepRow {
    std::vector<std::pair<std::string, double>> values;
    bool interrupted = false;  ///< cancelled before it finished: not a result
};

/// The counts of a run (quick: n_steps / 50 (at least min(100, n) for the truncated map and
/// min(50, n) for the flow), samples / 50 (at least 400 / 100)).
SweepCounts sweep_counts(const SweepScene& s, bool quick);
/// The points of a scene, in Python's order (series-major).
std::vector<SweepPoint> sweep_points(const SweepScene& s);
/// Names of the result values of a point of this kind (the order of SweepRow::values).
std::vector<std::string> result_columns(const SweepScene& s);
/// Names and canonical text (shortest round-trip doubles) of every parameter that changes a
/// point's numbers: the resume key, and the readable columns after the results.
std::vector<std::pair<std::string, std::string>> point_parameters(const SweepScene& s, const SweepPoint& p,
                                                                  const SweepCounts& c);
/// Throws std::invalid_argument if this program cannot run the scene as written (an [integrator]
/// accuracy target: Python turns it into a stepper and tolerances by measurement), before any work.
void check_runnable(const SweepScene& s);
/// Measure one point. n_threads: 0 = all cores; cancel (optional) stops it early (then
/// interrupted is set); progress (optional) counts map steps / flow returns as hovering_area does.
SweepRow run_point(const SweepScene& s, const SweepPoint& p, const SweepCounts& c, int n_threads = 0,
                   const std::atomic<bool>* cancel = nullptr, std::atomic<std::int64_t>* progress = nullptr);

}  // namespace hovering::scene
