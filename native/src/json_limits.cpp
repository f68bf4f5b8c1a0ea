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

namespace {

// The limits, checked by a SAX pass that builds nothing: linear in the text. (nlohmann 3.11.2's
// callback parser rescans a container's elements at every object end — quadratic: a sequence
// file of 100,001 one-key frames took 4 s, and 150 s under the sanitizers, before its size check.)
class LimitsSax {
 public:
  LimitsSax(const std::string& origin, const JsonLimits& lim) : origin_(origin), lim_(lim) {}

  bool null() { return value(); }
  bool boolean(bool) { return value(); }
  bool number_integer(json::number_integer_t) { return value(); }
  bool number_unsigned(json::number_unsigned_t) { return value(); }
  bool number_float(json::number_float_t, const json::string_t&) { return value(); }
  bool string(json::string_t& s) {
    check_string(s, "string");
    return value();
  }
  bool binary(json::binary_t&) { return value(); }
  bool start_object(std::size_t) {
    open();
    keys_.emplace_back();
    return true;
  }
  bool key(json::string_t& k) {
    check_string(k, "key");
    if (!keys_.empty() && !keys_.back().insert(k).second)
      throw ParamError(origin_ + ": key \"" + brief_text(k, 60) + "\" appears twice in one object");
    return true;
  }
  bool end_object() {
    keys_.pop_back();
    --depth_;
    return value();
  }
  bool start_array(std::size_t) {
    open();
    return true;
  }
  bool end_array() {
    --depth_;
    return value();
  }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception& e) {
    // syntax errors, and numbers out of range such as 1e999
    throw ParamError(origin_ + ": not valid JSON (" + brief_text(json_error_text(e.what()), 160) + ")");
  }

 private:
  void open() {
    if (++depth_ > lim_.max_depth)
      throw ParamError(origin_ + ": nested deeper than " + std::to_string(lim_.max_depth) + " levels");
  }
  bool value() {
    if (++values_ > lim_.max_values)
      throw ParamError(origin_ + ": more than " + std::to_string(lim_.max_values) + " values");
    return true;
  }
  void check_string(const std::string& s, const char* what) const {
    if (s.size() > lim_.max_string)
      throw ParamError(origin_ + ": a " + what + " of " + std::to_string(s.size()) + " bytes (at most " +
                       std::to_string(lim_.max_string) + "): \"" + brief_text(s, 40) + "\"");
  }

  const std::string& origin_;
  const JsonLimits& lim_;
  int depth_ = 0;
  std::size_t values_ = 0;
  std::vector<std::set<std::string>> keys_;  // per open object: the keys seen
};

}  // namespace

json parse_json_limited(std::string_view text, const std::string& origin, const JsonLimits& lim) {
  if (text.size() > lim.max_bytes)
    throw ParamError(origin + ": the file is " + std::to_string(text.size()) + " bytes; at most " +
                     std::to_string(lim.max_bytes) + " are read");
  LimitsSax limits(origin, lim);
  json::sax_parse(text.begin(), text.end(), &limits);  // throws ParamError on any limit or syntax error
  try {
    return json::parse(text.begin(), text.end());  // within every limit now: the DOM, in one linear pass
  } catch (const json::exception& e) {
    throw ParamError(origin + ": not valid JSON (" + brief_text(json_error_text(e.what()), 160) + ")");
  }
}

}  // namespace cg
