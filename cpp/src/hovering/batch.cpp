// The one validator of the batch options both models share: see batch.hpp.

#include "hovering/batch.hpp"

#include <string>

#include "hovering/detail/common.hpp"
#include "hovering/detail/parallel.hpp"
#include "hovering/types.hpp"

namespace hovering {

using detail::bad;

void BatchOptions::validate() const {
    if (n_steps < 0) bad("n_steps must be >= 0, got " + std::to_string(n_steps));
    if (exit_mask >= (1u << kRegionCount))
        bad("exit_mask must be a set of region codes 0.." + std::to_string(kRegionCount - 1) + " (a bit mask < " +
            std::to_string(1u << kRegionCount) + "), got " + std::to_string(exit_mask));
    if (stop_on_exit && exit_mask == 0u) bad("stop_on_exit needs a non-empty set of regions to stay in");
    if (n_threads < 0 || n_threads > detail::kMaxThreads)
        bad("n_threads must be in [0, " + std::to_string(detail::kMaxThreads) + "] (0 = all cores), got " +
            std::to_string(n_threads));
    if (every < 1) bad("every must be >= 1 (record every k-th state), got " + std::to_string(every));
    stop.validate();
}

}  // namespace hovering
