// cli/bake.cpp — `cloudgen bake` and `cloudgen preview`: the verbs that write files.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "cli/commands.h"
#include "cloudgen/grid.h"
#include "cloudgen/model.h"
#include "cloudgen/param_io.h"
#include "io/atomic_file.h"
#include "io/image_io.h"
#include "io/vdb_io.h"

namespace cli {

namespace {

constexpr long long kMaxResolution = 1000000;
constexpr int kMaxImageSide = 16384;

const char* const kBakeHelp =
    "usage: cloudgen bake (--preset NAME | --params FILE.json) --resolution N --output FILE.vdb\n"
    "                     [--time T] [--frames A-B [--fps F]] [--tolerance X] [--no-skip] [--no-lod]\n"
    "                     [--threads N] [--half] [--max-memory GiB] [--quiet]\n"
    "\n"
    "Evaluates the cloud density on a voxel grid over the cloud box and writes it\n"
    "as an OpenVDB file: one float grid named `density`, class fog volume,\n"
    "background 0, only voxels with density > 0 active, Blosc compression, the\n"
    "parameters and version as metadata. Voxel (i,j,k) has its centre at\n"
    "(i,j,k)·voxel + origin + voxel/2 in the cloud object's local frame.\n"
    "\n"
    "  --preset NAME       start from a cloud type (see `cloudgen presets`)\n"
    "  --params FILE.json  a parameter file (see `cloudgen params`)\n"
    "  --resolution N      voxels along the longest box side, cubic voxels, N in [1, 1000000]\n"
    "  --output FILE.vdb   the file to write; for a sequence a run of # in the name is\n"
    "                      the zero-padded frame number, else _0001 goes before .vdb\n"
    "  --time T            overrides the `time` parameter (seconds)\n"
    "  --frames A-B        bake frames A..B (or one frame A), time = frame / fps\n"
    "  --fps F             frames per second for --frames (default 24)\n"
    "  --tolerance X       drop voxels with density <= X (default 0)\n"
    "  --no-skip           evaluate every tile (no skipping of provably empty tiles)\n"
    "  --no-lod            evaluate every noise octave (no level of detail)\n"
    "  --threads N         worker threads (default 0 = one per core)\n"
    "  --half              store 16-bit floats (half the file size)\n"
    "  --max-memory GiB    refuse, before allocating, a bake whose estimated memory\n"
    "                      exceeds this budget (default 8)\n"
    "  --quiet             no progress lines\n"
    "\n"
    "Output: progress lines `bake: P%` on stdout, then one `wrote PATH ...` line per\n"
    "file. Files appear atomically (temporary file + rename): an error, SIGINT or\n"
    "SIGTERM leaves no partial file (frames already finished stay).\n"
    "Exit codes: 0 ok, 1 I/O failure, 2 bad argument, 130 cancelled.\n";

const char* const kPreviewHelp =
    "usage: cloudgen preview (--preset NAME | --params FILE.json) --axis x|y|z --offset O\n"
    "                        --size W[xH] --output FILE.png|FILE.exr [--lod] [--time T] [--threads N]\n"
    "\n"
    "Writes the 2D cross-section of the density through the cloud box, the plane\n"
    "perpendicular to --axis at --offset (a generated box coordinate in [0, 1],\n"
    "0.5 = the centre). Image axes: axis x → columns +y, rows z; axis y → columns\n"
    "+x, rows z; axis z → columns +x, rows y; the top row is the largest coordinate.\n"
    "\n"
    "  --axis x|y|z        the axis the plane is perpendicular to\n"
    "  --offset O          plane position in [0, 1] (default 0.5)\n"
    "  --size W[xH]        image size in pixels, each in [1, 16384] (default 256); H\n"
    "                      defaults to W × the aspect of the box face\n"
    "  --output FILE       .png: 8-bit grey for the eye, level = round(255·(1 − exp(−density/4)))\n"
    "                      .exr: 32-bit float channel Y = density, with metadata\n"
    "                      cloudgen:params (JSON), cloudgen:axis, cloudgen:offset, cloudgen:version\n"
    "  --lod               limit noise octaves to the pixel footprint (default: all octaves)\n"
    "  --time T            overrides the `time` parameter (seconds)\n"
    "  --threads N         worker threads (default 0 = one per core)\n"
    "\n"
    "The file appears atomically (temporary file + rename).\n"
    "Exit codes: 0 ok, 1 I/O failure, 2 bad argument, 130 cancelled.\n";

bool ends_with_ci(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  for (std::size_t i = 0; i < suffix.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(s[s.size() - suffix.size() + i])) != suffix[i]) return false;
  return true;
}

void set_time(cg::Params& p, double t, const std::string& option) {
  try {
    p.set(cg::TIME, static_cast<float>(t));
  } catch (const cg::ParamError& e) {
    throw UsageError(option + ": " + e.what());
  }
}

// Frame file name: the last run of '#' becomes the zero-padded frame number,
// else _NNNN goes before the extension.
std::string frame_path(const std::string& pattern, long long frame) {
  const auto last = pattern.find_last_of('#');
  if (last != std::string::npos) {
    auto first = last;
    while (first > 0 && pattern[first - 1] == '#') --first;
    const int width = int(last - first + 1);
    char num[32];
    std::snprintf(num, sizeof num, "%0*lld", width, frame);
    return pattern.substr(0, first) + num + pattern.substr(last + 1);
  }
  char num[32];
  std::snprintf(num, sizeof num, "_%04lld", frame);
  return pattern.substr(0, pattern.size() - 4) + num + pattern.substr(pattern.size() - 4);
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int cmd_bake(const std::vector<std::string>& argv) {
  Args a("bake", argv,
         {{"--preset", true}, {"--params", true}, {"--resolution", true}, {"--output", true}, {"--time", true},
          {"--frames", true}, {"--fps", true}, {"--tolerance", true}, {"--no-skip", false}, {"--no-lod", false},
          {"--threads", true}, {"--half", false}, {"--max-memory", true}, {"--quiet", false}});
  if (a.help()) return std::cout << kBakeHelp, kExitOk;
  if (!a.positional().empty()) throw UsageError("bake: unexpected argument '" + a.positional()[0] + "'");

  std::string preset;
  cg::Params params = load_params(a, preset);
  cg::BakeOptions opts;
  opts.resolution = static_cast<int>(a.integer("--resolution", 1, kMaxResolution));
  const std::string output = a.text("--output");
  if (!ends_with_ci(output, ".vdb")) throw UsageError("--output '" + output + "' must name a .vdb file");
  if (a.has("--tolerance")) opts.tolerance = static_cast<float>(a.number("--tolerance", 0.0, 1.0e30));
  if (a.has("--threads")) opts.threads = static_cast<int>(a.integer("--threads", 0, 1024));
  opts.skip_empty = !a.has("--no-skip");
  opts.lod = !a.has("--no-lod");
  const double budget_gib = a.has("--max-memory") ? a.number("--max-memory", 0.0, 1.0e6, true) : 8.0;
  const bool quiet = a.has("--quiet");

  // Frames: (frame number, time, path); one entry without --frames.
  struct Job {
    long long frame;
    float time;
    std::string path;
  };
  std::vector<Job> jobs;
  if (a.has("--frames")) {
    if (a.has("--time")) throw UsageError("--time and --frames exclude each other (with --frames, time = frame / fps)");
    const std::string spec = *a.get("--frames");
    const auto dash = spec.find('-', 1);
    const auto from = parse_integer(spec.substr(0, dash));
    const auto to = dash == std::string::npos ? from : parse_integer(spec.substr(dash + 1));
    if (!from || !to || *from < 0 || *to < *from || *to > 1000000)
      throw UsageError("--frames must be A-B (or A) with integers 0 <= A <= B <= 1000000; got '" + spec + "'");
    const double fps = a.has("--fps") ? a.number("--fps", 0.0, 1000.0, true) : 24.0;
    for (long long f = *from; f <= *to; ++f) {
      set_time(params, double(f) / fps, "--frames (frame " + std::to_string(f) + ")");
      jobs.push_back({f, params.get(cg::TIME), frame_path(output, f)});
    }
  } else {
    if (a.has("--fps")) throw UsageError("--fps needs --frames");
    if (a.has("--time")) set_time(params, a.number("--time", -1.0e6, 1.0e6), "--time");
    jobs.push_back({-1, params.get(cg::TIME), output});
  }
  for (const Job& j : jobs) cgio::check_output_path(j.path);

  // Memory budget, before anything is allocated (the shape bound does not
  // depend on time, so one estimate holds for every frame).
  const cg::Model first = cg::prepare(params);
  const double gib = double(cg::estimate_bake_bytes(first, opts)) / double(1ull << 30);
  const cg::GridSpec spec = cg::grid_for_box(first, opts.resolution);
  if (cancel_requested()) throw cg::Cancelled();  // the estimate may take seconds at huge resolutions
  if (gib > budget_gib) {
    char msg[256];
    std::snprintf(msg, sizeof msg, "--resolution %d needs an estimated %.3g GiB, more than --max-memory %g GiB",
                  opts.resolution, gib, budget_gib);
    throw UsageError(msg);
  }
  if (!quiet) {
    std::printf("bake: %s, %dx%dx%d voxels of %g, estimated memory <= %.3f GiB, %d thread(s)\n",
                preset.empty() ? "parameters" : preset.c_str(), spec.n[0], spec.n[1], spec.n[2], spec.voxel, gib,
                cg::resolve_threads(opts.threads));
    std::fflush(stdout);
  }

  const std::size_t n_jobs = jobs.size();
  for (std::size_t fi = 0; fi < n_jobs; ++fi) {
    const Job& job = jobs[fi];
    const auto t0 = std::chrono::steady_clock::now();
    params.set(cg::TIME, job.time);
    const cg::Model model = cg::prepare(params);
    if (!quiet && job.frame >= 0) {
      std::printf("bake: frame %lld (time %g) -> %s\n", job.frame, job.time, job.path.c_str());
      std::fflush(stdout);
    }
    int last_pct = -1;
    auto progress = [&](std::int64_t done, std::int64_t total) {
      if (!quiet) {
        const double frac = total > 0 ? double(done) / double(total) : 1.0;
        const int pct = static_cast<int>(std::floor(100.0 * (double(fi) + frac) / double(n_jobs)));
        if (pct != last_pct) {
          std::printf("bake: %d%%\n", pct);
          std::fflush(stdout);
          last_pct = pct;
        }
      }
      return !cancel_requested();
    };
    cgio::AtomicFile file(job.path);
    const cg::BakeResult result = cg::bake(model, opts, progress);
    if (cancel_requested()) throw cg::Cancelled();
    cgio::VdbWriteOptions wo;
    wo.half = a.has("--half");
    wo.params_json = cg::params_to_json(params);
    wo.preset = preset;
    wo.time = job.time;
    wo.resolution = opts.resolution;
    file.write_with([&](const std::string& tmp) { cgio::write_vdb(tmp, result, wo); });
    if (cancel_requested()) throw cg::Cancelled();
    file.commit();
    std::printf("wrote %s (%lld active voxels of %dx%dx%d, %.2f MiB, %.2f s)\n", job.path.c_str(),
                static_cast<long long>(result.stats.voxels_active), spec.n[0], spec.n[1], spec.n[2],
                double(cgio::file_size(job.path)) / double(1 << 20), seconds_since(t0));
    std::fflush(stdout);
  }
  return kExitOk;
}

int cmd_preview(const std::vector<std::string>& argv) {
  Args a("preview", argv,
         {{"--preset", true}, {"--params", true}, {"--axis", true}, {"--offset", true}, {"--size", true},
          {"--output", true}, {"--lod", false}, {"--time", true}, {"--threads", true}, {"--quiet", false}});
  if (a.help()) return std::cout << kPreviewHelp, kExitOk;
  if (!a.positional().empty()) throw UsageError("preview: unexpected argument '" + a.positional()[0] + "'");

  std::string preset;
  cg::Params params = load_params(a, preset);
  if (a.has("--time")) set_time(params, a.number("--time", -1.0e6, 1.0e6), "--time");
  cg::SliceSpec s;
  const std::string axis = a.text("--axis");
  if (axis != "x" && axis != "y" && axis != "z") throw UsageError("--axis must be x, y or z; got '" + axis + "'");
  s.axis = axis[0] - 'x';
  s.offset = a.has("--offset") ? static_cast<float>(a.number("--offset", 0.0, 1.0)) : 0.5f;
  s.lod = a.has("--lod");
  if (a.has("--threads")) s.threads = static_cast<int>(a.integer("--threads", 0, 1024));
  const std::string output = a.text("--output");
  const auto format = cgio::image_format_for(output);
  if (!format) throw UsageError("--output '" + output + "' must name a .png or .exr file");

  const cg::Model model = cg::prepare(params);
  const std::string size = a.get("--size").value_or("256");
  const auto x = size.find_first_of("xX");
  const std::string bad_size = "--size must be W or WxH with integers in [1, " + std::to_string(kMaxImageSide) +
                               "]; got '" + size + "'";
  const auto w = parse_integer(size.substr(0, x));
  if (!w || *w < 1 || *w > kMaxImageSide) throw UsageError(bad_size);
  s.width = static_cast<int>(*w);
  if (x != std::string::npos) {
    const auto h = parse_integer(size.substr(x + 1));
    if (!h || *h < 1 || *h > kMaxImageSide) throw UsageError(bad_size);
    s.height = static_cast<int>(*h);
  } else {
    int ca, ra;
    cg::slice_axes(s.axis, ca, ra);
    const double aspect = double(model.box[ra]) / double(model.box[ca]);
    s.height = static_cast<int>(std::clamp(std::lround(double(s.width) * aspect), 1L, long(kMaxImageSide)));
  }
  cgio::check_output_path(output);

  const auto t0 = std::chrono::steady_clock::now();
  cgio::AtomicFile file(output);
  const std::vector<float> values = cg::slice(model, s);
  if (cancel_requested()) throw cg::Cancelled();
  cgio::SliceMeta meta;
  meta.params_json = cg::params_to_json(params);
  meta.axis = axis[0];
  meta.offset = s.offset;
  file.write_with([&](const std::string& tmp) { cgio::write_slice(tmp, *format, values, s.width, s.height, meta); });
  if (cancel_requested()) throw cg::Cancelled();
  file.commit();
  const float peak = values.empty() ? 0.0f : *std::max_element(values.begin(), values.end());
  std::printf("wrote %s (%dx%d, axis %s at %g, max density %g, %.2f s)\n", output.c_str(), s.width, s.height,
              axis.c_str(), s.offset, peak, seconds_since(t0));
  return kExitOk;
}

}  // namespace cli
