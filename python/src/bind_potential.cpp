// Bindings of the potentials and the onset parameters.
//
// Besides the compiled potentials, V and V' may come from Python: a subclass of hovering.Potential
// (through the trampoline PyPotential) or two callables (CallablePotential, behind
// hovering.CustomPotential). The base class Potential answers every energy question from V and dV
// alone, so nothing else is needed from Python. The core may call them from the return map's worker
// threads with the GIL released: every call into Python takes the GIL itself (through the gate of
// gil.hpp), and a Python exception travels up through the core (and GSL's frames) as
// pybind11::error_already_set, which the flow's thread pool hands to the calling thread.
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <memory>
#include <string>
#include <utility>

#include "gil.hpp"
#include "hovering/flow/system.hpp"
#include "pybind.hpp"

using namespace hovering;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// A double as Python prints it (shortest round trip): a message names the value the core really
/// saw, in the user's language. Called with the GIL held (every caller is talking to Python).
std::string fmt(double v) {
    return py::repr(py::float_(v)).cast<std::string>();
}

/// A Python exception of a Python-defined potential on its way through the core (GSL's frames, the
/// worker threads) to the caller, where the module's translator raises it again unchanged. Its
/// Python part is dropped through the gate (gil.hpp): a second worker's exception is discarded on
/// that worker, without the GIL, and pybind11's own exception would take the GIL for it there
/// unconditionally (PyGILState_Ensure), also while the interpreter exits.
class PotentialError : public std::exception {
public:
    /// Takes over e (GIL held).
    explicit PotentialError(py::error_already_set&& e)
        : what_(e.what()), error_(new py::error_already_set(std::move(e)), drop) {}
    const char* what() const noexcept override { return what_.c_str(); }
    /// Set the potential's exception as the Python error (GIL held).
    void restore() const { error_->restore(); }

private:
    static void drop(py::error_already_set* e) {
        const hovering_py::Gil gil;
        if (gil) delete e;  // else the interpreter is exiting: leak it
    }
    std::string what_;
    std::shared_ptr<py::error_already_set> error_;
};

/// f() with the GIL, taken on any thread through the gate (gil.hpp); a Python exception leaves it
/// as PotentialError. Once the interpreter exits the thread parks instead (its computation's
/// result would never be seen).
template <class F>
auto in_python(F&& f) -> decltype(f()) {
    const hovering_py::Gil gil;
    if (!gil) hovering_py::GilGate::refused();
    try {
        return f();
    } catch (py::error_already_set& e) {
        throw PotentialError(std::move(e));
    }
}

/// hovering.Potential.ReturnError, set by register_potential (leaked, like the module).
PyObject* potential_return_error = nullptr;

/// Raise Potential.ReturnError(msg) (GIL held): a method of a Python-defined potential returned the
/// wrong kind of value. The class derives from ValueError, the module's exception for bad input,
/// and from TypeError, which V and V' raised for it before (callers may catch either).
[[noreturn]] void wrong_return(const std::string& msg) {
    PyErr_SetString(potential_return_error ? potential_return_error : PyExc_ValueError, msg.c_str());
    throw py::error_already_set();
}

/// The float value of what a Python V or V' returned (GIL held). Anything float() accepts (float,
/// int, NumPy scalars) is a value; anything else is a Potential.ReturnError naming the potential and the call.
/// A non-finite value at |q| < q_limit is a ValueError: inside the well it is a defect of the
/// callable, and the generic quadrature and root finding would turn it into garbage. Outside the
/// well (where only a rejected trial step of the integrator can look) it is passed on, so that the
/// step-size control shrinks the step, or the orbit ends with status NON_FINITE.
double checked_value(const py::object& r, const Potential& pot, const char* fn, double q) {
    double v;
    if (PyFloat_CheckExact(r.ptr())) {
        v = PyFloat_AS_DOUBLE(r.ptr());
    } else {
        v = PyFloat_AsDouble(r.ptr());
        if (v == -1.0 && PyErr_Occurred()) {
            PyErr_Clear();
            wrong_return(pot.name() + "." + fn + "(" + fmt(q) + ") returned " + short_repr(r, 80) + " of type " +
                         std::string(Py_TYPE(r.ptr())->tp_name) + ": V and V' must return a real number (a float)");
        }
    }
    if (!std::isfinite(v)) {
        const double lim = pot.q_limit();
        if (std::fabs(q) < lim)
            throw py::value_error(pot.name() + "." + fn + "(" + fmt(q) + ") = " + fmt(v) +
                                  ": V and V' must be finite inside the well, |q| < q_limit = " + fmt(lim));
    }
    return v;
}

