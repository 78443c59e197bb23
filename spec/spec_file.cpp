// Reading a spec file: the one way (spec/schemas.h).
#include <fmt/format.h>

#include "spec/json_text.h"
#include "spec/schemas.h"

namespace gravsweep::spec {

const char* file_kind(Schema which) {
  switch (which) {
    case Schema::scenario:
      return "scenario file";
    case Schema::sweep:
      return "sweep spec file";
    case Schema::model:
      return "model spec file";
  }
  return "spec file";
}

namespace {

[[noreturn]] void fail(Schema which, std::string source, std::string found, std::string expected,
                       std::string pointer = {}) {
  std::vector<SpecProblem> problems{{std::move(pointer), std::move(found), std::move(expected)}};
  if (which == Schema::sweep) throw SpecError::sweep_spec(std::move(source), std::move(problems));
  throw SpecError(std::move(source), std::move(problems));
}

}  // namespace

nlohmann::json parse_spec_text(const std::string& text, const std::string& source, Schema which) {
  nlohmann::json doc;
  if (const auto err = parse_json_text(text, doc))
    fail(which, fmt::format("{}:{}:{}", source, err->line, err->column), err->what,
         err->pointer.empty() ? "valid JSON" : "valid JSON, each key once in an object", err->pointer);
  return doc;
}

nlohmann::json read_spec_file(const std::filesystem::path& path, Schema which) {
  std::string why;
  const auto text = read_text_file(path, why);
  if (!text) fail(which, path.string(), why, fmt::format("a readable {}", file_kind(which)));
  return parse_spec_text(*text, path.string(), which);
}

}  // namespace gravsweep::spec
