// Bindings of the flow: FlowSystem and FlowOptions as classes, points of Sigma_h and their
// coordinates, and the batch return map (core thread pool, GIL released, Ctrl-C honoured).
#include <atomic>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "flow_results.hpp"
#include "hovering/flow/return_map.hpp"
#include "pybind.hpp"
#include "signals.hpp"

using namespace hovering;

namespace {

FlowSystem make_system(std::shared_ptr<const Potential> V1, std::shared_ptr<const Potential> V2,
                       std::vector<std::array<double, 3>> terms, double eps, double qw1, double qw2,
                       Geometry geometry) {
    FlowSystem s;
    s.V1 = std::move(V1);
    s.V2 = std::move(V2);
    s.coupling.terms = std::move(terms);
    s.eps = eps;
    s.qw1 = qw1;
    s.qw2 = qw2;
    s.geometry = geometry;
    s.validate();
    return s;
}

// A batch of returns of states z0 (n, 4) as the dict Section.return_map reads; run(z0, n, cancel,
// out, progress) computes them (return_maps, or a ReturnMapper's).
template <class Run>
py::dict returns_dict(const darray& z0, double trajectory_dt, std::int64_t max_points_per_orbit, py::object progress,
                      const char* stepper, Run run) {
    if (z0.ndim() != 2 || z0.shape(1) != 4) throw py::value_error("z0 must have shape (n, 4)");
    if (!(trajectory_dt >= 0 && std::isfinite(trajectory_dt)))
        throw py::value_error("trajectory_dt must be finite and >= 0 (0: no trajectory), got " +
                              std::to_string(trajectory_dt));
    const py::ssize_t n = z0.shape(0);
    darray z({n, py::ssize_t(4)}), time(n), err(n), chart({n, py::ssize_t(2)});
    py::array_t<std::int8_t> status(n), region(n);
    py::array_t<std::int64_t> steps(n);
    std::vector<std::string> itin{static_cast<std::size_t>(n)};
    hovering_py::Trajectories traj(n, trajectory_dt, max_points_per_orbit);
    FlowWork work;
    ReturnMapsOutput out;
    out.z = z.mutable_data();
    out.time = time.mutable_data();
    out.energy_error = err.mutable_data();
    out.status = status.mutable_data();
    out.region = region.mutable_data();
    out.steps = steps.mutable_data();
    out.itinerary = itin.data();
    out.chart = chart.mutable_data();
    out.work = &work;
    out.trajectory = traj.output();
    std::atomic<bool> cancel{false};
    std::atomic<std::int64_t> done{0};
    const hovering_py::ProgressReport report{&done, std::int64_t(n), std::move(progress)};
    // Orbits are independent and write disjoint slots of freshly allocated arrays.
    const bool interrupted = hovering_py::run_watched(
        [&] { run(z0.data(), std::int64_t(n), &cancel, out, report.active() ? &done : nullptr); }, cancel, n >= 64,
        &report);
    py::dict d;
    d["z"] = z;
    d["time"] = time;
    d["energy_error"] = err;
    d["status"] = status;
    d["region"] = region;
    d["steps"] = steps;
    d["itinerary"] = itin;
    d["chart"] = chart;  // the image's section coordinates, computed once by the tracer's chart check
    d["work"] = hovering_py::work_dict(work);
    traj.put(d);
    d["interrupted"] = interrupted;
    d["stepper"] = stepper;  // what ran ("auto" resolved)
    return d;
}

}  // namespace

