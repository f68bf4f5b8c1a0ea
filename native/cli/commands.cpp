// cli/commands.cpp — argument parsing, parameter loading, and the read-only
// verbs: presets, params, info. (bake and preview live in bake.cpp.)
#include "cli/commands.h"
#include "cloudgen/names.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cloudgen/param_io.h"
#include "cloudgen/tiers.h"
#include "io/atomic_file.h"
#include "io/vdb_io.h"
#include "io/vdb_sandbox.h"

namespace cli {

std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r' || c == '\t') c = ' ';
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

std::string clipped(const std::string& s, std::size_t n) { return s.size() > n ? s.substr(0, n) + "..." : s; }

std::optional<long long> parse_integer(const std::string& s) {
  long long v = 0;
  const char* b = s.data();
  const char* e = b + s.size();
  if (b != e && *b == '+') ++b;
  auto [ptr, ec] = std::from_chars(b, e, v);
  if (ec != std::errc() || ptr != e || b == e) return std::nullopt;
  return v;
}

std::optional<double> parse_number(const std::string& s) {
  if (s.empty() || s.find_first_not_of("0123456789+-.eE") != std::string::npos) return std::nullopt;
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v)) return std::nullopt;
  return v;
}

// ---- Args ----

Args::Args(const std::string& verb, const std::vector<std::string>& argv, const std::vector<OptionSpec>& specs)
    : verb_(verb) {
  for (std::size_t i = 0; i < argv.size(); ++i) {
    const std::string& a = argv[i];
    if (a == "--help" || a == "-h") {
      help_ = true;
      continue;
    }
    if (a.size() < 2 || a[0] != '-' || (a.size() >= 2 && std::isdigit(static_cast<unsigned char>(a[1])))) {
      positional_.push_back(a);
      continue;
    }
    const auto eq = a.find('=');
    const std::string name = a.substr(0, eq);
    const OptionSpec* spec = nullptr;
    for (const OptionSpec& s : specs)
      if (name == s.name) spec = &s;
    if (!spec) {
      std::vector<std::string> names;
      for (const OptionSpec& s : specs) names.push_back(s.name);
      throw UsageError("unknown option '" + clipped(name, 100) + "' for '" + verb + "'" +
                       cg::did_you_mean(name, names) + " (see `cloudgen " + verb + " --help`)");
    }
    if (values_.count(name)) throw UsageError("option '" + name + "' given twice");
    if (!spec->takes_value) {
      if (eq != std::string::npos) throw UsageError("option '" + name + "' takes no value");
      values_[name] = "";
    } else if (eq != std::string::npos) {
      values_[name] = a.substr(eq + 1);
    } else {
      if (i + 1 >= argv.size() || argv[i + 1].rfind("--", 0) == 0)
        throw UsageError("option '" + name + "' needs a value");
      values_[name] = argv[++i];
    }
  }
}

std::optional<std::string> Args::get(const std::string& name) const {
  auto it = values_.find(name);
  if (it == values_.end()) return std::nullopt;
  return it->second;
}

std::string Args::text(const std::string& name) const {
  auto v = get(name);
  if (!v) throw UsageError(name + " is required (see `cloudgen " + verb_ + " --help`)");
  if (v->empty()) throw UsageError(name + " must not be empty");
  return *v;
}

long long Args::integer(const std::string& name, long long lo, long long hi) const {
  const std::string range = "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  auto v = get(name);
  if (!v) throw UsageError(name + " is required: " + range);
  const auto x = parse_integer(*v);
  if (!x || *x < lo || *x > hi) throw UsageError(name + " must be " + range + "; got '" + clipped(*v, 100) + "'");
  return *x;
}

