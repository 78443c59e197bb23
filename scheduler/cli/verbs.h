// One file pair per CLI verb: scheduler/cli/verb_<name>.{h,cpp} defines setup_<name>(CLI::App&),
// which adds the subcommand, its options, its --help text (with an example) and its callback.
// The table in main.cpp lists every verb once; adding a verb is one file pair and one row.
#pragma once
#include <CLI/CLI.hpp>

namespace gravsweep::cli {

void setup_bench(CLI::App& app);
void setup_measurements(CLI::App& app);
void setup_model(CLI::App& app);
// The sub-verbs of `model`, one file each (verb_model_<name>.cpp; lolo also adds `regimes`).
void setup_model_table3(CLI::App& model);
void setup_model_fit(CLI::App& model);
void setup_model_residuals(CLI::App& model);
void setup_model_check_detection(CLI::App& model);
void setup_model_rank(CLI::App& model);
void setup_model_collapse(CLI::App& model);
void setup_model_lolo(CLI::App& model);
void setup_model_scaling(CLI::App& model);
void setup_model_predict(CLI::App& model);
void setup_model_infer(CLI::App& model);
void setup_synth(CLI::App& app);
void setup_report(CLI::App& app);
void setup_run(CLI::App& app);
void setup_submit(CLI::App& app);
void setup_work(CLI::App& app);
void setup_status(CLI::App& app);
void setup_resume(CLI::App& app);
void setup_results(CLI::App& app);
void setup_bench_queue(CLI::App& app);
void setup_pile(CLI::App& app);
void setup_plot(CLI::App& app);
void setup_export(CLI::App& app);
void setup_campaign(CLI::App& app);
void setup_slurm(CLI::App& app);
void setup_serve(CLI::App& app);

}  // namespace gravsweep::cli
