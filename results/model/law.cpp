// A gravity-scaled law kept in a file and applied to new cases (see law.h).
#include "results/model/model_spec.h"
#include "results/model/fit.h"
#include "results/model/predict.h"
#include "results/model/law.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <stdexcept>

#include "engine/core/error.h"
#include "results/model/froude.h"
#include "results/model/level_out.h"
#include "results/model/stats.h"

namespace gravsweep::results {

using nlohmann::json;

namespace {

/// A bed deep enough that no floor enters a prediction (bottom_stiffening reads the fill height).
constexpr double kUnboundedFill_m = 1e3;

void widen(LawRange& r, double x) {
  if (!std::isfinite(x)) return;
  r.lo = std::isnan(r.lo) ? x : std::min(r.lo, x);
  r.hi = std::isnan(r.hi) ? x : std::max(r.hi, x);
}

/// A bed field a trial may leave at 0 (not recorded): only recorded values widen the range.
void widen_recorded(LawRange& r, double x) {
  if (x > 0) widen(r, x);
}

/// The constants refitted on resamples of whole drops, drawn within each gravity level.
std::vector<std::vector<double>> bootstrap_constants(const ModelSpec& law, const Campaign& c, int resamples,
                                                     unsigned seed) {
  const auto by_level = c.trials_by_level();
  std::mt19937 rng(seed);
  std::vector<std::vector<double>> out;
  for (int b = 0; b < resamples; ++b) {
    try {
      const FittedModel m = fit_model(law, c, resample_within(by_level, c.trials.size(), rng));
      out.emplace_back(m.coef.data(), m.coef.data() + m.coef.size());
    } catch (const std::exception&) {  // a resample the fit cannot solve: left out
    }
  }
  return out;
}

/// Per design Froude number, the RMS of the signed relative errors of `err` (one row per drop:
/// Fr, zstop %, tstop %, apeak %).
std::vector<LawFormError> by_froude(const std::vector<std::array<double, 4>>& err) {
  std::vector<double> ln_fr;
  for (const auto& e : err) ln_fr.push_back(std::log(e[0]));
  const std::vector<int> group = froude_groups(ln_fr);
  const int groups = group.empty() ? 0 : *std::max_element(group.begin(), group.end()) + 1;
  std::vector<LawFormError> out(static_cast<std::size_t>(groups));
  std::vector<std::array<double, 4>> sum(out.size(), {0, 0, 0, 0});
  std::vector<std::array<int, 3>> n(out.size(), {0, 0, 0});
  for (std::size_t i = 0; i < err.size(); ++i) {
    const auto g = static_cast<std::size_t>(group[i]);
    sum[g][0] += err[i][0];
    ++out[g].drops;
    for (int k = 0; k < 3; ++k)
      if (std::isfinite(err[i][static_cast<std::size_t>(k + 1)]))
        sum[g][static_cast<std::size_t>(k + 1)] +=
            err[i][static_cast<std::size_t>(k + 1)] * err[i][static_cast<std::size_t>(k + 1)],
            ++n[g][static_cast<std::size_t>(k)];
  }
  for (std::size_t g = 0; g < out.size(); ++g) {
    out[g].froude = sum[g][0] / out[g].drops;
    const auto rms = [&](int k) { return n[g][k] > 0 ? std::sqrt(sum[g][k + 1] / n[g][k]) : NAN; };
    out[g].zstop_rms_pct = rms(0);
    out[g].tstop_rms_pct = rms(1);
    out[g].apeak_rms_pct = rms(2);
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.froude < b.froude; });
  return out;
}

double pct(double pred, double meas) { return meas > 0 && std::isfinite(pred) ? 100 * (pred - meas) / meas : NAN; }

/// The law's errors by Froude number: held out by level with two levels or more, else in sample.
void form_errors(const ModelSpec& law, const Campaign& c, const FittedModel& all, SavedLaw& s) {
  std::vector<std::array<double, 4>> err;
  if (c.gravity_levels().size() >= 2) {
    for (const auto& row : leave_level_out(law, c))
      for (const auto& t : row.per_trial)
        err.push_back({t.impact_froude, t.zstop_err_pct, t.tstop_err_pct, t.apeak_err_pct});
    s.form_error_source = "leave one gravity level out";
  } else {
    for (const auto& t : c.trials) {
      const Prediction p = predict(all, t);
      const auto& m = t.processed.metrics;
      err.push_back(
          {impact_froude(t), pct(p.zstop_m, m.zstop_m), pct(p.tstop_s, m.tstop_s), pct(p.apeak_m_s2, m.apeak_m_s2)});
    }
    s.form_error_source = "in sample";
  }
  std::erase_if(err, [](const auto& e) { return !(e[0] > 0); });
  s.form_error = by_froude(err);
}

}  // namespace

