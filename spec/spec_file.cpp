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

nlohmann::json read_spec_file(const std::filesystem::path& path, Schema which) {
  auto fail = [&](std::string source, std::string found, std::string expected, std::string pointer = {}) {
    std::vector<SpecProblem> problems{{std::move(pointer), std::move(found), std::move(expected)}};
    if (which == Schema::sweep) throw SpecError::sweep_spec(std::move(source), std::move(problems));
    throw SpecError(std::move(source), std::move(problems));
  };
  std::string why;
  const auto text = read_text_file(path, why);
  if (!text) fail(path.string(), why, fmt::format("a readable {}", file_kind(which)));
  nlohmann::json doc;
  if (const auto err = parse_json_text(*text, doc))
    fail(fmt::format("{}:{}:{}", path.string(), err->line, err->column), err->what,
         err->pointer.empty() ? "valid JSON" : "valid JSON, each key once in an object", err->pointer);
  return doc;
}

}  // namespace gravsweep::spec
