// `gravsweep`: one binary, one subcommand per verb (see verbs.h). main() only wires them up and
// turns exceptions (and a verb's ExitWith) into the exit codes of exit_codes.h.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>

#include "engine/core/error.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/verbs.h"
#include "scheduler/pipeline/build_version.h"
#include "scheduler/pipeline/job_kinds.h"

namespace {

using SetupFn = void (*)(CLI::App&);
// The verb table: one row per verb, in the order `gravsweep --help` lists them.
constexpr SetupFn kVerbs[] = {
    &gravsweep::cli::setup_run,          &gravsweep::cli::setup_bench,  &gravsweep::cli::setup_pile,
    &gravsweep::cli::setup_measurements, &gravsweep::cli::setup_model,  &gravsweep::cli::setup_synth,
    &gravsweep::cli::setup_report,       &gravsweep::cli::setup_submit, &gravsweep::cli::setup_work,
    &gravsweep::cli::setup_status,       &gravsweep::cli::setup_resume, &gravsweep::cli::setup_results,
    &gravsweep::cli::setup_plot,         &gravsweep::cli::setup_export, &gravsweep::cli::setup_bench_queue,
    &gravsweep::cli::setup_campaign,     &gravsweep::cli::setup_slurm,  &gravsweep::cli::setup_serve,
};

}  // namespace

int main(int argc, char** argv) {
  using namespace gravsweep;
  // OpenMP threads that spin while waiting at barriers lose whole time slices when the machine
  // runs anything else (other workers, a build): measured 2,000 vs 214 ns per particle-step with
  // 2 threads on a busy 2-core machine. Passive waiting with a short spin first (kBarrierSpins)
  // keeps most of that and wins back the futex sleep/wake of a quiet machine's barriers: 46.0 vs
  // 51.4 ns quiet, 98 vs 90 ns beside a busy process (BENCHMARKS.md). libgomp reads both
  // when it loads, so set them and re-execute once; a user's own OMP_WAIT_POLICY or
  // GOMP_SPINCOUNT is kept.
  constexpr const char* kBarrierSpins = "500";
  if (std::getenv("OMP_WAIT_POLICY") == nullptr) {
    setenv("OMP_WAIT_POLICY", "passive", 1);
    setenv("GOMP_SPINCOUNT", kBarrierSpins, 0);
    execv("/proc/self/exe", argv);  // returns only on failure: then run with the default policy
  }
  CLI::App app{
      "gravsweep: campaigns of granular impact simulations (soft-sphere DEM) across gravity levels,\n"
      "and the comparison of collision models with laboratory measurements.\n\n"
      "Typical session:\n"
      "  gravsweep run examples/impact_1g.json --out runs/1g     # one impact, end to end\n"
      "  gravsweep bench                                         # engine speed on the paper's bed\n\n"
      "Run `gravsweep <verb> --help` for each verb, with an example.",
      "gravsweep"};
  app.require_subcommand(1);
  pipeline::register_job_kinds();  // the sweep kinds (a spec's "job") and their runners
  app.set_version_flag("--version", std::string(pipeline::build_version()));
  for (SetupFn setup : kVerbs) setup(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return cli::kExitUsage;
  } catch (const cli::ExitWith& e) {  // a verb that finished with another outcome than success
    std::fflush(nullptr);
    if (e.skip_exit_handlers) _exit(e.code);
    return e.code;
  } catch (const cli::UsageError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return cli::kExitUsage;
  } catch (const ConfigError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return cli::kExitUsage;
  } catch (const NumericalFailure& e) {
    std::fprintf(stderr, "numerical failure: %s\n", e.what());
    return cli::kExitNumerical;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    // A runtime failure (disk full, say) may leave HDF5 objects of the failed job open; HDF5's own
    // atexit clean-up then crashes (SIGSEGV in H5_term_library). Everything finished is already
    // committed and fsynced: leave without running exit handlers.
    std::fflush(nullptr);
    _exit(cli::kExitFailure);
  }
  return cli::kExitOk;
}
