#pragma once
// What a batch iteration of either model does besides stepping: the options the truncated maps'
// iterate (IterateOptions) and the flow map's (FlowIterateOptions) share, with their one
// validator, so that both refuse the same bad value with the same words.

#include <atomic>
#include <cstdint>

#include "hovering/curve.hpp"

namespace hovering {

/// The options every batch iteration takes (IterateOptions and FlowIterateOptions add their own).
struct BatchOptions {
    std::int64_t n_steps = 0;  ///< steps (returns) per orbit, >= 0
    /// Bit r set: Region r is in the watched set (for exit_step / stop_on_exit); 0 disables the watch.
    unsigned exit_mask = 0;
    bool stop_on_exit = false;  ///< stop an orbit (Status::Exited) when it first leaves the set
    /// Stop an orbit (Status::Stopped) at the first state x_n (x_0 included) in the set; a state
    /// outside the band is Escaped instead.
    StopCondition stop;
    std::int64_t every = 1;                     ///< record every k-th state (and the return from it), k >= 1
    int n_threads = 0;                          ///< worker threads; 0 = all hardware threads
    const std::atomic<bool>* cancel = nullptr;  ///< polled while the batch runs; set it to stop early
    /// Steps (returns) accounted for (relaxed increments; an orbit that stops early adds the steps it
    /// will not take), so it ends at n * n_steps unless cancelled. Null: not counted.
    std::atomic<std::int64_t>* progress = nullptr;

    /// Throw std::invalid_argument naming the first bad field, its value and the allowed range.
    void validate() const;
    /// Whether the caller asked to stop (cancel set).
    bool cancelled() const { return cancel && cancel->load(std::memory_order_relaxed); }
};

}  // namespace hovering
