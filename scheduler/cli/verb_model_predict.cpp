// `gravsweep model predict`: a saved gravity-scaled law (results/model/law.h) applied to cases of
// one's own (a gravity, an impact speed, a projectile diameter and mass): zstop, tstop and apeak
// with 95 % intervals, the Froude number, and whether each case lies inside the law's fitted
// ranges, just outside them (extrapolated, with a warning) or far beyond (refused, exit 2, unless
// --extrapolate).
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "engine/core/error.h"
#include "results/io/csv.h"
#include "results/io/table.h"
#include "results/model/law.h"
#include "results/report/figures.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/format_option.h"
#include "scheduler/cli/verbs.h"

namespace gravsweep::cli {

namespace {

using results::num;

struct PredictOptions {
  std::string law;
  std::vector<double> gravity, speed;
  double diameter_m = 0.1, mass_kg = 1.0;
  std::string cases;
  bool extrapolate = false;
  std::string format = "table";
  std::string plot;                 ///< PNG of the prediction against g; empty: none
  std::vector<double> plot_froude;  ///< the figure's curves at these Froude numbers (else at the speeds)
};

/// A number of the cases table: rounded to `digits` significant digits for the eye (`nan` when
/// not finite), or at full precision for a script (csv and json; null, an empty CSV cell, when
/// not finite), so that a prediction read back is the one computed.
nlohmann::json number_cell(double x, int digits, bool full) {
  if (!full) return num(x, digits);
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
}

/// Points of the figure's g grid per decade, and how far beyond the fitted g range it reaches
/// (a factor: past the extrapolation limit, so that the refused zone shows).
constexpr int kPlotPointsPerDecade = 12;
constexpr double kPlotBeyondGravity = 30.0;

/// The prediction against g: one curve per --plot-froude value (v = Fr sqrt(g D)) or per --speed.
void plot_against_gravity(const PredictOptions& o, const results::SavedLaw& law) {
  const bool by_froude = !o.plot_froude.empty();
  const std::vector<double>& fixed = by_froude ? o.plot_froude : o.speed;
  if (fixed.empty()) throw UsageError("--plot: give --speed (curves at fixed speeds) or --plot-froude");
  const double lo = std::log10(law.gravity_m_s2.lo / kPlotBeyondGravity);
  const double hi = std::log10(law.gravity_m_s2.hi * kPlotBeyondGravity);
  const int n = static_cast<int>(std::ceil((hi - lo) * kPlotPointsPerDecade));
  std::vector<results::LawCurvePoint> pts;
  for (const double x : fixed) {
    const std::string curve = by_froude ? fmt::format("Fr = {:g}", x) : fmt::format("v = {:g} m/s", x);
    for (int i = 0; i <= n; ++i) {
      const double g = std::pow(10.0, lo + (hi - lo) * i / n);
      const results::LawCase c{g, by_froude ? x * std::sqrt(g * o.diameter_m) : x, o.diameter_m, o.mass_kg};
      results::LawPrediction p = results::predict_case(law, c);
      if (p.range == results::LawRangeFlag::refused) {
        p = results::predict_case(results::without_ranges(law), c);
        p.range = results::LawRangeFlag::refused;
      }
      pts.push_back({curve, g, p});
    }
  }
  results::draw_law_against_gravity(
      pts, law.gravity_m_s2, o.plot,
      fmt::format("{}: D = {:g} m, m = {:g} kg ({})", law.model, o.diameter_m, o.mass_kg, o.law));
}

/// The cases of a CSV file: columns gravity_m_s2 and speed_m_s, optional diameter_m and mass_kg
/// (the options' values where absent). ConfigError naming the file, line and column otherwise.
std::vector<results::LawCase> read_cases(const PredictOptions& o) {
  std::ifstream in(o.cases);
  if (!in) throw ConfigError(fmt::format("{}: cannot read the cases file", o.cases));
  results::CsvReader csv(in);
  std::vector<std::string> names, f;
  int line = 0;
  if (!csv.next(names, line))
    throw ConfigError(fmt::format("{}: empty; expected a header gravity_m_s2,speed_m_s[,diameter_m,mass_kg]", o.cases));
  std::map<std::string, std::size_t> col;
  for (std::size_t i = 0; i < names.size(); ++i) col[names[i]] = i;
  for (const char* need : {"gravity_m_s2", "speed_m_s"})
    if (col.count(need) == 0)
      throw ConfigError(
          fmt::format("{}:1: no column {} (header: gravity_m_s2,speed_m_s[,diameter_m,mass_kg])", o.cases, need));
  std::vector<results::LawCase> out;
  while (csv.next(f, line)) {
    const auto value = [&](const char* name, double fallback) {
      const auto it = col.find(name);
      if (it == col.end()) return fallback;
      const std::string& text = it->second < f.size() ? f[it->second] : std::string();
      char* end = nullptr;
      const double x = std::strtod(text.c_str(), &end);
      if (text.empty() || *end != '\0' || !(x > 0) || !std::isfinite(x))
        throw ConfigError(fmt::format("{}:{}: {} = '{}': expected a positive number", o.cases, line, name, text));
      return x;
    };
    out.push_back({value("gravity_m_s2", NAN), value("speed_m_s", NAN), value("diameter_m", o.diameter_m),
                   value("mass_kg", o.mass_kg)});
  }
  return out;
}

std::vector<results::LawCase> cases_of(const PredictOptions& o) {
  if (!o.cases.empty()) return read_cases(o);
  if (o.gravity.empty() || o.speed.empty())
    throw UsageError(
        "give --gravity and --speed (each may list several values: every pair is a case), or --cases FILE");
  std::vector<results::LawCase> out;
  for (double g : o.gravity)
    for (double v : o.speed) out.push_back({g, v, o.diameter_m, o.mass_kg});
  return out;
}

void run_predict(const PredictOptions& o) {
  const results::SavedLaw law = results::read_law(o.law);
  if (!o.plot.empty()) {
    plot_against_gravity(o, law);
    if (o.format == "table") fmt::print("wrote {}\n", o.plot);
    if (o.gravity.empty() && o.cases.empty()) return;  // the figure alone
  }
  const std::vector<results::LawCase> cases = cases_of(o);
  results::Table t({"gravity_m_s2", "speed_m_s", "diameter_m", "mass_kg", "impact_froude", "zstop_m", "zstop_lo_m",
                    "zstop_hi_m", "tstop_s", "tstop_lo_s", "tstop_hi_s", "apeak_m_s2", "apeak_lo_m_s2", "apeak_hi_m_s2",
                    "range", "note"});
  int refused = 0, extrapolated = 0;
  for (const auto& c : cases) {
    results::LawPrediction p = results::predict_case(law, c);
    if (p.range == results::LawRangeFlag::refused && o.extrapolate) {
      const std::string note = p.note;  // --extrapolate: predicted all the same, still flagged
      p = results::predict_case(results::without_ranges(law), c);
      p.range = results::LawRangeFlag::refused;
      p.note = note + " (predicted: --extrapolate)";
    }
    refused += p.range == results::LawRangeFlag::refused ? 1 : 0;
    extrapolated += p.range == results::LawRangeFlag::extrapolated ? 1 : 0;
    const auto cell = [full = o.format != "table"](double x, int digits) { return number_cell(x, digits, full); };
    t.add_values({cell(c.gravity_m_s2, 4), cell(c.speed_m_s, 4), cell(c.diameter_m, 4), cell(c.mass_kg, 4),
                  cell(p.froude, 3), cell(p.zstop_m, 4), cell(p.zstop_lo_m, 4), cell(p.zstop_hi_m, 4),
                  cell(p.tstop_s, 4), cell(p.tstop_lo_s, 4), cell(p.tstop_hi_s, 4), cell(p.apeak_m_s2, 4),
                  cell(p.apeak_lo_m_s2, 4), cell(p.apeak_hi_m_s2, 4), results::to_string(p.range), p.note});
  }
  if (o.format == "table")
    fmt::print("Law {} ({}; fitted on {} trials at {} levels, {:.3g}-{:.3g} m/s2, Fr {:.2g}-{:.2g}):\n", law.model,
               o.law, law.trials, law.levels, law.gravity_m_s2.lo, law.gravity_m_s2.hi, law.froude.lo, law.froude.hi);
  t.print(o.format);
  if (o.format == "table")
    fmt::print(
        "\n95 % intervals: the constants' bootstrap spread and 1.96 x the law's RMS error at the case's Froude "
        "number ({}), in quadrature.\n",
        law.form_error_source);
  if (extrapolated > 0)
    std::fprintf(stderr, "warning: %d case(s) outside the law's fitted ranges (range = extrapolated): see the note\n",
                 extrapolated);
  if (refused > 0 && !o.extrapolate) {
    std::fprintf(stderr,
                 "error: %d case(s) far beyond the law's fitted ranges (range = refused; see the note): not predicted. "
                 "--extrapolate predicts them all the same\n",
                 refused);
    throw ExitWith{kExitUsage};
  }
}

}  // namespace

void setup_model_predict(CLI::App& model) {
  auto o = std::make_shared<PredictOptions>();
  auto* sub = model.add_subcommand(
      "predict",
      "Apply a saved law (`model fit ... --save law.json`) to a gravity, impact speed, projectile\n"
      "diameter and mass of one's own: Eq. 1 with the fitted resistance integrated from the impact\n"
      "to the stop gives zstop (maximum depth), tstop (contact to rest) and apeak (the law's peak\n"
      "deceleration, smooth: a measured record's peak is higher by its force chains), each with a\n"
      "95 % interval that holds the constants' uncertainty (bootstrap over drops) and the law's\n"
      "error at the case's Froude number Fr = v / sqrt(g D) (held out by gravity level), and a range\n"
      "flag: inside the fitted ranges of g, Fr, D and m; extrapolated (outside them by at most a\n"
      "factor 10 in g, 2 in Fr and D, 4 in m: a warning); refused (further: not predicted, exit 2,\n"
      "unless --extrapolate).\n\n"
      "Examples:\n"
      "  gravsweep model predict --law law.json --gravity 0.01 --speed 0.2\n"
      "  gravsweep model predict --law law.json --gravity 9.81 1.62 0.1 --speed 0.5 1 --format csv\n"
      "  gravsweep model predict --law law.json --cases cases.csv   # gravity_m_s2,speed_m_s[,diameter_m,mass_kg]\n"
      "  gravsweep model predict --law law.json --plot-froude 0.5 2 8 --plot law_g.png   # against g at fixed Fr");
  sub->add_option("--law", o->law, "the law file (model fit --save)")->required()->check(CLI::ExistingFile);
  sub->add_option("--gravity", o->gravity, "gravity, m/s2 (several: each is a case with each --speed)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--speed", o->speed, "impact speed, m/s (several allowed)")->check(CLI::PositiveNumber);
  sub->add_option("--diameter", o->diameter_m, "projectile diameter, m")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  sub->add_option("--mass", o->mass_kg, "projectile mass, kg")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--cases", o->cases, "CSV of cases: gravity_m_s2,speed_m_s[,diameter_m,mass_kg]")
      ->check(CLI::ExistingFile);
  sub->add_flag("--extrapolate", o->extrapolate, "predict cases far beyond the fitted ranges too (still flagged)");
  sub->add_option("--plot", o->plot,
                  "also draw zstop, tstop and apeak against g with their 95 % bands (PNG): one curve per --speed, "
                  "or per --plot-froude value; --gravity is then optional");
  sub->add_option("--plot-froude", o->plot_froude, "the figure's curves at these Froude numbers (v = Fr sqrt(g D))")
      ->check(CLI::PositiveNumber);
  add_format_option(sub, o->format);
  sub->callback([o]() { run_predict(*o); });
}

}  // namespace gravsweep::cli
