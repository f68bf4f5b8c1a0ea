// io/atomic_file.h — outputs that appear whole or not at all.
//
// Every file cloudgen writes goes first to a temporary file in the same
// directory (so the final rename cannot cross file systems) and is renamed
// into place only by commit(). Destroying an uncommitted AtomicFile removes
// the temporary; a signal handler can remove every live temporary with
// remove_temporaries_signal_safe() before it exits.
#pragma once

#include <stdexcept>
#include <string>

namespace cgio {

// A runtime I/O failure (the CLI exits with 1).
struct IoError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A bad output argument found before any work (the CLI exits with 2). The
// message names `option` (e.g. "--output").
struct OutputPathError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Checks up front that `path` can be written: not empty, not a directory, its
// directory exists, is a directory and is writable. Throws OutputPathError.
void check_output_path(const std::string& path, const std::string& option = "--output");

class AtomicFile {
 public:
  // Chooses a fresh temporary name next to `final_path`, keeping its
  // extension (".name.tmp-PID-N.ext"), and registers it for signal cleanup.
  // Nothing is created on disk yet: the writer creates temp_path().
  explicit AtomicFile(std::string final_path);
  ~AtomicFile();  // removes the temporary unless committed
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::string& path() const { return final_; }
  const std::string& temp_path() const { return temp_; }

  // Runs write(temp_path()); an IoError it throws is rethrown naming path()
  // where it named the temporary, so messages show the file the user asked for.
  template <class Write>
  void write_with(Write&& write) {
    try {
      write(temp_);
    } catch (const IoError& e) {
      std::string message = e.what();
      for (std::size_t at; (at = message.find(temp_)) != std::string::npos;) message.replace(at, temp_.size(), final_);
      throw IoError(message);
    }
  }

  // Flushes the temporary to disk and renames it to path(). Throws IoError
  // (the temporary is removed) when it is missing or the rename fails.
  void commit();
  // Removes the temporary now (idempotent).
  void discard();

 private:
  std::string final_, temp_;
  int slot_ = -1;
  bool done_ = false;
};

// Unlinks every registered temporary; only async-signal-safe calls.
void remove_temporaries_signal_safe();

// Temporaries left by a process that was killed (SIGKILL, power loss) before it
// could remove them: in the directory of `final_path`, files named like an
// AtomicFile temporary (".STEM.tmp-PID-N[.EXT]"), owned by this user, whose PID
// is no running process. Removes them and returns how many. Nothing ever reads
// a temporary; this only keeps them from piling up. Errors are ignored.
int remove_stale_temporaries(const std::string& final_path);

// Size of a file in bytes, or -1.
long long file_size(const std::string& path);

}  // namespace cgio
