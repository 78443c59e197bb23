// Reading JSON text users wrote (sweep, scenario and model specs): bounded nesting depth, every error with
// its line and column, numbers out of double range, a key given twice in one object and unreadable
// files (a folder) refused.
#pragma once
#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <string>

namespace gravsweep::spec {

inline constexpr std::size_t kMaxJsonDepth = 64;  ///< arrays/objects nested deeper are refused

struct JsonTextError {
  std::size_t line = 0, column = 0;
  std::string what;                         ///< e.g. "nesting deeper than 64 levels", "number 1e999 out of range"
  std::string pointer;                      ///< the JSON pointer the error is about ("" = the document)
  [[nodiscard]] std::string where() const;  ///< "line L, column C"
};

/// Parses `text` into `out`; the error (line, column, what) when it is not acceptable JSON. A key
/// given twice in one object is an error at its second occurrence, with its JSON pointer: JSON
/// parsers keep one of the two silently (nlohmann's the last), so a spec would not say what it
/// seems to.
std::optional<JsonTextError> parse_json_text(const std::string& text, nlohmann::json& out,
                                             std::size_t max_depth = kMaxJsonDepth);

/// Reads a whole file; nullopt (and `why`) when it is missing, a folder or unreadable.
std::optional<std::string> read_text_file(const std::filesystem::path& path, std::string& why);

}  // namespace gravsweep::spec
