#pragma once
// Long core computations with the GIL released and Ctrl-C honoured: the work runs on a runner
// thread while the calling thread, if it is Python's main thread (the only one signal handlers
// run on), polls PyErr_CheckSignals every 100 ms. On KeyboardInterrupt the core's cancel flag is
// set; the core then ends every orbit promptly with an Interrupted status and keeps what it
// computed, and the Python wrapper raises KeyboardInterrupt with that partial result attached.
// The same waiting thread reports progress to a Python callable (ProgressReport) when asked to.
// Every GIL acquisition here goes through the gate of gil.hpp (none once the interpreter exits).
//
// The runner is a new thread per call. When the process can start no thread (ulimit -u, a pids
// limit, or an address space too full for another stack: a long-lived process under load), the
// work used to run on the calling thread, where nothing polls for signals: Ctrl-C and kill -INT
// were ignored and progress went silent until the call ended (minutes to hours), in that process
// only. The runner is then the reserve thread (ReserveRunner), started by an earlier call while
// threads could still be started and kept for the life of the process.

#include <Python.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <new>
#include <system_error>
#include <thread>

#include "gil.hpp"
#include "pybind.hpp"

namespace hovering_py {

/// One thread kept for the life of the process, which runs a watched call's work when no new
/// thread can be started (see the top of this file). It is started by the first watched call (and
/// again by the first one in a child of os.fork, where the parent's threads do not exist); it never
/// touches Python while idle, and is neither joined nor destroyed (nothing waits for it at exit).
/// One call at a time uses it; a second one that finds no thread runs on its calling thread.
class ReserveRunner {
public:
    /// This process's reserve (null only if not even the object could be allocated); its thread
    /// may not be running yet (start()).
    static ReserveRunner* get() noexcept {
        static std::atomic<ReserveRunner*> current{nullptr};
        const pid_t pid = getpid();
        ReserveRunner* r = current.load();
        while (r == nullptr || r->pid_ != pid) {  // none yet, or the parent's (gone with os.fork)
            ReserveRunner* fresh = new (std::nothrow) ReserveRunner(pid);
            if (fresh == nullptr) return nullptr;
            if (current.compare_exchange_strong(r, fresh)) return fresh;  // the parent's is leaked
            delete fresh;  // another thread made it first: r is now theirs
        }
        return r;
    }

    /// Start the thread if it is not running yet; whether it runs. A refused start is tried again
    /// by the next call.
    bool start() noexcept {
        try {
            std::call_once(started_once_, [this] {
                std::thread([this] { loop(); }).detach();
                started_ = true;
            });
        } catch (...) {  // std::system_error: no thread to spare now
        }
        return started_;
    }

    /// Run fn(arg) on the reserve thread if it runs and is idle (true); else false and nothing runs.
    bool try_run(void (*fn)(void*), void* arg) noexcept {
        if (!start()) return false;
        std::lock_guard<std::mutex> lock(mu_);
        if (busy_) return false;
        busy_ = true;
        fn_ = fn;
        arg_ = arg;
        cv_.notify_all();
        return true;
    }

