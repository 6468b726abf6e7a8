// Bindings of the bridge between the two models: the tangential curve (normal coordinates) and
// the flow's return map as an iterable map (FlowMap), vectorised, GIL released, Ctrl-C honoured.
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "flow_results.hpp"
#include "hovering/normal/flow_map.hpp"
#include "hovering/normal/tangential_curve.hpp"
#include "pybind.hpp"
#include "signals.hpp"

using namespace hovering;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void same_size(const darray& a, const darray& b, const char* an, const char* bn) {
    if (a.ndim() != 1 || b.ndim() != 1 || a.size() != b.size())
        throw py::value_error(std::string(an) + " and " + bn + " must be 1-D arrays of the same size");
}

// Elementwise f over a 1-D array with the GIL released (f only reads the curve).
template <class F>
darray map1(const darray& a, F f) {
    if (a.ndim() != 1) throw py::value_error("expected a 1-D array");
    darray out(a.size());
    const double* in = a.data();
    double* o = out.mutable_data();
    {
        hovering_py::GilRelease release;
        for (py::ssize_t i = 0; i < a.size(); ++i) o[i] = f(in[i]);
    }
    return out;
}

py::dict steps(const FlowMap& fm, const darray& x, const darray& y, bool inverse, int n_threads) {
    same_size(x, y, "x", "y");
    const py::ssize_t n = x.size();
    std::vector<FlowStep> res(static_cast<std::size_t>(n));
    std::atomic<bool> cancel{false};
    const bool interrupted = hovering_py::run_watched(
        [&] { fm.steps(x.data(), y.data(), n, inverse, n_threads, &cancel, res.data()); }, cancel, n >= 64);
    darray x1(n), y1(n), time(n), err(n), z({n, py::ssize_t(4)});
    py::array_t<std::int8_t> status(n), region(n);
    py::array_t<std::int64_t> nsteps(n);
    std::vector<std::string> itin(static_cast<std::size_t>(n));
    for (py::ssize_t i = 0; i < n; ++i) {
        const FlowStep& s = res[std::size_t(i)];
        x1.mutable_data()[i] = s.x;
        y1.mutable_data()[i] = s.y;
        time.mutable_data()[i] = s.ret.status == FlowStatus::OffSection ? kNaN : s.ret.time;
        err.mutable_data()[i] = s.ret.status == FlowStatus::Ok ? s.ret.energy_error : kNaN;
        status.mutable_data()[i] = static_cast<std::int8_t>(s.ret.status);
        region.mutable_data()[i] = static_cast<std::int8_t>(s.region);
        nsteps.mutable_data()[i] = s.ret.steps;
        itin[std::size_t(i)] = s.ret.itinerary;
        for (int k = 0; k < 4; ++k) z.mutable_data()[4 * i + k] = s.ret.z[std::size_t(k)];
    }
    py::dict d;
    d["x"] = x1;
    d["y"] = y1;
    d["status"] = status;
    d["region"] = region;
    d["time"] = time;
    d["energy_error"] = err;
    d["steps"] = nsteps;
    d["itinerary"] = itin;
    d["z"] = z;
    d["interrupted"] = interrupted;
    return d;
}

py::dict jacobians(const FlowMap& fm, const darray& x, const darray& y, int n_threads) {
    same_size(x, y, "x", "y");
    const py::ssize_t n = x.size();
    std::vector<FlowJacobian> res(static_cast<std::size_t>(n));
    std::atomic<bool> cancel{false};
    const bool interrupted = hovering_py::run_watched(
        [&] { fm.jacobians(x.data(), y.data(), n, n_threads, &cancel, res.data()); }, cancel, n >= 16);
    darray x1(n), y1(n), time(n), J({n, py::ssize_t(2), py::ssize_t(2)});
    py::array_t<std::int8_t> status(n), region(n);
    py::array_t<std::int64_t> nsteps(n);
    std::vector<std::string> itin(static_cast<std::size_t>(n));
    for (py::ssize_t i = 0; i < n; ++i) {
        const FlowJacobian& r = res[std::size_t(i)];
        x1.mutable_data()[i] = r.step.x;
        y1.mutable_data()[i] = r.step.y;
        time.mutable_data()[i] = r.step.ret.status == FlowStatus::OffSection ? kNaN : r.step.ret.time;
        // The map's vocabulary (Status, as iterate's), not the flow's: both models' jacobian() agree.
        status.mutable_data()[i] = static_cast<std::int8_t>(orbit_status(r.step.ret.status));
        region.mutable_data()[i] = static_cast<std::int8_t>(r.step.region);
        nsteps.mutable_data()[i] = r.step.ret.steps;
        itin[std::size_t(i)] = r.step.ret.itinerary;
        for (int k = 0; k < 4; ++k) J.mutable_data()[4 * i + k] = r.J[k];
    }
    py::dict d;
    d["x"] = x1;
    d["y"] = y1;
    d["J"] = J;
    d["status"] = status;
    d["region"] = region;
    d["time"] = time;
    d["steps"] = nsteps;
    d["itinerary"] = itin;
    d["interrupted"] = interrupted;
    return d;
}

