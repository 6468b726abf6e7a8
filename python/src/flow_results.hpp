#pragma once
// Shared by the flow's bindings (return maps, flow-map iteration): the work counters as a dict
// and the per-orbit trajectories flattened into NumPy arrays.

#include <array>
#include <cstdint>
#include <cstring>
#include <vector>

#include "hovering/flow/return_map.hpp"
#include "pybind.hpp"
#include "signals.hpp"

namespace hovering_py {

/// Interned Python strings of these names, made once per call site (a function-local static) and
/// never freed: they outlive every dict they key. Making a key from a C string each time cost
/// ~1 us of a one-point call's result.
template <std::size_t N>
inline std::array<PyObject*, N> interned(const char* const (&names)[N]) {
    std::array<PyObject*, N> k{};
    for (std::size_t i = 0; i < N; ++i)
        if (!(k[i] = PyUnicode_InternFromString(names[i]))) throw py::error_already_set();
    return k;
}

/// A new C-contiguous NumPy array of T with these dimensions (uninitialised; data at
/// array_data), made with NumPy's C API: pybind11's array_t constructor builds shape and stride
/// vectors on the heap, ~0.1 us of each of a one-point result's nine small arrays.
template <class T, int N>
inline py::object small_array(const py::ssize_t (&dims)[N]) {
    auto& api = py::detail::npy_api::get();
    PyObject* descr = api.PyArray_DescrFromType_(py::detail::npy_format_descriptor<T>::value);
    if (!descr) throw py::error_already_set();
    Py_intptr_t d[N];
    for (int i = 0; i < N; ++i) d[i] = Py_intptr_t(dims[i]);
    PyObject* a = api.PyArray_NewFromDescr_(api.PyArray_Type_, descr, N, d, nullptr, nullptr, 0, nullptr);
    if (!a) throw py::error_already_set();
    return py::reinterpret_steal<py::object>(a);
}

/// The data of an array made by small_array.
template <class T>
inline T* array_data(const py::object& a) {
    return reinterpret_cast<T*>(py::detail::array_proxy(a.ptr())->data);
}

/// A dict of these keys, each None, kept as the template of keyed_dict (made once per call site:
/// a function-local static, never freed).
template <std::size_t N>
inline PyObject* key_template(const std::array<PyObject*, N>& keys) {
    PyObject* d = PyDict_New();
    if (!d) throw py::error_already_set();
    for (PyObject* k : keys)
        if (PyDict_SetItem(d, k, Py_None) != 0) throw py::error_already_set();
    return d;
}

/// A new dict with the template's keys (key_template), each None: a copy takes the template's table
/// whole, where inserting 15 keys one by one into an empty dict grew it twice.
inline py::dict keyed_dict(PyObject* tmpl) {
    PyObject* d = PyDict_Copy(tmpl);
    if (!d) throw py::error_already_set();
    return py::reinterpret_steal<py::dict>(d);
}

/// d[key] = value (key: one of interned()'s).
inline void set_item(py::dict& d, PyObject* key, const py::object& value) {
    if (PyDict_SetItem(d.ptr(), key, value.ptr()) != 0) throw py::error_already_set();
}

/// FlowWork as a dict of ints (the keys are the field names).
inline py::dict work_dict(const hovering::FlowWork& w) {
    static const auto k = interned({"field_evaluations", "coupling_evaluations", "wall_searches", "section_searches",
                                    "label_operations", "dense_samples", "steps"});
    static PyObject* const tmpl = key_template(k);
    py::dict d = keyed_dict(tmpl);
    set_item(d, k[0], py::int_(w.field_evaluations));
    set_item(d, k[1], py::int_(w.coupling_evaluations));
    set_item(d, k[2], py::int_(w.wall_searches));
    set_item(d, k[3], py::int_(w.section_searches));
    set_item(d, k[4], py::int_(w.label_operations));
    set_item(d, k[5], py::int_(w.dense_samples));
    set_item(d, k[6], py::int_(w.steps));
    return d;
}

/// The per-orbit vectors a batch records its trajectories into, and their flat NumPy form.
class Trajectories {
public:
    /// n orbits sampled every dt, at most max_points points each; dt = 0 records nothing.
    Trajectories(py::ssize_t n, double dt, std::int64_t max_points) {
        if (dt == 0) return;
        points_.resize(std::size_t(n));
        kinds_.resize(std::size_t(n));
        truncated_ = py::array_t<bool>(n);
        out_.dt = dt;
        out_.max_points_per_orbit = max_points;
        out_.points = points_.data();
        out_.kinds = kinds_.data();
        static_assert(sizeof(bool) == sizeof(std::int8_t), "bool flags are written as int8");
        out_.truncated = reinterpret_cast<std::int8_t*>(truncated_.mutable_data());
    }
    /// What the core writes into (inactive when nothing is recorded).
    const hovering::TrajectoryOutput& output() const { return out_; }
    /// Put trajectory (N, 5), trajectory_index (n + 1), trajectory_kind (N) and
    /// trajectory_truncated (n) into d (nothing when inactive); frees the per-orbit vectors.
    void put(py::dict& d) {
        if (!out_.active()) return;
        const py::ssize_t n = py::ssize_t(points_.size());
        py::array_t<std::int64_t> index(n + 1);
        std::int64_t* ix = index.mutable_data();
        ix[0] = 0;
        for (py::ssize_t i = 0; i < n; ++i) ix[i + 1] = ix[i] + std::int64_t(kinds_[std::size_t(i)].size());
        const py::ssize_t total = py::ssize_t(ix[n]);
        py::array_t<double> pts({total, py::ssize_t(5)});
        py::array_t<std::int8_t> kind(total);
        double* p = pts.mutable_data();
        std::int8_t* k = kind.mutable_data();
        {
            GilRelease release;
            for (py::ssize_t i = 0; i < n; ++i) {
                auto& v = points_[std::size_t(i)];
                auto& c = kinds_[std::size_t(i)];
                if (!v.empty()) std::memcpy(p + 5 * ix[i], v.data(), v.size() * sizeof(double));
                if (!c.empty()) std::memcpy(k + ix[i], c.data(), c.size());
                std::vector<double>().swap(v);
                std::vector<std::int8_t>().swap(c);
            }
        }
        d["trajectory"] = pts;
        d["trajectory_index"] = index;
        d["trajectory_kind"] = kind;
        d["trajectory_truncated"] = truncated_;
    }

private:
    std::vector<std::vector<double>> points_;
    std::vector<std::vector<std::int8_t>> kinds_;
    py::array_t<bool> truncated_;
    hovering::TrajectoryOutput out_;
};

}  // namespace hovering_py