    /// Wait until what try_run started has returned (and no longer touches anything of the caller's).
    void wait() noexcept {
        std::unique_lock<std::mutex> lock(mu_);
        cv_.wait(lock, [this] { return !busy_; });
    }

private:
    explicit ReserveRunner(pid_t pid) : pid_(pid) {}
    void loop() noexcept {
        std::unique_lock<std::mutex> lock(mu_);
        for (;;) {
            cv_.wait(lock, [this] { return fn_ != nullptr; });
            void (*fn)(void*) = fn_;
            void* arg = arg_;
            fn_ = nullptr;
            lock.unlock();
            fn(arg);  // catches everything itself (run_watched's runner)
            lock.lock();
            busy_ = false;
            cv_.notify_all();
        }
    }
    const pid_t pid_;
    std::once_flag started_once_;
    bool started_ = false;  // written once, inside call_once (which orders it before later reads)
    std::mutex mu_;
    std::condition_variable cv_;
    bool busy_ = false;
    void (*fn_)(void*) = nullptr;
    void* arg_ = nullptr;
};

/// Whether the calling thread (GIL held) is Python's main thread. It runs Python code (threading's),
/// which may hand the GIL to another thread and take it back: through the gate, as every GIL
/// acquisition with our frames on the stack (gil.hpp); a daemon thread that calls in once the
/// interpreter exits parks here.
inline bool on_main_thread() {
    const Gil gil;
    if (!gil) GilGate::refused();
    const auto threading = py::module_::import("threading");
    return threading.attr("current_thread")().is(threading.attr("main_thread")());
}

/// Progress of a core computation as run_watched reports it: the core's counter (relaxed
/// increments), the value it ends at, and a Python callable progress(done, total).
struct ProgressReport {
    const std::atomic<std::int64_t>* done = nullptr;  ///< the core's counter
    std::int64_t total = 0;                           ///< where the counter ends when nothing is cancelled
    py::object callback;                              ///< progress(done, total); None or null: no report
    /// Whether there is anything to report to.
    bool active() const { return done != nullptr && callback && !callback.is_none(); }
};

/// Run work() with the GIL released. watch: poll for signals (pass false for short work, where a
/// watcher thread would cost more than the work). Returns true if Ctrl-C interrupted it (cancel
/// is then set); an exception raised by another signal handler (e.g. SIGALRM's) is rethrown
/// unchanged once the work has stopped, as is any exception of the work itself.
///
/// With an active progress report the waiting thread also calls progress(done, total) (GIL held)
/// every ~100 ms and once at the end, whatever the size of the work and on any thread (signals
/// are only polled on the main thread). An exception the callable raises stops the work like a
/// signal handler's: KeyboardInterrupt (Ctrl-C landing inside the callable) counts as Ctrl-C,
/// anything else is rethrown once the work has stopped.
template <class Work>
bool run_watched(Work&& work, std::atomic<bool>& cancel, bool watch, const ProgressReport* progress = nullptr) {
    const bool signals = watch && on_main_thread();
    const bool report = progress != nullptr && progress->active();
    bool interrupted = false;
    std::unique_ptr<py::error_already_set> handler_error;
    // progress(done, total), GIL held; what it raises stops the work (see above).
    auto call_progress = [&] {
        try {
            progress->callback(progress->done->load(std::memory_order_relaxed), progress->total);
        } catch (py::error_already_set& e) {
            cancel.store(true);
            if (e.matches(PyExc_KeyboardInterrupt))
                interrupted = true;  // re-raised by the Python wrapper, with the partial result
            else if (!handler_error)
                handler_error = std::make_unique<py::error_already_set>(std::move(e));
        }
    };
    {
        GilRelease release;
        if (!signals && !report) {
            work();
        } else {
            std::exception_ptr err;
            std::mutex mu;
            std::condition_variable cv;
            bool done = false;
            auto run = [&] {
                try {
                    work();
                } catch (...) {
                    err = std::current_exception();
                }
                std::lock_guard<std::mutex> lock(mu);
                done = true;
                cv.notify_one();
            };
            // Started now, while threads can be: it is what runs the work once none can.
            ReserveRunner* const reserve = ReserveRunner::get();
            if (reserve != nullptr) reserve->start();
            std::thread runner;
            bool threaded = true, on_reserve = false;
            try {
                runner = std::thread(run);
            } catch (const std::system_error&) {
                // No new thread (see the top of this file): the reserve runs the work; if it is
                // busy with another call too, compute here, where only Ctrl-C's promptness and the
                // intermediate progress reports are lost, not the result.
                on_reserve = reserve != nullptr &&
                             reserve->try_run([](void* r) { (*static_cast<decltype(run)*>(r))(); }, &run);
                threaded = on_reserve;
            }
            if (!threaded) {
                work();
            } else {
                std::unique_lock<std::mutex> lock(mu);
                while (!cv.wait_for(lock, std::chrono::milliseconds(100), [&] { return done; })) {
                    lock.unlock();
                    if (!cancel.load()) {
                        const Gil gil;  // false once the interpreter exits: no signal, no report then
                        if (gil && signals && PyErr_CheckSignals() != 0) {
                            cancel.store(true);
                            if (PyErr_ExceptionMatches(PyExc_KeyboardInterrupt)) {
                                PyErr_Clear();  // re-raised by the Python wrapper, with the partial result
                                interrupted = true;
                            } else {
                                handler_error = std::make_unique<py::error_already_set>();
                            }
                        }
                        if (gil && report && !cancel.load()) call_progress();
                    }
                    lock.lock();
                }
                lock.unlock();
                if (on_reserve)
                    reserve->wait();
                else
                    runner.join();
                if (err) std::rethrow_exception(err);
            }
        }
    }
    if (report && !handler_error) {  // once at the end (GIL held again), unless the interpreter exits
        const Gil gil;
        if (gil) call_progress();
    }
    if (handler_error) throw std::move(*handler_error);  // what a signal handler raised, unchanged
    return interrupted;
}

}  // namespace hovering_py