void register_flow(py::module_& m) {
    py::class_<FlowSystem>(m, "FlowSystem",
                           "H = p1^2/2 + V1(q1) + p2^2/2 + V2(q2) + eps Vc(q1, q2) with walls at qw1, qw2 "
                           "(validated; use hovering.StepSystem).")
        .def(py::init(&make_system), py::arg("V1"), py::arg("V2"), py::arg("terms"), py::arg("eps"), py::arg("qw1"),
             py::arg("qw2"), py::arg("geometry"))
        .def_readonly("eps", &FlowSystem::eps)
        .def_readonly("qw1", &FlowSystem::qw1)
        .def_readonly("qw2", &FlowSystem::qw2)
        .def_readonly("geometry", &FlowSystem::geometry)
        .def_property_readonly(
            "terms", [](const FlowSystem& s) { return s.coupling.terms; },
            "Coupling terms (c, i, j): Vc = sum c q1^i q2^j.")
        .def(
            "energy",
            [](const FlowSystem& s, const darray& z) {
                if (z.ndim() != 2 || z.shape(1) != 4) throw py::value_error("z must have shape (n, 4)");
                darray out(z.shape(0));
                for (py::ssize_t i = 0; i < z.shape(0); ++i) out.mutable_data()[i] = s.energy(z.data() + 4 * i);
                return out;
            },
            py::arg("z"), "H of states z (shape (n, 4)).");

    py::tuple steppers(kSteppers.size());
    for (std::size_t i = 0; i < kSteppers.size(); ++i) steppers[i] = kSteppers[i];
    m.attr("STEPPERS") = steppers;  // the names FlowOptions.stepper takes, its default first
    m.def("default_atol", &FlowOptions::default_atol, py::arg("rtol"),
          "The absolute tolerance wherever none is given (FlowOptions.default_atol: rtol's).");

    py::class_<FlowOptions>(m, "FlowOptions", "Integrator settings of the return map (validated on use).")
        .def(py::init([](const std::string& stepper, double rtol, std::optional<double> atol, double event_tol,
                         std::int64_t max_steps, int max_impacts, double grazing_tol, double corner_tol,
                         std::int64_t verify_steps) {
                 FlowOptions o;
                 o.stepper = parse_stepper(stepper);  // the one place a name becomes a Stepper
                 o.rtol = rtol;
                 o.atol = atol ? *atol : FlowOptions::default_atol(rtol);
                 o.event_tol = event_tol;
                 o.max_steps = max_steps;
                 o.max_impacts = max_impacts;
                 o.grazing_tol = grazing_tol;
                 o.corner_tol = corner_tol;
                 o.verify_steps = verify_steps;
                 o.validate();
                 return o;
             }),
             // The core's defaults (FlowOptions{}), the one place they are written; atol None:
             // FlowOptions::default_atol(rtol), the one policy.
             py::arg("stepper") = std::string(stepper_name(FlowOptions{}.stepper)),
             py::arg("rtol") = FlowOptions{}.rtol,
             py::arg("atol") = py::none(), py::arg("event_tol") = FlowOptions{}.event_tol,
             py::arg("max_steps") = FlowOptions{}.max_steps, py::arg("max_impacts") = FlowOptions{}.max_impacts,
             py::arg("grazing_tol") = FlowOptions{}.grazing_tol, py::arg("corner_tol") = FlowOptions{}.corner_tol,
             py::arg("verify_steps") = FlowOptions{}.verify_steps)
        .def_property_readonly(
            "stepper", [](const FlowOptions& o) { return std::string(stepper_name(o.stepper)); },
            "The stepper's name (an entry of STEPPERS).")
        .def_readonly("rtol", &FlowOptions::rtol)
        .def_readonly("atol", &FlowOptions::atol)
        .def_readonly("event_tol", &FlowOptions::event_tol)
        .def_readonly("max_steps", &FlowOptions::max_steps)
        .def_readonly("max_impacts", &FlowOptions::max_impacts)
        .def_readonly("grazing_tol", &FlowOptions::grazing_tol)
        .def_readonly("corner_tol", &FlowOptions::corner_tol)
        .def_readonly("verify_steps", &FlowOptions::verify_steps)
        .def(
            "validate_for", [](const FlowOptions& o, const FlowSystem& s) { o.validate(s); }, py::arg("system"),
            "Raise ValueError unless the stepper applies to the system (\"exact\" needs a closed-form flow).")
        .def(
            "resolved_for", [](const FlowOptions& o, const FlowSystem& s) { return o.resolved(s); }, py::arg("system"),
            "A copy whose stepper is the one that runs on the system: \"auto\" is \"taylor\" where Taylor's method "
            "applies (V1, V2 each Harmonic or Tan), else \"rk8pd\"; any other stepper is itself.");

    m.def(
        "section_points",
        [](const FlowSystem& s, double h, const darray& theta, const darray& I) {
            if (theta.ndim() != 1 || I.ndim() != 1 || theta.size() != I.size())
                throw py::value_error("theta and I must be 1-D arrays of the same size");
            const py::ssize_t n = theta.size();
            darray z({n, py::ssize_t(4)});
            py::array_t<bool> ok(n);
            std::vector<std::string> why(static_cast<std::size_t>(n));
            for (py::ssize_t i = 0; i < n; ++i) {
                std::array<double, 4> p{};
                const bool good = try_section_point(s, h, theta.data()[i], I.data()[i], p, &why[std::size_t(i)]);
                if (!good) p.fill(std::numeric_limits<double>::quiet_NaN());
                ok.mutable_data()[i] = good;
                for (int k = 0; k < 4; ++k) z.mutable_data()[4 * i + k] = p[std::size_t(k)];
            }
            return py::make_tuple(z, ok, why);
        },
        py::arg("system"), py::arg("h"), py::arg("theta"), py::arg("I"),
        "Points of Sigma_h at (theta, I): (z (n, 4), ok, reasons); NaN rows where no point exists.");
    m.def(
        "section_coordinates",
        [](const FlowSystem& s, const darray& z) {
            if (z.ndim() != 2 || z.shape(1) != 4) throw py::value_error("z must have shape (n, 4)");
            darray out({z.shape(0), py::ssize_t(2)});
            for (py::ssize_t i = 0; i < z.shape(0); ++i) {
                const double* zi = z.data() + 4 * i;
                std::array<double, 2> c{std::numeric_limits<double>::quiet_NaN(),
                                        std::numeric_limits<double>::quiet_NaN()};
                if (std::isfinite(zi[0]) && std::isfinite(zi[1]) && std::isfinite(zi[2]) && std::isfinite(zi[3]))
                    c = section_coordinates(s, zi);
                out.mutable_data()[2 * i] = c[0];
                out.mutable_data()[2 * i + 1] = c[1];
            }
            return out;
        },
        py::arg("system"), py::arg("z"), "Section coordinates (theta, I) of states z (NaN rows stay NaN).");
    m.def(
        "return_maps",
        [](const FlowSystem& s, const darray& z0, const FlowOptions& o, int n_threads, double trajectory_dt,
           std::int64_t max_points_per_orbit, py::object progress) {
            o.validate();
            return returns_dict(z0, trajectory_dt, max_points_per_orbit, std::move(progress),
                                stepper_name(resolve_stepper(o.stepper, s)),
                                [&](const double* z, std::int64_t n, const std::atomic<bool>* cancel,
                                    const ReturnMapsOutput& out, std::atomic<std::int64_t>* done) {
                                    return_maps(s, z, n, o, n_threads, cancel, out, done);
                                });
        },
        py::arg("system"), py::arg("z0"), py::arg("options"), py::arg("n_threads"), py::arg("trajectory_dt") = 0.0,
        py::arg("max_points_per_orbit") = 0, py::arg("progress") = py::none(),
        "Returns of states z0 (n, 4): per-orbit outcomes, never a batch error for one orbit; with trajectory_dt > 0 "
        "each return's trajectory too; progress(done, total) is called every ~0.1 s and at the end.");

    py::class_<ReturnMapper>(m, "ReturnMapper",
                             "return_maps of one system with one set of options, validated once, its tracers kept "
                             "from call to call (what a Section keeps per options).")
        .def(py::init<const FlowSystem&, const FlowOptions&>(), py::arg("system"), py::arg("options"))
        .def(
            "run",
            [](const ReturnMapper& rm, const darray& z0, int n_threads, double trajectory_dt,
               std::int64_t max_points_per_orbit, py::object progress) {
                return returns_dict(z0, trajectory_dt, max_points_per_orbit, std::move(progress),
                                    stepper_name(resolve_stepper(rm.options().stepper, rm.system())),
                                    [&](const double* z, std::int64_t n, const std::atomic<bool>* cancel,
                                        const ReturnMapsOutput& out, std::atomic<std::int64_t>* done) {
                                        rm.run(z, n, n_threads, cancel, out, done);
                                    });
            },
            py::arg("z0"), py::arg("n_threads"), py::arg("trajectory_dt") = 0.0, py::arg("max_points_per_orbit") = 0,
            py::arg("progress") = py::none(), "return_maps(system, z0, options, ...) on the kept tracers (the same dict).")
        .def(
            "point",
            [](const ReturnMapper& rm, double h, double theta, double I, py::handle result_type) {
                // One return of the point (theta, I) of Sigma_h, on this thread: no watcher (Ctrl-C
                // is seen when the return ends), the section coordinates of an Ok image; the fields
                // of a ReturnMapResult of one return, as the batch path fills them.
                const FlowSystem& s = rm.system();
                std::array<double, 4> z0{};
                ReturnResult r;
                FlowWork work;
                {
                    hovering_py::GilRelease release;  // a Python-defined potential takes it back
                    if (try_section_point(s, h, theta, I, z0))
                        r = rm.one(z0, &work);
                    else
                        r.status = FlowStatus::OffSection;
                }
                const double nan = std::numeric_limits<double>::quiet_NaN();
                std::array<double, 2> c{nan, nan};
                if (r.status == FlowStatus::Ok) c = r.chart;  // the tracer's section_coordinates of z
                if (r.status == FlowStatus::OffSection) r.z = {nan, nan, nan, nan};
                const Region reg = r.status == FlowStatus::Ok ? region_of(r.itinerary) : Region::None;
                using hovering_py::array_data;
                using hovering_py::small_array;
                auto one = [](auto v) {
                    py::object a = small_array<decltype(v)>({1});
                    array_data<decltype(v)>(a)[0] = v;
                    return a;
                };
                py::object z = small_array<double>({1, 4});
                for (int k = 0; k < 4; ++k) array_data<double>(z)[k] = r.z[std::size_t(k)];
                py::object status = one(static_cast<std::int8_t>(r.status));
                py::object region = one(static_cast<std::int8_t>(reg));
                py::object steps = one(static_cast<std::int64_t>(r.steps));
                py::list itin;
                itin.append(r.itinerary);
                static const auto k = hovering_py::interned(
                    {"theta", "I", "z", "time", "itinerary", "status", "energy_error", "steps", "region", "work",
                     "stepper", "trajectory", "trajectory_index", "trajectory_kind", "trajectory_truncated"});
                using hovering_py::set_item;
                // The result object itself, its fields straight into its __dict__ (object.__new__,
                // no __init__): a dict and a Python constructor around it took 0.4 us of the call.
                PyTypeObject* type = reinterpret_cast<PyTypeObject*>(result_type.ptr());
                if (!PyType_Check(result_type.ptr()) || type->tp_dictoffset == 0)
                    throw py::type_error("result_type must be a class whose instances have a __dict__");
                py::object self = py::reinterpret_steal<py::object>(type->tp_alloc(type, 0));
                if (!self) throw py::error_already_set();
                static PyObject* const tmpl = hovering_py::key_template(k);
                py::dict d = hovering_py::keyed_dict(tmpl);
                if (PyObject_GenericSetDict(self.ptr(), d.ptr(), nullptr) != 0) throw py::error_already_set();
                set_item(d, k[0], one(c[0]));
                set_item(d, k[1], one(c[1]));
                set_item(d, k[2], z);
                set_item(d, k[3], one(r.time));
                set_item(d, k[4], itin);
                set_item(d, k[5], status);
                set_item(d, k[6], one(r.energy_error));
                set_item(d, k[7], steps);
                set_item(d, k[8], region);
                set_item(d, k[9], hovering_py::work_dict(work));
                set_item(d, k[10], py::str(stepper_name(resolve_stepper(rm.options().stepper, s))));
                return self;
            },
            py::arg("h"), py::arg("theta"), py::arg("I"), py::arg("result_type"),
            "One return of the section point (theta, I): an instance of result_type (made without its __init__) "
            "holding the fields of a ReturnMapResult of one point (arrays of length 1); ValueError for theta "
            "outside [-pi, pi] or a non-finite I, as section_points.");
}