py::dict iterate(const FlowMap& fm, const darray& x0, const darray& y0, std::int64_t n_steps, const py::set& record,
                 unsigned exit_mask, bool stop_on_exit, int n_threads, double trajectory_dt,
                 std::int64_t max_points_per_orbit, py::object progress, std::int64_t every, int stop_side,
                 py::object stop_curve) {
    same_size(x0, y0, "x0", "y0");
    if (n_steps < 0) throw py::value_error("n_steps must be >= 0, got " + std::to_string(n_steps));
    if (every < 1) throw py::value_error("every must be >= 1, got " + std::to_string(every));
    const py::ssize_t n = x0.size();
    // Points and returns kept per orbit: every e-th (see FlowIterateOutput).
    const py::ssize_t np = py::ssize_t(recorded_states(n_steps, every)),
                      ns = py::ssize_t(recorded_returns(n_steps, every));
    auto has = [&](const char* k) { return record.contains(py::str(k)); };
    FlowIterateOptions opt;
    opt.n_steps = n_steps;
    opt.exit_mask = exit_mask;
    opt.stop_on_exit = stop_on_exit;
    opt.n_threads = n_threads;
    opt.every = every;
    opt.stop = stop_condition(stop_side, std::move(stop_curve));
    // Labels only where something reads them: otherwise no crossing of q1 = qw1 is tracked and no
    // itinerary built (the orbit is the same bit for bit).
    opt.labels =
        exit_mask != 0 || has("regions") || has("visited") || has("itinerary") || has("rotation") || has("residence");
    if (has("trajectory") != (trajectory_dt > 0))
        throw py::value_error("record 'trajectory' and trajectory_dt > 0 go together");
    if (!(trajectory_dt >= 0 && std::isfinite(trajectory_dt)))
        throw py::value_error("trajectory_dt must be finite and >= 0, got " + std::to_string(trajectory_dt));
    FlowIterateOutput out;
    py::dict d;
    darray xf(n), yf(n);
    py::array_t<std::int8_t> status(n);
    py::array_t<std::int64_t> done(n);
    out.x_final = xf.mutable_data();
    out.y_final = yf.mutable_data();
    out.status = status.mutable_data();
    out.steps_done = done.mutable_data();
    d["x_final"] = xf;
    d["y_final"] = yf;
    d["status"] = status;
    d["steps_done"] = done;
    auto per_point = [&](const char* key, double*& slot) {
        darray a({n, np});
        slot = a.mutable_data();
        d[key] = a;
    };
    auto per_return = [&](const char* key, double*& slot) {
        darray a({n, ns});
        slot = a.mutable_data();
        d[key] = a;
    };
    if (has("orbit")) {
        per_point("x", out.orbit_x);
        per_point("y", out.orbit_y);
    }
    if (has("section")) {
        per_point("theta", out.orbit_theta);
        per_point("I", out.orbit_I);
    }
    if (has("states")) {
        darray a({n, np, py::ssize_t(4)});
        out.states = a.mutable_data();
        d["z"] = a;
    }
    if (has("regions")) {
        py::array_t<std::int8_t> a({n, ns});
        out.regions = a.mutable_data();
        d["region"] = a;
    }
    if (has("times")) per_return("time", out.times);
    if (has("energy_error")) per_return("energy_error", out.energy_error);
    if (has("steps")) {
        py::array_t<std::int64_t> a({n, ns});
        out.integrator_steps = a.mutable_data();
        d["integrator_steps"] = a;
    }
    std::vector<std::string> itin;
    if (has("itinerary")) {
        itin.resize(static_cast<std::size_t>(n * ns));
        out.itinerary = itin.data();
    }
    if (has("rotation")) {
        darray a(n);
        out.rotation = a.mutable_data();
        d["rotation"] = a;
    }
    if (exit_mask) {
        py::array_t<std::int64_t> a(n);
        out.exit_step = a.mutable_data();
        d["exit_step"] = a;
    }
    if (has("visited")) {
        py::array_t<std::int8_t> a(n);
        out.visited = a.mutable_data();
        d["visited"] = a;
    }
    if (has("extrema")) {
        darray lo(n), hi(n);
        out.y_min = lo.mutable_data();
        out.y_max = hi.mutable_data();
        d["y_min"] = lo;
        d["y_max"] = hi;
    }
    if (has("residence")) {
        py::array_t<std::int64_t> a({n, py::ssize_t(kRegionCount)});
        out.residence = a.mutable_data();
        d["residence"] = a;
    }
    if (opt.stop.active()) {
        py::array_t<std::int64_t> a(n);
        out.stop_step = a.mutable_data();
        d["stop_step"] = a;
    }
    if (has("jacobian")) hovering_py::tangent_outputs(n, out.tangent, d);
    hovering_py::Trajectories traj(n, trajectory_dt, max_points_per_orbit);
    out.trajectory = traj.output();
    FlowWork work;
    out.work = &work;
    std::atomic<bool> cancel{false};
    std::atomic<std::int64_t> returns_done{0};
    opt.cancel = &cancel;
    const hovering_py::ProgressReport report{&returns_done, std::int64_t(n) * n_steps, std::move(progress)};
    if (report.active()) opt.progress = &returns_done;  // no counting at all otherwise
    const bool interrupted = hovering_py::run_watched([&] { fm.iterate(x0.data(), y0.data(), n, opt, out); }, cancel,
                                                      n * n_steps >= 16, &report);
    d["work"] = hovering_py::work_dict(work);
    traj.put(d);
    if (has("itinerary")) {
        py::list rows;
        for (py::ssize_t i = 0; i < n; ++i) {
            py::list row;
            for (py::ssize_t k = 0; k < ns; ++k) row.append(itin[std::size_t(i * ns + k)]);
            rows.append(row);
        }
        d["itinerary"] = rows;
    }
    d["interrupted"] = interrupted;
    return d;
}

}  // namespace

