#pragma once
// The one owner of every GIL acquisition the bindings make on their own initiative: the caller's
// re-acquisition after a long computation (GilRelease), the progress and signal watcher, the calls
// of Python-defined potentials from the core's worker threads, and the Python references dropped
// on threads that do not hold the GIL. (The GIL a Python caller holds when it calls in is not ours.)
//
// Why: from the moment CPython sets its finalising flag, a thread other than the finalising one
// that takes the GIL is ended by CPython (pthread_exit, a forced unwinding). Through C++ frames that
// is std::terminate (a noexcept destructor, a joinable std::thread) or "FATAL: exception not
// rethrown" (a catch (...) that keeps the exception), i.e. an abort of the whole process at exit.
// Checking the flag before taking the GIL cannot help: the flag may be set between the check and
// the acquisition, or while the thread waits for the GIL.
//
// How: every such acquisition passes a gate first. An `atexit` hook (registered when the module is
// imported; atexit callbacks run with the GIL held, after the non-daemon threads are joined and
// before CPython sets its finalising flag) closes the gate and then waits, with the GIL released,
// until no thread is between "passed the gate" and "done with the GIL". After that no thread but
// the finalising one takes the GIL through us: a caller whose long computation ends later, or a
// thread about to call a Python-defined potential, parks (sleeps until the process ends, as
// CPython 3.14 does with daemon threads; one that holds the GIL releases it first), a progress
// report is skipped, a reference is leaked. The gate is a single atomic word: no lock that a fork
// or an exit could leave held.
//
// pybind11 takes the GIL on its own in two places our threads reach: its lazy one-time set-up of
// NumPy (done at import instead: register_gil_gate) and the destructor of a Python exception
// (error_already_set) dropped on a thread without the GIL (bind_potential.cpp wraps the exceptions
// of Python-defined potentials so that they are dropped through the gate).
//
// While the finalising thread itself waits in a long computation (a hovering call in a later atexit
// callback), it cannot finalise: other threads (its own workers) may pass then, and it waits for
// them before it takes the GIL back.
//
// The GIL a Python caller holds is not ours, but Python code our frames run on its thread may hand
// it to another thread and take it back: any bytecode (the interpreter's periodic switch) and
// NumPy's casts and copies of large arrays (astype). Taken back after finalisation began, CPython
// ends the thread there, and the unwinding runs our frames' destructors without the GIL
// (Py_DECREF: a crash) or aborts at a noexcept frame (std::terminate).
// Such code runs inside a pass as well (a Gil: on a thread that holds the GIL it only takes the
// pass; on_main_thread in signals.hpp), or is not called from a binding at all (hovering_estimate
// fills its bool arrays itself). The same holds for NumPy's own C++ (np.unique's hash table takes
// the GIL back in a destructor): the package's Python code run by a long call uses
// hovering._arrays.unique instead, and a caller waiting for pieces on a thread pool parks at exit
// (hovering.parallel.executor).

#include <Python.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <thread>

#include "pybind.hpp"

namespace hovering_py {

/// The gate every GIL acquisition of the bindings goes through (see the top of this file).
class GilGate {
public:
    /// How a thread passed the gate.
    enum class Pass : std::uint8_t {
        Refused,    ///< gate closed for this thread: do not take the GIL
        Counted,    ///< passed; the finaliser waits for leave()
        Finaliser,  ///< the thread that closed the gate, before CPython finalises (not counted)
    };

    /// Ask to take the GIL (holding it already or not). Never blocks. A Refused thread must not
    /// take the GIL nor run Python code; any other pass must be given back with leave().
    static Pass enter() noexcept {
        if (finaliser()) return Py_IsInitialized() ? Pass::Finaliser : Pass::Refused;
        std::uint64_t w = word().load();
        for (;;) {
            // Open; or closed while the finaliser waits in a computation before it finalised; or
            // this thread holds a pass already (the finaliser waits for it: refusing it would
            // leave that wait without end).
            const bool open = !(w & kClosed) || ((w & kBusyMask) != 0 && !finalizing()) || held() > 0;
            if (!open) return Pass::Refused;
            if (word().compare_exchange_weak(w, w + 1)) {
                ++held();
                return Pass::Counted;
            }
        }
    }

