// Entry point of hovering._core: a thin module with one submodule per topic of the core
// (truncated, flow, normal, analysis), each registering itself; the shared enums live at the top.
#include "gil.hpp"
#include "hovering/build_info.hpp"
#include "pybind.hpp"

PYBIND11_MODULE(_core, m) {
    m.doc() = "Compiled core of hovering: the truncated map, the impact flow, and the flow as a map on (phi, K).";
    hovering_py::register_gil_gate();  // before anything can take the GIL from another thread
    register_enums(m);
    register_curve(m);
    auto truncated = m.def_submodule("truncated", "The truncated near-tangency family F_{eps1,eps2}.");
    register_truncated(truncated);
    auto flow = m.def_submodule("flow", "Potentials, the oscillators-step system, Sigma_h and the return map.");
    register_potential(flow);
    register_flow(flow);
    auto normal = m.def_submodule("normal", "The tangential curve (normal coordinates) and the flow map.");
    register_normal(normal);
    auto analysis = m.def_submodule("analysis", "The hovering area's samples, outcomes, estimate and default box.");
    register_analysis(analysis);
    m.def(
        "build_info",
        [] {
            py::list out;
            for (const auto& f : hovering::build_info()) {
                const py::object value = f.number ? py::object(py::int_(std::stoll(f.value))) : py::str(f.value);
                out.append(py::make_tuple(f.name, value));
            }
            return out;
        },
        "The core's build facts as (name, value) pairs (hovering::build_info): version, git commit, compiler, "
        "GSL, Eigen and SLEEF versions, SIMD width, platform, hardware threads.");
    register_pickles(m);  // after every class it adds pickling to
    // `from hovering._core.flow import X` needs the submodules in sys.modules (def_submodule only
    // sets them as attributes).
    auto modules = py::module_::import("sys").attr("modules");
    for (auto sub : {truncated, flow, normal, analysis}) modules[sub.attr("__name__")] = sub;
}
