// Pickling of the compiled maps, systems, options and the tangential curve (protocol 2+, copy,
// deepcopy), added to the classes the other binding files registered.
//
// The state of each class is what its constructor takes (for the tangential curve: its measured
// samples, so unpickling rebuilds the interpolants without tracing the flow again), and unpickling
// runs the constructor's checks again: a corrupted state is a ValueError naming the entry. The
// rebuilt objects compute bit for bit what the originals did (the same doubles go through the same
// construction). The compiled FlowMap has no pickle: hovering.FlowMap rebuilds it from its own
// constructor arguments.
#include <string>
#include <vector>

#include "hovering/flow/return_map.hpp"
#include "hovering/normal/tangential_curve.hpp"
#include "hovering/truncated/map.hpp"
#include "pybind.hpp"

using namespace hovering;

namespace {

/// The tuple a __setstate__ received, checked to have n entries.
py::tuple state_of(const py::handle& state, std::size_t n, const char* cls, const char* fields) {
    if (!py::isinstance<py::tuple>(state) || py::len(state) != n)
        throw py::value_error(std::string(cls) + ".__setstate__: expected the tuple " + fields + ", got " +
                              short_repr(state));
    return py::reinterpret_borrow<py::tuple>(state);
}

/// A list of real numbers from a state entry (a ValueError naming the entry otherwise).
std::vector<double> reals(const py::handle& v, const char* cls, const char* name) {
    if (!py::isinstance<py::sequence>(v) || py::isinstance<py::str>(v))
        throw py::value_error(std::string(cls) + ".__setstate__: " + name +
                              " must be a sequence of real numbers, got " + short_repr(v));
    std::vector<double> out;
    for (const auto& x : py::reinterpret_borrow<py::sequence>(v)) out.push_back(real_arg(x, cls, name));
    return out;
}

py::array_t<double> as_array(const std::vector<double>& v) {
    return py::array_t<double>(py::ssize_t(v.size()), v.data());
}

/// The K grid and tables a TruncatedFamily was built from, read back from its splines: Omega on the
/// whole grid, |J_R| and |J_1| on its K <= 0 part (|J_1| splined in sqrt(-K), in reverse order);
/// the constructor ignores |J_R| and |J_1| above 0, which come back as 0.
// Every __getstate__ here returns py::object, the type its __setstate__ takes (pybind11 3.0.0, the
// declared floor, requires the two to match): the setter takes any object so that a wrong state is
// state_of's ValueError, not pybind11's TypeError.
py::object family_state(const TruncatedFamily& m) {
    const TabulatedArcs& a = m.arcs();
    const std::vector<double>& K = a.Omega.x();
    std::vector<double> JR(K.size(), 0.0), J1(K.size(), 0.0);
    const std::vector<double>& jr = a.JR.y();
    const std::vector<double>& j1 = a.J1s.y();  // reversed: s = sqrt(-K) increases as K decreases
    std::size_t n_neg = jr.size();
    for (std::size_t i = 0; i < n_neg; ++i) {
        JR[i] = jr[i];
        J1[i] = j1[n_neg - 1 - i];
    }
    return py::make_tuple(m.eps(), as_array(K), as_array(a.Omega.y()), as_array(JR), as_array(J1),
                          as_array(m.forcing().b), m.band().hi);
}

}  // namespace

