// The impact job kinds ("bed" and "drop") on top of scheduler/pipeline/impact_job.h. The pipeline
// is part of every build (scheduler/CMakeLists.txt compiles pipeline/*.cpp into the library).
#pragma once
#include "scheduler/queue/worker.h"
#include "scheduler/sweep/spec.h"

namespace gravsweep::queue {

/// Drops with equal keys share a bed (pipeline::bed_key).
sweep::BedKeyFn impact_bed_key();
/// Adds the "bed" and "drop" runners.
void add_impact_runners(RunnerTable& table);
/// Every runner: noop, bed and drop.
RunnerTable all_runners();

}  // namespace gravsweep::queue