/// The Python object of a trampoline instance, or an empty handle if it no longer exists (GIL held).
py::handle python_self(const Potential* p) {
    return py::detail::get_object_handle(p, py::detail::get_type_info(typeid(Potential)));
}

/// A subclass's own definition of `attr` (a class constant, a property or a method, which is
/// called: then *called is set), or an empty object when only the base class's property would
/// answer: that property calls back into the trampoline, so reading it here would recurse.
py::object subclass_attr(py::handle self, const char* attr, bool* called = nullptr) {
    const py::object mine = py::getattr(py::type::handle_of(self), attr, py::none());
    if (mine.is(py::type::of<Potential>().attr(attr))) return py::object();
    py::object v = py::getattr(self, attr);
    const bool call = PyCallable_Check(v.ptr());
    if (call) v = v();
    if (called) *called = call;
    return v;
}

/// Trampoline of hovering.Potential: a Python subclass defines V(self, q) and dV(self, q), and may
/// define name and q_limit (class constants, properties or methods).
class PyPotential : public Potential {
public:
    double V(double q) const override { return call("V", q); }
    double dV(double q) const override { return call("dV", q); }

    std::string name() const override {
        return in_python([&] { return name_of_class(); });
    }

    double q_limit() const override {  // asked once per orbit, on the worker threads too
        return in_python([&] { return limit_of_class(); });
    }

private:
    std::string name_of_class() const {
        const py::handle self = python_self(this);
        if (!self) return "Potential(<Python object released>)";
        const std::string fallback = py::type::handle_of(self).attr("__name__").cast<std::string>() + "()";
        // The name goes into the core's error messages: a name that raises must not replace them.
        // One of the wrong type is a defect of the class, named like any other wrong return.
        py::object v;
        bool called = false;
        try {
            v = subclass_attr(self, "name", &called);
        } catch (py::error_already_set&) {
            return fallback;
        }
        if (!v) return fallback;
        if (!PyUnicode_Check(v.ptr()))
            wrong_return(fallback + ": name" + (called ? "() must return" : " must be") + " a str, got " +
                         short_repr(v) + " of type " + std::string(Py_TYPE(v.ptr())->tp_name));
        return v.cast<std::string>();
    }

    double limit_of_class() const {
        const py::handle self = python_self(this);
        if (!self) return kInf;
        bool called = false;
        const py::object v = subclass_attr(self, "q_limit", &called);
        if (!v) return kInf;
        double lim;
        if (!as_real(v, &lim) || !(lim > 0))
            wrong_return(name() + ": q_limit" + (called ? "() must return" : " must be") +
                         " a real number > 0 or inf, got " + short_repr(v));
        return lim;
    }

    double call(const char* fn, double q) const {
        return in_python([&] {
            const py::function f = py::get_override(static_cast<const Potential*>(this), fn);
            if (!f) {
                if (!python_self(this))
                    throw std::runtime_error(std::string("Potential.") + fn +
                                             ": the Python object of this potential was released");
                throw py::type_error(name() + " does not define " + fn +
                                     "(self, q): subclass hovering.Potential and define V(self, q) and dV(self, q), "
                                     "or use hovering.CustomPotential(V, dV)");
            }
            return checked_value(f(q), *this, fn, q);
        });
    }
};

