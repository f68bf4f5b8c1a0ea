// cloudgen_bench — throughput of the native cloud model, bake and preview.
//
//   cloudgen_bench [--reps N] [--points N] [--only samples,bake,preview]
//                  [--resolutions 128,256] [--json FILE] [--quick]
//   cloudgen_bench --callgrind-samples K [--kernel full|noise|perlin|worley|block_LEVEL] [--config defaults|cumulus]
//
// The first form times everything (best and median of N repetitions after one
// warm-up) and writes a human table to stdout and the raw numbers as JSON.
// The second evaluates exactly K samples on a fixed set of points and exits:
// bench/run.sh runs it under callgrind with K and 2K, so the difference of the
// two instruction counts divided by K is the cost of one sample, start-up
// (parsing presets, making points) cancelling out. block_LEVEL (LEVEL: scalar,
// baseline, avx2, avx512) is the batched kernel cg::density_block at that
// instruction-set level, in batches of 500 points (valgrind has no AVX-512).
// Bakes and previews use the level chosen at start-up: CLOUDGEN_SIMD forces one.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_util.h"
#include "cloudgen/density_block.h"
#include "cloudgen/grid.h"
#include "cloudgen/model.h"
#include "cloudgen/parallel.h"
#include "cloudgen/param_io.h"
#include "cloudgen/params.h"

using json = nlohmann::ordered_json;
using cgbench::si;

namespace {

#ifndef CLOUDGEN_BENCH_BUILD_TYPE
#define CLOUDGEN_BENCH_BUILD_TYPE "unknown"
#endif
#ifndef CLOUDGEN_BENCH_COMPILER
#define CLOUDGEN_BENCH_COMPILER "unknown"
#endif
#ifndef CLOUDGEN_BENCH_FLAGS
#define CLOUDGEN_BENCH_FLAGS ""
#endif

struct Options {
  int reps = 7;
  std::size_t points = 1 << 17;
  std::vector<int> resolutions{128, 256};
  bool samples = true, bake = true, preview = true;
  std::string json_path = "bench/results/native.json";
  long long callgrind_samples = 0;
  std::string kernel = "full", config = "defaults";
};

[[noreturn]] void usage_error(const std::string& msg) {
  std::fprintf(stderr, "cloudgen_bench: %s (see the header of bench/bench_main.cpp)\n", msg.c_str());
  std::exit(2);
}

std::vector<int> parse_ints(const std::string& s) {
  std::vector<int> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(std::stoi(item));
  return out;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage_error("missing value after " + a);
      return argv[++i];
    };
    try {
      if (a == "--reps")
        o.reps = std::max(1, std::stoi(value()));
      else if (a == "--points")
        o.points = std::max<long long>(4096, std::stoll(value()));
      else if (a == "--resolutions")
        o.resolutions = parse_ints(value());
      else if (a == "--json")
        o.json_path = value();
      else if (a == "--callgrind-samples")
        o.callgrind_samples = std::stoll(value());
      else if (a == "--kernel")
        o.kernel = value();
      else if (a == "--config")
        o.config = value();
      else if (a == "--quick") {
        o.reps = 2;
        o.points = 1 << 14;
        o.resolutions = {64};
      } else if (a == "--only") {
        const std::string v = value();
        o.samples = v.find("samples") != std::string::npos;
        o.bake = v.find("bake") != std::string::npos;
        o.preview = v.find("preview") != std::string::npos;
      } else if (a == "--help" || a == "-h") {
        std::puts(
            "cloudgen_bench [--reps N] [--points N] [--only samples,bake,preview] [--resolutions 128,256]\n"
            "               [--json FILE] [--quick]\n"
            "cloudgen_bench --callgrind-samples K [--kernel full|noise|perlin|worley|block_LEVEL]\n"
            "               [--config defaults|cumulus]");
        std::exit(0);
      } else
        usage_error("unknown argument " + a);
    } catch (const std::invalid_argument&) {
      usage_error("bad number after " + a);
    }
  }
  cg::SimdLevel unused;
  if (o.kernel != "full" && o.kernel != "noise" && o.kernel != "perlin" && o.kernel != "worley" &&
      !(o.kernel.rfind("block_", 0) == 0 && cg::parse_simd_level(o.kernel.c_str() + 6, unused)))
    usage_error("--kernel must be full, noise, perlin, worley or block_LEVEL (scalar, baseline, avx2, avx512)");
  if (o.config != "defaults" && o.config != "cumulus") usage_error("--config must be defaults or cumulus");
  return o;
}

