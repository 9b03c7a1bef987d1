// Independent runs over the machine's cores with results that do not depend on the number
// of threads: task i writes only its own slot, every task is seeded from its index (never
// from the thread or the order it ran in), and the caller reads the slots in index order.
// Exceptions: the one of the lowest index is rethrown after every thread has stopped.
#pragma once

#include <cstddef>
#include <functional>

namespace jg::eval {

/// The number of threads for `--jobs 0` (all cores; at least 1).
int default_jobs();

/// Runs body(i) for i in [0, count) on up to `jobs` threads (the calling thread is one of
/// them). `progress` (may be empty) is called from the calling thread only, with the share
/// of tasks done, so it needs no locking.
void parallel_for(std::size_t count, int jobs, const std::function<void(std::size_t)>& body,
                  const std::function<void(double)>& progress = {});

}  // namespace jg::eval