/// V and V' as two Python callables (hovering.CustomPotential validates them first).
class CallablePotential final : public Potential {
public:
    /// Stores the callables; q_limit > 0 (inf for an unbounded well).
    CallablePotential(py::object V, py::object dV, double q_limit, std::string name)
        : V_(std::move(V)), dV_(std::move(dV)), q_limit_(q_limit), name_(std::move(name)) {
        if (!PyCallable_Check(V_.ptr()) || !PyCallable_Check(dV_.ptr()))
            throw py::value_error("V and dV must be callable");
        if (!(q_limit_ > 0)) throw py::value_error("q_limit must be > 0 (or inf), got " + fmt(q_limit_));
    }
    /// The last reference may go from a thread without the GIL (a core object holding the
    /// potential): dropping the callables needs it.
    ~CallablePotential() override {
        const hovering_py::Gil gil;
        if (!gil) {  // the interpreter is exiting: leak rather than touch it
            V_.release();
            dV_.release();
            return;
        }
        V_ = py::object();
        dV_ = py::object();
    }
    double V(double q) const override { return call(V_, "V", q); }
    double dV(double q) const override { return call(dV_, "dV", q); }
    std::string name() const override { return name_; }
    double q_limit() const override { return q_limit_; }
    /// The callable V.
    py::object V_callable() const { return V_; }
    /// The callable V'.
    py::object dV_callable() const { return dV_; }

private:
    double call(const py::object& f, const char* fn, double q) const {
        return in_python([&] { return checked_value(f(q), *this, fn, q); });
    }
    py::object V_, dV_;
    double q_limit_;
    std::string name_;
};

/// A shared_ptr to the C++ part of a Python potential whose control block also owns a reference to
/// the Python object. pybind11's shared_ptr holder keeps only the C++ part alive: a core object that
/// stores the potential (Numerical) would otherwise outlive a Python subclass's methods, which live
/// on the Python side (the holder has no py::trampoline_self_life_support; that is a smart_holder
/// feature of pybind11 >= 3 only).
std::shared_ptr<const Potential> keep_python_alive(const py::object& obj) {
    if (!py::isinstance<Potential>(obj))
        throw py::type_error(
            "expected a hovering potential (Harmonic, Tan, CustomPotential, a Potential subclass), got " +
            py::repr(obj).cast<std::string>());
    const Potential* cpp = obj.cast<const Potential*>();
    std::shared_ptr<py::object> owner(new py::object(obj), [](py::object* o) {
        const hovering_py::Gil gil;
        if (!gil) o->release();  // the interpreter is exiting: leak the reference rather than touch it
        delete o;
    });
    return std::shared_ptr<const Potential>(owner, cpp);
}

/// The tuple a __setstate__ received, checked to have n entries (a ValueError naming the class
/// otherwise: a corrupted or foreign pickle, not a crash).
py::tuple state_tuple(const py::handle& state, std::size_t n, const char* cls, const char* fields) {
    if (!py::isinstance<py::tuple>(state) || py::len(state) != n)
        throw py::value_error(std::string(cls) + ".__setstate__: expected the tuple " + fields + ", got " +
                              short_repr(state));
    return py::reinterpret_borrow<py::tuple>(state);
}

/// Bind one compiled potential P from its kInfo: constructor (each argument through real_arg, named
/// in a wrong type's message), a read-only property per parameter, and pickling by the parameters
/// (the state is what the constructor takes: unpickling runs its checks again).
template <class P, std::size_t... I>
void bind_kind(py::module_& m, std::index_sequence<I...>) {
    constexpr std::size_t n = sizeof...(I);
    const std::string doc = std::string(P::kInfo.formula) + " (closed-form action-angle).";
    py::class_<P, Potential, std::shared_ptr<P>> c(m, P::kInfo.cls, doc.c_str());
    c.def(py::init([](decltype((void)I, py::handle())... a) {
              return std::make_shared<P>(real_arg(a, P::kInfo.cls, P::kInfo.params[I].name)...);
          }),
          py::arg(P::kInfo.params[I].name)...);
    (c.def_property_readonly(P::kInfo.params[I].name, [](const P& p) { return p.parameters()[I]; }), ...);
    std::string fields = "(";
    for (const PotentialParam& q : P::kInfo.params) fields += std::string(q.name) + ", ";
    fields = fields.substr(0, fields.size() - 2) + (n == 1 ? ",)" : ")");
    c.def(py::pickle(
        [](const P& p) {
            const auto v = p.parameters();
            return py::object(py::make_tuple(v[I]...));
        },
        [fields](const py::object& state) {
            const py::tuple t = state_tuple(state, n, P::kInfo.cls, fields.c_str());
            return std::make_shared<P>(real_arg(t[I], P::kInfo.cls, P::kInfo.params[I].name)...);
        }));
}

