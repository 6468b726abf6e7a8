#pragma once
// A double as a sweep's JSON holds it (internal to the sweep library): the plan's checkpoint keys
// (plan.cpp) and the rows appended to a checkpoint (run.cpp) write numbers the same way, the way
// hovering.parallel.checkpoint writes them.

#include <cmath>

#include <nlohmann/json.hpp>

namespace hovering::sweep {

/// A JSON number, or the string naming a non-finite one ("NaN", "Infinity", "-Infinity").
inline nlohmann::json jnum(double x) {
    if (std::isnan(x)) return "NaN";
    if (std::isinf(x)) return x > 0 ? "Infinity" : "-Infinity";
    return x;
}

}  // namespace hovering::sweep
