// parallel.cpp — interruptible parallel loop on std::thread.
#include "cloudgen/parallel.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#if defined(__linux__)
#include <sched.h>
#endif

namespace cg {

int usable_cores() {
#if defined(__linux__)
  // The cores this process may run on (taskset, cgroup cpusets, a farm's slot),
  // not every core of the machine.
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof set, &set) == 0) {
    const int n = CPU_COUNT(&set);
    if (n > 0) return n;
  }
#endif
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

int resolve_threads(int requested) { return requested > 0 ? requested : usable_cores(); }

bool parallel_for(std::int64_t count, int threads, const std::function<void(std::int64_t, int)>& body,
                  const Progress& progress) {
  if (count <= 0) return progress ? progress(0, 0) : true;
  const int n_workers = static_cast<int>(std::min<std::int64_t>(resolve_threads(threads), count));
  std::atomic<std::int64_t> next{0}, done{0};
  std::atomic<bool> stop{false};
  std::exception_ptr error;
  std::mutex error_mutex;

  auto work = [&](int worker) {
    while (!stop.load(std::memory_order_relaxed)) {
      const std::int64_t item = next.fetch_add(1, std::memory_order_relaxed);
      if (item >= count) break;
      try {
        body(item, worker);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        stop = true;
      }
      done.fetch_add(1, std::memory_order_relaxed);
    }
  };

  std::vector<std::thread> pool;
  for (int w = 1; w < n_workers; ++w) pool.emplace_back(work, w);
  bool cancelled = false;
  if (!progress) {
    work(0);
  } else {
    // The calling thread reports progress and works in between reports.
    std::thread helper;
    if (n_workers >= 1) helper = std::thread(work, 0);
    auto last_report = std::chrono::steady_clock::now();
    while (done.load() < count && !stop.load()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      const auto now = std::chrono::steady_clock::now();
      if (now - last_report < std::chrono::milliseconds(100)) continue;
      last_report = now;
      if (!progress(done.load(), count)) {
        cancelled = true;
        stop = true;
      }
    }
    helper.join();
  }
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
  if (!cancelled && progress) cancelled = !progress(done.load(), count);
  return !cancelled && done.load() == count;
}

}  // namespace cg