/// Bind every compiled potential (the core's registry, CompiledPotentials) and its list of kinds.
template <class... P>
void bind_compiled(py::module_& m, PotentialList<P...>) {
    (bind_kind<P>(m, std::make_index_sequence<P::kInfo.params.size()>{}), ...);
    py::class_<PotentialParam>(m, "PotentialParam", "A parameter of a compiled potential: its name and range.")
        .def_property_readonly("name", [](const PotentialParam& p) { return std::string(p.name); })
        .def_readonly("lo", &PotentialParam::lo)
        .def_readonly("hi", &PotentialParam::hi)
        .def("__repr__", [](const PotentialParam& p) {
            return "PotentialParam(" + std::string(p.name) + " in [" + fmt(p.lo) + ", " + fmt(p.hi) + "])";
        });
    py::class_<PotentialKind>(m, "PotentialKind",
                              "A compiled potential kind: its name in scene files and plans, its class, its "
                              "formula and its parameters in the constructor's order.")
        .def_readonly("kind", &PotentialKind::kind)
        .def_readonly("cls", &PotentialKind::cls)
        .def_readonly("formula", &PotentialKind::formula)
        .def_readonly("params", &PotentialKind::params)
        .def("__repr__", [](const PotentialKind& k) { return "PotentialKind(" + k.kind + ": " + k.cls + ")"; });
    py::tuple kinds(potential_kinds().size());
    for (std::size_t i = 0; i < potential_kinds().size(); ++i) kinds[i] = py::cast(potential_kinds()[i]);
    m.attr("POTENTIAL_KINDS") = kinds;  // the core's registry, in its order
}

/// Pickling of the potentials and the onset parameters (protocol 2+, copy, deepcopy): the state is
/// what the constructor takes, and unpickling runs the constructor's checks again. A Python subclass
/// of Potential keeps its instance dict (its class must be importable, as for any pickled class);
/// hovering.CustomPotential adds its own __reduce_ex__, which names a callable that cannot be pickled.
void register_potential_pickles(py::module_& m) {
    py::class_<Potential, PyPotential, std::shared_ptr<Potential>> pot(m.attr("Potential"));
    pot.def(py::pickle([](const py::object& self) { return py::object(py::getattr(self, "__dict__", py::dict())); },
                       [](const py::object& state) {
                           if (!py::isinstance<py::dict>(state))
                               throw py::value_error("Potential.__setstate__: expected the instance dict, got " +
                                                     short_repr(state));
                           return std::make_pair(new PyPotential(), py::reinterpret_borrow<py::dict>(state));
                       }));
    py::class_<Numerical, Potential, std::shared_ptr<Numerical>> numerical(m.attr("Numerical"));
    numerical.def(py::pickle(
        [](const Numerical& p) { return py::object(py::make_tuple(std::const_pointer_cast<Potential>(p.base()))); },
        [](const py::object& state) {
            const py::tuple t = state_tuple(state, 1, "Numerical", "(base,)");
            return std::make_shared<Numerical>(keep_python_alive(t[0]));
        }));
    numerical.def_property_readonly(
        "base", [](const Numerical& p) { return std::const_pointer_cast<Potential>(p.base()); },
        "The wrapped potential (whose V and V' this one uses).");
    py::class_<CallablePotential, Potential, std::shared_ptr<CallablePotential>> callable(m.attr("_CallablePotential"));
    callable.def(py::pickle(
        [](const CallablePotential& p) {
            return py::object(py::make_tuple(p.V_callable(), p.dV_callable(), p.q_limit(), p.name()));
        },
        [](const py::object& state) {
            const py::tuple t = state_tuple(state, 4, "_CallablePotential", "(V, dV, q_limit, name)");
            if (!py::isinstance<py::str>(t[3]))
                throw py::value_error("_CallablePotential.__setstate__: name must be a str, got " + short_repr(t[3]));
            return std::make_shared<CallablePotential>(t[0], t[1], real_arg(t[2], "_CallablePotential", "q_limit"),
                                                       t[3].cast<std::string>());
        }));
    py::class_<OnsetParameters> onset(m.attr("OnsetParameters"));
    onset.def(py::pickle(
        [](const OnsetParameters& p) {
            return py::object(py::make_tuple(p.Omega0, p.tau0, p.tau1, p.lam, p.theta_w, p.I_tan));
        },
        [](const py::object& state) {
            const py::tuple t = state_tuple(state, 6, "OnsetParameters", "(Omega0, tau0, tau1, lam, theta_w, I_tan)");
            const char* names[6] = {"Omega0", "tau0", "tau1", "lam", "theta_w", "I_tan"};
            double v[6];
            for (std::size_t i = 0; i < 6; ++i) v[i] = real_arg(t[i], "OnsetParameters", names[i]);
            return OnsetParameters{v[0], v[1], v[2], v[3], v[4], v[5]};
        }));
}

}  // namespace

