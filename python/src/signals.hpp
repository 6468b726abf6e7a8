#pragma once
// Long core computations with the GIL released and Ctrl-C honoured: the work runs on a runner
// thread while the calling thread, if it is Python's main thread (the only one signal handlers
// run on), polls PyErr_CheckSignals every 100 ms. On KeyboardInterrupt the core's cancel flag is
// set; the core then ends every orbit promptly with an Interrupted status and keeps what it
// computed, and the Python wrapper raises KeyboardInterrupt with that partial result attached.

#include <Python.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <system_error>
#include <thread>

#include "pybind.hpp"

namespace hovering_py {

/// Releases the GIL for a pure C++ computation and takes it back at the end, like
/// py::gil_scoped_release, except when the interpreter is finalising by then (the call ran on a
/// daemon thread, or on a thread the main thread stopped waiting for): taking the GIL would make
/// CPython exit the thread by forced unwinding, which through this (noexcept) destructor ends in
/// std::terminate ("terminate called without an active exception", exit 134). The thread then
/// parks until the process ends instead, as CPython 3.14 itself does with daemon threads.
class GilRelease {
public:
    GilRelease() : state_(PyEval_SaveThread()) {}
    ~GilRelease() {
        while (finalizing()) std::this_thread::sleep_for(std::chrono::seconds(1));
        PyEval_RestoreThread(state_);
    }
    GilRelease(const GilRelease&) = delete;
    GilRelease& operator=(const GilRelease&) = delete;
    /// Whether the interpreter is shutting down (taking the GIL would end the calling thread).
    static bool finalizing() {
#if PY_VERSION_HEX >= 0x030D0000
        return Py_IsFinalizing() != 0;
#else
        return _Py_IsFinalizing() != 0;
#endif
    }

private:
    PyThreadState* state_;
};

/// Whether the calling thread (GIL held) is Python's main thread.
inline bool on_main_thread() {
    const auto threading = py::module_::import("threading");
    return threading.attr("current_thread")().is(threading.attr("main_thread")());
}

/// Run work() with the GIL released. watch: poll for signals (pass false for short work, where a
/// watcher thread would cost more than the work). Returns true if Ctrl-C interrupted it (cancel
/// is then set); an exception raised by another signal handler (e.g. SIGALRM's) is rethrown
/// unchanged once the work has stopped, as is any exception of the work itself.
template <class Work>
bool run_watched(Work&& work, std::atomic<bool>& cancel, bool watch) {
    watch = watch && on_main_thread();
    bool interrupted = false;
    std::unique_ptr<py::error_already_set> handler_error;
    {
        GilRelease release;
        if (!watch) {
            work();
        } else {
            std::exception_ptr err;
            std::mutex mu;
            std::condition_variable cv;
            bool done = false;
            std::thread runner;
            try {
                runner = std::thread([&] {
                    try {
                        work();
                    } catch (...) {
                        err = std::current_exception();
                    }
                    std::lock_guard<std::mutex> lock(mu);
                    done = true;
                    cv.notify_one();
                });
            } catch (const std::system_error&) {
                // No thread to spare (ulimit -u, a container's pids limit): compute here; only
                // Ctrl-C's promptness is lost, not the result.
                work();
                return false;
            }
            std::unique_lock<std::mutex> lock(mu);
            while (!cv.wait_for(lock, std::chrono::milliseconds(100), [&] { return done; })) {
                lock.unlock();
                if (!cancel.load()) {
                    py::gil_scoped_acquire acquire;
                    if (PyErr_CheckSignals() != 0) {
                        cancel.store(true);
                        if (PyErr_ExceptionMatches(PyExc_KeyboardInterrupt)) {
                            PyErr_Clear();  // re-raised by the Python wrapper, with the partial result
                            interrupted = true;
                        } else {
                            handler_error = std::make_unique<py::error_already_set>();
                        }
                    }
                }
                lock.lock();
            }
            lock.unlock();
            runner.join();
            if (err) std::rethrow_exception(err);
        }
    }
    if (handler_error) throw std::move(*handler_error);  // what a signal handler raised, unchanged
    return interrupted;
}

}  // namespace hovering_py
