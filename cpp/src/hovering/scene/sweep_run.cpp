// Placeholder while the runner is written (see sweep_run.hpp).
#include "hovering/scene/sweep_run.hpp"

#include <stdexcept>

namespace hovering::scene {
SweepCounts sweep_counts(const SweepScene& s, bool) { return {s.n_steps, s.samples}; }
std::vector<SweepPoint> sweep_points(const SweepScene&) { return {}; }
std::vector<std::string> result_columns(const SweepScene&) { return {}; }
std::vector<std::pair<std::string, std::string>> point_parameters(const SweepScene&, const SweepPoint&,
                                                                  const SweepCounts&) {
    return {};
}
SweepRow run_point(const SweepScene&, const SweepPoint&, const SweepCounts&, int, const std::atomic<bool>*,
                   std::atomic<std::int64_t>*) {
    throw std::logic_error("run_point: not written yet");
}
}  // namespace hovering::scene
