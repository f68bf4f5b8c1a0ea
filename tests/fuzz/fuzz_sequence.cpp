// fuzz_sequence.cpp — libFuzzer target: sequence files (cg::parse_sequence).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "cloudgen/params.h"
#include "cloudgen/sequence.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto frames = cg::parse_sequence(text, "fuzz");
    if (frames.empty() || std::ptrdiff_t(frames.size()) > cg::kMaxSequenceFrames) std::abort();
    for (const cg::SequenceFrame& f : frames)
      if (f.frame < 0 || f.frame > cg::kMaxFrameNumber) std::abort();
  } catch (const cg::ParamError& e) {
    if (e.message.size() > 1000) std::abort();
  }
  return 0;
}
