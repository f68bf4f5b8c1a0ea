// names.cpp — case-insensitive names and "did you mean" (see names.h).
#include "cloudgen/names.h"

#include <algorithm>
#include <cctype>
#include <cstring>

namespace cg {

namespace {

char lower(char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); }

// Levenshtein distance ignoring case; the inputs are names (short), the known lists small.
std::size_t distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

}  // namespace

bool same_name(std::string_view a, std::string_view b) {
  return a.size() == b.size() &&
         std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) { return lower(x) == lower(y); });
}

std::optional<std::string> closest_name(std::string_view typed, const std::vector<std::string>& known) {
  if (typed.size() > 200) return std::nullopt;  // a name, not a document
  const std::size_t limit = std::max<std::size_t>(1, typed.size() / 3);
  std::optional<std::string> best;
  std::size_t best_distance = limit + 1;
  for (const std::string& name : known) {
    const std::size_t d = distance(typed, name);
    if (d < best_distance) best = name, best_distance = d;
  }
  return best;
}

std::string did_you_mean(std::string_view typed, const std::vector<std::string>& known) {
  const auto best = closest_name(typed, known);
  return best ? "; did you mean '" + *best + "'?" : std::string();
}

std::string json_error_text(const char* what) {
  const char* text = what;
  if (std::strncmp(text, "[json.exception.", 16) == 0)
    if (const char* end = std::strchr(text, ']')) text = end + 1 + (end[1] == ' ' ? 1 : 0);
  return text;
}

}  // namespace cg