cg::Params config_params(const std::string& name) {
  if (name == "defaults") return cg::Params();
  const cg::Preset* p = cg::find_preset(name);
  if (!p) usage_error("no preset " + name);
  return p->params;
}

std::string now_utc() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

// ---------------------------------------------------------------- samples ---

enum class Kernel { Full, Noise, Perlin, Worley, Block };

const char* kernel_name(Kernel k) {
  switch (k) {
    case Kernel::Full:
      return "density";
    case Kernel::Noise:
      return "noise_at";
    case Kernel::Perlin:
      return "perlin_fbm";
    case Kernel::Worley:
      return "worley_fbm";
    case Kernel::Block:
      return "density_block";
  }
  return "?";
}

// The two halves of noise_at, called the way cg_cloud_noise calls them (no LOD).
inline float perlin_part(const cg::Model& m, cg::vec3 p) {
  return cg::cg_perlin_fbm(p * m.perlin_frequency + m.perlin_offset, m.w4, m.noise_detail, CG_MAX_OCTAVES,
                           m.noise_whisp, m.seed);
}
inline float worley_part(const cg::Model& m, cg::vec3 p) {
  return cg::cg_worley_fbm(p * m.worley_frequency + m.worley_offset, CG_WORLEY_OCTAVES, CG_MAX_OCTAVES, m.worley_clump,
                           m.seed ^ CG_SEED_SALT_WORLEY);
}

template <class F>
float sum_over(const std::vector<cg::vec3>& pts, std::size_t lo, std::size_t hi, F f) {
  float s = 0.0f;
  for (std::size_t i = lo; i < hi; ++i) s += f(pts[i]);
  return s;
}

// Evaluates the kernel on every point with `threads` workers (chunks of 4096
// points handed out by cg::parallel_for); returns the sum so nothing is elided.
// Kernel::Block: cg::density_block at `level` on each chunk of 4096 points.
float evaluate(const cg::Model& m, const std::vector<cg::vec3>& pts, Kernel k, int threads,
               cg::SimdLevel level = cg::SimdLevel::Scalar) {
  constexpr std::int64_t kChunk = 4096;
  const std::int64_t chunks = (std::int64_t(pts.size()) + kChunk - 1) / kChunk;
  struct alignas(64) Partial {
    float sum = 0.0f;
  };
  std::vector<Partial> partial(std::max(threads, 1));
  cg::parallel_for(chunks, threads, [&](std::int64_t c, int worker) {
    const std::size_t lo = std::size_t(c * kChunk), hi = std::min(pts.size(), std::size_t(lo + kChunk));
    float s = 0.0f;
    switch (k) {
      case Kernel::Full:
        s = sum_over(pts, lo, hi, [&](cg::vec3 p) { return cg::density(m, p); });
        break;
      case Kernel::Noise:
        s = sum_over(pts, lo, hi, [&](cg::vec3 p) { return cg::noise_at(m, p); });
        break;
      case Kernel::Perlin:
        s = sum_over(pts, lo, hi, [&](cg::vec3 p) { return perlin_part(m, p); });
        break;
      case Kernel::Worley:
        s = sum_over(pts, lo, hi, [&](cg::vec3 p) { return worley_part(m, p); });
        break;
      case Kernel::Block: {
        float out[kChunk];
        cg::density_block(level, m, &pts[lo], hi - lo, cg::kNoLod, out);
        for (std::size_t i = 0; i < hi - lo; ++i) s += out[i];
        break;
      }
    }
    partial[worker].sum += s;
  });
  float total = 0.0f;
  for (const Partial& p : partial) total += p.sum;
  return total;
}

json timing_json(const cgbench::Timing& t) {
  return json{{"best_s", t.best()},
              {"median_s", t.median()},
              {"runs_s", t.seconds},
              {"cpu_best_s", t.cpu_best()},
              {"cpu_runs_s", t.cpu_seconds}};
}

