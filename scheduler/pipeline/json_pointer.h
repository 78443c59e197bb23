// JSON pointers (RFC 6901) as the spec validators and canonical_json() write them in messages.
// The one place a reference token is escaped; no dependency on the rest of the scheduler, so
// scheduler/pipeline and scheduler/sweep both include it.
#pragma once
#include <string>
#include <string_view>

namespace gravsweep::pipeline {

/// One reference token escaped (RFC 6901 Sect. 3): '~' -> "~0", '/' -> "~1".
inline std::string pointer_token(std::string_view key) {
  std::string out;
  out.reserve(key.size());
  for (char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

/// The pointer of member `key` of the value at `parent` ("" = the document): parent/key, escaped.
inline std::string pointer_child(const std::string& parent, std::string_view key) {
  return parent + "/" + pointer_token(key);
}

}  // namespace gravsweep::pipeline
