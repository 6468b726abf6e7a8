// Bindings of the truncated family (MapCore<...>): vectorised single steps and the batch iteration.
//
// Every loop over user arrays runs with the GIL released: the core only reads the input buffers
// (owned by the caller's arrays, kept alive by this frame) and writes freshly allocated outputs.

#include <atomic>
#include <cmath>

#include "hovering/truncated/map.hpp"
#include "pybind.hpp"
#include "signals.hpp"

using namespace hovering;

namespace {

std::vector<py::ssize_t> shape_of(const darray& a) {
    return {a.shape(), a.shape() + a.ndim()};
}

void same_shape(const darray& a, const darray& b, const char* an, const char* bn) {
    if (shape_of(a) != shape_of(b)) throw py::value_error(std::string(an) + " and " + bn + " must have the same shape");
}

// Apply a scalar (phi, K) -> (x, y) member elementwise.
template <class Map, class Fn>
py::tuple map2(const Map& m, const darray& phi, const darray& K, Fn fn) {
    same_shape(phi, K, "phi", "K");
    darray o1(shape_of(phi)), o2(shape_of(phi));
    const double *p = phi.data(), *k = K.data();
    double *a = o1.mutable_data(), *b = o2.mutable_data();
    const py::ssize_t n = phi.size();
    {
        hovering_py::GilRelease release;
        for (py::ssize_t i = 0; i < n; ++i) {
            auto r = fn(m, p[i], k[i]);
            a[i] = r.first;
            b[i] = r.second;
        }
    }
    return py::make_tuple(o1, o2);
}

// Runs the batch iteration with Ctrl-C watched (signals.hpp), so a long run can be interrupted and
// still hand back everything computed so far.
template <class Map>
py::dict iterate(const Map& m, const darray& phi0, const darray& K0, std::int64_t n_steps, bool record_orbit,
                 bool record_regions, bool record_rotation, unsigned exit_mask, bool stop_on_exit, int n_threads,
                 const std::string& kernel, double sin_ulp, bool record_visited, py::object progress,
                 std::int64_t every, int stop_side, py::object stop_curve, bool record_extrema, bool record_residence,
                 bool record_jacobian) {
    if (phi0.ndim() != 1 || K0.ndim() != 1) throw py::value_error("phi0 and K0 must be 1-D arrays");
    same_shape(phi0, K0, "phi0", "K0");
    if (n_steps < 0) throw py::value_error("n_steps must be >= 0, got " + std::to_string(n_steps));
    if (every < 1) throw py::value_error("every must be >= 1, got " + std::to_string(every));
    IterateOptions opt;
    opt.n_steps = n_steps;
    opt.every = every;
    opt.stop = stop_condition(stop_side, std::move(stop_curve));
    opt.exit_mask = exit_mask;
    opt.stop_on_exit = stop_on_exit;
    opt.n_threads = n_threads;
    if (kernel == "simd")
        opt.kernel = Kernel::Simd;
    else if (kernel == "scalar")
        opt.kernel = Kernel::Scalar;
    else
        throw py::value_error("kernel must be 'simd' or 'scalar', got '" + kernel + "'");
    if (sin_ulp == 3.5)
        opt.fast_sin = true;
    else if (sin_ulp != 1.0)
        throw py::value_error("sin_ulp must be 1.0 or 3.5 (max error of the SIMD sin in ulp), got " +
                              std::to_string(sin_ulp));

    const py::ssize_t n = phi0.shape(0);
    py::dict res;
    darray phi_f(n), K_f(n);
    py::array_t<std::int8_t> status(n);
    py::array_t<std::int64_t> steps(n);
    IterateOutput out;
    out.phi_final = phi_f.mutable_data();
    out.K_final = K_f.mutable_data();
    out.status = status.mutable_data();
    out.steps_done = steps.mutable_data();
    res["phi_final"] = phi_f;
    res["K_final"] = K_f;
    res["status"] = status;
    res["steps_done"] = steps;
    const py::ssize_t n_states = py::ssize_t(recorded_states(n_steps, every)),
                      n_returns = py::ssize_t(recorded_returns(n_steps, every));
    if (record_orbit) {
        darray op({n, n_states}), ok({n, n_states});
        out.orbit_phi = op.mutable_data();
        out.orbit_K = ok.mutable_data();
        res["phi"] = op;
        res["K"] = ok;
    }
    if (record_regions) {
        py::array_t<std::int8_t> reg({n, n_returns});
        out.regions = reg.mutable_data();
        res["region"] = reg;
    }
    if (record_rotation) {
        darray rot(n);
        out.rotation = rot.mutable_data();
        res["rotation"] = rot;
    }
    if (exit_mask) {
        py::array_t<std::int64_t> ex(n);
        out.exit_step = ex.mutable_data();
        res["exit_step"] = ex;
    }
    if (record_visited) {
        py::array_t<std::int8_t> vis(n);
        out.visited = vis.mutable_data();
        res["visited"] = vis;
    }
    if (record_extrema) {
        darray lo(n), hi(n);
        out.K_min = lo.mutable_data();
        out.K_max = hi.mutable_data();
        res["K_min"] = lo;
        res["K_max"] = hi;
    }
    if (record_residence) {
        py::array_t<std::int64_t> r({n, py::ssize_t(kRegionCount)});
        out.residence = r.mutable_data();
        res["residence"] = r;
    }
    if (opt.stop.active()) {
        py::array_t<std::int64_t> st(n);
        out.stop_step = st.mutable_data();
        res["stop_step"] = st;
    }
    if (record_jacobian) hovering_py::tangent_outputs(n, out.tangent, res);

    std::atomic<bool> cancel{false};
    std::atomic<std::int64_t> done{0};
    opt.cancel = &cancel;
    const hovering_py::ProgressReport report{&done, std::int64_t(n) * n_steps, std::move(progress)};
    if (report.active()) opt.progress = &done;  // no counting at all otherwise
    // Short runs (< 2e6 orbit-steps, ~5 ms) get no watcher thread unless progress is reported: its
    // ~50 us would dominate.
    const bool interrupted = hovering_py::run_watched([&] { m.iterate(phi0.data(), K0.data(), n, opt, out); }, cancel,
                                                      double(n) * double(n_steps) >= 2e6, &report);
    res["interrupted"] = interrupted;
    return res;
}

template <class Map, class Cls>
void bind_common(Cls& cls) {
    cls.def("_step",
            [](const Map& m, const darray& phi, const darray& K) {
                return map2(m, phi, K, [](const Map& mm, double p, double k) { return mm.step(p, k); });
            })
        .def("_step1",
             [](const Map& m, double phi, double K) {
                 // One point, a tuple back (no arrays): _step's numbers for a scalar.
                 const auto r = m.step(phi, K);
                 return py::make_tuple(r.first, r.second);
             })
        .def("_step_inverse1",
             [](const Map& m, double phi, double K) {
                 const auto r = m.step_inverse(phi, K);
                 return py::make_tuple(r.first, r.second);
             })
        .def("_step_inverse",
             [](const Map& m, const darray& phi, const darray& K) {
                 return map2(m, phi, K, [](const Map& mm, double p, double k) { return mm.step_inverse(p, k); });
             })
        .def("_jacobian",
             [](const Map& m, const darray& phi, const darray& K) {
                 // Flat (n,) inputs: images, Jacobians (n, 2, 2), regions and statuses.
                 same_shape(phi, K, "phi", "K");
                 const py::ssize_t n = phi.size();
                 darray x1(n), y1(n), J({n, py::ssize_t(2), py::ssize_t(2)});
                 py::array_t<std::int8_t> reg(n), st(n);
                 const double *p = phi.data(), *k = K.data();
                 double *a = x1.mutable_data(), *b = y1.mutable_data(), *j = J.mutable_data();
                 auto *r = reg.mutable_data(), *t = st.mutable_data();
                 {
                     hovering_py::GilRelease release;
                     for (py::ssize_t i = 0; i < n; ++i) {
                         const StepJacobian sj = m.step_jacobian(p[i], k[i]);
                         a[i] = sj.phi;
                         b[i] = sj.K;
                         for (int c = 0; c < 4; ++c) j[4 * i + c] = sj.J[c];
                         r[i] = static_cast<std::int8_t>(sj.region);
                         t[i] = static_cast<std::int8_t>(sj.status);
                     }
                 }
                 py::dict d;
                 d["x"] = x1;
                 d["y"] = y1;
                 d["J"] = J;
                 d["region"] = reg;
                 d["status"] = st;
                 return d;
             })
        .def("_region_rotation",
             [](const Map& m, const darray& phi, const darray& K, const std::string& who) {
                 same_shape(phi, K, "phi", "K");
                 py::array_t<std::int8_t> reg(shape_of(phi));
                 darray rot(shape_of(phi));
                 const double *p = phi.data(), *k = K.data();
                 auto* r = reg.mutable_data();
                 auto* w = rot.mutable_data();
                 {
                     hovering_py::GilRelease release;
                     for (py::ssize_t i = 0; i < phi.size(); ++i) {
                         const auto c = m.classify_point(p[i], k[i], who.c_str());
                         r[i] = static_cast<std::int8_t>(c.first);
                         w[i] = c.second;
                     }
                 }
                 return py::make_tuple(reg, rot);
             })
        .def("_arcs",
             [](const Map& m, const darray& K) {
                 // (n, 6): |J_1|, |J_R|, |J_0|, and the left ends of J_1, J_R, J_0 (NaN for K >= 0).
                 darray out({K.size(), py::ssize_t(6)});
                 double* o = out.mutable_data();
                 const double* k = K.data();
                 for (py::ssize_t i = 0; i < K.size(); ++i) {
                     const ArcLengths a = m.arc_lengths(k[i]);
                     o[6 * i + 0] = a.J1;
                     o[6 * i + 1] = a.JR;
                     o[6 * i + 2] = k[i] < 0 ? 2 * M_PI - a.J1 - a.JR : 2 * M_PI;
                     if (k[i] < 0) {
                         const auto s = m.arc_starts(k[i]);
                         for (int j = 0; j < 3; ++j) o[6 * i + 3 + j] = s[std::size_t(j)];
                     } else {
                         for (int j = 0; j < 3; ++j) o[6 * i + 3 + j] = std::nan("");
                     }
                 }
                 return out;
             })
        .def("_iterate", &iterate<Map>, py::arg("phi0"), py::arg("K0"), py::arg("n_steps"), py::arg("record_orbit"),
             py::arg("record_regions"), py::arg("record_rotation"), py::arg("exit_mask"), py::arg("stop_on_exit"),
             py::arg("n_threads"), py::arg("kernel"), py::arg("sin_ulp"), py::arg("record_visited") = false,
             py::arg("progress") = py::none(), py::arg("every") = 1, py::arg("stop_side") = 0,
             py::arg("stop_curve") = py::none(), py::arg("record_extrema") = false, py::arg("record_residence") = false,
             py::arg("record_jacobian") = false)
        .def_property_readonly("eps", &Map::eps, "Perturbation amplitude eps.")
        .def(
            "valid_band", [](const Map& m) { return py::make_tuple(m.band().lo, m.band().hi); },
            "Open interval (lo, hi) of K on which the map is defined: all three arcs in (0, 2 pi) and the\n"
            "rotation |Omega(K)| <= 1e6 (beyond, one step keeps less than ~2e-10 rad of phi).");
}

}  // namespace

