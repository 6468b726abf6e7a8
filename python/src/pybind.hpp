#pragma once
// Shared by every binding file: pybind11 includes and the array conventions of the module.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

namespace py = pybind11;

#include <string>

/// A Python real number (int, float, numpy scalar; not bool, str, complex, None or an array) as a
/// double, or a ValueError "who: name must be a real number, got ..." instead of pybind11's
/// overload listing.
inline double real_arg(py::handle o, const char* who, const char* name) {
    // Leaked on purpose: a static py::object would be released after the interpreter is gone.
    static PyObject* real = py::object(py::module_::import("numbers").attr("Real")).release().ptr();
    if (!PyBool_Check(o.ptr()) && PyObject_IsInstance(o.ptr(), real) == 1) {
        const double v = PyFloat_AsDouble(o.ptr());
        if (!(v == -1.0 && PyErr_Occurred())) return v;
    }
    PyErr_Clear();
    std::string r = py::repr(o).cast<std::string>();
    if (r.size() > 60) r = r.substr(0, 57) + "...";
    throw py::value_error(std::string(who) + ": " + name + " must be a real number (within the range of a double), got " + r);
}

/// Input arrays: C-contiguous doubles, converted (copied) only when the caller's array is not.
using darray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// Register Region, Status, FlowStatus, Geometry and Kernel (enum.IntEnum classes).
void register_enums(py::module_& m);

/// Register the truncated-map classes (TruncatedMap, TruncatedFamily).
void register_truncated(py::module_& m);

/// Register the potentials and onset parameters.
void register_potential(py::module_& m);

/// Register the flow: FlowSystem, FlowOptions, points of Sigma_h, return maps.
void register_flow(py::module_& m);

/// Register the bridge: TangentialCurve and FlowMap.
void register_normal(py::module_& m);