SavedLaw make_saved_law(const ModelSpec& law, const Campaign& c, int resamples, unsigned seed) {
  if (!one_law_for_all_levels(law))
    throw std::invalid_argument(fmt::format(
        "'{}' has a term with a value per gravity level, so it holds at the fitted levels only: save a law for "
        "every level (scaled_base, terms shared or carried by g^p)",
        law.name()));
  SavedLaw s;
  s.model = law.name();
  const FittedModel m = fit_model(law, c);
  s.constants = m.column_names;
  s.values.assign(m.coef.data(), m.coef.data() + m.coef.size());
  for (Eigen::Index i = 0; i < m.cov.rows(); ++i) {
    s.covariance.emplace_back();
    for (Eigen::Index j = 0; j < m.cov.cols(); ++j) s.covariance.back().push_back(m.cov(i, j));
  }
  s.bootstrap = bootstrap_constants(law, c, resamples, seed);
  for (const auto& t : c.trials) {
    widen(s.gravity_m_s2, t.info.gravity_m_s2);
    widen(s.froude, impact_froude(t));
    widen(s.diameter_m, t.info.projectile_diameter_m);
    widen(s.mass_kg, t.info.projectile_mass_kg);
    widen(s.grain_diameter_m, t.info.grain_diameter_m);
    widen_recorded(s.bulk_density_kg_m3, t.info.bulk_density_kg_m3);
    widen_recorded(s.fill_height_m, t.info.fill_height_m);
  }
  s.trials = static_cast<int>(c.trials.size());
  s.levels = static_cast<int>(c.gravity_levels().size());
  form_errors(law, c, m, s);
  return s;
}

FittedModel law_model(const SavedLaw& s) {
  FittedModel m;
  m.spec = parse_model(s.model);
  m.gravity_levels = {s.gravity_m_s2.hi};
  m.column_names = s.constants;
  m.coef = Eigen::Map<const Eigen::VectorXd>(s.values.data(), static_cast<Eigen::Index>(s.values.size()));
  const auto n = static_cast<Eigen::Index>(s.values.size());
  m.cov = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j)
      m.cov(i, j) = s.covariance[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
  return m;
}

// ---------------------------------------------------------------------------------------------
// The file

