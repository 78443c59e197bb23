// `gravsweep model table3`: the paper's method (Sunday et al. 2021 Sect. 4, Table 3), per gravity
// level: Eq. 2 fitted to apeak(vc), vt (Eq. 5) and alpha (zstop ~ H^alpha) with their errors.
#include <fmt/format.h>

#include <memory>
#include <string>

#include "results/model/table3.h"
#include "results/io/table.h"
#include "scheduler/cli/model_inputs.h"
#include "scheduler/cli/verbs.h"

namespace gravsweep::cli {

namespace {

using results::num;

void run_table3(const ModelInputs& o) {
  const auto c = load_model_campaign(o);
  results::Table t({"gravity_m_s2", "trials", "f0_N", "f0_se_N", "f0_boot_se_N", "inv_d1_1_m", "inv_d1_se_1_m",
                    "inv_d1_boot_se_1_m", "vt_m_s", "vt_se_m_s", "alpha", "alpha_se", "note"});
  for (const auto& r : results::table3(c))
    t.add({num(r.g_m_s2), std::to_string(r.trials), num(r.f0_N, 3), num(r.f0_se_N, 2), num(r.f0_boot_se_N, 2),
           num(r.inv_d1_1_m, 3), num(r.inv_d1_se_1_m, 2), num(r.inv_d1_boot_se_1_m, 2), num(r.vt_m_s, 3),
           num(r.vt_se_m_s, 2), num(r.alpha, 3), num(r.alpha_se, 2), r.note});
  t.print(o.format);
}

}  // namespace

void setup_model_table3(CLI::App& model) {
  auto o = std::make_shared<ModelInputs>();
  auto* sub = model.add_subcommand(
      "table3",
      "The paper's method (Sunday et al. 2021 Sect. 4): per gravity level fit Eq. 2 to apeak(vc),\n"
      "print f0, 1/d1, vt (Eq. 5) and alpha (zstop ~ H^alpha) with standard errors, as Table 3,\n"
      "and bootstrap errors of f0 and 1/d1 over whole drops (*_boot_se_*: they include the\n"
      "scatter between impact sites, which the least-squares errors understate when sites repeat).\n\n"
      "Examples:\n  gravsweep model table3 ../shared/data/measurements/depth-friction-dev\n"
      "  gravsweep model table3 campaign.db --where 'impact_speed_m_s>=0.5'");
  add_model_inputs(sub, *o)->callback([o]() { run_table3(*o); });
}

}  // namespace gravsweep::cli