void register_truncated(py::module_& mod) {
    py::class_<TruncatedMap> tm(mod, "TruncatedMap", "Compiled F_eps (eq:truncatedmap); use hovering.TruncatedMap.");
    tm.def(py::init([](double eps, double Omega0, double theta_w, double tau0, double tau1, double lam, double K_max) {
               return make_truncated_map(eps, Omega0, theta_w, tau0, tau1, lam, K_max);
           }),
           py::arg("eps"), py::arg("Omega0"), py::arg("theta_w"), py::arg("tau0"), py::arg("tau1"), py::arg("lam"),
           py::arg("K_max"))
        .def_property_readonly("Omega0", [](const TruncatedMap& m) { return m.arcs().Omega0; })
        .def_property_readonly("theta_w", [](const TruncatedMap& m) { return m.arcs().theta_w; })
        .def_property_readonly("tau0", [](const TruncatedMap& m) { return m.arcs().tau0; })
        .def_property_readonly("tau1", [](const TruncatedMap& m) { return m.arcs().tau1; })
        .def_property_readonly("lam", [](const TruncatedMap& m) { return m.arcs().lam; });
    bind_common<TruncatedMap>(tm);

    py::class_<TruncatedFamily> tf(mod, "TruncatedFamily", "Compiled F_{eps1,eps2}; use hovering.TruncatedFamily.");
    tf.def(py::init([](double eps, std::vector<double> K, std::vector<double> Omega, std::vector<double> JR,
                       std::vector<double> J1, std::vector<double> forcing, double K_max) {
               return TruncatedFamily(eps, TabulatedArcs(K, Omega, JR, J1), FourierForcing{std::move(forcing)}, K_max);
           }),
           py::arg("eps"), py::arg("K"), py::arg("Omega"), py::arg("JR"), py::arg("J1"), py::arg("forcing"),
           py::arg("K_max"))
        .def_property_readonly("forcing", [](const TruncatedFamily& m) { return m.forcing().b; });
    bind_common<TruncatedFamily>(tf);

    mod.def("simd_is_avx2", &simd_is_avx2, "Whether the selected SIMD lane kernel uses AVX2 or wider vectors.");
    mod.def("simd_width", &simd_width,
            "Doubles per SIMD packet of the selected lane kernel (8 AVX-512, 4 AVX2, 2 SSE2).");
    mod.def("simd_level", &simd_level,
            "Instruction set of the selected SIMD kernels (the truncated map's lanes, the flow's Taylor "
            "expansion): 'sse2', 'avx2', 'avx512'.");
    mod.def("simd_levels", &simd_levels, "The lane kernels of this build that this CPU runs, narrowest first.");
    mod.def("set_simd_level", &set_simd_level, py::arg("level"),
            "Select the SIMD kernels' level by name ('auto': the widest this CPU runs); ValueError names the "
            "allowed ones.");
}
