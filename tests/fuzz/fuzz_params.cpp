// fuzz_params.cpp — libFuzzer target: parameter files (cg::params_from_json).
// Any input must end in Params or a ParamError; never a crash, a sanitizer
// report, an unbounded allocation or an error message longer than ~1000 bytes.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "cloudgen/param_io.h"
#include "cloudgen/params.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const cg::Params p = cg::params_from_json(text, "fuzz");
    (void)cg::params_to_json(p);
  } catch (const cg::ParamError& e) {
    if (e.message.size() > 1000) std::abort();  // a bad value must be shown briefly
  }
  return 0;
}
