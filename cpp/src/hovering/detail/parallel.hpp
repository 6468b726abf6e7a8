#pragma once
// The core's one thread pool: batch iterations of the truncated map, batch return maps and the
// flow map's iterations all hand out independent orbits to workers through a WorkQueue.

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

namespace hovering::detail {

/// Largest thread count a caller may ask for (0 means one per hardware thread).
inline constexpr int kMaxThreads = 4096;

/// Indices [0, n) handed out in blocks from one shared counter (lock-free).
struct WorkQueue {
    std::atomic<std::int64_t> next{0};
    std::int64_t n = 0;      ///< number of items
    std::int64_t block = 1;  ///< items taken per visit to the shared counter
    WorkQueue(std::int64_t n_items, std::int64_t block_size)
        : n(n_items), block(std::max<std::int64_t>(1, block_size)) {}
    /// Hand out nothing more (cancellation, or a worker failed).
    void stop() { next.store(n); }
};

/// One worker's view of a WorkQueue: pops its block item by item.
struct WorkCursor {
    WorkQueue& q;
    std::int64_t cur = 0, end = 0;
    explicit WorkCursor(WorkQueue& queue) : q(queue) {}
    /// Next item index; false when the queue is exhausted.
    bool pop(std::int64_t& i) {
        if (cur == end) {
            cur = q.next.fetch_add(q.block);
            if (cur >= q.n) {
                cur = end = q.n;
                return false;
            }
            end = std::min(q.n, cur + q.block);
        }
        i = cur++;
        return true;
    }
};

/// One worker's share of a progress counter: units (steps, returns) gather locally and are added
/// to the shared counter (relaxed, so the hot loop has no atomic) once `chunk` of them have
/// gathered, and when the worker ends. A null target makes every call a no-op.
class ProgressShare {
public:
    /// Report into target (may be null) in chunks of at least `chunk` units.
    ProgressShare(std::atomic<std::int64_t>* target, std::int64_t chunk) : target_(target), chunk_(chunk) {}
    ~ProgressShare() { flush(); }
    ProgressShare(const ProgressShare&) = delete;
    ProgressShare& operator=(const ProgressShare&) = delete;
    /// Count k more units done.
    void add(std::int64_t k) {
        if (!target_) return;
        pending_ += k;
        if (pending_ >= chunk_) flush();
    }
    /// Hand the units gathered so far to the shared counter.
    void flush() {
        if (target_ && pending_ != 0) target_->fetch_add(pending_, std::memory_order_relaxed);
        pending_ = 0;
    }

private:
    std::atomic<std::int64_t>* target_;
    std::int64_t chunk_;
    std::int64_t pending_ = 0;
};

/// Hardware threads of this machine, asked once: glibc reads /sys/devices/system/cpu/online on every
/// std::thread::hardware_concurrency() call, ~5 us, as much as a return of the flow.
inline unsigned hardware_threads() {
    static const unsigned n = std::thread::hardware_concurrency();
    return n;
}

/// Worker threads for a batch: `requested` (0 = all hardware threads), at least 1, at most `useful`.
inline int worker_count(int requested, std::int64_t useful) {
    std::int64_t t = requested > 0 ? requested : std::int64_t(hardware_threads());
    return int(std::clamp<std::int64_t>(t, 1, std::max<std::int64_t>(1, useful)));
}

/// Block size that keeps workers balanced when items take very different times (early exit):
/// about 8 blocks per worker, at most `cap` items each.
inline std::int64_t balanced_block(std::int64_t n, int threads, std::int64_t cap) {
    return std::clamp<std::int64_t>((n + 8 * std::int64_t(threads) - 1) / (8 * std::int64_t(threads)), 1, cap);
}

/// Run body(cursor) on `threads` workers, the calling thread being one of them. The first
/// exception a worker throws stops the queue (the others drain no more work) and is rethrown once
/// all have returned. Threads the system refuses to start are done without: the others share their work.
template <class Body>
void run_workers(int threads, WorkQueue& q, Body&& body) {
    std::exception_ptr error;
    std::mutex mu;
    auto work = [&] {
        try {
            WorkCursor c(q);
            body(c);
        } catch (...) {
            std::lock_guard<std::mutex> lock(mu);
            if (!error) error = std::current_exception();
            q.stop();
        }
    };
    std::vector<std::thread> pool;
    pool.reserve(std::size_t(std::max(0, threads - 1)));
    try {
        for (int k = 1; k < threads; ++k) pool.emplace_back(work);
    } catch (const std::system_error&) {
        // The system refused more threads (ulimit -u, a container's pids limit): the workers share
        // one queue and each orbit's result does not depend on who computes it, so the ones that
        // started (and this thread) finish the job, only slower.
    }
    work();
    for (auto& t : pool) t.join();
    if (error) std::rethrow_exception(error);
}

}  // namespace hovering::detail
