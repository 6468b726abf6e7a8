#pragma once
// Shared by the flow's bindings (return maps, flow-map iteration): the work counters as a dict
// and the per-orbit trajectories flattened into NumPy arrays.

#include <cstdint>
#include <cstring>
#include <vector>

#include "hovering/flow/return_map.hpp"
#include "pybind.hpp"
#include "signals.hpp"

namespace hovering_py {

/// FlowWork as a dict of ints (the keys are the field names).
inline py::dict work_dict(const hovering::FlowWork& w) {
    py::dict d;
    d["field_evaluations"] = w.field_evaluations;
    d["coupling_evaluations"] = w.coupling_evaluations;
    d["wall_searches"] = w.wall_searches;
    d["section_searches"] = w.section_searches;
    d["label_operations"] = w.label_operations;
    d["dense_samples"] = w.dense_samples;
    d["steps"] = w.steps;
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
