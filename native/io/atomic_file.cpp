// io/atomic_file.cpp — temporary file + rename, and the checks before it.
#include "io/atomic_file.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>

namespace cgio {

namespace {

// Registry of live temporaries for the signal handler: fixed storage, no
// allocation, a slot is readable only while its state is kReady.
constexpr int kSlots = 16;
constexpr std::size_t kPathMax = 4096;
enum : int { kFree = 0, kBusy = 1, kReady = 2 };
std::atomic<int> g_state[kSlots];
char g_paths[kSlots][kPathMax];
std::atomic<unsigned> g_counter{0};

int register_temp(const std::string& path) {
  if (path.size() >= kPathMax) return -1;
  for (int s = 0; s < kSlots; ++s) {
    int expected = kFree;
    if (g_state[s].compare_exchange_strong(expected, kBusy)) {
      std::memcpy(g_paths[s], path.c_str(), path.size() + 1);
      g_state[s].store(kReady);
      return s;
    }
  }
  return -1;
}

void unregister_temp(int slot) {
  if (slot >= 0) g_state[slot].store(kFree);
}

std::string dir_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

std::string base_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

void check_output_path(const std::string& path, const std::string& option) {
  const std::string what = option + " '" + path + "'";
  if (path.empty()) throw OutputPathError(option + " must name a file; got an empty path");
  if (path.back() == '/') throw OutputPathError(what + " names a directory; expected a file name");
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
    throw OutputPathError(what + " is a directory; expected a file name");
  const std::string dir = dir_of(path);
  if (::stat(dir.c_str(), &st) != 0)
    throw OutputPathError(what + ": directory '" + dir + "' " +
                          (errno == ENOTDIR ? "is not a directory (a parent is a file)"
                                            : "does not exist (" + std::string(std::strerror(errno)) + ")"));
  if (!S_ISDIR(st.st_mode)) throw OutputPathError(what + ": '" + dir + "' is not a directory");
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw OutputPathError(what + ": directory '" + dir + "' is not writable (" + std::strerror(errno) + ")");
}

AtomicFile::AtomicFile(std::string final_path) : final_(std::move(final_path)) {
  const std::string base = base_of(final_);
  const auto dot = base.find_last_of('.');
  const std::string stem = dot == std::string::npos || dot == 0 ? base : base.substr(0, dot);
  const std::string ext = dot == std::string::npos || dot == 0 ? "" : base.substr(dot);
  const std::string dir = dir_of(final_);
  temp_ = (final_.find('/') == std::string::npos ? std::string() : dir + "/") + "." + stem + ".tmp-" +
          std::to_string(::getpid()) + "-" + std::to_string(g_counter.fetch_add(1)) + ext;
  slot_ = register_temp(temp_);
}

AtomicFile::~AtomicFile() { discard(); }

void AtomicFile::discard() {
  if (!done_) {
    ::unlink(temp_.c_str());
    done_ = true;
  }
  unregister_temp(slot_);
  slot_ = -1;
}

void AtomicFile::commit() {
  if (done_) throw IoError("internal: commit of a finished file '" + final_ + "'");
  const int fd = ::open(temp_.c_str(), O_RDONLY);
  if (fd < 0) {
    const std::string reason = std::strerror(errno);
    discard();
    throw IoError("cannot write '" + final_ + "': the temporary file vanished (" + reason + ")");
  }
  const bool synced = ::fsync(fd) == 0;
  const std::string sync_reason = synced ? "" : std::strerror(errno);
  ::close(fd);
  if (!synced) {
    discard();
    throw IoError("cannot write '" + final_ + "': " + sync_reason);
  }
  if (::rename(temp_.c_str(), final_.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    discard();
    throw IoError("cannot rename the temporary file to '" + final_ + "': " + reason);
  }
  done_ = true;
  unregister_temp(slot_);
  slot_ = -1;
}

void remove_temporaries_signal_safe() {
  for (int s = 0; s < kSlots; ++s)
    if (g_state[s].load() == kReady) ::unlink(g_paths[s]);
}

namespace {

// The PID of an AtomicFile temporary's name, or -1 when the name is not one.
long temp_pid(const std::string& name) {
  if (name.size() < 9 || name[0] != '.') return -1;
  const auto at = name.rfind(".tmp-");
  if (at == std::string::npos || at < 2) return -1;
  std::size_t i = at + 5, digits = 0;
  long pid = 0;
  for (; i < name.size() && name[i] >= '0' && name[i] <= '9' && digits < 10; ++i, ++digits)
    pid = pid * 10 + (name[i] - '0');
  if (digits == 0 || i >= name.size() || name[i] != '-') return -1;
  std::size_t n = 0;
  for (++i; i < name.size() && name[i] >= '0' && name[i] <= '9'; ++i) ++n;
  if (n == 0) return -1;
  if (i < name.size()) {  // an extension: a dot and letters or digits only
    if (name[i] != '.' || i + 1 == name.size()) return -1;
    for (++i; i < name.size(); ++i)
      if (!std::isalnum(static_cast<unsigned char>(name[i]))) return -1;
  }
  return pid;
}

}  // namespace

int remove_stale_temporaries(const std::string& final_path) {
  const std::string dir = dir_of(final_path);
  DIR* d = ::opendir(dir.c_str());
  if (!d) return 0;
  int removed = 0;
  while (const dirent* e = ::readdir(d)) {
    const std::string name = e->d_name;
    const long pid = temp_pid(name);
    if (pid <= 0 || pid == long(::getpid())) continue;
    if (::kill(pid_t(pid), 0) == 0 || errno != ESRCH) continue;  // alive (or not ours to know): leave it
    const std::string path = dir + "/" + name;
    struct stat st {};
    if (::lstat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode) || st.st_uid != ::geteuid()) continue;
    if (::unlink(path.c_str()) == 0) ++removed;
  }
  ::closedir(d);
  return removed;
}

long long file_size(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 ? static_cast<long long>(st.st_size) : -1;
}

}  // namespace cgio
