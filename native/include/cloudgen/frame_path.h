// cloudgen/frame_path.h — the name of a sequence frame's file.
//
// One function for the CLI and the Python module (cloudgen_native.frame_path),
// so that nothing else in the project names frame files (docs/cli_protocol.md).
#pragma once

#include <string>
#include <string_view>

namespace cg {

// The file of `frame` for the output pattern `pattern`: the LAST run of '#' in
// the pattern becomes the frame number, zero-padded to the run's length (a
// longer number is written whole: frame 12345 in `f_##.vdb` is `f_12345.vdb`);
// with no '#', "_NNNN" (at least 4 digits) goes before the extension of the
// last path component (at the end when it has none). Negative frames keep
// their sign in front of the padding ("-007"). Any run length is allowed.
std::string frame_path(std::string_view pattern, long long frame);

}  // namespace cg