json bench_samples(const Options& o) {
  json rows = json::array();
  std::printf("\n== Samples: one sample = one call on a point uniformly inside the cloud box ==\n");
  std::printf("%-9s %-22s %3s %12s %12s %10s\n", "config", "kernel", "thr", "best /s", "median /s", "ns/sample");
  for (const char* config : {"defaults", "cumulus"}) {
    const cg::Model m = cg::prepare(config_params(config));
    double rejected = 0.0;
    const auto noisy = cgbench::box_points(m, o.points, 0xC10D, true, &rejected);
    const auto plain = cgbench::box_points(m, o.points, 0xC10D, false);
    struct Case {
      const char* name;
      Kernel k;
      const std::vector<cg::vec3>* pts;
      std::vector<int> threads;
    };
    const Case cases[] = {
        {"density (noise needed)", Kernel::Full, &noisy, {1, 2}}, {"noise_at only", Kernel::Noise, &noisy, {1, 2}},
        {"  perlin fBm part", Kernel::Perlin, &noisy, {1}},       {"  worley fBm part", Kernel::Worley, &noisy, {1}},
        {"density (whole box)", Kernel::Full, &plain, {1, 2}},
    };
    for (const Case& c : cases)
      for (int threads : c.threads) {
        const cgbench::Timing t = cgbench::time_reps(o.reps, [&] { cgbench::sink(evaluate(m, *c.pts, c.k, threads)); });
        const double n = double(c.pts->size());
        std::printf("%-9s %-22s %3d %12s %12s %10.0f\n", config, c.name, threads, si(n / t.best()).c_str(),
                    si(n / t.median()).c_str(), 1e9 * t.best() / n);
        json row{{"config", config},
                 {"kernel", kernel_name(c.k)},
                 {"points", c.pts == &noisy ? "noise_needed" : "whole_box"},
                 {"threads", threads},
                 {"count", c.pts->size()}};
        row.update(timing_json(t));
        row["samples_per_s_best"] = n / t.best();
        row["samples_per_s_median"] = n / t.median();
        row["ns_per_sample_best"] = 1e9 * t.best() / n;
        if (c.pts == &noisy) row["box_fraction_provably_empty"] = rejected;
        rows.push_back(row);
      }
    // The batched kernel at every level this CPU runs (the same points as "density (noise needed)").
    for (int l = 0; l < cg::kSimdLevelCount; ++l) {
      const cg::SimdLevel level = cg::SimdLevel(l);
      if (!cg::simd_level_supported(level)) continue;
      for (int threads : {1, 2}) {
        const cgbench::Timing t =
            cgbench::time_reps(o.reps, [&] { cgbench::sink(evaluate(m, noisy, Kernel::Block, threads, level)); });
        const double n = double(noisy.size());
        const std::string name = std::string("density_block ") + cg::simd_level_name(level);
        std::printf("%-9s %-22s %3d %12s %12s %10.0f\n", config, name.c_str(), threads, si(n / t.best()).c_str(),
                    si(n / t.median()).c_str(), 1e9 * t.best() / n);
        json row{{"config", config},         {"kernel", "density_block"}, {"level", cg::simd_level_name(level)},
                 {"points", "noise_needed"}, {"threads", threads},        {"count", noisy.size()}};
        row.update(timing_json(t));
        row["samples_per_s_best"] = n / t.best();
        row["samples_per_s_median"] = n / t.median();
        row["ns_per_sample_best"] = 1e9 * t.best() / n;
        rows.push_back(row);
      }
    }
    std::printf("%-9s (%.1f %% of uniform box points are provably empty by the shape: no noise there)\n", config,
                100.0 * rejected);
  }
  return rows;
}

// ------------------------------------------------------------------- bake ---

constexpr double kGeometryNodesVoxelsPerS = 1.4e6;  // docs/platform.md "Measured anchors", 256^3

// Bakes of 256^3 and more take seconds each: at most 5 repetitions there.
int bake_reps(const Options& o, int resolution) { return resolution >= 256 ? std::min(o.reps, 5) : o.reps; }

