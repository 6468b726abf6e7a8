// hovering._core.scene: the C++ reading of sweep scenes and its point runner, exposed so the test
// suite can hold them to Python's schema, messages and numbers (the sweep executable uses the same code).
#include <atomic>

#include "hovering/scene/sweep_run.hpp"
#include "hovering/scene/sweep_scene.hpp"
#include "pybind.hpp"
#include "signals.hpp"

using namespace hovering::scene;

namespace {

py::dict map_dict(const MapParams& m) {
    py::dict d;
    d["Omega0"] = m.Omega0;
    d["theta_w"] = m.theta_w;
    d["tau0"] = m.tau0;
    d["tau1"] = m.tau1;
    d["lam"] = m.lam;
    return d;
}

py::dict potential_dict(const PotentialSpec& p) {
    py::dict d;
    d["kind"] = p.kind;
    d["omega"] = p.omega;
    d["alpha"] = p.kind == "tan" ? py::object(py::float_(p.alpha)) : py::object(py::none());
    return d;
}

/// The parsed scene as plain Python values (the same names as Python's spec dataclasses).
py::dict scene_dict(const SweepScene& s) {
    py::dict d;
    d["name"] = s.name;
    d["kind"] = s.kind;
    d["title"] = s.title;
    d["output"] = s.output;
    d["dpi"] = s.dpi;
    d["n_steps"] = s.n_steps;
    d["samples"] = s.samples;
    d["seed"] = s.seed;
    d["eps"] = py::tuple(py::cast(s.eps));
    if (s.kind == "hovering_area") {
        py::list series;
        for (const auto& x : s.series) {
            py::dict sd = map_dict(x.map);
            sd["label"] = x.label;
            sd["golden_c"] = x.golden ? py::object(py::float_(x.golden_c)) : py::object(py::none());
            if (x.golden) {
                sd["Omega0"] = py::none();
                sd["theta_w"] = py::none();
            }
            sd["K_low"] = x.has_K_low ? py::object(py::float_(x.K_low)) : py::object(py::none());
            sd["color"] = x.color.empty() ? py::object(py::none()) : py::object(py::str(x.color));
            series.append(sd);
        }
        d["series"] = series;
    } else {
        py::dict sys;
        sys["V1"] = potential_dict(s.system.V1);
        sys["V2"] = potential_dict(s.system.V2);
        py::list terms;
        for (const auto& t : s.system.coupling) terms.append(py::make_tuple(t[0], int(t[1]), int(t[2])));
        sys["coupling"] = py::tuple(terms);
        sys["eps"] = s.system.eps;
        sys["qw1"] = s.system.qw1;
        sys["qw2"] = s.system.qw2;
        sys["geometry"] = s.system.geometry;
        d["system"] = sys;
        d["h"] = s.h;
        py::dict integ;
        integ["stepper"] = s.integrator.stepper;
        integ["rtol"] = s.integrator.rtol;
        integ["atol"] = s.integrator.atol;
        integ["accuracy"] = s.integrator.accuracy == s.integrator.accuracy ? py::object(py::float_(s.integrator.accuracy))
                                                                            : py::object(py::none());
        d["integrator"] = integ;
        d["models"] = py::tuple(py::cast(s.models));
    }
    return d;
}

}  // namespace

void register_scene(py::module_& m) {
    m.def(
        "parse_sweep_scene", [](const std::string& text, const std::string& where) { return scene_dict(parse_sweep_scene(text, where)); },
        py::arg("text"), py::arg("where") = "scene",
        "The C++ reading of a sweep scene (TOML text) as a dict; ValueError with Python's message for a bad one.");
    m.def(
        "run_point",
        [](const std::string& text, const std::string& where, std::size_t index, bool quick, int n_threads) {
            const SweepScene s = parse_sweep_scene(text, where);
            const auto points = sweep_points(s);
            if (index >= points.size())
                throw py::index_error("point " + std::to_string(index) + " of a scene with " +
                                      std::to_string(points.size()) + " points");
            const SweepCounts c = sweep_counts(s, quick);
            std::atomic<bool> cancel{false};
            SweepRow row;
            const bool stopped = hovering_py::run_watched([&] { row = run_point(s, points[index], c, n_threads, &cancel); }, cancel, true);
            if (stopped || row.interrupted) {
                PyErr_SetNone(PyExc_KeyboardInterrupt);
                throw py::error_already_set();
            }
            py::dict d;
            for (const auto& [k, v] : row.values) d[py::str(k)] = v;
            py::dict key;
            for (const auto& [k, v] : point_parameters(s, points[index], c)) key[py::str(k)] = v;
            d["key"] = key;
            return d;
        },
        py::arg("text"), py::arg("where"), py::arg("index"), py::arg("quick"), py::arg("n_threads") = 0,
        "Run point `index` of a sweep scene with the C++ runner of hovering_sweep: its result values and key.");
}
