// Registries and set-up validation: unknown names and bad parameters are refused with messages
// that name the law/model and the parameter.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/system/law_registry.h"
#include "engine/core/error.h"
#include "engine/core/registry.h"
#include "engine/integrate/integrators.h"
#include "engine/system/force_loop.h"
#include "engine/contact/hertz_chrono.h"
#include "engine/contact/hooke_pkdgrav.h"
#include "engine/rolling/rolling_none.h"
#include "engine/rolling/rolling_sunday.h"
#include "engine/rolling/rolling_zhang.h"
#include "engine/scenario/paper_params.h"
#include "engine/system/system.h"

using namespace gravsweep;

namespace {
std::string init_error(SystemConfig cfg, double radius = 0.005) {
  System s(std::move(cfg));
  s.particles.add(Vec3::Zero(), radius, 1e-3, 0, SizeClass::grain);
  try {
    s.initialize();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Registry, ListsLawsModelsAndIntegrators) {
  EXPECT_EQ(contact_law_names(), (std::vector<std::string>{"hertz", "hooke"}));
  EXPECT_EQ(rolling_model_names(), (std::vector<std::string>{"none", "sunday", "zhang"}));
  EXPECT_EQ(integrator_table().size(), 3u);
  EXPECT_FALSE(contact_law_description("hertz").empty());
}

TEST(Registry, UnknownContactLawListsValidNames) {
  auto cfg = chrono_table1_config();
  cfg.contact_law = "hertzz";
  const std::string msg = init_error(cfg);
  EXPECT_NE(msg.find("unknown contact law 'hertzz'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("hertz, hooke"), std::string::npos) << msg;
}

TEST(Registry, UnknownRollingModelAndIntegrator) {
  auto cfg = chrono_table1_config();
  cfg.rolling_model = "spring";
  EXPECT_NE(init_error(cfg).find("valid rolling models: none, sunday, zhang"), std::string::npos);
  cfg = chrono_table1_config();
  cfg.integrator = "rk4";
  EXPECT_NE(init_error(cfg).find("valid integrators: semi_implicit_euler"), std::string::npos);
}

// Every table is looked up the same way (engine/core/registry.h): the row, or one message shape.
TEST(Registry, EveryTableIsLookedUpTheSameWay) {
  struct Row {
    const char* name;
    int value;
  };
  const std::vector<Row> rows{{"a", 1}, {"b", 2}};
  EXPECT_EQ(find_row(rows, "b", "thing").value, 2);
  EXPECT_EQ(find_row_or_null(rows, "c"), nullptr);
  try {
    (void)find_row(rows, "c", "thing", "; or d");
    ADD_FAILURE() << "an unknown name was found";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(), "unknown thing 'c'; valid things: a, b; or d");
  }
  EXPECT_EQ(&find_row(integrator_table(), "leapfrog_kdk", "integrator"), &integrator_table()[1]);
}

// The (law, rolling) table hands out the force loop of that very pair, for every pair.
TEST(Registry, EachLawAndRollingModelSelectsItsOwnForceLoop) {
  EXPECT_EQ(select_force_function("hertz", "none"), (&force_loop<HertzChrono, RollingNone>));
  EXPECT_EQ(select_force_function("hertz", "sunday"), (&force_loop<HertzChrono, RollingSunday>));
  EXPECT_EQ(select_force_function("hertz", "zhang"), (&force_loop<HertzChrono, RollingZhang>));
  EXPECT_EQ(select_force_function("hooke", "none"), (&force_loop<HookePkdgrav, RollingNone>));
  EXPECT_EQ(select_force_function("hooke", "sunday"), (&force_loop<HookePkdgrav, RollingSunday>));
  EXPECT_EQ(select_force_function("hooke", "zhang"), (&force_loop<HookePkdgrav, RollingZhang>));
  EXPECT_TRUE(uses_frame_history("hooke", "none"));
  EXPECT_TRUE(uses_frame_history("hertz", "zhang"));
  EXPECT_FALSE(uses_frame_history("hertz", "sunday"));
}

TEST(Validation, PoissonRatioOutsideRange) {
  auto cfg = chrono_table1_config();
  cfg.materials[0].poisson_ratio = 0.5;
  const std::string msg = init_error(cfg);
  EXPECT_NE(msg.find("material 'grain'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("poisson_ratio"), std::string::npos) << msg;
}

TEST(Validation, RestitutionAndModulus) {
  auto cfg = chrono_table1_config();
  cfg.materials[1].cor_normal = 1.2;
  EXPECT_NE(init_error(cfg).find("cor_normal"), std::string::npos);
  cfg = chrono_table1_config();
  cfg.materials[0].young_modulus_Pa = 0;
  EXPECT_NE(init_error(cfg).find("young_modulus_Pa"), std::string::npos);
  cfg = chrono_table1_config();
  cfg.materials[0].cor_normal = 0.0;
  EXPECT_NE(init_error(cfg).find("COR in (0, 1]"), std::string::npos);
}

TEST(Validation, HertzTimeStepAboveStabilityBound) {
  auto cfg = chrono_table1_config();
  cfg.dt_s = 5e-5;  // Rayleigh time of a 5 mm glass bead at 700 MPa is 50.8 us
  const std::string msg = init_error(cfg);
  EXPECT_NE(msg.find("contact law 'hertz'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("dt"), std::string::npos) << msg;
  cfg.dt_s = 1e-5;
  EXPECT_EQ(init_error(cfg), "");
}

TEST(Validation, HookeNeedsSpringAndStableStep) {
  auto cfg = chrono_table1_config();
  cfg.contact_law = "hooke";
  cfg.rolling_model = "zhang";
  std::string msg = init_error(cfg);
  EXPECT_NE(msg.find("contact law 'hooke': kn_N_m"), std::string::npos) << msg;
  for (auto& m : cfg.materials) m.kn_N_m = 7.48e5;
  cfg.dt_s = 5e-7;
  EXPECT_EQ(init_error(cfg), "");
  cfg.dt_s = 2e-5;  // grain-grain contact ~93 us -> bound 9.3 us
  msg = init_error(cfg);
  EXPECT_NE(msg.find("stability bound"), std::string::npos) << msg;
}

// With track_energy the force pass sums the normal spring energy: (8/15) E* sqrt(R*) d^2.5 for hertz.
TEST(Energy, HertzNormalSpringEnergyIsReported) {
  auto cfg = chrono_table1_config();
  cfg.gravity_m_s2 = Vec3::Zero();
  cfg.track_energy = true;
  System s(cfg);
  const double r = 0.005, d = 1e-5;
  s.particles.add(Vec3::Zero(), r, 1.3e-3, 0, SizeClass::grain);
  s.particles.add(Vec3(0, 0, 2 * r - d), r, 1.3e-3, 0, SizeClass::grain);
  s.compute_forces();
  const double E_eff = s.pair_table()(0, 0).E_eff_Pa;
  const double expect = 8.0 / 15.0 * E_eff * std::sqrt(r / 2) * std::pow(d, 2.5);
  EXPECT_NEAR(s.stats().elastic_energy_J, expect, 1e-9 * expect + 1e-18);
  EXPECT_GT(expect, 0);
}
