// `gravsweep model`: collision models as sums of named terms, compared with a measurement
// campaign. This file holds the parent verb and `model terms`; each other sub-verb has its own
// file, scheduler/cli/verb_model_<name>.cpp, sharing scheduler/cli/model_inputs.h.
#include <memory>
#include <string>

#include "results/model/model_spec.h"
#include "results/io/table.h"
#include "scheduler/cli/format_option.h"
#include "scheduler/cli/verbs.h"

namespace gravsweep::cli {

namespace {

/// `model terms`: the term registry (results/model/terms), one row a term.
void run_terms(const std::string& format) {
  results::Table t({"term", "parameters", "default_sharing", "meaning", "references"});
  for (const auto& r : results::term_registry()) {
    std::string p;
    for (const auto& x : r.params) p += (p.empty() ? "" : " ") + x;
    t.add({r.name, p, r.per_gravity ? "per_gravity" : "shared", r.meaning, r.references});
  }
  t.print(format);
}

}  // namespace

void setup_model(CLI::App& app) {
  auto* sub = app.add_subcommand("model",
                                 "Collision models m dv/dt = m g - R(z, v, g) as sums of named terms, compared with a\n"
                                 "measurement campaign. Run `gravsweep model terms` for the term library.");
  sub->require_subcommand(1);
  auto format = std::make_shared<std::string>("table");
  auto* terms = sub->add_subcommand("terms", "List the registered model terms.\n\nExample:\n  gravsweep model terms");
  add_format_option(terms, *format);
  terms->callback([format]() { run_terms(*format); });
  // The order of `gravsweep model --help`.
  setup_model_table3(*sub);
  setup_model_fit(*sub);
  setup_model_residuals(*sub);
  setup_model_check_detection(*sub);
  setup_model_rank(*sub);
  setup_model_collapse(*sub);
  setup_model_lolo(*sub);
  setup_model_scaling(*sub);
  setup_model_predict(*sub);
  setup_model_infer(*sub);
}

}  // namespace gravsweep::cli