namespace {

json range_json(const LawRange& r) { return json{{"min", r.lo}, {"max", r.hi}}; }

/// The ranges; the bed's only when recorded (a law from trials without them, or read from an
/// older file, has none, and the file then has no such field).
json ranges_json(const SavedLaw& s) {
  json r{{"gravity_m_s2", range_json(s.gravity_m_s2)},
         {"impact_froude", range_json(s.froude)},
         {"projectile_diameter_m", range_json(s.diameter_m)},
         {"projectile_mass_kg", range_json(s.mass_kg)},
         {"grain_diameter_m", range_json(s.grain_diameter_m)}};
  if (std::isfinite(s.bulk_density_kg_m3.lo)) r["bulk_density_kg_m3"] = range_json(s.bulk_density_kg_m3);
  if (std::isfinite(s.fill_height_m.lo)) r["fill_height_m"] = range_json(s.fill_height_m);
  return r;
}

json form_error_json(const std::vector<LawFormError>& f) {
  json a = json::array();
  for (const auto& e : f)
    a.push_back({{"froude", e.froude},
                 {"drops", e.drops},
                 {"zstop_rms_pct", std::isfinite(e.zstop_rms_pct) ? json(e.zstop_rms_pct) : json(nullptr)},
                 {"tstop_rms_pct", std::isfinite(e.tstop_rms_pct) ? json(e.tstop_rms_pct) : json(nullptr)},
                 {"apeak_rms_pct", std::isfinite(e.apeak_rms_pct) ? json(e.apeak_rms_pct) : json(nullptr)}});
  return a;
}

/// Reads the file's fields, naming the file and the JSON pointer of the first that is wrong.
class LawReader {
 public:
  LawReader(std::filesystem::path path, json j) : path_(std::move(path)), j_(std::move(j)) {}
  [[noreturn]] void fail(const std::string& pointer, const std::string& what) const {
    throw ConfigError(fmt::format("{}: {}: {}", path_.string(), pointer, what));
  }
  bool has(const std::string& pointer) const { return j_.contains(json::json_pointer(pointer)); }
  const json& at(const std::string& pointer) const {
    const json::json_pointer p(pointer);
    if (!j_.contains(p)) fail(pointer, "missing");
    return j_.at(p);
  }
  double number(const std::string& pointer, bool positive = false) const {
    const json& v = at(pointer);
    if (!v.is_number() || (positive && !(v.get<double>() > 0)))
      fail(pointer, fmt::format("{} is not a {}number", v.dump(), positive ? "positive " : ""));
    return v.get<double>();
  }
  double number_or_nan(const std::string& pointer) const {
    const json& v = at(pointer);
    if (v.is_null()) return NAN;
    return number(pointer);
  }
  std::string text(const std::string& pointer) const {
    const json& v = at(pointer);
    if (!v.is_string()) fail(pointer, fmt::format("{} is not a string", v.dump()));
    return v.get<std::string>();
  }
  std::vector<double> numbers(const std::string& pointer, std::size_t n) const {
    const json& v = at(pointer);
    if (!v.is_array() || v.size() != n) fail(pointer, fmt::format("expected an array of {} numbers", n));
    std::vector<double> out;
    for (std::size_t i = 0; i < n; ++i) out.push_back(number(fmt::format("{}/{}", pointer, i)));
    return out;
  }
  LawRange range(const std::string& pointer) const {
    LawRange r{number(pointer + "/min", true), number(pointer + "/max", true)};
    if (r.lo > r.hi) fail(pointer, fmt::format("min {} above max {}", r.lo, r.hi));
    return r;
  }
  /// A range a version-1 file may lack (written before it was recorded): NaN when absent.
  LawRange optional_range(const std::string& pointer) const { return has(pointer) ? range(pointer) : LawRange{}; }

 private:
  std::filesystem::path path_;
  json j_;
};

}  // namespace

void write_law(const std::filesystem::path& path, const SavedLaw& s) {
  const json j{{"format", kLawFormat},
               {"format_version", kLawFormatVersion},
               {"model", s.model},
               {"constants", s.constants},
               {"values", s.values},
               {"covariance", s.covariance},
               {"bootstrap", s.bootstrap},
               {"form_error", {{"source", s.form_error_source}, {"by_froude", form_error_json(s.form_error)}}},
               {"ranges", ranges_json(s)},
               {"trials", s.trials},
               {"levels", s.levels},
               {"code_version", s.code_version},
               {"fitted_on", s.fitted_on}};
  const std::filesystem::path tmp = path.string() + ".tmp";
  {
    std::ofstream f(tmp);
    if (!f) throw ConfigError(fmt::format("{}: cannot write", tmp.string()));
    f << j.dump(1) << "\n";
    if (!f) throw ConfigError(fmt::format("{}: write failed", tmp.string()));
  }
  std::filesystem::rename(tmp, path);
}

