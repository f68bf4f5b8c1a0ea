// io/vdb_sandbox.h — reading an untrusted VDB file in a child process.
//
// OpenVDB 10 trusts the length fields of the files it reads (see
// docs/hostile_inputs.md): a hostile file can allocate gigabytes, overflow a
// heap buffer or take minutes. So every command that opens a VDB it did not
// just write (`cloudgen info`, `bake --update`) first runs the cheap checks of
// vdb_check.h in-process, then lets OpenVDB read the file in a child: fork +
// exec of the CLI itself with a hidden verb (`cloudgen __vdb-info-child PATH`,
// which prints the VdbFileInfo as one JSON object on stdout). The child runs
// with an address-space limit (RLIMIT_AS; under AddressSanitizer, which
// reserves terabytes of address space, the allocator's own limits instead), a
// CPU-time limit, and the parent kills it at a wall-clock deadline. Whatever
// the child does — crash, hang, exhaust its memory — the caller gets one
// IoError line; the parent process never runs OpenVDB on the file.
#pragma once

#include <cstdint>
#include <string>

#include "io/vdb_io.h"

namespace cgio {

struct VdbReadLimits {
  // Address space of the child: base + per_file_byte * file size, at most max.
  // Environment override: CLOUDGEN_VDB_READ_MIB (MiB, whole budget).
  std::uint64_t memory_base = 1ull << 30, memory_per_file_byte = 32, memory_max = 16ull << 30;
  // Wall-clock seconds: base + 1 s per per_second bytes of file.
  // Environment override: CLOUDGEN_VDB_READ_SECONDS.
  double seconds_base = 30, bytes_per_second = 20e6;
  std::size_t max_output = 256u << 20;  // bytes of JSON accepted from the child
};

// The verb the CLI must dispatch to vdb_info_child_main.
inline constexpr const char* kVdbInfoChildVerb = "__vdb-info-child";

// Checks `path` (check_vdb_file) and reads it with OpenVDB in a child running
// `helper` (an executable that dispatches kVdbInfoChildVerb; "" = this
// process's own executable, /proc/self/exe). Throws IoError with one line.
VdbFileInfo read_vdb_info_isolated(const std::string& path, const std::string& helper = "",
                                   const VdbReadLimits& limits = {});

// The child's side: reads `path` with read_vdb_info and writes one JSON object
// ({"info": ...} or {"error": "..."}) to stdout. Returns the exit code.
int vdb_info_child_main(const std::string& path);

std::string vdb_info_to_json(const VdbFileInfo& info);
VdbFileInfo vdb_info_from_json(const std::string& text);  // throws IoError

}  // namespace cgio
