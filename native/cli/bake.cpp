// cli/bake.cpp — `cloudgen bake`: one frame, a frame range or a per-frame
// parameter sequence, at a fixed resolution, a quality tier's settings or the
// resolution a camera can resolve; frames whose field is already on disk are
// copied or kept instead of baked again.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "cli/commands.h"
#include "cli/events.h"
#include "cloudgen/camera.h"
#include "cloudgen/field_key.h"
#include "cloudgen/frame_path.h"
#include "cloudgen/grid.h"
#include "cloudgen/model.h"
#include "cloudgen/names.h"
#include "cloudgen/param_io.h"
#include "cloudgen/sequence.h"
#include "cloudgen/tiers.h"
#include "io/atomic_file.h"
#include "io/vdb_io.h"
#include "io/vdb_sandbox.h"

namespace cli {

namespace {

constexpr long long kMaxResolution = 1000000;
constexpr float kMinVoxel = 1e-7f;  // smallest voxel edge written (OpenVDB: a scale near 0 is an error)

const char* const kBakeHelp =
    "usage: cloudgen bake (--preset NAME | --params FILE.json | --sequence FILE.json) --output FILE.vdb\n"
    "                     [--resolution N] [--quality draft|preview|final] [--camera CAMERA.json]\n"
    "                     [--time T] [--frames A-B [--fps F]] [--update] [--tolerance X] [--no-skip]\n"
    "                     [--no-lod] [--threads N] [--half] [--max-memory GiB] [--quiet] [--json]\n"
    "                     [--brick I/N] [--ring INNER[,OUTER]] [--supersample K] [--dry-run]\n"
    "\n"
    "Evaluates the cloud density on a voxel grid over the cloud box and writes it\n"
    "as an OpenVDB file: one float grid named `density`, class fog volume,\n"
    "background 0, only voxels with density > 0 active, Blosc compression, the\n"
    "parameters, version and bake key as metadata. Voxel (i,j,k) has its centre at\n"
    "(i,j,k)·voxel + origin + voxel/2 in the cloud object's local frame and holds\n"
    "the density there; a cell overhanging the cloud's box holds the density at\n"
    "the centre of its part inside the box times that part's share of the cell\n"
    "(a layer thinner than a voxel keeps its column; docs/camera.md).\n"
    "\n"
    "  --preset NAME       start from a cloud type (see `cloudgen presets`)\n"
    "  --params FILE.json  a parameter file (see `cloudgen params`)\n"
    "  --sequence FILE     per-frame parameters: {\"frames\": [{\"frame\": N, \"params\": {...}}, ...]}\n"
    "                      (each params object as in a parameter file; time comes from it)\n"
    "  --resolution N      voxels along the longest box side, cubic voxels, N in [1, 1000000];\n"
    "                      with --camera the upper limit of what the camera may ask for\n"
    "  --quality TIER      take resolution, LOD, tolerance and half floats from a quality\n"
    "                      tier (see `cloudgen tiers`); explicit options win; with --camera\n"
    "                      the tier's pixels per voxel unless the camera file sets them\n"
    "  --camera FILE.json  camera-aware bake (docs/camera.md): voxel = one pixel's footprint\n"
    "                      at the nearest visible point of the box, octaves capped there,\n"
    "                      only the view frustum plus a shadow margin baked\n"
    "  --output FILE.vdb   the file to write; for a sequence the last run of # in the name\n"
    "                      is the zero-padded frame number, else _0001 goes before .vdb\n"
    "  --time T            overrides the `time` parameter (seconds)\n"
    "  --frames A-B        bake frames A..B (or one frame A), time = frame / fps\n"
    "  --fps F             frames per second for --frames (default 24)\n"
    "  --update            keep an existing output whose stored bake key matches\n"
    "  --tolerance X       drop voxels with density <= X (default 0)\n"
    "  --no-skip           evaluate every tile (no skipping of provably empty tiles)\n"
    "  --no-lod            evaluate every noise octave (no level of detail)\n"
    "  --threads N         worker threads (default 0 = one per core)\n"
    "  --half              store 16-bit floats (half the file size)\n"
    "  --max-memory GiB    refuse, before allocating, a bake whose estimated memory\n"
    "                      exceeds this budget (default 8)\n"
    "  --quiet             no progress\n"
    "  --brick I/N         bake only brick I (0-based) of N: the I-th of N contiguous ranges of\n"
    "                      the grid's 8^3 tiles (one frame only); `cloudgen merge` joins the N\n"
    "                      bricks into the whole bake (the distributed runner does this)\n"
    "  --ring IN[,OUT]     bake only the square ring IN <= max(|x|,|y|) < OUT of the horizontal\n"
    "                      plane (cloud frame, scene units; one voxel of margin each side; no OUT:\n"
    "                      no outer limit), 0 <= IN < OUT: a level of a nested bake of a layer\n"
    "                      whose inner levels cover the hole (docs/camera.md)\n"
    "  --supersample K     each voxel holds the mean of K^3 samples spread over its cell (K in\n"
    "                      [1, 4], default 1 = the centre): no stripes from a thin layer's\n"
    "                      edges sharper than a voxel (docs/camera.md); costs K^3 the time\n"
    "  --dry-run           check everything and print the plan (files, grid, keys), write nothing\n"
    "  --json              machine-readable output: one JSON object per line on stdout\n"
    "                      (plan, camera, frame, progress, wrote, copied, kept, error;\n"
    "                      docs/cli_protocol.md)\n"
    "\n"
    "Frames whose density field equals an earlier frame's (a cloud without wind\n"
    "and evolution, unchanged keyframes) are byte copies of that frame's file\n"
    "(its metadata, e.g. cloudgen_time, is that frame's). In a --sequence file,\n"
    "\"fps\" is informational: each frame's time is its params' \"time\".\n"
    "Output: per file one line `wrote PATH ...`, `copied PATH (same field as frame N)`\n"
    "or `kept PATH (unchanged)` on stdout; progress `bake: P%` on stderr.\n"
    "Files appear atomically (temporary file + rename): an error, SIGINT or\n"
    "SIGTERM leaves no partial file (frames already finished stay).\n"
    "Exit codes: 0 ok, 1 I/O failure, 2 bad argument, 130 cancelled.\n";

bool ends_with_ci(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  for (std::size_t i = 0; i < suffix.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(s[s.size() - suffix.size() + i])) != suffix[i]) return false;
  return true;
}

struct Job {
  long long frame;  // -1: a single bake
  cg::Params params;
  std::string path;
};

std::vector<Job> sequence_jobs(const std::string& file, const std::string& output) {
  // Limits, duplicate keys, fps and frame entries: cg::parse_sequence (cloudgen/sequence.h).
  std::vector<Job> jobs;
  for (cg::SequenceFrame& f : cg::parse_sequence(read_text_file(file, "--sequence", 64u << 20), "--sequence " + file))
    jobs.push_back({f.frame, std::move(f.params), cg::frame_path(output, f.frame)});
  return jobs;
}

std::vector<Job> plan_jobs(const Args& a, const std::string& output, std::string& preset) {
  if (a.has("--sequence")) {
    for (const char* o : {"--preset", "--params", "--frames", "--time", "--fps"})
      if (a.has(o)) throw UsageError(std::string("--sequence carries the parameters of every frame; drop ") + o);
    preset.clear();
    return sequence_jobs(*a.get("--sequence"), output);
  }
  cg::Params params = load_params(a, preset);
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
      jobs.push_back({f, params, cg::frame_path(output, f)});
    }
    return jobs;
  }
  if (a.has("--fps")) throw UsageError("--fps needs --frames");
  if (a.has("--time")) set_time(params, a.number("--time", -1.0e6, 1.0e6), "--time");
  jobs.push_back({-1, params, output});
  return jobs;
}