json bench_bake(const Options& o) {
  json rows = json::array();
  const cg::Model m = cg::prepare(config_params("cumulus"));
  const int hw = cg::resolve_threads(0);
  std::printf("\n== Bake (cumulus, box 4 x 4 x 3; voxels/s counts every voxel of the box grid) ==\n");
  std::printf("%5s %-11s %3s %9s %9s %12s %9s %12s %8s\n", "res", "mode", "thr", "best s", "median s", "evaluated",
              "active %", "voxels/s", "vs GN");
  struct Mode {
    const char* name;
    bool skip, lod;
  };
  const Mode modes[] = {
      {"dense", false, false}, {"sparse", true, false}, {"lod", false, true}, {"sparse+lod", true, true}};
  for (int res : o.resolutions) {
    std::vector<int> thread_counts{hw};
    if (hw != 1 && res <= 128) thread_counts.insert(thread_counts.begin(), 1);
    for (int threads : thread_counts)
      for (const Mode& mode : modes) {
        cg::BakeOptions b;
        b.resolution = res;
        b.skip_empty = mode.skip;
        b.lod = mode.lod;
        b.threads = threads;
        cg::BakeStats stats;
        std::int64_t grid_voxels = 0;
        // No warm-up for bakes (the slowest take seconds); best of N covers it.
        const cgbench::Timing t = cgbench::time_reps(
            bake_reps(o, res),
            [&] {
              const cg::BakeResult r = cg::bake(m, b);
              stats = r.stats;
              grid_voxels = r.grid.voxel_count();
              cgbench::sink(float(r.tiles.size()));
            },
            false);
        const double vps = double(grid_voxels) / t.best();
        const double active = double(stats.voxels_active) / double(grid_voxels);
        std::printf("%5d %-11s %3d %9.3f %9.3f %12lld %8.1f%% %12s %7.1fx\n", res, mode.name, threads, t.best(),
                    t.median(), (long long)stats.voxels_evaluated, 100.0 * active, si(vps).c_str(),
                    vps / kGeometryNodesVoxelsPerS);
        json row{{"resolution", res}, {"mode", mode.name},  {"skip_empty", mode.skip},
                 {"lod", mode.lod},   {"threads", threads}, {"grid_voxels", grid_voxels}};
        row.update(timing_json(t));
        row["voxels_per_s_best"] = vps;
        row["vs_geometry_nodes"] = vps / kGeometryNodesVoxelsPerS;
        row["tiles_total"] = stats.tiles_total;
        row["tiles_skipped"] = stats.tiles_skipped;
        row["tiles_evaluated"] = stats.tiles_evaluated;
        row["tiles_kept"] = stats.tiles_kept;
        row["voxels_evaluated"] = stats.voxels_evaluated;
        row["voxels_active"] = stats.voxels_active;
        row["active_fraction"] = active;
        row["lod_worley_octaves"] = stats.lod_worley_octaves;
        row["lod_perlin_octaves"] = stats.lod_perlin_octaves;
        rows.push_back(row);
      }
  }
  return rows;
}

// ---------------------------------------------------------------- preview ---

json bench_preview(const Options& o) {
  json rows = json::array();
  std::printf("\n== Preview: 256 x 256 cross-section, axis y, offset 0.5 ==\n");
  std::printf("%-9s %-4s %3s %9s %9s\n", "config", "lod", "thr", "best ms", "median ms");
  const int reps = std::max(o.reps, 20);
  for (const char* config : {"defaults", "cumulus"}) {
    const cg::Model m = cg::prepare(config_params(config));
    for (bool lod : {false, true})
      for (int threads : {1, 2}) {
        cg::SliceSpec s;
        s.axis = 1;
        s.offset = 0.5f;
        s.width = s.height = 256;
        s.lod = lod;
        s.threads = threads;
        std::int64_t nonzero = 0;
        const cgbench::Timing t = cgbench::time_reps(reps, [&] {
          const std::vector<float> img = cg::slice(m, s);
          nonzero = std::count_if(img.begin(), img.end(), [](float v) { return v > 0.0f; });
        });
        std::printf("%-9s %-4s %3d %9.2f %9.2f\n", config, lod ? "yes" : "no", threads, 1e3 * t.best(),
                    1e3 * t.median());
        json row{{"config", config}, {"width", 256}, {"height", 256},     {"axis", "y"},
                 {"offset", 0.5},    {"lod", lod},   {"threads", threads}};
        row.update(timing_json(t));
        row["ms_best"] = 1e3 * t.best();
        row["ms_median"] = 1e3 * t.median();
        row["nonzero_fraction"] = double(nonzero) / (256.0 * 256.0);
        rows.push_back(row);
      }
  }
  return rows;
}

