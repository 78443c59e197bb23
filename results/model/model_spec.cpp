// Model specs: parsing "base+depth_friction" and model files (see model_spec.h).
#include "results/model/model_spec.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "engine/core/error.h"
#include "spec/problems.h"
#include "spec/schemas.h"

namespace gravsweep::results {

// ---------------------------------------------------------------------------------------------
// Specs

std::string ModelSpec::name() const {
  std::string s;
  for (const auto& t : terms) {
    if (!s.empty()) s += "+";
    s += t.term->name;
    if (t.g_scaled())
      s += fmt::format(":g^{:g}", t.g_power);
    else if (t.per_gravity != t.term->per_gravity)
      s += t.per_gravity ? ":per_gravity" : ":shared";
  }
  return s;
}

bool ModelSpec::has(const std::string& term_name) const {
  return std::any_of(terms.begin(), terms.end(), [&](const ModelTerm& t) { return t.term->name == term_name; });
}

bool one_law_for_all_levels(const ModelSpec& spec) {
  return std::none_of(spec.terms.begin(), spec.terms.end(), [](const ModelTerm& t) { return t.per_gravity; });
}

namespace {

/// The terms of a model file (schemas/model.schema.json, checked by spec/schemas.h; then each name
/// looked up: a generated form's numbers must be in range). Throws spec::SpecError naming the file
/// and the JSON pointer of every problem.
std::vector<ModelTerm> model_file_terms(const std::string& file) {
  nlohmann::json j = spec::read_spec_file(file, spec::Schema::model);
  spec::Problems problems;
  spec::validator(spec::Schema::model).collect(j, problems.list());
  if (!problems.empty()) throw spec::SpecError(file, std::move(problems.list()));
  std::vector<ModelTerm> terms;
  for (std::size_t i = 0; i < j["terms"].size(); ++i) {
    const auto& e = j["terms"][i];
    const std::string name = e["name"].get<std::string>();
    ModelTerm mt;
    try {
      mt.term = &find_term(name);
    } catch (const ConfigError& ex) {
      problems.add(fmt::format("/terms/{}/name", i), e["name"], ex.what());
      continue;
    }
    mt.per_gravity = e.contains("shared") ? !e["shared"].get<bool>() : mt.term->per_gravity;
    if (e.contains("g_power")) {
      mt.g_power = e["g_power"].get<double>();
      mt.per_gravity = false;
    }
    mt.scale = e.value("scale", 1.0);
    terms.push_back(mt);
  }
  if (!problems.empty()) throw spec::SpecError(file, std::move(problems.list()));
  return terms;
}

/// ":g^p": one constant for all levels times (g / kGPowerReference_m_s2)^p.
void set_g_power(ModelTerm& mt, const std::string& mode, const std::string& text) {
  const std::string p = mode.substr(2);
  char* end = nullptr;
  const double x = std::strtod(p.c_str(), &end);
  if (p.empty() || end != p.c_str() + p.size() || !std::isfinite(x) || std::abs(x) > 4)
    throw std::invalid_argument(
        fmt::format("model '{}': '{}' after ':' must be g^<power> with a power between -4 and 4", text, mode));
  mt.g_power = x;
  mt.per_gravity = false;
}

}  // namespace

ModelSpec parse_model(const std::string& text) {
  ModelSpec spec;
  if (std::filesystem::exists(text) && std::filesystem::is_regular_file(text)) {
    spec.terms = model_file_terms(text);
  } else {
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, '+')) {
      if (item.empty()) continue;
      ModelTerm mt;
      std::string name = item;
      double scale = 1.0;
      // "*2.5" after a term is a synth scale; a '*' inside a generated form ("z^1*v^1") is not.
      if (auto p = name.rfind('*'); p != std::string::npos) {
        const std::string tail = name.substr(p + 1);
        char* end = nullptr;
        const double x = std::strtod(tail.c_str(), &end);
        if (!tail.empty() && end == tail.c_str() + tail.size()) {
          scale = x;
          name = name.substr(0, p);
        }
      }
      std::string mode;
      if (auto p = name.find(':'); p != std::string::npos) {
        mode = name.substr(p + 1);
        name = name.substr(0, p);
      }
      mt.term = &find_term(name);
      mt.per_gravity = mt.term->per_gravity;
      if (mode == "shared")
        mt.per_gravity = false;
      else if (mode == "per_gravity")
        mt.per_gravity = true;
      else if (mode.rfind("g^", 0) == 0)
        set_g_power(mt, mode, text);
      else if (!mode.empty())
        throw std::invalid_argument(fmt::format(
            "model '{}': '{}' after ':' must be shared, per_gravity or g^<power> (e.g. g^0.3)", text, mode));
      mt.scale = scale;
      spec.terms.push_back(mt);
    }
  }
  if (spec.terms.empty())
    throw std::invalid_argument(fmt::format("model '{}': no terms (example: base+depth_friction)", text));
  return spec;
}

}  // namespace gravsweep::results
