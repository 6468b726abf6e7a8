// hovering._core.analysis: the hovering area's numerics (hovering/analysis/hovering_area.hpp), which
// hovering.hovering_area calls: the samples of an index range, the per-sample outcomes (GIL
// released, Ctrl-C honoured, progress reported), the estimate from them, and the default box.
#include <atomic>
#include <string>
#include <vector>

#include "hovering/analysis/hovering_area.hpp"
#include "pybind.hpp"
#include "signals.hpp"

using namespace hovering;

namespace {

using i8array = py::array_t<std::int8_t, py::array::c_style | py::array::forcecast>;
using i64array = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;

template <class T>
py::array_t<T> as_array(const std::vector<T>& v) {
    return py::array_t<T>(py::ssize_t(v.size()), v.data());
}

/// 0/1 flags as a NumPy bool array, filled here: NumPy's own cast (astype) releases the GIL for a large
/// array and takes it back inside this binding's frames, which a daemon thread must not do while the
/// interpreter exits (python/src/gil.hpp; CPython ends it there, through our C++ frames).
py::array_t<bool> as_bool_array(const std::vector<std::int8_t>& v) {
    py::array_t<bool> a(py::ssize_t(v.size()));
    bool* p = a.mutable_data();
    for (std::size_t i = 0; i < v.size(); ++i) p[i] = v[i] != 0;
    return a;
}

template <class T>
std::vector<T> as_vector(const py::array_t<T, py::array::c_style | py::array::forcecast>& a, std::int64_t n,
                         const char* name) {
    if (a.ndim() != 1 || a.size() != n)
        throw py::value_error(std::string(name) + " must be a 1-D array of " + std::to_string(n) + " entries");
    return std::vector<T>(a.data(), a.data() + n);
}

/// Outcomes of the points (phi, K) under F_0 and F_eps; run(opt) does the core call.
template <class Run>
py::dict outcomes(const darray& phi, const darray& K, std::int64_t n_steps, int n_threads, py::object progress,
                  Run&& run) {
    if (phi.ndim() != 1 || K.ndim() != 1 || phi.size() != K.size())
        throw py::value_error("phi and K must be 1-D arrays of the same size");
    if (n_steps < 0) throw py::value_error("n_steps must be >= 0, got " + std::to_string(n_steps));
    const std::int64_t n = phi.size();
    std::atomic<bool> cancel{false};
    std::atomic<std::int64_t> done{0};
    HoveringAreaOptions opt;
    opt.n_steps = n_steps;
    opt.n_threads = n_threads;
    opt.cancel = &cancel;
    const hovering_py::ProgressReport report{&done, 2 * n * n_steps, std::move(progress)};
    if (report.active()) opt.progress = &done;
    HoveringOutcomes r;
    const bool interrupted = hovering_py::run_watched([&] { r = run(phi.data(), K.data(), n, opt); }, cancel,
                                                      double(n) * double(n_steps) >= 1e6, &report);
    py::dict d;
    d["status_F0"] = as_array(r.status_F0);
    d["status"] = as_array(r.status);
    d["steps_done"] = as_array(r.steps_done);
    d["visited"] = as_array(r.visited);
    d["interrupted"] = interrupted || r.interrupted;
    return d;
}

template <class Map>
void bind_outcomes(py::module_& m) {
    m.def(
        "hovering_outcomes",
        [](const Map& map, const darray& phi, const darray& K, std::int64_t n_steps, int n_threads,
           py::object progress) {
            return outcomes(phi, K, n_steps, n_threads, std::move(progress),
                            [&](const double* p, const double* k, std::int64_t n, const HoveringAreaOptions& o) {
                                return hovering_outcomes(map, p, k, n, o);
                            });
        },
        py::arg("m"), py::arg("phi"), py::arg("K"), py::arg("n_steps"), py::arg("n_threads") = 0,
        py::arg("progress") = py::none());
}

}  // namespace