    /// Done with the GIL (released it, or returned to Python): the end of what enter() began.
    static void leave(Pass p) noexcept {
        if (p != Pass::Counted) return;
        --held();
        std::uint64_t w = word().load();
        // Never below zero: a fork child starts from zero passes (after_fork_in_child).
        while ((w & kInsideMask) != 0 && !word().compare_exchange_weak(w, w - 1)) {
        }
    }

    /// The atexit hook (GIL held): close the gate, then wait, with the GIL released, until every
    /// thread that passed it is done. Idempotent.
    static void close() {
        finaliser() = true;
        word().fetch_or(kClosed);
        if (inside() == 0) return;
        Py_BEGIN_ALLOW_THREADS wait_until_empty();
        Py_END_ALLOW_THREADS
    }

    /// Sleep until the process ends: what a thread the gate refused does instead of calling
    /// Python. A thread holding the GIL (one that called in after the gate closed) releases it
    /// first, so that the interpreter can finalise.
    [[noreturn]] static void park() noexcept {
        if (holds_gil()) PyEval_SaveThread();
        for (;;) std::this_thread::sleep_for(std::chrono::hours(1));
    }

    /// What a computation does where it needs Python and the gate refused: park, except on the
    /// finalising thread (refused only once CPython finalises), which nothing would end: there the
    /// computation fails instead (a hovering call from a destructor run by the finalisation).
    [[noreturn]] static void refused() {
        if (finaliser()) throw std::runtime_error("Python can no longer be called: the interpreter is finalising");
        park();
    }

    /// Whether CPython's finalising flag is set (from then on only the finalising thread may take
    /// the GIL).
    static bool finalizing() noexcept {
#if PY_VERSION_HEX >= 0x030D0000
        return Py_IsFinalizing() != 0;
#else
        return _Py_IsFinalizing() != 0;
#endif
    }

    /// Called by the finaliser when it releases the GIL for a computation (others may pass then);
    /// true if it was the finaliser (then end_busy() must follow).
    static bool begin_busy() noexcept {
        if (!finaliser()) return false;
        word().fetch_add(kBusyOne);
        return true;
    }

    /// The finaliser's computation ended: no one passes any more; wait until those who did are
    /// done, before the finaliser takes the GIL back.
    static void end_busy() noexcept {
        word().fetch_sub(kBusyOne);
        wait_until_empty();
    }

    /// In a child made by os.fork only the forking thread exists: the passes other threads held
    /// went with them (an exit of the child would wait for them forever).
    static void after_fork_in_child() noexcept { word().fetch_and(kClosed); }

private:
    static constexpr std::uint64_t kClosed = std::uint64_t(1) << 63;
    static constexpr std::uint64_t kBusyOne = std::uint64_t(1) << 32;
    static constexpr std::uint64_t kBusyMask = (kClosed - 1) & ~(kBusyOne - 1);
    static constexpr std::uint64_t kInsideMask = kBusyOne - 1;

