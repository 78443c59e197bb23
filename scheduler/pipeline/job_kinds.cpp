#include "scheduler/pipeline/job_kinds.h"

#include "scheduler/pipeline/impact_runners.h"
#include "scheduler/sweep/sweep_kind.h"

namespace gravsweep::pipeline {

void register_job_kinds() {
  static const bool registered = [] {
    // One row per kind: its definition lives in its own file.
    sweep::register_sweep_kind(impact_sweep_kind());
    return true;
  }();
  (void)registered;
}

}  // namespace gravsweep::pipeline
