// The impact job kinds ("bed" and "drop") on top of scheduler/pipeline/impact_job.h, when that
// pipeline is part of the build; otherwise available() is false and submit refuses impact sweeps.
#pragma once
#include "scheduler/queue/worker.h"
#include "scheduler/sweep/spec.h"

namespace gravsweep::queue {

bool impact_available();
/// Drops with equal keys share a bed (pipeline::bed_key); empty function when unavailable.
sweep::BedKeyFn impact_bed_key();
/// Adds the "bed" and "drop" runners (no-op when unavailable).
void add_impact_runners(RunnerTable& table);
/// Every runner this build has: noop, and bed/drop when available.
RunnerTable all_runners();

}  // namespace gravsweep::queue
