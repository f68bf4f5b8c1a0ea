// cli/commands.h — the verbs of the cloudgen command-line tool.
//
// Exit codes: 0 ok; 2 bad usage or argument (UsageError, ParamError,
// OutputPathError: one line naming the argument and what it accepts);
// 1 runtime failure (IoError); 130 cancelled (SIGINT/SIGTERM).
#pragma once

#include <chrono>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "cloudgen/params.h"

namespace cli {

constexpr int kExitOk = 0, kExitFailure = 1, kExitUsage = 2, kExitCancelled = 130;

// A bad command line; what() is the one-line reason.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Set by the SIGINT/SIGTERM handler (main.cpp).
bool cancel_requested();

// ---- argument parsing ----

struct OptionSpec {
  const char* name;  // "--resolution"
  bool takes_value;
};

// Parsed options of one verb: `--name value`, `--name=value` or a flag.
// Unknown options, missing values and repeats are UsageErrors.
class Args {
 public:
  Args(const std::string& verb, const std::vector<std::string>& argv, const std::vector<OptionSpec>& specs);
  bool help() const { return help_; }
  bool has(const std::string& name) const { return values_.count(name) != 0; }
  std::optional<std::string> get(const std::string& name) const;
  const std::vector<std::string>& positional() const { return positional_; }

  // Typed values; a bad value is a UsageError naming the option and the range.
  std::string text(const std::string& name) const;  // required
  long long integer(const std::string& name, long long lo, long long hi) const;
  double number(const std::string& name, double lo, double hi, bool lo_open = false) const;

 private:
  std::string verb_;
  bool help_ = false;
  std::map<std::string, std::string> values_;
  std::vector<std::string> positional_;
};

// Strict parsing of a whole string; nullopt unless it is entirely a finite number.
std::optional<long long> parse_integer(const std::string& s);
std::optional<double> parse_number(const std::string& s);

// The whole file as text; UsageError naming `option` when it cannot be read,
// is a directory or holds more than `max_bytes` (read no further than that).
std::string read_text_file(const std::string& path, const std::string& option, std::size_t max_bytes);

// The parameters from exactly one of --preset NAME / --params FILE.json
// (UsageError/ParamError otherwise); `preset` receives the preset's name.
cg::Params load_params(const Args& args, std::string& preset);

// Sets the `time` parameter; a bad value is a UsageError naming `option`.
void set_time(cg::Params& p, double t, const std::string& option);

// Wall seconds since t0 (steady clock).
double seconds_since(std::chrono::steady_clock::time_point t0);

// Collapses a message onto one line.
std::string one_line(std::string s);
// At most n characters of s, then "..." (bad values in messages).
std::string clipped(const std::string& s, std::size_t n);

// ---- verbs: each returns the exit code, throws for errors ----
int cmd_bake(const std::vector<std::string>& argv);
int cmd_preview(const std::vector<std::string>& argv);
int cmd_presets(const std::vector<std::string>& argv);
int cmd_params(const std::vector<std::string>& argv);
int cmd_info(const std::vector<std::string>& argv);
int cmd_tiers(const std::vector<std::string>& argv);
int cmd_merge(const std::vector<std::string>& argv);

extern const char* const kUsage;  // cloudgen --help

}  // namespace cli
