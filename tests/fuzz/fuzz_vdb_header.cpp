// fuzz_vdb_header.cpp — libFuzzer target: the VDB checks that run before
// OpenVDB sees a file (cgio::check_vdb_bytes). The whole input is the file;
// it is also checked as a prefix of a longer file (the reader's 16 MiB cut).
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "io/vdb_check.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const cgio::VdbHeaderLimits limits;
  cgio::VdbHeaderSummary sum;
  const std::string why = cgio::check_vdb_bytes(data, size, std::int64_t(size), limits, &sum);
  if (why.size() > 1000) std::abort();
  if (why.empty() && size >= 12 && (sum.version < limits.min_version || sum.version > limits.max_version))
    std::abort();  // accepted means a version OpenVDB 10 reads
  (void)cgio::check_vdb_bytes(data, size / 2, std::int64_t(size) * 4, limits, &sum);
  return 0;
}
