#include "spec/json_text.h"

#include <fmt/format.h>

#include <fstream>
#include <sstream>

namespace gravsweep::spec {

namespace {

JsonTextError at_offset(const std::string& text, std::size_t offset, std::string what) {
  JsonTextError e{1, 1, std::move(what)};
  for (std::size_t i = 0; i < offset && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++e.line;
      e.column = 1;
    } else {
      ++e.column;
    }
  }
  return e;
}

/// Offset of the first bracket nested deeper than max_depth (outside strings), or npos.
std::size_t too_deep_at(const std::string& text, std::size_t max_depth) {
  std::size_t depth = 0;
  bool in_string = false, escaped = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth) return i;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return std::string::npos;
}

}  // namespace

std::string JsonTextError::where() const { return fmt::format("line {}, column {}", line, column); }

std::optional<JsonTextError> parse_json_text(const std::string& text, nlohmann::json& out, std::size_t max_depth) {
  if (const std::size_t deep = too_deep_at(text, max_depth); deep != std::string::npos)
    return at_offset(text, deep, fmt::format("arrays and objects nested deeper than {} levels", max_depth));
  try {
    out = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    return at_offset(text, e.byte > 0 ? e.byte - 1 : 0, fmt::format("a JSON syntax error ({})", e.what()));
  } catch (const nlohmann::json::exception& e) {
    // A number beyond the range of a double (1e999): the message quotes it; find it in the text.
    const std::string msg = e.what();
    const auto a = msg.find('\''), b = msg.rfind('\'');
    const std::string token = a != std::string::npos && b > a ? msg.substr(a + 1, b - a - 1) : std::string();
    const std::size_t at = token.empty() ? std::string::npos : text.find(token);
    return at_offset(
        text, at == std::string::npos ? 0 : at,
        fmt::format("a number beyond the range of a double{} ({})", token.empty() ? "" : " (" + token + ")", msg));
  }
  return std::nullopt;
}

std::optional<std::string> read_text_file(const std::filesystem::path& path, std::string& why) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    why = "a folder, not a file";
    return std::nullopt;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    why = "no readable file";
    return std::nullopt;
  }
  std::stringstream ss;
  ss << in.rdbuf();
  if (in.bad()) {
    why = "a read error";
    return std::nullopt;
  }
  return ss.str();
}

}  // namespace gravsweep::spec
