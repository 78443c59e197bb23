#include "spec/json_text.h"

#include <fmt/format.h>

#include <cctype>
#include <fstream>
#include <functional>
#include <optional>
#include <map>
#include <set>
#include <sstream>
#include <vector>

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

/// A JSON pointer token: '~' as "~0", '/' as "~1" (RFC 6901).
std::string pointer_token(const std::string& key) {
  std::string t;
  for (char c : key) t += c == '~' ? "~0" : c == '/' ? "~1" : std::string(1, c);
  return t;
}

/// Offset of the n-th (1-based) occurrence of "key" followed by a colon (an object key), or npos.
std::size_t key_occurrence_at(const std::string& text, const std::string& key, int n) {
  const std::string quoted = nlohmann::json(key).dump();
  for (std::size_t at = text.find(quoted); at != std::string::npos; at = text.find(quoted, at + 1)) {
    std::size_t k = at + quoted.size();
    while (k < text.size() && std::isspace(static_cast<unsigned char>(text[k]))) ++k;
    if (k < text.size() && text[k] == ':' && --n == 0) return at;
  }
  return std::string::npos;
}

/// Watches nlohmann's parse events for a key given twice in one object; the first one found.
class DuplicateKeys {
 public:
  bool operator()(int /*depth*/, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
    using E = nlohmann::json::parse_event_t;
    switch (event) {
      case E::object_start:
        frames_.push_back({true, {}, {}, 0});
        break;
      case E::array_start:
        frames_.push_back({false, {}, {}, 0});
        break;
      case E::key: {
        auto& f = frames_.back();
        f.key = parsed.get<std::string>();
        ++seen_[f.key];
        if (!f.keys.insert(f.key).second && !duplicate_)
          duplicate_ = Found{path() + "/" + pointer_token(f.key), f.key, seen_[f.key]};
        break;
      }
      case E::object_end:
      case E::array_end:
        frames_.pop_back();
        next_element();
        break;
      case E::value:
        next_element();
        break;
    }
    return true;
  }
  struct Found {
    std::string pointer, key;
    int occurrence = 0;  ///< of this key name in the whole text (to find its line)
  };
  [[nodiscard]] const std::optional<Found>& found() const { return duplicate_; }

 private:
  struct Frame {
    bool object;
    std::set<std::string> keys;
    std::string key;    ///< object: the current member's key
    std::size_t index;  ///< array: the current element's index
  };
  void next_element() {
    if (!frames_.empty() && !frames_.back().object) ++frames_.back().index;
  }
  [[nodiscard]] std::string path() const {
    std::string p;
    for (std::size_t i = 0; i + 1 < frames_.size(); ++i)
      p += "/" + (frames_[i].object ? pointer_token(frames_[i].key) : std::to_string(frames_[i].index));
    return p;
  }
  std::vector<Frame> frames_;
  std::map<std::string, int> seen_;
  std::optional<Found> duplicate_;
};

}  // namespace

std::string JsonTextError::where() const { return fmt::format("line {}, column {}", line, column); }

std::optional<JsonTextError> parse_json_text(const std::string& text, nlohmann::json& out, std::size_t max_depth) {
  if (const std::size_t deep = too_deep_at(text, max_depth); deep != std::string::npos)
    return at_offset(text, deep, fmt::format("arrays and objects nested deeper than {} levels", max_depth));
  DuplicateKeys duplicates;
  try {
    out = nlohmann::json::parse(text, std::ref(duplicates));
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
  if (const auto& d = duplicates.found()) {
    const std::size_t at = key_occurrence_at(text, d->key, d->occurrence);
    JsonTextError e = at_offset(text, at == std::string::npos ? 0 : at,
                                fmt::format("the key \"{}\" given twice in one object (a parser would keep one "
                                            "silently)",
                                            d->key));
    e.pointer = d->pointer;
    return e;
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
