// Held-out comparisons of collision models (before/after tables), the data files behind the
// report figures, and the PNG plots (results/report/plots.py, run with Debian's python3).
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "results/model/cross_validation.h"
#include "results/model/discover.h"
#include "results/model/model_spec.h"

namespace gravsweep::results {

struct ComparedModel {
  std::string name;  ///< "paper Eq. 2-4 (Table 3)", "base", "base+depth_friction"
  HeldOut held_out;
  ErrorSummary errors;
};

/// The paper's method first, then each spec, all by grouped K-fold CV on whole trials.
std::vector<ComparedModel> compare_models(const Campaign& c, const std::vector<ModelSpec>& specs, int folds = 6);

/// Writes the CSV files the plots read into `dir`: trials.csv (each trial's gravity level, vc,
/// fill and drop height and measured apeak, zstop, tstop, rebound), residuals.csv (fit-window samples with residuals of
/// the first and last spec), errors.csv, ranking.csv, table3.csv, model_curves.csv (metrics vs vc per g).
void write_report_data(const std::string& dir, const Campaign& c, const std::vector<ComparedModel>& compared,
                       const std::vector<ModelSpec>& specs, const Discovery* discovery);

/// Runs the plotting script on `dir` (writes the PNGs there); returns the script's exit status
/// and fills `log` with its output.
int run_plots(const std::string& dir, const std::string& which, std::string& log);

/// A private temporary folder for a figure's data (<tmp>/gravsweep-<tag>-XXXXXX, made by mkdtemp,
/// mode 0700: one of its own for each use, even within one process), removed afterwards.
struct ScratchDir {
  std::filesystem::path path;
  explicit ScratchDir(const std::string& tag);
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
};

}  // namespace gravsweep::results
