// Binding of the core's Curve (a closed curve K(phi), the periodic cubic spline through uniform
// samples) and of the stop conditions the iterations take: the one evaluation Python calls.
#include <memory>
#include <vector>

#include "gil.hpp"
#include "hovering/curve.hpp"
#include "pybind.hpp"

using namespace hovering;

namespace {

// Curve values at an array of angles (any shape), with the GIL released.
py::array_t<double> evaluate(const Curve& c,
                             const py::array_t<double, py::array::c_style | py::array::forcecast>& phi) {
    py::array_t<double> out(std::vector<py::ssize_t>(phi.shape(), phi.shape() + phi.ndim()));
    const double* p = phi.data();
    double* o = out.mutable_data();
    const py::ssize_t n = phi.size();
    {
        hovering_py::GilRelease release;
        for (py::ssize_t i = 0; i < n; ++i) o[i] = c(p[i]);
    }
    return out;
}

}  // namespace

void register_curve(py::module_& m) {
    py::class_<Curve, std::shared_ptr<Curve>>(m, "Curve", "Compiled closed curve K(phi); use hovering.Curve.")
        .def(py::init([](const darray& K) {
                 if (K.ndim() != 1) throw py::value_error("curve samples K must be a 1-D array");
                 std::vector<double> v(K.data(), K.data() + K.size());
                 hovering_py::GilRelease release;  // the spline solve is O(n)
                 return std::make_shared<Curve>(std::move(v));
             }),
             py::arg("K"))
        .def("evaluate", &evaluate, py::arg("phi"),
             "K at the angles phi (|phi| <= 1e6, wrapped to [-pi, pi) first; NaN gives NaN).")
        .def_property_readonly(
            "samples", [](const Curve& c) { return py::array_t<double>(py::ssize_t(c.size()), c.samples().data()); })
        .def_property_readonly(
            "cells",
            [](const Curve& c) { return py::array_t<double>({py::ssize_t(c.size()), py::ssize_t(4)}, c.cells()); },
            "Cell polynomials (y, b, c, d) per cell: y + s (b + s (c + s d)), s in [0, 1).")
        .def_property_readonly("lower", &Curve::lower, "A number at or below every value of the curve.")
        .def_property_readonly("upper", &Curve::upper, "A number at or above every value of the curve.")
        .def_property_readonly("max_samples", [](const Curve&) { return Curve::kMaxSamples; });
}

/// The stop condition of an iteration from the Python layer's (side code, core Curve or None).
StopCondition stop_condition(int side, py::object curve) {
    StopCondition s;
    if (side == 0) return s;
    if (side != 1 && side != 2)
        throw py::value_error("stop side must be 0 (none), 1 (above) or 2 (below), got " + std::to_string(side));
    if (curve.is_none()) throw py::value_error("a stop condition needs a curve");
    s.side = side == 1 ? StopSide::Above : StopSide::Below;
    s.curve = curve.cast<std::shared_ptr<Curve>>();
    return s;
}