SavedLaw read_law(const std::filesystem::path& path) {
  std::ifstream f(path);
  if (!f) throw ConfigError(fmt::format("{}: cannot read the law file", path.string()));
  json j;
  try {
    j = json::parse(f);
  } catch (const json::parse_error& e) {
    throw ConfigError(fmt::format("{}: not JSON ({}); a law file is written by `gravsweep model fit --save`",
                                  path.string(), e.what()));
  }
  const LawReader r(path, j);
  if (!j.is_object() || r.text("/format") != kLawFormat)
    r.fail("/format", fmt::format("not a gravsweep law (expected \"{}\")", kLawFormat));
  if (r.number("/format_version") != kLawFormatVersion)
    r.fail("/format_version",
           fmt::format("{}, this build reads version {}", r.at("/format_version").dump(), kLawFormatVersion));
  SavedLaw s;
  s.model = r.text("/model");
  ModelSpec spec;
  try {
    spec = parse_model(s.model);
  } catch (const std::exception& e) {
    r.fail("/model", e.what());
  }
  if (!one_law_for_all_levels(spec)) r.fail("/model", "a law with per-level terms holds at its fitted levels only");
  std::size_t columns = 0;
  for (const auto& t : spec.terms) columns += t.term->params.size();
  const json& names = r.at("/constants");
  if (!names.is_array() || names.empty()) r.fail("/constants", "expected the names of the law's constants");
  for (std::size_t i = 0; i < names.size(); ++i) s.constants.push_back(r.text(fmt::format("/constants/{}", i)));
  const std::size_t n = s.constants.size();
  if (n != columns) r.fail("/constants", fmt::format("{} constants, the model '{}' has {}", n, s.model, columns));
  s.values = r.numbers("/values", n);
  for (std::size_t i = 0; i < n; ++i) s.covariance.push_back(r.numbers(fmt::format("/covariance/{}", i), n));
  const json& boot = r.at("/bootstrap");
  if (!boot.is_array()) r.fail("/bootstrap", "expected an array of resamples");
  for (std::size_t b = 0; b < boot.size(); ++b) s.bootstrap.push_back(r.numbers(fmt::format("/bootstrap/{}", b), n));
  s.form_error_source = r.text("/form_error/source");
  const json& fe = r.at("/form_error/by_froude");
  if (!fe.is_array()) r.fail("/form_error/by_froude", "expected an array");
  for (std::size_t i = 0; i < fe.size(); ++i) {
    const std::string p = fmt::format("/form_error/by_froude/{}", i);
    s.form_error.push_back({r.number(p + "/froude", true), static_cast<int>(r.number(p + "/drops")),
                            r.number_or_nan(p + "/zstop_rms_pct"), r.number_or_nan(p + "/tstop_rms_pct"),
                            r.number_or_nan(p + "/apeak_rms_pct")});
  }
  s.gravity_m_s2 = r.range("/ranges/gravity_m_s2");
  s.froude = r.range("/ranges/impact_froude");
  s.diameter_m = r.range("/ranges/projectile_diameter_m");
  s.mass_kg = r.range("/ranges/projectile_mass_kg");
  s.grain_diameter_m = r.range("/ranges/grain_diameter_m");
  s.bulk_density_kg_m3 = r.optional_range("/ranges/bulk_density_kg_m3");
  s.fill_height_m = r.optional_range("/ranges/fill_height_m");
  s.trials = static_cast<int>(r.number("/trials"));
  s.levels = static_cast<int>(r.number("/levels"));
  s.code_version = r.text("/code_version");
  s.fitted_on = r.text("/fitted_on");
  return s;
}

// ---------------------------------------------------------------------------------------------
// Predictions

const char* to_string(LawRangeFlag f) {
  switch (f) {
    case LawRangeFlag::inside:
      return "inside";
    case LawRangeFlag::extrapolated:
      return "extrapolated";
    case LawRangeFlag::refused:
      return "refused";
  }
  return "?";
}

namespace {

/// Flags `x` against `r`: beyond it by at most `factor` (ratio) extrapolated, further refused.
void check_range(const char* what, double x, const LawRange& r, double factor, LawPrediction& p) {
  if (r.holds(x)) return;
  const bool far = x < r.lo / factor || x > r.hi * factor;
  const auto flag = far ? LawRangeFlag::refused : LawRangeFlag::extrapolated;
  if (static_cast<int>(flag) > static_cast<int>(p.range)) p.range = flag;
  p.note += fmt::format("{}{} {:.3g} outside the fitted {:.3g}-{:.3g}{}", p.note.empty() ? "" : "; ", what, x, r.lo,
                        r.hi, far ? fmt::format(" (beyond a factor {:g}: refused)", factor) : "");
}

}  // namespace

