// cloudgen/names.h — matching what a person typed against the names we know.
//
// Preset, tier, parameter, option and command names are matched here, so every
// front end (CLI, module, add-on through the module) is as forgiving as the
// others: case does not matter where a name is a word ("Cumulus" is the preset
// cumulus), and an unknown name gets a "did you mean" from the known ones.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cg {

// Equal ignoring ASCII case ("Cumulus" == "cumulus").
bool same_name(std::string_view a, std::string_view b);

// The known name closest to `typed` (edit distance ignoring case, at most a
// third of its length and at least 1), or nullopt when none is that close.
std::optional<std::string> closest_name(std::string_view typed, const std::vector<std::string>& known);

// "; did you mean 'density'?" for closest_name, else "".
std::string did_you_mean(std::string_view typed, const std::vector<std::string>& known);

// A message of nlohmann::json without its "[json.exception.parse_error.101] " tag.
std::string json_error_text(const char* what);

}  // namespace cg
