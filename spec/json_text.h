// Reading JSON text users wrote (sweep, scenario and model specs): bounded nesting depth, every error with
// its line and column, numbers out of double range and unreadable files (a folder) refused.
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
  [[nodiscard]] std::string where() const;  ///< "line L, column C"
};

/// Parses `text` into `out`; the error (line, column, what) when it is not acceptable JSON.
std::optional<JsonTextError> parse_json_text(const std::string& text, nlohmann::json& out,
                                             std::size_t max_depth = kMaxJsonDepth);

/// Reads a whole file; nullopt (and `why`) when it is missing, a folder or unreadable.
std::optional<std::string> read_text_file(const std::filesystem::path& path, std::string& why);

}  // namespace gravsweep::spec
