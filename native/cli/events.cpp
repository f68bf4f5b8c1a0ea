// cli/events.cpp — human and JSON output of the verbs (see events.h).
#include "cli/events.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>

namespace cli {

namespace {
OutputMode g_mode = OutputMode::Human;

// Paths and messages may hold bytes that are not UTF-8: replace, never throw.
std::string dump(const Fields& j) { return j.dump(-1, ' ', false, Fields::error_handler_t::replace); }
}  // namespace

void set_output_mode(OutputMode mode) { g_mode = mode; }
OutputMode output_mode() { return g_mode; }

void emit(const char* name, const Fields& fields, const std::string& human) {
  if (g_mode == OutputMode::Json) {
    Fields event = {{"event", name}};
    event.update(fields);
    std::fputs((dump(event) + "\n").c_str(), stdout);
  } else if (!human.empty()) {
    std::fputs((human + "\n").c_str(), stdout);
  }
  std::fflush(stdout);
}

void Progress::update(double fraction) {
  if (quiet_) return;
  const double f = std::isfinite(fraction) ? std::fmin(std::fmax(fraction, 0.0), 1.0) : 0.0;
  const int pct = static_cast<int>(std::floor(100.0 * f));
  if (g_mode == OutputMode::Json) {
    if (pct == last_percent_) return;
    last_percent_ = pct;
    emit("progress", {{"fraction", f}}, "");
    return;
  }
  static const bool terminal = ::isatty(2) == 1;
  const int step = terminal ? pct : pct / 10 * 10;
  if (step == last_percent_) return;
  last_percent_ = step;
  if (terminal) {
    std::fprintf(stderr, "\r%s: %3d%%", what_, step);
    line_open_ = true;
  } else {
    std::fprintf(stderr, "%s: %d%%\n", what_, step);
  }
  std::fflush(stderr);
}

void Progress::finish() {
  if (line_open_) std::fputs("\n", stderr), std::fflush(stderr);
  line_open_ = false;
}

void report_error(int code, const std::string& message) {
  std::fflush(stdout);
  if (g_mode == OutputMode::Json) emit("error", {{"code", code}, {"message", message}}, "");
  std::fprintf(stderr, "cloudgen: error: %s\n", message.c_str());
}

}  // namespace cli
