// cloudgen/parallel.h — a small interruptible parallel loop.
#pragma once

#include <cstdint>
#include <functional>

namespace cg {

// Called on the calling thread about every 100 ms and once at the end with
// (items done, items total). Return false to cancel: no new items are started,
// items already running finish, and parallel_for returns false.
using Progress = std::function<bool(std::int64_t done, std::int64_t total)>;

// Cores this process may run on: its CPU affinity (taskset, cpusets) where the
// system tells, else the hardware threads; at least 1.
int usable_cores();

// Number of worker threads to use for `requested` (0 = one per usable core).
int resolve_threads(int requested);

// Runs body(item, worker) for every item in [0, count) on `threads` workers
// (worker in [0, threads)). Returns true when every item ran, false when cancelled.
bool parallel_for(std::int64_t count, int threads, const std::function<void(std::int64_t item, int worker)>& body,
                  const Progress& progress = {});

}  // namespace cg
