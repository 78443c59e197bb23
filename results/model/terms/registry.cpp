#include <fmt/format.h>

#include <stdexcept>

#include "results/model/term.h"

namespace gravsweep::results {

const std::vector<TermInfo>& term_registry() {
#define GRAVSWEEP_TERM_ROW(name) name##_term(),
  static const std::vector<TermInfo> terms{GRAVSWEEP_MODEL_TERMS(GRAVSWEEP_TERM_ROW)};
#undef GRAVSWEEP_TERM_ROW
  return terms;
}

const TermInfo& find_term(const std::string& name) {
  std::string known;
  for (const auto& t : term_registry()) {
    if (t.name == name) return t;
    known += (known.empty() ? "" : ", ") + t.name;
  }
  throw std::invalid_argument(fmt::format("unknown model term '{}' (known: {})", name, known));
}

}  // namespace gravsweep::results
