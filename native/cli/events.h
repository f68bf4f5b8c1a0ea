// cli/events.h — what a command tells its caller: human lines or JSON lines.
//
// Every verb reports through these functions, never with printf of its own, so
// the human output and the machine-readable one (`--json`, docs/cli_protocol.md)
// cannot drift apart. Human mode: results on stdout, progress on stderr (one
// line rewritten in place on a terminal, every 10 % otherwise). JSON mode: one
// object per line on stdout, nothing else there; the error line on stderr stays.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace cli {

// Event fields keep the order they are written in ("event" first).
using Fields = nlohmann::ordered_json;

enum class OutputMode { Human, Json };

// Chosen once per run by the verb (from --json); main() uses it to report errors.
void set_output_mode(OutputMode mode);
OutputMode output_mode();
inline bool json_output() { return output_mode() == OutputMode::Json; }

// One event: in JSON mode {"event": name, ...fields} on stdout; in human mode
// `human` on stdout (nothing when it is empty). Flushed at once.
void emit(const char* name, const Fields& fields, const std::string& human);

// Progress of the whole run, 0..1, of a task named `what` ("bake"). Throttled
// to whole percents (JSON) or tenths (human, not a terminal); `quiet` drops it.
class Progress {
 public:
  Progress(const char* what, bool quiet) : what_(what), quiet_(quiet) {}
  ~Progress() { finish(); }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  void update(double fraction);
  void finish();  // ends a terminal's in-place line
 private:
  const char* what_;
  bool quiet_;
  int last_percent_ = -1;
  bool line_open_ = false;
};

// The last line of a failed run: the `error` event in JSON mode (stdout) and
// always `cloudgen: error: MESSAGE` on stderr.
void report_error(int code, const std::string& message);

}  // namespace cli
