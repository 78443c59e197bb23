// The impact job kinds ("bed" and "drop") as runners of the queue's workers
// (scheduler/queue/worker.h RunnerTable), on top of scheduler/pipeline/impact_job.h: the queue
// knows job kinds by name and runs what is registered for them.
#pragma once
#include "scheduler/queue/worker.h"
#include "scheduler/sweep/spec.h"

namespace gravsweep::pipeline {

/// Validates a sweep point once, at submit: the text its jobs store (stored_scenario: validated,
/// marked, with the point as written) and its bed key (drops with equal keys share a bed).
sweep::PointCheckFn impact_point_check();
/// Adds the "bed" and "drop" runners.
void add_impact_runners(queue::RunnerTable& table);
/// Every runner: noop, bed and drop.
queue::RunnerTable all_runners();

}  // namespace gravsweep::pipeline
