#pragma once
// The sweep kinds of the scene files (TOML) read without Python: "hovering_area" (|HOV| of the
// truncated map against eps, one series per map family) and "flow_hovering_area" (|HOV| of the
// full flow against eps). Same schema, defaults and error messages as python/hovering/scenes/
// schema.py: every key at every level is checked before anything is computed, and a bad one is a
// std::invalid_argument naming it (as "scene.toml.series[1].K_low"), its value (Python's repr) and
// what is allowed. Keys that only the Python figure uses (title, output, dpi, figsize, color,
// models) are checked the same way and kept, so one file serves both programs.

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace hovering::scene {

/// The golden mean rotation pi (sqrt 5 - 1) (OMEGA_G of the scene expressions).
constexpr double kOmegaG = 3.883222077450933;  // float(np.pi * (np.sqrt(5.0) - 1.0)), to the last bit

/// The parameters of one truncated map F_eps (eq:truncatedmap) apart from eps.
struct MapParams {
    double Omega0 = 0, theta_w = 0, tau0 = 1.0, tau1 = 0.5, lam = 0.5;
};

/// (Omega0, theta_w) of the golden family of thm:hoveringc at eps (Omega0 = OMEGA_G - c eps / 2,
/// theta_w = acos((c / tau0) sin(OMEGA_G / 2 - c eps / 4))); throws std::invalid_argument as Python's.
std::pair<double, double> golden_family(double eps, double c, double tau0);

/// One [[series]] of a hovering_area scene.
struct Series {
    std::string label;
    bool golden = false;  ///< golden family: Omega0 and theta_w follow golden_c and eps
    double golden_c = std::numeric_limits<double>::quiet_NaN();
    MapParams map;        ///< Omega0, theta_w are NaN for a golden series
    bool has_K_low = false;  ///< K_low given (else the default box of hovering_area)
    double K_low = std::numeric_limits<double>::quiet_NaN();
    std::string color;    ///< "" when not given
    /// The map parameters of this series at eps (the golden family's at that eps).
    MapParams at(double eps) const;
};

/// A potential of the [system] table: kind "harmonic" (omega) or "tan" (omega, alpha).
struct PotentialSpec {
    std::string kind;
    double omega = 0;
    double alpha = std::numeric_limits<double>::quiet_NaN();  ///< NaN for "harmonic"
};

/// The [system] table of a flow scene.
struct SystemSpec {
    PotentialSpec V1, V2;
    std::vector<std::array<double, 3>> coupling{{1.0, 1.0, 1.0}};  ///< (c, i, j): c q1^i q2^j
    double eps = 0.0, qw1 = -1.0, qw2 = -0.5;
    std::string geometry = "step";
};

/// The [integrator] table of a flow scene (accuracy NaN when not given).
struct IntegratorSpec {
    std::string stepper = "rk8pd";
    double rtol = 1e-10, atol = 1e-10;
    double accuracy = std::numeric_limits<double>::quiet_NaN();
};

/// A validated sweep scene.
struct SweepScene {
    std::string path;   ///< the file it came from ("" for text)
    std::string name;   ///< the file's stem ("scene" for text)
    std::string kind;   ///< "hovering_area" or "flow_hovering_area"
    std::string title, output;
    int dpi = 130;
    std::int64_t n_steps = 0;
    std::int64_t samples = 0;  ///< 100000 (truncated) / 1000 (flow) when not given
    std::uint64_t seed = 0;
    std::vector<double> eps;
    std::vector<Series> series;            ///< hovering_area only
    SystemSpec system;                     ///< flow_hovering_area only
    double h = 1.0;                        ///< flow_hovering_area only
    IntegratorSpec integrator;             ///< flow_hovering_area only
    std::vector<std::string> models{"onset", "measured"};  ///< flow_hovering_area only
};

/// Validate a scene given as TOML text; where names it in messages (the file name). Throws
/// std::invalid_argument with the message Python's parse_scene(..., check_output=False) gives.
SweepScene parse_sweep_scene(const std::string& text, const std::string& where = "scene");
/// Read (at most 1 MiB, UTF-8) and validate a scene file; name = the file's stem.
SweepScene load_sweep_scene(const std::string& path);

}  // namespace hovering::scene