void register_normal(py::module_& m) {
    py::class_<TangentialCurve, std::shared_ptr<TangentialCurve>>(
        m, "TangentialCurve", "I_tan^eps(theta) measured on the flow (use hovering.TangentialCurve).")
        .def(py::init([](const FlowSystem& s, double h, int n, const FlowOptions& o, int n_check) {
                 hovering_py::GilRelease release;
                 return std::make_shared<TangentialCurve>(TangentialCurve::measure(s, h, n, o, n_check));
             }),
             py::arg("system"), py::arg("h"), py::arg("n"), py::arg("options"), py::arg("n_check"))
        .def(
            "I_tan",
            [](const TangentialCurve& c, const darray& th) { return map1(th, [&](double t) { return c.I_tan(t); }); },
            py::arg("theta"), "I_tan(theta) (the curve must be a graph).")
        .def(
            "parameter_of",
            [](const TangentialCurve& c, const darray& th) {
                return map1(th, [&](double t) { return c.parameter_of(t); });
            },
            py::arg("theta"), "Wall angle s with theta(s) = theta.")
        .def(
            "at",
            [](const TangentialCurve& c, const darray& s) {
                return py::make_tuple(map1(s, [&](double x) { return c.at(x).first; }),
                                      map1(s, [&](double x) { return c.at(x).second; }));
            },
            py::arg("s"), "(theta(s), I(s)) at wall angles s.")
        .def_property_readonly("is_graph", &TangentialCurve::is_graph)
        .def_property_readonly("min_slope", &TangentialCurve::min_slope)
        .def_property_readonly("min_slope_at", &TangentialCurve::min_slope_at)
        .def_property_readonly("interpolation_error", &TangentialCurve::interpolation_error)
        .def_property_readonly("not_graph_reason", &TangentialCurve::not_graph_reason)
        .def_property_readonly("I_tan0", &TangentialCurve::I_tan0)
        .def_property_readonly("h", &TangentialCurve::h)
        .def_property_readonly("s", [](const TangentialCurve& c) { return darray(c.s().size(), c.s().data()); })
        .def_property_readonly("theta",
                               [](const TangentialCurve& c) { return darray(c.theta().size(), c.theta().data()); })
        .def_property_readonly("I", [](const TangentialCurve& c) { return darray(c.I().size(), c.I().data()); })
        .def_static(
            "measure_refined",
            [](const FlowSystem& s, double h, const FlowOptions& o, int n_check) {
                hovering_py::GilRelease release;  // pure C++ (a Python-defined potential takes the GIL back)
                return std::make_shared<TangentialCurve>(TangentialCurve::measure_refined(s, h, o, n_check));
            },
            py::arg("system"), py::arg("h"), py::arg("options"), py::arg("n_check") = 4,
            "The curve from 64 wall points, doubled (up to 1024) until its measured interpolation error is below "
            "1e-12.")
        .def(
            "forcing_coefficients",
            [](const TangentialCurve& c, int n_modes, int n_phi) {
                const auto b = c.forcing_coefficients(n_modes, n_phi);
                return darray(py::ssize_t(b.size()), b.data());
            },
            py::arg("n_modes") = TangentialCurve::kForcingModes, py::arg("n_phi") = TangentialCurve::kForcingSamples,
            "Sine coefficients b_1..b_n_modes of the measured forcing f (eq:defoff), f sampled at "
            "forcing_angles(n_phi).");
    m.attr("FORCING_MODES") = TangentialCurve::kForcingModes;
    m.attr("FORCING_SAMPLES") = TangentialCurve::kForcingSamples;
    m.def(
        "forcing_angles",
        [](int n_phi) {
            const auto ph = forcing_angles(n_phi);
            return darray(py::ssize_t(ph.size()), ph.data());
        },
        py::arg("n_phi") = TangentialCurve::kForcingSamples,
        "The midpoint angles -pi + 2 pi (j + 1/2) / n_phi at which a forcing is sampled.");
    m.def(
        "sine_coefficients",
        [](const darray& f, int n_modes) {
            if (f.ndim() != 1) throw py::value_error("f must be a 1-D array of values at forcing_angles(n_phi)");
            const auto b = sine_coefficients(std::vector<double>(f.data(), f.data() + f.size()), n_modes);
            return darray(py::ssize_t(b.size()), b.data());
        },
        py::arg("f"), py::arg("n_modes") = TangentialCurve::kForcingModes,
        "Sine coefficients of f from its values at forcing_angles(len(f)) (the discrete sine transform).");

    py::class_<FlowMap>(m, "FlowMap", "The flow's return map as an iterable map (use hovering.FlowMap).")
        .def(py::init([](const FlowSystem& s, double h, const FlowOptions& o, std::shared_ptr<TangentialCurve> curve,
                         py::object lift) {
                 std::shared_ptr<const AnalyticArcs> arcs;
                 if (!lift.is_none()) {
                     const auto v = lift.cast<std::array<double, 5>>();  // Omega0, theta_w, tau0, tau1, lam
                     arcs = std::make_shared<AnalyticArcs>(AnalyticArcs{v[0], v[1], v[2], v[3], v[4]});
                 }
                 return FlowMap(s, h, o, std::move(curve), std::move(arcs));
             }),
             py::arg("system"), py::arg("h"), py::arg("options"), py::arg("curve"), py::arg("lift"))
        .def("steps", &steps, py::arg("x"), py::arg("y"), py::arg("inverse"), py::arg("n_threads"))
        .def(
            "step1",
            [](const FlowMap& fm, double x, double y, bool inverse) {
                // One point on this thread, a tuple back: no arrays, no watcher thread (a return
                // takes microseconds; Ctrl-C is seen when it ends). The same return as steps().
                FlowStep st;
                {
                    hovering_py::GilRelease release;  // a Python-defined potential takes it back
                    st = inverse ? fm.step_inverse(x, y) : fm.step(x, y);
                }
                return py::make_tuple(st.x, st.y, int(st.ret.status), int(st.region));
            },
            py::arg("x"), py::arg("y"), py::arg("inverse") = false,
            "One return of one point: (x1, y1, FlowStatus, Region), steps()' numbers bit for bit.")
        .def("jacobians", &jacobians, py::arg("x"), py::arg("y"), py::arg("n_threads"))
        .def("iterate", &iterate, py::arg("x0"), py::arg("y0"), py::arg("n_steps"), py::arg("record"),
             py::arg("exit_mask"), py::arg("stop_on_exit"), py::arg("n_threads"), py::arg("trajectory_dt") = 0.0,
             py::arg("max_points_per_orbit") = 0, py::arg("progress") = py::none(), py::arg("every") = 1,
             py::arg("stop_side") = 0, py::arg("stop_curve") = py::none())
        .def("to_section",
             [](const FlowMap& fm, const darray& x, const darray& y) {
                 same_size(x, y, "x", "y");
                 darray a(x.size()), b(x.size());
                 for (py::ssize_t i = 0; i < x.size(); ++i) {
                     const auto c = fm.to_section(x.data()[i], y.data()[i]);
                     a.mutable_data()[i] = c.first;
                     b.mutable_data()[i] = c.second;
                 }
                 return py::make_tuple(a, b);
             })
        .def("from_section",
             [](const FlowMap& fm, const darray& x, const darray& y) {
                 same_size(x, y, "theta", "I");
                 darray a(x.size()), b(x.size());
                 for (py::ssize_t i = 0; i < x.size(); ++i) {
                     const auto c = fm.from_section(x.data()[i], y.data()[i]);
                     a.mutable_data()[i] = c.first;
                     b.mutable_data()[i] = c.second;
                 }
                 return py::make_tuple(a, b);
             })
        .def_property_readonly("h", &FlowMap::h);
}
