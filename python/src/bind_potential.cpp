// Bindings of the potentials and the onset parameters (pure C++ numerics; no GIL-sensitive loops).
#include <memory>

#include "hovering/potential.hpp"
#include "pybind.hpp"

using namespace hovering;

void register_potential(py::module_& m) {
    py::class_<Potential, std::shared_ptr<Potential>> pot(m, "Potential", "A single-well potential V(q) (compiled).");
    pot.def("V", &Potential::V, py::arg("q"), "V(q).")
        .def("dV", &Potential::dV, py::arg("q"), "V'(q).")
        .def("turning_points", &Potential::turning_points, py::arg("h"), "Turning points (q_min, q_max) of the level V = h.")
        .def("period", &Potential::period, py::arg("h"), "Period T(h).")
        .def("frequency", &Potential::frequency, py::arg("h"), "omega(h) = 2 pi / T(h) = dH/dI.")
        .def("action", &Potential::action, py::arg("h"), "Action I(h).")
        .def("energy", &Potential::energy, py::arg("I"), "Energy H(I), inverse of action().")
        .def("angle_of", &Potential::angle_of, py::arg("q"), py::arg("h"),
             "Angle of (q, p < 0) on the level h: omega(h) x time from q to q_max (paper's convention).")
        .def_property_readonly("name", &Potential::name)
        .def_property_readonly("q_limit", &Potential::q_limit, "Largest |q| inside the well (inf if unbounded).")
        .def("__repr__", &Potential::name);
    py::class_<Harmonic, Potential, std::shared_ptr<Harmonic>>(m, "Harmonic", "V = omega^2 q^2 / 2 (closed-form action-angle).")
        .def(py::init<double>(), py::arg("omega"))
        .def_property_readonly("omega", &Harmonic::omega);
    py::class_<Tan, Potential, std::shared_ptr<Tan>>(m, "Tan",
                                                    "V = omega^2 / (2 alpha^2) tan^2(alpha q) (closed-form action-angle).")
        .def(py::init<double, double>(), py::arg("omega"), py::arg("alpha"))
        .def_property_readonly("omega", &Tan::omega)
        .def_property_readonly("alpha", &Tan::alpha);
    py::class_<Numerical, Potential, std::shared_ptr<Numerical>>(
        m, "Numerical", "Answers every energy question of another potential by GSL quadrature and root finding.")
        .def(py::init<std::shared_ptr<const Potential>>(), py::arg("base"));

    py::class_<OnsetParameters>(m, "OnsetParameters", "Onset parameters of sec:parametersdef.")
        .def_readonly("Omega0", &OnsetParameters::Omega0)
        .def_readonly("tau0", &OnsetParameters::tau0)
        .def_readonly("tau1", &OnsetParameters::tau1)
        .def_readonly("lam", &OnsetParameters::lam)
        .def_readonly("theta_w", &OnsetParameters::theta_w)
        .def_readonly("I_tan", &OnsetParameters::I_tan)
        .def("__repr__", [](const OnsetParameters& p) {
            return "OnsetParameters(Omega0=" + std::to_string(p.Omega0) + ", tau0=" + std::to_string(p.tau0) +
                   ", tau1=" + std::to_string(p.tau1) + ", lam=" + std::to_string(p.lam) +
                   ", theta_w=" + std::to_string(p.theta_w) + ", I_tan=" + std::to_string(p.I_tan) + ")";
        });
    m.def("_onset_parameters", &onset_parameters, py::arg("V1"), py::arg("V2"), py::arg("qw1"), py::arg("qw2"), py::arg("h"));
    m.def("_onset_parameters_closed_form", &onset_parameters_closed_form, py::arg("omega1"), py::arg("alpha1"),
          py::arg("omega2"), py::arg("alpha2"), py::arg("qw1"), py::arg("qw2"), py::arg("h"));
}
