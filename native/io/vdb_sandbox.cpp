// io/vdb_sandbox.cpp — fork + exec of a limited child that reads a VDB file.
#include "io/vdb_sandbox.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <limits>
#include <new>
#include <nlohmann/json.hpp>
#include <vector>

#include "io/atomic_file.h"
#include "io/vdb_check.h"

extern char** environ;

namespace cgio {

namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAsan = true;
#else
constexpr bool kAsan = false;
#endif

using json = nlohmann::json;

json num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }
double num(const json& j) { return j.is_number() ? j.get<double>() : std::numeric_limits<double>::quiet_NaN(); }

// One line, runs of blanks collapsed (OpenVDB pads some messages with hundreds), at most n characters.
std::string clip(const std::string& in, std::size_t n = 100) {
  std::string s;
  for (char c : in) {
    if (c == '\n' || c == '\r' || c == '\t') c = ' ';
    if (c == ' ' && (s.empty() || s.back() == ' ')) continue;
    s += c;
  }
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s.size() > n ? s.substr(0, n) + "..." : s;
}

double env_number(const char* name, double fallback) {
  const char* v = std::getenv(name);
  if (!v || !*v) return fallback;
  char* end = nullptr;
  const double x = std::strtod(v, &end);
  return (end && *end == 0 && x > 0 && std::isfinite(x)) ? x : fallback;
}

std::string signal_text(int sig) {
  const char* name = sig == SIGSEGV   ? "SIGSEGV"
                     : sig == SIGABRT ? "SIGABRT"
                     : sig == SIGBUS  ? "SIGBUS"
                     : sig == SIGKILL ? "SIGKILL"
                     : sig == SIGXCPU ? "SIGXCPU"
                     : sig == SIGFPE  ? "SIGFPE"
                                      : "";
  return *name ? std::string(name) : "signal " + std::to_string(sig);
}

}  // namespace

std::string vdb_info_to_json(const VdbFileInfo& f) {
  json doc = {{"version", f.version}, {"compression", f.compression}, {"grids", json::array()}};
  for (const VdbGridInfo& g : f.grids)
    doc["grids"].push_back({{"name", g.name},
                            {"class", g.grid_class},
                            {"value_type", g.value_type},
                            {"voxel_size", {num(g.voxel_size[0]), num(g.voxel_size[1]), num(g.voxel_size[2])}},
                            {"linear", g.linear},
                            {"half", g.half},
                            {"active_voxels", g.active_voxels},
                            {"leaf_count", g.leaf_count},
                            {"empty", g.empty},
                            {"bbox_min", g.bbox_min},
                            {"bbox_max", g.bbox_max},
                            {"min", num(g.min)},
                            {"max", num(g.max)},
                            {"background", num(g.background)},
                            {"metadata", g.metadata}});
  // Metadata text from a foreign file need not be UTF-8: replaced, never thrown.
  return doc.dump(-1, ' ', false, json::error_handler_t::replace);
}

VdbFileInfo vdb_info_from_json(const std::string& text) {
  try {
    const json doc = json::parse(text);
    VdbFileInfo f;
    f.version = doc.at("version").get<std::string>();
    f.compression = doc.at("compression").get<std::string>();
    for (const json& g : doc.at("grids")) {
      VdbGridInfo i;
      i.name = g.at("name").get<std::string>();
      i.grid_class = g.at("class").get<std::string>();
      i.value_type = g.at("value_type").get<std::string>();
      for (int k = 0; k < 3; ++k) i.voxel_size[k] = num(g.at("voxel_size").at(k));
      i.linear = g.at("linear").get<bool>();
      i.half = g.at("half").get<bool>();
      i.active_voxels = g.at("active_voxels").get<std::int64_t>();
      i.leaf_count = g.at("leaf_count").get<std::int64_t>();
      i.empty = g.at("empty").get<bool>();
      i.bbox_min = g.at("bbox_min").get<std::array<int, 3>>();
      i.bbox_max = g.at("bbox_max").get<std::array<int, 3>>();
      i.min = num(g.at("min"));
      i.max = num(g.at("max"));
      i.background = num(g.at("background"));
      i.metadata = g.at("metadata").get<std::map<std::string, std::string>>();
      f.grids.push_back(std::move(i));
    }
    return f;
  } catch (const json::exception& e) {
    throw IoError(std::string("the reader process answered malformed data (") + clip(e.what()) + ")");
  }
}