void register_analysis(py::module_& m) {
    m.def(
        "sample_grid",
        [](std::int64_t samples, double K_low) {
            const SampleGrid g = sample_grid(samples, K_low);
            return py::make_tuple(g.n_phi, g.n_K);
        },
        py::arg("samples"), py::arg("K_low"), "(n_phi, n_K) of the stratified grid of hovering_area's box.");
    m.def(
        "stratified_samples",
        [](std::int64_t samples, double K_low, std::uint64_t seed, std::int64_t lo, py::object hi) {
            const std::int64_t n = sample_grid(samples, K_low).size();
            const std::int64_t h = hi.is_none() ? n : hi.cast<std::int64_t>();
            if (lo < 0 || h < lo || h > n)
                throw py::value_error("the sample range [" + std::to_string(lo) + ", " + std::to_string(h) +
                                      ") must lie in [0, " + std::to_string(n) + "]");
            darray phi(h - lo), K(h - lo);
            stratified_samples(samples, K_low, seed, lo, h, phi.mutable_data(), K.mutable_data());
            return py::make_tuple(phi, K);
        },
        py::arg("samples"), py::arg("K_low"), py::arg("seed"), py::arg("lo") = 0, py::arg("hi") = py::none(),
        "Samples lo..hi-1 (phi, K) of hovering_area's box: numpy's default_rng(seed) stream, jumped ahead to lo.");
    bind_outcomes<TruncatedMap>(m);
    bind_outcomes<TruncatedFamily>(m);
    m.def(
        "hovering_outcomes",
        [](const FlowMap& map, const FlowMap& map0, const darray& phi, const darray& K, std::int64_t n_steps,
           int n_threads, py::object progress) {
            return outcomes(phi, K, n_steps, n_threads, std::move(progress),
                            [&](const double* p, const double* k, std::int64_t n, const HoveringAreaOptions& o) {
                                return hovering_outcomes(map, map0, p, k, n, o);
                            });
        },
        py::arg("m"), py::arg("m0"), py::arg("phi"), py::arg("K"), py::arg("n_steps"), py::arg("n_threads") = 0,
        py::arg("progress") = py::none(),
        "Per-sample outcomes (status_F0, status, steps_done, visited) of F_0 then F_eps with early exit from "
        "{J_0u, J_0}.");
    m.def(
        "hovering_estimate",
        [](const i8array& status_F0, const i8array& status, const i64array& steps_done, const i8array& visited,
           const darray& K, std::int64_t n_steps, double K_low, bool keep_points) {
            if (K.ndim() != 1) throw py::value_error("K must be a 1-D array");
            const std::int64_t n = K.size();
            HoveringOutcomes r;
            r.status_F0 = as_vector(status_F0, n, "status_F0");
            r.status = as_vector(status, n, "status");
            r.steps_done = as_vector(steps_done, n, "steps_done");
            r.visited = as_vector(visited, n, "visited");
            const HoveringAreaResult h = hovering_estimate(r, K.data(), n, n_steps, K_low, keep_points);
            py::dict d;
            d["area"] = h.area;
            d["error"] = h.error;
            d["sampling_error"] = h.sampling_error;
            d["iteration_error"] = h.iteration_error;
            d["area_N4"] = h.area_quarter;
            d["area_N2"] = h.area_half;
            d["n_samples"] = h.n_samples;
            d["impact_fraction_F0"] = h.impact_fraction_F0;
            d["floor_touched"] = h.floor_touched;
            d["area_both_sides"] = h.area_both_sides;
            d["unresolved"] = h.unresolved;
            if (keep_points) {
                d["hovering"] = as_bool_array(h.hovering);
                d["both_sides"] = as_bool_array(h.both_sides);
            }
            return d;
        },
        py::arg("status_F0"), py::arg("status"), py::arg("steps_done"), py::arg("visited"), py::arg("K"),
        py::arg("n_steps"), py::arg("K_low"), py::arg("keep_points") = false,
        "The estimates at N/4, N/2, N, the error bar and the counts from the samples' outcomes (pieces "
        "concatenated in index order give the single-process answer).");
    m.def(
        "part_area",
        [](std::int64_t count, std::int64_t n, double K_low) {
            const PartArea a = part_area(count, n, K_low);
            return py::make_tuple(a.area, a.sampling_error);
        },
        py::arg("count"), py::arg("n"), py::arg("K_low"),
        "(area, sampling_error) of the part of hovering_area's box holding count of its n samples.");
    m.def("default_depth", &default_depth, py::arg("eps"), py::arg("Omega0"), py::arg("forcing"),
          "Depth of hovering_area's default box below K = 0 (inf when not finite and positive).");
    m.def("box_floor", &box_floor, py::arg("band_lo"),
          "The deepest box bottom inside a band whose lower end is band_lo: band_lo (1 - 1e-9).");
    m.def("default_K_low", &default_K_low, py::arg("eps"), py::arg("Omega0"), py::arg("forcing"), py::arg("band_lo"),
          "Bottom of hovering_area's default box: -default_depth (0.1 at eps = 0), raised to box_floor(band_lo).");
    m.def(
        "first_order_shape",
        [](const std::vector<double>& b, double Omega0, const darray& psi) {
            darray out(psi.request().shape);
            const double* in = psi.data();
            double* o = out.mutable_data();
            for (py::ssize_t i = 0; i < psi.size(); ++i) o[i] = first_order_shape(b, Omega0, in[i]);
            return out;
        },
        py::arg("forcing"), py::arg("Omega0"), py::arg("psi"),
        "G(psi) = sum_k b_k (1 - cos(k psi)) / (2 sin(k Omega0 / 2)) at each psi.");
}