std::string stored_bake_key(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return {};
  try {
    // An existing output is untrusted: read in a limited child (io/vdb_sandbox.h).
    const cgio::VdbFileInfo info = cgio::read_vdb_info_isolated(path);
    for (const cgio::VdbGridInfo& g : info.grids) {
      const auto it = g.metadata.find("cloudgen_bake_key");
      if (g.name == "density" && it != g.metadata.end()) return it->second;
    }
  } catch (const std::exception&) {
    // unreadable, hostile or foreign: bake it again
  }
  return {};
}

void copy_atomically(const std::string& from, const std::string& to) {
  cgio::AtomicFile file(to);
  file.write_with([&](const std::string& tmp) {
    std::error_code ec;
    std::filesystem::copy_file(from, tmp, std::filesystem::copy_options::overwrite_existing, ec);
    if (ec) throw cgio::IoError("cannot copy " + from + " to " + tmp + ": " + ec.message());
  });
  file.commit();
}

// --ring INNER[,OUTER] into the options, compared as the floats the bake uses
// (1,1.00000001 is no ring); false unless 0 <= INNER < OUTER <= 1e30.
bool parse_ring(const std::string& spec, cg::BakeOptions& o) {
  const auto number = [](const std::string& s) -> std::optional<float> {
    const auto v = parse_number(s);  // finite, or nullopt
    return v && std::fabs(*v) <= 1e30 ? std::optional<float>(static_cast<float>(*v)) : std::nullopt;
  };
  const auto comma = spec.find(',');
  const auto inner = number(spec.substr(0, comma));
  const auto outer = comma == std::string::npos ? std::optional<float>(std::numeric_limits<float>::infinity())
                                                : number(spec.substr(comma + 1));
  if (!inner || !outer || !(*inner >= 0.0f && *outer > *inner)) return false;
  o.ring_inner = *inner;
  o.ring_outer = *outer;
  return true;
}

}  // namespace

