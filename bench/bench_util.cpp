// bench_util.cpp — timing and sampling helpers for cloudgen_bench.
#include "bench_util.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>

namespace cgbench {

double Timing::best() const { return seconds.empty() ? 0.0 : *std::min_element(seconds.begin(), seconds.end()); }

double Timing::cpu_best() const {
  return cpu_seconds.empty() ? 0.0 : *std::min_element(cpu_seconds.begin(), cpu_seconds.end());
}

double Timing::median() const {
  if (seconds.empty()) return 0.0;
  std::vector<double> s = seconds;
  std::sort(s.begin(), s.end());
  const std::size_t n = s.size();
  return n % 2 ? s[n / 2] : 0.5 * (s[n / 2 - 1] + s[n / 2]);
}

namespace {
double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}
}  // namespace

Timing time_reps(int reps, const std::function<void()>& body, bool warmup) {
  using clock = std::chrono::steady_clock;
  if (warmup) body();
  Timing t;
  for (int r = 0; r < reps; ++r) {
    const double cpu0 = process_cpu_seconds();
    const auto start = clock::now();
    body();
    const auto stop = clock::now();
    t.cpu_seconds.push_back(process_cpu_seconds() - cpu0);
    t.seconds.push_back(std::chrono::duration<double>(stop - start).count());
  }
  return t;
}

namespace {

// splitmix64: small, fast, and the same on every platform (unlike std distributions).
struct Rng {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  float uniform() { return float(next() >> 40) * (1.0f / 16777216.0f); }  // [0, 1)
};

}  // namespace

std::vector<cg::vec3> box_points(const cg::Model& m, std::size_t count, std::uint64_t seed, bool need_noise,
                                 double* rejected) {
  Rng rng{seed};
  std::vector<cg::vec3> pts;
  pts.reserve(count);
  std::uint64_t drawn = 0;
  // Give up on rejection after many tries (a shape that is empty everywhere):
  // then the points are plain box points.
  const std::uint64_t max_draws = std::uint64_t(count) * 1000 + 1000;
  while (pts.size() < count) {
    const cg::vec3 p{(rng.uniform() - 0.5f) * m.box[0], (rng.uniform() - 0.5f) * m.box[1],
                     (rng.uniform() - 0.5f) * m.box[2]};
    ++drawn;
    if (need_noise && drawn < max_draws && cg::cg_shape_proves_empty(cg::shape_at(m, p), m.distortion)) continue;
    pts.push_back(p);
  }
  if (rejected) *rejected = drawn ? double(drawn - count) / double(drawn) : 0.0;
  return pts;
}

std::string si(double v, int precision) {
  const char* suffix = "";
  double x = v;
  if (std::fabs(v) >= 1e9) {
    x = v / 1e9;
    suffix = " G";
  } else if (std::fabs(v) >= 1e6) {
    x = v / 1e6;
    suffix = " M";
  } else if (std::fabs(v) >= 1e3) {
    x = v / 1e3;
    suffix = " k";
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g%s", precision, x, suffix);
  return buf;
}

double load_average() {
  std::ifstream f("/proc/loadavg");
  double l = -1.0;
  if (f) f >> l;
  return l;
}

namespace {
volatile float g_sink = 0.0f;
}

void sink(float v) { g_sink = g_sink + v; }
float sunk() { return g_sink; }

}  // namespace cgbench