void register_potential(py::module_& m) {
    py::class_<Potential, PyPotential, std::shared_ptr<Potential>> pot(
        m, "Potential",
        "A single-well potential V(q), V(0) = 0, q V'(q) > 0. Subclass it in Python by defining V(self, q) and "
        "dV(self, q) (and optionally name, q_limit); every energy question is then answered by quadrature.");
    // Every argument goes through real_arg: a wrong type is a ValueError naming the method and the
    // parameter, not pybind11's list of overloads.
    auto one = [](auto f, const char* who, const char* a) {
        return [f, who, a](const Potential& self, py::handle x) { return (self.*f)(real_arg(x, who, a)); };
    };
    auto two = [](auto f, const char* who, const char* a, const char* b) {
        return [f, who, a, b](const Potential& self, py::handle x, py::handle y) {
            return (self.*f)(real_arg(x, who, a), real_arg(y, who, b));
        };
    };
    pot.def(py::init<>())
        .def("V", one(&Potential::V, "V", "q"), py::arg("q"), "V(q).")
        .def("dV", one(&Potential::dV, "dV", "q"), py::arg("q"), "V'(q).")
        .def("turning_points", one(&Potential::turning_points, "turning_points", "h"), py::arg("h"),
             "Turning points (q_min, q_max) of the level V = h.")
        .def("period", one(&Potential::period, "period", "h"), py::arg("h"), "Period T(h).")
        .def("frequency", one(&Potential::frequency, "frequency", "h"), py::arg("h"), "omega(h) = 2 pi / T(h) = dH/dI.")
        .def("action", one(&Potential::action, "action", "h"), py::arg("h"), "Action I(h).")
        .def("energy", one(&Potential::energy, "energy", "I"), py::arg("I"), "Energy H(I), inverse of action().")
        .def("angle_of", two(&Potential::angle_of, "angle_of", "q", "h"), py::arg("q"), py::arg("h"),
             "Angle of (q, p < 0) on the level h: omega(h) x time from q to q_max (paper's convention).")
        .def("point_at", two(&Potential::point_at, "point_at", "theta", "h"), py::arg("theta"), py::arg("h"),
             "(q, p) at angle theta in [-pi, pi] on the level h (sign(p) = -sign(theta)).")
        .def(
            "angle_of_point",
            [](const Potential& self, py::handle q, py::handle p, py::handle h) {
                return self.angle_of_point(real_arg(q, "angle_of_point", "q"), real_arg(p, "angle_of_point", "p"),
                                           real_arg(h, "angle_of_point", "h"));
            },
            py::arg("q"), py::arg("p"), py::arg("h"),
            "Signed angle in [-pi, pi] of the phase point (q, p) on its level h = p^2/2 + V(q) (ValueError if "
            "p^2/2 + V(q) differs from h by more than 1e-8 h).")
        .def_property_readonly("name", &Potential::name)
        .def_property_readonly("q_limit", &Potential::q_limit, "Largest |q| inside the well (inf if unbounded).")
        .def("__repr__", &Potential::name);
    // Potential.ReturnError(ValueError, TypeError), built by type() because pybind11's
    // py::exception takes one base; nested in Potential (qualified name, so it pickles) rather
    // than a new name of the module.
    py::object err = py::reinterpret_borrow<py::object>(reinterpret_cast<PyObject*>(&PyType_Type))(
        "ReturnError", py::make_tuple(py::handle(PyExc_ValueError), py::handle(PyExc_TypeError)),
        py::dict(py::arg("__module__") = m.attr("__name__"), py::arg("__qualname__") = "Potential.ReturnError",
                 py::arg("__doc__") =
                     "A method of a potential defined in Python (V, dV, q_limit, name) returned a value "
                     "of the wrong kind: a ValueError, and the TypeError V and V' raised for it before."));
    pot.attr("ReturnError") = err;
    potential_return_error = err.release().ptr();
    bind_compiled(m, CompiledPotentials{});
    py::class_<Numerical, Potential, std::shared_ptr<Numerical>>(
        m, "Numerical", "Answers every energy question of another potential by GSL quadrature and root finding.")
        .def(py::init([](const py::object& base) { return std::make_shared<Numerical>(keep_python_alive(base)); }),
             py::arg("base"));
    py::class_<CallablePotential, Potential, std::shared_ptr<CallablePotential>>(
        m, "_CallablePotential", "V and V' as Python callables (unvalidated; use hovering.CustomPotential).")
        .def(py::init<py::object, py::object, double, std::string>(), py::arg("V"), py::arg("dV"), py::arg("q_limit"),
             py::arg("name"))
        .def_property_readonly("V_callable", &CallablePotential::V_callable, "The callable V(q).")
        .def_property_readonly("dV_callable", &CallablePotential::dV_callable, "The callable V'(q).");

    py::class_<OnsetParameters>(m, "OnsetParameters", "Onset parameters of sec:parametersdef.")
        .def_readonly("Omega0", &OnsetParameters::Omega0)
        .def_readonly("tau0", &OnsetParameters::tau0)
        .def_readonly("tau1", &OnsetParameters::tau1)
        .def_readonly("lam", &OnsetParameters::lam)
        .def_readonly("theta_w", &OnsetParameters::theta_w)
        .def_readonly("I_tan", &OnsetParameters::I_tan)
        .def("__repr__", [](const OnsetParameters& p) {
            // %.10g: std::to_string's fixed %f printed tau1 = 1.7e-7 as 0.000000.
            auto g = [](double v) {
                char b[32];
                std::snprintf(b, sizeof b, "%.10g", v);
                return std::string(b);
            };
            return "OnsetParameters(Omega0=" + g(p.Omega0) + ", tau0=" + g(p.tau0) + ", tau1=" + g(p.tau1) +
                   ", lam=" + g(p.lam) + ", theta_w=" + g(p.theta_w) + ", I_tan=" + g(p.I_tan) + ")";
        });
    register_potential_pickles(m);
    // A Python-defined potential's exception reaches the caller as the exception it raised.
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const PotentialError& e) {
            e.restore();
        }
    });
    m.def("_onset_parameters", &onset_parameters, py::arg("V1"), py::arg("V2"), py::arg("qw1"), py::arg("qw2"),
          py::arg("h"), py::arg("rtol") = 1e-6);
    m.def("_onset_parameters_closed_form", &onset_parameters_closed_form, py::arg("omega1"), py::arg("alpha1"),
          py::arg("omega2"), py::arg("alpha2"), py::arg("qw1"), py::arg("qw2"), py::arg("h"), py::arg("rtol") = 1e-6);
    // (values, errors) as two OnsetParameters.
    m.def(
        "_onset_estimate",
        [](const Potential& V1, const Potential& V2, double qw1, double qw2, double h, double rtol) {
            const OnsetEstimate e = onset_estimate(V1, V2, qw1, qw2, h, rtol);
            return std::make_pair(e.value, e.error);
        },
        py::arg("V1"), py::arg("V2"), py::arg("qw1"), py::arg("qw2"), py::arg("h"), py::arg("rtol") = 1e-6);
    m.def(
        "_onset_estimate_closed_form",
        [](double w1, double a1, double w2, double a2, double qw1, double qw2, double h, double rtol) {
            const OnsetEstimate e = onset_estimate_closed_form(w1, a1, w2, a2, qw1, qw2, h, rtol);
            return std::make_pair(e.value, e.error);
        },
        py::arg("omega1"), py::arg("alpha1"), py::arg("omega2"), py::arg("alpha2"), py::arg("qw1"), py::arg("qw2"),
        py::arg("h"), py::arg("rtol") = 1e-6);
}