int vdb_info_child_main(const std::string& path) {
  json out;
  int code = 0;
  try {
    std::string text = vdb_info_to_json(read_vdb_info(path));
    std::fwrite(text.data(), 1, text.size(), stdout);
    std::fflush(stdout);
    return 0;
  } catch (const std::bad_alloc&) {
    out = {{"error", "OpenVDB ran out of the memory allowed for reading it (corrupt or hostile file?)"}};
    code = 3;
  } catch (const std::exception& e) {
    out = {{"error", clip(e.what(), 300)}};
    code = 3;
  }
  const std::string text = out.dump(-1, ' ', false, json::error_handler_t::replace);
  std::fwrite(text.data(), 1, text.size(), stdout);
  std::fflush(stdout);
  return code;
}

VdbFileInfo read_vdb_info_isolated(const std::string& path, const std::string& helper, const VdbReadLimits& lim) {
  const std::string what = "cannot read '" + path + "': ";
  (void)check_vdb_file(path);  // regular file, header, descriptors, metadata: throws IoError
  const double file_bytes = double(std::max(0LL, file_size(path)));
  double memory =
      std::min(double(lim.memory_base) + double(lim.memory_per_file_byte) * file_bytes, double(lim.memory_max));
  memory = env_number("CLOUDGEN_VDB_READ_MIB", memory / double(1 << 20)) * double(1 << 20);
  const double seconds = env_number("CLOUDGEN_VDB_READ_SECONDS", lim.seconds_base + file_bytes / lim.bytes_per_second);

  // Everything the child needs is built before fork: after it, only async-signal-safe calls.
  const std::string exe = helper.empty() ? "/proc/self/exe" : helper;
  std::vector<std::string> args = {exe, kVdbInfoChildVerb, path};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env;
  for (char** e = environ; e && *e; ++e)
    if (!kAsan || std::strncmp(*e, "ASAN_OPTIONS=", 13) != 0) env.emplace_back(*e);
  if (kAsan) {  // the allocator's limits stand in for RLIMIT_AS; reports still abort the child
    const char* old = std::getenv("ASAN_OPTIONS");
    const long mib = long(memory / double(1 << 20));
    env.push_back("ASAN_OPTIONS=" + std::string(old ? old : "") + (old && *old ? ":" : "") +
                  "detect_leaks=0:allocator_may_return_null=1:max_allocation_size_mb=" + std::to_string(mib) +
                  ":hard_rss_limit_mb=" + std::to_string(mib));
  }
  std::vector<char*> envp;
  for (std::string& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);
  struct rlimit as_limit {
    rlim_t(memory), rlim_t(memory)
  };
  struct rlimit cpu_limit {
    rlim_t(seconds) + 1, rlim_t(seconds) + 2
  };
  struct rlimit no_core {
    0, 0
  };

  // stdout: the answer. stderr: /dev/null, except under ASan, where the
  // parent reads it to tell a memory-limit report from a real one.
  int out[2], err[2] = {-1, -1};
  if (::pipe2(out, O_CLOEXEC) != 0) throw IoError(what + "pipe: " + std::strerror(errno));
  if (kAsan && ::pipe2(err, O_CLOEXEC) != 0) {
    ::close(out[0]), ::close(out[1]);
    throw IoError(what + "pipe: " + std::strerror(errno));
  }
  const int devnull = ::open("/dev/null", O_RDWR | O_CLOEXEC);
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int e = errno;
    for (int fd : {out[0], out[1], err[0], err[1], devnull})
      if (fd >= 0) ::close(fd);
    throw IoError(what + "fork: " + std::strerror(e));
  }
  if (pid == 0) {
    if (devnull >= 0) ::dup2(devnull, 0);
    ::dup2(out[1], 1);
    if (kAsan)
      ::dup2(err[1], 2);
    else if (devnull >= 0)
      ::dup2(devnull, 2);  // OpenVDB's own messages stay out of the one-line error
    if (!kAsan) ::setrlimit(RLIMIT_AS, &as_limit);
    ::setrlimit(RLIMIT_CPU, &cpu_limit);
    ::setrlimit(RLIMIT_CORE, &no_core);
    ::execve(exe.c_str(), argv.data(), envp.data());
    ::_exit(127);
  }
  for (int fd : {out[1], err[1], devnull})
    if (fd >= 0) ::close(fd);

  std::string text, errors;
  bool timed_out = false, too_big = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  char buf[65536];
  int open_fds = err[0] >= 0 ? 2 : 1;
  struct pollfd fds[2] = {{out[0], POLLIN, 0}, {err[0], POLLIN, 0}};
  while (open_fds > 0) {
    const double left = std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0) {
      timed_out = true;
      break;
    }
    const int r = ::poll(fds, 2, int(std::min(left * 1000.0, 1000.0)) + 1);
    if (r <= 0) continue;  // EINTR or nothing yet
    for (int i = 0; i < 2; ++i) {
      if (fds[i].fd < 0 || !(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      const ssize_t n = ::read(fds[i].fd, buf, sizeof buf);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        ::close(fds[i].fd);
        fds[i].fd = -1;  // poll ignores negative descriptors
        --open_fds;
        continue;
      }
      std::string& sink = i == 0 ? text : errors;
      if (i == 1 && errors.size() > (1u << 20)) continue;  // a report's head is enough
      sink.append(buf, std::size_t(n));
      if (i == 0 && text.size() > lim.max_output) too_big = true;
    }
    if (too_big) break;
  }
  for (const pollfd& f : fds)
    if (f.fd >= 0) ::close(f.fd);
  if (timed_out || too_big) ::kill(pid, SIGKILL);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (kAsan && !errors.empty()) {
    // Allocations past the limit are ASan reports too: they are the limit doing its work.
    const bool memory_limit = errors.find("allocation-size-too-big") != std::string::npos ||
                              errors.find("out-of-memory") != std::string::npos ||
                              errors.find("rss-limit-exceeded") != std::string::npos ||
                              errors.find("hard rss limit exhausted") != std::string::npos ||
                              errors.find("allocator is out of memory") != std::string::npos;
    if (memory_limit)
      throw IoError(what + "OpenVDB ran out of the memory allowed for reading it (corrupt or hostile file?)");
    if (errors.find("Sanitizer") != std::string::npos || errors.find("runtime error") != std::string::npos)
      std::cerr << errors << std::flush;  // a real report: shown whole, the tests fail on it
  }
  char limits[160];
  std::snprintf(limits, sizeof limits, "limits: %.0f MiB, %.0f s", memory / double(1 << 20), seconds);
  if (timed_out)
    throw IoError(what + "OpenVDB did not finish reading it in time (corrupt or hostile file?; " + limits + ")");
  if (too_big) throw IoError(what + "the reader process answered more than the allowed output");
  if (WIFSIGNALED(status))
    throw IoError(what + "OpenVDB failed reading it (the reader process ended by " + signal_text(WTERMSIG(status)) +
                  "; corrupt or hostile file?; " + limits + ")");
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == 127 && text.empty()) throw IoError(what + "cannot start the reader process '" + exe + "'");
  if (code == 0) return vdb_info_from_json(text);
  std::string reason = "the reader process failed (exit " + std::to_string(code) + ")";
  try {
    const json doc = json::parse(text);
    if (doc.contains("error") && doc["error"].is_string()) reason = doc["error"].get<std::string>();
  } catch (const json::exception&) {
    if (kAsan && code != 3 && !errors.empty()) reason += " (see the sanitizer report above)";
  }
  std::string message = clip(reason, 300);
  const std::string prefix = "cannot read '" + path + "': ";
  if (message.rfind(prefix, 0) == 0) message.erase(0, prefix.size());
  throw IoError(what + message);
}

}  // namespace cgio
