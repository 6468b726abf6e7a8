#pragma once
// Shared by every binding file: pybind11 includes and the array conventions of the module.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

namespace py = pybind11;

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
