// JSON pointers (RFC 6901) as the spec validator (spec/json_schema.h), the sweep and model spec
// checks and canonical_json() write them in messages: the one place a reference token is escaped.
#pragma once
#include <string>
#include <string_view>

namespace gravsweep::spec {

/// One reference token escaped (RFC 6901 Sect. 3): '~' -> "~0", '/' -> "~1".
inline std::string pointer_token(std::string_view key) {
  std::string out;
  out.reserve(key.size());
  for (char c : key) {
    if (c == '~')
      out += "~0";
    else if (c == '/')
      out += "~1";
    else
      out += c;
  }
  return out;
}

/// The pointer of member `key` of the value at `parent` ("" = the document): parent/key, escaped.
inline std::string pointer_child(const std::string& parent, std::string_view key) {
  return parent + "/" + pointer_token(key);
}

}  // namespace gravsweep::spec
