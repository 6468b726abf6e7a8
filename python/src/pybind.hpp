#pragma once
// Shared by every binding file: pybind11 includes and the array conventions of the module.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

namespace py = pybind11;

#include <string>

#include "hovering/tangent.hpp"

/// The value of a Python real number: int, float, a NumPy scalar or a 0-d NumPy array of integer or
/// float dtype (np.array(2.0)); not bool, str, complex, None or an array with a dimension (even of one
/// element). False, with no Python error set, for anything else (or an int beyond a double's range).
inline bool as_real(py::handle o, double* v) {
    // Leaked on purpose: a static py::object would be released after the interpreter is gone.
    static PyObject* real = py::object(py::module_::import("numbers").attr("Real")).release().ptr();
    bool number = !PyBool_Check(o.ptr()) && PyObject_IsInstance(o.ptr(), real) == 1;
    // A 0-d array is what NumPy reductions and indexing with () return; it is not registered as
    // numbers.Real, but float() reads it exactly like the scalar it holds.
    if (!number && py::isinstance<py::array>(o)) {
        const auto a = py::reinterpret_borrow<py::array>(o);
        const char kind = a.dtype().kind();
        number = a.ndim() == 0 && (kind == 'i' || kind == 'u' || kind == 'f');
    }
    if (number) {
        *v = PyFloat_AsDouble(o.ptr());
        if (!(*v == -1.0 && PyErr_Occurred())) return true;
    }
    PyErr_Clear();
    return false;
}

/// repr(o), cut to `width` characters, for messages.
inline std::string short_repr(py::handle o, std::size_t width = 60) {
    std::string r = py::repr(o).cast<std::string>();
    if (r.size() > width) r = r.substr(0, width - 3) + "...";
    return r;
}

/// A Python real number (see as_real) as a double, or a ValueError "who: name must be a real
/// number, got ..." instead of pybind11's overload listing.
inline double real_arg(py::handle o, const char* who, const char* name) {
    double v;
    if (as_real(o, &v)) return v;
    throw py::value_error(std::string(who) + ": " + name +
                          " must be a real number (within the range of a double), got " + short_repr(o));
}

/// Input arrays: C-contiguous doubles, converted (copied) only when the caller's array is not.
using darray = py::array_t<double, py::array::c_style | py::array::forcecast>;

namespace hovering_py {
/// Arrays for record "jacobian" of n orbits, wired into t and put into d: jacobian_q (n, 2, 2),
/// jacobian_log (n, 2), jacobian_r12 (n,), jacobian_status (n,).
inline void tangent_outputs(py::ssize_t n, hovering::TangentOutput& t, py::dict& d) {
    py::array_t<double> q({n, py::ssize_t(2), py::ssize_t(2)}), lr({n, py::ssize_t(2)}), u(n);
    py::array_t<std::int8_t> st(n);
    t.q = q.mutable_data();
    t.log_r = lr.mutable_data();
    t.r12 = u.mutable_data();
    t.status = st.mutable_data();
    d["jacobian_q"] = q;
    d["jacobian_log"] = lr;
    d["jacobian_r12"] = u;
    d["jacobian_status"] = st;
}
}  // namespace hovering_py

/// Register Region, Status, FlowStatus, Geometry and Kernel (enum.IntEnum classes).
void register_enums(py::module_& m);

/// Register the closed curve K(phi) (hovering._core.Curve).
void register_curve(py::module_& m);

namespace hovering {
struct StopCondition;
}
/// The stop condition of an iteration from the Python layer's side code (0 none, 1 above, 2
/// below) and its core Curve (None without one).
hovering::StopCondition stop_condition(int side, py::object curve);

/// Register the truncated-map classes (TruncatedMap, TruncatedFamily).
void register_truncated(py::module_& m);

/// Register the potentials and onset parameters.
void register_potential(py::module_& m);

/// Register the flow: FlowSystem, FlowOptions, points of Sigma_h, return maps.
void register_flow(py::module_& m);

/// Register the bridge: TangentialCurve and FlowMap.
void register_normal(py::module_& m);
/// hovering._core.analysis: the hovering area's samples, outcomes, estimate and default box.
void register_analysis(py::module_& m);

/// Add pickling to the truncated maps, FlowSystem, FlowOptions and TangentialCurve (after they are registered).
void register_pickles(py::module_& core);