int cmd_bake(const std::vector<std::string>& argv) {
  // before parsing: a bad argument is reported as an `error` event too
  if (std::find(argv.begin(), argv.end(), "--json") != argv.end()) set_output_mode(OutputMode::Json);
  Args a("bake", argv, {{"--preset", true},     {"--params", true},      {"--sequence", true}, {"--resolution", true},
                        {"--quality", true},    {"--camera", true},      {"--output", true},   {"--time", true},
                        {"--frames", true},     {"--fps", true},         {"--update", false},  {"--tolerance", true},
                        {"--no-skip", false},   {"--no-lod", false},     {"--threads", true},  {"--half", false},
                        {"--max-memory", true}, {"--quiet", false},      {"--json", false},    {"--brick", true},
                        {"--ring", true},       {"--supersample", true}, {"--dry-run", false}});
  if (a.help()) return std::cout << kBakeHelp, kExitOk;
  if (!a.positional().empty()) throw UsageError("bake: unexpected argument '" + a.positional()[0] + "'");

  const std::string output = a.text("--output");
  if (!ends_with_ci(output, ".vdb")) throw UsageError("--output '" + output + "' must name a .vdb file");
  std::string preset;
  const std::vector<Job> jobs = plan_jobs(a, output, preset);

  cg::BakeOptions opts;
  bool half = a.has("--half");
  if (a.has("--quality")) {
    const std::string name = *a.get("--quality");
    const cg::Tier* tier = cg::find_tier(name);
    if (!tier) {
      std::string names;
      for (const cg::Tier& t : cg::tiers()) names += (names.empty() ? "" : ", ") + t.name;
      std::vector<std::string> tier_names;
      for (const cg::Tier& t : cg::tiers()) tier_names.push_back(t.name);
      throw UsageError("--quality '" + name.substr(0, 100) + "' is not a tier; choose one of: " + names +
                       cg::did_you_mean(name, tier_names));
    }
    opts.resolution = tier->bake_resolution;
    opts.lod = tier->bake_lod;
    opts.tolerance = tier->bake_tolerance;
    half = half || tier->bake_half;
  }
  std::optional<cg::CameraView> camera;
  if (a.has("--camera")) {
    const std::string file = *a.get("--camera");
    camera = cg::parse_camera(read_text_file(file, "--camera", 1u << 20), "--camera " + file);
    if (camera->pixels_per_voxel <= 0.0f && a.has("--quality"))
      camera->pixels_per_voxel = cg::find_tier(*a.get("--quality"))->bake_pixels_per_voxel;
  }
  const bool have_resolution = a.has("--resolution");
  if (have_resolution)
    opts.resolution = static_cast<int>(a.integer("--resolution", 1, kMaxResolution));
  else if (!a.has("--quality") && !camera)
    throw UsageError("give --resolution N (or --quality TIER or --camera FILE)");
  if (a.has("--tolerance")) opts.tolerance = static_cast<float>(a.number("--tolerance", 0.0, 1.0e30));
  if (a.has("--threads")) opts.threads = static_cast<int>(a.integer("--threads", 0, 1024));
  if (a.has("--brick")) {
    const std::string spec = *a.get("--brick");
    const auto slash = spec.find('/');
    const auto i = parse_integer(spec.substr(0, slash));
    const auto n = slash == std::string::npos ? std::nullopt : parse_integer(spec.substr(slash + 1));
    if (!i || !n || *n < 1 || *n > 1000000 || *i < 0 || *i >= *n)
      throw UsageError("--brick must be I/N with integers 0 <= I < N <= 1000000; got '" + spec.substr(0, 40) + "'");
    if (jobs.size() != 1) throw UsageError("--brick splits one grid: give one frame, not a sequence");
    opts.brick_index = static_cast<int>(*i);
    opts.brick_count = static_cast<int>(*n);
  }
  if (a.has("--ring") && !parse_ring(*a.get("--ring"), opts))
    throw UsageError(
        "--ring must be INNER or INNER,OUTER with numbers 0 <= INNER < OUTER <= 1e30 (scene units); got '" +
        clipped(*a.get("--ring"), 40) + "'");
  if (a.has("--supersample")) opts.supersample = static_cast<int>(a.integer("--supersample", 1, cg::kMaxSupersample));
  opts.skip_empty = !a.has("--no-skip");
  if (a.has("--no-lod")) opts.lod = false;
  const double budget_gib = a.has("--max-memory") ? a.number("--max-memory", 0.0, 1.0e6, true) : 8.0;
  const bool quiet = a.has("--quiet"), update = a.has("--update");
  for (const Job& j : jobs) cgio::check_output_path(j.path);
  {  // temporaries of killed runs (SIGKILL during a write), once per output directory
    std::set<std::string> dirs;
    for (const Job& j : jobs)
      if (dirs.insert(std::filesystem::path(j.path).parent_path().string()).second)
        cgio::remove_stale_temporaries(j.path);
  }

  // Per frame: the model, the options (a camera fits them to the frame's box)
  // and the key of what would be written. Memory is checked for every frame
  // before anything is baked.
  struct Planned {
    cg::Model model;
    cg::BakeOptions opts;
    cg::CameraFit fit;
    cg::GridSpec grid;
    std::string key;
  };
  std::vector<Planned> plan;
  for (const Job& job : jobs) {
    Planned p{cg::prepare(job.params), opts, {}, {}, {}};
    if (camera) {
      p.fit = cg::fit_camera(p.model, *camera);
      const float longest = std::max({p.model.box[0], p.model.box[1], p.model.box[2]});
      // Bounded up front: a camera inside the box or a tiny pixel footprint once
      // hung the estimate or failed at write time ("Non-zero scale values required").
      const float finest_allowed = longest / float(kMaxResolution);
      if (p.fit.visible && !have_resolution && !(p.fit.voxel >= finest_allowed)) {
        char msg[500];
        std::snprintf(msg, sizeof msg,
                      "--camera%s: the camera asks for voxels of %g (pixel footprint %g at depth %g), finer than the "
                      "box's longest side / %lld = %g; move the camera away from (or out of) the box, raise "
                      "pixels_per_voxel or cap the detail with --resolution N",
                      job.frame >= 0 ? (" (frame " + std::to_string(job.frame) + ")").c_str() : "", p.fit.voxel,
                      p.fit.footprint, p.fit.nearest_depth, kMaxResolution, finest_allowed);
        throw UsageError(msg);
      }
      const float finest = have_resolution ? longest / float(opts.resolution) : 0.0f;
      p.opts.voxel = std::max(p.fit.voxel, finest);
      p.opts.use_region = true;
      p.opts.region = p.fit.region;
    }
    p.grid = cg::bake_grid(p.model, p.opts);
    if (!(p.grid.voxel >= kMinVoxel)) {  // OpenVDB's transform refuses scales near 0
      char msg[300];
      const std::string what = camera ? "--camera" : "--resolution " + std::to_string(opts.resolution);
      std::snprintf(msg, sizeof msg,
                    "%s: voxels of %g are smaller than %g scene units; lower --resolution or "
                    "enlarge the box",
                    what.c_str(), p.grid.voxel, kMinVoxel);
      throw UsageError(msg);
    }
    p.key = cg::bake_key(p.model, p.opts, half);
    const double gib = double(cg::estimate_bake_bytes(p.model, p.opts)) / double(1ull << 30);
    if (cancel_requested()) throw cg::Cancelled();  // the estimate may take seconds at huge resolutions
    if (gib > budget_gib) {
      const std::string what = camera ? std::string("--camera") : "--resolution " + std::to_string(opts.resolution);
      const std::string frame = job.frame >= 0 ? " (frame " + std::to_string(job.frame) + ")" : "";
      char msg[400];
      std::snprintf(msg, sizeof msg,
                    "%s%s: %dx%dx%d voxels of %g need an estimated %.3g GiB, more than --max-memory %g GiB%s",
                    what.c_str(), frame.c_str(), p.grid.n[0], p.grid.n[1], p.grid.n[2], p.grid.voxel, gib, budget_gib,
                    camera ? " (lower the camera's resolution, raise pixels_per_voxel or cap --resolution)" : "");
      throw UsageError(msg);
    }
    plan.push_back(std::move(p));
  }

  // What the run will write, before it writes anything: the CLI alone names files.
  {
    const Planned& first = plan.front();
    Fields files = Fields::array();
    for (std::size_t fi = 0; fi < jobs.size(); ++fi)
      files.push_back({{"frame", jobs[fi].frame >= 0 ? Fields(jobs[fi].frame) : Fields()},
                       {"path", jobs[fi].path},
                       {"key", plan[fi].key}});
    const double gib = double(cg::estimate_bake_bytes(first.model, first.opts)) / double(1ull << 30);
    const int threads = cg::resolve_threads(opts.threads);
    char ring[100] = "", samples[40] = "";
    if (opts.has_ring()) std::snprintf(ring, sizeof ring, ", ring [%g, %g)", opts.ring_inner, opts.ring_outer);
    if (opts.samples_per_axis() > 1)
      std::snprintf(samples, sizeof samples, ", %d^3 samples per voxel", opts.samples_per_axis());
    char human[400];
    std::snprintf(human, sizeof human,
                  "bake: %s, %dx%dx%d voxels of %g%s%s, estimated memory <= %.3f GiB, %d thread(s)",
                  preset.empty() ? "parameters" : preset.c_str(), first.grid.n[0], first.grid.n[1], first.grid.n[2],
                  first.grid.voxel, ring, samples, gib, threads);
    Fields plan_fields = {{"protocol", cg::kProtocolVersion},
                          {"files", files},
                          {"grid", {first.grid.n[0], first.grid.n[1], first.grid.n[2]}},
                          {"voxel", first.grid.voxel},
                          {"memory_gib", gib},
                          {"threads", threads},
                          {"preset", preset.empty() ? Fields() : Fields(preset)}};
    if (opts.samples_per_axis() > 1) plan_fields["supersample"] = opts.samples_per_axis();
    if (opts.has_ring())  // [inner, outer], outer null when unlimited
      plan_fields["ring"] = {opts.ring_inner, std::isinf(opts.ring_outer) ? Fields() : Fields(opts.ring_outer)};
    emit("plan", plan_fields, quiet ? "" : human);
    if (opts.brick_count > 1) {
      cg::BakeOptions whole = first.opts;
      whole.brick_index = 0, whole.brick_count = 1;
      const std::int64_t total = std::int64_t(first.grid.tiles(0)) * first.grid.tiles(1) * first.grid.tiles(2);
      const cg::TileSpan span = cg::brick_tiles(total, opts);
      emit("brick",
           {{"index", opts.brick_index},
            {"count", opts.brick_count},
            {"tiles", {span.first, span.last}},
            {"tiles_in_grid", total},
            {"whole_key", cg::bake_key(first.model, whole, half)}},
           quiet ? ""
                 : "brick " + std::to_string(opts.brick_index) + "/" + std::to_string(opts.brick_count) + ": tiles " +
                       std::to_string(span.first) + " to " + std::to_string(span.last - 1) + " of " +
                       std::to_string(total));
    }
    if (camera) {
      const cg::CameraFit& fit = first.fit;
      Fields fields = {{"visible", fit.visible}};
      std::string line = "camera: the cloud box is outside the view; nothing to bake";
      if (fit.visible) {
        fields.update({{"nearest_depth", fit.nearest_depth},
                       {"footprint", fit.footprint},
                       {"voxel", first.grid.voxel},
                       {"margin", fit.margin}});
        char buf[300];
        std::snprintf(buf, sizeof buf, "camera: nearest visible depth %g, pixel footprint %g, voxel %g, margin %g",
                      fit.nearest_depth, fit.footprint, first.grid.voxel, fit.margin);
        line = buf;
      }
      emit("camera", fields, quiet ? "" : line);
    }
  }

  if (a.has("--dry-run")) return kExitOk;

  std::map<std::string, const Job*> done;  // bake key -> the frame that has it on disk
  const std::size_t n_jobs = jobs.size();
  Progress progress("bake", quiet);
  for (std::size_t fi = 0; fi < n_jobs; ++fi) {
    const Job& job = jobs[fi];
    const Planned& p = plan[fi];
    const Fields frame = job.frame >= 0 ? Fields(job.frame) : Fields();
    if (cancel_requested()) throw cg::Cancelled();
    if (update && stored_bake_key(job.path) == p.key) {
      done.emplace(p.key, &job);
      emit("kept", {{"path", job.path}, {"frame", frame}}, "kept " + job.path + " (unchanged)");
      continue;
    }
    if (const auto it = done.find(p.key); it != done.end()) {
      copy_atomically(it->second->path, job.path);
      emit("copied",
           {{"path", job.path}, {"frame", frame}, {"source", it->second->path}, {"source_frame", it->second->frame}},
           "copied " + job.path + " (same field as frame " + std::to_string(it->second->frame) + ")");
      continue;
    }
    const auto t0 = std::chrono::steady_clock::now();
    if (job.frame >= 0) {
      char line[64];
      std::snprintf(line, sizeof line, "bake: frame %lld (time %g) -> ", job.frame, job.params.get(cg::TIME));
      emit("frame", {{"frame", job.frame}, {"time", job.params.get(cg::TIME)}, {"path", job.path}},
           quiet ? "" : line + job.path);
    }
    auto on_progress = [&](std::int64_t finished, std::int64_t total) {
      const double frac = total > 0 ? double(finished) / double(total) : 1.0;
      progress.update((double(fi) + frac) / double(n_jobs));
      return !cancel_requested();
    };
    cgio::AtomicFile file(job.path);
    const cg::BakeResult result = cg::bake(p.model, p.opts, on_progress);
    if (cancel_requested()) throw cg::Cancelled();
    cgio::VdbWriteOptions wo;
    wo.half = half;
    wo.threads = p.opts.threads;
    wo.params_json = cg::params_to_json(job.params);
    wo.preset = preset;
    wo.time = job.params.get(cg::TIME);
    wo.resolution = std::max({p.grid.n[0], p.grid.n[1], p.grid.n[2]});
    wo.bake_key = p.key;
    wo.supersample = p.opts.samples_per_axis();
    if (p.opts.brick_count > 1) {
      cg::BakeOptions whole = p.opts;
      whole.brick_index = 0, whole.brick_count = 1;
      wo.brick = std::to_string(p.opts.brick_index) + "/" + std::to_string(p.opts.brick_count);
      wo.whole_bake_key = cg::bake_key(p.model, whole, half);
    }
    file.write_with([&](const std::string& tmp) { cgio::write_vdb(tmp, result, wo); });
    if (cancel_requested()) throw cg::Cancelled();
    file.commit();
    done.emplace(p.key, &job);
    progress.finish();
    const std::uintmax_t bytes = cgio::file_size(job.path);
    const double seconds = seconds_since(t0);
    const auto& st = result.stats;
    char line[400];
    std::snprintf(line, sizeof line, " (%lld active voxels of %dx%dx%d, %.2f MiB, %.2f s)",
                  static_cast<long long>(st.voxels_active), p.grid.n[0], p.grid.n[1], p.grid.n[2],
                  double(bytes) / double(1 << 20), seconds);
    std::string human = "wrote " + job.path + line;
    if (camera) {
      std::snprintf(line, sizeof line, "\ncamera: voxel %g, %lld visible tiles of %lld", p.grid.voxel,
                    static_cast<long long>(st.tiles_total - st.tiles_culled), static_cast<long long>(st.tiles_total));
      human += line;
    }
    emit("wrote",
         {{"path", job.path},
          {"frame", frame},
          {"key", p.key},
          {"active_voxels", st.voxels_active},
          {"grid", {p.grid.n[0], p.grid.n[1], p.grid.n[2]}},
          {"voxel", p.grid.voxel},
          {"bytes", bytes},
          {"seconds", seconds},
          {"tiles_total", st.tiles_total},
          {"tiles_culled", st.tiles_culled}},
         human);
  }
  progress.update(1.0);
  progress.finish();
  return kExitOk;
}

}  // namespace cli
