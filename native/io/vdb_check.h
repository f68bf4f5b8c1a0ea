// io/vdb_check.h — cheap checks of a VDB file before OpenVDB sees it.
//
// OpenVDB's readers trust the length fields of a file: a hostile file can make
// them allocate gigabytes, read past a buffer or loop (docs/hostile_inputs.md).
// What can be checked cheaply, without OpenVDB, is checked here: the file is a
// regular file (never opened blocking: a FIFO is refused at once), the magic,
// the file format version (what this OpenVDB reads: 220 .. OPENVDB_FILE_VERSION),
// the header, the file metadata, the grid count and every grid descriptor
// (names, offsets inside the file), and each grid's metadata that sits at a
// known place (every grid of a file with offsets, the first grid of a stream):
// each value's size against its type, bools 0 or 1, and the length of the
// transform's type name that follows. The rest (transform, tree,
// values) is read by OpenVDB in a child process with limits (vdb_sandbox.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace cgio {

struct VdbHeaderLimits {
  std::uint32_t min_version = 220;  // OPENVDB_FILE_VERSION_SELECTIVE_COMPRESSION
  std::uint32_t max_version = 224;  // OPENVDB_FILE_VERSION of OpenVDB 10 (checked in vdb_io.cpp)
  std::int64_t max_grids = 1024;
  std::int64_t max_metadata = 4096;     // entries per metadata map
  std::uint32_t max_name = 4096;        // bytes in a name or type name
  std::uint32_t max_value = 64u << 20;  // bytes in one metadata value
};

struct VdbHeaderSummary {
  std::uint32_t version = 0;
  bool offsets = false;  // the file has grid offsets (random access)
  std::int64_t grids = 0;
  int grids_checked = 0;  // grids whose metadata was checked
};

// Checks the first `size` bytes of a file of `file_size` bytes (size <=
// file_size; checks stop quietly where the prefix ends, not where the file
// does). Returns "" when nothing is wrong, else a one-line reason.
std::string check_vdb_bytes(const unsigned char* data, std::size_t size, std::int64_t file_size,
                            const VdbHeaderLimits& limits, VdbHeaderSummary* summary = nullptr);

// Opens `path` without blocking, refuses anything but a regular file, reads at
// most `prefix` bytes and runs check_vdb_bytes. Throws IoError naming the path.
VdbHeaderSummary check_vdb_file(const std::string& path, const VdbHeaderLimits& limits = {},
                                std::size_t prefix = 16u << 20);

}  // namespace cgio
