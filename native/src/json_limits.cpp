// json_limits.cpp — limited JSON parsing and brief values for messages.
#include "json_limits.h"

#include "cloudgen/names.h"

#include <set>
#include <vector>

#include "cloudgen/params.h"

namespace cg {

using nlohmann::json;

std::string brief_text(std::string_view s, std::size_t max_chars) {
  std::string out;
  for (std::size_t i = 0; i < s.size() && out.size() < max_chars; ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    out += c < 32 || c == 127 ? '?' : char(c);
  }
  return out.size() < s.size() ? out + "..." : out;
}

namespace {

// Appends v to out until out holds `max` characters.
void brief_into(const json& v, std::string& out, std::size_t max, int depth) {
  if (out.size() >= max) return;
  if (v.is_array() || v.is_object()) {
    if (depth > 32) {
      out += "...";
      return;
    }
    out += v.is_array() ? '[' : '{';
    bool first = true;
    for (auto it = v.begin(); it != v.end() && out.size() < max; ++it) {
      out += first ? "" : ",";
      first = false;
      if (v.is_object()) out += json(brief_text(it.key(), 40)).dump() + ":";
      brief_into(*it, out, max, depth + 1);
    }
    out += v.is_array() ? ']' : '}';
  } else if (v.is_string()) {
    out += json(brief_text(v.get_ref<const std::string&>(), max)).dump(-1, ' ', false, json::error_handler_t::replace);
  } else {
    out += v.dump();
  }
}

}  // namespace

std::string brief(const json& v, std::size_t max_chars) {
  std::string out;
  brief_into(v, out, max_chars, 0);
  return out.size() > max_chars ? out.substr(0, max_chars) + "..." : out;
}

json parse_json_limited(std::string_view text, const std::string& origin, const JsonLimits& lim) {
  if (text.size() > lim.max_bytes)
    throw ParamError(origin + ": the file is " + std::to_string(text.size()) + " bytes; at most " +
                     std::to_string(lim.max_bytes) + " are read");
  int depth = 0;
  std::size_t values = 0;
  std::vector<std::set<std::string>> keys;  // per open object: the keys seen
  auto check_string = [&](const std::string& s, const char* what) {
    if (s.size() > lim.max_string)
      throw ParamError(origin + ": a " + what + " of " + std::to_string(s.size()) + " bytes (at most " +
                       std::to_string(lim.max_string) + "): \"" + brief_text(s, 40) + "\"");
  };
  auto callback = [&](int, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
      case json::parse_event_t::array_start:
        if (++depth > lim.max_depth)
          throw ParamError(origin + ": nested deeper than " + std::to_string(lim.max_depth) + " levels");
        if (event == json::parse_event_t::object_start) keys.emplace_back();
        break;
      case json::parse_event_t::object_end:
        keys.pop_back();
        [[fallthrough]];
      case json::parse_event_t::array_end:
        --depth;
        [[fallthrough]];
      case json::parse_event_t::value:
        if (++values > lim.max_values)
          throw ParamError(origin + ": more than " + std::to_string(lim.max_values) + " values");
        if (parsed.is_string()) check_string(parsed.get_ref<const std::string&>(), "string");
        break;
      case json::parse_event_t::key: {
        const std::string& k = parsed.get_ref<const std::string&>();
        check_string(k, "key");
        if (!keys.empty() && !keys.back().insert(k).second)
          throw ParamError(origin + ": key \"" + brief_text(k, 60) + "\" appears twice in one object");
        break;
      }
    }
    return true;
  };
  try {
    return json::parse(text.begin(), text.end(), callback);
  } catch (const json::exception& e) {  // parse errors, and numbers out of range such as 1e999
    throw ParamError(origin + ": not valid JSON (" + brief_text(json_error_text(e.what()), 160) + ")");
  }
}

}  // namespace cg
