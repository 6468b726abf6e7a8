// Placeholder: the TOML reading of sweep scenes is being written (see sweep_scene.hpp).
#include "hovering/scene/sweep_scene.hpp"

#include <cmath>
#include <stdexcept>
#include <tuple>

namespace hovering::scene {

std::pair<double, double> golden_family(double eps, double c, double tau0) {
    const double Omega0 = kOmegaG - 0.5 * c * eps;
    return {Omega0, std::acos((c / tau0) * std::sin(0.5 * kOmegaG - 0.25 * c * eps))};
}

MapParams Series::at(double eps) const {
    MapParams m = map;
    if (golden) std::tie(m.Omega0, m.theta_w) = golden_family(eps, golden_c, m.tau0);
    return m;
}

SweepScene parse_sweep_scene(const std::string&, const std::string&) {
    throw std::invalid_argument("parse_sweep_scene: not written yet");
}

SweepScene load_sweep_scene(const std::string& path) { return parse_sweep_scene("", path); }

}  // namespace hovering::scene
