// cloudgen/sequence.h — per-frame parameter files (`cloudgen bake --sequence`).
//
// A sequence file is one JSON object:
//   {"fps": F (optional, informational, a number in (0, 1000]),
//    "frames": [{"frame": N, "params": {...a parameter file's object...}}, ...]}
// Frame numbers are integers in [0, kMaxFrameNumber], each listed once; at
// most kMaxSequenceFrames frames; no other keys, at the top or in an entry.
// The file is parsed with the limits of kSequenceFileLimits (64 MiB, nesting
// depth 16, strings of 4096 bytes, duplicate keys refused).
#pragma once

#include <string_view>
#include <vector>

#include "cloudgen/params.h"

namespace cg {

inline constexpr long long kMaxFrameNumber = 1000000;
inline constexpr long long kMaxSequenceFrames = 100000;

struct SequenceFrame {
  long long frame;
  Params params;
};

// Throws ParamError naming `origin` and what is wrong (values shown briefly).
std::vector<SequenceFrame> parse_sequence(std::string_view text, std::string_view origin);

}  // namespace cg