double form_error_at(const std::vector<LawFormError>& f, double fr, int k) {
  const auto value = [k](const LawFormError& e) {
    return k == 0 ? e.zstop_rms_pct : k == 1 ? e.tstop_rms_pct : e.apeak_rms_pct;
  };
  std::vector<std::pair<double, double>> pts;
  for (const auto& e : f)
    if (std::isfinite(value(e))) pts.push_back({std::log(e.froude), value(e)});
  if (pts.empty()) return NAN;
  const double x = std::log(fr);
  if (x <= pts.front().first) return pts.front().second;
  if (x >= pts.back().first) return pts.back().second;
  for (std::size_t i = 1; i < pts.size(); ++i)
    if (x <= pts[i].first) {
      const double w = (x - pts[i - 1].first) / (pts[i].first - pts[i - 1].first);
      return pts[i - 1].second + w * (pts[i].second - pts[i - 1].second);
    }
  return pts.back().second;
}

namespace {

/// The 95 % interval of one metric: the bootstrap's spread and the form error, in quadrature.
void interval(double value, const std::vector<double>& boot, double form_rms_pct, double& lo, double& hi) {
  constexpr double kZ95 = 1.959964;
  const double b_lo = quantile(boot, 0.025), b_hi = quantile(boot, 0.975);
  const double param_rel = value > 0 && std::isfinite(b_lo) ? 0.5 * (b_hi - b_lo) / value : 0.0;
  const double form_rel = std::isfinite(form_rms_pct) ? kZ95 * form_rms_pct / 100 : 0.0;
  const double half = std::hypot(param_rel, form_rel);
  lo = value * std::max(0.0, 1 - half);
  hi = value * (1 + half);
}

}  // namespace

TermContext law_case_context(const SavedLaw& law, const LawCase& c) {
  TermContext ctx;
  const LawRange& d = law.grain_diameter_m;
  if (d.lo > 0 && d.hi > 0 && std::isfinite(d.lo) && std::isfinite(d.hi)) ctx.grain_diameter_m = std::sqrt(d.lo * d.hi);
  ctx.g_m_s2 = c.gravity_m_s2;
  ctx.diameter_m = c.diameter_m;
  ctx.mass_kg = c.mass_kg;
  ctx.fill_height_m = kUnboundedFill_m;
  ctx.v_m_s = ctx.vc_m_s = c.speed_m_s;
  return ctx;
}

SavedLaw without_ranges(SavedLaw law) {
  law.gravity_m_s2 = {0, 1e300};
  law.froude = {0, 1e300};
  law.diameter_m = {0, 1e300};
  law.mass_kg = {0, 1e300};
  return law;
}

LawPrediction predict_case(const SavedLaw& law, const LawCase& c) {
  LawPrediction p;
  p.froude = c.speed_m_s / std::sqrt(c.gravity_m_s2 * c.diameter_m);
  check_range("gravity (m/s2)", c.gravity_m_s2, law.gravity_m_s2, kLawExtrapolateGravity, p);
  check_range("impact Froude number", p.froude, law.froude, kLawExtrapolateFroude, p);
  check_range("projectile diameter (m)", c.diameter_m, law.diameter_m, kLawExtrapolateDiameter, p);
  check_range("projectile mass (kg)", c.mass_kg, law.mass_kg, kLawExtrapolateMass, p);
  if (p.range == LawRangeFlag::refused) return p;
  const TermContext ctx = law_case_context(law, c);
  FittedModel m = law_model(law);
  const Prediction best = predict(m, ctx);
  p.zstop_m = best.zstop_m, p.tstop_s = best.tstop_s, p.apeak_m_s2 = best.apeak_m_s2;
  std::vector<double> z, t, a;
  for (const auto& b : law.bootstrap) {
    m.coef = Eigen::Map<const Eigen::VectorXd>(b.data(), static_cast<Eigen::Index>(b.size()));
    const Prediction q = predict(m, ctx);
    z.push_back(q.zstop_m), t.push_back(q.tstop_s), a.push_back(q.apeak_m_s2);
  }
  interval(p.zstop_m, z, form_error_at(law.form_error, p.froude, 0), p.zstop_lo_m, p.zstop_hi_m);
  interval(p.tstop_s, t, form_error_at(law.form_error, p.froude, 1), p.tstop_lo_s, p.tstop_hi_s);
  interval(p.apeak_m_s2, a, form_error_at(law.form_error, p.froude, 2), p.apeak_lo_m_s2, p.apeak_hi_m_s2);
  if (!best.stopped) p.note += std::string(p.note.empty() ? "" : "; ") + "the law's motion did not stop";
  return p;
}

}  // namespace gravsweep::results
