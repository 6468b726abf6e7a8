#pragma once
// What built this core and where it runs, recorded beside every result (the Python package's
// provenance record and the header of hovering_sweep's CSV) so that a result says what made it.

#include <string>
#include <vector>

namespace hovering {

/// One fact of a build: its name and its value as text (`number`: the text is an integer).
struct BuildFact {
    std::string name;     ///< e.g. "gsl"
    std::string value;    ///< e.g. "2.7.1"
    bool number = false;  ///< whether value is an integer (written without quotes in JSON)
};

/// The facts, in this order: hovering (version), git (commit the core was built from, "-dirty" when
/// the checkout had uncommitted changes, "unknown" outside a checkout), compiler, gsl, eigen, sleef,
/// simd_width, platform (system-release-machine of this machine), hardware_threads.
std::vector<BuildFact> build_info();

/// `facts` as one line of JSON: {"name": value, ...} in their order.
std::string facts_json(const std::vector<BuildFact>& facts);

}  // namespace hovering
