// bench_util.h — timing and sampling helpers for cloudgen_bench.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "cloudgen/model.h"

namespace cgbench {

// Wall-clock seconds of each repetition, and their best and median.
struct Timing {
  std::vector<double> seconds;      // wall clock
  std::vector<double> cpu_seconds;  // CPU time of the whole process (all threads) in the same runs
  double cpu_best() const;
  double best() const;
  double median() const;
};

// Runs `body` once untimed (warm-up) unless warmup is false, then `reps` times timed.
Timing time_reps(int reps, const std::function<void()>& body, bool warmup = true);

// Points drawn uniformly inside the cloud box (local space), deterministic.
// When `need_noise` is true, points where the shape alone proves the density
// is 0 (density() returns before evaluating noise) are rejected, so every
// point costs a real noise evaluation. `rejected` receives the fraction of
// uniform box points that were rejected.
std::vector<cg::vec3> box_points(const cg::Model& m, std::size_t count, std::uint64_t seed, bool need_noise,
                                 double* rejected = nullptr);

// "1.23 M" style, for the human table.
std::string si(double v, int precision = 3);

// The 1-minute load average now (from /proc/loadavg), -1 if unavailable.
double load_average();

// Consumes a float so the compiler cannot drop the work that made it.
void sink(float v);
float sunk();

}  // namespace cgbench