// -------------------------------------------------------------- callgrind ---

int run_callgrind_mode(const Options& o) {
  const cg::Model m = cg::prepare(config_params(o.config));
  // A fixed set of points whatever K is, so making them costs the same in both runs.
  const auto pts = cgbench::box_points(m, 10000, 0xC10D, true);
  float s = 0.0f;
  auto run = [&](auto f) {
    for (long long i = 0; i < o.callgrind_samples; ++i) s += f(pts[std::size_t(i % (long long)pts.size())]);
  };
  if (o.kernel == "full")
    run([&](cg::vec3 p) { return cg::density(m, p); });
  else if (o.kernel == "noise")
    run([&](cg::vec3 p) { return cg::noise_at(m, p); });
  else if (o.kernel.rfind("block_", 0) == 0) {
    cg::SimdLevel level = cg::SimdLevel::Scalar;
    cg::parse_simd_level(o.kernel.c_str() + 6, level);
    if (!cg::simd_level_supported(level)) {
      std::fprintf(stderr, "cloudgen_bench: level %s is not supported here\n", cg::simd_level_name(level));
      return 1;
    }
    constexpr long long kBatch = 500;  // divides the 10000 points: a batch never wraps around
    float out[kBatch];
    for (long long i = 0; i < o.callgrind_samples; i += kBatch) {
      const long long n = std::min(kBatch, o.callgrind_samples - i);
      cg::density_block(level, m, &pts[std::size_t(i % (long long)pts.size())], std::size_t(n), cg::kNoLod, out);
      for (long long j = 0; j < n; ++j) s += out[j];
    }
  } else if (o.kernel == "perlin")
    run([&](cg::vec3 p) { return perlin_part(m, p); });
  else
    run([&](cg::vec3 p) { return worley_part(m, p); });
  cgbench::sink(s);
  std::printf("%s %s: %lld samples, sum %g\n", o.config.c_str(), o.kernel.c_str(), o.callgrind_samples, double(s));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  if (o.callgrind_samples > 0) return run_callgrind_mode(o);

  json meta{{"date_utc", now_utc()},
            {"build_type", CLOUDGEN_BENCH_BUILD_TYPE},
            {"compiler", CLOUDGEN_BENCH_COMPILER},
#ifdef __VERSION__
            {"compiler_version", __VERSION__},
#endif
            {"flags", CLOUDGEN_BENCH_FLAGS},
            {"core_version", cg::version()},
            {"simd_level", cg::simd_level_name(cg::simd_level())},
            {"hardware_threads", std::thread::hardware_concurrency()},
            {"reps", o.reps},
            {"points", o.points},
            {"bake_reps_256_and_up", std::min(o.reps, 5)},
            {"load_average_start", cgbench::load_average()}};
  std::printf("cloudgen_bench %s — %s build, %s, best/median of %d runs, load average %.2f, kernel level %s\n",
              cg::version(), CLOUDGEN_BENCH_BUILD_TYPE, CLOUDGEN_BENCH_COMPILER, o.reps, cgbench::load_average(),
              cg::simd_level_name(cg::simd_level()));
  std::string bt = CLOUDGEN_BENCH_BUILD_TYPE;
  if (bt != "Release" && bt != "RelWithDebInfo")
    std::fprintf(stderr, "warning: %s build: these numbers do not describe the optimised core\n", bt.c_str());

  json out{{"meta", meta}};
  if (o.samples) out["samples"] = bench_samples(o);
  if (o.bake) out["bake"] = bench_bake(o);
  if (o.preview) out["preview"] = bench_preview(o);
  out["meta"]["load_average_end"] = cgbench::load_average();
  out["meta"]["geometry_nodes_anchor_voxels_per_s"] = kGeometryNodesVoxelsPerS;

  if (!o.json_path.empty()) {
    std::ofstream f(o.json_path);
    if (!f) {
      std::fprintf(stderr, "cloudgen_bench: cannot write %s\n", o.json_path.c_str());
      return 1;
    }
    f << out.dump(2) << "\n";
    std::printf("\nwrote %s (load average at the end %.2f)\n", o.json_path.c_str(), cgbench::load_average());
  }
  return 0;
}