void register_pickles(py::module_& core) {
    py::module_ truncated = core.attr("truncated"), flow = core.attr("flow"), normal = core.attr("normal");

    // The truncated maps: the band's upper end is the K_max they were built with, capped where the
    // rotation reaches 1e6 rad; the cap of the rebuilt map is the same, so the band is too.
    py::class_<TruncatedMap> tm(truncated.attr("TruncatedMap"));
    tm.def(py::pickle(
        [](const TruncatedMap& m) -> py::object {
            const AnalyticArcs& a = m.arcs();
            return py::make_tuple(m.eps(), a.Omega0, a.theta_w, a.tau0, a.tau1, a.lam, m.band().hi);
        },
        [](const py::object& state) {
            const py::tuple t = state_of(state, 7, "TruncatedMap", "(eps, Omega0, theta_w, tau0, tau1, lam, K_max)");
            const char* names[7] = {"eps", "Omega0", "theta_w", "tau0", "tau1", "lam", "K_max"};
            double v[7];
            for (std::size_t i = 0; i < 7; ++i) v[i] = real_arg(t[i], "TruncatedMap", names[i]);
            return make_truncated_map(v[0], v[1], v[2], v[3], v[4], v[5], v[6]);
        }));

    py::class_<TruncatedFamily> tf(truncated.attr("TruncatedFamily"));
    tf.def(py::pickle(&family_state, [](const py::object& state) {
        const char* who = "TruncatedFamily";
        const py::tuple t = state_of(state, 7, who, "(eps, K, Omega, JR, J1, forcing, K_max)");
        return TruncatedFamily(real_arg(t[0], who, "eps"),
                               TabulatedArcs(reals(t[1], who, "K"), reals(t[2], who, "Omega"), reals(t[3], who, "JR"),
                                             reals(t[4], who, "J1")),
                               FourierForcing{reals(t[5], who, "forcing")}, real_arg(t[6], who, "K_max"));
    }));

    py::class_<FlowSystem> fs(flow.attr("FlowSystem"));
    fs.def(py::pickle(
        [](const FlowSystem& s) -> py::object {
            return py::make_tuple(std::const_pointer_cast<Potential>(s.V1), std::const_pointer_cast<Potential>(s.V2),
                                  s.coupling.terms, s.eps, s.qw1, s.qw2, s.geometry);
        },
        [](const py::object& state) {
            const py::tuple t = state_of(state, 7, "FlowSystem", "(V1, V2, terms, eps, qw1, qw2, geometry)");
            // Through the constructor: its conversions and checks (FlowSystem::validate).
            return py::module_::import("hovering._core.flow").attr("FlowSystem")(*t).cast<FlowSystem>();
        }));

    py::class_<FlowOptions> fo(flow.attr("FlowOptions"));
    fo.def(py::pickle(
        [](const FlowOptions& o) -> py::object {
            return py::make_tuple(std::string(stepper_name(o.stepper)), o.rtol, o.atol, o.event_tol, o.max_steps,
                                  o.max_impacts, o.grazing_tol, o.corner_tol, o.verify_steps);
        },
        [](const py::object& state) {
            // Pickles from before verify_steps hold 8 entries: they get its default.
            const bool old = py::isinstance<py::tuple>(state) && py::len(state) == 8;
            const py::tuple t = state_of(
                state, old ? 8 : 9, "FlowOptions",
                "(stepper, rtol, atol, event_tol, max_steps, max_impacts, grazing_tol, corner_tol, verify_steps)");
            FlowOptions o;
            try {
                o.stepper = parse_stepper(t[0].cast<std::string>());
                o.rtol = t[1].cast<double>();
                o.atol = t[2].cast<double>();
                o.event_tol = t[3].cast<double>();
                o.max_steps = t[4].cast<std::int64_t>();
                o.max_impacts = t[5].cast<int>();
                o.grazing_tol = t[6].cast<double>();
                o.corner_tol = t[7].cast<double>();
                if (!old) o.verify_steps = t[8].cast<std::int64_t>();
            } catch (const py::cast_error&) {
                throw py::value_error("FlowOptions.__setstate__: wrong entry types in " + short_repr(state, 200));
            }
            o.validate();
            return o;
        }));

    // The tangential curve: its measured samples (the wall angles are the equispaced grid), energy,
    // eps, I_tan0 and measured interpolation errors; TangentialCurve::from_samples rebuilds the
    // interpolants exactly as measure() built them.
    py::class_<TangentialCurve, std::shared_ptr<TangentialCurve>> tc(normal.attr("TangentialCurve"));
    tc.def(py::pickle(
        [](const TangentialCurve& c) -> py::object {
            const auto [et, eI] = c.interpolation_error();
            return py::make_tuple(c.h(), c.eps(), c.I_tan0(), as_array(c.theta()), as_array(c.I()), et, eI);
        },
        [](const py::object& state) {
            const char* who = "TangentialCurve";
            const py::tuple t = state_of(state, 7, who, "(h, eps, I_tan0, theta, I, err_theta, err_I)");
            return std::make_shared<TangentialCurve>(TangentialCurve::from_samples(
                real_arg(t[0], who, "h"), real_arg(t[1], who, "eps"), real_arg(t[2], who, "I_tan0"),
                reals(t[3], who, "theta"), reals(t[4], who, "I"), real_arg(t[5], who, "err_theta"),
                real_arg(t[6], who, "err_I")));
        }));
}
