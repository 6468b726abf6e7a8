// Bindings of the flow: section coordinates and the batch return map (threads, GIL released).
#include "hovering/flow/return_map.hpp"
#include "pybind.hpp"

using namespace hovering;

namespace {

FlowSystem make_system(std::shared_ptr<const Potential> V1, std::shared_ptr<const Potential> V2,
                       std::vector<std::array<double, 3>> terms, double eps, double qw1, double qw2, int geometry) {
    FlowSystem s;
    s.V1 = std::move(V1);
    s.V2 = std::move(V2);
    s.coupling.terms = std::move(terms);
    s.eps = eps;
    s.qw1 = qw1;
    s.qw2 = qw2;
    s.geometry = static_cast<Geometry>(geometry);
    s.validate();
    return s;
}

}  // namespace

void register_flow(py::module_& m) {
    m.def("_section_points",
          [](std::shared_ptr<const Potential> V1, std::shared_ptr<const Potential> V2, std::vector<std::array<double, 3>> terms,
             double eps, double qw1, double qw2, int geometry, double h, const darray& theta, const darray& I) {
              const FlowSystem s = make_system(V1, V2, terms, eps, qw1, qw2, geometry);
              if (theta.size() != I.size()) throw py::value_error("theta and I must have the same size");
              darray z({theta.size(), py::ssize_t(4)});
              double* o = z.mutable_data();
              for (py::ssize_t i = 0; i < theta.size(); ++i) {
                  const auto p = section_point(s, h, theta.data()[i], I.data()[i]);
                  for (int k = 0; k < 4; ++k) o[4 * i + k] = p[std::size_t(k)];
              }
              return z;
          });
    m.def("_section_coordinates",
          [](std::shared_ptr<const Potential> V1, std::shared_ptr<const Potential> V2, std::vector<std::array<double, 3>> terms,
             double eps, double qw1, double qw2, int geometry, const darray& z) {
              const FlowSystem s = make_system(V1, V2, terms, eps, qw1, qw2, geometry);
              if (z.ndim() != 2 || z.shape(1) != 4) throw py::value_error("z must have shape (n, 4)");
              darray out({z.shape(0), py::ssize_t(2)});
              for (py::ssize_t i = 0; i < z.shape(0); ++i) {
                  const auto c = section_coordinates(s, z.data() + 4 * i);
                  out.mutable_data()[2 * i] = c[0];
                  out.mutable_data()[2 * i + 1] = c[1];
              }
              return out;
          });
    m.def("_return_maps",
          [](std::shared_ptr<const Potential> V1, std::shared_ptr<const Potential> V2, std::vector<std::array<double, 3>> terms,
             double eps, double qw1, double qw2, int geometry, const darray& z0, const std::string& stepper, double rtol,
             double atol, double event_tol, std::int64_t max_steps, int max_impacts, double grazing_tol, double corner_tol,
             int n_threads) {
              const FlowSystem s = make_system(V1, V2, terms, eps, qw1, qw2, geometry);
              FlowOptions o;
              o.stepper = stepper;
              o.rtol = rtol;
              o.atol = atol;
              o.event_tol = event_tol;
              o.max_steps = max_steps;
              o.max_impacts = max_impacts;
              o.grazing_tol = grazing_tol;
              o.corner_tol = corner_tol;
              o.validate();
              if (z0.ndim() != 2 || z0.shape(1) != 4) throw py::value_error("z0 must have shape (n, 4)");
              if (n_threads < 0 || n_threads > 4096) throw py::value_error("n_threads must be in [0, 4096], got " + std::to_string(n_threads));
              const py::ssize_t n = z0.shape(0);
              darray z({n, py::ssize_t(4)}), time(n), err(n);
              py::array_t<std::int8_t> status(n);
              py::array_t<std::int64_t> steps(n);
              std::vector<std::string> itin{static_cast<std::size_t>(n)};
              ReturnMapsOutput out;
              out.z = z.mutable_data();
              out.time = time.mutable_data();
              out.energy_error = err.mutable_data();
              out.status = status.mutable_data();
              out.steps = steps.mutable_data();
              out.itinerary = itin.data();
              {
                  // Orbits are independent and write disjoint slots of freshly allocated arrays.
                  py::gil_scoped_release release;
                  return_maps(s, z0.data(), n, o, n_threads, nullptr, out);
              }
              py::dict d;
              d["z"] = z;
              d["time"] = time;
              d["energy_error"] = err;
              d["status"] = status;
              d["steps"] = steps;
              d["itinerary"] = itin;
              return d;
          });
}
