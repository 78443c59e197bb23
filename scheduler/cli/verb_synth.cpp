// `gravsweep synth`: a synthetic impact laboratory. Writes a measurement campaign (trials.csv and
// traces in the laboratory format) from a model spec plus a noise model.
#include <fmt/format.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "results/model/model_spec.h"
#include "results/model/synth.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/verbs.h"

namespace gravsweep::cli {

void setup_synth(CLI::App& app) {
  auto o = std::make_shared<results::SynthOptions>();
  auto model = std::make_shared<std::string>("base");
  auto out = std::make_shared<std::string>();
  auto* sub =
      app.add_subcommand("synth",
                         "Write a synthetic measurement campaign (docs/formats/measurements.md) from a model\n"
                         "(terms with their typical values, see `gravsweep model terms`) plus a noise model: sensor\n"
                         "noise and bias (scaled with g, or fixed for one sensor range at every level), grain-scale\n"
                         "force fluctuations (correlated, multiplicative), per-trial bed spread, a contact ramp over\n"
                         "the first millimetre, the sampling rate and the rest tail. Use it to hide an effect and\n"
                         "check that `gravsweep model rank` finds it.\n"
                         "Beside trials.csv it writes truth.csv: each trial's true zstop_m and tstop_s (contact to\n"
                         "rest of the integrated motion) and t_contact_s (on the trace's clock), to check the\n"
                         "processing against.\n\n"
                         "Examples:\n"
                         "  gravsweep synth --out /tmp/c1 --model base+viscous_drag --seed 3\n"
                         "  gravsweep synth --out /tmp/c2 --model base+bottom_stiffening --fill 0.06,0.08,0.12\n"
                         "  gravsweep synth --out /tmp/c3 --model spec.json --repeats 2 --rate 10000\n"
                         "  gravsweep synth --out /tmp/c4 --gravity 0.4,0.1 --rest-tail 0.03 --sensor-noise 0.03");
  sub->add_option("--out", *out, "campaign folder to write")->required();
  sub->add_option("--model", *model, "model: 'base+depth_friction' or a JSON spec file (schemas/model.schema.json)")
      ->capture_default_str();
  sub->add_option("--seed", o->seed, "random seed")->capture_default_str();
  sub->add_option("--gravity", o->gravity_m_s2, "gravity levels, m/s2")->delimiter(',')->capture_default_str();
  sub->add_option("--speeds", o->impact_speed_m_s, "impact speeds, m/s")->delimiter(',')->capture_default_str();
  sub->add_option("--fill", o->fill_height_m, "fill heights, m (cycled over trials)")
      ->delimiter(',')
      ->capture_default_str();
  sub->add_option("--repeats", o->repeats, "trials per (gravity, speed)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  sub->add_option("--rate", o->sample_rate_hz, "accelerometer sampling rate, Hz")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  sub->add_option("--sensor-noise", o->sensor_noise_g, "sensor noise std, in g")->capture_default_str();
  sub->add_option("--bias", o->sensor_bias_g, "per-trial sensor bias std, in g")->capture_default_str();
  sub->add_option("--sensor-range", o->sensor_range_m_s2,
                  "accelerometer range, m/s2: readings beyond it saturate (a flat top; 0: no limit)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  sub->add_option("--rest-tail", o->rest_tail_s, "record length after the projectile comes to rest, s")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  sub->add_flag_function(
      "--fixed-range-sensor", [o](std::int64_t) { o->noise_scales_with_g = false; },
      "noise and bias in units of 9.81 m/s2 at every level (default: of each level's g)");
  sub->add_option("--fluct", o->force_fluct, "grain-scale force fluctuation (relative std)")->capture_default_str();
  sub->add_option("--bed-spread", o->bed_spread_f0, "per-trial relative spread of friction terms")
      ->capture_default_str();
  sub->callback([o, model, out]() {
    results::ModelSpec spec;
    try {
      spec = results::parse_model(*model);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
    const int n = results::write_synthetic_campaign(*out, spec, *o);
    fmt::print("{} trials of model {} written to {} (seed {})\n", n, spec.name(), *out, o->seed);
  });
}

}  // namespace gravsweep::cli
