// json_limits.h — JSON from files we did not write: parsed with limits, shown briefly.
//
// Every parameter, camera and sequence file goes through parse_json_limited:
// the text size, the nesting depth (checked by a SAX pass before any document
// is built, so a deep value never reaches the JSON library's recursive dump()
// or destructor; both passes are linear in the text), string
// lengths and the number of values are bounded, and duplicate keys are refused
// (nlohmann keeps the last one silently). brief() renders a value for an
// error message in at most ~100 characters.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace cg {

struct JsonLimits {
  std::size_t max_bytes;   // the whole text
  int max_depth;           // nested arrays/objects; the top-level object is depth 1
  std::size_t max_string;  // bytes in one string or key
  std::size_t max_values;  // values of any kind in the document
};

// Parameter and camera files: 1 MiB, depth 16, 4096-byte strings, 100,000 values.
inline constexpr JsonLimits kSmallFileLimits{1u << 20, 16, 4096, 100000};
// Sequence files: 64 MiB, depth 16, 4096-byte strings, 4,000,000 values.
inline constexpr JsonLimits kSequenceFileLimits{64u << 20, 16, 4096, 4000000};

// Parses `text`; throws ParamError("<origin>: ...") naming the limit passed or
// the JSON error (its message clipped).
nlohmann::json parse_json_limited(std::string_view text, const std::string& origin, const JsonLimits& limits);

// At most `max_chars` characters of `v` as JSON (then "..."); never recursive
// beyond the depth parse_json_limited allows.
std::string brief(const nlohmann::json& v, std::size_t max_chars = 100);
// At most `max_chars` characters of `s`, control characters as '?', then "...".
std::string brief_text(std::string_view s, std::size_t max_chars = 100);

// The parameters of an already parsed (and limited) JSON object, as
// params_from_json (param_io.cpp); used for the frames of a sequence file.
struct Params;
Params params_from_value(const nlohmann::json& value, std::string_view origin);

}  // namespace cg
