// The impact job kinds ("bed" and "drop") as runners of the queue's workers
// (scheduler/queue/worker.h RunnerTable), on top of scheduler/pipeline/impact_job.h: the queue
// knows job kinds by name and runs what is registered for them.
#pragma once
#include "scheduler/queue/worker.h"
#include "scheduler/sweep/spec.h"

namespace gravsweep::pipeline {

/// Drops with equal keys share a bed (pipeline::bed_key).
sweep::PointCheckFn impact_point_check();
/// Adds the "bed" and "drop" runners.
void add_impact_runners(queue::RunnerTable& table);
/// Every runner: noop, bed and drop.
queue::RunnerTable all_runners();

}  // namespace gravsweep::pipeline