    /// closed (bit 63), finaliser's computations under way (bits 32-62), passes held (bits 0-31).
    /// Trivially destructible: threads parked or running at exit() may still read it.
    static std::atomic<std::uint64_t>& word() noexcept {
        static std::atomic<std::uint64_t> w{0};
        return w;
    }
    /// Whether the calling thread closed the gate (the thread that finalises the interpreter).
    static bool& finaliser() noexcept {
        static thread_local bool f = false;
        return f;
    }
    /// Passes the calling thread holds.
    static int& held() noexcept {
        static thread_local int n = 0;
        return n;
    }
    static std::uint64_t inside() noexcept { return word().load() & kInsideMask; }
    /// Whether the calling thread holds the GIL; safe at any time, also while or after the
    /// interpreter finalises: the thread state holding the GIL (3.11: any thread's; 3.12+: this
    /// thread's, or null) is compared with this thread's own, pointers only (PyGILState_Check
    /// answers 1 once its thread-local key is gone).
    static bool holds_gil() noexcept {
        PyThreadState* const current = py::detail::get_thread_state_unchecked();
        return current != nullptr && current == PyGILState_GetThisThreadState();
    }
    static void wait_until_empty() noexcept {
        while (inside() != 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
};

/// Releases the GIL for a pure C++ computation and takes it back at the end, through the gate:
/// if the interpreter has begun to exit by then, the thread parks until the process ends instead
/// (its result is never seen).
class GilRelease {
public:
    GilRelease() : state_(PyEval_SaveThread()), busy_(GilGate::begin_busy()) {}
    ~GilRelease() {
        if (busy_) {
            GilGate::end_busy();
            PyEval_RestoreThread(state_);
            return;
        }
        const GilGate::Pass p = GilGate::enter();
        if (p == GilGate::Pass::Refused) GilGate::park();
        PyEval_RestoreThread(state_);
        GilGate::leave(p);
    }
    GilRelease(const GilRelease&) = delete;
    GilRelease& operator=(const GilRelease&) = delete;

private:
    PyThreadState* state_;
    bool busy_;
};

/// Holds the GIL for one stretch of Python work started from C++, on any thread (one holding the
/// GIL already, a Python thread that released it, or a thread Python does not know), through the
/// gate. Test it: false means the interpreter is exiting and nothing of Python may be touched
/// (the GIL is not held then).
///
/// On a thread Python does not know (the core's workers), the first acquisition creates a Python
/// thread state; it is kept, with one extra reference, until the thread ends, instead of being
/// created and destroyed every time (which made a two-thread return map with Python potentials
/// 16x slower: 21 ms instead of 1.3 ms per return). Threads Python created are left alone.
class Gil {
public:
    Gil() : pass_(GilGate::enter()) {
        if (pass_ == GilGate::Pass::Refused) return;
        const bool fresh = PyGILState_GetThisThreadState() == nullptr;
        gil_.emplace();
        if (fresh) {
            gil_->inc_ref();
            keeper().kept = true;
        }
    }
    ~Gil() {
        gil_.reset();
        GilGate::leave(pass_);
    }
    Gil(const Gil&) = delete;
    Gil& operator=(const Gil&) = delete;
    /// Whether the GIL is held (false: the interpreter is exiting).
    explicit operator bool() const { return pass_ != GilGate::Pass::Refused; }

private:
    /// Drops the kept thread state when its thread ends (leaks it if the interpreter is exiting).
    struct Keeper {
        bool kept = false;
        ~Keeper() {
            if (!kept) return;
            const GilGate::Pass p = GilGate::enter();
            if (p == GilGate::Pass::Refused) return;
            {
                py::gil_scoped_acquire gil;
                gil.dec_ref();  // the extra reference: the state is deleted when `gil` ends
            }
            GilGate::leave(p);
        }
    };
    static Keeper& keeper() {
        static thread_local Keeper k;
        return k;
    }
    GilGate::Pass pass_;
    std::optional<py::gil_scoped_acquire> gil_;
};

/// Registers the gate's atexit hook and its fork handler (once, at import of the module; they are
/// not names of the module: nothing else may call them).
inline void register_gil_gate() {
    // pybind11 sets up its NumPy state lazily, and the first use releases and re-takes the GIL
    // (gil_safe_call_once_and_store), outside the gate: first used by a daemon thread's call that
    // started as the interpreter exits, that aborted the process. Done here, on the importing
    // thread, it never happens later.
    py::detail::npy_api::get();
    (void)py::dtype(py::buffer_info(static_cast<double*>(nullptr), 0));  // its PEP 3118 parser, the other one
    py::module_::import("atexit").attr("register")(py::cpp_function(&GilGate::close));
    const py::module_ os = py::module_::import("os");
    if (py::hasattr(os, "register_at_fork"))
        os.attr("register_at_fork")(py::arg("after_in_child") = py::cpp_function(&GilGate::after_fork_in_child));
}

}  // namespace hovering_py
