#include <fmt/format.h>

#include <algorithm>

#include <map>
#include <memory>
#include <mutex>
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

namespace {

/// "term.param": the one parameter `param` of a registered term with several, as a term of its own
/// (the scaling check frees one constant of a law at a time; a model may give one constant of a
/// term its own sharing, e.g. scaled_base.phi+scaled_base.inv_d1_1_m:g^0.2). Null when `name` is
/// not of that form.
const TermInfo* parameter_term(const std::string& name) {
  const auto dot = name.find('.');
  if (dot == std::string::npos) return nullptr;
  const TermInfo* parent = find_row_or_null(term_registry(), name.substr(0, dot));
  if (parent == nullptr || parent->params.size() < 2) return nullptr;
  const std::string param = name.substr(dot + 1);
  const auto it = std::find(parent->params.begin(), parent->params.end(), param);
  if (it == parent->params.end()) return nullptr;
  const auto j = static_cast<std::size_t>(it - parent->params.begin());
  static std::mutex mutex;
  static std::map<std::string, std::unique_ptr<TermInfo>> built;  // stable addresses for ModelTerm
  const std::lock_guard<std::mutex> lock(mutex);
  auto& slot = built[name];
  if (slot) return slot.get();
  slot = std::make_unique<TermInfo>(*parent);
  TermInfo& t = *slot;
  t.name = name;
  t.meaning = fmt::format("the parameter {} of {} alone: {}", param, parent->name, parent->meaning);
  t.params = {param};
  const auto features = parent->features;
  const std::size_t n = parent->params.size();
  t.features = [features, j, n](const TermContext& c, double* out) {
    double all[8];
    if (n > 8) throw std::logic_error("a model term with more than 8 parameters");
    features(c, all);
    out[0] = all[j];
  };
  if (parent->typical) {
    const auto typical = parent->typical;
    t.typical = [typical, j](double g, double m, double d) { return std::vector<double>{typical(g, m, d)[j]}; };
  }
  return slot.get();
}

}  // namespace

const TermInfo& find_term(const std::string& name) {
  if (const TermInfo* t = find_row_or_null(term_registry(), name)) return *t;
  if (const TermInfo* p = parameter_term(name)) return *p;
  if (const TermInfo* g = generated_term(name)) return *g;
  throw unknown_name(term_registry(), name, "model term",
                     "; or one parameter of a term (scaled_base.inv_d1_1_m); or a generated form such as z^1*v^1, "
                     "exp(-z/0.01), (1-exp(-z/0.01)), v^2*exp(-z/0.02)");
}

}  // namespace gravsweep::results
