// io/vdb_check.cpp — the VDB header walk (no OpenVDB here: fuzzed on its own).
#include "io/vdb_check.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <map>
#include <vector>

#include "io/atomic_file.h"

namespace cgio {

namespace {

struct Bad {  // the file is wrong: the reason
  std::string why;
};
struct PrefixEnd {};  // the checked prefix ends here; the rest is OpenVDB's

// Little-endian reads over the prefix, bounded by the file size.
class Cursor {
 public:
  Cursor(const unsigned char* d, std::size_t n, std::int64_t file) : d_(d), n_(n), file_(file) {}
  std::int64_t pos() const { return pos_; }
  void seek(std::int64_t p, const char* what) {
    if (p < 0 || p > file_) throw Bad{std::string(what) + " points outside the file"};
    pos_ = p;
  }
  void need(std::int64_t bytes, const char* what) {
    if (bytes < 0 || bytes > file_ - pos_)
      throw Bad{std::string("truncated or corrupt: ") + what + " runs past the end"};
    if (pos_ + bytes > std::int64_t(n_)) throw PrefixEnd{};
  }
  std::uint64_t uint(int bytes, const char* what) {
    need(bytes, what);
    std::uint64_t v = 0;
    for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | d_[pos_ + i];
    pos_ += bytes;
    return v;
  }
  std::string text(std::uint32_t max, const char* what) {
    const std::uint32_t len = std::uint32_t(uint(4, what));
    if (len > max)
      throw Bad{std::string(what) + " is " + std::to_string(len) + " bytes long (at most " + std::to_string(max) + ")"};
    need(len, what);
    std::string s(reinterpret_cast<const char*>(d_ + pos_), len);
    pos_ += len;
    return s;
  }
  void skip(std::int64_t bytes, const char* what) {
    need(bytes, what);
    pos_ += bytes;
  }
  unsigned char byte_at(std::int64_t p) const { return d_[p]; }

