// frame_path.cpp — sequence frame file names (see frame_path.h).
#include "cloudgen/frame_path.h"

#include <cstddef>

namespace cg {

namespace {

// |frame| in decimal, zero-padded to `width` digits, the sign in front.
std::string padded(long long frame, std::size_t width) {
  // magnitude as unsigned: -LLONG_MIN does not fit a long long
  unsigned long long mag =
      frame < 0 ? 0ull - static_cast<unsigned long long>(frame) : static_cast<unsigned long long>(frame);
  std::string digits;
  do {
    digits.insert(digits.begin(), static_cast<char>('0' + mag % 10));
    mag /= 10;
  } while (mag != 0);
  if (digits.size() < width) digits.insert(0, width - digits.size(), '0');
  return frame < 0 ? "-" + digits : digits;
}

}  // namespace

std::string frame_path(std::string_view pattern, long long frame) {
  const std::size_t last = pattern.find_last_of('#');
  if (last != std::string_view::npos) {
    std::size_t first = last;
    while (first > 0 && pattern[first - 1] == '#') --first;
    std::string out(pattern.substr(0, first));
    out += padded(frame, last - first + 1);
    out += pattern.substr(last + 1);
    return out;
  }
  const std::size_t slash = pattern.find_last_of('/');
  const std::size_t name = slash == std::string_view::npos ? 0 : slash + 1;
  std::size_t dot = pattern.find_last_of('.');
  // no extension: a dot only in a folder name, or a leading dot (".vdb" is a name)
  if (dot == std::string_view::npos || dot <= name) dot = pattern.size();
  std::string out(pattern.substr(0, dot));
  out += "_" + padded(frame, 4);
  out += pattern.substr(dot);
  return out;
}

}  // namespace cg
