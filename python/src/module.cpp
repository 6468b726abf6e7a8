// Entry point of hovering._core: a thin module, each topic registers itself.
#include "pybind.hpp"

PYBIND11_MODULE(_core, m) {
    m.doc() = "Compiled core of hovering: the truncated near-tangency map and its batch iteration.";
    register_truncated_map(m);
    register_potential(m);
    register_flow(m);
}