 private:
  const unsigned char* d_;
  std::size_t n_;
  std::int64_t file_, pos_ = 0;
};

// Sizes OpenVDB reads for its fixed-size metadata types (0: any length).
int fixed_size(const std::string& type) {
  static const std::map<std::string, int> sizes = {{"bool", 1},   {"int32", 4},  {"int64", 8},  {"float", 4},
                                                   {"double", 8}, {"vec2i", 8},  {"vec2s", 8},  {"vec2d", 16},
                                                   {"vec3i", 12}, {"vec3s", 12}, {"vec3d", 24}, {"vec4i", 16},
                                                   {"vec4s", 16}, {"vec4d", 32}, {"mat4s", 64}, {"mat4d", 128}};
  const auto it = sizes.find(type);
  return it == sizes.end() ? 0 : it->second;
}

std::string clip(const std::string& s) {
  std::string out;
  for (char c : s.substr(0, 60)) out += (c >= 32 && c < 127) ? c : '?';
  return s.size() > 60 ? out + "..." : out;
}

void check_meta_map(Cursor& c, const VdbHeaderLimits& lim, const std::string& where) {
  const std::int64_t count = std::int32_t(c.uint(4, "a metadata count"));
  if (count < 0 || count > lim.max_metadata)
    throw Bad{where + " metadata count " + std::to_string(count) + " is outside [0, " +
              std::to_string(lim.max_metadata) + "]"};
  for (std::int64_t i = 0; i < count; ++i) {
    const std::string name = c.text(lim.max_name, "a metadata name");
    const std::string type = c.text(lim.max_name, "a metadata type name");
    const std::uint32_t size = std::uint32_t(c.uint(4, "a metadata size"));
    const int fixed = fixed_size(type);
    const std::string what = where + " metadata '" + clip(name) + "' (" + clip(type) + ")";
    if (fixed && size != std::uint32_t(fixed))
      throw Bad{what + " holds " + std::to_string(size) + " bytes; its type has " + std::to_string(fixed)};
    if (size > lim.max_value)
      throw Bad{what + " holds " + std::to_string(size) + " bytes (at most " + std::to_string(lim.max_value) + ")"};
    if (type == "bool") {
      c.need(1, "a metadata value");
      const unsigned char b = c.byte_at(c.pos());
      if (b > 1) throw Bad{what + " holds the byte " + std::to_string(b) + "; a bool is 0 or 1"};
    }
    c.skip(size, "a metadata value");
  }
}

// One grid's descriptor; returns the grid's end offset (0 when unknown).
std::int64_t check_descriptor(Cursor& c, std::uint32_t version, bool offsets, const VdbHeaderLimits& lim, int index,
                              VdbHeaderSummary& sum) {
  const std::string where = "grid " + std::to_string(index);
  const std::string name = c.text(lim.max_name, "a grid name");
  c.text(lim.max_name, "a grid type name");
  if (version >= 216) c.text(lim.max_name, "a grid instance parent name");
  const std::int64_t grid_pos = std::int64_t(c.uint(8, "a grid offset"));
  const std::int64_t block_pos = std::int64_t(c.uint(8, "a grid offset"));
  const std::int64_t end_pos = std::int64_t(c.uint(8, "a grid offset"));
  if (offsets) {
    if (!(c.pos() <= grid_pos && grid_pos <= block_pos && block_pos <= end_pos))
      throw Bad{where + " ('" + clip(name) + "') has offsets outside the file or out of order"};
    c.seek(end_pos, "a grid end offset");  // checks end_pos <= file size
    c.seek(grid_pos, "a grid offset");
  }
  if (version >= 222) {
    const std::uint64_t flags = c.uint(4, "a grid compression");
    if (flags > 7) throw Bad{where + " compression flags " + std::to_string(flags) + " are unknown"};
  }
  check_meta_map(c, lim, where + " ('" + clip(name) + "')");
  c.text(lim.max_name, "a transform type name");  // the transform follows the metadata
  ++sum.grids_checked;
  return offsets ? end_pos : 0;
}

}  // namespace

std::string check_vdb_bytes(const unsigned char* data, std::size_t size, std::int64_t file_size,
                            const VdbHeaderLimits& lim, VdbHeaderSummary* summary) {
  VdbHeaderSummary sum;
  if (std::int64_t(size) > file_size) size = std::size_t(file_size);
  Cursor c(data, size, file_size);
  try {
    if (c.uint(8, "the magic number") != 0x56444220u) return "not a VDB file (no VDB magic number)";
    sum.version = std::uint32_t(c.uint(4, "the file version"));
    if (sum.version < lim.min_version || sum.version > lim.max_version)
      return "file format version " + std::to_string(sum.version) + " is outside what this reader accepts [" +
             std::to_string(lim.min_version) + ", " + std::to_string(lim.max_version) + "]";
    c.skip(8, "the library version");
    const std::uint64_t offsets = c.uint(1, "the header");
    if (offsets > 1) return "the header's grid-offsets flag is " + std::to_string(offsets) + "; expected 0 or 1";
    sum.offsets = offsets == 1;
    if (sum.version < 222) c.skip(1, "the header");
    c.skip(36, "the file UUID");
    check_meta_map(c, lim, "file");
    sum.grids = std::int32_t(c.uint(4, "the grid count"));
    if (sum.grids < 0 || sum.grids > lim.max_grids)
      return "grid count " + std::to_string(sum.grids) + " is outside [0, " + std::to_string(lim.max_grids) + "]";
    for (int i = 0; i < sum.grids; ++i) {
      const std::int64_t end = check_descriptor(c, sum.version, sum.offsets, lim, i, sum);
      if (!sum.offsets) break;  // a stream: the next grid follows this one's tree
      c.seek(end, "a grid end offset");
    }
  } catch (const Bad& b) {
    return b.why;
  } catch (const PrefixEnd&) {
  }
  if (summary) *summary = sum;
  return "";
}

VdbHeaderSummary check_vdb_file(const std::string& path, const VdbHeaderLimits& lim, std::size_t prefix) {
  const std::string what = "cannot read '" + path + "': ";
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) throw IoError(what + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw IoError(what + (S_ISDIR(st.st_mode) ? "a directory" : "not a regular file") + ", not a VDB file");
  }
  const std::int64_t file = st.st_size;
  std::vector<unsigned char> buf(std::size_t(std::min<std::int64_t>(file, std::int64_t(prefix))));
  std::size_t got = 0;
  while (got < buf.size()) {
    const ssize_t n = ::read(fd, buf.data() + got, buf.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    got += std::size_t(n);
  }
  ::close(fd);
  VdbHeaderSummary sum;
  const std::string why = check_vdb_bytes(buf.data(), got, got < buf.size() ? std::int64_t(got) : file, lim, &sum);
  if (!why.empty()) throw IoError(what + why);
  return sum;
}

}  // namespace cgio