static std::string fmt_num(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

double Args::number(const std::string& name, double lo, double hi, bool lo_open) const {
  const std::string range =
      "a finite number in " + std::string(lo_open ? "(" : "[") + fmt_num(lo) + ", " + fmt_num(hi) + "]";
  auto v = get(name);
  if (!v) throw UsageError(name + " is required: " + range);
  const auto x = parse_number(*v);
  if (!x || *x < lo || *x > hi || (lo_open && *x == lo))
    throw UsageError(name + " must be " + range + "; got '" + clipped(*v, 100) + "'");
  return *x;
}

// ---- parameters ----

std::string read_text_file(const std::string& path, const std::string& option, std::size_t max_bytes) {
  const std::string what = option + " '" + path + "'";
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw UsageError(what + ": a directory, expected a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UsageError(what + ": cannot read (" + std::strerror(errno) + ")");
  std::string text;
  char buf[65536];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    text.append(buf, std::size_t(in.gcount()));
    if (text.size() > max_bytes)
      throw UsageError(what + ": larger than " + std::to_string(max_bytes) + " bytes, the limit for this file");
  }
  if (in.bad()) throw UsageError(what + ": read error");
  return text;
}

void set_time(cg::Params& p, double t, const std::string& option) {
  try {
    p.set(cg::TIME, static_cast<float>(t));
  } catch (const cg::ParamError& e) {
    throw UsageError(option + ": " + e.what());
  }
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

cg::Params load_params(const Args& args, std::string& preset) {
  const bool has_preset = args.has("--preset"), has_file = args.has("--params");
  if (has_preset == has_file) throw UsageError("give exactly one of --preset NAME or --params FILE.json");
  if (has_preset) {
    const std::string name = *args.get("--preset");
    const cg::Preset* p = cg::find_preset(name);
    if (!p) {
      std::string names;
      for (const cg::Preset& q : cg::presets()) names += (names.empty() ? "" : ", ") + q.name;
      throw UsageError("--preset '" + name.substr(0, 100) + "' is not a preset; choose one of: " + names +
                       cg::did_you_mean(name, cg::preset_names()));
    }
    preset = p->name;
    return p->params;
  }
  const std::string path = *args.get("--params");
  const std::string text = read_text_file(path, "--params", 1u << 20);
  preset.clear();
  try {
    return cg::params_from_json(text, "--params " + path);
  } catch (const cg::ParamError&) {
    throw;
  } catch (const std::exception& e) {
    // nlohmann's out_of_range (e.g. 1e999) is not a parse_error and escapes params_from_json.
    throw UsageError("--params " + path + ": not valid JSON (" + cg::json_error_text(e.what()) + ")");
  }
}

// ---- presets ----

static const char* const kPresetsHelp =
    "usage: cloudgen presets [--json]\n"
    "\n"
    "Lists the cloud types (presets) with a one-line description and the\n"
    "material settings they suggest (Henyey-Greenstein anisotropy, colour,\n"
    "volume step rate). --json prints the presets data file itself (every\n"
    "preset with its parameter values and material).\n"
    "Use a preset with `cloudgen bake --preset NAME` or as \"preset\" in a\n"
    "parameter file.\n";

int cmd_presets(const std::vector<std::string>& argv) {
  Args a("presets", argv, {{"--json", false}});
  if (a.help()) return std::cout << kPresetsHelp, kExitOk;
  if (!a.positional().empty()) throw UsageError("presets: unexpected argument '" + a.positional()[0] + "'");
  if (a.has("--json")) {
    std::cout << cg::presets_json();
    return kExitOk;
  }
  for (const cg::Preset& p : cg::presets()) {
    std::printf("%-18s %s\n", p.name.c_str(), p.description.c_str());
    if (p.material.empty()) continue;
    std::string line;
    for (const cg::MaterialValue& m : p.material) {
      line += line.empty() ? "" : ", ";
      line += m.key + " ";
      for (size_t i = 0; i < m.values.size(); ++i) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%s%g", i ? " " : "", m.values[i]);
        line += buf;
      }
    }
    std::printf("%-18s material: %s\n", "", line.c_str());
  }
  return kExitOk;
}

// ---- tiers ----

static const char* const kTiersHelp =
    "usage: cloudgen tiers [--json]\n"
    "\n"
    "Lists the quality tiers (Draft, Preview, Final): named points on the measured\n"
    "speed/accuracy trade (docs/accuracy.md) with their render settings (Cycles\n"
    "samples, volume step rate), bake settings (resolution, LOD, drop tolerance,\n"
    "half floats) and preview size. --json prints the tiers data file with the\n"
    "measured times and errors per scene. Use one with `cloudgen bake --quality NAME`.\n";

int cmd_tiers(const std::vector<std::string>& argv) {
  Args a("tiers", argv, {{"--json", false}});
  if (a.help()) return std::cout << kTiersHelp, kExitOk;
  if (!a.positional().empty()) throw UsageError("tiers: unexpected argument '" + a.positional()[0] + "'");
  if (a.has("--json")) {
    (void)cg::tiers();  // validated before printing
    std::cout << cg::tiers_json();
    return kExitOk;
  }
  for (const cg::Tier& t : cg::tiers()) {
    std::printf("%-8s %s\n", t.name.c_str(), t.description.c_str());
    std::printf(
        "%-8s render: %d samples, step rate %g; bake: resolution %d, lod %s, tolerance %g, %s floats, "
        "%g px/voxel with --camera; preview %d px\n",
        "", t.render_samples, t.render_step_rate, t.bake_resolution, t.bake_lod ? "on" : "off", t.bake_tolerance,
        t.bake_half ? "half" : "full", t.bake_pixels_per_voxel, t.preview_size);
  }
  return kExitOk;
}

// ---- params ----

static const char* const kParamsHelp =
    "usage: cloudgen params [--json | --defaults]\n"
    "\n"
    "Lists every parameter a parameter file (--params FILE.json) may set: its\n"
    "key, kind, default, accepted range, unit and meaning. Values outside the\n"
    "range, NaN and Inf are refused.\n"
    "  --json      the declarations as JSON (name, label, group, kind, count,\n"
    "              default, min, max, soft_min, soft_max, map, unit, help)\n"
    "  --defaults  a parameter file holding every default value\n"
    "\n"
    "A parameter file is one JSON object, e.g.\n"
    "  {\"preset\": \"cumulus\", \"density\": 0.8, \"box_size\": [4, 4, 3]}\n"
    "\"preset\" (optional) names the cloud type to start from; missing keys keep\n"
    "their defaults; vectors and the shape curve are lists.\n";

static std::string value_text(const cg::Params& p, cg::P id) {
  const cg::ParamDecl& d = cg::kParams[id];
  const int n = cg::component_count(d.kind);
  std::string s = n > 1 ? "[" : "";
  for (int c = 0; c < n; ++c) s += (c ? ", " : "") + fmt_num(p.get(id, c));
  return n > 1 ? s + "]" : s;
}

int cmd_params(const std::vector<std::string>& argv) {
  Args a("params", argv, {{"--json", false}, {"--defaults", false}});
  if (a.help()) return std::cout << kParamsHelp, kExitOk;
  if (!a.positional().empty()) throw UsageError("params: unexpected argument '" + a.positional()[0] + "'");
  if (a.has("--json")) {
    std::cout << cg::declarations_json(2) << "\n";
    return kExitOk;
  }
  if (a.has("--defaults")) {
    std::cout << cg::params_to_json(cg::Params(), 2) << "\n";
    return kExitOk;
  }
  const cg::Params defaults;
  std::string group;
  for (int i = 0; i < cg::PARAM_COUNT; ++i) {
    const cg::ParamDecl& d = cg::kParams[i];
    if (group != d.group) {
      group = d.group;
      std::printf("%s%s\n", i ? "\n" : "", d.group);
      std::printf("  %-18s %-6s %-16s %-22s %s\n", "key", "kind", "default", "range", "unit — meaning");
    }
    std::string def = value_text(defaults, static_cast<cg::P>(i));
    if (def.size() > 16) def.replace(13, std::string::npos, "...");
    std::string range("[");
    range.append(fmt_num(d.min)).append(", ").append(fmt_num(d.max)).append("]");
    std::printf("  %-18s %-6s %-16s %-22s %s — %s\n", d.key, cg::kind_name(d.kind), def.c_str(), range.c_str(), d.unit,
                d.help);
  }
  return kExitOk;
}

// ---- info ----

static const char* const kInfoHelp =
    "usage: cloudgen info FILE.vdb [--json]\n"
    "\n"
    "Reads a VDB file with OpenVDB and prints, for every grid: name, class,\n"
    "value type, voxel size, transform, active voxel count, index bounding\n"
    "box, minimum and maximum of the active values, and all metadata (for\n"
    "cloudgen files: version, parameters, preset, time, resolution, LOD).\n"
    "  --json   the same as one JSON object\n"
    "Exit code 1 when the file is missing or not a readable VDB file. The file is\n"
    "checked first (magic, version, header, descriptors, metadata sizes) and read\n"
    "by OpenVDB in a child process with memory and time limits\n"
    "(docs/hostile_inputs.md; CLOUDGEN_VDB_READ_MIB, CLOUDGEN_VDB_READ_SECONDS).\n";

int cmd_info(const std::vector<std::string>& argv) {
  Args a("info", argv, {{"--json", false}});
  if (a.help()) return std::cout << kInfoHelp, kExitOk;
  if (a.positional().size() != 1) throw UsageError("info needs exactly one FILE.vdb argument");
  const std::string path = a.positional()[0];
  // Checked, then read by OpenVDB in a limited child process: a hostile file costs one error line.
  const cgio::VdbFileInfo f = cgio::read_vdb_info_isolated(path);
  if (a.has("--json")) {
    nlohmann::json doc = {{"file", path},
                          {"bytes", cgio::file_size(path)},
                          {"version", f.version},
                          {"compression", f.compression},
                          {"grids", nlohmann::json::array()}};
    for (const cgio::VdbGridInfo& g : f.grids)
      doc["grids"].push_back({{"name", g.name},
                              {"class", g.grid_class},
                              {"value_type", g.value_type},
                              {"voxel_size", g.voxel_size},
                              {"linear", g.linear},
                              {"half", g.half},
                              {"active_voxels", g.active_voxels},
                              {"leaf_count", g.leaf_count},
                              {"empty", g.empty},
                              {"bbox_min", g.bbox_min},
                              {"bbox_max", g.bbox_max},
                              {"min", g.min},
                              {"max", g.max},
                              {"background", g.background},
                              {"metadata", g.metadata}});
    std::cout << doc.dump(2) << "\n";
    return kExitOk;
  }
  std::printf("file: %s (%lld bytes, OpenVDB file version %s, compression %s)\n", path.c_str(), cgio::file_size(path),
              f.version.c_str(), f.compression.c_str());
  std::printf("grids: %zu\n", f.grids.size());
  for (const cgio::VdbGridInfo& g : f.grids) {
    std::printf("grid: %s\n", g.name.c_str());
    std::printf("  class: %s\n", g.grid_class.c_str());
    std::printf("  value type: %s (saved as half: %s)\n", g.value_type.c_str(), g.half ? "yes" : "no");
    std::printf("  voxel size: %g %g %g (%s transform)\n", g.voxel_size[0], g.voxel_size[1], g.voxel_size[2],
                g.linear ? "linear" : "non-linear");
    std::printf("  active voxels: %lld\n", static_cast<long long>(g.active_voxels));
    std::printf("  leaf nodes: %lld\n", static_cast<long long>(g.leaf_count));
    if (g.empty) {
      std::printf("  index bbox: empty\n");
    } else {
      std::printf("  index bbox: [%d %d %d] .. [%d %d %d]\n", g.bbox_min[0], g.bbox_min[1], g.bbox_min[2],
                  g.bbox_max[0], g.bbox_max[1], g.bbox_max[2]);
      std::printf("  min: %.9g\n  max: %.9g\n", g.min, g.max);
    }
    std::printf("  background: %g\n", g.background);
    std::printf("  metadata:\n");
    for (const auto& [k, v] : g.metadata) std::printf("    %s: %s\n", k.c_str(), one_line(v).c_str());
  }
  return kExitOk;
}

}  // namespace cli
