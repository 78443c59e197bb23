#include <fmt/format.h>

#include <stdexcept>

#include "engine/core/registry.h"

#include "results/model/generated.h"
#include "results/model/term.h"

namespace gravsweep::results {

const std::vector<TermInfo>& term_registry() {
#define GRAVSWEEP_TERM_ROW(name) name##_term(),
  static const std::vector<TermInfo> terms{GRAVSWEEP_MODEL_TERMS(GRAVSWEEP_TERM_ROW)};
#undef GRAVSWEEP_TERM_ROW
  return terms;
}

const TermInfo& find_term(const std::string& name) {
  if (const TermInfo* t = find_row_or_null(term_registry(), name)) return *t;
  if (const TermInfo* g = generated_term(name)) return *g;
  throw unknown_name(term_registry(), name, "model term",
                     "; or a generated form such as z^1*v^1, exp(-z/0.01), (1-exp(-z/0.01)), v^2*exp(-z/0.02)");
}

}  // namespace gravsweep::results
